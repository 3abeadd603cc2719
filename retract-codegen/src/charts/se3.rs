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
    body_angular_velocity, chart_rotation, jet3, mat_mul, param_entries, rates,
};
use crate::front::signature::Signature;
use proc_macro2::TokenStream;
use quote::quote;

use super::Chart;
use crate::ir::diff::substitute_jet;
use crate::ir::graph::{Graph, Id};

/// `roots` (L and its guarded expressions, in the arguments g, xi, ... of `sig`) rewritten
/// in the chart jet: `Var::Jet { order: 0, index: e }` becomes g_e of the pose (R, p) and
/// `Var::Jet { order: j, index: a }` (j >= 1) becomes xi^(j-1)_a. The centre parameter is
/// number `sig.params.len()`.
pub fn compose(g: &mut Graph, sig: &Signature, roots: &[Id]) -> Vec<Id> {
    let param = sig.params.len() as u32;
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
    jet.extend(rates(g, xi, 6, sig.order));
    substitute_jet(g, roots, jet)
}

/// The product chart of SE(3) (module docs).
pub(crate) struct Se3;

impl Chart for Se3 {
    fn compose(&self, graph: &mut Graph, sig: &Signature, roots: &[Id]) -> Vec<Id> {
        compose(graph, sig, roots)
    }

    fn description(&self) -> &'static str {
        "SE(3), written in the pose (R, p) and the body velocity (Omega, v) with its derivatives, \
         in the chart (Gibbs chart of R, position in the centre's axes) centred at `se3_centre` \
         (R^6; see `retract::se3`),"
    }

    fn arguments(&self, k: usize) -> String {
        format!("(R, p), xi, ..., xi^({})", k - 1)
    }

    fn top(&self, k: usize) -> String {
        format!("xi^({})", k - 1)
    }

    fn runtime(&self) -> [&'static str; 4] {
        ["se3", "Se3System", "centre", "with_centre"]
    }

    fn frame_doc(&self) -> &'static str {
        "The chart's centre (C, c), a pose: C row major, then c (`retract::se3::centre_pose`), \
         moved by `retract::se3`; the identity after `new`."
    }

    fn initial_frame(&self) -> TokenStream {
        quote!([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    }
}
