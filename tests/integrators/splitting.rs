//! The explicit splitting of `retract::split` on the obstacle model L = 1/2 |q''|^2 + V(q)
//! (which the macro marks `Separable`): order 2, and 4, 6, 8 composed; symplectic, with a
//! derivative that matches differences; the same solution as the implicit midpoint
//! compositions, also at order k = 3 with a weight c != 1; and the guard. (That forms other
//! than c/2 |u|^2 + V(q) are not marked is tested in retract-codegen's `separable`.)

use crate::common;

use common::models::RigidBody;
use retract::compose::compose;
use retract::diagnostics::canonical_structure;
use retract::nalgebra::SVector;
use retract::split::{Separable, split_step, split_step_derivative};
use retract::{Error, LiftedSystem, StepOptions, composed_step, higher_order_lagrangian};

type Z = SVector<f64, 12>;

fn setup() -> (RigidBody, Z) {
    let system = RigidBody { tau: 0.5, r: 1.0 };
    let jet = [
        -2.0, 1.2, 0.0, 1.0, 0.0, 0.5, 0.1, -0.2, 0.3, 0.0, 0.1, -0.2,
    ];
    let z0 = system.legendre(&Z::from_column_slice(&jet));
    (system, z0)
}

/// `steps` steps over [0, t_end] of the splitting composed to `order` (2: Strang itself).
fn split_run(system: &RigidBody, z0: &Z, t_end: f64, steps: usize, order: u32) -> Z {
    let options = StepOptions::default();
    let h = t_end / steps as f64;
    let mut z = *z0;
    for _ in 0..steps {
        z = compose(|z, h| split_step(system, z, h, &options), &z, h, order)
            .expect("regular")
            .0;
    }
    z
}

/// The order-8 composition of the implicit midpoint rule with many steps.
fn reference(system: &RigidBody, z0: &Z, t_end: f64) -> Z {
    let (options, steps) = (StepOptions::default(), 512);
    let h = t_end / steps as f64;
    (0..steps).fold(*z0, |z, _| {
        composed_step(system, &z, h, 8, &options)
            .expect("regular")
            .0
    })
}

#[test]
fn the_macro_marks_the_obstacle_model_separable() {
    let (system, _) = setup();
    assert_eq!(system.kinetic_weight(), 1.0);
}

#[test]
fn the_splitting_has_order_2_and_its_compositions_4_6_and_8() {
    let (system, z0) = setup();
    let exact = reference(&system, &z0, 1.0);
    for (order, sweep, range) in [
        (2, [32, 64], 1.9..2.1),
        (4, [16, 32], 3.8..4.3),
        (6, [8, 16], 5.6..6.6),
        (8, [4, 8], 7.3..8.9),
    ] {
        let errors = sweep.map(|n| (split_run(&system, &z0, 1.0, n, order) - exact).amax());
        let observed = (errors[0] / errors[1]).log2();
        println!("order {order}: errors {errors:?}, observed {observed:.3}");
        assert!(
            range.contains(&observed),
            "order {order}: observed {observed} ({errors:?})"
        );
    }
}

#[test]
fn the_splitting_agrees_with_the_midpoint_compositions() {
    // the order-8 compositions of both, at 64 steps, agree to their error (below 1e-10)
    let (system, z0) = setup();
    let exact = reference(&system, &z0, 1.0);
    let split = split_run(&system, &z0, 1.0, 64, 8);
    assert!(
        (split - exact).amax() < 1e-10,
        "{:e}",
        (split - exact).amax()
    );
}

#[test]
fn the_splitting_step_is_symplectic() {
    let (system, z0) = setup();
    let h = 0.1;
    let d = split_step_derivative(&system, &z0, h).expect("regular");
    let j = canonical_structure::<12>();
    let error = (d.transpose() * j * d - j).amax();
    assert!(error < 1e-12, "|D^T J D - J| = {error:e}");
    // the derivative is that of the step: central differences
    let e = 1e-6;
    let options = StepOptions::default();
    for c in 0..12 {
        let mut dz = Z::zeros();
        dz[c] = e;
        let plus = split_step(&system, &(z0 + dz), h, &options).unwrap().0;
        let minus = split_step(&system, &(z0 - dz), h, &options).unwrap().0;
        let column = (plus - minus) / (2.0 * e);
        assert!((column - d.column(c)).amax() < 1e-7, "column {c}");
    }
}

#[test]
fn a_step_into_the_obstacle_is_a_domain_error() {
    // from just outside the unit disc, heading into it at speed 10: one step of 0.1 lands
    // inside
    let system = RigidBody { tau: 1e-6, r: 1.0 };
    let jet = [
        1.05, 0.0, 0.0, -10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ];
    let z0 = system.legendre(&Z::from_column_slice(&jet));
    let result = split_step(&system, &z0, 0.1, &StepOptions::default());
    assert!(matches!(result, Err(Error::Domain(_))), "{result:?}");
}

/// k = 3 with the weight m: L = m/2 |q^(3)|^2 + a cos(q_0 q_1) + q_0^4 / 10.
#[higher_order_lagrangian(order = 3)]
fn weighted(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], dddq: [f64; 2], m: f64, a: f64) -> f64 {
    0.5 * m * (dddq[0].powi(2) + dddq[1].powi(2)) + a * (q[0] * q[1]).cos() + 0.1 * q[0].powi(4)
}

#[test]
fn with_a_weight_at_order_3_the_splitting_matches_the_midpoint_compositions() {
    let system = Weighted { m: 2.5, a: 0.7 };
    assert_eq!(system.kinetic_weight(), 2.5);
    let jet = SVector::<f64, 12>::from([
        0.3, -0.2, 0.5, 0.1, -0.4, 0.2, 0.3, 0.0, -0.1, 0.2, 0.05, -0.3,
    ]);
    let z0 = system.legendre(&jet);
    let options = StepOptions::default();
    let (t, steps) = (1.0, 64);
    let h = t / steps as f64;
    let run = |order: u32, splitting: bool| {
        (0..steps).fold(z0, |z, _| {
            if splitting {
                compose(|z, h| split_step(&system, z, h, &options), &z, h, order)
            } else {
                composed_step(&system, &z, h, order, &options)
            }
            .expect("regular")
            .0
        })
    };
    let (split8, midpoint8) = (run(8, true), run(8, false));
    let gap = (split8 - midpoint8).amax();
    assert!(gap < 1e-10, "order 8: {gap:e}");
    // Strang's splitting alone is a different method of order 2: far from both
    let strang = (run(2, true) - midpoint8).amax();
    assert!(strang > 1e3 * gap, "{strang:e}");
}
