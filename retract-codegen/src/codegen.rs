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
//! in the last bits only.

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use crate::graph::{Func, Graph, Id, Node, Var, children};

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
    let mut emitter = Emitter {
        g,
        leaves,
        inline: &inline,
        reciprocal: &reciprocal,
        latency: Vec::new(),
    };
    emitter.latency = vec![0; len];
    for i in 0..len {
        emitter.latency[i] = emitter.estimate(Id(i as u32));
    }
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
    /// Estimated cycles from the function's inputs to each node's value.
    latency: Vec<u32>,
}

/// Latencies (cycles) of the operations on a current x86 core, for the balancing only.
const ADD: u32 = 4;
const DIV: u32 = 14;
const SQRT: u32 = 18;
const CALL: u32 = 40;

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

impl Emitter<'_> {
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

    /// The operands of the chain of `kind` at `id` with their signs (`true`: negated), through
    /// inlined nodes of the same chain and negations; `Neg` of a node of the other kind (or a
    /// bound one) is an operand with a sign.
    fn operands(
        &self,
        id: Id,
        kind: Chain,
        in_loop: bool,
        negate: bool,
        out: &mut Vec<(Operand, bool)>,
    ) {
        let through = |c: Id| !in_loop && self.inline[c.0 as usize];
        let push = |this: &Self, c: Id, negate: bool, out: &mut Vec<(Operand, bool)>| {
            if through(c)
                && (this.chain(c, in_loop) == Some(kind) || matches!(this.g.node(c), Node::Neg(_)))
            {
                this.operands(c, kind, in_loop, negate, out);
            } else {
                out.push((Operand::Node(c), negate));
            }
        };
        match *self.g.node(id) {
            Node::Neg(a) => push(self, a, !negate, out),
            Node::Add(a, b) if kind == Chain::Sum => {
                push(self, a, negate, out);
                push(self, b, negate, out);
            }
            Node::Sub(a, b) if kind == Chain::Sum => {
                push(self, a, negate, out);
                push(self, b, !negate, out);
            }
            Node::Mul(a, b) if kind == Chain::Product => {
                push(self, a, negate, out);
                push(self, b, false, out);
            }
            Node::Div(a, b) if kind == Chain::Product => {
                push(self, a, negate, out);
                out.push((Operand::Reciprocal(b), false));
            }
            _ => out.push((Operand::Node(id), negate)),
        }
    }

    fn operand_latency(&self, op: Operand) -> u32 {
        match op {
            Operand::Node(id) => self.latency[id.0 as usize],
            Operand::Reciprocal(id) => self.latency[id.0 as usize] + DIV,
        }
    }

    /// The chain emitted at `id`: its own, or for a negation of an inlined chain, that chain.
    fn head(&self, id: Id, in_loop: bool) -> Option<Chain> {
        match *self.g.node(id) {
            Node::Neg(a) if !in_loop && self.inline[a.0 as usize] => self.chain(a, in_loop),
            _ => self.chain(id, in_loop),
        }
    }

    /// Latency of `id` as emitted (function level), from its children's.
    fn estimate(&self, id: Id) -> u32 {
        let l = |c: Id| self.latency[c.0 as usize];
        if let Some(kind) = self.head(id, false) {
            let mut ops = Vec::new();
            self.operands(id, kind, false, false, &mut ops);
            let latencies = ops.iter().map(|&(op, _)| ((), self.operand_latency(op)));
            return earliest_first(latencies.collect(), |(), ()| ()).map_or(0, |(_, l)| l);
        }
        match *self.g.node(id) {
            Node::Const(_) | Node::Var(_) | Node::Named(_) => 0,
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) => l(a).max(l(b)) + ADD,
            Node::Div(a, b) => l(a).max(l(b)) + DIV,
            Node::Neg(a) => l(a) + 1,
            Node::Powi(a, n) => l(a) + ADD * (32 - n.unsigned_abs().leading_zeros()).max(1),
            Node::Unary(Func::Sqrt, a) => l(a) + SQRT,
            Node::Unary(Func::Abs | Func::Signum, a) => l(a) + 1,
            Node::Unary(_, a) => l(a) + CALL,
            Node::Powf(a, b) | Node::Atan2(a, b) | Node::Hypot(a, b) => l(a).max(l(b)) + CALL,
            Node::Sum { .. } => CALL,
        }
    }

    /// A chain as a balanced tree: repeatedly combines the two operands available first.
    fn balanced(&self, id: Id, kind: Chain, in_loop: bool) -> TokenStream {
        let mut ops = Vec::new();
        self.operands(id, kind, in_loop, false, &mut ops);
        // ((negated, tokens), latency)
        let mut terms: Vec<((bool, TokenStream), u32)> = ops
            .iter()
            .map(|&(op, negate)| {
                let tokens = match op {
                    Operand::Node(c) => self.reference(c, in_loop),
                    Operand::Reciprocal(b) => reciprocal_name(b),
                };
                ((negate, tokens), self.operand_latency(op))
            })
            .collect();
        if kind == Chain::Product {
            // the sign of a product is carried to its end
            let negate = terms.iter().filter(|t| t.0.0).count() % 2 == 1;
            for (i, t) in terms.iter_mut().enumerate() {
                t.0.0 = i == 0 && negate;
            }
        }
        let combined = earliest_first(terms, |a, b| match kind {
            Chain::Product => {
                let ((na, a), (nb, b)) = (a, b);
                (na ^ nb, quote!((#a * #b)))
            }
            Chain::Sum => signed_add(a, b),
        });
        match combined {
            None => quote!(0.0),
            Some(((false, tokens), _)) => tokens,
            Some(((true, tokens), _)) => quote!(-#tokens),
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
/// the two known first (the earlier position on ties) into a term known `ADD` later: the
/// balanced tree of least latency. `None` for no terms.
fn earliest_first<T>(
    mut terms: Vec<(T, u32)>,
    mut merge: impl FnMut(T, T) -> T,
) -> Option<(T, u32)> {
    let take = |terms: &mut Vec<(T, u32)>| {
        let at = (0..terms.len()).min_by_key(|&i| (terms[i].1, i))?;
        Some(terms.remove(at))
    };
    while terms.len() > 1 {
        let (a, la) = take(&mut terms)?;
        let (b, lb) = take(&mut terms)?;
        terms.push((merge(a, b), la.max(lb) + ADD));
    }
    terms.pop()
}

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

    /// The roots as emitted, evaluated at `x`.
    fn emitted(g: &Graph, roots: &[Id], x: &[f64]) -> Vec<f64> {
        let code = emit(g, roots, &Names);
        let stmts = &code.stmts;
        let block: syn::Block = syn::parse2(quote!({ #stmts })).expect("statements");
        let mut env: HashMap<String, f64> = (0..x.len()).map(|i| (format!("x{i}"), x[i])).collect();
        for stmt in &block.stmts {
            let syn::Stmt::Local(local) = stmt else {
                panic!("not a let: {stmt:?}")
            };
            let syn::Pat::Type(typed) = &local.pat else {
                panic!("untyped let")
            };
            let syn::Pat::Ident(name) = &*typed.pat else {
                panic!("pattern")
            };
            let init = &local.init.as_ref().expect("initialiser").expr;
            env.insert(name.ident.to_string(), evaluate(init, &env));
        }
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
