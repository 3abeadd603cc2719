//! Runtime messages that fit the situation: a boundary-value line search does not advise step
//! halving, a start or goal no guess can repair says so, an initial state outside the domain
//! is flagged at step 0, and `{:?}` of an interrupted trajectory is a summary. Every test asserts on the message text.

use crate::common;

use common::models::{DISC_GOAL, DISC_START, OneDisc, disc_bump_guess};
use retract::bvp::root_finder::{BoundaryValueProblem, BvpOptions, ClearanceFn, Guess};
use retract::bvp::{Failure, OptimalControlProblem, PlanGuess, PlanOptions};
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{DomainKind, Error, LiftedSystem, ReducedStepper, StepOptions, trajectory};

/// The one disc as a logarithmic barrier: L = 1/2 |q''|^2 - tau ln(x^2 + y^2 - 1), defined
/// only outside the disc (the `ln` guard is a condition at every point).
#[higher_order_lagrangian(order = 2)]
fn log_disc(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) - tau * (q[0].powi(2) + q[1].powi(2) - 1.0).ln()
}

/// A jet (q, q') inside the unit disc, at rest.
const INSIDE: [f64; 4] = [0.0, 0.5, 0.0, 0.0];
/// The denominator of `OneDisc` as written.
const DISC_DENOMINATOR: &str = "q[0].powi(2) + q[1].powi(2) - 1.0";

fn contains_all(message: &str, words: &[&str]) {
    for word in words {
        assert!(message.contains(word), "`{message}` lacks `{word}`");
    }
}

/// Signed distance of (x, y) to the unit disc.
fn disc_clearance(z: &SVector<f64, 8>, out: &mut [f64]) {
    out[0] = z[0].hypot(z[1]) - 1.0;
}

/// The state of the jet `jet` (q, q', q'' = q''' = 0).
fn state<Sys: LiftedSystem<8, 10>>(system: &Sys, jet: [f64; 4]) -> SVector<f64, 8> {
    let mut full = SVector::<f64, 8>::zeros();
    full.fixed_rows_mut::<4>(0).copy_from_slice(&jet);
    system.legendre(&full)
}

// ---- boundary-value Newton: advice that fits a boundary-value problem ---------------------

#[test]
fn a_boundary_value_line_search_failure_does_not_advise_step_halving() {
    // Above the disc (the straight guess is clear of it); a full Newton step that must
    // remove the whole residual (Armijo constant 1/2, no backtracking) never passes on this
    // nonlinear problem.
    let system = OneDisc { tau: 1e-2 };
    let (start, goal) = ([-2.0, 1.5, 1.0, 0.0], [2.0, 1.5, 1.0, 0.0]);
    let mut options = BvpOptions::default();
    options.armijo = 0.5;
    options.max_backtracks = 0;
    let error = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 40)
        .with_options(options)
        .solve(Guess::Spline)
        .unwrap_err();
    assert!(
        matches!(
            error,
            Error::BoundaryValueLineSearchFailed { iteration: 1, .. }
        ),
        "{error:?}"
    );
    let message = error.to_string();
    contains_all(
        &message,
        &[
            "boundary-value line search failed",
            "iteration 1",
            "better guess",
            "Guess::States",
            "continuation",
        ],
    );
    assert!(
        !message.contains("step halving") && !message.contains("step size"),
        "{message}"
    );
}

#[test]
fn a_boundary_value_iteration_cap_does_not_advise_step_halving() {
    let system = OneDisc { tau: 1e-2 };
    let (start, goal) = ([-2.0, 1.5, 1.0, 0.0], [2.0, 1.5, 1.0, 0.0]);
    let error = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 40)
        .with_options(
            BvpOptions::default()
                .with_max_iterations(1)
                .with_residual_tolerance(0.0),
        )
        .solve(Guess::Spline)
        .unwrap_err();
    assert!(
        matches!(
            error,
            Error::BoundaryValueNoConvergence { iterations: 1, .. }
        ),
        "{error:?}"
    );
    let message = error.to_string();
    contains_all(
        &message,
        &[
            "boundary-value",
            "1 iterations",
            "max_iterations",
            "better guess",
        ],
    );
    assert!(
        !message.contains("step halving") && !message.contains("step size"),
        "{message}"
    );
}

