//! The feasibility restoration phase: a guess from which the filter line search jams (the
//! slacks of the thrust bounds and the disc at their bounds, the steps cut to nothing) is
//! brought back to the feasible region and the plan certified; a phase that cannot lower the
//! violation at all names the point locally infeasible, and the constraint it names is the
//! one violated most, the fixed ends and the dynamics included.

use std::f64::consts::PI;

use crate::cart_pole::{CartForce, CartPole, PoleTorque};
use crate::quadrotor::{Clearance, Lateral, Quadrotor, Rotors};
use retract::bvp::{
    ConstraintKind, Curve, Failure, Location, OptimalControlProblem, Plan, PlanError, PlanGuess,
    PlanOptions,
};

/// The quadrotor of the constrained suite (thrusts in [0, 15], the disc, T = 2, N = 50) from
/// the zero guess: every thrust starts at its lower bound, far from the hover thrust; the
/// filter line search takes steps of 1e-3 and shorter and, with the restoration phase off,
/// the solve fails (stalled infeasible after 735 iterations). With it (the default), the plan
/// is certified at IPOPT's
/// minimum on the same transcription from the same guess, J = 51.514725806 (IPOPT 3.14 with
/// MUMPS through CasADi, tol 1e-10, 51 iterations; the reference script `ip.py` with
/// `'{"prob":"quad","T":2.0,"N":50,"kind":"Zero","F":15.0,"goal":[2.0,1.0,0.0]}'`).
#[test]
fn the_quadrotor_from_the_zero_guess_is_restored_and_certified() {
    let (m, inertia, arm) = (1.0, 0.01, 0.1);
    let zero = Curve::from_derivatives(|_, _| [0.0; 3]);
    let (system, lateral) = (Quadrotor::new(m, inertia, arm), Lateral::new(m));
    let (rotors, disc) = (Rotors::new(m, inertia, arm), Clearance::new());
    let goal = [2.0, 1.0, 0.0, 0.0, 0.0, 0.0];
    let problem = OptimalControlProblem::new(&system, &[0.0; 6], &goal, 2.0, 50)
        .with_equality(&lateral)
        .with_vector_bounds(&rotors, &[0.0; 2], &[15.0; 2])
        .with_inequality(&disc);
    let plan = problem
        .solve(PlanGuess::Curve(&zero))
        .unwrap_or_else(|e| panic!("{e}"));
    let off = PlanOptions::default().with_restoration(false);
    match problem.with_options(off).solve(PlanGuess::Curve(&zero)) {
        Err(e) => assert!(matches!(e.failure, Failure::StalledInfeasible(_)), "{e}"),
        Ok(plan) => panic!("certified without restoration: J = {}", plan.cost),
    }
    assert_eq!(plan.certificate.negative_directions, 0);
    assert!(plan.violations.imposed() <= 1e-8, "{:?}", plan.violations);
    let ipopt = 51.514_725_806_007_796;
    assert!(
        (plan.cost - ipopt).abs() <= 1e-7 * ipopt,
        "J = {}",
        plan.cost
    );
}

/// The cart-pole of the constrained suite with a force bound too small to swing it up in
/// time (|F| <= 5, T = 2.5, N = 50), from the straight line: the filter's steps shrink to
/// nothing at a violation the restoration phase cannot lower either, and the solve names
/// the stall an infeasibility in a few dozen iterations (it ran to the iteration limit,
/// 3000, when a phase without progress was only retried). IPOPT on the same transcription
/// from the smoothstep also ends in local infeasibility (`Infeasible_Problem_Detected`,
/// 224 iterations, CasADi, tol 1e-10); every guess of the failure hunt
/// (`cargo run --release --example hunt -- cartpole "T=2.5 F=5 N=50"`) fails here.
#[test]
fn a_restoration_without_progress_names_the_infeasibility() {
    let t_end = 2.5;
    let line = Curve::from_fn(move |t| [0.0, PI * t / t_end]);
    let error = match swing_up(5.0, (t_end, 50), PlanGuess::Curve(&line)) {
        Err(e) => e,
        Ok(plan) => panic!("certified with |F| <= 5: J = {}", plan.cost),
    };
    let Failure::StalledInfeasible(infeasibility) = &error.failure else {
        panic!("{error}");
    };
    assert!(infeasibility.violation > 1e-3, "{infeasibility}");
    let last = error.last.as_ref().expect("the last iterate");
    assert!(last.iterations < 500, "{} iterations", last.iterations);
    // from the zero path (the goal's node too) the solve stalls with the goal's angle missed
    // by more than any constraint is violated (0.38): the miss is named
    let zero = Curve::from_derivatives(|_, _| [0.0; 2]);
    let error = match swing_up(5.0, (t_end, 50), PlanGuess::Curve(&zero)) {
        Err(e) => e,
        Ok(plan) => panic!("certified with |F| <= 5: J = {}", plan.cost),
    };
    let Failure::StalledInfeasible(missed) = &error.failure else {
        panic!("{error}");
    };
    let last = error.last.as_ref().expect("the last iterate");
    assert_eq!(missed.constraint.kind, ConstraintKind::FixedEnd, "{error}");
    assert_eq!(
        (missed.constraint.index, missed.location),
        (1, Location::Goal)
    );
    assert_eq!(missed.violation, last.certificate.feasibility, "{error}");
    assert!(last.violations.imposed() <= missed.violation, "{error}");
    assert!(error.to_string().contains("misses the goal's jet entry 1"));
}

/// The cart-pole of the constrained suite with |F| <= 8, T = 2.5 on a fine grid (N = 800)
/// from the smoothstep, certified at IPOPT's minimum on the same transcription from the same
/// guess, J = 20.4183113258 in 85 iterations (`NSTEPS=800 python3
/// validation/ipopt/constrained_suite.py cartpole-T2.5-F8`), in no more iterations. The two
/// sides of |F| <= 8 have a slack each where IPOPT has one, and the line search's constraint
/// violation counted the nonlinearity of F in both: the first full step raised it (802
/// against IPOPT's 511 at the same trial point), the steps shrank to 1e-5 and the solve
/// stalled as infeasible after 359 iterations. Each side now weighs a half.
#[test]
fn both_sides_of_a_bound_count_once_in_the_violation() {
    let plan = swing_up(8.0, (2.5, 800), PlanGuess::Spline).unwrap_or_else(|e| panic!("{e}"));
    let ipopt = 20.418_311_325_8;
    assert!(
        (plan.cost - ipopt).abs() <= 1e-7 * ipopt,
        "J = {}",
        plan.cost
    );
    assert!(plan.iterations <= 85, "{} iterations", plan.iterations);
    assert_eq!(plan.certificate.negative_directions, 0);
    assert!(plan.violations.imposed() <= 1e-8, "{:?}", plan.violations);
}

/// The cart-pole of the constrained suite (rest to upright) with |F| <= `limit`, horizon and
/// steps `(t_end, steps)`, solved from `guess`.
fn swing_up(
    limit: f64,
    (t_end, steps): (f64, usize),
    guess: PlanGuess<'_, 2, 4>,
) -> Result<Plan<2, 4>, PlanError<2, 4>> {
    let (mc, mp, l) = (1.0, 0.3, 0.5);
    let system = CartPole::new(mc, mp, l);
    let unactuated = PoleTorque::new(mp, l, 9.81);
    let force = CartForce::new(mc, mp, l);
    OptimalControlProblem::new(&system, &[0.0; 4], &[0.0, PI, 0.0, 0.0], t_end, steps)
        .with_equality(&unactuated)
        .with_function_bounds(&force, -limit, limit)
        .solve(guess)
}
