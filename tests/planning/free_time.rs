//! A free final time (`OptimalControlProblem::solve_free_time`) against the closed form of a
//! problem whose cost scales as a power of T, at a bound of the interval, on the minimum-time
//! cart-pole (C5, fewer steps), and with bad data.

use retract::bvp::{Failure, FreeTime, OptimalControlProblem, PlanGuess, Variable};
use retract::higher_order_lagrangian;

use crate::cart_pole::MinTimeCartPole;

/// The minimum acceleration on R^2, L = 1/2 |q''|^2.
#[higher_order_lagrangian(order = 2)]
fn acceleration(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1])
}

const START: [f64; 4] = [0.0, 0.0, 0.0, 0.0];
const GOAL: [f64; 4] = [1.0, 2.0, 0.0, 0.0];
const STEPS: usize = 40;

/// The lifted scheme is covariant under a change of time scale, so from rest to rest the
/// discrete minimum of 1/2 |q''|^2 is J(T) = C / T^3 with C = J(1); w T + C / T^3 is least at
/// T* = (3 C / w)^(1/4), with second derivative 12 C / T*^5 there.
#[test]
fn the_free_time_is_the_closed_form_minimiser_of_w_t_plus_c_over_t_cubed() {
    let problem =
        |t_end: f64| OptimalControlProblem::new(&Acceleration, &START, &GOAL, t_end, STEPS);
    let c = problem(1.0).solve(PlanGuess::Spline).unwrap().cost;
    // the covariance itself: J(2) = C / 8
    let at_two = problem(2.0).solve(PlanGuess::Spline).unwrap().cost;
    assert!(
        (at_two - c / 8.0).abs() <= 1e-10 * c,
        "{at_two} vs {}",
        c / 8.0
    );
    for (w, t0) in [(1.0, 2.0), (10.0, 0.7), (0.1, 4.0)] {
        let want = (3.0 * c / w).powf(0.25);
        let free = problem(t0)
            .solve_free_time(FreeTime::new(0.1, 10.0, w), PlanGuess::Spline)
            .unwrap();
        println!(
            "w = {w}: T = {} (closed form {want}), {} solves, {} iterations, curvature {}",
            free.t_end, free.solves, free.iterations, free.curvature
        );
        assert!(
            (free.t_end - want).abs() <= 1e-5 * want,
            "w = {w}: T = {} vs {want}",
            free.t_end
        );
        let cost = w * want + c / want.powi(3);
        assert!(
            (free.cost - cost).abs() <= 1e-9 * cost,
            "cost {} vs {cost}",
            free.cost
        );
        assert!((free.plan.cost - c / free.t_end.powi(3)).abs() <= 1e-9 * free.plan.cost);
        let curvature = 12.0 * c / want.powi(5);
        assert!(
            (free.curvature - curvature).abs() <= 1e-2 * curvature,
            "curvature {} vs {curvature}",
            free.curvature
        );
        assert!(!free.at_bound);
        assert!((free.plan.h * STEPS as f64 - free.t_end).abs() <= 1e-12 * free.t_end);
        assert_eq!(free.plan.certificate.negative_directions, 0);
    }
}

/// Where the interval ends before the unconstrained minimiser, the plan is at that bound, and
/// the cost increases into the interval.
#[test]
fn a_minimiser_beyond_the_interval_ends_at_its_bound() {
    let problem = OptimalControlProblem::new(&Acceleration, &START, &GOAL, 1.0, STEPS);
    let c = problem.solve(PlanGuess::Spline).unwrap().cost;
    // w = 1: T* = (3 C)^(1/4) > 1.2, so on [0.5, 1.2] the minimum is at 1.2
    assert!((3.0 * c).powf(0.25) > 1.5);
    let free = problem
        .solve_free_time(FreeTime::new(0.5, 1.2, 1.0), PlanGuess::Spline)
        .unwrap();
    assert!(free.at_bound && free.curvature.is_nan(), "{free:?}");
    assert!((free.t_end - 1.2).abs() <= 1e-5, "T = {}", free.t_end);
}

/// Bad intervals, weights and a start outside the interval are refused before solving.
#[test]
fn bad_free_time_data_are_refused() {
    let problem = OptimalControlProblem::new(&Acceleration, &START, &GOAL, 1.0, STEPS);
    for free in [
        FreeTime::new(2.0, 1.0, 1.0),
        FreeTime::new(0.0, 1.0, 1.0),
        FreeTime::new(0.5, f64::INFINITY, 1.0),
        FreeTime::new(0.5, 2.0, -1.0),
        FreeTime::new(0.5, 2.0, f64::NAN),
        FreeTime::new(0.5, 2.0, 1.0).with_tolerance(0.0),
        FreeTime::new(2.0, 3.0, 1.0),
    ] {
        let error = problem
            .solve_free_time(free, PlanGuess::Spline)
            .unwrap_err();
        assert!(
            matches!(error.failure, Failure::Invalid(_)),
            "{free:?}: {error}"
        );
        assert!(error.last.is_none());
    }
}

