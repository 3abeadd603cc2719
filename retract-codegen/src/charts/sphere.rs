//! The stage behind `#[higher_order_lagrangian(order = k, sphere)]`: a Lagrangian written in
//! ambient coordinates of the unit sphere S^2 (q, q', ..., q^(k) in R^3), composed with a
//! gnomonic chart so that the rest of the pipeline sees an order-k Lagrangian on R^2.
//!
//! The chart is a run-time parameter `sphere_chart = [c, e1, e2]` (a point c of S^2 and an
//! orthonormal basis of its tangent plane):
//!
//! phi(y) = s / |s|,  s = c + y_0 e1 + y_1 e2,
//!
//! and the ambient jet is its lift, q^(j) = D^j phi(y), with D the total derivative of the
//! chart jet (D y^(i) = y^(i+1)). Every ambient jet variable of L (and of its guards) is
//! replaced by that expression; |s| >= 1, so the chart itself needs no guard.

use quote::quote;

use super::{Chart, Frame};
use crate::ir::diff::{Differentiator, substitute_jet, total_derivative};
use crate::ir::graph::{Func, Graph, Id, Var};

/// The ambient jet q^(j)_a = D^j phi_a(y), j = 0..=k, as nodes in the chart jet
/// (`Var::Jet` with index 0, 1) and the chart parameter (`Var::Param { param: chart }`).
fn ambient_jet(g: &mut Graph, chart: u32, k: usize) -> Vec<[Id; 3]> {
    let p = |g: &mut Graph, i: u32| {
        g.var(Var::Param {
            param: chart,
            index: i,
        })
    };
    let y: [Id; 2] = [0, 1].map(|a| g.var(Var::Jet { order: 0, index: a }));
    let s: [Id; 3] = core::array::from_fn(|i| {
        let c = p(g, i as u32);
        let e1 = p(g, 3 + i as u32);
        let e2 = p(g, 6 + i as u32);
        let t1 = g.mul(y[0], e1);
        let t2 = g.mul(y[1], e2);
        let t = g.add_op(t1, t2);
        g.add_op(c, t)
    });
    let mut r2 = g.constant(0.0);
    for &si in &s {
        let sq = g.powi(si, 2);
        r2 = g.add_op(r2, sq);
    }
    let r = g.unary(Func::Sqrt, r2);
    let q0: [Id; 3] = s.map(|si| g.div(si, r));
    let mut d = Differentiator::default();
    let mut jet = vec![q0];
    for j in 1..=k {
        let previous = jet[j - 1];
        jet.push(previous.map(|f| total_derivative(g, &mut d, f, 2, j)));
    }
    jet
}

/// `roots` (L and its guarded expressions, in the ambient jet of an order-`order` function)
/// rewritten in the chart jet: each ambient `Var::Jet { order: j, index: a }` becomes
/// D^j phi_a(y). The chart parameter is number `chart`.
pub fn compose(g: &mut Graph, order: usize, chart: u32, roots: &[Id]) -> Vec<Id> {
    let jet = ambient_jet(g, chart, order);
    substitute_jet(g, roots, jet.into_iter().map(|q| q.to_vec()).collect())
}

/// The gnomonic chart of S^2 (module docs).
pub(crate) struct Sphere;

impl Chart for Sphere {
    fn option(&self) -> Option<&'static str> {
        Some("sphere")
    }

    fn frame(&self) -> Option<Frame> {
        Some(Frame {
            name: "sphere_chart",
            len: 9,
            runtime: ["SphereSystem", "chart", "with_chart"],
            doc: "The gnomonic chart's frame [c, e1, e2] (`retract::sphere::Chart::params`), set \
                  by `retract::sphere`; the north pole (c = z, e1 = x, e2 = y) after `new`.",
            initial: || quote!([0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
        })
    }

    fn chart_dim(&self, _dim: usize) -> usize {
        2
    }

    fn required_argument(&self, _order: usize, i: usize) -> Option<usize> {
        (i == 0).then_some(3)
    }

    fn wrong_argument(&self, _order: usize, _i: usize, _name: &syn::Ident, found: &str) -> String {
        format!(
            "a Lagrangian on the sphere (`sphere`) is written in ambient coordinates: its jet q, \
             q', ... must be `[f64; 3]`, not {found}"
        )
    }

    fn compose(&self, graph: &mut Graph, order: usize, frame: u32, roots: &[Id]) -> Vec<Id> {
        compose(graph, order, frame, roots)
    }

    fn description(&self, _dim: usize) -> String {
        "the unit sphere S^2, in the gnomonic chart `sphere_chart` (R^2; see `retract::sphere`),"
            .into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evaluates `node` at the chart jet `y[order][a]` and chart `[c, e1, e2]`.
    fn eval(g: &Graph, node: Id, y: &[[f64; 2]], chart: &[f64; 9]) -> f64 {
        let values = g.evaluate(node, &|n| match n {
            crate::ir::graph::Node::Var(Var::Jet { order, index }) => {
                Some(y[*order as usize][*index as usize])
            }
            crate::ir::graph::Node::Var(Var::Param { index, .. }) => Some(chart[*index as usize]),
            _ => None,
        });
        values[node.0 as usize].expect("evaluable")
    }

    #[test]
    fn the_ambient_jet_is_the_lift_of_the_chart() {
        // a chart at c = (0, 0, 1) with e1 = x, e2 = y, and the curve y(t) = (t + t^2, 2t):
        // q(t) = (t + t^2, 2t, 1) / sqrt(1 + (t + t^2)^2 + 4 t^2); compare q, q' and q'' at
        // t = 0.3 with central differences of q(t).
        let chart = [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let mut g = Graph::default();
        let jet = ambient_jet(&mut g, 0, 2);
        let curve = |t: f64| {
            let s = [t + t * t, 2.0 * t, 1.0];
            let r = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            s.map(|v| v / r)
        };
        let t = 0.3;
        let y = [[t + t * t, 2.0 * t], [1.0 + 2.0 * t, 2.0], [2.0, 0.0]];
        let e = 1e-4;
        for (a, [q, dq, ddq]) in (0..3).map(|a| (a, [jet[0][a], jet[1][a], jet[2][a]])) {
            let f = |t: f64| curve(t)[a];
            let d1 = (f(t + e) - f(t - e)) / (2.0 * e);
            let d2 = (f(t + e) - 2.0 * f(t) + f(t - e)) / (e * e);
            assert!((eval(&g, q, &y, &chart) - f(t)).abs() < 1e-15);
            assert!((eval(&g, dq, &y, &chart) - d1).abs() < 1e-7, "{a}");
            assert!((eval(&g, ddq, &y, &chart) - d2).abs() < 1e-6, "{a}");
        }
    }
}
