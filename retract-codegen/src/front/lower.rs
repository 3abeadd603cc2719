//! The body of the Lagrangian to a graph node.
//!
//! Supported: f64 literals; consts by path; the jet arguments `q[i]`; parameters; `+ - * /`,
//! unary minus, parentheses; the f64 methods of [`METHODS`]; `let`, `let mut` with `=`,
//! `+=`, `-=`, `*=`, `/=`; `const` items; `for` over integer ranges (unrolled) and over
//! slice parameters (a run-time sum: the body may only accumulate into outer variables with
//! `+=` / `-=`); local arrays, tuples and helper `fn`s ([`values`]); named outputs
//! ([`outputs`]). Everything else is a
//! `syn::Error` at its span; errors are collected so the user sees all of them.
//!
//! Limits, each an error at its span beyond it: integers known at compile time (indices, loop
//! bounds, `powi` exponents) are computed in i64 with overflow checks, `powi` exponents must
//! fit in i32; indices (of the jet, of parameter arrays and of slice elements) go up to
//! `u32::MAX` = 4 294 967 295 and are never truncated; range loops unroll at most
//! [`MAX_UNROLLED`] statements in all.

use std::collections::HashMap;

use proc_macro2::Span;
use quote::ToTokens;
use syn::spanned::Spanned;
use syn::{BinOp, Block, Expr, Lit, Pat, Stmt, UnOp};

use crate::front::signature::{Attribute, Kind, Signature};
use crate::ir::graph::{Func, Graph, Id, Node, Var};
use crate::util::{ErrorContext, tidy};

mod outputs;
mod values;
pub use outputs::{item_without_output_marks, without_output_marks};
pub use values::Returned;
use values::Value;
pub(crate) use values::helper_signature_problem;

/// The supported f64 methods.
pub const METHODS: &str = "powi, powf, sqrt, exp, ln, sin, cos, tan, tanh, atan2, hypot, recip, \
     abs, asin, acos, atan, sinh, cosh, cbrt, ln_1p, exp_m1, log2, log10, mul_add (and the \
     functions smooth_max(a, b, eps), smooth_min(a, b, eps) and stumpff(k, s) of `retract`)";

/// Unrolled iterations allowed in one function (a guard against runaway expansion).
const MAX_UNROLLED: usize = 10_000;
/// The deepest nesting of expressions lowered (each operand, argument or receiver one level):
/// far beyond hand-written formulas, short of what overflows the compiler's stack.
const MAX_NESTING: usize = 512;

#[derive(Clone, Copy, Debug)]
enum Binding {
    Value {
        id: Id,
        mutable: bool,
    },
    Int(i64),
    /// A jet argument: component i is `Var::Jet { order, index: offset + i }` (the offset
    /// places v after q in the 2n-dimensional jet of a discretization map).
    Jet {
        order: u8,
        offset: u32,
    },
    Param {
        param: u32,
        kind: Kind,
    },
    Element {
        param: u32,
        len: usize,
    },
    /// A local array: its components are `arrays[slot]`.
    Array {
        slot: u32,
    },
    /// A binding whose initialiser was already reported as an error: later uses are silent.
    Poisoned,
}

/// A named output of a Lagrangian: `#[output] let name = ...;` at the top level of its body,
/// a number or an array, emitted as a method of the generated type.
pub struct Output {
    /// The name (and the method's).
    pub name: syn::Ident,
    /// Its components (one for a number).
    pub ids: Vec<Id>,
    /// Whether it is an array (`[f64; len]`) rather than a number.
    pub array: bool,
}

/// What a guarded expression must satisfy along a trajectory.
///
/// The singular operations the macro accepts, and what is guarded for each:
/// - `a / b`, `a /= b`, `b.recip()`, `b.powi(-m)`, `b.powf(-m)` (a negative integer
///   exponent): the denominator `b` ([`GuardKind::Denominator`]);
/// - `x.tan()`: `x.cos()` as a denominator;
/// - `y.atan2(x)` and `x.hypot(y)` (singular derivatives where both arguments vanish): `x^2 +
///   y^2` as a denominator, reported as `x.hypot(y)`;
/// - `x.ln()`: `x > 0`; `x.powf(e)` with `e` not an integer constant: `x > 0`; `x.sqrt()`:
///   `x >= 0`.
///
/// `exp`, `sin`, `cos`, `tanh`, `powi` and `powf` with a non-negative integer exponent are
/// entire; `abs` is a kink (its derivative is bounded), not a singularity, and is not guarded.
/// Each guarded expression is also split into the factors whose zeros are its zeros
/// (`zero_factors`: the base of an even power, the arguments of `abs` and `sqrt`, the factors
/// of a product); those must keep their sign and not vanish, so that `1 / q'^2` is caught
/// where `q'` changes sign although `q'^2` does not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuardKind {
    /// A denominator: must keep its sign and not vanish.
    Denominator,
    /// A `sqrt` argument: must stay >= 0.
    SqrtArgument,
    /// A `ln` argument: must stay > 0.
    LnArgument,
    /// A `powf` base: must stay > 0.
    PowfBase,
    /// `1 - x^2` for the argument x of `asin` or `acos`: must stay > 0.
    AsinArgument,
}

/// An expression of the Lagrangian where it can become singular.
#[derive(Clone, Debug)]
pub struct Guard {
    pub kind: GuardKind,
    pub node: Id,
    /// The expression as the user wrote it.
    pub text: String,
    /// The slice parameter whose elements it depends on, if any.
    pub slice: Option<u32>,
    /// A factor of the guarded expression (the base of an even power, the argument of `abs`
    /// or `sqrt`, a factor of a product): it is checked like a denominator (keeps its sign,
    /// does not vanish), since the guarded expression vanishes where it does, even when the
    /// expression itself does not change sign. Reported under `kind` and `text`.
    pub factor: bool,
    /// Whether the "vanishes" rule (the quadratic through the three samples stays clear of
    /// zero) applies: to the irreducible factors only, which are usually linear or quadratic
    /// along a step, where the quadratic is exact (a product such as `q^3` would be fitted
    /// badly, its factor `q` exactly).
    pub touch: bool,
}

/// At most this many factors of one guarded expression are guarded separately.
const MAX_FACTORS: usize = 64;

struct SliceLoop {
    param: u32,
    /// Scope depth of the loop body; bindings below it are outer.
    depth: usize,
    /// Accumulated contributions per outer variable.
    contributions: Vec<(String, Id)>,
}

/// The optimal string alignment distance: insertions, deletions, substitutions and swaps of
/// neighbouring characters, one each.
fn edit_distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

