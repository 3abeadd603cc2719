//! Robustness of the runtime: a step is accepted only with a small residual row by row, the
//! reduced stepper's cache of factorisations, and sizes too large for memory.

use crate::common;

use common::models::RigidBody;
use retract::bvp::root_finder::{BoundaryValueProblem, BvpOptions, Guess};
use retract::nalgebra::SVector;
use retract::reduced::CACHE_SIZE;
use retract::{Error, LiftedSystem, ReducedStepper, StepOptions, step, trajectory};

type Z = SVector<f64, 12>;

fn body() -> (RigidBody, Z) {
    let system = RigidBody { tau: 1e-2, r: 1.0 };
    let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let z0 = system.legendre(&Z::from_column_slice(&jet));
    (system, z0)
}

/// The largest row of |F(z0, w)| beyond the absolute tolerance 1e-14 of the residual test,
/// over its scale: the sum of the magnitudes of the row's linear terms
/// |dF/dw| |w| + |dF/dz0| |z0| (0 for a row that meets the absolute test).
fn scaled_residual(system: &RigidBody, z0: &Z, w: &SVector<f64, 15>, h: f64) -> f64 {
    let f = system.residual(z0, w, h, 0.5);
    let scale = system.jacobian(z0, w, h, 0.5).abs() * w.abs()
        + system.jacobian_initial(z0, w, h, 0.5).abs() * z0.abs();
    f.iter()
        .zip(scale.iter())
        .map(|(fi, si)| (fi.abs() - 1e-14).max(0.0) / si)
        .fold(0.0, f64::max)
}

#[test]
fn converged_means_a_small_residual_in_every_row() {
    // one huge entry (a momentum of 1e154) made every Newton step small against |w|_inf, so
    // the general step returned an iterate whose position rows were off by 1 (residual 1.05
    // against terms of 1.05: the y position of the step was 0 instead of 1.05)
    let (system, z0) = body();
    let h = 0.01;
    let options = StepOptions::default();
    let mut checked = 0;
    for index in 0..12 {
        for size in [1e20, 1e50, 1e100, 1e154] {
            let mut z = z0;
            z[index] = size;
            let general = system
                .predictor(&z, h, 0.5)
                .and_then(|guess| retract::step::solve_step(&system, &z, guess, h, &options));
            let Ok((w, report)) = general else {
                continue; // a typed error is an answer; a wrong Ok is not
            };
            let scaled = scaled_residual(&system, &z, &w, h);
            assert!(
                scaled < 1e-12,
                "z[{index}] = {size:e}: accepted with a row of the residual {scaled:e} of its \
                 terms ({report:?})"
            );
            // the reduced step solves the same equations: the same state, entry by entry
            let mut stepper = ReducedStepper::new(&system);
            if let Ok((reduced, _)) = stepper.step(&z, h, &options) {
                for (i, (a, b)) in w.iter().zip(reduced.iter()).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                        "z[{index}] = {size:e}: entry {i} is {a:e}, the reduced step's {b:e}"
                    );
                }
                checked += 1;
            }
        }
    }
    assert!(checked >= 30, "only {checked} cases compared");
    // the case of the issue: p0x = 1e154 converges, to the reduced step's state
    let mut z = z0;
    z[6] = 1e154;
    let (z1, report) = step(&system, &z, h, &options).expect("a representable step");
    let (reduced, _) = ReducedStepper::new(&system)
        .step(&z, h, &options)
        .expect("a representable step");
    assert!(
        (z1[1] - 1.05).abs() < 1e-12 && (reduced[1] - 1.05).abs() < 1e-12,
        "{z1:?}"
    );
    assert!(report.iterations >= 1);
}

