//! Symbolic differentiation and substitution on the [`Graph`].
//!
//! Forward mode with a memo keyed by (node, variable): a gradient over m variables costs
//! O(m * nodes), and every derivative is itself hash-consed, so shared subexpressions of the
//! gradient and Hessian are built once. Two sweeps cost O(nodes) instead: the derivative
//! along one direction ([`directional`], e.g. the total time derivative of many functions at
//! once) and the gradient of one scalar by reverse accumulation ([`reverse_gradient`]); the
//! three share one chain rule per node kind ([`chain_rule`]).

use std::collections::{HashMap, HashSet};

use crate::ir::graph::{Func, Graph, Id, Node, Var, children};

/// The nodes below `root` (itself included) that `pending` accepts, each once, in ascending
/// order, which is children before parents (a node's children have smaller ids); found with
/// an explicit stack. The recursive rules below run on them in this order, so every child is
/// already memoised when its parent's rule asks for it: the recursion is one level deep
/// however deep the expression (an unrolled recurrence of 10 000 iterations is tens of
/// thousands of nodes deep, which overflowed the compiler's stack).
fn pending_below(g: &Graph, root: Id, pending: impl Fn(Id) -> bool) -> Vec<Id> {
    let mut seen = HashSet::new();
    let mut stack = vec![root];
    let mut out = Vec::new();
    while let Some(n) = stack.pop() {
        if pending(n) && seen.insert(n) {
            out.push(n);
            stack.extend(children(g.node(n)));
        }
    }
    out.sort_unstable();
    out
}

/// Memoised derivatives.
#[derive(Default)]
pub struct Differentiator {
    memo: HashMap<(Id, Var), Id>,
}

impl Differentiator {
    /// d(node)/d(var).
    pub fn diff(&mut self, g: &mut Graph, node: Id, var: Var) -> Id {
        if let Some(&d) = self.memo.get(&(node, var)) {
            return d;
        }
        for n in pending_below(g, node, |n| !self.memo.contains_key(&(n, var))) {
            let d = self.rule(g, n, var);
            self.memo.insert((n, var), d);
        }
        self.memo[&(node, var)]
    }

    /// The derivative of `node` from those of its children (already memoised).
    fn rule(&mut self, g: &mut Graph, node: Id, var: Var) -> Id {
        let tangents: Vec<Id> = match g.node(node) {
            Node::Var(v) => return g.constant(if *v == var { 1.0 } else { 0.0 }),
            other => children(other),
        }
        .into_iter()
        .map(|c| self.memo[&(c, var)])
        .collect();
        chain_rule(g, node, &tangents)
    }
}

