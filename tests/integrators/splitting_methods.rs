//! The splitting methods of `retract::split_methods` stepped by `retract::split_stepper` on the
//! obstacle model L = 1/2 |q''|^2 + V(q): the fused compositions equal the per-stage ones;
//! Blanes and Moan's RKN methods reach their orders (4, 6, 6) although the problem is not of
//! the form 1/2 |p|^2 + V(q) (its kicks satisfy {V, {V, H_0}} = 0, which is all RKN methods
//! need) and agree with the implicit midpoint compositions, also at k = 3 with a weight
//! c != 1; symplectic; the gradient reused across steps changes nothing; the guard and the
//! errors.

use crate::common;

use common::models::RigidBody;
use retract::compose::compose;
use retract::diagnostics::canonical_structure;
use retract::nalgebra::SVector;
use retract::split::split_step;
use retract::split_methods::SplittingMethod;
use retract::split_stepper::SplitStepper;
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

/// `steps` steps of `method` over [0, t_end].
fn run(system: &RigidBody, z0: &Z, t_end: f64, steps: usize, method: SplittingMethod) -> Z {
    let options = StepOptions::default();
    let mut stepper = SplitStepper::new(system, method).expect("valid weight");
    let h = t_end / steps as f64;
    (0..steps).fold(*z0, |z, _| {
        stepper.step(&z, h, &options).expect("regular").0
    })
}

#[test]
fn fused_compositions_equal_the_per_stage_ones() {
    let (system, z0) = setup();
    let options = StepOptions::default();
    let h = 0.1;
    for order in [2, 4, 6, 8] {
        let mut stepper =
            SplitStepper::new(&system, SplittingMethod::composition(order).unwrap()).unwrap();
        let (mut fused, mut per_stage) = (z0, z0);
        for _ in 0..5 {
            fused = stepper.step(&fused, h, &options).unwrap().0;
            per_stage = compose(
                |z, h| split_step(&system, z, h, &options),
                &per_stage,
                h,
                order,
            )
            .unwrap()
            .0;
        }
        let gap = (fused - per_stage).amax();
        assert!(gap < 1e-13, "order {order}: {gap:e}");
    }
}

#[test]
fn the_rkn_methods_reach_their_orders() {
    let (system, z0) = setup();
    // reference: the fused order-8 composition with many steps (its error ~1e-15 here)
    let exact = run(
        &system,
        &z0,
        1.0,
        256,
        SplittingMethod::composition(8).unwrap(),
    );
    let methods = [
        (
            "SRKN6b",
            SplittingMethod::blanes_moan_4(),
            [16, 32],
            3.8..4.4,
        ),
        (
            "SRKN11b",
            SplittingMethod::blanes_moan_6(),
            [8, 16],
            5.6..6.6,
        ),
        (
            "SRKN14a",
            SplittingMethod::blanes_moan_6a(),
            [6, 12],
            5.6..6.6,
        ),
    ];
    for (name, method, sweep, range) in methods {
        assert!(range.contains(&f64::from(method.order())));
        let errors = sweep.map(|n| (run(&system, &z0, 1.0, n, method) - exact).amax());
        let observed = (errors[0] / errors[1]).log2();
        println!("{name}: errors {errors:?}, observed order {observed:.3}");
        assert!(
            range.contains(&observed),
            "{name}: observed {observed} ({errors:?})"
        );
    }
}

#[test]
fn the_rkn_methods_agree_with_the_midpoint_compositions() {
    // the order-8 midpoint composition at 64 steps is within 1e-11 of the solution here
    let (system, z0) = setup();
    let (options, steps) = (StepOptions::default(), 64);
    let h = 1.0 / steps as f64;
    let midpoint = (0..steps).fold(z0, |z, _| {
        composed_step(&system, &z, h, 8, &options)
            .expect("regular")
            .0
    });
    for method in [
        SplittingMethod::blanes_moan_6(),
        SplittingMethod::blanes_moan_6a(),
    ] {
        let gap = (run(&system, &z0, 1.0, steps, method) - midpoint).amax();
        assert!(gap < 1e-10, "{gap:e}");
    }
}

