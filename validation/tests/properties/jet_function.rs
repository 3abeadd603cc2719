//! `#[jet_function]` at 100 random points per function: `value` against the annotated
//! function itself, `gradient` and `hessian` against fourth-order central finite differences
//! of the annotated function (first and nested second differences, relative tolerance
//! 1e-8). The functions may be linear in, or independent of, the top derivative, which a
//! Lagrangian may not.

#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

use crate::common;

use common::{close, fd, grad_entry, hess_entry};

use proptest::prelude::*;
use retract::JetFunction;
use retract::jet_function;
use retract::nalgebra::SVector;

// ---- the functions ----------------------------------------------------------------------

/// The cart-pole pole torque (q = (x, th)): linear in q''.
#[jet_function(order = 2)]
fn pole_torque(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], mp: f64, l: f64, g: f64) -> f64 {
    mp * l * q[1].cos() * ddq[0] + mp * l.powi(2) * ddq[1] + mp * g * l * q[1].sin()
}

/// Nonlinear: sqrt, exp, atan2, a parameter array and a slice parameter summed in a run-time
/// loop; linear in q''_1.
#[jet_function(order = 2)]
fn clearance(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], w: [f64; 2], obstacles: &[[f64; 3]]) -> f64 {
    let mut s = 0.0;
    for o in obstacles {
        let d = ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2)).sqrt() - o[2];
        s += (-d).exp();
    }
    s + w[0] * dq[1].atan2(dq[0]) + w[1] * (1.0 + ddq[0] * ddq[0]).sqrt() * ddq[1]
}

/// Order 1 on R (scalar jet), linear in q'.
#[jet_function(order = 1)]
fn speed_limit(q: f64, dq: f64, c: f64) -> f64 {
    dq * (c * q).cos() + q.tanh()
}

/// Order 1 on R^2, independent of q', with a chosen type name.
#[jet_function(order = 1, name = Ellipse)]
fn ellipse_constraint(q: [f64; 2], _dq: [f64; 2], a: f64, b: f64) -> f64 {
    (q[0] / a).powi(2) + (q[1] / b).powi(2) - 1.0
}

/// Order 3 on R^2, linear in q''' with a configuration-dependent coefficient.
#[jet_function(order = 3)]
fn jerk_limit(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], dddq: [f64; 2], a: f64) -> f64 {
    dddq[0] + q[0].sin() * dddq[1] + a * ddq[1] * dq[0] + (q[1] * dq[1]).exp()
}

// ---- finite differences -----------------------------------------------------------------

/// `value`, `gradient` and `hessian` of `f` at the flat jet `v` = (q, ..., q^(k)) against
/// `original`, the annotated function called on the same flat jet.
fn check<F: JetFunction<N, K>, const N: usize, const K: usize>(
    f: &F,
    original: impl Fn(&[f64]) -> f64,
    v: &[f64],
) {
    let m = N * (K + 1);
    assert_eq!(v.len(), m);
    let x: [SVector<f64, N>; K] = core::array::from_fn(|j| SVector::from_fn(|i, _| v[j * N + i]));
    let u = SVector::<f64, N>::from_fn(|i, _| v[K * N + i]);
    let at = |moves: &[(usize, f64)]| {
        let mut w = v.to_vec();
        for &(c, t) in moves {
            w[c] += t;
        }
        original(&w)
    };

    let value = f.value(&x, &u);
    let want = original(v);
    close("g", value, want, want.abs());

    let eps = 1e-3;
    let g = f.gradient(&x, &u);
    let h = f.hessian(&x, &u);
    let g_scale = (0..m).map(|c| grad_entry(&g, c).abs()).fold(0.0, f64::max);
    let h_scale = (0..m * m)
        .map(|e| hess_entry(&h, e / m, e % m).abs())
        .fold(0.0, f64::max);
    for a in 0..m {
        let want = fd(|t| at(&[(a, t)]), eps);
        close(&format!("dg/dv{a}"), grad_entry(&g, a), want, g_scale);
        for b in 0..m {
            let want = fd(|s| fd(|t| at(&[(a, s), (b, t)]), eps), eps);
            close(
                &format!("d2g/dv{a}dv{b}"),
                hess_entry(&h, a, b),
                want,
                h_scale,
            );
        }
    }
}