/// C5 of the constrained suite at a fifth of its steps: the minimum-time swing-up with the
/// force bound and the track, certified, its constraints kept, and its T a minimiser: the
/// cost at T +- 1 % is higher (solved at those fixed horizons).
#[test]
fn the_minimum_time_cart_pole_is_certified_and_its_horizon_is_least() {
    let system = MinTimeCartPole::new(1.0, 0.3, 0.5, 9.81);
    let (passive, force) = (system.unactuated_torques(), system.input_functions());
    let goal = [0.0, std::f64::consts::PI, 0.0, 0.0];
    let problem = |t_end: f64| {
        OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, 20)
            .with_equalities(&passive)
            .with_function_bounds(&force[0], -10.0, 10.0)
            .with_bounds(Variable::Jet(0), -1.0, 1.0)
    };
    let free = problem(3.0)
        .solve_free_time(FreeTime::new(0.5, 5.0, 1.0), PlanGuess::Spline)
        .unwrap();
    println!(
        "T = {}, J = {}, {} solves, {} iterations, curvature {}",
        free.t_end, free.cost, free.solves, free.iterations, free.curvature
    );
    assert!(free.plan.violations.imposed() <= 1e-8);
    assert!(free.curvature > 0.0 && !free.at_bound);
    for factor in [0.99, 1.01] {
        let t = free.t_end * factor;
        let (x, u) = (free.plan.x.clone(), free.plan.u.clone());
        let guess = PlanGuess::Path { x: &x, u: &u };
        let cost = problem(t)
            .solve(guess)
            .map_or(f64::INFINITY, |p| t + p.cost);
        assert!(cost > free.cost, "T = {t}: {cost} <= {}", free.cost);
    }
}

/// At N = 10 the minimum-time cart-pole's phi(T) is not unimodal (the fixed-horizon solves
/// end in different local minima, and below T = 1.45 none is feasible): the search, restarted
/// about any lower value its certificate's probes find, ends certified and no worse than the
/// best horizon of a scan of [0.5, 5] by steps of 0.1, each solved from the spline, also from
/// a first horizon that has no solution.
#[test]
fn a_rugged_cost_in_t_ends_no_worse_than_a_scan() {
    let system = MinTimeCartPole::new(1.0, 0.3, 0.5, 9.81);
    let (passive, force) = (system.unactuated_torques(), system.input_functions());
    let goal = [0.0, std::f64::consts::PI, 0.0, 0.0];
    let problem = |t_end: f64| {
        OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, 10)
            .with_equalities(&passive)
            .with_function_bounds(&force[0], -10.0, 10.0)
            .with_bounds(Variable::Jet(0), -1.0, 1.0)
    };
    let scan = (0..=45)
        .map(|i| 0.5 + 0.1 * f64::from(i))
        .filter_map(|t| problem(t).solve(PlanGuess::Spline).ok().map(|p| t + p.cost))
        .fold(f64::INFINITY, f64::min);
    assert!(scan.is_finite());
    // from T = 3, and from T = 1, where no plan meets the bounds
    assert!(problem(1.0).solve(PlanGuess::Spline).is_err());
    for t0 in [3.0, 1.0] {
        let free = problem(t0)
            .solve_free_time(FreeTime::new(0.5, 5.0, 1.0), PlanGuess::Spline)
            .unwrap();
        println!(
            "from {t0}: T = {}, J = {} (scan {scan}), {} solves",
            free.t_end, free.cost, free.solves
        );
        assert!(free.cost <= scan, "from {t0}: {} > {scan}", free.cost);
        assert!(free.curvature > 0.0 || free.curvature.is_nan());
    }
}

/// Where the search certifies no horizon it says so, and how far it went: the minimum-time
/// cart-pole with |F| <= 15 and the track |x| <= 0.2 at N = 50 from T = 2 (the failure
/// hunt's `mintime` family with a narrower track than its grid's, whose 135 variants are all
/// certified) ends its rounds each with a probe finding a lower value. The failure counts the search's solves and
/// iterations (not those of the attached plan's own solve), and the attached plan is the best
/// certified fixed-horizon plan found.
#[test]
fn a_search_without_a_certified_horizon_says_so() {
    let system = MinTimeCartPole::new(1.0, 0.3, 0.5, 9.81);
    let (passive, force) = (system.unactuated_torques(), system.input_functions());
    let goal = [0.0, std::f64::consts::PI, 0.0, 0.0];
    let result = OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 50)
        .with_equalities(&passive)
        .with_function_bounds(&force[0], -15.0, 15.0)
        .with_bounds(Variable::Jet(0), -0.2, 0.2)
        .solve_free_time(FreeTime::new(0.5, 5.0, 1.0), PlanGuess::Spline);
    let error = match result {
        Ok(free) => panic!(
            "certified at T = {}: pick another failing variant",
            free.t_end
        ),
        Err(error) => error,
    };
    let Failure::FreeTimeSearch {
        solves,
        iterations,
        budget_spent,
    } = error.failure
    else {
        panic!("{error}");
    };
    let best = error.last.as_ref().expect("the best plan");
    assert!(!budget_spent && (10..150).contains(&solves), "{error}");
    assert!(iterations > 5 * best.iterations, "{error}");
    assert!(best.violations.imposed() <= 1e-8, "{:?}", best.violations);
    let message = error.to_string();
    assert!(
        message.contains("free-time search certified no horizon"),
        "{message}"
    );
    assert!(
        message.contains(&format!("{solves} fixed-horizon solves")),
        "{message}"
    );
}
