//! Detection of the form L = c/2 |u|^2 + V(q) (u = q^(k)), for which `retract_core::split`
//! gives an explicit symplectic splitting: every derivative below is read off the
//! mechanics' gradient and Hessian, and must vanish (or be constant) identically, by the
//! graph's simplifier, not only at some points; and L must be smooth in u.

use std::collections::HashSet;

use crate::ir::graph::{Func, Graph, Id, Node, Var, children};
use crate::mechanics::Mechanics;

/// Whether `node` depends on a jet variable accepted by `which` (`Var::Jet { order, .. }`).
fn depends_on(g: &Graph, node: Id, which: &dyn Fn(u8) -> bool) -> bool {
    let mut stack = vec![node];
    let mut seen = HashSet::new();
    while let Some(id) = stack.pop() {
        if !seen.insert(id) {
            continue;
        }
        let n = g.node(id);
        if let Node::Var(Var::Jet { order, .. }) = n
            && which(*order)
        {
            return true;
        }
        stack.extend(children(n));
    }
    false
}

/// Whether L has a kink in u: an `abs` or `signum` of an expression of u. There the
/// simplifier's derivatives (`signum`, then 0) are those of one side only, so the conditions
/// below, which hold identically for a smooth L only, would not see a term like
/// `|u_0| - u_0`.
fn kink_in_top(g: &Graph, lagrangian: Id, k: usize) -> bool {
    let mut stack = vec![lagrangian];
    let mut seen = HashSet::new();
    while let Some(id) = stack.pop() {
        if !seen.insert(id) {
            continue;
        }
        let n = g.node(id);
        if let Node::Unary(Func::Abs | Func::Signum, a) = *n
            && depends_on(g, a, &|order| order as usize == k)
        {
            return true;
        }
        stack.extend(children(n));
    }
    false
}

/// The weight c when L = c/2 |u|^2 + V(q) in dimension `n` and order `k`: L has no kink in u
/// ([`kink_in_top`]), dL/dq^(j) = 0 for 0 < j < k, d2L/du_a dq_b = 0, d2L/du_a du_b =
/// c delta_ab with c one node free of the jet, and dL/du = 0 at u = 0 (the Legendre
/// inverse's b = dL/du(x, 0)). For a smooth L these give dL/du = c u, hence the form.
pub fn kinetic_weight(g: &Graph, mech: &Mechanics, n: usize, k: usize) -> Option<Id> {
    let zero = |id: Id| g.is_const(id, 0.0);
    let middle_free = (n..k * n).all(|r| zero(mech.gradient[r]));
    let u = |a: usize| k * n + a;
    let uncoupled = (0..n).all(|a| (0..n).all(|b| zero(mech.hessian[u(a)][b])));
    let c = mech.hessian[u(0)][u(0)];
    let diagonal = (0..n).all(|a| {
        (0..n).all(|b| {
            let entry = mech.hessian[u(a)][u(b)];
            if a == b { entry == c } else { zero(entry) }
        })
    });
    let no_linear_term = mech
        .legendre_inverse
        .as_ref()
        .is_some_and(|inverse| inverse.b.iter().all(|&b| zero(b)));
    let c_constant = !depends_on(g, c, &|_| true);
    let smooth = !kink_in_top(g, mech.lagrangian, k);
    (middle_free && uncoupled && diagonal && no_linear_term && c_constant && smooth).then_some(c)
}

#[cfg(test)]
mod tests {
    use crate::attribute::lagrangian::try_expand;

    /// Whether the expansion of `body` (order 2 on R^2, parameters `tau` and `m`) implements
    /// `Separable`.
    fn separable(body: &str) -> bool {
        let item = format!(
            "fn l(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], tau: f64, m: f64) -> f64 {{ {body} }}"
        );
        let out = crate::util::pretty_expansion(try_expand, "order = 2", &item).expect("expands");
        out.contains("Separable")
    }

    #[test]
    fn the_separable_form_is_detected() {
        assert!(separable(
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)"
        ));
        // a weight that is a parameter, and a potential with a transcendental function
        assert!(separable(
            "0.5 * m * (ddq[0] * ddq[0] + ddq[1] * ddq[1]) - tau * (q[0] * q[1]).cos()"
        ));
    }

    #[test]
    fn other_forms_are_not_separable() {
        for body in [
            // depends on q'
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + dq[0] * dq[0]",
            // couples u and q
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + q[0] * ddq[1]",
            // a weight that depends on q
            "0.5 * (1.0 + q[0] * q[0]) * (ddq[0].powi(2) + ddq[1].powi(2))",
            // different weights
            "0.5 * (ddq[0].powi(2) + 2.0 * ddq[1].powi(2)) + tau * q[0]",
            // a term linear in u
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau * ddq[0]",
            // not quadratic in u
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + 0.1 * ddq[0].powi(4)",
            // off-diagonal
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + 0.1 * ddq[0] * ddq[1]",
            // a kink in u, with zero slope on one side (its simplified derivatives vanish)
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau * (ddq[0].abs() - ddq[0]) + m * q[0]",
            "0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau * (ddq[1] * q[0]).abs()",
        ] {
            assert!(!separable(body), "{body}");
        }
    }
}
