//! Symmetric compositions of the midpoint rule: observed orders 4, 6 and 8, and a symplectic
//! composed map.

use crate::common;

use common::models::RigidBody;
use retract::compose::{coefficients, compose_with, triple_jump};
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

/// `steps` composed steps over [0, t_end] with the step-size fractions `gamma`.
fn run(system: &RigidBody, z0: &Z, t_end: f64, steps: usize, gamma: &[f64]) -> Z {
    let options = StepOptions::default();
    let h = t_end / steps as f64;
    let mut stepper = ReducedStepper::new(system);
    let mut z = *z0;
    for _ in 0..steps {
        z = compose_with(|z, h| stepper.step(z, h, &options), &z, h, gamma)
            .expect("regular")
            .0;
    }
    z
}

/// Observed order of the last refinement in `sweep` against a reference from the order-8
/// Kahan-Li composition with many steps.
fn observed_order(gamma: &[f64], sweep: &[usize]) -> f64 {
    let (system, z0) = setup();
    let (reference_gamma, len) = coefficients(8).unwrap();
    let reference = run(&system, &z0, 1.0, 256, &reference_gamma[..len]);
    let errors: Vec<f64> = sweep
        .iter()
        .map(|&n| (run(&system, &z0, 1.0, n, gamma) - reference).amax())
        .collect();
    println!("{} stages: errors {errors:?}", gamma.len());
    let k = sweep.len() - 1;
    // log(e(N_a) / e(N_b)) / log(N_b / N_a), for non-doubling sweeps too
    (errors[k - 1] / errors[k]).ln() / (sweep[k] as f64 / sweep[k - 1] as f64).ln()
}

#[test]
fn compositions_reach_orders_four_six_and_eight() {
    for (order, sweep, range) in [
        (4, [8, 16, 32, 64], 3.8..4.3),
        (6, [4, 8, 16, 32], 5.6..6.6),
        (8, [4, 6, 9, 13], 7.0..9.5),
    ] {
        for (family, set) in [
            ("cheapest", coefficients as fn(u32) -> _),
            ("triple jump", triple_jump),
        ] {
            let (gamma, len) = set(order).unwrap();
            let rate = observed_order(&gamma[..len], &sweep);
            assert!(
                range.contains(&rate),
                "{family}, order {order}: observed {rate:.2}"
            );
        }
    }
}

/// At equal work (stages times steps) the Kahan-Li methods are more accurate than the
/// triple jumps of the same order.
#[test]
fn kahan_li_beats_the_triple_jump_at_equal_work() {
    for (order, steps, triple_steps) in [(6, 8, 8), (8, 9, 5)] {
        let (kl, kl_len) = coefficients(order).unwrap();
        let (tj, tj_len) = triple_jump(order).unwrap();
        let (system, z0) = setup();
        let (reference_gamma, len) = coefficients(8).unwrap();
        let reference = run(&system, &z0, 1.0, 256, &reference_gamma[..len]);
        let e_kl = (run(&system, &z0, 1.0, steps, &kl[..kl_len]) - reference).amax();
        let e_tj = (run(&system, &z0, 1.0, triple_steps, &tj[..tj_len]) - reference).amax();
        println!(
            "order {order}: Kahan-Li {e_kl:e} ({} stages), triple jump {e_tj:e} ({} stages)",
            steps * kl_len,
            triple_steps * tj_len
        );
        assert!(steps * kl_len <= triple_steps * tj_len);
        assert!(
            e_kl < e_tj,
            "order {order}: Kahan-Li {e_kl:e}, triple jump {e_tj:e}"
        );
    }
}

#[test]
fn composed_map_is_symplectic() {
    let (system, z0) = setup();
    let options = StepOptions::default();
    for order in [4, 6, 8] {
        let (gamma, stages) = coefficients(order).unwrap();
        assert!(stages > 1);
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
