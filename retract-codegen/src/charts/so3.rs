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
//! replaced by that expression; 1 + |y|^2 >= 1, so the chart itself needs no guard. The
//! pieces (Q, Omega, the derivatives) also serve the SE(3) stage (`crate::charts::se3`).

use quote::quote;

use super::{Chart, Frame};
use crate::ir::diff::{Differentiator, substitute_jet, total_derivative};
use crate::ir::graph::{Graph, Id, Var};

/// `a x b` in the graph.
fn cross(g: &mut Graph, a: [Id; 3], b: [Id; 3]) -> [Id; 3] {
    core::array::from_fn(|i| {
        let (j, l) = ((i + 1) % 3, (i + 2) % 3);
        let p = g.mul(a[j], b[l]);
        let m = g.mul(a[l], b[j]);
        g.sub(p, m)
    })
}

/// |y|^2 in the graph.
fn norm_squared(g: &mut Graph, y: [Id; 3]) -> Id {
    let mut n = g.constant(0.0);
    for &yi in &y {
        let sq = g.powi(yi, 2);
        n = g.add_op(n, sq);
    }
    n
}

/// The chart variables `Var::Jet { order, index: first + a }`, a = 0, 1, 2.
pub(crate) fn jet3(g: &mut Graph, order: u8, first: u32) -> [Id; 3] {
    core::array::from_fn(|a| {
        g.var(Var::Jet {
            order,
            index: first + a as u32,
        })
    })
}

/// The components `first..first + len` of the parameter number `param`.
pub(crate) fn param_entries(g: &mut Graph, param: u32, first: u32, len: u32) -> Vec<Id> {
    (first..first + len)
        .map(|index| g.var(Var::Param { param, index }))
        .collect()
}

/// Q(y) = ((1 - |y|^2) I + 2 y y^T + 2 [y]x) / (1 + |y|^2), row major.
pub(crate) fn chart_rotation(g: &mut Graph, y: [Id; 3]) -> [Id; 9] {
    let n = norm_squared(g, y);
    let one = g.constant(1.0);
    let two = g.constant(2.0);
    let (diagonal, den) = (g.sub(one, n), g.add_op(one, n));
    // Q_ij = ((1 - n) delta_ij + 2 y_i y_j + 2 [y]x_ij) / (1 + n), [y]x_ij = -eps_ijl y_l
    core::array::from_fn(|e| {
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
    })
}

/// The product `a b` of 3x3 matrices, row major.
pub(crate) fn mat_mul(g: &mut Graph, a: &[Id], b: &[Id; 9]) -> [Id; 9] {
    core::array::from_fn(|e| {
        let (i, j) = (e / 3, e % 3);
        let mut acc = g.constant(0.0);
        for l in 0..3 {
            let term = g.mul(a[3 * i + l], b[3 * l + j]);
            acc = g.add_op(acc, term);
        }
        acc
    })
}

/// Omega = s (y' - y x y'), s = 2 / (1 + |y|^2): the body angular velocity of Q(y(t)).
pub(crate) fn body_angular_velocity(g: &mut Graph, y: [Id; 3], dy: [Id; 3]) -> [Id; 3] {
    let n = norm_squared(g, y);
    let one = g.constant(1.0);
    let two = g.constant(2.0);
    let den = g.add_op(one, n);
    let s = g.div(two, den);
    let ydy = cross(g, y, dy);
    core::array::from_fn(|a| {
        let v = g.sub(dy[a], ydy[a]);
        g.mul(s, v)
    })
}

/// The body rate `xi` (in the jet up to order 1 of a chart of dimension `dim`) and its total
/// derivatives: xi^(j) = D^j xi, j = 0..k-1 (xi^(k-1) reads the chart's q^(k)).
pub(crate) fn rates(g: &mut Graph, xi: Vec<Id>, dim: usize, k: usize) -> Vec<Vec<Id>> {
    let mut d = Differentiator::default();
    let mut rates = vec![xi];
    for j in 1..k {
        let previous = rates[j - 1].clone();
        rates.push(
            previous
                .into_iter()
                .map(|f| total_derivative(g, &mut d, f, dim, j + 1))
                .collect(),
        );
    }
    rates
}