#[test]
fn the_step_is_symplectic_and_its_derivative_is_the_steps() {
    let (system, z0) = setup();
    let (h, e, options) = (0.1, 1e-6, StepOptions::default());
    let j = canonical_structure::<12>();
    for method in [
        SplittingMethod::blanes_moan_6(),
        SplittingMethod::blanes_moan_6a(),
    ] {
        let stepper = SplitStepper::new(&system, method).unwrap();
        let d = stepper.step_derivative(&z0, h).expect("regular");
        let error = (d.transpose() * j * d - j).amax();
        assert!(error < 1e-12, "|D^T J D - J| = {error:e}");
        for c in 0..12 {
            let mut dz = Z::zeros();
            dz[c] = e;
            // fresh steppers: no gradient carried over between the two points
            let mut plus = SplitStepper::new(&system, method).unwrap();
            let mut minus = SplitStepper::new(&system, method).unwrap();
            let column = (plus.step(&(z0 + dz), h, &options).unwrap().0
                - minus.step(&(z0 - dz), h, &options).unwrap().0)
                / (2.0 * e);
            assert!((column - d.column(c)).amax() < 1e-7, "column {c}");
        }
    }
}

#[test]
fn the_gradient_carried_to_the_next_step_changes_nothing() {
    // SRKN11b ends with a kick at the next step's first point; a fresh stepper per step
    // recomputes that gradient
    let (system, z0) = setup();
    let method = SplittingMethod::blanes_moan_6();
    let options = StepOptions::default();
    let mut carried = SplitStepper::new(&system, method).unwrap();
    let (mut a, mut b) = (z0, z0);
    for i in 0..10 {
        let h = if i < 5 { 0.1 } else { 0.07 };
        a = carried.step(&a, h, &options).unwrap().0;
        b = SplitStepper::new(&system, method)
            .unwrap()
            .step(&b, h, &options)
            .unwrap()
            .0;
    }
    assert_eq!(a, b);
}

#[test]
fn a_step_into_the_obstacle_and_bad_input_are_errors() {
    let system = RigidBody { tau: 1e-6, r: 1.0 };
    let jet = [
        1.05, 0.0, 0.0, -10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ];
    let z0 = system.legendre(&Z::from_column_slice(&jet));
    let options = StepOptions::default();
    let mut stepper = SplitStepper::new(&system, SplittingMethod::blanes_moan_6a()).unwrap();
    let result = stepper.step(&z0, 0.1, &options);
    assert!(matches!(result, Err(Error::Domain(_))), "{result:?}");
    // off, the step lands inside
    let unchecked = stepper.step(&z0, 0.1, &options.with_domain_check(false));
    assert!(unchecked.is_ok_and(|(z, _)| z[0].hypot(z[1]) < 1.0));
    let result = stepper.step(&z0, 0.0, &options);
    assert!(
        matches!(result, Err(Error::InvalidArgument { .. })),
        "{result:?}"
    );
    let mut bad = z0;
    bad[7] = f64::NAN;
    let result = stepper.step(&bad, 0.1, &options);
    assert!(matches!(result, Err(Error::NonFinite { .. })), "{result:?}");
}

/// k = 3 with the weight m: L = m/2 |q^(3)|^2 + a cos(q_0 q_1) + q_0^4 / 10.
#[higher_order_lagrangian(order = 3)]
fn weighted(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], dddq: [f64; 2], m: f64, a: f64) -> f64 {
    0.5 * m * (dddq[0].powi(2) + dddq[1].powi(2)) + a * (q[0] * q[1]).cos() + 0.1 * q[0].powi(4)
}

#[test]
fn with_a_weight_at_order_3_the_rkn_method_matches_the_midpoint_composition() {
    let system = Weighted { m: 2.5, a: 0.7 };
    let jet = SVector::<f64, 12>::from([
        0.3, -0.2, 0.5, 0.1, -0.4, 0.2, 0.3, 0.0, -0.1, 0.2, 0.05, -0.3,
    ]);
    let z0 = system.legendre(&jet);
    let options = StepOptions::default();
    let steps = 64;
    let h = 1.0 / steps as f64;
    let midpoint = (0..steps).fold(z0, |z, _| {
        composed_step(&system, &z, h, 8, &options)
            .expect("regular")
            .0
    });
    for method in [
        SplittingMethod::blanes_moan_6(),
        SplittingMethod::blanes_moan_6a(),
    ] {
        let mut stepper = SplitStepper::new(&system, method).unwrap();
        let z = (0..steps).fold(z0, |z, _| stepper.step(&z, h, &options).unwrap().0);
        let gap = (z - midpoint).amax();
        assert!(gap < 1e-10, "{gap:e}");
    }
}
