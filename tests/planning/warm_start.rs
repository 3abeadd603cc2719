//! Warm starts from the plan of a nearby problem: the bounded cart-pole of the constrained
//! suite (C1, `../shared/BENCHMARKS.md`, at a fifth of its steps) re-solved from a plan whose
//! start differs, converges to a certified plan of the new problem in no more iterations than
//! a cold start from the spline.

use retract::bvp::{OptimalControlProblem, Plan, PlanGuess, PlanOptions};

use crate::cart_pole::{CartForce, CartPole, PoleTorque};
use crate::common::models::{DISC_GOAL, DISC_START, DoublePendulum, OneDisc, disc_bump_guess};

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

/// The double pendulum's upright rest.
const UPRIGHT_PENDULUM: [f64; 4] = [std::f64::consts::PI, 0.0, 0.0, 0.0];

/// The cart-pole swing-up (T = 2, N = 40) with |F| <= 12, from the cart at `x0`.
fn solve_from(x0: f64, guess: PlanGuess<'_, 2, 4>) -> Plan<2, 4> {
    solve_under(x0, guess, PlanOptions::default())
}

/// [`solve_from`] under `options`.
fn solve_under(x0: f64, guess: PlanGuess<'_, 2, 4>, options: PlanOptions) -> Plan<2, 4> {
    let system = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, 9.81);
    let force = CartForce::new(1.0, 0.3, 0.5);
    OptimalControlProblem::new(&system, &[x0, 0.0, 0.0, 0.0], &UPRIGHT, 2.0, 40)
        .with_equality(&unactuated)
        .with_function_bounds(&force, -12.0, 12.0)
        .with_options(options)
        .solve(guess)
        .unwrap_or_else(|e| panic!("tolerance {:e}, x0 = {x0}: {e}", options.tolerance))
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

/// The largest difference between two plans' jets and controls.
fn plan_distance(a: &Plan<2, 4>, b: &Plan<2, 4>) -> f64 {
    let jets = a.x.iter().zip(&b.x).map(|(p, q)| (p - q).amax());
    let controls = a.u.iter().zip(&b.u).map(|(p, q)| (p - q).amax());
    jets.chain(controls).fold(0.0, f64::max)
}

/// A warm-started plan `warm` ends with its stationarity and feasibility below `tolerance`
/// (not at the acceptable level), at the cold start's plan (to `distance`), in no more
/// iterations.
fn assert_converged_as_cold(
    (warm, cold): (&Plan<2, 4>, &Plan<2, 4>),
    (tolerance, distance): (f64, f64),
    case: &str,
) {
    let c = &warm.certificate;
    eprintln!(
        "{case}: warm {} iterations, stationarity {:.1e}; cold {}, {:.1e}; distance {:.1e}",
        warm.iterations,
        c.stationarity,
        cold.iterations,
        cold.certificate.stationarity,
        plan_distance(warm, cold)
    );
    assert!(
        c.stationarity <= tolerance && c.feasibility <= tolerance,
        "{case}: stationarity {:e}, feasibility {:e} (cold {:e})",
        c.stationarity,
        c.feasibility,
        cold.certificate.stationarity
    );
    let apart = plan_distance(warm, cold);
    assert!(
        apart <= distance,
        "{case}: warm and cold plans {apart:e} apart"
    );
    assert!(
        warm.iterations <= cold.iterations,
        "{case}: warm {} iterations, cold {}",
        warm.iterations,
        cold.iterations
    );
}

/// Warm starts with active bounds converge to the tolerance, not at the acceptable level: the
/// bounded cart-pole above (|F| <= 12 active on some steps), at the default tolerance and at
/// 1e-12, re-solved from its own plan and from the plan of the start x0 = 0 at nearby starts,
/// ends below the tolerance at the cold start's plan (to 1e-8 and 1e-10), in no more
/// iterations.
/// At the default tolerance and at 1e-12: the plan `solve(base, Spline)` has an active bound
/// (a multiplier above 1e-3), and for each parameter of `nearby` the solve warm-started from
/// it converges as the cold one ([`assert_converged_as_cold`], to 1e3 times the tolerance).
fn assert_warm_starts_converge(
    what: &str,
    (base, nearby): (f64, &[f64]),
    solve: impl Fn(f64, PlanGuess<'_, 2, 4>, PlanOptions) -> Plan<2, 4>,
) {
    let default = PlanOptions::default().tolerance;
    for tolerance in [default, 1e-12] {
        let options = PlanOptions::default().with_tolerance(tolerance);
        let first = solve(base, PlanGuess::Spline, options);
        let bound = first.duals.step_multipliers.iter().filter(|z| **z > 1e-3);
        assert!(
            bound.count() > 0,
            "{what}: the bound is active at some steps"
        );
        for &p in nearby {
            let cold = solve(p, PlanGuess::Spline, options);
            let warm = solve(p, PlanGuess::Plan(&first), options);
            let case = format!("{what}, tolerance {tolerance:e}, parameter {p}");
            assert_converged_as_cold(
                (&warm, &cold),
                (tolerance, 1e3 * tolerance.max(1e-11)),
                &case,
            );
        }
    }
}

#[test]
fn warm_starts_with_active_bounds_converge_to_the_tolerance() {
    let nearby = [0.0, 0.02, 0.1, -0.1];
    assert_warm_starts_converge("cart-pole x0", (0.0, &nearby), solve_under);
}

/// The swing-up (T = 2, N = 40) with |q''| <= 22 on both joints (active on some steps), at
/// the default tolerance and at 1e-12: re-solved with gravity moved by 1e-4 and 1e-2 from the
/// plan at g = 9.81, it ends below the tolerance at the cold start's plan (to 1e-8 and
/// 1e-10), in no more iterations.
#[test]
fn a_bounded_swing_up_warm_starts_to_the_tolerance() {
    let nearby = [9.81, 9.81 + 1e-4, 9.81 - 1e-4, 9.81 + 1e-2];
    assert_warm_starts_converge("swing-up g", (9.81, &nearby), |g, guess, options| {
        let system = DoublePendulum { g };
        OptimalControlProblem::new(&system, &[0.0; 4], &UPRIGHT_PENDULUM, 2.0, 40)
            .with_input_bounds([-22.0; 2], [22.0; 2])
            .with_options(options)
            .solve(guess)
            .unwrap_or_else(|e| panic!("g = {g}, tolerance {:e}: {e}", options.tolerance))
    });
}
