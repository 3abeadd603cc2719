//! The stage behind `#[higher_order_lagrangian(order = k, se3)]`: a Lagrangian written on
//! SE(3) in body coordinates (the pose g = (R, p) and the body velocity xi = (Omega, v),
//! v = R^T p', with its derivatives), composed with the product chart so that the rest of
//! the pipeline sees an order-k Lagrangian on R^6 with the chart jet (y, x).
//!
//! The chart is centred at the pose (C, c), a run-time parameter `se3_centre: [f64; 12]`
//! (C row major, then c), and is the left translation of the chart at the identity:
//!
//! (R, p) = (C, c) (Q(y), x) = (C Q(y), c + C x),
//! Omega = s (y' - y x y'),  v = R^T p' = Q(y)^T x',  xi^(j) = D^j xi,
//!
//! with Q the Gibbs chart of `crate::charts::so3` and D the total derivative of the chart jet. A
//! left-invariant L (one that reads only xi, ..., xi^(k-1)) is the same function of the chart
//! jet for every centre.

use crate::charts::so3::{
    body_angular_velocity, body_argument, chart_rotation, jet3, mat_mul, param_entries, rates,
    wrong_body_argument,
};
use quote::quote;

use super::{Chart, Frame};
use crate::ir::diff::substitute_jet;
use crate::ir::graph::{Graph, Id};

/// `roots` (L and its guarded expressions, in the arguments g, xi, ... of `sig`) rewritten
/// in the chart jet: `Var::Jet { order: 0, index: e }` becomes g_e of the pose (R, p) and
/// `Var::Jet { order: j, index: a }` (j >= 1) becomes xi^(j-1)_a. The centre parameter is
/// number `param`.
pub fn compose(g: &mut Graph, order: usize, param: u32, roots: &[Id]) -> Vec<Id> {
    let (rotation, position) = (param_entries(g, param, 0, 9), param_entries(g, param, 9, 3));
    let (y, x) = (jet3(g, 0, 0), jet3(g, 0, 3));
    let (dy, dx) = (jet3(g, 1, 0), jet3(g, 1, 3));
    let q = chart_rotation(g, y);
    let mut pose = mat_mul(g, &rotation, &q).to_vec();
    // p = c + C x
    for i in 0..3 {
        let mut acc = position[i];
        for l in 0..3 {
            let term = g.mul(rotation[3 * i + l], x[l]);
            acc = g.add_op(acc, term);
        }
        pose.push(acc);
    }
    // xi = (Omega, Q^T x')
    let mut xi = body_angular_velocity(g, y, dy).to_vec();
    for i in 0..3 {
        let mut acc = g.constant(0.0);
        for l in 0..3 {
            let term = g.mul(q[3 * l + i], dx[l]);
            acc = g.add_op(acc, term);
        }
        xi.push(acc);
    }
    let mut jet = vec![pose];
    jet.extend(rates(g, xi, 6, order));
    substitute_jet(g, roots, jet)
}

/// The product chart of SE(3) (module docs).
pub(crate) struct Se3;

impl Chart for Se3 {
    fn option(&self) -> Option<&'static str> {
        Some("se3")
    }

    fn frame(&self) -> Option<Frame> {
        Some(Frame {
            name: "se3_centre",
            len: 12,
            runtime: ["Se3System", "centre", "with_centre"],
            doc: "The chart's centre (C, c), a pose: C row major, then c \
                  (`retract::se3::centre_pose`), moved by `retract::se3`; the identity after \
                  `new`.",
            initial: || quote!([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
        })
    }

    fn body_coordinates(&self) -> Option<(usize, usize)> {
        Some((12, 6))
    }

    fn required_argument(&self, order: usize, i: usize) -> Option<usize> {
        body_argument(12, 6, order, i)
    }

    fn wrong_argument(&self, order: usize, i: usize, name: &syn::Ident, found: &str) -> String {
        let prefix = format!(
            "a Lagrangian on SE(3) (`se3`) of order {order} takes g = (R, p): [f64; 12], then \
             xi, ..., xi^({}): [f64; 6] (xi = (Omega, v))",
            order - 1
        );
        let expected = if i == 0 { 12 } else { 6 };
        wrong_body_argument(
            [
                &prefix,
                "the pose g = (R, p): R row major (g[3 * i + j] = R_ij), then p = g[9..12]",
                "the body velocity xi = (Omega, v), v = R^T p'",
                "xi",
            ],
            (i, expected),
            name,
            found,
        )
    }

    fn missing_arguments(&self, order: usize, found: usize) -> Option<String> {
        Some(format!(
            "order = {order} with `se3` needs {} arguments before the parameters (g: [f64; 12], \
             then xi, ..., xi^({}): [f64; 6]); the signature has {found}",
            order + 1,
            order - 1,
        ))
    }

    fn compose(&self, graph: &mut Graph, order: usize, frame: u32, roots: &[Id]) -> Vec<Id> {
        compose(graph, order, frame, roots)
    }

    fn description(&self, _dim: usize) -> String {
        "SE(3), written in the pose (R, p) and the body velocity (Omega, v) with its derivatives, \
         in the chart (Gibbs chart of R, position in the centre's axes) centred at `se3_centre` \
         (R^6; see `retract::se3`),"
            .into()
    }

    fn arguments(&self, k: usize) -> String {
        format!("(R, p), xi, ..., xi^({})", k - 1)
    }

    fn top(&self, k: usize) -> String {
        format!("xi^({})", k - 1)
    }
}