/// The tangent of `node` (not a symbol) from the tangents of its children, in the order of
/// [`children`]: one arm per node kind, linear in the tangents (so that a tangent that is
/// zero drops its term, which the reverse mode uses to take one child's share).
pub fn chain_rule(g: &mut Graph, node: Id, tangents: &[Id]) -> Id {
    let t = |i: usize| tangents.get(i).copied();
    let zero = g.constant(0.0);
    let (da, db) = (t(0).unwrap_or(zero), t(1).unwrap_or(zero));
    match g.node(node).clone() {
        Node::Const(_) | Node::Named(_) | Node::Var(_) => zero,
        Node::Add(..) => g.add_op(da, db),
        Node::Sub(..) => g.sub(da, db),
        Node::Mul(a, b) => {
            let l = g.mul(da, b);
            let r = g.mul(a, db);
            g.add_op(l, r)
        }
        Node::Div(_, b) => {
            // (a/b)' = a'/b - (a/b) b'/b
            let l = g.div(da, b);
            let ratio = g.mul(node, db);
            let r = g.div(ratio, b);
            g.sub(l, r)
        }
        Node::Neg(..) => g.neg(da),
        Node::Powi(a, n) => {
            if g.is_const(da, 0.0) {
                return da;
            }
            // a^(n-1), or a^n / a where n - 1 is below i32::MIN
            let p = match n.checked_sub(1) {
                Some(m) => g.powi(a, m),
                None => g.div(node, a),
            };
            let c = g.constant(n as f64);
            let cp = g.mul(c, p);
            g.mul(cp, da)
        }
        Node::Powf(a, b) => {
            // exponent b does not depend on the jet: (a^b)' = b a^(b-1) a'
            if g.is_const(da, 0.0) {
                return da;
            }
            let one = g.constant(1.0);
            let bm1 = g.sub(b, one);
            let p = g.powf(a, bm1);
            let bp = g.mul(b, p);
            g.mul(bp, da)
        }
        Node::Unary(f, a) => {
            if g.is_const(da, 0.0) {
                return da;
            }
            let outer = match f {
                // 1 / (2 sqrt a)
                Func::Sqrt => {
                    let two = g.constant(2.0);
                    let den = g.mul(two, node);
                    let one = g.constant(1.0);
                    g.div(one, den)
                }
                Func::Exp => node,
                Func::Ln => {
                    let one = g.constant(1.0);
                    g.div(one, a)
                }
                Func::Sin => g.unary(Func::Cos, a),
                Func::Cos => {
                    let s = g.unary(Func::Sin, a);
                    g.neg(s)
                }
                // 1 + tan^2, 1 - tanh^2
                Func::Tan => {
                    let one = g.constant(1.0);
                    let sq = g.powi(node, 2);
                    g.add_op(one, sq)
                }
                Func::Tanh => {
                    let one = g.constant(1.0);
                    let sq = g.powi(node, 2);
                    g.sub(one, sq)
                }
                Func::Abs => g.unary(Func::Signum, a),
                Func::Signum => return g.constant(0.0),
                // c_k' = (k c_{k+2} - c_{k+1}) / 2
                Func::Stumpff(k) => {
                    let next = g.unary(Func::Stumpff(k + 1), a);
                    let after = g.unary(Func::Stumpff(k + 2), a);
                    let scaled = g.constant(f64::from(k));
                    let scaled = g.mul(scaled, after);
                    let difference = g.sub(scaled, next);
                    let half = g.constant(0.5);
                    g.mul(half, difference)
                }
                _ => inverse_and_hyperbolic(g, f, node, a),
            };
            g.mul(outer, da)
        }
        Node::Atan2(y, x) => {
            // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2), dy = da, dx = db
            let xdy = g.mul(x, da);
            let ydx = g.mul(y, db);
            let num = g.sub(xdy, ydx);
            if g.is_const(num, 0.0) {
                return num;
            }
            let x2 = g.powi(x, 2);
            let y2 = g.powi(y, 2);
            let den = g.add_op(x2, y2);
            g.div(num, den)
        }
        Node::Hypot(a, b) => {
            // (a da + b db) / hypot(a, b)
            let l = g.mul(a, da);
            let r = g.mul(b, db);
            let num = g.add_op(l, r);
            g.div(num, node)
        }
        Node::Sum { param, .. } => g.sum(param, da),
    }
}

