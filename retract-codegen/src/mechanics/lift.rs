//! The lift of a discretization map to $T^{(k-1)}Q$ and the derivatives the integrator needs
//! (`#[discretization_map]`), as graph nodes.
//!
//! The map's body is lowered with q and v as one 2n-dimensional point of order 0: q_a is
//! `Var::Jet { order: 0, index: a }` and v_a is `Var::Jet { order: 0, index: n + a }`. The
//! total derivative over that 2n-dimensional jet is then the D of the lift, D q^(i) =
//! q^(i+1) and D v^(i) = v^(i+1): component j of the lift of R_s is D^j R_s, a function of
//! x_i = q^(i) (`Jet { order: i, index: a }`) and xi_i = v^(i) (`Jet { order: i, index: n + a
//! }`), i <= j.

use crate::ir::diff::{Differentiator, total_derivative};
use crate::ir::graph::{Graph, Id, Var};

/// The lifted map and its derivatives; every matrix is row-major nk x nk over the flat
/// index `j * n + a` of component a of block j.
pub struct Lift {
    /// `points[s][j * n + a]` = D^j R_{s+1, a}.
    pub points: [Vec<Id>; 2],
    /// `jacobians[s][0]` = dR_{s+1}/dx and `jacobians[s][1]` = dR_{s+1}/dxi.
    pub jacobians: [[Vec<Id>; 2]; 2],
    /// The Hessian of phi = w2 . R2 - w1 . R1 (w as `Var::Covector`): `[xx, x_xi, xi_xi]`,
    /// rows x for `x_xi`.
    pub hessian: [Vec<Id>; 3],
}

/// The variable x_{j, a} (`tangent` false) or xi_{j, a} (`tangent` true).
pub fn lifted_var(n: usize, tangent: bool, j: usize, a: usize) -> Var {
    Var::Jet {
        order: j as u8,
        index: (a + if tangent { n } else { 0 }) as u32,
    }
}

/// The covector component `w_{side+1}[j][a]`.
fn covector(side: usize, j: usize, a: usize) -> Var {
    Var::Covector {
        side: side as u8,
        block: j as u8,
        index: a as u32,
    }
}

/// Lifts the map `r = [R1, R2]` (n components each, in q and v) to order k and
/// differentiates it.
pub fn lift(g: &mut Graph, r: &[Vec<Id>; 2], n: usize, k: usize) -> Lift {
    let mut d = Differentiator::default();
    let points: [Vec<Id>; 2] = core::array::from_fn(|s| {
        let mut out = r[s].clone();
        for j in 1..k {
            for a in 0..n {
                let previous = out[(j - 1) * n + a];
                let next = total_derivative(g, &mut d, previous, 2 * n, j);
                out.push(next);
            }
        }
        out
    });
    let nk = n * k;
    let vars = |tangent: bool| -> Vec<Var> {
        (0..nk)
            .map(|c| lifted_var(n, tangent, c / n, c % n))
            .collect()
    };
    let (x_vars, xi_vars) = (vars(false), vars(true));
    let jacobian = |g: &mut Graph, d: &mut Differentiator, f: &[Id], vs: &[Var]| -> Vec<Id> {
        f.iter()
            .flat_map(|&e| vs.iter().map(|&v| (e, v)).collect::<Vec<_>>())
            .map(|(e, v)| d.diff(g, e, v))
            .collect()
    };
    let jacobians: [[Vec<Id>; 2]; 2] = [0, 1].map(|s| {
        [
            jacobian(g, &mut d, &points[s], &x_vars),
            jacobian(g, &mut d, &points[s], &xi_vars),
        ]
    });
    // phi = w2 . R2 - w1 . R1
    let mut phi = g.constant(0.0);
    for (s, side) in points.iter().enumerate() {
        for (c, &e) in side.iter().enumerate() {
            let w = g.var(covector(s, c / n, c % n));
            let term = g.mul(w, e);
            phi = if s == 0 {
                g.sub(phi, term)
            } else {
                g.add_op(phi, term)
            };
        }
    }
    let grad_x: Vec<Id> = x_vars.iter().map(|&v| d.diff(g, phi, v)).collect();
    let grad_xi: Vec<Id> = xi_vars.iter().map(|&v| d.diff(g, phi, v)).collect();
    let xx = symmetric(g, &mut d, &grad_x, &x_vars);
    let x_xi = jacobian(g, &mut d, &grad_x, &xi_vars);
    let xi_xi = symmetric(g, &mut d, &grad_xi, &xi_vars);
    Lift {
        points,
        jacobians,
        hessian: [xx, x_xi, xi_xi],
    }
}

/// The Jacobian of a gradient, which is symmetric: the upper triangle, mirrored (shared ids).
fn symmetric(g: &mut Graph, d: &mut Differentiator, gradient: &[Id], vars: &[Var]) -> Vec<Id> {
    let m = vars.len();
    let mut out = vec![g.constant(0.0); m * m];
    for r in 0..m {
        for c in r..m {
            let h = d.diff(g, gradient[r], vars[c]);
            out[r * m + c] = h;
            out[c * m + r] = h;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ir::graph::tests::show;

    #[test]
    fn the_lift_of_a_product_is_its_total_derivative() {
        // n = 1: R1 = q, R2 = q + v + q v^2; D R2 = q' (v^2 + 1) + (1 + 2 q v) v'
        let mut g = Graph::default();
        let q = g.var(lifted_var(1, false, 0, 0));
        let v = g.var(lifted_var(1, true, 0, 0));
        let v2 = g.powi(v, 2);
        let qv2 = g.mul(q, v2);
        let qv = g.add_op(q, v);
        let r2 = g.add_op(qv, qv2);
        let lift = lift(&mut g, &[vec![q], vec![r2]], 1, 2);
        assert_eq!(show(&g, lift.points[0][1]), "q1_0");
        assert_eq!(
            show(&g, lift.points[1][1]),
            "((q1_0 * (q0_1^2 + 1)) + ((1 + (q0_0 * (2 * q0_1))) * q1_1))"
        );
        // dR2_1/dxi_1 = 1 + 2 q v, the (1, 1) entry of jacobians[1][1]
        assert_eq!(
            show(&g, lift.jacobians[1][1][3]),
            "(1 + (q0_0 * (2 * q0_1)))"
        );
    }
}