/// Lowers statements into the graph.
pub struct Lower<'a> {
    pub g: &'a mut Graph,
    sig: &'a Signature,
    scopes: Vec<HashMap<String, Binding>>,
    slice: Option<SliceLoop>,
    /// The errors of the body, checked by the pipeline once the body is lowered.
    pub errors: ErrorContext,
    /// Guarded expressions that depend on the jet, in order of appearance, deduplicated.
    pub guards: Vec<Guard>,
    unrolled: usize,
    /// Whether "loop too long to unroll" was reported (once, not per outer iteration).
    too_long: bool,
    /// Whether a `powf` exponent that depends on the jet was reported (once per expansion,
    /// not per call: a chain of such calls is one mistake).
    variable_powf: bool,
    /// The components of the local arrays ([`Binding::Array`]).
    arrays: Vec<Vec<Id>>,
    /// The helper functions defined in the body, by name.
    helpers: HashMap<String, syn::ItemFn>,
    /// The helpers being inlined, innermost last.
    inlining: Vec<String>,
    /// The depth of expression nesting being lowered, and whether [`MAX_NESTING`] was
    /// reported.
    nesting: (usize, bool),
    /// Whether each node depends on the jet, where decided ([`Self::depends_on_jet`]).
    jet_memo: Vec<Option<bool>>,
    /// Helper calls inlined so far (every call is inlined; capped by
    /// `values::MAX_INLINED`), and whether the cap was reported.
    inlined: (usize, bool),
    /// Names are looked up in `scopes[barrier..]` only: inside a helper, its own scopes.
    barrier: usize,
    /// The named outputs (`#[output] let`), in order.
    pub outputs: Vec<Output>,
    /// Whether the statement being lowered is at the top level of the body.
    top_level: bool,
}

impl Drop for Lower<'_> {
    /// The lowering is over: the graph folds freely again (the derivatives).
    fn drop(&mut self) {
        self.g.keep_domain = false;
    }
}

impl<'a> Lower<'a> {
    /// A lowering context with the arguments of `sig` in scope.
    pub fn new(g: &'a mut Graph, sig: &'a Signature) -> Self {
        // folds keep the user's function where it is not finite until the lowering ends
        g.keep_domain = true;
        let mut top = HashMap::new();
        for (position, name) in sig.jet.iter().enumerate() {
            // a map's (q, v) is the 2n-dimensional point (q, v) of order 0
            let binding = match sig.attribute {
                Attribute::Map => Binding::Jet {
                    order: 0,
                    offset: (position * sig.dim) as u32,
                },
                _ => Binding::Jet {
                    order: position as u8,
                    offset: 0,
                },
            };
            top.insert(name.to_string(), binding);
        }
        for (i, p) in sig.params.iter().enumerate() {
            top.insert(
                p.name.to_string(),
                Binding::Param {
                    param: i as u32,
                    kind: p.kind,
                },
            );
        }
        Self {
            g,
            sig,
            scopes: vec![top],
            slice: None,
            errors: ErrorContext::new(),
            guards: Vec::new(),
            unrolled: 0,
            too_long: false,
            variable_powf: false,
            arrays: Vec::new(),
            helpers: HashMap::new(),
            inlining: Vec::new(),
            inlined: (0, false),
            nesting: (0, false),
            jet_memo: Vec::new(),
            barrier: 0,
            outputs: Vec::new(),
            top_level: false,
        }
    }

    /// Records an error; messages name a Lagrangian, reworded for `#[jet_function]`.
    fn error(&mut self, span: Span, msg: impl Into<String>) -> Id {
        let msg = self.sig.attribute.reword(msg.into());
        self.errors.error(span, msg);
        self.g.constant(0.0)
    }

    /// ` (did you mean `x`?)` for the name in scope closest to `name` (at most two edits, a
    /// swap of neighbours counting one, and fewer than its length), else nothing.
    fn suggestion(&self, name: &str) -> String {
        self.scopes
            .iter()
            .flat_map(|scope| scope.keys())
            .map(|candidate| (edit_distance(name, candidate), candidate))
            .filter(|&(d, _)| d <= 2 && d < name.chars().count())
            .min()
            .map(|(_, candidate)| format!(" (did you mean `{candidate}`?)"))
            .unwrap_or_default()
    }

    fn lookup(&self, name: &str) -> Option<(usize, Binding)> {
        self.scopes
            .iter()
            .enumerate()
            .skip(self.barrier)
            .rev()
            .find_map(|(depth, s)| s.get(name).map(|b| (depth, *b)))
    }

    fn bind(&mut self, name: String, binding: Binding) {
        if let Some(scope) = self.scopes.last_mut() {
            scope.insert(name, binding);
        }
    }

    /// The whole function body: statements, then the tail expression.
    pub fn body(&mut self, block: &Block) -> Id {
        let Some((last, init)) = block.stmts.split_last() else {
            return self.error(
                block.span(),
                "the Lagrangian body is empty: return an f64 expression",
            );
        };
        self.register_helpers(&block.stmts);
        for stmt in init {
            self.top_level = true;
            self.stmt(stmt);
            self.top_level = false;
            if let Stmt::Local(local) = stmt
                && outputs::is_output(local)
            {
                self.record_output(local);
            }
        }
        match last {
            Stmt::Expr(e, None) => self.expr(e),
            Stmt::Expr(Expr::Return(r), _) => match &r.expr {
                Some(e) => self.expr(e),
                None => self.error(r.span(), "`return` needs the value of the Lagrangian"),
            },
            other => {
                self.stmt(other);
                self.error(
                    other.span(),
                    "the body must end with the value of the Lagrangian (an expression without `;`)",
                )
            }
        }
    }

    /// The whole body of a jet function returning `[f64; m]`: statements, then the tail, an
    /// array of `m` numbers (a literal, a local array or a helper's result); `m` placeholders
    /// where it is in error (the errors are in `self.errors`).
    pub fn vector_body(&mut self, block: &Block, m: usize) -> Vec<Id> {
        let Some((last, init)) = block.stmts.split_last() else {
            let msg = format!("the body is empty: return an array of {m} f64 expressions");
            return vec![self.error(block.span(), msg); m];
        };
        self.statements(init);
        let tail = match last {
            Stmt::Expr(Expr::Return(r), _) => r.expr.as_deref(),
            Stmt::Expr(e, None) => Some(e),
            _ => None,
        };
        let Some(tail) = tail else {
            let msg = format!(
                "the body must end with the function's value, an array of {m} f64 expressions \
                 (without `;`)"
            );
            return vec![self.error(last.span(), msg); m];
        };
        match self.value(tail) {
            values::Value::Array(ids) if ids.len() == m => ids,
            values::Value::Array(ids) => {
                let msg = format!(
                    "the value has {} components, but the return type `[f64; {m}]` has {m}",
                    ids.len()
                );
                vec![self.error(tail.span(), msg); m]
            }
            _ => {
                let msg = format!("the value must be an array of {m} f64 expressions");
                vec![self.error(tail.span(), msg); m]
            }
        }
    }

    /// Statements before the tail expression of a body (for a body whose tail is not one
    /// value: the points of a discretization map).
    pub fn statements(&mut self, stmts: &[Stmt]) {
        self.register_helpers(stmts);
        for stmt in stmts {
            self.stmt(stmt);
        }
    }