fn point(len: usize, lo: f64, hi: f64) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(lo..hi, len)
}

fn pair(v: &[f64], j: usize) -> [f64; 2] {
    [v[2 * j], v[2 * j + 1]]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]

    #[test]
    fn pole_torque_linear_in_the_top_derivative(
        v in point(6, -2.0, 2.0),
        mp in 0.1..2.0,
        l in 0.2..1.5,
    ) {
        let g = 9.81;
        check(
            &PoleTorque { mp, l, g },
            |v| pole_torque(pair(v, 0), pair(v, 1), pair(v, 2), mp, l, g),
            &v,
        );
    }

    #[test]
    fn clearance_sqrt_exp_atan2_slice(mut v in point(6, -1.0, 1.0), w0 in -1.0..1.0, w1 in -1.0..1.0) {
        v[0] += 3.0; // q clear of the obstacles' centres (sqrt at 0)
        v[2] += 2.0; // q' away from the atan2 branch point at the origin
        let obstacles = [[0.0, 0.0, 1.0], [1.0, -1.5, 0.5], [-0.5, 2.0, 0.3]];
        let w = [w0, w1];
        check(
            &Clearance::new(w, &obstacles),
            |v| clearance(pair(v, 0), pair(v, 1), pair(v, 2), w, &obstacles),
            &v,
        );
    }

    #[test]
    fn speed_limit_order_1_scalar(v in point(2, -2.0, 2.0), c in 0.1..2.0) {
        check(&SpeedLimit { c }, |v| speed_limit(v[0], v[1], c), &v);
    }

    #[test]
    fn ellipse_order_1_independent_of_the_top_derivative(
        v in point(4, -2.0, 2.0),
        a in 0.5..2.0,
        b in 0.5..2.0,
    ) {
        check(
            &Ellipse { a, b },
            |v| ellipse_constraint(pair(v, 0), pair(v, 1), a, b),
            &v,
        );
    }

    #[test]
    fn jerk_limit_order_3(v in point(8, -1.0, 1.0), a in -2.0..2.0) {
        check(
            &JerkLimit { a },
            |v| jerk_limit(pair(v, 0), pair(v, 1), pair(v, 2), pair(v, 3), a),
            &v,
        );
    }
}

#[test]
fn generated_types_and_functions() {
    let x = [SVector::from([0.1, 0.2]), SVector::from([0.3, 0.4])];
    let u = SVector::from([0.5, 0.6]);
    let torque = PoleTorque::new(0.3, 0.5, 9.81);
    assert_eq!(
        torque.value(&x, &u),
        pole_torque([0.1, 0.2], [0.3, 0.4], [0.5, 0.6], 0.3, 0.5, 9.81)
    );
    // linear in q'': the (u, u) block vanishes, the gradient in u is (mp l cos th, mp l^2)
    let h = torque.hessian(&x, &u);
    assert_eq!(h.uu, retract::nalgebra::SMatrix::<f64, 2, 2>::zeros());
    let g = torque.gradient(&x, &u);
    assert!((g.u[0] - 0.3 * 0.5 * 0.2f64.cos()).abs() < 1e-15);
    assert!((g.u[1] - 0.3 * 0.25).abs() < 1e-15);
    assert_eq!((PoleTorque::DIMENSION, PoleTorque::ORDER), (2, 2));
    assert_eq!((SpeedLimit::DIMENSION, SpeedLimit::ORDER), (1, 1));
    assert_eq!((JerkLimit::DIMENSION, JerkLimit::ORDER), (2, 3));
    assert_eq!(Ellipse::new(1.0, 2.0), Ellipse { a: 1.0, b: 2.0 });
}

/// Usable behind the trait, as the optimal-control solver takes it.
#[test]
fn usable_as_a_trait_object() {
    let constraints: [&dyn JetFunction<2, 2>; 2] = [
        &PoleTorque::new(0.3, 0.5, 9.81),
        &Clearance::new([0.0, 1.0], &[]),
    ];
    let x = [SVector::from([0.0, 0.0]), SVector::from([1.0, 0.0])];
    let u = SVector::from([0.0, 2.0]);
    assert!((constraints[0].value(&x, &u) - 0.3 * 0.25 * 2.0).abs() < 1e-15);
    assert!((constraints[1].value(&x, &u) - 2.0).abs() < 1e-15);
}
