//! Straight-line Rust from graph nodes.
//!
//! For a set of roots, every needed non-leaf node that is used more than once becomes one
//! `let __tN: f64 = ...;` in id order (children first), so each shared subexpression is
//! computed once; a node used once is inlined, parenthesised, into its parent. Leaves (symbols,
//! constants, named consts) are inlined. A [`Node::Sum`] becomes a run-time loop over its
//! slice parameter; the nodes of its body that depend on the loop element are emitted inside
//! the loop, the others are hoisted before it.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::graph::{Graph, Id, Node, Var, children};

/// How a function names the leaves: symbol -> expression tokens.
pub trait Leaves {
    /// The expression for a symbol.
    fn var(&self, var: Var) -> TokenStream;
    /// The slice parameter `param` to loop over, e.g. `self.obstacles`.
    fn slice(&self, param: u16) -> TokenStream;
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
        if value < 0.0 {
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
    let inline: Vec<bool> = (0..len)
        .map(|i| top[i] && uses[i] == 1 && !pinned[i] && !is_leaf(g.node(Id(i as u32))))
        .collect();
    // a denominator shared by several function-level divisions is inverted once:
    // `let __rN = 1.0 / b;` and each `a / b` becomes `a * __rN`
    let mut denominators = vec![0usize; len];
    for (i, _) in top.iter().enumerate().filter(|(_, t)| **t) {
        if let Node::Div(_, b) = g.node(Id(i as u32)) {
            denominators[b.0 as usize] += 1;
        }
    }
    let reciprocal: Vec<bool> = denominators.iter().map(|&n| n >= 2).collect();
    let emitter = Emitter {
        g,
        leaves,
        inline: &inline,
        reciprocal: &reciprocal,
    };
    let reference = |id: Id| emitter.reference(id, false);
    let value = |id: Id| emitter.value(id, false);

    let mut stmts = TokenStream::new();
    let bind_reciprocal = |stmts: &mut TokenStream, id: Id| {
        let (r, b) = (reciprocal_name(id), reference(id));
        stmts.extend(quote!(let #r: f64 = 1.0 / #b;));
    };
    for (i, _) in reciprocal.iter().enumerate().filter(|(_, r)| **r) {
        let id = Id(i as u32);
        if is_leaf(g.node(id)) {
            bind_reciprocal(&mut stmts, id);
        }
    }
    for i in 0..len {
        let id = Id(i as u32);
        let node = g.node(id);
        if !top[i] || is_leaf(node) || inline[i] {
            continue;
        }
        let t = temp(id);
        if let Node::Sum { param, body } = *node {
            let marks = &body_of[i];
            let mut inside = TokenStream::new();
            for (j, &m) in marks.iter().enumerate() {
                let jd = Id(j as u32);
                if m && !is_leaf(g.node(jd)) {
                    let tj = temp(jd);
                    let v = emitter.value(jd, true);
                    inside.extend(quote!(let #tj: f64 = #v;));
                }
            }
            let slice = leaves.slice(param);
            let element = leaves.element();
            let b = emitter.reference(body, true);
            stmts.extend(quote! {
                let mut #t: f64 = 0.0;
                for #element in #slice.iter() {
                    #inside
                    #t += #b;
                }
            });
        } else {
            let v = value(id);
            stmts.extend(quote!(let #t: f64 = #v;));
        }
        if reciprocal[i] {
            bind_reciprocal(&mut stmts, id);
        }
    }
    Emitted {
        stmts,
        exprs: roots.iter().map(|&r| reference(r)).collect(),
    }
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
    inline: &'a [bool],
    /// Denominators bound once as a reciprocal (function level only).
    reciprocal: &'a [bool],
}

impl Emitter<'_> {
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
        match self.g.node(id).clone() {
            Node::Add(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a + #b)
            }
            Node::Sub(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a - #b)
            }
            Node::Mul(a, b) => {
                let (a, b) = (r(a), r(b));
                quote!(#a * #b)
            }
            Node::Div(a, b) if !in_loop && self.reciprocal[b.0 as usize] => {
                let (a, b) = (r(a), reciprocal_name(b));
                quote!(#a * #b)
            }
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
