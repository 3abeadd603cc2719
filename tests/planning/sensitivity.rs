//! Sensitivities of a plan with respect to a parameter of its Lagrangian
//! (`parameter_sensitivity`, from the KKT factorisation at the solution) against central
//! differences of solves with the parameter moved: the swing-up of the double pendulum
//! (gravity), the acrobot's (gravity, in its cost and in its active equality) and the one-disc
//! scene (the barrier weight tau).

use std::f64::consts::PI;

use crate::common::models::{DISC_GOAL, DISC_START, DoublePendulum, OneDisc, disc_bump_guess};
use retract::bvp::{
    Failure, OptimalControlProblem, ParameterSensitivity, Plan, PlanGuess, PlanOptions,
};
use retract::jet_function;
use retract::nalgebra::SVector;

/// dL/dg of the swing-up suite's double pendulum (`DoublePendulum`, L = 1/2 |tau|^2 with
/// tau = M(q) q'' + C(q, q') q' + g G_1(q)): tau . G_1(q), G_1 = (2 sin q_0 + sin(q_0 + q_1),
/// sin(q_0 + q_1)).
#[jet_function(order = 2)]
pub(crate) fn gravity_derivative(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    let c2 = q[1].cos();
    let s2 = q[1].sin();
    let m11 = 3.0 + 2.0 * c2;
    let m12 = 1.0 + c2;
    let unit1 = 2.0 * q[0].sin() + (q[0] + q[1]).sin();
    let unit2 = (q[0] + q[1]).sin();
    let tau1 = m11 * ddq[0] + m12 * ddq[1] - s2 * (2.0 * dq[0] * dq[1] + dq[1] * dq[1]) + g * unit1;
    let tau2 = m12 * ddq[0] + ddq[1] + s2 * dq[0] * dq[0] + g * unit2;
    tau1 * unit1 + tau2 * unit2
}

/// dL/dtau of the one-disc scene (L = 1/2 |q''|^2 + tau / (x^2 + y^2 - 1)).
#[jet_function(order = 2)]
pub(crate) fn barrier_derivative(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2]) -> f64 {
    1.0 / (q[0].powi(2) + q[1].powi(2) - 1.0)
}

/// Asserts that `sensitivity` matches the central differences of `plus` and `minus` (solved at
/// p +- eps) to 1e-6 relative: the largest error over the jets and top derivatives against the
/// sensitivity's largest entry, and the cost's error against its derivative (both above 1e-2:
/// the parameter moves the plan); returns the largest entry.
pub(crate) fn assert_matches(
    case: &str,
    sensitivity: &ParameterSensitivity<2, 4>,
    (plus, minus): (&Plan<2, 4>, &Plan<2, 4>),
    eps: f64,
) -> f64 {
    let central = |a: f64, b: f64| (a - b) / (2.0 * eps);
    let mut error: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for (i, d) in sensitivity.x.iter().enumerate() {
        let fd = SVector::<f64, 4>::from_fn(|r, _| central(plus.x[i][r], minus.x[i][r]));
        error = error.max((d - fd).amax());
        scale = scale.max(d.amax());
    }
    for (i, d) in sensitivity.u.iter().enumerate() {
        let fd = SVector::<f64, 2>::from_fn(|r, _| central(plus.u[i][r], minus.u[i][r]));
        error = error.max((d - fd).amax());
        scale = scale.max(d.amax());
    }
    let cost_error = (sensitivity.cost - central(plus.cost, minus.cost)).abs();
    let cost_scale = sensitivity.cost.abs();
    eprintln!("{case}: {error:e} of {scale:e}; cost {cost_error:e} of {cost_scale:e}");
    assert!(scale > 1e-2 && cost_scale > 1e-2, "{scale} {cost_scale}");
    assert!(error <= 1e-6 * scale, "{error:e} of {scale:e}");
    assert!(
        cost_error <= 1e-6 * cost_scale,
        "{cost_error:e} of {cost_scale:e}"
    );
    scale
}

/// The swing-up of the double pendulum (hanging rest to upright rest, T = 2, N = 40): the
/// derivative of the plan and of its cost with respect to gravity, against central
/// differences of solves at g = 9.81 +- 1e-4 (tolerance 1e-12), to 1e-6 relative.
#[test]
fn the_swing_up_s_gravity_sensitivity_matches_central_differences() {
    let goal = [PI, 0.0, 0.0, 0.0];
    let options = PlanOptions::default().with_tolerance(1e-12);
    let solve = |g: f64, guess: PlanGuess<'_, 2, 4>| {
        let system = DoublePendulum { g };
        OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 40)
            .with_options(options)
            .solve(guess)
            .expect("swing-up")
    };
    let (g, eps) = (9.81, 1e-4);
    let plan = solve(g, PlanGuess::Spline);
    let system = DoublePendulum { g };
    let problem = OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 40);
    let mut rti = problem
        .real_time_iteration(PlanGuess::Plan(&plan))
        .expect("rti");
    let prepared = problem.prepare(&mut rti).expect("prepared");
    assert_eq!(prepared.regularization, 0.0);
    let dl = GravityDerivative::new(g);
    let sensitivity = problem
        .parameter_sensitivity(&rti, &dl, &[])
        .expect("sensitivity");
    let plus = solve(g + eps, PlanGuess::Plan(&plan));
    let minus = solve(g - eps, PlanGuess::Plan(&plan));
    let scale = assert_matches("swing-up", &sensitivity, (&plus, &minus), eps);
    // the ends are fixed: they do not move with g
    assert_eq!(sensitivity.x[0], SVector::<f64, 4>::zeros());
    assert!(sensitivity.x[40].amax() < 1e-12 * scale);
}