/// f'(a) for the functions beyond the elementary ones (`node` = f(a)):
/// asin' = 1/sqrt(1 - a^2), acos' = -1/sqrt(1 - a^2), atan' = 1/(1 + a^2), sinh' = cosh,
/// cosh' = sinh, cbrt' = 1/(3 cbrt(a)^2), ln_1p' = 1/(1 + a), exp_m1' = exp(a),
/// log2' = 1/(a ln 2), log10' = 1/(a ln 10).
fn inverse_and_hyperbolic(g: &mut Graph, f: Func, node: Id, a: Id) -> Id {
    let one = g.constant(1.0);
    let one_minus_square = |g: &mut Graph| {
        let sq = g.powi(a, 2);
        let d = g.sub(one, sq);
        g.unary(Func::Sqrt, d)
    };
    match f {
        Func::Asin => {
            let r = one_minus_square(g);
            g.div(one, r)
        }
        Func::Acos => {
            let r = one_minus_square(g);
            let q = g.div(one, r);
            g.neg(q)
        }
        Func::Atan => {
            let sq = g.powi(a, 2);
            let d = g.add_op(one, sq);
            g.div(one, d)
        }
        Func::Sinh => g.unary(Func::Cosh, a),
        Func::Cosh => g.unary(Func::Sinh, a),
        Func::Cbrt => {
            let three = g.constant(3.0);
            let sq = g.powi(node, 2);
            let d = g.mul(three, sq);
            g.div(one, d)
        }
        Func::Ln1p => {
            let d = g.add_op(one, a);
            g.div(one, d)
        }
        Func::ExpM1 => g.unary(Func::Exp, a),
        Func::Log2 | Func::Log10 => {
            let base: f64 = if f == Func::Log2 { 2.0 } else { 10.0 };
            let ln = g.constant(base.ln());
            let d = g.mul(a, ln);
            g.div(one, d)
        }
        // the elementary functions are differentiated by the caller
        _ => g.constant(f64::NAN),
    }
}

/// Rebuilds `node` with every variable `v` for which `map(v)` is `Some` replaced; memoised
/// in `memo`, which must only be shared between calls with the same `map`.
pub fn substitute(
    g: &mut Graph,
    node: Id,
    map: &dyn Fn(&mut Graph, Var) -> Option<Id>,
    memo: &mut HashMap<Id, Id>,
) -> Id {
    if let Some(&done) = memo.get(&node) {
        return done;
    }
    for n in pending_below(g, node, |n| !memo.contains_key(&n)) {
        let out = rebuild(g, n, map, memo);
        memo.insert(n, out);
    }
    memo[&node]
}

/// `node` rebuilt from its substituted children (already in `memo`, see [`pending_below`]).
fn rebuild(
    g: &mut Graph,
    node: Id,
    map: &dyn Fn(&mut Graph, Var) -> Option<Id>,
    memo: &mut HashMap<Id, Id>,
) -> Id {
    let mut sub = |g: &mut Graph, id: Id| substitute(g, id, map, memo);
    let out = match g.node(node).clone() {
        Node::Const(_) | Node::Named(_) => node,
        Node::Var(v) => map(g, v).unwrap_or(node),
        Node::Add(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.add_op(a, b)
        }
        Node::Sub(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.sub(a, b)
        }
        Node::Mul(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.mul(a, b)
        }
        Node::Div(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.div(a, b)
        }
        Node::Neg(a) => {
            let a = sub(g, a);
            g.neg(a)
        }
        Node::Powi(a, n) => {
            let a = sub(g, a);
            g.powi(a, n)
        }
        Node::Powf(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.powf(a, b)
        }
        Node::Unary(f, a) => {
            let a = sub(g, a);
            g.unary(f, a)
        }
        Node::Atan2(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.atan2(a, b)
        }
        Node::Hypot(a, b) => {
            let (a, b) = (sub(g, a), sub(g, b));
            g.hypot(a, b)
        }
        Node::Sum { param, body } => {
            let b = sub(g, body);
            g.sum(param, b)
        }
    };
    memo.insert(node, out);
    out
}

/// The derivatives of `roots` along the direction in which each symbol `v` moves at the rate
/// `seed(v)` (a symbol without one is fixed): one forward sweep over the nodes below the
/// roots, D f = sum_v df/dv seed(v), each node's tangent built once for all roots.
pub fn directional(
    g: &mut Graph,
    roots: &[Id],
    seed: &dyn Fn(&mut Graph, Var) -> Option<Id>,
) -> Vec<Id> {
    let mut tangent: HashMap<Id, Id> = HashMap::new();
    let mut out = Vec::with_capacity(roots.len());
    for &root in roots {
        for n in pending_below(g, root, |n| !tangent.contains_key(&n)) {
            let t = match g.node(n).clone() {
                Node::Var(v) => seed(g, v).unwrap_or_else(|| g.constant(0.0)),
                other => {
                    let tangents: Vec<Id> = children(&other).iter().map(|c| tangent[c]).collect();
                    chain_rule(g, n, &tangents)
                }
            };
            tangent.insert(n, t);
        }
        out.push(tangent[&root]);
    }
    out
}

