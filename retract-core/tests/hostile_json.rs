//! The optimizer's and the boundary-value solver's public types read from hostile JSON: each
//! reads (a file holds whatever numbers it was given) and is refused by its use, with an
//! error that names it, never turned into a NaN result. (`Plan` and `Extrapolated` have
//! their own in `plan` and `extrapolate`.)

#![cfg(feature = "serde")]

use serde_json::{Value, json};

use retract_core::Error;
use retract_core::bvp::root_finder::{BoundaryValueProblem, BvpOptions, BvpSolution, Guess};
use retract_core::bvp::{Failure, OptimalControlProblem, PlanGuess, PlanOptions, Variable};
use retract_core::models::PlanarBarrier;

type Edit = fn(&mut Value);

const SYSTEM: PlanarBarrier = PlanarBarrier {
    tau: 1e-2,
    radius: 1.0,
    mass: 1.0,
};

/// From (-2, 1.5) to (2, 1.5) at rest above the disc, in 4 time units.
const START: [f64; 4] = [-2.0, 1.5, 0.0, 0.0];
const GOAL: [f64; 4] = [2.0, 1.5, 0.0, 0.0];

/// `value` with `edit` applied.
fn edited(value: &Value, edit: Edit) -> Value {
    let mut value = value.clone();
    edit(&mut value);
    value
}

/// Whether `error` is an invalid argument named one of `names`.
fn names(error: &Error, names: &[&str]) -> bool {
    matches!(error, Error::InvalidArgument { name, .. } if names.contains(name))
}

/// Planner options with a field out of its range read back, and are refused by the solve
/// (before an iterate) and, where the problem is not needed to tell, by
/// [`PlanOptions::validate`].
#[test]
fn hostile_plan_options_are_refused_by_the_solve() {
    let problem =
        |options| OptimalControlProblem::new(&SYSTEM, &START, &GOAL, 4.0, 10).with_options(options);
    let valid = serde_json::to_value(PlanOptions::default()).expect("writes");
    let read: PlanOptions = serde_json::from_value(valid.clone()).expect("reads");
    assert_eq!(read, PlanOptions::default());
    assert!(read.validate().is_ok());
    assert!(problem(read).solve(PlanGuess::Spline).is_ok());
    let hostile: [(&str, Edit); 13] = [
        ("theta = 2", |v| v["theta"] = 2.0.into()),
        ("theta = \"NaN\"", |v| v["theta"] = "NaN".into()),
        ("tolerance = -1", |v| v["tolerance"] = (-1.0).into()),
        ("tolerance = \"inf\"", |v| v["tolerance"] = "inf".into()),
        ("acceptable = \"inf\"", |v| v["acceptable"] = "inf".into()),
        ("acceptable = \"NaN\"", |v| v["acceptable"] = "NaN".into()),
        ("acceptable < tolerance", |v| v["acceptable"] = 1e-12.into()),
        ("max_iterations = 0", |v| v["max_iterations"] = 0.into()),
        ("armijo = 0.5", |v| v["armijo"] = 0.5.into()),
        ("initial_barrier = -1e308", |v| {
            v["initial_barrier"] = (-1e308).into()
        }),
        ("chord_spacing = 0", |v| v["chord_spacing"] = 0.0.into()),
        ("max_chord_pieces = 2^32 - 1", |v| {
            v["max_chord_pieces"] = u32::MAX.into()
        }),
        ("interior_samples = 64", |v| {
            v["interior_samples"] = 64.into()
        }),
    ];
    for (what, edit) in hostile {
        let options: PlanOptions =
            serde_json::from_value(edited(&valid, edit)).unwrap_or_else(|e| panic!("{what}: {e}"));
        let refused = options.validate().expect_err(what);
        assert!(names(&refused, &["options", "theta"]), "{what}: {refused}");
        let result = problem(options).solve(PlanGuess::Spline);
        assert!(
            matches!(&result, Err(e) if e.last.is_none() && e.failure == Failure::Invalid(refused)),
            "{what}: {result:?}"
        );
    }
    // mu_0 = 1e308 is finite, but mu_0 / h per unit time (h = 0.4) is not: the problem says so
    let options: PlanOptions =
        serde_json::from_value(edited(&valid, |v| v["initial_barrier"] = 1e308.into()))
            .expect("reads");
    assert!(options.validate().is_ok());
    let result = problem(options).solve(PlanGuess::Spline);
    assert!(
        matches!(&result, Err(e) if matches!(&e.failure, Failure::Invalid(e) if names(e, &["options"]))),
        "{result:?}"
    );
}

/// Boundary-value options with a field out of its range read back, and are refused by both
/// solves and by [`BvpOptions::validate`].
#[test]
fn hostile_bvp_options_are_refused_by_the_solve() {
    let problem =
        |options| BoundaryValueProblem::new(&SYSTEM, &START, &GOAL, 4.0, 20).with_options(options);
    let valid = serde_json::to_value(BvpOptions::default()).expect("writes");
    let read: BvpOptions = serde_json::from_value(valid.clone()).expect("reads");
    assert_eq!(read, BvpOptions::default());
    assert!(problem(read).solve(Guess::Spline).is_ok());
    let hostile: [(&str, Edit); 8] = [
        ("theta = -0.5", |v| v["theta"] = (-0.5).into()),
        ("theta = \"NaN\"", |v| v["theta"] = "NaN".into()),
        ("residual_tolerance = \"-inf\"", |v| {
            v["residual_tolerance"] = "-inf".into()
        }),
        ("max_iterations = 0", |v| v["max_iterations"] = 0.into()),
        ("armijo = \"NaN\"", |v| v["armijo"] = "NaN".into()),
        ("armijo = -1", |v| v["armijo"] = (-1.0).into()),
        ("armijo = 0.75", |v| v["armijo"] = 0.75.into()),
        ("armijo = 1e308", |v| v["armijo"] = 1e308.into()),
    ];
    for (what, edit) in hostile {
        let options: BvpOptions =
            serde_json::from_value(edited(&valid, edit)).unwrap_or_else(|e| panic!("{what}: {e}"));
        let refused = options.validate().expect_err(what);
        assert!(names(&refused, &["options", "theta"]), "{what}: {refused}");
        assert_eq!(
            problem(options).solve(Guess::Spline),
            Err(refused),
            "{what}"
        );
    }
}