#[test]
fn alternating_up_to_16_step_sizes_factorises_once_per_size() {
    assert_eq!(CACHE_SIZE, 16);
    let (system, z0) = body();
    let options = StepOptions::default();
    for sizes in 9..=CACHE_SIZE {
        let mut stepper = ReducedStepper::new(&system);
        let mut z = z0;
        let rounds = 20;
        for round in 0..rounds {
            for k in 0..sizes {
                let h = 1e-3 * (1.0 + k as f64 / 16.0);
                z = stepper.step(&z, h, &options).expect("regular").0;
            }
            // once per size in the first round, never again
            assert_eq!(
                stepper.factorisations(),
                sizes,
                "{sizes} alternating sizes, round {round}"
            );
        }
        assert!(z.iter().all(|v| v.is_finite()));
    }
    // a constant size factorises once; a new size once more; the least recently used size is
    // the one replaced, so a size used every other step survives 15 others going through
    let mut stepper = ReducedStepper::new(&system);
    let mut z = z0;
    for _ in 0..100 {
        z = stepper.step(&z, 1e-3, &options).expect("regular").0;
    }
    assert_eq!(stepper.factorisations(), 1);
    for k in 0..64 {
        z = stepper.step(&z, 1e-3, &options).expect("regular").0;
        z = stepper
            .step(&z, 2e-3 + 1e-6 * k as f64, &options)
            .expect("regular")
            .0;
    }
    assert_eq!(stepper.factorisations(), 65);
    // a composition of order 8 (8 distinct stage sizes) factorises 8 times over many steps
    let mut stepper = ReducedStepper::new(&system);
    let mut z = z0;
    for _ in 0..50 {
        z = retract::compose::compose(|z, h| stepper.step(z, h, &options), &z, 1e-2, 8)
            .expect("regular")
            .0;
    }
    assert_eq!(stepper.factorisations(), 8);
}

fn assert_too_large(error: &Error, name: &str) {
    assert!(
        matches!(error, Error::InvalidArgument { name: n, .. } if *n == name),
        "{error:?}"
    );
}

#[test]
fn sizes_too_large_for_memory_are_invalid_arguments() {
    let (system, z0) = body();
    let options = StepOptions::default();
    // trajectories: no `capacity overflow`, no overflow in steps + 1, no allocation abort
    for steps in [1usize << 40, usize::MAX / 2, usize::MAX - 1, usize::MAX] {
        let stop = trajectory(&system, &z0, 0.01, steps, &options).unwrap_err();
        assert_too_large(&stop.error, "steps");
        assert!(stop.trajectory.states.is_empty() && stop.step == 0);
        let mut stepper = ReducedStepper::new(&system);
        let stop = stepper.trajectory(&z0, 0.01, steps, &options).unwrap_err();
        assert_too_large(&stop.error, "steps");
    }
    // boundary-value problems: N (N M + S unknowns) and the number of obstacles
    let (start, goal) = (
        [-2.0, 1.5, 0.0, 1.0, 0.0, 0.0],
        [2.0, 1.5, 0.0, 1.0, 0.0, 0.0],
    );
    let clearance = |_: &Z, out: &mut [f64]| out.fill(1.0);
    for steps in [1usize << 40, 1 << 60, usize::MAX / 2, usize::MAX] {
        let problem = BoundaryValueProblem::new(&system, &start, &goal, 4.0, steps);
        assert_too_large(&problem.solve(Guess::Spline).unwrap_err(), "steps");
        let problem = BoundaryValueProblem::new(&system, &start, &goal, 4.0, steps);
        assert_too_large(&problem.solve_reduced(Guess::Spline).unwrap_err(), "steps");
    }
    for obstacles in [usize::MAX / 2, usize::MAX] {
        let problem = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 10)
            .with_clearance(obstacles, &clearance);
        assert_too_large(&problem.solve(Guess::Spline).unwrap_err(), "obstacles");
    }
    // solve_reduced checks its arguments before forming the step map (h = T / N)
    for (t_end, steps) in [(4.0, 0), (f64::NAN, 10), (f64::INFINITY, 10), (-1.0, 10)] {
        let problem = BoundaryValueProblem::new(&system, &start, &goal, t_end, steps);
        for result in [
            problem.solve(Guess::Spline),
            problem.solve_reduced(Guess::Spline),
        ] {
            assert!(
                matches!(result, Err(Error::InvalidArgument { .. })),
                "T = {t_end}, N = {steps}: {result:?}"
            );
        }
    }
    // a tolerance that every residual meets is no tolerance: rejected, not the guess as Ok
    for tolerance in [f64::INFINITY, f64::NAN, -1.0] {
        let problem = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 10)
            .with_options(BvpOptions::default().with_residual_tolerance(tolerance));
        for result in [
            problem.solve(Guess::Spline),
            problem.solve_reduced(Guess::Spline),
        ] {
            assert!(
                matches!(
                    result,
                    Err(Error::InvalidArgument {
                        name: "options",
                        ..
                    })
                ),
                "tolerance {tolerance}: {result:?}"
            );
        }
    }
    // and a problem of ordinary size still solves, with its obstacle clearance
    let solved = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 40)
        .with_clearance(1, &clearance)
        .solve_reduced(Guess::Spline)
        .expect("a regular problem");
    assert_eq!(solved.states.len(), 41);
    assert_eq!(solved.clearance, vec![1.0]);
}