    fn block(&mut self, block: &Block) {
        let top_level = std::mem::replace(&mut self.top_level, false);
        self.scopes.push(HashMap::new());
        self.register_helpers(&block.stmts);
        for stmt in &block.stmts {
            match stmt {
                Stmt::Expr(e, None) if !matches!(e, Expr::ForLoop(_)) => {
                    self.error(
                        e.span(),
                        "a loop body must not produce a value: end it with `;`",
                    );
                }
                _ => self.stmt(stmt),
            }
        }
        self.scopes.pop();
        self.top_level = top_level;
    }

    fn stmt(&mut self, stmt: &Stmt) {
        match stmt {
            Stmt::Local(local) => {
                if outputs::is_output(local) && !self.top_level {
                    self.error(
                        local.span(),
                        "a named output is a `let` at the top level of the body, outside \
                         loops and helpers",
                    );
                }
                let before = self.errors.len();
                let value = match &local.init {
                    Some(init) if init.diverge.is_none() => Some(self.value(&init.expr)),
                    Some(init) => {
                        self.error(init.expr.span(), "`let ... else` is not supported");
                        None
                    }
                    None => {
                        self.error(local.span(), "a `let` needs an initial value");
                        None
                    }
                };
                let value = value.filter(|_| self.errors.len() == before);
                self.bind_pattern(&local.pat, value);
            }
            Stmt::Item(syn::Item::Const(c)) => {
                let name = c.ident.to_string();
                match &*c.ty {
                    syn::Type::Path(p) if p.path.is_ident("f64") => {
                        let id = self.expr(&c.expr);
                        if self.g.as_const(id).is_none() && self.errors.is_empty() {
                            self.error(c.expr.span(), "a `const` must have a constant value");
                        }
                        self.bind(name, Binding::Value { id, mutable: false });
                    }
                    _ => match self.int(&c.expr) {
                        Some(v) => self.bind(name, Binding::Int(v)),
                        None => {
                            self.bind(name, Binding::Int(0));
                        }
                    },
                }
            }
            // (registered when its block began)
            Stmt::Item(syn::Item::Fn(_)) => {}
            Stmt::Item(item) => {
                self.error(
                    item.span(),
                    "items inside a Lagrangian are not supported, except `const` values and \
                     helper `fn`s",
                );
            }
            Stmt::Macro(m) => {
                self.error(m.span(), "macros are not supported inside a Lagrangian");
            }
            Stmt::Expr(e, _) => self.effect(e),
        }
    }

    /// An expression statement: assignment, compound assignment or a `for` loop.
    fn effect(&mut self, e: &Expr) {
        match e {
            Expr::Assign(a) => {
                let value = self.expr(&a.right);
                self.assign(&a.left, None, value, &a.right);
            }
            Expr::Binary(b) if is_assign_op(&b.op) => {
                let value = self.expr(&b.right);
                self.assign(&b.left, Some(b.op), value, &b.right);
            }
            Expr::ForLoop(f) => self.for_loop(f),
            other => {
                self.unsupported(other);
            }
        }
    }