// ---- a start or goal that no guess can repair -------------------------------------------

#[test]
fn optimizer_start_inside_the_disc_says_no_guess_can_fix_it() {
    let system = OneDisc { tau: 1e-2 };
    // the spline guess and a guess around the disc are refused alike, before any iteration
    let (x, u) = disc_bump_guess(40);
    for guess in [PlanGuess::Spline, PlanGuess::Path { x: &x, u: &u }] {
        let error = OptimalControlProblem::new(&system, &INSIDE, &DISC_GOAL, 4.0, 40)
            .solve(guess)
            .unwrap_err();
        assert!(
            matches!(
                error.failure,
                Failure::Invalid(Error::BoundariesSeparated { .. })
            ),
            "{error:?}"
        );
        assert!(error.last.is_none());
        contains_all(
            &error.to_string(),
            &[
                "the start and the goal lie on opposite sides",
                DISC_DENOMINATOR,
                "inside an obstacle",
                "no guess can fix it",
            ],
        );
    }
    // a goal inside, the same message
    let error = OptimalControlProblem::new(&system, &DISC_START, &INSIDE, 4.0, 40)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    contains_all(
        &error.to_string(),
        &["opposite sides", "no guess can fix it"],
    );
}

#[test]
fn optimizer_goal_on_the_circle_is_outside_the_domain() {
    let system = OneDisc { tau: 1e-2 };
    let on_circle = [1.0, 0.0, 0.0, 0.0];
    let error = OptimalControlProblem::new(&system, &DISC_START, &on_circle, 4.0, 40)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    let Failure::Invalid(Error::GoalOutsideDomain { expression, .. }) = error.failure else {
        panic!("expected GoalOutsideDomain, got {error:?}");
    };
    assert_eq!(expression, DISC_DENOMINATOR);
    contains_all(
        &error.to_string(),
        &[
            "the goal lies outside the domain of the Lagrangian",
            "vanishes",
            "inside an obstacle",
            "no guess",
        ],
    );
}

#[test]
fn optimizer_start_inside_a_log_barrier_is_outside_the_domain() {
    let system = LogDisc { tau: 1e-2 };
    let error = OptimalControlProblem::new(&system, &INSIDE, &DISC_GOAL, 4.0, 40)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(
        matches!(
            error.failure,
            Failure::Invalid(Error::StartOutsideDomain {
                kind: DomainKind::LnArgument,
                ..
            })
        ),
        "{error:?}"
    );
    contains_all(
        &error.to_string(),
        &[
            "the start lies outside the domain of the Lagrangian",
            "ln is not positive",
            "no guess",
        ],
    );
}

#[test]
fn root_finder_start_or_goal_inside_an_obstacle_says_so() {
    let system = OneDisc { tau: 1e-2 };
    let clearance: ClearanceFn<'_, 8> = &disc_clearance;
    for (start, goal, data) in [(INSIDE, DISC_GOAL, "start"), (DISC_START, INSIDE, "goal")] {
        let error = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 40)
            .with_clearance(1, clearance)
            .solve(Guess::Spline)
            .unwrap_err();
        let Error::BoundaryInObstacle {
            end,
            obstacle: 0,
            clearance,
        } = error
        else {
            panic!("{data}: expected BoundaryInObstacle, got {error:?}");
        };
        assert_eq!(end, data);
        assert!((clearance + 0.5).abs() < 1e-12, "{clearance}");
        contains_all(
            &error.to_string(),
            &[
                &format!("the {data} is inside obstacle 0"),
                "clearance -5e-1",
                "no guess can fix it",
            ],
        );
    }
    // a guess of states around the disc does not change it
    let guess: Vec<SVector<f64, 8>> = disc_bump_guess(40)
        .0
        .iter()
        .map(|x| state(&system, [x[0], x[1], x[2], x[3]]))
        .collect();
    let error = BoundaryValueProblem::new(&system, &INSIDE, &DISC_GOAL, 4.0, 40)
        .with_clearance(1, clearance)
        .solve(Guess::States(&guess))
        .unwrap_err();
    assert!(
        matches!(
            error,
            Error::BoundaryInObstacle {
                end: "start",
                obstacle: 0,
                ..
            }
        ),
        "{error:?}"
    );
}