/// The total time derivatives D f of `roots` over jets up to q^(top) on R^n
/// ([`total_derivative`]), as one [`directional`] sweep: q^(j) moves at the rate q^(j+1).
pub fn total_derivatives(g: &mut Graph, roots: &[Id], n: usize, top: usize) -> Vec<Id> {
    let next = |g: &mut Graph, v: Var| match v {
        Var::Jet { order, index } if usize::from(order) < top && (index as usize) < n => {
            Some(g.var(Var::Jet {
                order: order + 1,
                index,
            }))
        }
        _ => None,
    };
    directional(g, roots, &next)
}

/// The gradient of the scalar `f` in `vars` by reverse accumulation: the adjoint of each node
/// is the sum over its parents of the parent's adjoint times the parent's partial derivative
/// in it (the parent's [`chain_rule`] with that child's tangent set to the parent's adjoint,
/// the others zero), swept from `f` down; O(nodes) new nodes for the whole gradient. `None`
/// where `f` has a sum over a slice parameter (its body is a function of the loop's element:
/// [`Differentiator`] differentiates it).
pub fn reverse_gradient(g: &mut Graph, f: Id, vars: &[Var]) -> Option<Vec<Id>> {
    let nodes = pending_below(g, f, |_| true);
    // the nodes through which some variable of `vars` reaches f (the others get no adjoint)
    let mut varying: HashSet<Id> = HashSet::new();
    for &n in &nodes {
        let node = g.node(n);
        if matches!(node, Node::Sum { .. }) {
            return None;
        }
        let on = match node {
            Node::Var(v) => vars.contains(v),
            other => children(other).iter().any(|c| varying.contains(c)),
        };
        if on {
            varying.insert(n);
        }
    }
    let zero = g.constant(0.0);
    let mut adjoint: HashMap<Id, Id> = HashMap::new();
    adjoint.insert(f, g.constant(1.0));
    for &n in nodes.iter().rev() {
        let Some(&a) = adjoint.get(&n) else {
            continue;
        };
        let kids = children(g.node(n));
        for (i, &c) in kids.iter().enumerate() {
            // (a child that appears twice takes both shares at once)
            if !varying.contains(&c) || kids[..i].contains(&c) {
                continue;
            }
            let tangents: Vec<Id> = kids
                .iter()
                .map(|&k| if k == c { a } else { zero })
                .collect();
            let share = chain_rule(g, n, &tangents);
            if g.is_const(share, 0.0) {
                continue;
            }
            let sum = match adjoint.get(&c) {
                Some(&before) => g.add_op(before, share),
                None => share,
            };
            adjoint.insert(c, sum);
        }
    }
    Some(
        vars.iter()
            .map(|&v| {
                let id = g.var(v);
                adjoint.get(&id).copied().unwrap_or(zero)
            })
            .collect(),
    )
}

/// The total time derivative $D f = \sum_{j < top} \sum_i \partial f/\partial q^{(j)}_i \thinspace q^{(j+1)}_i$
/// over jets up to q^(top).
pub fn total_derivative(g: &mut Graph, d: &mut Differentiator, f: Id, n: usize, top: usize) -> Id {
    let mut acc = g.constant(0.0);
    for order in 0..top {
        for index in 0..n {
            let var = Var::Jet {
                order: order as u8,
                index: index as u32,
            };
            let partial = d.diff(g, f, var);
            if g.is_const(partial, 0.0) {
                continue;
            }
            let next = g.var(Var::Jet {
                order: order as u8 + 1,
                index: index as u32,
            });
            let term = g.mul(partial, next);
            acc = g.add_op(acc, term);
        }
    }
    acc
}