    fn assign(&mut self, target: &Expr, op: Option<BinOp>, value: Id, value_expr: &Expr) {
        let Expr::Path(p) = target else {
            self.error(
                target.span(),
                "only local `let mut` variables can be assigned",
            );
            return;
        };
        let Some(ident) = p.path.get_ident() else {
            self.error(
                target.span(),
                "only local `let mut` variables can be assigned",
            );
            return;
        };
        let name = ident.to_string();
        let Some((depth, Binding::Value { id: old, mutable })) = self.lookup(&name) else {
            self.error(
                ident.span(),
                format!(
                    "`{name}` is not a local variable: only `let mut` bindings can be assigned"
                ),
            );
            return;
        };
        if !mutable {
            self.error(
                ident.span(),
                format!("`{name}` is not mutable: declare it with `let mut`"),
            );
            return;
        }
        if let Some(slice) = &self.slice
            && depth < slice.depth
        {
            let sign = match op {
                Some(BinOp::AddAssign(_)) => 1.0,
                Some(BinOp::SubAssign(_)) => -1.0,
                _ => {
                    self.error(
                        target.span(),
                        format!(
                            "inside a loop over a slice parameter `{name}` can only be \
                             accumulated with `+=` or `-=` (the loop is a run-time sum)"
                        ),
                    );
                    return;
                }
            };
            let signed = if sign < 0.0 { self.g.neg(value) } else { value };
            let g = &mut *self.g;
            if let Some(slice) = &mut self.slice {
                match slice.contributions.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, acc)) => *acc = g.add_op(*acc, signed),
                    None => slice.contributions.push((name, signed)),
                }
            }
            return;
        }
        let new = match op {
            None => value,
            Some(BinOp::AddAssign(_)) => self.g.add_op(old, value),
            Some(BinOp::SubAssign(_)) => self.g.sub(old, value),
            Some(BinOp::MulAssign(_)) => self.g.mul(old, value),
            Some(BinOp::DivAssign(_)) => {
                self.guard(GuardKind::Denominator, value, value_expr);
                self.g.div(old, value)
            }
            Some(other) => {
                self.error(
                    other.span(),
                    "unsupported compound assignment; supported: =, +=, -=, *=, /=",
                );
                return;
            }
        };
        for scope in self.scopes.iter_mut().rev() {
            if let Some(b) = scope.get_mut(&name) {
                *b = Binding::Value {
                    id: new,
                    mutable: true,
                };
                break;
            }
        }
    }

    fn for_loop(&mut self, f: &syn::ExprForLoop) {
        if f.label.is_some() {
            self.error(f.span(), "loop labels are not supported");
            return;
        }
        let var = match &*f.pat {
            Pat::Ident(p) if p.by_ref.is_none() && p.mutability.is_none() => {
                Some(p.ident.to_string())
            }
            Pat::Wild(_) => None,
            other => {
                self.error(other.span(), "unsupported loop pattern: use a plain name");
                return;
            }
        };
        match &*f.expr {
            Expr::Range(r) => {
                let start = match &r.start {
                    Some(s) => self.int(s),
                    None => Some(0),
                };
                let Some(end) = r.end.as_ref().and_then(|e| self.int(e)) else {
                    if r.end.is_none() {
                        self.error(r.span(), "the range of a `for` loop needs an end");
                    }
                    return;
                };
                let Some(start) = start else { return };
                // in i128, so that neither `end + 1` nor `end - start` overflows at the ends
                // of i64; the unrolled work is counted with checked arithmetic
                let end = match r.limits {
                    syn::RangeLimits::HalfOpen(_) => i128::from(end),
                    syn::RangeLimits::Closed(_) => i128::from(end) + 1,
                };
                let count = (end - i128::from(start)).max(0);
                let iterations = usize::try_from(count).ok();
                let total = iterations
                    .and_then(|count| count.checked_mul(f.body.stmts.len().max(1)))
                    .and_then(|work| work.checked_add(self.unrolled))
                    .filter(|&total| total <= MAX_UNROLLED);
                let (Some(iterations), Some(total)) = (iterations, total) else {
                    if !self.too_long {
                        self.too_long = true;
                        // at the bound (on stable, the span of a range is its first token)
                        let span = r.end.as_ref().map_or(r.span(), |end| end.span());
                        self.error(
                            span,
                            format!(
                                "loop too long to unroll at compile time: {count} iterations, \
                                 but at most {MAX_UNROLLED} statements are unrolled in all the \
                                 loops of a Lagrangian; a long sum over data is a loop over a \
                                 slice parameter `&[[f64; N]]` (a run-time loop)"
                            ),
                        );
                    }
                    return;
                };
                self.unrolled = total;
                // `count` iterations from `start`, each index in i64 (it is below `end`)
                for i in (start..=i64::MAX).take(iterations) {
                    self.scopes.push(HashMap::new());
                    if let Some(v) = &var {
                        self.bind(v.clone(), Binding::Int(i));
                    }
                    self.block(&f.body);
                    self.scopes.pop();
                }
            }
            iterable => self.slice_loop(f, var, iterable),
        }
    }

    fn slice_loop(&mut self, f: &syn::ExprForLoop, var: Option<String>, iterable: &Expr) {
        let target = match iterable {
            Expr::MethodCall(m) if m.method == "iter" && m.args.is_empty() => &*m.receiver,
            Expr::Reference(r) => &*r.expr,
            other => other,
        };
        let slice = match target {
            Expr::Path(p) => p
                .path
                .get_ident()
                .and_then(|i| self.lookup(&i.to_string()))
                .and_then(|(_, b)| match b {
                    Binding::Param {
                        param,
                        kind: Kind::Slice(len),
                    } => Some((param, len)),
                    _ => None,
                }),
            _ => None,
        };
        let Some((param, len)) = slice else {
            self.error(
                iterable.span(),
                "a `for` loop must run over an integer range `a..b` (literal or const bounds) \
                 or over a slice parameter `&[[f64; N]]`",
            );
            return;
        };
        if self.slice.is_some() {
            self.error(
                iterable.span(),
                "nested loops over slice parameters are not supported",
            );
            return;
        }
        self.slice = Some(SliceLoop {
            param,
            depth: self.scopes.len(),
            contributions: Vec::new(),
        });
        self.scopes.push(HashMap::new());
        if let Some(v) = var {
            self.bind(v, Binding::Element { param, len });
        }
        self.block(&f.body);
        self.scopes.pop();
        let Some(done) = self.slice.take() else {
            return;
        };
        for (name, body) in done.contributions {
            let sum = self.g.sum(done.param, body);
            if let Some((_, Binding::Value { id, .. })) = self.lookup(&name) {
                let new = self.g.add_op(id, sum);
                for scope in self.scopes.iter_mut().rev() {
                    if let Some(b) = scope.get_mut(&name) {
                        *b = Binding::Value {
                            id: new,
                            mutable: true,
                        };
                        break;
                    }
                }
            }
        }
    }

    /// An integer expression: literal, loop variable, integer const, + - * and unary minus.
    fn int(&mut self, e: &Expr) -> Option<i64> {
        let fail = |this: &mut Self, span: Span| {
            this.error(
                span,
                "expected an integer known at compile time: a literal, a loop variable or a \
                 `const` declared in the Lagrangian",
            );
            None
        };
        let overflow = |this: &mut Self, span: Span| {
            this.error(
                span,
                "integer overflow at compile time: integers in a Lagrangian (indices, loop \
                 bounds, exponents) are computed in i64",
            );
            None
        };
        match e {
            Expr::Lit(l) => match &l.lit {
                Lit::Int(i) => i.base10_parse().ok().or_else(|| overflow(self, i.span())),
                other => fail(self, other.span()),
            },
            Expr::Paren(p) => self.int(&p.expr),
            Expr::Group(g) => self.int(&g.expr),
            Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
                // `-9223372036854775808` is i64::MIN although its digits are not an i64
                if let Expr::Lit(syn::ExprLit {
                    lit: Lit::Int(i), ..
                }) = &*u.expr
                    && let Some(v) = i
                        .base10_parse::<i128>()
                        .ok()
                        .and_then(|v| i64::try_from(-v).ok())
                {
                    return Some(v);
                }
                let v = self.int(&u.expr)?;
                v.checked_neg().or_else(|| overflow(self, u.span()))
            }
            Expr::Binary(b) => {
                let (l, r) = (self.int(&b.left)?, self.int(&b.right)?);
                match b.op {
                    BinOp::Add(_) => l.checked_add(r).or_else(|| overflow(self, b.span())),
                    BinOp::Sub(_) => l.checked_sub(r).or_else(|| overflow(self, b.span())),
                    BinOp::Mul(_) => l.checked_mul(r).or_else(|| overflow(self, b.span())),
                    _ => fail(self, b.span()),
                }
            }
            Expr::Path(p) => match p.path.get_ident().and_then(|i| self.lookup(&i.to_string())) {
                Some((_, Binding::Int(v))) => Some(v),
                _ => fail(self, p.span()),
            },
            other => fail(self, other.span()),
        }
    }

    fn unsupported(&mut self, e: &Expr) -> Id {
        let msg = match e {
            Expr::If(_) => "`if` is not supported: a Lagrangian must be smooth straight-line code \
                            (write smooth switches with tanh, abs, ...)"
                .to_string(),
            Expr::Match(_) => {
                "`match` is not supported: a Lagrangian must be straight-line code".into()
            }
            Expr::While(_) | Expr::Loop(_) => {
                "`while` and `loop` are not supported: use `for` over \
                                               an integer range or a slice parameter"
                    .into()
            }
            Expr::Closure(_) => "closures are not supported inside a Lagrangian".into(),
            Expr::Macro(_) => "macros are not supported inside a Lagrangian".into(),
            Expr::Block(_) | Expr::Unsafe(_) => {
                "blocks are not supported inside an expression".into()
            }
            Expr::ForLoop(_) => "a `for` loop is a statement, not a value".into(),
            Expr::Assign(_) => "an assignment is a statement, not a value".into(),
            Expr::Reference(_) => "references are not supported in expressions".into(),
            Expr::Field(_) => "field access is not supported: parameters are f64, [f64; N] or \
                               &[[f64; N]]"
                .into(),
            _ => format!(
                "unsupported expression `{}`; supported: f64 literals, consts, the arguments \
                 (indexed as q[i]), + - * /, unary minus, and the methods {METHODS}",
                e.to_token_stream()
            ),
        };
        self.error(e.span(), msg)
    }

    /// An f64 expression.
    pub fn expr(&mut self, e: &Expr) -> Id {
        match self.enter(e) {
            Some(refused) => refused,
            None => {
                let id = self.expr_inner(e);
                self.nesting.0 -= 1;
                id
            }
        }
    }

    /// Counts one more level of expression nesting before lowering `e`; past [`MAX_NESTING`]
    /// refuses it (`Some`, with an error reported once per expansion) instead of recursing
    /// further (deep nesting overflowed the compiler's stack).
    fn enter(&mut self, e: &Expr) -> Option<Id> {
        if self.nesting.0 >= MAX_NESTING {
            if !std::mem::replace(&mut self.nesting.1, true) {
                return Some(self.error(
                    e.span(),
                    format!(
                        "expressions nest deeper than {MAX_NESTING} levels here: bind \
                         intermediate values with `let`"
                    ),
                ));
            }
            return Some(self.g.constant(0.0));
        }
        self.nesting.0 += 1;
        None
    }

    fn expr_inner(&mut self, e: &Expr) -> Id {
        match e {
            Expr::Lit(l) => match &l.lit {
                Lit::Float(f) => match f.base10_parse::<f64>() {
                    Ok(v) => self.g.constant(v),
                    Err(err) => self.error(f.span(), err.to_string()),
                },
                Lit::Int(i) => match i.base10_parse::<f64>() {
                    Ok(v) => self.g.constant(v),
                    Err(err) => self.error(i.span(), err.to_string()),
                },
                other => self.error(other.span(), "only numeric literals are supported"),
            },
            Expr::Paren(p) => self.expr(&p.expr),
            Expr::Group(g) => self.expr(&g.expr),
            Expr::Unary(u) => match u.op {
                UnOp::Neg(_) => {
                    let a = self.expr(&u.expr);
                    self.g.neg(a)
                }
                _ => self.error(u.span(), "unsupported unary operator; supported: `-`"),
            },
            Expr::Binary(b) => self.binary_chain(b),
            Expr::Path(p) => self.path(p),
            Expr::Index(ix) => self.index(ix),
            Expr::MethodCall(m) => self.method_chain(m),
            Expr::Call(c) => self.call(c),
            Expr::Cast(c) => {
                if let Some(v) = self.int_silently(&c.expr) {
                    return self.g.constant(v as f64);
                }
                self.expr(&c.expr)
            }
            other => self.unsupported(other),
        }
    }

    fn int_silently(&mut self, e: &Expr) -> Option<i64> {
        let before = self.errors.len();
        let v = self.int(e);
        self.errors.truncate(before);
        v
    }

    fn path(&mut self, p: &syn::ExprPath) -> Id {
        if p.qself.is_some() {
            return self.error(p.span(), "qualified paths are not supported");
        }
        let Some(ident) = p.path.get_ident() else {
            // a const or static of the user's crate, by path
            let text = p.path.to_token_stream().to_string().replace(' ', "");
            return self.g.named(text);
        };
        let name = ident.to_string();
        match self.lookup(&name) {
            Some((depth, Binding::Value { id, .. })) => {
                if let Some(slice) = &self.slice
                    && depth < slice.depth
                    && slice.contributions.iter().any(|(n, _)| *n == name)
                {
                    return self.error(
                        ident.span(),
                        format!(
                            "`{name}` is being accumulated by this loop over a slice and cannot \
                             be read inside it"
                        ),
                    );
                }
                id
            }
            Some((_, Binding::Int(v))) => self.g.constant(v as f64),
            Some((_, Binding::Poisoned)) => self.g.constant(0.0),
            Some((_, Binding::Jet { order, offset })) => {
                if self.sig.scalar_jet {
                    self.g.var(Var::Jet {
                        order,
                        index: offset,
                    })
                } else {
                    self.error(
                        ident.span(),
                        format!("`{name}` is an array: use its components `{name}[i]`"),
                    )
                }
            }
            Some((_, Binding::Param { param, kind })) => match kind {
                Kind::Scalar => self.g.var(Var::Param { param, index: 0 }),
                _ => self.error(
                    ident.span(),
                    format!("`{name}` is an array: use its components `{name}[i]`"),
                ),
            },
            Some((_, Binding::Element { .. } | Binding::Array { .. })) => self.error(
                ident.span(),
                format!("`{name}` is an array: use its components `{name}[i]`"),
            ),
            None if is_const_name(&name) => self.g.named(name),
            None => {
                let hint = self.suggestion(&name);
                self.error(
                    ident.span(),
                    format!(
                        "cannot find `{name}`{hint}: a Lagrangian may use its arguments, `let` \
                         bindings, loop variables and consts (SCREAMING_CASE or by path)"
                    ),
                )
            }
        }
    }

    fn index(&mut self, ix: &syn::ExprIndex) -> Id {
        let Expr::Path(p) = &*ix.expr else {
            // a helper's result or an array literal (a helper that failed was reported)
            let before = self.errors.len();
            return match self.value(&ix.expr) {
                Value::Array(ids) => self.component(&ids, ix, "the array"),
                _ if self.errors.len() > before => self.g.constant(0.0),
                _ => self.error(ix.expr.span(), "only arrays can be indexed, as `q[i]`"),
            };
        };
        if let Some(ident) = p.path.get_ident()
            && let Some((_, Binding::Array { slot })) = self.lookup(&ident.to_string())
        {
            let ids = self.arrays[slot as usize].clone();
            return self.component(&ids, ix, &format!("`{ident}`"));
        }
        let Some(ident) = p.path.get_ident() else {
            return self.error(p.span(), "only arguments can be indexed, as `q[i]`");
        };
        let name = ident.to_string();
        let Some(i) = self.int(&ix.index) else {
            return self.g.constant(0.0);
        };
        let (len, var) = match self.lookup(&name) {
            Some((_, Binding::Jet { order, offset })) if !self.sig.scalar_jet => (
                self.sig.jet_len(order),
                Var::Jet {
                    order,
                    index: offset,
                },
            ),
            Some((
                _,
                Binding::Param {
                    param,
                    kind: Kind::Array(len),
                },
            )) => (len, Var::Param { param, index: 0 }),
            Some((_, Binding::Element { param, len })) => (len, Var::Elem { param, index: 0 }),
            None => {
                let hint = self.suggestion(&name);
                return self.error(
                    ident.span(),
                    format!("cannot find `{name}`{hint}; only array arguments can be indexed"),
                );
            }
            _ => {
                return self.error(
                    ident.span(),
                    format!("`{name}` cannot be indexed: only array arguments can, as `q[i]`"),
                );
            }
        };
        let Some(at) = usize::try_from(i).ok().filter(|&at| at < len) else {
            return self.error(
                ix.index.span(),
                format!("index {i} out of range for `{name}`, which has {len} components"),
            );
        };
        // indices are stored as u32: never truncated, larger ones are an error
        let Ok(index) = u32::try_from(at) else {
            return self.error(
                ix.index.span(),
                format!(
                    "index {i} of `{name}` is too large: indices up to {} are supported",
                    u32::MAX
                ),
            );
        };
        let var = match var {
            Var::Jet {
                order,
                index: offset,
            } => Var::Jet {
                order,
                index: offset + index,
            },
            Var::Param { param, .. } => Var::Param { param, index },
            Var::Elem { param, .. } => Var::Elem { param, index },
            other => other,
        };
        self.g.var(var)
    }

    /// Component `ix.index` (an integer known at compile time) of the array `ids`.
    fn component(&mut self, ids: &[Id], ix: &syn::ExprIndex, what: &str) -> Id {
        let Some(i) = self.int(&ix.index) else {
            return self.g.constant(0.0);
        };
        match usize::try_from(i).ok().and_then(|at| ids.get(at)) {
            Some(&id) => id,
            None => self.error(
                ix.index.span(),
                format!(
                    "index {i} out of range for {what}, which has {} components",
                    ids.len()
                ),
            ),
        }
    }

    /// `a op b op c ...`, a left-associative chain of binary operators (a long sum or
    /// product): the left spine is walked without recursion and each operator costs no level
    /// of nesting ([`MAX_NESTING`]), so a sum of many terms lowers in linear time and stack.
    /// The operands are lowered left to right, as by recursion.
    fn binary_chain(&mut self, top: &syn::ExprBinary) -> Id {
        let mut spine = vec![top];
        let mut first = &*top.left;
        while let Expr::Binary(b) = first {
            spine.push(b);
            first = &b.left;
        }
        let mut acc = self.expr(first);
        for b in spine.into_iter().rev() {
            let r = self.expr(&b.right);
            acc = self.binary(b, acc, r);
        }
        acc
    }

    /// `l op r` for the lowered operands of `b`.
    fn binary(&mut self, b: &syn::ExprBinary, l: Id, r: Id) -> Id {
        match b.op {
            BinOp::Add(_) => self.g.add_op(l, r),
            BinOp::Sub(_) => self.g.sub(l, r),
            BinOp::Mul(_) => self.g.mul(l, r),
            BinOp::Div(_) => {
                self.guard(GuardKind::Denominator, r, &b.right);
                self.g.div(l, r)
            }
            op if is_assign_op(&op) => {
                self.error(b.span(), "an assignment is a statement, not a value")
            }
            _ => self.error(
                b.op.span(),
                format!(
                    "unsupported operator `{}`; supported: + - * /",
                    b.op.to_token_stream()
                ),
            ),
        }
    }

    /// `x.f().g(y)...`, a chain of method calls (parenthesised receivers included): the
    /// receivers are walked without recursion and each call costs no level of nesting, so
    /// that a long chain lowers in linear time and stack.
    fn method_chain(&mut self, top: &syn::ExprMethodCall) -> Id {
        let mut spine = vec![top];
        let mut inner = &*top.receiver;
        loop {
            match inner {
                Expr::MethodCall(m) => {
                    spine.push(m);
                    inner = &m.receiver;
                }
                Expr::Paren(p) => inner = &p.expr,
                Expr::Group(g) => inner = &g.expr,
                _ => break,
            }
        }
        let mut x = self.expr(inner);
        for m in spine.into_iter().rev() {
            x = self.method(m, x);
        }
        x
    }

    /// The call `m` on its lowered receiver `receiver`.
    fn method(&mut self, m: &syn::ExprMethodCall, receiver: Id) -> Id {
        if m.turbofish.is_some() {
            return self.error(m.span(), "turbofish is not supported");
        }
        let name = m.method.to_string();
        let args: Vec<&Expr> = m.args.iter().collect();
        self.apply(&name, m.method.span(), m, (receiver, &m.receiver), &args)
    }

    /// `f64::sqrt(x)` and friends: the method form with the receiver as first argument.
    fn call(&mut self, c: &syn::ExprCall) -> Id {
        if let Some(f) = self.helper_of(c) {
            return match self.inline(&f, c) {
                Value::Scalar(id) => id,
                _ => self.error(
                    c.span(),
                    format!(
                        "`{}` returns an array or a tuple: bind it with `let` or index it",
                        f.sig.ident
                    ),
                ),
            };
        }
        let Expr::Path(p) = &*c.func else {
            return self.unsupported(&c.func);
        };
        if let Some(ident) = p.path.get_ident()
            && matches!(
                self.lookup(&ident.to_string()),
                Some((_, Binding::Poisoned))
            )
        {
            return self.g.constant(0.0);
        }
        let segments: Vec<String> = p
            .path
            .segments
            .iter()
            .map(|s| s.ident.to_string())
            .collect();
        if let Some(last) = segments.last()
            && (last == "smooth_max" || last == "smooth_min")
        {
            return self.smooth_extremum(last == "smooth_max", c);
        }
        if segments.last().is_some_and(|last| last == "stumpff") {
            return self.stumpff(c);
        }
        if segments.len() == 2 && segments[0] == "f64" && !c.args.is_empty() {
            let args: Vec<&Expr> = c.args.iter().collect();
            let receiver = self.expr(args[0]);
            let span = p.path.segments[1].ident.span();
            return self.apply(&segments[1], span, c, (receiver, args[0]), &args[1..]);
        }
        self.error(
            c.func.span(),
            format!(
                "call to unknown function `{}`: a Lagrangian can only call the f64 methods \
                 {METHODS} and helper functions defined in its body (`fn name(x: f64) -> f64 \
                 {{ ... }}`, inlined)",
                p.path.to_token_stream().to_string().replace(' ', "")
            ),
        )
    }

    /// `smooth_max(a, b, eps)` = (a + b + sqrt((a - b)^2 + eps^2)) / 2 and `smooth_min` with
    /// the sign of the root flipped (`retract::smooth_max`): smooth for eps != 0, within
    /// |eps| / 2 of max(a, b) (min(a, b)).
    fn smooth_extremum(&mut self, max: bool, c: &syn::ExprCall) -> Id {
        if c.args.len() != 3 {
            return self.error(
                c.span(),
                "`smooth_max` and `smooth_min` take 3 arguments: (a, b, eps)",
            );
        }
        let [a, b, eps] = [0, 1, 2].map(|i| self.expr(&c.args[i]));
        let diff = self.g.sub(a, b);
        let d2 = self.g.powi(diff, 2);
        let e2 = self.g.powi(eps, 2);
        let arg = self.g.add_op(d2, e2);
        let root = self.g.unary(Func::Sqrt, arg);
        let sum = self.g.add_op(a, b);
        let twice = if max {
            self.g.add_op(sum, root)
        } else {
            self.g.sub(sum, root)
        };
        let half = self.g.constant(0.5);
        self.g.mul(half, twice)
    }

    /// `stumpff(k, s)`: the Stumpff function c_k(s) (`retract::stumpff`) for an integer
    /// literal k <= 100; entire, so without a guard.
    fn stumpff(&mut self, c: &syn::ExprCall) -> Id {
        if c.args.len() != 2 {
            return self.error(c.span(), "`stumpff` takes 2 arguments: (k, s)");
        }
        let k = match &c.args[0] {
            Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(k),
                ..
            }) => k.base10_parse::<u8>().ok().filter(|k| *k <= 100),
            _ => None,
        };
        let Some(k) = k else {
            return self.error(
                c.args[0].span(),
                "the order k of `stumpff(k, s)` must be an integer literal from 0 to 100",
            );
        };
        let s = self.expr(&c.args[1]);
        self.g.unary(Func::Stumpff(k), s)
    }

    fn apply(
        &mut self,
        name: &str,
        name_span: Span,
        call: &dyn Spanned,
        (x, x_expr): (Id, &Expr),
        args: &[&Expr],
    ) -> Id {
        let expected = match name {
            "powi" | "powf" | "atan2" | "hypot" => 1,
            "mul_add" => 2,
            "sqrt" | "exp" | "ln" | "sin" | "cos" | "tan" | "tanh" | "recip" | "abs" | "asin"
            | "acos" | "atan" | "sinh" | "cosh" | "cbrt" | "ln_1p" | "exp_m1" | "log2"
            | "log10" => 0,
            _ => {
                return self.error(
                    name_span,
                    format!("unsupported method `{name}`; supported: {METHODS}"),
                );
            }
        };
        if args.len() != expected {
            // the span of the whole call only here: it costs the call's size
            return self.error(
                call.span(),
                format!("`{name}` takes {expected} argument(s)"),
            );
        }
        let unary = |f| Some(f);
        let func = match name {
            "sqrt" => unary(Func::Sqrt),
            "exp" => unary(Func::Exp),
            "ln" => unary(Func::Ln),
            "sin" => unary(Func::Sin),
            "cos" => unary(Func::Cos),
            "tan" => unary(Func::Tan),
            "tanh" => unary(Func::Tanh),
            "abs" => unary(Func::Abs),
            "asin" => unary(Func::Asin),
            "acos" => unary(Func::Acos),
            "atan" => unary(Func::Atan),
            "sinh" => unary(Func::Sinh),
            "cosh" => unary(Func::Cosh),
            "cbrt" => unary(Func::Cbrt),
            "ln_1p" => unary(Func::Ln1p),
            "exp_m1" => unary(Func::ExpM1),
            "log2" => unary(Func::Log2),
            "log10" => unary(Func::Log10),
            _ => None,
        };
        if let Some(f) = func {
            self.guard_function(f, x, x_expr);
            return self.g.unary(f, x);
        }
        match name {
            "mul_add" => {
                // x * a + b
                let (a, b) = (self.expr(args[0]), self.expr(args[1]));
                let product = self.g.mul(x, a);
                self.g.add_op(product, b)
            }
            "recip" => {
                self.guard(GuardKind::Denominator, x, x_expr);
                let one = self.g.constant(1.0);
                self.g.div(one, x)
            }
            "powi" => match self.int(args[0]) {
                Some(n) if i32::try_from(n).is_ok() => {
                    if n < 0 {
                        // x^-m = 1 / x^m
                        self.guard(GuardKind::Denominator, x, x_expr);
                    }
                    self.g.powi(x, n as i32)
                }
                Some(_) => self.error(args[0].span(), "exponent out of range for powi"),
                None => self.g.constant(0.0),
            },
            "powf" => {
                let e = self.expr(args[0]);
                if self.depends_on_jet(e) {
                    if self.variable_powf {
                        return self.g.constant(0.0);
                    }
                    self.variable_powf = true;
                    return self.error(
                        args[0].span(),
                        "the exponent of `powf` must not depend on the jet (q, q', ...): write \
                         `(b * a.ln()).exp()` for a variable exponent (reported at the first \
                         such call only)",
                    );
                }
                match self.g.as_const(e) {
                    // an integer power: singular at 0 only when negative
                    Some(v) if v.fract() == 0.0 => {
                        if v < 0.0 {
                            self.guard(GuardKind::Denominator, x, x_expr);
                        }
                    }
                    _ => self.guard(GuardKind::PowfBase, x, x_expr),
                }
                self.g.powf(x, e)
            }
            // "atan2" | "hypot"
            _ => {
                let other = self.expr(args[0]);
                // both are singular (in their derivatives) where both arguments vanish: the
                // denominator of d atan2 and d hypot is x^2 + y^2
                let (sx, so) = (self.g.powi(x, 2), self.g.powi(other, 2));
                let squares = self.g.add_op(sx, so);
                let text = format!("{}.hypot({})", atom_text(x_expr), text_of(args[0]));
                self.guard_text(GuardKind::Denominator, squares, text);
                if name == "atan2" {
                    self.g.atan2(x, other)
                } else {
                    self.g.hypot(x, other)
                }
            }
        }
    }

    /// The guard of the function `f` of `x` (written as `x_expr`): sqrt needs x >= 0; ln, log2
    /// and log10 x > 0; ln_1p 1 + x > 0; asin and acos 1 - x^2 > 0; tan a nonzero cos(x);
    /// cbrt (whose derivative is singular at 0) a nonzero x. The others are entire.
    fn guard_function(&mut self, f: Func, x: Id, x_expr: &Expr) {
        match f {
            Func::Sqrt => self.guard(GuardKind::SqrtArgument, x, x_expr),
            Func::Ln | Func::Log2 | Func::Log10 => self.guard(GuardKind::LnArgument, x, x_expr),
            Func::Cbrt => self.guard(GuardKind::Denominator, x, x_expr),
            Func::Ln1p => {
                let one = self.g.constant(1.0);
                let arg = self.g.add_op(one, x);
                let text = format!("1 + ({})", text_of(x_expr));
                self.guard_text(GuardKind::LnArgument, arg, text);
            }
            Func::Asin | Func::Acos => {
                let one = self.g.constant(1.0);
                let sq = self.g.powi(x, 2);
                let arg = self.g.sub(one, sq);
                self.guard_text(GuardKind::AsinArgument, arg, text_of(x_expr));
            }
            Func::Tan => {
                // tan = sin / cos: singular where cos(x) = 0
                let cos = self.g.unary(Func::Cos, x);
                if self.depends_on_jet(cos) {
                    let text = format!("{}.cos()", atom_text(x_expr));
                    self.guard_text(GuardKind::Denominator, cos, text);
                }
            }
            _ => {}
        }
    }

    /// Records `node` (written as `expr`) as a guarded expression if it depends on the jet.
    fn guard(&mut self, kind: GuardKind, node: Id, expr: &Expr) {
        if self.depends_on_jet(node) {
            self.guard_text(kind, node, text_of(expr));
        }
    }

    /// Records `node` (described by `text`) and its factors as guarded expressions.
    fn guard_text(&mut self, kind: GuardKind, node: Id, text: String) {
        if !self.depends_on_jet(node) {
            return;
        }
        let factors = zero_factors(self.g, node);
        if factors.len() > MAX_FACTORS || factors == [node] {
            self.push_guard(kind, node, text, (false, true));
            return;
        }
        self.push_guard(kind, node, text.clone(), (false, false));
        for f in factors {
            if self.depends_on_jet(f) {
                self.push_guard(kind, f, text.clone(), (true, true));
            }
        }
    }

    /// Records one guarded node; `(factor, touch)` as in [`Guard`].
    fn push_guard(
        &mut self,
        kind: GuardKind,
        node: Id,
        text: String,
        (factor, touch): (bool, bool),
    ) {
        if self
            .guards
            .iter()
            .any(|g| g.node == node && g.kind == kind && g.factor == factor)
        {
            return;
        }
        let slice = self
            .slice
            .as_ref()
            .map(|s| s.param)
            .filter(|_| self.depends_on_element(node));
        self.guards.push(Guard {
            kind,
            node,
            text,
            slice,
            factor,
            touch,
        });
    }

    /// Whether `id` depends on a loop element (not counting elements bound inside a sum).
    fn depends_on_element(&self, id: Id) -> bool {
        self.reaches(id, |v| matches!(v, Var::Elem { .. }), false)
    }

    /// Whether `id` depends on the jet (inside sums too), memoised per node in `jet_memo` (a
    /// walk per guarded node made nested guards quadratic in the depth).
    fn depends_on_jet(&mut self, id: Id) -> bool {
        if self.jet_memo.len() < self.g.len() {
            self.jet_memo.resize(self.g.len(), None);
        }
        // post-order without recursion: a node is decided once its children are
        let mut stack = vec![(id, false)];
        while let Some((n, children_done)) = stack.pop() {
            if self.jet_memo[n.0 as usize].is_some() {
                continue;
            }
            let node = self.g.node(n);
            let children = crate::ir::graph::children(node);
            if let Node::Var(v) = node {
                self.jet_memo[n.0 as usize] = Some(matches!(v, Var::Jet { .. }));
            } else if children_done {
                let any = children
                    .iter()
                    .any(|c| self.jet_memo[c.0 as usize] == Some(true));
                self.jet_memo[n.0 as usize] = Some(any);
            } else {
                stack.push((n, true));
                stack.extend(children.into_iter().map(|c| (c, false)));
            }
        }
        self.jet_memo[id.0 as usize] == Some(true)
    }

    /// Whether a variable with `target` is reachable from `id`; `into_sums`: whether to look
    /// inside the bodies of sums.
    fn reaches(&self, id: Id, target: impl Fn(&Var) -> bool, into_sums: bool) -> bool {
        let mut stack = vec![id];
        let mut seen = std::collections::HashSet::new();
        while let Some(n) = stack.pop() {
            if !seen.insert(n) {
                continue;
            }
            match self.g.node(n) {
                Node::Var(v) if target(v) => return true,
                Node::Sum { .. } if !into_sums => {}
                node => stack.extend(crate::ir::graph::children(node)),
            }
        }
        false
    }
}

