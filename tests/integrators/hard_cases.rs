//! Hard cases through the macro. Each ends in convergence or a typed error: never a NaN in
//! a returned state, never a panic.

use crate::common;

use common::models::{RigidBody, bounded_pais_uhlenbeck};
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{
    Error, Interrupted, LiftedSystem, NewtonOptions, ReducedStepper, StepOptions, Trajectory, step,
    trajectory,
};

/// Minimum snap with a potential, k = 4.
#[higher_order_lagrangian(order = 4)]
fn snap(
    q: [f64; 2],
    _dq: [f64; 2],
    _ddq: [f64; 2],
    _dddq: [f64; 2],
    d4q: [f64; 2],
    kappa: f64,
) -> f64 {
    0.5 * (d4q[0].powi(2) + d4q[1].powi(2)) + kappa * (q[0] * q[1]).cos()
}

/// Every returned state is finite; an error is typed (its message is not empty).
fn sound<const S: usize>(result: &Result<Trajectory<S>, Interrupted<S>>) {
    let states = match result {
        Ok(run) => &run.states,
        Err(stop) => {
            assert!(!stop.to_string().is_empty());
            &stop.trajectory.states
        }
    };
    assert!(states.iter().all(|z| z.iter().all(|v| v.is_finite())));
}

fn body(tau: f64, jet: [f64; 12]) -> (RigidBody, SVector<f64, 12>) {
    let system = RigidBody { tau, r: 1.0 };
    let z0 = system.legendre(&SVector::from_column_slice(&jet));
    (system, z0)
}

#[test]
fn grazing_the_barrier_at_a_millionth() {
    // aimed to pass 1e-6 above the unit circle; tau small enough not to push it away first
    let (system, z0) = body(
        1e-14,
        [
            -2.0, 1.000001, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
        ],
    );
    let result = trajectory(&system, &z0, 1e-3, 4000, &StepOptions::default());
    sound(&result);
    let run = result.expect("a grazing pass stays outside");
    let closest = run
        .states
        .iter()
        .map(|z| z[0].hypot(z[1]) - 1.0)
        .fold(f64::INFINITY, f64::min);
    assert!(closest > 0.0 && closest < 2e-6, "closest {closest:e}");
}

#[test]
fn barrier_weights_from_1e_minus_20_to_1e2() {
    for exponent in [-20, -15, -10, -5, -2, 0, 1, 2] {
        let tau = 10f64.powi(exponent);
        let (system, z0) = body(
            tau,
            [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        );
        let result = trajectory(&system, &z0, 0.01, 400, &StepOptions::default());
        sound(&result);
        if exponent <= -2 {
            assert!(result.is_ok(), "tau = {tau:e}: {}", result.unwrap_err());
        }
    }
}

#[test]
fn a_step_too_large_for_newton_is_reported_and_halving_recovers() {
    // A controller caps Newton at 3 iterations; next to a strong barrier a step of h = 1
    // needs about 10 (measured), so it fails with an error that points at the step size.
    let (system, z0) = body(
        10.0,
        [-1.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    let capped =
        StepOptions::default().with_newton(NewtonOptions::default().with_max_iterations(3));
    let e = step(&system, &z0, 1.0, &capped).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NoConvergence { .. } | Error::LineSearchFailed { .. }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("reduce the step size"), "{e}");
    // with halving allowed, the trajectory driver splits the step and reports it
    let result = trajectory(&system, &z0, 1.0, 1, &capped.with_max_halvings(8));
    sound(&result);
    let run = result.expect("halving recovers");
    assert!(run.reports[0].halvings > 0, "{:?}", run.reports);
    assert_eq!(run.states.len(), 2);
    // the halved step is exactly 2^m plain substeps of h / 2^m
    let pieces = 1usize << run.reports[0].halvings;
    let plain = trajectory(
        &system,
        &z0,
        1.0 / pieces as f64,
        pieces,
        &StepOptions::default(),
    )
    .unwrap();
    assert!((run.states[1] - plain.states[pieces]).amax() < 1e-12);
}

#[test]
fn nan_and_infinite_inputs_and_parameters() {
    let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        // parameter
        let (system, z0) = body(bad, jet);
        let result = trajectory(&system, &z0, 0.01, 10, &StepOptions::default());
        sound(&result);
        // named, not a bare non-finite residual
        let error = result.unwrap_err().error;
        assert!(
            matches!(error, Error::NonFiniteParameter { name: "tau", .. }),
            "{error}"
        );
        // state
        let (system, mut z0) = body(1e-2, jet);
        z0[4] = bad;
        let result = trajectory(&system, &z0, 0.01, 10, &StepOptions::default());
        sound(&result);
        assert!(result.unwrap_err().trajectory.states.is_empty());
        // step size and theta
        let (system, z0) = body(1e-2, jet);
        assert!(matches!(
            step(&system, &z0, bad, &StepOptions::default()),
            Err(Error::InvalidArgument { .. })
        ));
        let theta = StepOptions::default().with_theta(bad);
        assert!(matches!(
            step(&system, &z0, 0.01, &theta),
            Err(Error::InvalidArgument { .. })
        ));
    }
}

#[test]
fn reduced_step_on_non_finite_and_overflowing_states_is_an_error() {
    let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let (system, z0) = body(1e-2, jet);
    let options = StepOptions::default();
    let mut stepper = ReducedStepper::new(&system);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut z = z0;
        z[4] = bad;
        assert!(matches!(
            stepper.step(&z, 0.01, &options),
            Err(Error::NonFinite {
                location: "state",
                ..
            })
        ));
    }
    // finite, but v + h p1 overflows in the recovered velocity while the core stays finite
    let mut z = z0;
    z[3] = f64::MAX;
    z[9] = f64::MAX;
    let result = stepper.step(&z, 0.01, &options);
    assert!(matches!(result, Err(Error::NonFinite { .. })), "{result:?}");
    // near the overflow threshold: a finite step or an error, never a non-finite state
    for size in [1e300, 1e307, f64::MAX / 4.0, f64::MAX / 2.0] {
        for (i, j) in [(3, 9), (0, 3), (9, 6), (2, 11)] {
            let mut z = z0;
            z[i] = size;
            z[j] = size;
            if let Ok((z1, _)) = stepper.step(&z, 0.01, &options) {
                assert!(z1.iter().all(|v| v.is_finite()), "{size:e} at {i}, {j}");
            }
        }
    }
    // invalid step sizes and theta, also after a valid step cached its factors
    for h in [f64::NAN, f64::INFINITY, 0.0] {
        assert!(matches!(
            stepper.step(&z0, h, &options),
            Err(Error::InvalidArgument { name: "h", .. })
        ));
    }
    for theta in [f64::NAN, -0.5, 1.5] {
        assert!(matches!(
            stepper.step(&z0, 0.01, &options.with_theta(theta)),
            Err(Error::InvalidArgument { name: "theta", .. })
        ));
    }
    // large and representable: a finite step
    let mut z = z0;
    z[3] = 1e150;
    let (z1, _) = stepper.step(&z, 0.01, &options).expect("finite");
    assert!(z1.iter().all(|v| v.is_finite()));
}

