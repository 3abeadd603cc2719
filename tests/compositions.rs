//! Symmetric compositions of the midpoint rule: observed orders 4, 6 and 8, and a symplectic
//! composed map.

mod common;

use common::models::RigidBody;
use retract::compose::coefficients;
use retract::diagnostics::{canonical_structure, step_map_derivative};
use retract::nalgebra::{SMatrix, SVector};
use retract::{LiftedSystem, ReducedStepper, StepOptions, composed_step};

type Z = SVector<f64, 12>;

fn setup() -> (RigidBody, Z) {
    let system = RigidBody { tau: 0.5, r: 1.0 };
    let jet = [
        -2.0, 1.2, 0.0, 1.0, 0.0, 0.5, 0.1, -0.2, 0.3, 0.0, 0.1, -0.2,
    ];
    let z0 = system.legendre(&Z::from_column_slice(&jet));
    (system, z0)
}

fn run(system: &RigidBody, z0: &Z, t_end: f64, steps: usize, order: u32) -> Z {
    let options = StepOptions::default();
    let h = t_end / steps as f64;
    let mut z = *z0;
    for _ in 0..steps {
        z = composed_step(system, &z, h, order, &options)
            .expect("regular")
            .0;
    }
    z
}

/// log2(e(N) / e(2N)) against a reference from the order-8 composition with many steps.
fn orders(order: u32, sweep: &[usize]) -> Vec<f64> {
    let (system, z0) = setup();
    let reference = run(&system, &z0, 1.0, 256, 8);
    let errors: Vec<f64> = sweep
        .iter()
        .map(|&n| (run(&system, &z0, 1.0, n, order) - reference).amax())
        .collect();
    println!("order {order}: errors {errors:?}");
    errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
}

#[test]
fn compositions_reach_orders_four_six_and_eight() {
    for (order, sweep, range) in [
        (4, [8, 16, 32, 64], 3.8..4.3),
        (6, [4, 8, 16, 32], 5.6..6.6),
        (8, [4, 6, 9, 13], 7.0..9.5),
    ] {
        let observed = orders(order, &sweep);
        let last = observed[observed.len() - 1];
        let (a, b) = (sweep[sweep.len() - 2] as f64, sweep[sweep.len() - 1] as f64);
        let rate = last / (b / a).log2(); // generalise log2 to non-doubling sweeps
        assert!(
            range.contains(&rate),
            "order {order}: observed {rate:.2} ({observed:?})"
        );
    }
}

#[test]
fn composed_map_is_symplectic() {
    let (system, z0) = setup();
    let options = StepOptions::default();
    for order in [4, 6, 8] {
        let (gamma, stages) = coefficients(order).unwrap();
        let mut z = z0;
        let mut d_psi = SMatrix::<f64, 12, 12>::identity();
        for &g in &gamma[..stages] {
            let (next, d) = step_map_derivative(&system, &z, g * 0.1, &options).unwrap();
            d_psi = d * d_psi;
            z = next;
        }
        let j = canonical_structure::<12>();
        let err = (d_psi.transpose() * j * d_psi - j).amax();
        assert!(err < 1e-12, "order {order}: {err:e}");
    }
}

#[test]
fn reduced_stepper_composes_too() {
    let (system, z0) = setup();
    let options = StepOptions::default();
    let mut stepper = ReducedStepper::new(&system);
    let (fast, _) =
        retract::compose::compose(|z, h| stepper.step(z, h, &options), &z0, 0.1, 6).unwrap();
    let (general, _) = composed_step(&system, &z0, 0.1, 6, &options).unwrap();
    assert!((fast - general).amax() < 1e-13);
    assert!(composed_step(&system, &z0, 0.1, 4, &options.with_theta(0.3)).is_err());
}
