//! Helper functions, local arrays and tuples in a Lagrangian: the same Lagrangian written with
//! them and written out inline generates the same value, gradient, Hessian and step.

use retract::nalgebra::SVector;
use retract::{Lagrangian, LiftedSystem, StepOptions, higher_order_lagrangian, step};

/// The double pendulum's minimum-torque cost with its torque in a helper returning an array
/// (called twice), the mass matrix as a tuple from a helper inside it, and the jet passed as
/// arrays.
#[higher_order_lagrangian(order = 2)]
fn with_helpers(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    fn torque(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> [f64; 2] {
        // (a helper of the helper, registered again at each of the two calls)
        fn mass(c2: f64) -> (f64, f64, f64) {
            (3.0 + 2.0 * c2, 1.0 + c2, 1.0)
        }
        let (m11, m12, m22) = mass(q[1].cos());
        let b = q[1].sin();
        let gravity = [
            2.0 * g * q[0].sin() + g * (q[0] + q[1]).sin(),
            g * (q[0] + q[1]).sin(),
        ];
        [
            m11 * ddq[0] + m12 * ddq[1] - b * (2.0 * dq[0] * dq[1] + dq[1] * dq[1]) + gravity[0],
            m12 * ddq[0] + m22 * ddq[1] + b * dq[0] * dq[0] + gravity[1],
        ]
    }
    #[output]
    let tau = torque(q, dq, ddq, g);
    #[output]
    let kinetic_hint = 0.5 * (dq[0] * dq[0] + dq[1] * dq[1]);
    let zero = [0.0; 1];
    0.5 * (tau[0] * tau[0] + torque(q, dq, ddq, g)[1].powi(2)) + zero[0] + 0.0 * kinetic_hint
}

/// The same, written out.
#[higher_order_lagrangian(order = 2)]
fn inline(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    let c2 = q[1].cos();
    let b = q[1].sin();
    let tau1 = (3.0 + 2.0 * c2) * ddq[0] + (1.0 + c2) * ddq[1]
        - b * (2.0 * dq[0] * dq[1] + dq[1] * dq[1])
        + 2.0 * g * q[0].sin()
        + g * (q[0] + q[1]).sin();
    let tau2 = (1.0 + c2) * ddq[0] + ddq[1] + b * dq[0] * dq[0] + g * (q[0] + q[1]).sin();
    0.5 * (tau1 * tau1 + tau2 * tau2)
}

/// Value, gradient and Hessian agree to rounding at random jets, and so does a step.
#[test]
fn helpers_arrays_and_tuples_lower_like_inline_code() {
    let (a, b) = (WithHelpers { g: 9.81 }, Inline { g: 9.81 });
    let mut random = crate::common::Noise::new(0x9e37_79b9_7f4a_7c15_u64);
    let mut noise = move || random.next();
    for _ in 0..20 {
        let x = [
            SVector::from([2.0 * noise(), 2.0 * noise()]),
            SVector::from([noise(), noise()]),
        ];
        let u = SVector::from([3.0 * noise(), 3.0 * noise()]);
        let scale = 1.0 + b.lagrangian(&x, &u).abs();
        assert!((a.lagrangian(&x, &u) - b.lagrangian(&x, &u)).abs() < 1e-12 * scale);
        let (ga, gb) = (a.gradient(&x, &u), b.gradient(&x, &u));
        assert!((ga.u - gb.u).amax() < 1e-12 * scale);
        for j in 0..2 {
            assert!((ga.x[j] - gb.x[j]).amax() < 1e-12 * scale);
        }
        // the named outputs: L = 1/2 |tau|^2, and the number output
        let tau = a.tau(&x, &u);
        let l = 0.5 * (tau[0] * tau[0] + tau[1] * tau[1]);
        assert!((l - b.lagrangian(&x, &u)).abs() < 1e-12 * scale);
        let hint = 0.5 * x[1].norm_squared();
        assert!((a.kinetic_hint(&x, &u) - hint).abs() < 1e-15 * (1.0 + hint));
        let (ha, hb) = (a.hessian(&x, &u), b.hessian(&x, &u));
        assert!((ha.uu - hb.uu).amax() < 1e-12 * scale);
        for j in 0..2 {
            assert!((ha.xu[j] - hb.xu[j]).amax() < 1e-12 * scale);
            for l in 0..2 {
                assert!((ha.xx[j][l] - hb.xx[j][l]).amax() < 1e-12 * scale);
            }
        }
    }
    let jet = SVector::<f64, 8>::from([0.3, -0.2, 0.5, 0.1, 0.2, -0.4, 0.0, 0.3]);
    let (za, zb) = (a.legendre(&jet), b.legendre(&jet));
    assert!((za - zb).amax() < 1e-12);
    let options = StepOptions::default();
    let (sa, _) = step(&a, &za, 0.01, &options).unwrap();
    let (sb, _) = step(&b, &zb, 0.01, &options).unwrap();
    assert!((sa - sb).amax() < 1e-12, "{}", (sa - sb).amax());
}