#[test]
fn root_finder_without_clearance_reports_the_singularity_between_the_ends() {
    let system = OneDisc { tau: 1e-2 };
    let problem = BoundaryValueProblem::new(&system, &INSIDE, &DISC_GOAL, 4.0, 40);
    for error in [
        problem.solve(Guess::Spline).unwrap_err(),
        problem.solve_reduced(Guess::Spline).unwrap_err(),
    ] {
        let Error::BoundariesSeparated {
            expression,
            kind: DomainKind::Denominator,
            element: None,
        } = error
        else {
            panic!("expected BoundariesSeparated, got {error:?}");
        };
        assert_eq!(expression, DISC_DENOMINATOR);
        assert_eq!(error.violation().map(|v| v.expression), Some(expression));
        contains_all(
            &error.to_string(),
            &["opposite sides", DISC_DENOMINATOR, "no guess can fix it"],
        );
    }
    // with a log barrier the start alone is outside the domain
    let system = LogDisc { tau: 1e-2 };
    let error = BoundaryValueProblem::new(&system, &DISC_START, &INSIDE, 4.0, 40)
        .solve(Guess::Spline)
        .unwrap_err();
    assert!(
        matches!(error, Error::GoalOutsideDomain { .. }),
        "{error:?}"
    );
    contains_all(
        &error.to_string(),
        &["the goal lies outside the domain", "ln is not positive"],
    );
}

#[test]
fn ends_on_the_same_side_are_not_refused() {
    // both outside the disc with a straight guess through it: the guess is at fault, and says so
    let system = OneDisc { tau: 1e-2 };
    let error = OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, 40)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(
        matches!(error.failure, Failure::GuessOutsideDomain { .. }),
        "{error:?}"
    );
    contains_all(&error.to_string(), &["first guess", "pass a guess"]);
    // both inside the disc: a valid problem for the denominator barrier (no boundary error)
    let plan = OptimalControlProblem::new(&system, &INSIDE, &[0.0, -0.5, 0.0, 0.0], 1.0, 20)
        .with_options(PlanOptions::default().with_max_iterations(5))
        .solve(PlanGuess::Spline);
    if let Err(error) = plan {
        assert!(
            !matches!(
                error.failure,
                Failure::Invalid(
                    Error::BoundariesSeparated { .. }
                        | Error::StartOutsideDomain { .. }
                        | Error::GoalOutsideDomain { .. }
                )
            ),
            "{error}"
        );
    }
}

// ---- initial-value problems ---------------------------------------------------------------

#[test]
fn an_initial_state_outside_the_domain_is_flagged_at_step_0() {
    let system = LogDisc { tau: 1e-2 };
    let z0 = state(&system, [0.0, 0.5, 0.3, 0.0]);
    let stop = trajectory(&system, &z0, 0.01, 100, &StepOptions::default()).unwrap_err();
    assert_eq!(stop.step, 0);
    assert!(stop.trajectory.states.is_empty());
    assert!(
        matches!(stop.error, Error::InitialStateOutsideDomain { .. }),
        "{stop:?}"
    );
    contains_all(
        &stop.to_string(),
        &[
            "step 0",
            "the initial state lies outside the domain of the Lagrangian",
            "ln is not positive",
        ],
    );
    assert!(!stop.to_string().contains("crossed"), "{stop}");
    // the reduced stepper's driver too
    let mut stepper = ReducedStepper::new(&system);
    let stop = stepper
        .trajectory(&z0, 0.01, 100, &StepOptions::default())
        .unwrap_err();
    assert_eq!((stop.step, stop.trajectory.states.len()), (0, 0));
    contains_all(&stop.to_string(), &["the initial state lies outside"]);
    // with the domain check off, nothing is checked
    let unchecked = StepOptions::default().with_domain_check(false);
    let result = trajectory(&system, &z0, 0.01, 1, &unchecked);
    if let Err(stop) = &result {
        assert!(
            !matches!(stop.error, Error::InitialStateOutsideDomain { .. }),
            "{stop}"
        );
    }
}