/// `roots` rewritten in the chart jet: every `Var::Jet { order: j, index: a }` of the function
/// as written becomes `jet[j][a]`, an expression in the chart jet.
pub fn substitute_jet(g: &mut Graph, roots: &[Id], jet: Vec<Vec<Id>>) -> Vec<Id> {
    let map = move |_: &mut Graph, v: Var| match v {
        Var::Jet { order, index } => Some(jet[order as usize][index as usize]),
        _ => None,
    };
    let mut memo = HashMap::new();
    roots
        .iter()
        .map(|&root| substitute(g, root, &map, &mut memo))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::graph::tests::show;

    fn q(g: &mut Graph, order: u8, index: u32) -> Id {
        g.var(Var::Jet { order, index })
    }

    fn d_of(build: impl Fn(&mut Graph, Id) -> Id) -> String {
        let mut g = Graph::default();
        let x = q(&mut g, 0, 0);
        let f = build(&mut g, x);
        let mut d = Differentiator::default();
        let df = d.diff(&mut g, f, Var::Jet { order: 0, index: 0 });
        show(&g, df)
    }

    #[test]
    fn derivative_table() {
        assert_eq!(d_of(|g, x| g.powi(x, 3)), "(3 * q0_0^2)");
        assert_eq!(d_of(|g, x| g.unary(Func::Sin, x)), "cos(q0_0)");
        assert_eq!(d_of(|g, x| g.unary(Func::Cos, x)), "-sin(q0_0)");
        assert_eq!(d_of(|g, x| g.unary(Func::Exp, x)), "exp(q0_0)");
        assert_eq!(d_of(|g, x| g.unary(Func::Ln, x)), "(1 / q0_0)");
        assert_eq!(
            d_of(|g, x| g.unary(Func::Sqrt, x)),
            "(1 / (2 * sqrt(q0_0)))"
        );
        assert_eq!(d_of(|g, x| g.unary(Func::Tanh, x)), "(1 - tanh(q0_0)^2)");
        assert_eq!(d_of(|g, x| g.unary(Func::Abs, x)), "signum(q0_0)");
        assert_eq!(
            d_of(|g, x| {
                let one = g.constant(1.0);
                g.div(one, x)
            }),
            "-((1 / q0_0) / q0_0)"
        );
        assert_eq!(
            d_of(|g, x| {
                let y = q(g, 0, 1);
                g.atan2(y, x)
            }),
            "(-q0_1 / (q0_0^2 + q0_1^2))"
        );
        assert_eq!(
            d_of(|g, x| {
                let c = g.constant(1.5);
                g.powf(x, c)
            }),
            "(1.5 * sqrt(q0_0))"
        );
        assert_eq!(
            d_of(|g, x| {
                let y = q(g, 0, 1);
                g.mul(x, y)
            }),
            "q0_1"
        );
    }

    #[test]
    fn substitution_rebuilds_and_simplifies() {
        let mut g = Graph::default();
        let x = q(&mut g, 0, 0);
        let y = q(&mut g, 0, 1);
        let f = g.mul(x, y);
        let mut memo = HashMap::new();
        let zero_y =
            |g: &mut Graph, v: Var| (v == Var::Jet { order: 0, index: 1 }).then(|| g.constant(0.0));
        let s = substitute(&mut g, f, &zero_y, &mut memo);
        assert_eq!(show(&g, s), "0");
    }

    #[test]
    fn total_derivative_of_a_jet_product() {
        // D(q * q') = q'^2 + q q''
        let mut g = Graph::default();
        let x = q(&mut g, 0, 0);
        let v = q(&mut g, 1, 0);
        let f = g.mul(x, v);
        let mut d = Differentiator::default();
        let df = total_derivative(&mut g, &mut d, f, 1, 2);
        assert_eq!(show(&g, df), "(q1_0^2 + (q0_0 * q2_0))");
    }
}