/// The one-disc scene (N = 100, from its bump guess): the derivative of the plan and of its
/// cost with respect to the barrier's weight tau = 1e-2, against central differences of
/// solves at tau +- 1e-6 (tolerance 1e-12), to 1e-6 relative. A sensitivity before a
/// preparation is refused.
#[test]
fn the_one_disc_barrier_sensitivity_matches_central_differences() {
    let steps = 100;
    let options = PlanOptions::default().with_tolerance(1e-12);
    let (x, u) = disc_bump_guess(steps);
    let solve = |tau: f64| {
        let system = OneDisc { tau };
        OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps)
            .with_options(options)
            .solve(PlanGuess::Path { x: &x, u: &u })
            .expect("one disc")
    };
    let (tau, eps) = (1e-2, 1e-6);
    let plan = solve(tau);
    let system = OneDisc { tau };
    let problem = OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps);
    let mut rti = problem
        .real_time_iteration(PlanGuess::Plan(&plan))
        .expect("rti");
    let dl = BarrierDerivative::new();
    let refused = problem
        .parameter_sensitivity(&rti, &dl, &[])
        .expect_err("unprepared");
    assert!(matches!(refused, Failure::Invalid(_)), "{refused}");
    problem.prepare(&mut rti).expect("prepared");
    let sensitivity = problem
        .parameter_sensitivity(&rti, &dl, &[])
        .expect("sensitivity");
    let (plus, minus) = (solve(tau + eps), solve(tau - eps));
    assert_matches("one disc", &sensitivity, (&plus, &minus), eps);
}

/// dL/dg of the acrobot's cost (`ElbowCost`, unit masses and rods: L = 1/2 tau_2^2):
/// tau_2 sin(q_0 + q_1).
#[jet_function(order = 2)]
fn elbow_gravity_derivative(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    let tau2 =
        (1.0 + q[1].cos()) * ddq[0] + ddq[1] + q[1].sin() * dq[0] * dq[0] + g * (q[0] + q[1]).sin();
    tau2 * (q[0] + q[1]).sin()
}

/// d tau_1 / dg of the acrobot's passive shoulder (`ShoulderTorque`, unit masses and rods):
/// 2 sin q_0 + sin(q_0 + q_1).
#[jet_function(order = 2)]
fn shoulder_gravity_derivative(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2]) -> f64 {
    2.0 * q[0].sin() + (q[0] + q[1]).sin()
}

/// The acrobot's swing-up (T = 2, N = 50; cost 1/2 tau_2^2, the shoulder's torque zero as an
/// equality at every step, active by definition): the derivative of the plan and its cost with
/// respect to gravity, which moves both the cost and the equality, against central
/// differences of solves at g = 9.81 +- 1e-4, to 1e-6 relative. Leaving out the equality's
/// derivative gives another (wrong) answer, and a list of the wrong length is refused.
#[test]
fn the_acrobot_s_gravity_sensitivity_with_its_equality_matches_central_differences() {
    use crate::pendulum::{ElbowCost, ShoulderTorque};
    let goal = [PI, 0.0, 0.0, 0.0];
    let (t_end, steps) = (2.0, 50);
    let solve = |g: f64, guess: PlanGuess<'_, 2, 4>| {
        let (cost, passive) = (
            ElbowCost::new(1.0, 1.0, 1.0, 1.0, g),
            ShoulderTorque::new(1.0, 1.0, 1.0, 1.0, g),
        );
        OptimalControlProblem::new(&cost, &[0.0; 4], &goal, t_end, steps)
            .with_equality(&passive)
            .solve(guess)
            .expect("acrobot")
    };
    let (g, eps) = (9.81, 1e-4);
    let plan = solve(g, PlanGuess::Spline);
    let (cost, passive) = (
        ElbowCost::new(1.0, 1.0, 1.0, 1.0, g),
        ShoulderTorque::new(1.0, 1.0, 1.0, 1.0, g),
    );
    let problem =
        OptimalControlProblem::new(&cost, &[0.0; 4], &goal, t_end, steps).with_equality(&passive);
    let mut rti = problem
        .real_time_iteration(PlanGuess::Plan(&plan))
        .expect("rti");
    problem.prepare(&mut rti).expect("prepared");
    let (dl, dg) = (
        ElbowGravityDerivative::new(g),
        ShoulderGravityDerivative::new(),
    );
    let sensitivity = problem
        .parameter_sensitivity(&rti, &dl, &[&dg])
        .expect("sensitivity");
    let plus = solve(g + eps, PlanGuess::Plan(&plan));
    let minus = solve(g - eps, PlanGuess::Plan(&plan));
    let scale = assert_matches("acrobot", &sensitivity, (&plus, &minus), eps);
    let without = problem
        .parameter_sensitivity(&rti, &dl, &[])
        .expect("cost only");
    let apart = (without.u.iter().zip(&sensitivity.u))
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);
    assert!(apart > 1e-3 * scale, "{apart:e}");
    let refused = problem
        .parameter_sensitivity(&rti, &dl, &[&dg, &dg])
        .expect_err("two for one");
    assert!(matches!(refused, Failure::Invalid(_)), "{refused}");
}
