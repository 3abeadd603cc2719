//! Straight-line Rust from graph nodes.
//!
//! For a set of roots, every needed non-leaf node that is used more than once becomes one
//! `let __tN: f64 = ...;` in id order (children first), so each shared subexpression is
//! computed once; a node used once is inlined, parenthesised, into its parent. Leaves (symbols,
//! constants, named consts) are inlined. A [`Node::Sum`] becomes a run-time loop over its
//! slice parameter; the nodes of its body that depend on the loop element are emitted inside
//! the loop, the others are hoisted before it.
//!
//! Chains of one operation through inlined nodes (`a * b * c`, `a - b + c`) are emitted as
//! balanced trees that combine the earliest available operands first (tree-height reduction
//! on an estimate of each value's latency), so a long chain does not wait on its slowest
//! operand at every step: `h * (t * (y * r))` with `r = 1/s` known last becomes
//! `(y * (h * t)) * r`. This reassociates floating-point operations, which changes results
//! in the last bits only. Each chain is collected once, from its head, and balanced with a
//! binary heap: O(m log m) for m operands, so that a sum of 10 000 terms costs no more per
//! term than a short one (the cost was cubic: a balancing per node of the chain, each a
//! linear search per merge).
//!
//! The emitted code nests at most [`MAX_DEPTH`] + 2 levels (parentheses, operators, calls):
//! an inlined node that would nest deeper is bound to its `let` instead, and a chain whose
//! balanced tree would is cut into `let __cN` temporaries (which changes no operation), so
//! that 1000 chained `let`s or a recurrence unrolled 10 000 times compile (rustc's parser
//! overflows its stack on a few thousand nested parentheses). Long code is grouped into
//! blocks (`scopes`) so that the `let`s do not nest thousands of scopes deep either.

use std::cell::{Cell, RefCell};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::emit::scopes::bounded_scopes;
use crate::ir::graph::{Func, Graph, Id, Node, Var, children};
use crate::util::core_path;

/// How a function names the leaves: symbol -> expression tokens.
pub trait Leaves {
    /// The expression for a symbol.
    fn var(&self, var: Var) -> TokenStream;
    /// The slice parameter `param` to loop over, e.g. `self.obstacles`.
    fn slice(&self, param: u32) -> TokenStream;
    /// The loop variable of the element of `param`.
    fn element(&self) -> TokenStream {
        quote!(__e)
    }
}

/// Straight-line code for some roots: `stmts`, after which `roots[i]` evaluates as `exprs[i]`.
pub struct Emitted {
    pub stmts: TokenStream,
    pub exprs: Vec<TokenStream>,
}