/// `roots` (L and its guarded expressions, in the arguments R, Omega, ... of `sig`)
/// rewritten in the chart jet: `Var::Jet { order: 0, index: e }` becomes R_e of
/// R = C Q(y) and `Var::Jet { order: j, index: a }` (j >= 1) becomes Omega^(j-1)_a. The
/// centre parameter is number `frame`.
pub fn compose(g: &mut Graph, order: usize, frame: u32, roots: &[Id]) -> Vec<Id> {
    let centre = param_entries(g, frame, 0, 9);
    let (y, dy) = (jet3(g, 0, 0), jet3(g, 1, 0));
    let q = chart_rotation(g, y);
    let r = mat_mul(g, &centre, &q).to_vec();
    let omega = body_angular_velocity(g, y, dy).to_vec();
    let mut jet = vec![r];
    jet.extend(rates(g, omega, 3, order));
    substitute_jet(g, roots, jet)
}

/// The Gibbs chart of SO(3) (module docs).
pub(crate) struct So3;

/// The length a Lagrangian in body coordinates of order `order` requires of its jet argument
/// `i` as written: the group element's (`group`) for i = 0, a body rate's (`rate`) for
/// 1 <= i <= order.
pub(crate) fn body_argument(group: usize, rate: usize, order: usize, i: usize) -> Option<usize> {
    match i {
        0 => Some(group),
        _ if i <= order => Some(rate),
        _ => None,
    }
}

/// The message for a jet argument of a Lagrangian in body coordinates whose type is not the
/// required one: `prefix` says what the arguments are, `element` and `velocity` what the
/// first two hold, `rate` the body rate's symbol.
pub(crate) fn wrong_body_argument(
    [prefix, element, velocity, rate]: [&str; 4],
    (i, expected): (usize, usize),
    name: &syn::Ident,
    found: &str,
) -> String {
    let what = match i {
        0 => element.to_string(),
        1 => velocity.to_string(),
        _ => format!("{rate}^({}), the derivative of the body velocity", i - 1),
    };
    format!(
        "{prefix}; argument {} (`{name}`) must be `[f64; {expected}]` ({what}), not {found}",
        i + 1
    )
}

impl Chart for So3 {
    fn option(&self) -> Option<&'static str> {
        Some("so3")
    }

    fn frame(&self) -> Option<Frame> {
        Some(Frame {
            name: "so3_centre",
            len: 9,
            runtime: ["So3System", "centre", "with_centre"],
            doc: "The Gibbs chart's centre C, a rotation matrix row major \
                  (`retract::so3::centre_matrix`), moved by `retract::so3`; the identity after \
                  `new`.",
            initial: || quote!([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
        })
    }

    fn body_coordinates(&self) -> Option<(usize, usize)> {
        Some((9, 3))
    }

    fn required_argument(&self, order: usize, i: usize) -> Option<usize> {
        body_argument(9, 3, order, i)
    }

    fn wrong_argument(&self, order: usize, i: usize, name: &syn::Ident, found: &str) -> String {
        let prefix = format!(
            "a Lagrangian on SO(3) (`so3`) of order {order} takes R: [f64; 9], then Omega, ..., \
             Omega^({}): [f64; 3]",
            order - 1
        );
        let expected = if i == 0 { 9 } else { 3 };
        wrong_body_argument(
            [
                &prefix,
                "the rotation R, row major: r[3 * i + j] = R_ij",
                "the body angular velocity Omega",
                "Omega",
            ],
            (i, expected),
            name,
            found,
        )
    }

    fn missing_arguments(&self, order: usize, found: usize) -> Option<String> {
        Some(format!(
            "order = {order} with `so3` needs {} arguments before the parameters (R: [f64; 9], \
             then Omega, ..., Omega^({}): [f64; 3]); the signature has {found}",
            order + 1,
            order - 1,
        ))
    }

    fn compose(&self, graph: &mut Graph, order: usize, frame: u32, roots: &[Id]) -> Vec<Id> {
        compose(graph, order, frame, roots)
    }

    fn description(&self, _dim: usize) -> String {
        "SO(3), written in the rotation R and the body velocity Omega with its derivatives, in \
         the Gibbs chart centred at `so3_centre` (R^3; see `retract::so3`),"
            .into()
    }

    fn arguments(&self, k: usize) -> String {
        format!("R, Omega, ..., Omega^({})", k - 1)
    }

    fn top(&self, k: usize) -> String {
        // (the top argument is Omega^(k-1), which holds the chart's q^(k))
        format!("Omega^({})", k - 1)
    }
}
