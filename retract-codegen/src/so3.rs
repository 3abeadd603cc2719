//! The stage behind `#[higher_order_lagrangian(order = k, so3)]`: a Lagrangian written on
//! SO(3) in body coordinates (the rotation R and the body angular velocity Omega with its
//! derivatives Omega', ..., Omega^(k-1)), composed with a Gibbs chart so that the rest of
//! the pipeline sees an order-k Lagrangian on R^3.
//!
//! The chart is centred at the rotation C, a run-time parameter `so3_centre: [f64; 9]` (C
//! row major), and
//!
//! R = C Q(y),  Q(y) = ((1 - |y|^2) I + 2 y y^T + 2 [y]x) / (1 + |y|^2),
//! Omega = s (y' - y x y'),  s = 2 / (1 + |y|^2),  Omega^(j) = D^j Omega,
//!
//! with [y]x v = y x v, Q(y)^T Q(y)' = [Omega]x, and D the total derivative of the chart jet
//! (D y^(i) = y^(i+1)); Omega^(k-1) reads y^(k). Every argument of L (and of its guards) is
//! replaced by that expression; 1 + |y|^2 >= 1, so the chart itself needs no guard.

use std::collections::HashMap;

use crate::diff::{Differentiator, substitute, total_derivative};
use crate::graph::{Graph, Id, Var};
use crate::signature::{Kind, Param, SO3_CENTRE, Signature};

/// The signature of the composed Lagrangian: dimension 3, the parameters of `sig` followed
/// by the centre `so3_centre: [f64; 9]`.
pub fn chart_signature(sig: &Signature) -> Signature {
    let mut chart = sig.clone();
    chart.dim = 3;
    chart.params.push(Param {
        name: syn::Ident::new(SO3_CENTRE, proc_macro2::Span::call_site()),
        kind: Kind::Array(9),
    });
    chart
}

/// `a x b` in the graph.
fn cross(g: &mut Graph, a: [Id; 3], b: [Id; 3]) -> [Id; 3] {
    core::array::from_fn(|i| {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let p = g.mul(a[j], b[l]);
        let m = g.mul(a[l], b[j]);
        g.sub(p, m)
    })
}

/// The rotation R = C Q(y), row major, in the chart point y and the centre parameter
/// (`Var::Param { param: centre }`).
fn rotation(g: &mut Graph, centre: u32, y: [Id; 3]) -> [Id; 9] {
    let mut n = g.constant(0.0);
    for &yi in &y {
        let sq = g.powi(yi, 2);
        n = g.add_op(n, sq);
    }
    let one = g.constant(1.0);
    let two = g.constant(2.0);
    let (diagonal, den) = (g.sub(one, n), g.add_op(one, n));
    // Q_ij = ((1 - n) delta_ij + 2 y_i y_j + 2 [y]x_ij) / (1 + n), [y]x_ij = -eps_ijl y_l
    let q: [Id; 9] = core::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        let yy = g.mul(y[i], y[j]);
        let mut num = g.mul(two, yy);
        if i == j {
            num = g.add_op(diagonal, num);
        } else {
            let l = 3 - i - j;
            let cross = g.mul(two, y[l]);
            // [y]x_ij = -y_l where j = i + 1 (mod 3), +y_l where j = i + 2
            num = if (j + 3 - i) % 3 == 1 {
                g.sub(num, cross)
            } else {
                g.add_op(num, cross)
            };
        }
        g.div(num, den)
    });
    core::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        let mut acc = g.constant(0.0);
        for l in 0..3 {
            let c = g.var(Var::Param {
                param: centre,
                index: (3 * i + l) as u32,
            });
            let term = g.mul(c, q[3 * l + j]);
            acc = g.add_op(acc, term);
        }
        acc
    })
}

/// The arguments of L in the chart jet: R (9 nodes) and Omega^(j), j = 0..k-1.
fn body_jet(g: &mut Graph, centre: u32, k: usize) -> (Vec<Id>, Vec<[Id; 3]>) {
    let jet = |g: &mut Graph, order: u8| -> [Id; 3] {
        core::array::from_fn(|a| {
            g.var(Var::Jet {
                order,
                index: a as u32,
            })
        })
    };
    let (y, dy) = (jet(g, 0), jet(g, 1));
    let r = rotation(g, centre, y).to_vec();
    let mut n = g.constant(0.0);
    for &yi in &y {
        let sq = g.powi(yi, 2);
        n = g.add_op(n, sq);
    }
    let one = g.constant(1.0);
    let two = g.constant(2.0);
    let den = g.add_op(one, n);
    let s = g.div(two, den);
    let ydy = cross(g, y, dy);
    let omega: [Id; 3] = core::array::from_fn(|a| {
        let v = g.sub(dy[a], ydy[a]);
        g.mul(s, v)
    });
    let mut d = Differentiator::default();
    let mut rates = vec![omega];
    for j in 1..k {
        let previous = rates[j - 1];
        rates.push(previous.map(|f| total_derivative(g, &mut d, f, 3, j + 1)));
    }
    (r, rates)
}

/// `roots` (L and its guarded expressions, in the arguments R, Omega, ... of `sig`)
/// rewritten in the chart jet: `Var::Jet { order: 0, index: e }` becomes R_e and
/// `Var::Jet { order: j, index: a }` (j >= 1) becomes Omega^(j-1)_a. The centre parameter
/// is number `sig.params.len()`.
pub fn compose(g: &mut Graph, sig: &Signature, roots: &[Id]) -> Vec<Id> {
    let centre = sig.params.len() as u32;
    let (r, rates) = body_jet(g, centre, sig.order);
    let map = move |_: &mut Graph, v: Var| match v {
        Var::Jet { order: 0, index } => Some(r[index as usize]),
        Var::Jet { order, index } => Some(rates[order as usize - 1][index as usize]),
        _ => None,
    };
    let mut memo = HashMap::new();
    roots
        .iter()
        .map(|&root| substitute(g, root, &map, &mut memo))
        .collect()
}
