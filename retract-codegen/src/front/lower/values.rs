//! Values that are not one number: local arrays `[a, b]`, tuples `(a, b)` destructured by
//! `let`, and helper functions written inside the Lagrangian (`fn torque(...) -> [f64; 2]`),
//! inlined at every call.
//!
//! A helper sees only its own arguments (as a nested `fn` in Rust: not the Lagrangian's
//! arguments or locals), the consts by path and the other helpers; its arguments are numbers
//! (`f64`) or arrays (`[f64; n]`: a local array, a jet argument, a parameter array or a slice
//! element), and it returns a number, an array or a tuple of those. Arrays are immutable:
//! build them with `[e0, e1, ...]` or `[e; n]`.

use std::collections::hash_map::Entry;

use syn::spanned::Spanned;
use syn::{Expr, Pat, Stmt};

use super::{Binding, Lower};
use crate::front::signature::Kind;
use crate::ir::graph::{Id, Var};

/// Helper calls nested deeper than this are an error.
const MAX_INLINE_DEPTH: usize = 16;
/// The most helper calls one expansion inlines (each call is inlined: helpers that call others
/// several times multiply, e.g. nine deep, three calls each, are 19 683 inlinings).
pub(super) const MAX_INLINED: usize = 4096;

/// The value of an expression that may not be a number.
pub(super) enum Value {
    Scalar(Id),
    /// The components of an array.
    Array(Vec<Id>),
    Tuple(Vec<Value>),
}

/// What a function named by an option returned (`Lower::call_by_name`).
pub enum Returned {
    Number(Id),
    Array(Vec<Id>),
    /// A tuple of arrays.
    Arrays(Vec<Vec<Id>>),
}

/// The shape a helper's argument or result must have.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Shape {
    Number,
    Array(usize),
}

impl Shape {
    fn of(ty: &syn::Type) -> Option<Self> {
        match ty {
            syn::Type::Path(p) if p.path.is_ident("f64") => Some(Self::Number),
            syn::Type::Array(a) => {
                let syn::Type::Path(p) = &*a.elem else {
                    return None;
                };
                let syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(len),
                    ..
                }) = &a.len
                else {
                    return None;
                };
                (p.path.is_ident("f64"))
                    .then(|| len.base10_parse().ok().map(Self::Array))
                    .flatten()
            }
            syn::Type::Paren(p) => Self::of(&p.elem),
            syn::Type::Group(g) => Self::of(&g.elem),
            _ => None,
        }
    }

    fn describe(self) -> String {
        match self {
            Self::Number => "an f64".into(),
            Self::Array(n) => format!("an array of {n} f64"),
        }
    }
}