#[test]
fn an_initial_state_on_a_singularity_is_flagged_at_step_0() {
    let system = OneDisc { tau: 1e-2 };
    let z0 = state(&system, [0.0, 1.0, 1.0, 0.0]);
    let stop = trajectory(&system, &z0, 0.01, 10, &StepOptions::default()).unwrap_err();
    assert_eq!((stop.step, stop.trajectory.states.len()), (0, 0));
    contains_all(
        &stop.to_string(),
        &[
            "the initial state lies outside",
            &format!("denominator `{DISC_DENOMINATOR}` vanishes"),
        ],
    );
}

#[test]
fn leaving_a_denominator_obstacle_is_not_called_entering_it() {
    // Inside the disc the barrier is negative and attracts to the circle: the run leaves the
    // disc. The guard sees only the sign change, so the message names both directions.
    let system = OneDisc { tau: 1e-2 };
    let z0 = state(&system, [0.0, 0.5, 0.0, 1.0]);
    let stop = trajectory(&system, &z0, 0.01, 200, &StepOptions::default()).unwrap_err();
    assert!(stop.step > 0, "{stop}");
    assert!(matches!(stop.error, Error::Domain(_)), "{stop:?}");
    contains_all(
        &stop.to_string(),
        &["crossed a singularity", "or left one it started inside"],
    );
}

#[test]
fn debug_of_an_interrupted_trajectory_is_a_summary() {
    // the case of tests/integrators/guard.rs: the path reaches the circle near t = 1.955 (step 195)
    let system = OneDisc { tau: 1e-2 };
    let z0 = state(&system, [-2.0, 1.19, 1.0, -0.1]);
    let stop = trajectory(&system, &z0, 0.01, 400, &StepOptions::default()).unwrap_err();
    assert!(stop.trajectory.states.len() > 100, "{stop}");
    let debug = format!("{stop:?}");
    let states = stop.trajectory.states.len();
    contains_all(
        &debug,
        &[
            "Interrupted",
            &format!("step: {}", stop.step),
            "error: Domain",
            &format!("states: {states}"),
            &format!("reports: {}", states - 1),
            "last_state",
            "h: 0.01",
        ],
    );
    let last = stop.trajectory.states.last().expect("a state");
    assert!(debug.contains(&format!("{:?}", last[0])), "{debug}");
    // a summary, not every state
    assert!(debug.len() < 1000, "{} characters: {debug}", debug.len());
    // the pretty form is a summary too
    assert!(format!("{stop:#?}").lines().count() < 60);
}

/// A planar body among discs given as a parameter list.
#[higher_order_lagrangian(order = 2)]
fn disc_list(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64, discs: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1]);
    for d in discs {
        l += tau / ((q[0] - d[0]).powi(2) + (q[1] - d[1]).powi(2) - d[2] * d[2]);
    }
    l
}