fn temp(id: Id) -> TokenStream {
    let ident = format_ident!("__t{}", id.0);
    quote!(#ident)
}

/// A constant as tokens: a suffixed literal, or the `f64` constant for NaN and infinities.
pub(crate) fn constant(value: f64) -> TokenStream {
    if value.is_nan() {
        quote!(::core::f64::NAN)
    } else if value.is_infinite() {
        if value > 0.0 {
            quote!(::core::f64::INFINITY)
        } else {
            quote!(::core::f64::NEG_INFINITY)
        }
    } else {
        let lit = Literal::f64_suffixed(value.abs());
        if value.is_sign_negative() {
            quote!((-#lit))
        } else {
            quote!(#lit)
        }
    }
}

fn is_leaf(node: &Node) -> bool {
    matches!(node, Node::Const(_) | Node::Var(_) | Node::Named(_))
}

/// Emits the roots.
pub fn emit(g: &Graph, roots: &[Id], leaves: &dyn Leaves) -> Emitted {
    let len = g.len();
    let placement = placement(g, roots);
    let inline = inlined(g, roots, &placement);
    let reciprocal = reciprocals(g, &placement.top);
    let mut emitter = Emitter {
        g,
        leaves,
        inline,
        reciprocal: &reciprocal,
        latency: vec![0; len],
        depth: vec![0; len],
        pending: RefCell::new(TokenStream::new()),
        cuts: Cell::new(0),
    };
    // the nodes emitted at function level or in a loop (the graph holds others)
    let mut emitted = placement.top.clone();
    for marks in placement.body_of.iter().filter(|m| !m.is_empty()) {
        for (e, &m) in emitted.iter_mut().zip(marks) {
            *e |= m;
        }
    }
    emitter.plan(&emitted);
    let emitter = emitter;
    let mut stmts = emitter.statements(&placement);
    let exprs = roots.iter().map(|&r| emitter.reference(r, false)).collect();
    stmts.extend(emitter.take_pending());
    Emitted {
        stmts: bounded_scopes(stmts),
        exprs,
    }
}

/// Where the nodes needed by some roots are emitted.
struct Placement {
    /// At function level.
    top: Vec<bool>,
    /// For a sum, the nodes of its loop body that depend on the loop element, emitted inside
    /// the loop (empty for other nodes).
    body_of: Vec<Vec<bool>>,
}

/// The nodes needed by `roots`, each at function level or inside the loop of a sum (the
/// nodes of a sum's body that depend on its element).
fn placement(g: &Graph, roots: &[Id]) -> Placement {
    let len = g.len();
    // depends on a loop element (a Sum binds its element, so it does not)
    let mut inner = vec![false; len];
    for i in 0..len {
        let node = g.node(Id(i as u32));
        inner[i] = match node {
            Node::Var(Var::Elem { .. }) => true,
            Node::Sum { .. } => false,
            n => children(n).iter().any(|c| inner[c.0 as usize]),
        };
    }
    // top[i]: emitted at function level; body_of[s]: inner nodes of the loop of sum s
    let mut top = vec![false; len];
    let mut body_of: Vec<Vec<bool>> = vec![Vec::new(); len];
    let mut stack: Vec<(Id, Option<Id>)> = roots.iter().map(|&r| (r, None)).collect();
    while let Some((id, sum)) = stack.pop() {
        let i = id.0 as usize;
        let node = g.node(id);
        let in_loop = match sum {
            Some(s) if inner[i] => Some(s),
            _ => None,
        };
        match in_loop {
            Some(s) => {
                let marks = &mut body_of[s.0 as usize];
                if marks.is_empty() {
                    marks.resize(len, false);
                }
                if marks[i] {
                    continue;
                }
                marks[i] = true;
            }
            None => {
                if top[i] {
                    continue;
                }
                top[i] = true;
            }
        }
        match node {
            Node::Sum { body, .. } => stack.push((*body, Some(id))),
            n => stack.extend(children(n).into_iter().map(|c| (c, in_loop))),
        }
    }
    Placement { top, body_of }
}

/// The function-level nodes inlined into their parent: a non-leaf used once, not a root and
/// not used from inside a loop.
fn inlined(g: &Graph, roots: &[Id], placement: &Placement) -> Vec<bool> {
    let Placement { top, body_of } = placement;
    let len = g.len();
    // use counts at function level: a node used once (and not from inside a loop) is inlined
    // into its parent instead of getting a `let`
    let mut uses = vec![0usize; len];
    let mut pinned = vec![false; len];
    for i in 0..len {
        let node = g.node(Id(i as u32));
        if top[i] && !is_leaf(node) {
            match node {
                Node::Sum { .. } => {
                    pinned[i] = true;
                    for (j, &m) in body_of[i].iter().enumerate() {
                        if m {
                            for c in children(g.node(Id(j as u32))) {
                                if top[c.0 as usize] {
                                    pinned[c.0 as usize] = true;
                                }
                            }
                        }
                    }
                    if let Node::Sum { body, .. } = node
                        && top[body.0 as usize]
                    {
                        pinned[body.0 as usize] = true;
                    }
                }
                n => {
                    for c in children(n) {
                        uses[c.0 as usize] += 1;
                    }
                }
            }
        }
    }
    for r in roots {
        uses[r.0 as usize] += 2; // roots are always bound
    }
    (0..len)
        .map(|i| top[i] && uses[i] == 1 && !pinned[i] && !is_leaf(g.node(Id(i as u32))))
        .collect()
}

/// The denominators shared by several function-level divisions: each is inverted once,
/// `let __rN = 1.0 / b;`, and each `a / b` becomes `a * __rN`.
fn reciprocals(g: &Graph, top: &[bool]) -> Vec<bool> {
    let mut denominators = vec![0usize; g.len()];
    for (i, _) in top.iter().enumerate().filter(|(_, t)| **t) {
        if let Node::Div(_, b) = g.node(Id(i as u32)) {
            denominators[b.0 as usize] += 1;
        }
    }
    denominators.iter().map(|&n| n >= 2).collect()
}

/// The temporary holding `1.0 / node`.
fn reciprocal_name(id: Id) -> TokenStream {
    let ident = format_ident!("__r{}", id.0);
    quote!(#ident)
}

/// Expression tokens of nodes, with single-use nodes inlined.
struct Emitter<'a> {
    g: &'a Graph,
    leaves: &'a dyn Leaves,
    /// Nodes inlined into their only parent ([`Emitter::plan`] binds those that would nest
    /// deeper than [`MAX_DEPTH`]).
    inline: Vec<bool>,
    /// Denominators bound once as a reciprocal (function level only).
    reciprocal: &'a [bool],
    /// Estimated cycles from the function's inputs to each node's value.
    latency: Vec<u32>,
    /// Nesting depth of each node's value as emitted (see [`MAX_DEPTH`]).
    depth: Vec<u32>,
    /// `let`s of the parts of long chains cut by [`Emitter::bind_deep`], to be emitted before
    /// the statement being built.
    pending: RefCell<TokenStream>,
    /// Number of such `let`s so far (their names `__cN`).
    cuts: Cell<usize>,
}

/// Latencies (cycles) of the operations on a current x86 core, for the balancing only.
const ADD: u32 = 4;
const DIV: u32 = 14;
const SQRT: u32 = 18;
const CALL: u32 = 40;

/// Bound on the nesting of an emitted expression, in levels: a parenthesis, an operator, a
/// method call or a unary minus each count one (so the parentheses nest less deeply still).
/// rustc's parser recurses once per level and overflows its stack (SIGSEGV) at a few
/// thousand; a node whose inlined value would nest deeper is bound to a `let` instead, and a
/// chain is cut into `let`s where its balanced tree would. Every emitted statement nests at
/// most `MAX_DEPTH + 2` levels.
pub(crate) const MAX_DEPTH: u32 = 64;

/// Nesting of a leaf as emitted (at most `(-1.5f64)`, `(path)` or `self.c[3]`).
const LEAF_DEPTH: u32 = 2;

/// Nesting of `(a op b)` from its operands' (one level for the parentheses, one for the
/// operator), after an operand nested more than `MAX_DEPTH - 2` levels is bound to a `let`
/// (nesting 0): at most `MAX_DEPTH`.
fn merged_depth(a: u32, b: u32) -> u32 {
    let bound = |d: u32| if d > MAX_DEPTH - 2 { 0 } else { d };
    2 + bound(a).max(bound(b))
}

/// The two operations whose chains are balanced.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Chain {
    /// `+` and `-`: operands with a sign.
    Sum,
    /// `*` and division by a bound reciprocal: operands with an overall sign.
    Product,
}

/// An operand of a chain: a node, or the bound reciprocal of a node.
#[derive(Clone, Copy)]
enum Operand {
    Node(Id),
    Reciprocal(Id),
}

/// A term of a chain being balanced: (negated, tokens, nesting).
type Term = (bool, TokenStream, u32);

impl Emitter<'_> {
    /// Latencies and nesting depths of all nodes, and which inlined nodes to bind instead
    /// because they would nest too deeply. Linear in the graph except for the chains, each
    /// collected and balanced once, in O(m log m) for m operands.
    fn plan(&mut self, emitted: &[bool]) {
        let len = self.g.len();
        // nodes inside the chain of another (an inlined operand of the same operation or a
        // negation): their latency and depth are their chain's, computed at its head; from
        // the parents down, so that each chain is walked once from its head
        let mut absorbed = vec![false; len];
        let mut ops = Vec::new();
        for i in (0..len).rev() {
            let id = Id(i as u32);
            if absorbed[i] || !emitted[i] {
                continue;
            }
            if let Some(kind) = self.head(id, false) {
                ops.clear();
                self.operands(id, kind, false, &mut ops, |c| absorbed[c.0 as usize] = true);
            }
        }
        // children first; binding a node that is not absorbed changes no chain
        let mut nest = vec![0; len];
        for i in 0..len {
            if absorbed[i] || !emitted[i] {
                continue;
            }
            let id = Id(i as u32);
            nest[i] = self.bind_deep_operands(id, &nest, &mut ops);
            let (latency, depth) = self.estimate(id);
            self.latency[i] = latency;
            self.depth[i] = depth;
            if self.inline[i] && depth + 1 > MAX_DEPTH {
                self.inline[i] = false;
            }
        }
    }

    /// Binds to its own `let` each inlined operand of `id` (its children, or the operands
    /// of the chain it heads) whose value [`Emitter::reference`] would reach through
    /// `MAX_DEPTH` or more inlined levels (`nest`, per node), or, for a chain, that is nested
    /// more deeply than a merge allows (see [`merged_depth`]); returns the levels of `id`.
    /// So the emitter's recursion through inlined values stays within `MAX_DEPTH` levels:
    /// the nesting of the code alone does not bound it, since a chain's long parts are cut
    /// into `let`s after their operands are built (the derivatives of a long product are
    /// sums and products nested in turn as deep as the product is long).
    fn bind_deep_operands(&mut self, id: Id, nest: &[u32], ops: &mut Vec<(Operand, bool)>) -> u32 {
        ops.clear();
        let kind = self.head(id, false);
        match kind {
            Some(kind) => self.operands(id, kind, false, ops, |_| {}),
            None => ops.extend(
                children(self.g.node(id))
                    .into_iter()
                    .map(|c| (Operand::Node(c), false)),
            ),
        }
        let mut levels = 0;
        for &(op, _) in ops.iter() {
            let Operand::Node(c) = op else { continue };
            let i = c.0 as usize;
            if !self.inline[i] || is_leaf(self.g.node(c)) {
                continue;
            }
            let too_deep = kind.is_some() && self.reference_depth(c, false) > MAX_DEPTH - 2;
            if too_deep || nest[i] >= MAX_DEPTH {
                self.inline[i] = false;
            } else {
                levels = levels.max(nest[i]);
            }
        }
        levels + 1
    }

    /// The chain `id` heads, if it is a sum or a product (a function-level `Neg` heads the
    /// chain of its operand).
    fn chain(&self, id: Id, in_loop: bool) -> Option<Chain> {
        match *self.g.node(id) {
            Node::Add(..) | Node::Sub(..) => Some(Chain::Sum),
            Node::Mul(..) => Some(Chain::Product),
            Node::Div(_, b) if !in_loop && self.reciprocal[b.0 as usize] => Some(Chain::Product),
            _ => None,
        }
    }

    /// The operands of the chain of `kind` at `id` with their signs (`true`: negated), left to
    /// right, through inlined nodes of the same chain and negations (each passed to
    /// `through`); `Neg` of a node of the other kind (or a bound one) is an operand with a
    /// sign. Iterative: a chain may have any length.
    fn operands(
        &self,
        id: Id,
        kind: Chain,
        in_loop: bool,
        out: &mut Vec<(Operand, bool)>,
        mut through: impl FnMut(Id),
    ) {
        enum Step {
            Walk(Id, bool),
            Push(Operand, bool),
        }
        let mut step = |c: Id, negate: bool| {
            let passes = !in_loop
                && self.inline[c.0 as usize]
                && (self.chain(c, in_loop) == Some(kind) || matches!(self.g.node(c), Node::Neg(_)));
            if passes {
                through(c);
                Step::Walk(c, negate)
            } else {
                Step::Push(Operand::Node(c), negate)
            }
        };
        let mut stack = vec![Step::Walk(id, false)];
        while let Some(next) = stack.pop() {
            let (id, negate) = match next {
                Step::Push(op, negate) => {
                    count_work(1);
                    out.push((op, negate));
                    continue;
                }
                Step::Walk(id, negate) => (id, negate),
            };
            count_work(1);
            // the right operand first onto the stack: the left one is walked first
            match *self.g.node(id) {
                Node::Neg(a) => stack.push(step(a, !negate)),
                Node::Add(a, b) if kind == Chain::Sum => {
                    stack.push(step(b, negate));
                    stack.push(step(a, negate));
                }
                Node::Sub(a, b) if kind == Chain::Sum => {
                    stack.push(step(b, !negate));
                    stack.push(step(a, negate));
                }
                Node::Mul(a, b) if kind == Chain::Product => {
                    stack.push(step(b, false));
                    stack.push(step(a, negate));
                }
                Node::Div(a, b) if kind == Chain::Product => {
                    stack.push(Step::Push(Operand::Reciprocal(b), false));
                    stack.push(step(a, negate));
                }
                _ => out.push((Operand::Node(id), negate)),
            }
        }
    }

    fn operand_latency(&self, op: Operand) -> u32 {
        match op {
            Operand::Node(id) => self.latency[id.0 as usize],
            Operand::Reciprocal(id) => self.latency[id.0 as usize] + DIV,
        }
    }

    /// Nesting of a reference to `id` (as [`Emitter::reference`] emits it).
    fn reference_depth(&self, id: Id, in_loop: bool) -> u32 {
        if is_leaf(self.g.node(id)) {
            LEAF_DEPTH
        } else if !in_loop && self.inline[id.0 as usize] {
            self.depth[id.0 as usize] + 1
        } else {
            0
        }
    }

    fn operand_depth(&self, op: Operand, in_loop: bool) -> u32 {
        match op {
            Operand::Node(id) => self.reference_depth(id, in_loop),
            Operand::Reciprocal(_) => 0,
        }
    }

    /// The chain emitted at `id`: its own, or for a negation of an inlined chain, that chain.
    fn head(&self, id: Id, in_loop: bool) -> Option<Chain> {
        match *self.g.node(id) {
            Node::Neg(a) if !in_loop && self.inline[a.0 as usize] => self.chain(a, in_loop),
            _ => self.chain(id, in_loop),
        }
    }

    /// Latency and nesting of `id` as emitted (function level), from its children's.
    fn estimate(&self, id: Id) -> (u32, u32) {
        if let Some(kind) = self.head(id, false) {
            let mut ops = Vec::new();
            self.operands(id, kind, false, &mut ops, |_| {});
            let terms = ops
                .iter()
                .map(|&(op, negate)| {
                    (
                        (negate, self.operand_depth(op, false)),
                        self.operand_latency(op),
                    )
                })
                .collect();
            let merge = |(na, da): (bool, u32), (nb, db): (bool, u32)| match kind {
                Chain::Product => (na ^ nb, merged_depth(da, db)),
                Chain::Sum => (na && nb, merged_depth(da, db)),
            };
            return match earliest_first(terms, merge) {
                None => (0, LEAF_DEPTH),
                Some(((negated, depth), latency)) => (latency, depth + u32::from(negated)),
            };
        }
        let l = |c: Id| self.latency[c.0 as usize];
        let d = |c: Id| self.reference_depth(c, false);
        // an operator, or a method call with its argument in parentheses
        let (latency, depth) = match *self.g.node(id) {
            Node::Const(_) | Node::Var(_) | Node::Named(_) => (0, LEAF_DEPTH),
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) => {
                (l(a).max(l(b)) + ADD, d(a).max(d(b)))
            }
            Node::Div(a, b) => (l(a).max(l(b)) + DIV, d(a).max(d(b))),
            Node::Neg(a) => (l(a) + 1, d(a)),
            Node::Powi(a, n) => {
                let squarings = (32 - n.unsigned_abs().leading_zeros()).max(1);
                (l(a) + ADD * squarings, d(a))
            }
            Node::Unary(Func::Sqrt, a) => (l(a) + SQRT, d(a)),
            Node::Unary(Func::Abs | Func::Signum, a) => (l(a) + 1, d(a)),
            Node::Unary(_, a) => (l(a) + CALL, d(a)),
            Node::Powf(a, b) | Node::Atan2(a, b) | Node::Hypot(a, b) => {
                (l(a).max(l(b)) + CALL, d(a).max(d(b)))
            }
            Node::Sum { .. } => (CALL, 0),
        };
        (latency, depth + 2)
    }

    /// Binds a term nested more deeply than a merge allows (see [`merged_depth`]) to a `let`.
    fn bind_deep(&self, (negated, tokens, depth): Term) -> Term {
        if depth <= MAX_DEPTH - 2 {
            return (negated, tokens, depth);
        }
        let n = self.cuts.get();
        self.cuts.set(n + 1);
        let name = format_ident!("__c{}", n);
        self.pending
            .borrow_mut()
            .extend(quote!(let #name: f64 = #tokens;));
        (negated, quote!(#name), 0)
    }

    /// The `let`s made by [`Emitter::bind_deep`] since the last call.
    fn take_pending(&self) -> TokenStream {
        std::mem::take(&mut *self.pending.borrow_mut())
    }

    /// A chain as a balanced tree: repeatedly combines the two operands available first.
    fn balanced(&self, id: Id, kind: Chain, in_loop: bool) -> TokenStream {
        let mut ops = Vec::new();
        self.operands(id, kind, in_loop, &mut ops, |_| {});
        let mut terms: Vec<(Term, u32)> = ops
            .iter()
            .map(|&(op, negate)| {
                let tokens = match op {
                    Operand::Node(c) => self.reference(c, in_loop),
                    Operand::Reciprocal(b) => reciprocal_name(b),
                };
                let depth = self.operand_depth(op, in_loop);
                ((negate, tokens, depth), self.operand_latency(op))
            })
            .collect();
        if kind == Chain::Product {
            // the sign of a product is carried to its end
            let negate = terms.iter().filter(|t| t.0.0).count() % 2 == 1;
            for (i, t) in terms.iter_mut().enumerate() {
                t.0.0 = i == 0 && negate;
            }
        }
        let combined = earliest_first(terms, |a, b| {
            let ((na, a, da), (nb, b, db)) = (self.bind_deep(a), self.bind_deep(b));
            let depth = merged_depth(da, db);
            match kind {
                Chain::Product => (na ^ nb, quote!((#a * #b)), depth),
                Chain::Sum => {
                    let (negated, tokens) = signed_add((na, a), (nb, b));
                    (negated, tokens, depth)
                }
            }
        });
        match combined {
            None => quote!(0.0),
            Some(((false, tokens, _), _)) => tokens,
            Some(((true, tokens, _), _)) => quote!(-#tokens),
        }
    }

    /// The `let`s of the function-level nodes that are not inlined, in id order (children
    /// first), a sum as a loop, and the bound reciprocals after their denominators.
    fn statements(&self, placement: &Placement) -> TokenStream {
        let g = self.g;
        let mut stmts = TokenStream::new();
        for (i, _) in self.reciprocal.iter().enumerate().filter(|(_, r)| **r) {
            let id = Id(i as u32);
            if is_leaf(g.node(id)) {
                self.bind_reciprocal(&mut stmts, id);
            }
        }
        for i in 0..g.len() {
            let id = Id(i as u32);
            let node = g.node(id);
            if !placement.top[i] || is_leaf(node) || self.inline[i] {
                continue;
            }
            let t = temp(id);
            if let Node::Sum { param, body } = *node {
                stmts.extend(self.sum_loop(&t, param, body, &placement.body_of[i]));
            } else {
                let v = self.value(id, false);
                stmts.extend(self.take_pending());
                stmts.extend(quote!(let #t: f64 = #v;));
            }
            if self.reciprocal[i] {
                self.bind_reciprocal(&mut stmts, id);
            }
        }
        stmts
    }

    /// `let __rN: f64 = 1.0 / b;` for the denominator `id`.
    fn bind_reciprocal(&self, stmts: &mut TokenStream, id: Id) {
        let (r, b) = (reciprocal_name(id), self.reference(id, false));
        stmts.extend(self.take_pending());
        stmts.extend(quote!(let #r: f64 = 1.0 / #b;));
    }

    /// The sum `t` of `body` over the elements of the slice parameter `param`, as a loop:
    /// the nodes `marks` of its body that depend on the element are emitted inside it.
    fn sum_loop(&self, t: &TokenStream, param: u32, body: Id, marks: &[bool]) -> TokenStream {
        let mut inside = TokenStream::new();
        for (j, &m) in marks.iter().enumerate() {
            let jd = Id(j as u32);
            if m && !is_leaf(self.g.node(jd)) {
                let tj = temp(jd);
                let v = self.value(jd, true);
                inside.extend(self.take_pending());
                inside.extend(quote!(let #tj: f64 = #v;));
            }
        }
        let slice = self.leaves.slice(param);
        let element = self.leaves.element();
        let b = self.reference(body, true);
        inside.extend(self.take_pending());
        quote! {
            let mut #t: f64 = 0.0;
            for #element in #slice.iter() {
                #inside
                #t += #b;
            }
        }
    }

    /// How a parent refers to `id`: a leaf, a temporary, or (inlined) its parenthesised value.
    /// `in_loop`: inside a loop body every non-leaf is a temporary.
    fn reference(&self, id: Id, in_loop: bool) -> TokenStream {
        match self.g.node(id) {
            Node::Const(bits) => constant(f64::from_bits(*bits)),
            Node::Var(v) => self.leaves.var(*v),
            Node::Named(k) => {
                let path: TokenStream = self.g.named[*k as usize]
                    .parse()
                    .unwrap_or_else(|_| quote!(::core::f64::NAN));
                quote!((#path))
            }
            _ if !in_loop && self.inline[id.0 as usize] => {
                let v = self.value(id, in_loop);
                quote!((#v))
            }
            _ => temp(id),
        }
    }

    /// The expression computing `id` from its children.
    fn value(&self, id: Id, in_loop: bool) -> TokenStream {
        let r = |c: Id| self.reference(c, in_loop);
        if let Some(kind) = self.head(id, in_loop) {
            return self.balanced(id, kind, in_loop);
        }
        match self.g.node(id).clone() {
            // sums, products and divisions by a bound reciprocal are chains (above)
            Node::Div(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a / #b)
            }
            Node::Neg(a) => {
                let a = r(a);
                quote!(-#a)
            }
            Node::Powi(a, n) => {
                let a = r(a);
                quote!(#a.powi(#n))
            }
            Node::Powf(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a.powf(#b))
            }
            Node::Unary(Func::Stumpff(k), a) => {
                let (a, k) = (r(a), u32::from(k));
                {
                    let core = core_path();
                    quote!(#core::stumpff(#k, #a))
                }
            }
            Node::Unary(f, a) => {
                let a = r(a);
                let m = format_ident!("{}", f.method());
                quote!(#a.#m())
            }
            Node::Atan2(y, x) => {
                let (y, x) = (r(y), r(x));
                quote!(#y.atan2(#x))
            }
            Node::Hypot(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a.hypot(#b))
            }
            _ => self.reference(id, in_loop),
        }
    }
}

/// Combines `terms` (each with the latency at which it is known) into one, repeatedly merging
/// the two known first (the earlier inserted on ties, merged terms inserted last) into a term
/// known `ADD` later: the balanced tree of least latency. `None` for no terms. A binary heap:
/// O(m log m) for m terms.
fn earliest_first<T>(terms: Vec<(T, u32)>, mut merge: impl FnMut(T, T) -> T) -> Option<(T, u32)> {
    type Heap = BinaryHeap<Reverse<(u32, usize)>>;
    fn take<T>(heap: &mut Heap, slots: &mut [Option<T>]) -> Option<(T, u32)> {
        count_work(1 + heap.len().max(1).ilog2() as usize);
        let Reverse((latency, slot)) = heap.pop()?;
        Some((slots[slot].take()?, latency))
    }
    let mut slots: Vec<Option<T>> = Vec::with_capacity(2 * terms.len());
    let mut heap = Heap::with_capacity(terms.len());
    count_work(terms.len());
    for (term, latency) in terms {
        heap.push(Reverse((latency, slots.len())));
        slots.push(Some(term));
    }
    while heap.len() > 1 {
        let (a, la) = take(&mut heap, &mut slots)?;
        let (b, lb) = take(&mut heap, &mut slots)?;
        count_work(1 + heap.len().max(1).ilog2() as usize);
        heap.push(Reverse((la.max(lb) + ADD, slots.len())));
        slots.push(Some(merge(a, b)));
    }
    take(&mut heap, &mut slots)
}

#[cfg(test)]
thread_local! {
    /// Work of the chains on this thread: operands walked and heap operations (each counted
    /// 1 + log2 of the heap's size), for the tests' bounds on the expansion's cost.
    static WORK: Cell<usize> = const { Cell::new(0) };
}

#[cfg(test)]
fn count_work(n: usize) {
    WORK.with(|w| w.set(w.get() + n));
}

#[cfg(not(test))]
fn count_work(_: usize) {}

/// `a + b` for terms `(negated, tokens)`, as `(negated, tokens)` with no negation inside.
pub(crate) fn signed_add(
    (na, a): (bool, TokenStream),
    (nb, b): (bool, TokenStream),
) -> (bool, TokenStream) {
    match (na, nb) {
        (false, false) => (false, quote!((#a + #b))),
        (false, true) => (false, quote!((#a - #b))),
        (true, false) => (false, quote!((#b - #a))),
        (true, true) => (true, quote!((#a + #b))),
    }
}

#[cfg(test)]
mod tests {
    use std::collections::HashMap;

    use proptest::prelude::*;
    use quote::ToTokens;

    use super::*;

    /// `x0`, `x1`, ... for the components of z0.
    struct Names;

    impl Leaves for Names {
        fn var(&self, var: Var) -> TokenStream {
            let Var::Z0(i) = var else {
                return quote!(::core::f64::NAN);
            };
            let name = format_ident!("x{}", i);
            quote!(#name)
        }

        fn slice(&self, _param: u32) -> TokenStream {
            quote!(slice)
        }
    }

    /// The value of a node by recursion over the graph (no emission).
    fn direct(g: &Graph, id: Id, x: &[f64]) -> f64 {
        let v = |c: Id| direct(g, c, x);
        match *g.node(id) {
            Node::Const(bits) => f64::from_bits(bits),
            Node::Var(Var::Z0(i)) => x[i as usize],
            Node::Add(a, b) => v(a) + v(b),
            Node::Sub(a, b) => v(a) - v(b),
            Node::Mul(a, b) => v(a) * v(b),
            Node::Div(a, b) => v(a) / v(b),
            Node::Neg(a) => -v(a),
            Node::Powi(a, n) => v(a).powi(n),
            Node::Unary(Func::Sqrt, a) => v(a).sqrt(),
            ref n => panic!("not in the test grammar: {n:?}"),
        }
    }

    /// Evaluates an emitted expression: literals, names, `+ - * /`, negation, parentheses,
    /// `.powi(n)` and `.sqrt()`.
    fn evaluate(e: &syn::Expr, env: &HashMap<String, f64>) -> f64 {
        use syn::{BinOp, Expr, Lit, UnOp};
        match e {
            Expr::Paren(p) => evaluate(&p.expr, env),
            Expr::Group(g) => evaluate(&g.expr, env),
            Expr::Lit(l) => match &l.lit {
                Lit::Float(f) => f.base10_parse().expect("float"),
                Lit::Int(i) => i.base10_parse().expect("int"),
                other => panic!("literal {other:?}"),
            },
            Expr::Path(p) => env[&p.path.segments.last().expect("name").ident.to_string()],
            Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => -evaluate(&u.expr, env),
            Expr::Binary(b) => {
                let (l, r) = (evaluate(&b.left, env), evaluate(&b.right, env));
                match b.op {
                    BinOp::Add(_) => l + r,
                    BinOp::Sub(_) => l - r,
                    BinOp::Mul(_) => l * r,
                    BinOp::Div(_) => l / r,
                    _ => panic!("operator {:?}", b.op),
                }
            }
            Expr::MethodCall(m) => {
                let receiver = evaluate(&m.receiver, env);
                match m.method.to_string().as_str() {
                    "sqrt" => receiver.sqrt(),
                    "powi" => receiver.powi(evaluate(&m.args[0], env) as i32),
                    other => panic!("method {other}"),
                }
            }
            other => panic!("expression {other:?}"),
        }
    }

    /// Runs `let`s into `env`: typed ones, and the blocks of long code (`scopes`), whose
    /// inner names are unique, so they are run into `env` directly.
    fn run(stmts: &[syn::Stmt], env: &mut HashMap<String, f64>) {
        for stmt in stmts {
            let syn::Stmt::Local(local) = stmt else {
                panic!("not a let: {stmt:?}")
            };
            let init = &local.init.as_ref().expect("initialiser").expr;
            match &local.pat {
                syn::Pat::Type(typed) => {
                    let syn::Pat::Ident(name) = &*typed.pat else {
                        panic!("pattern")
                    };
                    let value = evaluate(init, env);
                    env.insert(name.ident.to_string(), value);
                }
                syn::Pat::Tuple(_) => {
                    let syn::Expr::Block(block) = &**init else {
                        panic!("a tuple from a block")
                    };
                    let inner = &block.block.stmts;
                    run(&inner[..inner.len() - 1], env);
                }
                _ => panic!("untyped let"),
            }
        }
    }

    /// The roots as emitted, evaluated at `x`.
    fn emitted(g: &Graph, roots: &[Id], x: &[f64]) -> Vec<f64> {
        let code = emit(g, roots, &Names);
        let stmts = &code.stmts;
        let block: syn::Block = syn::parse2(quote!({ #stmts })).expect("statements");
        let mut env: HashMap<String, f64> = (0..x.len()).map(|i| (format!("x{i}"), x[i])).collect();
        run(&block.stmts, &mut env);
        code.exprs
            .iter()
            .map(|e| evaluate(&syn::parse2(e.clone()).expect("expression"), &env))
            .collect()
    }

    #[test]
    fn a_late_factor_is_multiplied_last() {
        let mut g = Graph::default();
        let x: Vec<Id> = (0..4).map(|i| g.var(Var::Z0(i))).collect();
        let late = g.unary(Func::Sqrt, x[0]);
        // ((sqrt(x0) * x1) * x2) * x3: the chain as written waits on the square root thrice
        let a = g.mul(late, x[1]);
        let b = g.mul(a, x[2]);
        let root = g.mul(b, x[3]);
        let code = emit(&g, &[root], &Names);
        let stmts = &code.stmts;
        let block: syn::Block = syn::parse2(quote!({ #stmts })).expect("statements");
        // the root is bound last
        let Some(syn::Stmt::Local(local)) = block.stmts.last() else {
            panic!("no binding: {stmts}")
        };
        let expr = &local.init.as_ref().expect("initialiser").expr;
        let mut top = &**expr;
        while let syn::Expr::Paren(p) = top {
            top = &p.expr;
        }
        let syn::Expr::Binary(product) = top else {
            panic!("not a product: {stmts}")
        };
        let (left, right) = (
            product.left.to_token_stream().to_string(),
            product.right.to_token_stream().to_string(),
        );
        // the square root is one operand of the last product, the other three the other
        assert_eq!(
            [left.contains("sqrt"), right.contains("sqrt")]
                .iter()
                .filter(|&&s| s)
                .count(),
            1,
            "{stmts}"
        );
        assert!(!left.contains("sqrt") || !left.contains('*'), "{stmts}");
        assert!(!right.contains("sqrt") || !right.contains('*'), "{stmts}");
    }

    /// A random expression over x0..x3: each op combines two earlier nodes (op 0..5: add,
    /// sub, mul, division by 1 + b^2, negation, a shared reciprocal); several roots.
    fn random_graph(ops: &[(u8, usize, usize)]) -> (Graph, Vec<Id>) {
        let mut g = Graph::default();
        let mut nodes: Vec<Id> = (0..4).map(|i| g.var(Var::Z0(i))).collect();
        nodes.push(g.constant(2.5));
        nodes.push(g.constant(-0.75));
        for &(op, i, j) in ops {
            let (a, b) = (nodes[i % nodes.len()], nodes[j % nodes.len()]);
            let one = g.constant(1.0);
            let node = match op % 6 {
                0 => g.add_op(a, b),
                1 => g.sub(a, b),
                2 => g.mul(a, b),
                3 => {
                    let square = g.mul(b, b);
                    let d = g.add_op(one, square);
                    g.div(a, d)
                }
                4 => g.neg(a),
                _ => {
                    // the same denominator twice: emitted as one reciprocal
                    let d = g.add_op(one, nodes[0]);
                    let p = g.div(a, d);
                    let q = g.div(b, d);
                    g.sub(p, q)
                }
            };
            nodes.push(node);
        }
        let len = nodes.len();
        (g, nodes[len.saturating_sub(3)..].to_vec())
    }

    /// |value| with every operation on magnitudes: bounds the rounding of any association.
    fn magnitude(g: &Graph, id: Id, x: &[f64]) -> f64 {
        let m = |c: Id| magnitude(g, c, x);
        match *g.node(id) {
            Node::Add(a, b) | Node::Sub(a, b) => m(a) + m(b),
            Node::Mul(a, b) => m(a) * m(b),
            Node::Div(a, b) => m(a) / direct(g, b, x).abs(),
            Node::Neg(a) => m(a),
            Node::Powi(a, n) => m(a).powi(n),
            _ => direct(g, id, x).abs(),
        }
    }

    /// Nesting of parentheses in `tokens`.
    fn paren_depth(tokens: &TokenStream) -> usize {
        tokens
            .clone()
            .into_iter()
            .map(|tree| match tree {
                proc_macro2::TokenTree::Group(g) => {
                    usize::from(g.delimiter() == proc_macro2::Delimiter::Parenthesis)
                        + paren_depth(&g.stream())
                }
                _ => 0,
            })
            .max()
            .unwrap_or(0)
    }

    /// Sum of `m` terms `x_(i mod 4) * c_i` (the constants distinct, so that the products
    /// are), and the work its emission counts.
    fn long_sum_work(m: usize) -> usize {
        let mut g = Graph::default();
        let x: Vec<Id> = (0..4).map(|i| g.var(Var::Z0(i))).collect();
        let mut sum = g.constant(0.5);
        for i in 0..m {
            let c = g.constant(1.0 + i as f64);
            let term = g.mul(x[i % 4], c);
            sum = g.add_op(sum, term);
        }
        WORK.with(|w| w.set(0));
        let code = emit(&g, &[sum], &Names);
        assert!(paren_depth(&code.stmts) <= MAX_DEPTH as usize + 2);
        WORK.with(|w| w.get())
    }

    /// Each chain is collected once and balanced with a heap, so the work of a sum of m terms
    /// is O(m log m) (it was O(m^3): a balancing at every node of the chain, each with a
    /// linear search per merge, about 1.7e11 steps at m = 10 000).
    #[test]
    fn a_sum_of_m_terms_costs_m_log_m_work() {
        for m in [10, 100, 1000, 10_000] {
            let work = long_sum_work(m);
            let bound = 24 * m * (m.ilog2() as usize + 1);
            assert!(work <= bound, "m = {m}: work {work} > {bound}");
        }
        // and grows quasi-linearly: 10x the terms, at most 15x the work
        let (small, large) = (long_sum_work(1000), long_sum_work(10_000));
        assert!(large <= 15 * small, "{small} -> {large}");
    }

    /// A recurrence x <- x * y + 1 through 5000 inlined nodes, or a chain whose balanced tree
    /// is a path (operands known ever later), is emitted nesting at most `MAX_DEPTH + 2`
    /// levels, and computes the same values.
    #[test]
    fn deep_graphs_are_emitted_with_bounded_nesting() {
        let mut g = Graph::default();
        let (y, z) = (g.var(Var::Z0(0)), g.var(Var::Z0(1)));
        let one = g.constant(1.0);
        let mut x = z;
        for _ in 0..5000 {
            let p = g.mul(x, y);
            x = g.add_op(p, one);
        }
        // a sum whose operands come ever later: sqrt(z), sqrt(sqrt(z)), ...
        let mut late = z;
        let mut path = g.constant(0.25);
        for _ in 0..300 {
            late = g.unary(Func::Sqrt, late);
            path = g.add_op(path, late);
        }
        let roots = [x, path];
        let code = emit(&g, &roots, &Names);
        let depth = paren_depth(&code.stmts);
        assert!(depth <= MAX_DEPTH as usize + 2, "nesting {depth}");
        let at = [0.5, 1.5];
        let got = emitted(&g, &roots, &at);
        // x_m = 2 - 0.5^m (1.5 - ... ) converges to 1 / (1 - y) = 2
        assert!((got[0] - 2.0).abs() < 1e-12, "{}", got[0]);
        let mut want = 0.25;
        let mut s = at[1];
        for _ in 0..300 {
            s = s.sqrt();
            want += s;
        }
        assert!((got[1] - want).abs() < 1e-12 * want, "{} vs {want}", got[1]);
    }

    proptest! {
        #[test]
        fn balanced_chains_compute_the_same_values(
            ops in proptest::collection::vec((0u8..6, 0usize..64, 0usize..64), 1..24),
            x in proptest::array::uniform4(0.5f64..2.0),
        ) {
            let (g, roots) = random_graph(&ops);
            let got = emitted(&g, &roots, &x);
            for (&root, got) in roots.iter().zip(got) {
                let want = direct(&g, root, &x);
                let scale = magnitude(&g, root, &x);
                prop_assert!(
                    (got - want).abs() <= 1e-12 * scale,
                    "{got} vs {want} (scale {scale})"
                );
            }
        }
    }
}
