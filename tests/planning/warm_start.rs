//! Warm starts from the plan of a nearby problem: the bounded cart-pole of the constrained
//! suite (C1, `../shared/BENCHMARKS.md`, at a fifth of its steps) re-solved from a plan whose
//! start differs, converges to a certified plan of the new problem in no more iterations than
//! a cold start from the spline.

use retract::bvp::{OptimalControlProblem, Plan, PlanGuess};

use crate::cart_pole::{CartForce, CartPole, PoleTorque};
use crate::common::models::{DISC_GOAL, DISC_START, OneDisc, disc_bump_guess};

/// A warm-started plan `warm` ends at the cold start's cost (to `relative` of it) in no more
/// iterations.
pub fn assert_warm_matches_cold(warm: &Plan<2, 4>, cold: &Plan<2, 4>, relative: f64, case: &str) {
    assert!(
        (warm.cost - cold.cost).abs() <= relative * cold.cost,
        "{case}: warm {} cold {}",
        warm.cost,
        cold.cost
    );
    assert!(
        warm.iterations <= cold.iterations,
        "{case}: warm {} iterations, cold {}",
        warm.iterations,
        cold.iterations
    );
}

const UPRIGHT: [f64; 4] = [0.0, std::f64::consts::PI, 0.0, 0.0];

/// The cart-pole swing-up (T = 2, N = 40) with |F| <= 12, from the cart at `x0`.
fn solve_from(x0: f64, guess: PlanGuess<'_, 2, 4>) -> Plan<2, 4> {
    let system = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, 9.81);
    let force = CartForce::new(1.0, 0.3, 0.5);
    OptimalControlProblem::new(&system, &[x0, 0.0, 0.0, 0.0], &UPRIGHT, 2.0, 40)
        .with_equality(&unactuated)
        .with_function_bounds(&force, -12.0, 12.0)
        .solve(guess)
        .unwrap_or_else(|e| panic!("from x0 = {x0}: {e}"))
}

#[test]
fn a_plan_of_a_nearby_start_warm_starts_in_no_more_iterations_than_cold() {
    let first = solve_from(0.0, PlanGuess::Spline);
    // the default certificate's smallest reduced-Hessian eigenvalue, with the force bound
    // active at some steps (in the null space through the second-order check's penalties)
    let eig = first.certificate.min_reduced_hessian_eig;
    assert!(eig > 0.0 && eig.is_finite(), "{eig}");
    for x0 in [0.02, 0.1, -0.1] {
        let cold = solve_from(x0, PlanGuess::Spline);
        let warm = solve_from(x0, PlanGuess::Plan(&first));
        assert_warm_matches_cold(&warm, &cold, 1e-8, &format!("x0 = {x0}"));
        // the duals come along (14-22 iterations cold, 3-6 warm; 6-12 with the primal
        // iterate alone and the barrier restarted)
        assert!(
            2 * warm.iterations <= cold.iterations,
            "x0 = {x0}: warm {}, cold {}",
            warm.iterations,
            cold.iterations
        );
    }
}

/// The one-disc scene (the obstacle a singular term of the Lagrangian): the plan from one start
/// warm-starts the solve from starts 0.05 and 0.2 higher, in no more iterations than a cold
/// start from the feasible bump guess.
#[test]
fn a_plan_past_the_soft_disc_warm_starts_a_nearby_start() {
    let system = OneDisc { tau: 1e-2 };
    let (x, u) = disc_bump_guess(40);
    let solve = |start: &[f64; 4], guess| {
        OptimalControlProblem::new(&system, start, &DISC_GOAL, 4.0, 40)
            .solve(guess)
            .unwrap_or_else(|e| panic!("{e}"))
    };
    let first = solve(&DISC_START, PlanGuess::Path { x: &x, u: &u });
    for dy in [0.05, 0.2] {
        let start = [
            DISC_START[0],
            DISC_START[1] + dy,
            DISC_START[2],
            DISC_START[3],
        ];
        let cold = solve(&start, PlanGuess::Path { x: &x, u: &u });
        let warm = solve(&start, PlanGuess::Plan(&first));
        assert_warm_matches_cold(&warm, &cold, 1e-9, &format!("dy = {dy}"));
    }
}

/// A plan read back from JSON with a NaN multiplier (written as "NaN") still warm-starts:
/// multipliers that are not finite are not used, as duals that do not fit the problem are
/// not (issue 33, item 7: deserialised values are validated on use).
#[test]
fn a_plan_read_back_with_nan_multipliers_warm_starts_without_them() {
    let first = solve_from(0.0, PlanGuess::Spline);
    let mut value = serde_json::to_value(&first).expect("serialisable");
    value["duals"]["equalities"][3][0] = "NaN".into();
    let read: Plan<2, 4> = serde_json::from_value(value).expect("NaN reads back");
    assert!(read.duals.equalities[3][0].is_nan());
    let warm = solve_from(0.02, PlanGuess::Plan(&read));
    let cold = solve_from(0.02, PlanGuess::Spline);
    assert_warm_matches_cold(&warm, &cold, 1e-8, "NaN multiplier");
}