/// A NaN parameter is named by steps, the reduced step and solves, not
/// reported as a non-finite residual.
#[test]
fn a_nan_parameter_is_named() {
    let system = OneDisc { tau: f64::NAN };
    let z0 = state(&OneDisc { tau: 1e-2 }, [-2.0, 0.2, 1.0, 0.0]);
    let options = StepOptions::default();
    let general = retract::step(&system, &z0, 0.01, &options).unwrap_err();
    assert!(
        matches!(
            general,
            Error::NonFiniteParameter {
                name: "tau",
                element: None,
                index: None
            }
        ),
        "{general}"
    );
    contains_all(&general.to_string(), &["parameter `tau`", "not finite"]);
    let reduced = ReducedStepper::new(&system)
        .step(&z0, 0.01, &options)
        .unwrap_err();
    assert!(
        matches!(reduced, Error::NonFiniteParameter { name: "tau", .. }),
        "{reduced}"
    );
    let (x, u) = disc_bump_guess(40);
    let plan = OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, 40)
        .solve(PlanGuess::Path { x: &x, u: &u })
        .unwrap_err();
    contains_all(&plan.to_string(), &["parameter `tau`"]);
    let bvp = BoundaryValueProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, 40)
        .solve(Guess::Spline)
        .unwrap_err();
    assert!(
        matches!(bvp, Error::NonFiniteParameter { name: "tau", .. }),
        "{bvp}"
    );
    // an element of a parameter list: its index and component
    let discs = [[0.0, -5.0, 1.0], [0.0, f64::INFINITY, 1.0]];
    let listed = DiscList {
        tau: 1e-2,
        discs: &discs,
    };
    let z0 = state(&listed, [-2.0, 0.2, 1.0, 0.0]);
    let error = retract::step(&listed, &z0, 0.01, &options).unwrap_err();
    assert!(
        matches!(
            error,
            Error::NonFiniteParameter {
                name: "discs",
                element: Some(1),
                index: Some(1)
            }
        ),
        "{error}"
    );
    contains_all(&error.to_string(), &["`discs` element 1 component 1"]);
    // finite parameters pass
    assert!(OneDisc { tau: 1e-2 }.check_parameters().is_ok());
}

/// A NaN parameter inside a guarded expression is named by trajectories as by steps: the
/// guard is NaN at every state, which is not the initial state's fault (issue 33, item 7).
#[test]
fn a_nan_parameter_is_named_by_trajectories() {
    let finite = [[0.0, -5.0, 1.0]];
    let z0 = state(
        &DiscList {
            tau: 1e-2,
            discs: &finite,
        },
        [-2.0, 0.2, 1.0, 0.0],
    );
    // a NaN radius: the guard `(q - c)^2 - r^2` of the disc is NaN everywhere
    let discs = [[0.0, -5.0, f64::NAN]];
    let listed = DiscList {
        tau: 1e-2,
        discs: &discs,
    };
    let named = |error: &Error| {
        matches!(
            error,
            Error::NonFiniteParameter {
                name: "discs",
                element: Some(0),
                index: Some(2)
            }
        )
    };
    for options in [
        StepOptions::default(),
        StepOptions::default().with_domain_check(false),
    ] {
        let stop = trajectory(&listed, &z0, 0.01, 10, &options).unwrap_err();
        assert!(named(&stop.error), "{stop}");
        assert_eq!((stop.step, stop.trajectory.states.len()), (0, 0), "{stop}");
        contains_all(
            &stop.to_string(),
            &["parameter `discs` element 0 component 2", "not finite"],
        );
        assert!(!stop.to_string().contains("initial state"), "{stop}");
        let stop = ReducedStepper::new(&listed)
            .trajectory(&z0, 0.01, 10, &options)
            .unwrap_err();
        assert!(named(&stop.error), "{stop}");
        let typed = retract::State::<2, 2>::from_vector(&z0)
            .trajectory(&listed, 0.01, 10, &options)
            .unwrap_err();
        assert!(named(&typed.error), "{typed}");
    }
    // a NaN weight outside every guard: named before the first step as well
    let system = LogDisc { tau: f64::NAN };
    let z0 = state(&LogDisc { tau: 1e-2 }, [-2.0, 0.2, 1.0, 0.0]);
    let stop = trajectory(&system, &z0, 0.01, 10, &StepOptions::default()).unwrap_err();
    assert!(
        matches!(stop.error, Error::NonFiniteParameter { name: "tau", .. }),
        "{stop}"
    );
}