#[test]
fn order_four_with_a_tiny_step() {
    let system = Snap { kappa: 0.5 };
    let jet = SVector::<f64, 16>::from_column_slice(&[
        0.3, -0.2, 1.0, 0.5, -0.3, 0.2, 0.7, -0.4, 0.5, 0.3, -0.6, 0.8, 0.2, 0.1, -0.3, 0.4,
    ]);
    let z0 = system.legendre(&jet);
    let result = trajectory(&system, &z0, 1e-4, 1000, &StepOptions::default());
    sound(&result);
    let run = result.expect("h = 1e-4 converges");
    assert!(
        run.max_iterations() <= 4,
        "max iterations {}",
        run.max_iterations()
    );
    // and agrees with a coarser run at t = 0.1 to the scheme's order
    let coarse = trajectory(&system, &z0, 1e-3, 100, &StepOptions::default()).unwrap();
    let diff = (coarse.states[100] - run.states[1000]).amax();
    assert!(diff < 1e-5, "h = 1e-3 vs 1e-4 at t = 0.1: {diff:e}");
}

#[test]
fn angular_momentum_over_a_million_steps() {
    // L is invariant under rotations of the plane, so J = q x p_0 + q' x p_1 is conserved;
    // the midpoint rule preserves quadratic invariants.
    let (system, z0) = bounded_pais_uhlenbeck();
    let momentum = |z: &SVector<f64, 8>| {
        let cross = |a: usize, b: usize| z[a] * z[b + 1] - z[a + 1] * z[b];
        cross(0, 4) + cross(2, 6)
    };
    let j0 = momentum(&z0);
    assert!(j0.abs() > 1e-3);
    let options = StepOptions::default();
    let mut z = z0;
    let mut worst: f64 = 0.0;
    for i in 0..1_000_000 {
        z = step(&system, &z, 0.1, &options)
            .unwrap_or_else(|e| panic!("step {i}: {e}"))
            .0;
        if i % 1000 == 0 {
            worst = worst.max(((momentum(&z) - j0) / j0).abs());
        }
    }
    worst = worst.max(((momentum(&z) - j0) / j0).abs());
    assert!(
        worst < 1e-10,
        "relative drift of the angular momentum {worst:e}"
    );
}