/// A boundary-value solution read back from hostile JSON is refused as a warm start and
/// not shifted; a valid one round-trips exactly, its non-finite descriptions included, and
/// warm-starts the solve at its solution.
#[test]
fn a_hostile_bvp_solution_is_refused_on_use() {
    let problem = BoundaryValueProblem::new(&SYSTEM, &START, &GOAL, 4.0, 20);
    let solution = problem.solve(Guess::Spline).expect("a regular problem");
    let valid = serde_json::to_value(&solution).expect("writes");
    let back: BvpSolution<8, 10> = serde_json::from_value(valid.clone()).expect("reads");
    assert!(back.validate().is_ok());
    let warm = problem.solve(Guess::Solution(&back)).expect("a warm start");
    assert!(warm.iterations <= 1, "{}", warm.iterations);
    assert!((warm.cost - solution.cost).abs() <= 1e-9 * solution.cost.abs());
    let hostile: [(&str, Edit); 8] = [
        ("h = 1e308 (T = N h overflows)", |v| v["h"] = 1e308.into()),
        ("h = \"NaN\"", |v| v["h"] = "NaN".into()),
        ("h = 0", |v| v["h"] = 0.0.into()),
        ("theta = 2", |v| v["theta"] = 2.0.into()),
        ("a NaN state", |v| v["states"][3][5] = "NaN".into()),
        ("an infinite unknown", |v| {
            v["unknowns"][7][9] = "-inf".into()
        }),
        ("an unknown missing", |v| {
            v["unknowns"].as_array_mut().map(Vec::pop);
        }),
        ("no states", |v| v["states"] = json!([])),
    ];
    for (what, edit) in hostile {
        let read: BvpSolution<8, 10> =
            serde_json::from_value(edited(&valid, edit)).unwrap_or_else(|e| panic!("{what}: {e}"));
        let refused = read.validate().expect_err(what);
        assert!(names(&refused, &["solution"]), "{what}: {refused}");
        assert_eq!(
            problem.solve(Guess::Solution(&read)),
            Err(refused),
            "{what}"
        );
        // shifted returns it unchanged (NaN fields compared by their Debug form)
        let shifted = read.shifted(&SYSTEM);
        assert_eq!(format!("{shifted:?}"), format!("{read:?}"), "{what}");
    }
    // non-finite descriptions (cost, residual) are written as strings and read back
    let mut described = solution.clone();
    (described.cost, described.residual_norm) = (f64::NAN, f64::INFINITY);
    let text = serde_json::to_string(&described).expect("writes");
    assert!(text.contains(r#""cost":"NaN""#) && text.contains(r#""residual_norm":"inf""#));
    let read: BvpSolution<8, 10> = serde_json::from_str(&text).expect("reads");
    assert!(read.cost.is_nan() && read.residual_norm == f64::INFINITY);
    assert_eq!(serde_json::to_string(&read).expect("writes"), text);
}

/// A plan whose duals were read from hostile JSON (wrong lengths, non-finite or negative
/// slacks and multipliers, a NaN barrier) warm-starts as a plan without duals: the duals
/// are checked against the problem's inequalities and dropped when they do not fit.
#[test]
fn hostile_duals_are_dropped_by_the_warm_start() {
    let problem = OptimalControlProblem::new(&SYSTEM, &START, &GOAL, 4.0, 10).with_bounds(
        Variable::Jet(1),
        1.2,
        3.0,
    );
    let plan = problem.solve(PlanGuess::Spline).expect("a regular problem");
    assert!(!plan.duals.step_slacks.is_empty() && !plan.duals.node_slacks.is_empty());
    let mut bare = plan.clone();
    bare.duals = retract_core::bvp::Duals::default();
    let without = problem.solve(PlanGuess::Plan(&bare)).expect("a warm start");
    let valid = serde_json::to_value(&plan).expect("writes");
    let hostile: [(&str, Edit); 6] = [
        ("barrier = \"NaN\"", |v| {
            v["duals"]["barrier"] = "NaN".into()
        }),
        ("a negative slack", |v| {
            v["duals"]["step_slacks"][2] = (-1.0).into()
        }),
        ("an infinite multiplier", |v| {
            v["duals"]["node_multipliers"][0] = "inf".into()
        }),
        ("a zero multiplier", |v| {
            v["duals"]["step_multipliers"][1] = 0.0.into()
        }),
        ("a slack missing", |v| {
            v["duals"]["node_slacks"].as_array_mut().map(Vec::pop);
        }),
        ("a NaN equality multiplier", |v| {
            v["duals"]["equalities"] = json!([["NaN", 0.0]])
        }),
    ];
    for (what, edit) in hostile {
        let mut read: retract_core::bvp::Plan<2, 4> =
            serde_json::from_value(edited(&valid, edit)).unwrap_or_else(|e| panic!("{what}: {e}"));
        // (the equalities' multipliers are dropped alike: compare with none)
        if what.contains("equality") {
            read.duals.barrier = f64::NAN;
        } else {
            read.duals.equalities.clear();
        }
        let warm = problem.solve(PlanGuess::Plan(&read)).expect(what);
        assert_eq!(format!("{warm:?}"), format!("{without:?}"), "{what}");
    }
}