impl Lower<'_> {
    /// Registers the helper `fn`s among `stmts` (before the statements run: Rust items are
    /// visible in their whole block).
    pub(super) fn register_helpers(&mut self, stmts: &[Stmt]) {
        for stmt in stmts {
            let Stmt::Item(syn::Item::Fn(f)) = stmt else {
                continue;
            };
            let name = f.sig.ident.to_string();
            if let Some(problem) = helper_signature_problem(&f.sig) {
                self.error(problem.0, problem.1);
                continue;
            }
            // (a helper's own helpers are registered again each time it is inlined)
            let text = |f: &syn::ItemFn| quote::ToTokens::to_token_stream(f).to_string();
            match self.helpers.entry(name) {
                Entry::Vacant(slot) => {
                    slot.insert(f.clone());
                }
                Entry::Occupied(existing) if text(existing.get()) == text(f) => {}
                Entry::Occupied(existing) => {
                    let message = format!("the helper `{}` is defined twice", existing.key());
                    self.error(f.sig.ident.span(), message);
                }
            }
        }
    }

    /// The helper `name` (registered from `stmts`, the body of the function being lowered)
    /// called with its arguments taken by name: each parameter is the argument or parameter of
    /// the function of the same name (its jet q, q' and its parameters, as the function gets
    /// them), or one of the arrays `extra`; `role` names the option in messages. Call it
    /// before the body is lowered (whose locals would shadow the arguments). `None` after an
    /// error (reported); else the value and the span of the helper's return type.
    pub fn call_by_name(
        &mut self,
        stmts: &[Stmt],
        name: &syn::Ident,
        role: &str,
        extra: &[(&str, Vec<Id>)],
    ) -> Option<(Returned, proc_macro2::Span)> {
        self.register_helpers(stmts);
        let Some(f) = self.helpers.get(&name.to_string()).cloned() else {
            self.error(
                name.span(),
                format!(
                    "`{role} = {name}`: no helper function `{name}`: write `#[helper] fn \
                     {name}(...)` before the system, or `fn {name}(...)` in its body"
                ),
            );
            return None;
        };
        let mut scope = std::collections::HashMap::new();
        for (extra_name, ids) in extra {
            self.arrays.push(ids.clone());
            let slot = (self.arrays.len() - 1) as u32;
            scope.insert((*extra_name).to_string(), Binding::Array { slot });
        }
        let mut args = syn::punctuated::Punctuated::new();
        let mut known = true;
        for input in &f.sig.inputs {
            let syn::FnArg::Typed(typed) = input else {
                continue; // (rejected at registration)
            };
            let Pat::Ident(param) = &*typed.pat else {
                continue;
            };
            let arg = param.ident.to_string();
            if !scope.contains_key(&arg) && !self.scopes[0].contains_key(&arg) {
                let mut names: Vec<String> = self.sig.jet.iter().map(|j| j.to_string()).collect();
                names.extend(extra.iter().map(|(n, _)| (*n).to_string()));
                names.extend(self.sig.params.iter().map(|p| p.name.to_string()));
                self.error(
                    param.ident.span(),
                    format!(
                        "`{arg}`: the arguments of `{name}` (`{role}`) are taken by name from \
                         those of the system: {}",
                        names.join(", ")
                    ),
                );
                known = false;
            }
            let path: syn::ExprPath = syn::parse_quote_spanned!(param.ident.span()=> #param);
            args.push(Expr::Path(path));
        }
        if !known {
            return None;
        }
        let call = syn::ExprCall {
            attrs: Vec::new(),
            func: Box::new(syn::parse_quote_spanned!(name.span()=> #name)),
            paren_token: Default::default(),
            args,
        };
        let errors = self.errors.len();
        self.scopes.push(scope);
        let value = self.inline(&f, &call);
        self.scopes.pop();
        let span = match &f.sig.output {
            syn::ReturnType::Type(_, ty) => ty.span(),
            syn::ReturnType::Default => name.span(),
        };
        let returned = match value {
            _ if self.errors.len() > errors => return None,
            Value::Scalar(id) => Returned::Number(id),
            Value::Array(ids) => Returned::Array(ids),
            Value::Tuple(parts) => {
                let arrays: Option<Vec<Vec<Id>>> = parts
                    .into_iter()
                    .map(|p| match p {
                        Value::Array(ids) => Some(ids),
                        _ => None,
                    })
                    .collect();
                match arrays {
                    Some(arrays) => Returned::Arrays(arrays),
                    None => {
                        self.error(span, format!("`{name}` returns a tuple of arrays or none"));
                        return None;
                    }
                }
            }
        };
        Some((returned, span))
    }

    /// The value of `e`: an array or tuple literal, a local array, a helper call, or a number.
    pub(super) fn value(&mut self, e: &Expr) -> Value {
        if let Some(refused) = self.enter(e) {
            return Value::Scalar(refused);
        }
        let value = self.value_inner(e);
        self.nesting.0 -= 1;
        value
    }

    fn value_inner(&mut self, e: &Expr) -> Value {
        match e {
            Expr::Array(a) => Value::Array(a.elems.iter().map(|x| self.expr(x)).collect()),
            Expr::Repeat(r) => {
                let element = self.expr(&r.expr);
                match self.int(&r.len) {
                    Some(n) if (0..=4096).contains(&n) => Value::Array(vec![element; n as usize]),
                    Some(_) => Value::Scalar(self.error(
                        r.len.span(),
                        "an array `[e; n]` in a Lagrangian has at most 4096 components",
                    )),
                    None => Value::Scalar(element),
                }
            }
            Expr::Tuple(t) => Value::Tuple(t.elems.iter().map(|x| self.value(x)).collect()),
            Expr::Paren(p) => self.value(&p.expr),
            Expr::Group(g) => self.value(&g.expr),
            Expr::Path(p) => match p.path.get_ident().map(|i| self.lookup(&i.to_string())) {
                Some(Some((_, binding))) => match self.components(binding) {
                    Some(ids) => Value::Array(ids),
                    None => Value::Scalar(self.expr(e)),
                },
                _ => Value::Scalar(self.expr(e)),
            },
            Expr::Call(c) => match self.helper_of(c) {
                Some(f) => self.inline(&f, c),
                None => Value::Scalar(self.expr(e)),
            },
            other => Value::Scalar(self.expr(other)),
        }
    }

    /// The components of an array binding (a local array, a jet argument, a parameter array
    /// or a slice element), as graph nodes; `None` for a binding that is not an array.
    pub(super) fn components(&mut self, binding: Binding) -> Option<Vec<Id>> {
        let vars: Vec<Var> = match binding {
            Binding::Array { slot } => return Some(self.arrays[slot as usize].clone()),
            Binding::Jet { order, offset } if !self.sig.scalar_jet => (0..self.sig.dim as u32)
                .map(|i| Var::Jet {
                    order,
                    index: offset + i,
                })
                .collect(),
            Binding::Param {
                param,
                kind: Kind::Array(len),
            } => (0..len as u32)
                .map(|index| Var::Param { param, index })
                .collect(),
            Binding::Element { param, len } => (0..len as u32)
                .map(|index| Var::Elem { param, index })
                .collect(),
            _ => return None,
        };
        Some(vars.into_iter().map(|v| self.g.var(v)).collect())
    }

    /// Binds the names of a `let` pattern to `value` (a name, or a tuple of names and `_`);
    /// `Poisoned` if the initialiser had errors.
    pub(super) fn bind_pattern(&mut self, pat: &Pat, value: Option<Value>) {
        let pat = match pat {
            Pat::Type(t) => &*t.pat,
            other => other,
        };
        match pat {
            Pat::Ident(p) if p.by_ref.is_none() && p.subpat.is_none() => {
                let name = p.ident.to_string();
                let mutable = p.mutability.is_some();
                let binding = match value {
                    None => Binding::Poisoned,
                    Some(Value::Scalar(id)) => Binding::Value { id, mutable },
                    Some(Value::Array(ids)) => {
                        if mutable {
                            self.error(
                                p.ident.span(),
                                "local arrays are immutable: build a new one with `[e0, e1, ...]`",
                            );
                        }
                        self.arrays.push(ids);
                        Binding::Array {
                            slot: (self.arrays.len() - 1) as u32,
                        }
                    }
                    Some(Value::Tuple(_)) => {
                        self.error(
                            p.ident.span(),
                            "bind a tuple by destructuring it: `let (a, b) = ...`",
                        );
                        Binding::Poisoned
                    }
                };
                self.bind(name, binding);
            }
            Pat::Wild(_) => {}
            Pat::Tuple(t) => {
                let parts = match value {
                    None => None,
                    Some(Value::Tuple(parts)) if parts.len() == t.elems.len() => Some(parts),
                    Some(_) => {
                        self.error(
                            t.span(),
                            format!(
                                "this pattern takes a tuple of {} values, and the value is not one",
                                t.elems.len()
                            ),
                        );
                        None
                    }
                };
                match parts {
                    Some(parts) => {
                        for (p, v) in t.elems.iter().zip(parts) {
                            self.bind_pattern(p, Some(v));
                        }
                    }
                    None => {
                        for p in &t.elems {
                            self.bind_pattern(p, None);
                        }
                    }
                }
            }
            other => {
                self.error(
                    other.span(),
                    "unsupported pattern: bind a plain name or a tuple of names",
                );
            }
        }
    }

    /// The helper that `c` calls, if it calls one by its bare name.
    pub(super) fn helper_of(&self, c: &syn::ExprCall) -> Option<syn::ItemFn> {
        let Expr::Path(p) = &*c.func else {
            return None;
        };
        let name = p.path.get_ident()?.to_string();
        self.helpers.get(&name).cloned()
    }

    /// Why a call of the helper `name` is not inlined, if it is not: `Some(message)` to
    /// report (a call of a helper being inlined, i.e. recursion, with the chain of calls; nesting
    /// deeper than [`MAX_INLINE_DEPTH`]; the first call past [`MAX_INLINED`]), `Some(None)`
    /// past the cap once it was reported.
    fn inline_refusal(&mut self, name: &str) -> Option<Option<String>> {
        if let Some(first) = self.inlining.iter().position(|h| h == name) {
            let chain = self.inlining[first..].join("` -> `");
            return Some(Some(format!(
                "`{name}` calls itself (`{chain}` -> `{name}`): recursion is not supported"
            )));
        }
        if self.inlining.len() >= MAX_INLINE_DEPTH {
            return Some(Some(format!(
                "helper calls nest deeper than {MAX_INLINE_DEPTH} at `{name}`"
            )));
        }
        if self.inlined.0 >= MAX_INLINED {
            let first = !std::mem::replace(&mut self.inlined.1, true);
            return Some(first.then(|| {
                format!(
                    "more than {MAX_INLINED} helper calls to inline at `{name}` (each call is \
                     inlined, and helpers that call others several times multiply): compute a \
                     repeated value once with `let`"
                )
            }));
        }
        None
    }

    /// The call `c` of the helper `f`, inlined: its arguments bound to its parameters in a
    /// scope that sees nothing of the caller's, its statements lowered, its tail the value.
    pub(super) fn inline(&mut self, f: &syn::ItemFn, c: &syn::ExprCall) -> Value {
        let name = f.sig.ident.to_string();
        if let Some(message) = self.inline_refusal(&name) {
            return Value::Scalar(match message {
                Some(message) => self.error(c.span(), message),
                // (reported once)
                None => self.g.constant(0.0),
            });
        }
        if f.sig.inputs.len() != c.args.len() {
            return Value::Scalar(self.error(
                c.span(),
                format!(
                    "`{name}` takes {} argument{}, given {}",
                    f.sig.inputs.len(),
                    if f.sig.inputs.len() == 1 { "" } else { "s" },
                    c.args.len()
                ),
            ));
        }
        let mut scope = std::collections::HashMap::new();
        for (input, arg) in f.sig.inputs.iter().zip(&c.args) {
            let syn::FnArg::Typed(typed) = input else {
                continue; // (rejected at registration)
            };
            let (Pat::Ident(param), Some(shape)) = (&*typed.pat, Shape::of(&typed.ty)) else {
                continue;
            };
            let value = self.value(arg);
            let binding = match (shape, value) {
                (Shape::Number, Value::Scalar(id)) => Binding::Value {
                    id,
                    mutable: param.mutability.is_some(),
                },
                (Shape::Array(n), Value::Array(ids)) if ids.len() == n => {
                    self.arrays.push(ids);
                    Binding::Array {
                        slot: (self.arrays.len() - 1) as u32,
                    }
                }
                (shape, _) => {
                    self.error(
                        arg.span(),
                        format!("`{name}` takes {} as `{}`", shape.describe(), param.ident),
                    );
                    Binding::Poisoned
                }
            };
            scope.insert(param.ident.to_string(), binding);
        }
        let barrier = std::mem::replace(&mut self.barrier, self.scopes.len());
        let top_level = std::mem::replace(&mut self.top_level, false);
        self.scopes.push(scope);
        self.inlining.push(name);
        self.inlined.0 += 1;
        let value = self.helper_body(f);
        self.inlining.pop();
        self.scopes.pop();
        self.barrier = barrier;
        self.top_level = top_level;
        value
    }

    /// The statements of a helper's body, then its tail value (checked against its return
    /// type).
    fn helper_body(&mut self, f: &syn::ItemFn) -> Value {
        let stmts = &f.block.stmts;
        self.register_helpers(stmts);
        let Some((Stmt::Expr(tail, None), init)) = stmts.split_last() else {
            return Value::Scalar(self.error(
                f.block.span(),
                "a helper must end with its value (an expression without `;`); `return` is \
                 not supported",
            ));
        };
        for stmt in init {
            self.stmt(stmt);
        }
        let value = self.value(tail);
        let syn::ReturnType::Type(_, ty) = &f.sig.output else {
            return value; // (rejected at registration)
        };
        match (ty.as_ref(), &value) {
            (syn::Type::Tuple(t), Value::Tuple(parts)) if t.elems.len() == parts.len() => value,
            (ty, _) => match (Shape::of(ty), &value) {
                (Some(Shape::Number), Value::Scalar(_)) => value,
                (Some(Shape::Array(n)), Value::Array(ids)) if ids.len() == n => value,
                _ => Value::Scalar(self.error(
                    tail.span(),
                    format!(
                        "the value of `{}` does not have its return type `{}`",
                        f.sig.ident,
                        ty.to_token_stream_string()
                    ),
                )),
            },
        }
    }
}

/// Why a helper's signature is not supported (at its span), if it is not.
pub(crate) fn helper_signature_problem(
    sig: &syn::Signature,
) -> Option<(proc_macro2::Span, String)> {
    if !sig.generics.params.is_empty() || sig.asyncness.is_some() || sig.variadic.is_some() {
        return Some((
            sig.span(),
            "a helper is a plain `fn` without generics: `fn name(x: f64, q: [f64; 2]) -> f64`"
                .into(),
        ));
    }
    for input in &sig.inputs {
        let ok = match input {
            syn::FnArg::Typed(t) => {
                matches!(&*t.pat, Pat::Ident(p) if p.by_ref.is_none() && p.subpat.is_none())
                    && Shape::of(&t.ty).is_some()
            }
            syn::FnArg::Receiver(_) => false,
        };
        if !ok {
            return Some((
                input.span(),
                "a helper's arguments are named `f64` numbers or `[f64; n]` arrays".into(),
            ));
        }
    }
    let returns_ok = match &sig.output {
        syn::ReturnType::Default => false,
        syn::ReturnType::Type(_, ty) => match ty.as_ref() {
            syn::Type::Tuple(t) => {
                !t.elems.is_empty() && t.elems.iter().all(|e| Shape::of(e).is_some())
            }
            other => Shape::of(other).is_some(),
        },
    };
    let span = match &sig.output {
        syn::ReturnType::Default => sig.ident.span(),
        syn::ReturnType::Type(_, ty) => ty.span(),
    };
    (!returns_ok).then(|| {
        (
            span,
            "a helper returns an `f64`, an array `[f64; n]` or a tuple of them".into(),
        )
    })
}

/// `to_string` of a type's tokens without the spaces `quote` puts between them.
trait TokenString {
    fn to_token_stream_string(&self) -> String;
}

impl TokenString for syn::Type {
    fn to_token_stream_string(&self) -> String {
        quote::ToTokens::to_token_stream(self)
            .to_string()
            .replace(' ', "")
    }
}