fn is_assign_op(op: &BinOp) -> bool {
    matches!(
        op,
        BinOp::AddAssign(_)
            | BinOp::SubAssign(_)
            | BinOp::MulAssign(_)
            | BinOp::DivAssign(_)
            | BinOp::RemAssign(_)
            | BinOp::BitXorAssign(_)
            | BinOp::BitAndAssign(_)
            | BinOp::BitOrAssign(_)
            | BinOp::ShlAssign(_)
            | BinOp::ShrAssign(_)
    )
}

/// SCREAMING_CASE names are consts of the user's crate.
fn is_const_name(name: &str) -> bool {
    name.chars().any(|c| c.is_ascii_uppercase())
        && name
            .chars()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_')
}

/// Expressions of at most this many nodes are quoted in full in the guards' messages; larger
/// ones with their operands elided, so that a guard's text costs constant time and nested
/// guards (a chain of `atan2`) emit text linear, not quadratic, in the depth.
const QUOTED_NODES: usize = 48;

/// `expr` as written, without enclosing parentheses; elided past [`QUOTED_NODES`] nodes (as
/// `(…).sin()`, `… + …`, `f64::atan2(…)`).
fn text_of(mut expr: &Expr) -> String {
    while let Expr::Paren(p) = expr {
        expr = &p.expr;
    }
    if has_at_most(expr, QUOTED_NODES) {
        return tidy(&expr.to_token_stream().to_string());
    }
    match expr {
        Expr::MethodCall(m) if m.args.is_empty() => format!("(…).{}()", m.method),
        Expr::MethodCall(m) => format!("(…).{}(…)", m.method),
        Expr::Binary(b) => format!("… {} …", b.op.to_token_stream()),
        Expr::Unary(_) => "-(…)".to_string(),
        Expr::Call(c) if has_at_most(&c.func, QUOTED_NODES) => {
            format!("{}(…)", tidy(&c.func.to_token_stream().to_string()))
        }
        _ => "…".to_string(),
    }
}

