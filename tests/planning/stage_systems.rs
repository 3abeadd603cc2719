//! Parameters that vary along the horizon: one Lagrangian per step
//! (`OptimalControlProblem::with_stage_systems`).

use retract::bvp::{Failure, OptimalControlProblem, PlanGuess};
use retract::higher_order_lagrangian;

/// Tracking the reference r with weight w: L = 1/2 q''^2 + w/2 (q - r)^2.
#[higher_order_lagrangian(order = 2)]
fn tracking(q: f64, _dq: f64, ddq: f64, w: f64, r: f64) -> f64 {
    0.5 * ddq * ddq + 0.5 * w * (q - r).powi(2)
}

/// The same about 0: L = 1/2 e''^2 + w/2 e^2.
#[higher_order_lagrangian(order = 2)]
fn regulation(e: f64, _de: f64, dde: f64, w: f64) -> f64 {
    0.5 * dde * dde + 0.5 * w * e * e
}

/// Tracking the ramp r(t) = c t, one system per step with r_i = c t_i at the step's
/// evaluation time t_i = (i + 1/2) h, is the time-invariant regulation of e = q - c t
/// (e'' = q''; on the scheme exactly, the ramp being linear): the plans agree node by node after
/// the change of variables, and so do their costs.
#[test]
fn a_ramp_reference_is_regulation_in_the_error() {
    let (w, c, t_end, steps) = (4.0, 0.7, 3.0, 60);
    let h = t_end / steps as f64;
    let systems: Vec<Tracking> = (0..steps)
        .map(|i| Tracking::new(w, c * (i as f64 + 0.5) * h))
        .collect();
    let refs: Vec<&Tracking> = systems.iter().collect();
    let (start, goal) = ([0.5, 0.0], [1.0, 0.2]);
    let tracked = OptimalControlProblem::new(&systems[0], &start, &goal, t_end, steps)
        .with_stage_systems(&refs)
        .solve(PlanGuess::Spline)
        .unwrap();
    let (e_start, e_goal) = ([start[0], start[1] - c], [goal[0] - c * t_end, goal[1] - c]);
    let regulated =
        OptimalControlProblem::new(&Regulation::new(w), &e_start, &e_goal, t_end, steps)
            .solve(PlanGuess::Spline)
            .unwrap();
    for (i, (x, e)) in tracked.x.iter().zip(&regulated.x).enumerate() {
        let t = i as f64 * h;
        assert!(
            (x[0] - c * t - e[0]).abs() < 1e-9,
            "node {i}: {} vs {}",
            x[0] - c * t,
            e[0]
        );
        assert!((x[1] - c - e[1]).abs() < 1e-9, "node {i}");
    }
    assert!((tracked.cost - regulated.cost).abs() < 1e-10 * regulated.cost);
    // the reference moved the plan: one fixed reference (that of step 0) gives another
    let fixed = OptimalControlProblem::new(&systems[0], &start, &goal, t_end, steps)
        .solve(PlanGuess::Spline)
        .unwrap();
    assert!((fixed.cost - tracked.cost).abs() > 1e-3 * tracked.cost);
}

/// The same system at every step is the problem without stage systems, and a wrong count is
/// an invalid input.
#[test]
fn stage_systems_are_checked_and_neutral_when_equal() {
    let system = Tracking::new(2.0, 0.3);
    let same = vec![&system; 40];
    let plain = OptimalControlProblem::new(&system, &[0.0, 0.0], &[1.0, 0.0], 2.0, 40);
    let per_step = plain.clone().with_stage_systems(&same);
    let (a, b) = (
        plain.solve(PlanGuess::Spline).unwrap(),
        per_step.solve(PlanGuess::Spline).unwrap(),
    );
    assert_eq!(a.x, b.x);
    assert_eq!(a.cost, b.cost);
    let short = vec![&system; 39];
    let error = plain
        .with_stage_systems(&short)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(matches!(error.failure, Failure::Invalid(_)), "{error}");
}