/// Whether `expr` has at most `budget` expression nodes, counted without recursion and
/// stopping past the budget (constant time for a large expression).
fn has_at_most(expr: &Expr, budget: usize) -> bool {
    let mut stack = vec![expr];
    let mut count = 0;
    while let Some(e) = stack.pop() {
        count += 1;
        if count > budget {
            return false;
        }
        match e {
            Expr::Binary(b) => stack.extend([&*b.left, &*b.right]),
            Expr::Unary(u) => stack.push(&u.expr),
            Expr::Paren(p) => stack.push(&p.expr),
            Expr::Group(g) => stack.push(&g.expr),
            Expr::Cast(c) => stack.push(&c.expr),
            Expr::Index(i) => stack.extend([&*i.expr, &*i.index]),
            Expr::MethodCall(m) => {
                stack.push(&m.receiver);
                stack.extend(m.args.iter());
            }
            Expr::Call(c) => {
                stack.push(&c.func);
                stack.extend(c.args.iter());
            }
            Expr::Lit(_) | Expr::Path(_) => {}
            // anything else (an error elsewhere) counts as the whole budget
            _ => count = budget,
        }
    }
    true
}

/// `expr` as the receiver of a method call: parenthesised unless it is an atom.
fn atom_text(expr: &Expr) -> String {
    let text = text_of(expr);
    match expr {
        Expr::Path(_) | Expr::Index(_) | Expr::MethodCall(_) | Expr::Call(_) | Expr::Field(_) => {
            text
        }
        Expr::Lit(_) | Expr::Paren(_) if !text.starts_with('-') => text,
        _ => format!("({text})"),
    }
}

/// The factors of `node` whose zeros are zeros of `node`: through products, quotients
/// (numerators), negation, positive powers, `abs`, `sqrt` and `powf`; `hypot(a, b)` as
/// `a^2 + b^2`; `exp` and negative powers never vanish. Anything else is its own factor.
fn zero_factors(g: &mut Graph, node: Id) -> Vec<Id> {
    let mut out = Vec::new();
    let mut stack = vec![node];
    while let Some(id) = stack.pop() {
        if out.len() > MAX_FACTORS {
            break;
        }
        match *g.node(id) {
            Node::Mul(a, b) => stack.extend([b, a]),
            Node::Div(a, _)
            | Node::Neg(a)
            | Node::Unary(Func::Abs | Func::Sqrt, a)
            | Node::Powf(a, _) => stack.push(a),
            Node::Powi(a, n) if n > 0 => stack.push(a),
            Node::Powi(..) | Node::Unary(Func::Exp, _) | Node::Const(_) => {}
            Node::Hypot(a, b) => {
                let (sa, sb) = (g.powi(a, 2), g.powi(b, 2));
                out.push(g.add_op(sa, sb));
            }
            _ => out.push(id),
        }
    }
    out.dedup();
    out
}
