//! Terminal costs and free end and start components, against closed-form optima of the
//! double integrator (L = 1/2 q''^2, T = 1).

use retract::bvp::{Failure, OptimalControlProblem, PlanGuess};
use retract::{higher_order_lagrangian, jet_function};

#[higher_order_lagrangian(order = 2)]
fn effort(_q: f64, _dq: f64, ddq: f64) -> f64 {
    0.5 * ddq * ddq
}

/// Phi = w/2 (q - 1)^2: missing the target 1 costs.
#[jet_function(order = 2)]
fn miss(q: f64, _dq: f64, _ddq: f64, w: f64) -> f64 {
    0.5 * w * (q - 1.0).powi(2)
}

/// Depends on the top derivative: not a terminal cost.
#[jet_function(order = 2)]
fn not_terminal(q: f64, _dq: f64, ddq: f64) -> f64 {
    q * q + ddq * ddq
}

/// The errors of the plans at N = 20, 40, 80 and the ratios of successive ones (about 4 at
/// order 2).
fn order_two(errors: &[f64]) {
    for pair in errors.windows(2) {
        let ratio = pair[0] / pair[1];
        assert!((3.5..4.5).contains(&ratio), "errors {errors:?}");
    }
}

/// q(1) = 1 with q'(1) free: the optimum is the cubic with q''(1) = 0,
/// u = 3 (1 - t), J = 3/2; the plans converge to it at order 2, and their velocity's momentum
/// vanishes at the end (the natural boundary condition).
#[test]
fn a_free_end_velocity_gives_the_natural_cubic() {
    let mut errors = Vec::new();
    for steps in [20, 40, 80] {
        let plan = OptimalControlProblem::new(&Effort, &[0.0, 0.0], &[1.0, 123.0], 1.0, steps)
            .with_free_end(&[1])
            .solve(PlanGuess::Spline)
            .unwrap();
        let end = plan.x[steps];
        assert!((end[0] - 1.0).abs() < 1e-12, "q(1) = {}", end[0]);
        let p_end = plan.momenta[steps];
        assert!(p_end[1].abs() < 1e-8, "p_1(1) = {}", p_end[1]);
        errors.push((plan.cost - 1.5).abs());
    }
    order_two(&errors);
}

/// Both end components free with Phi = 3/2 (q - 1)^2: Pontryagin gives u = l (t - 1) with
/// l = 3 (q(1) - 1), q(1) = -l/3, so q(1) = 1/2 and J = 3/4; at order 2 again, with
/// p_N = -grad Phi.
#[test]
fn a_terminal_cost_on_a_free_end_balances_effort_and_miss() {
    let phi = Miss::new(3.0);
    let (mut cost_errors, mut end_errors) = (Vec::new(), Vec::new());
    for steps in [20, 40, 80] {
        let plan = OptimalControlProblem::new(&Effort, &[0.0, 0.0], &[9.0, 9.0], 1.0, steps)
            .with_free_end(&[0, 1])
            .with_terminal_cost(&phi)
            .solve(PlanGuess::Spline)
            .unwrap();
        let (end, p_end) = (plan.x[steps], plan.momenta[steps]);
        assert!(
            (p_end[0] + 3.0 * (end[0] - 1.0)).abs() < 1e-8,
            "p_0 {}",
            p_end[0]
        );
        assert!(p_end[1].abs() < 1e-8, "p_1 {}", p_end[1]);
        cost_errors.push((plan.cost - 0.75).abs());
        end_errors.push((end[0] - 0.5).abs());
    }
    order_two(&cost_errors);
    order_two(&end_errors);
}

/// The time reversal of the natural cubic: q(0) = 0 with q'(0) free to q(1) = 1 at rest gives
/// J = 3/2 again (at order 2), with p_1(0) = 0.
#[test]
fn a_free_start_velocity_gives_the_reversed_cubic() {
    let mut errors = Vec::new();
    for steps in [20, 40, 80] {
        let plan = OptimalControlProblem::new(&Effort, &[0.0, -7.0], &[1.0, 0.0], 1.0, steps)
            .with_free_start(&[1])
            .solve(PlanGuess::Spline)
            .unwrap();
        assert!(plan.x[0][0].abs() < 1e-12, "q(0) = {}", plan.x[0][0]);
        assert!(
            plan.momenta[0][1].abs() < 1e-8,
            "p_1(0) = {}",
            plan.momenta[0][1]
        );
        errors.push((plan.cost - 1.5).abs());
    }
    order_two(&errors);
}

/// A terminal cost of the top derivative and a component out of range are invalid inputs.
#[test]
fn bad_ends_are_invalid() {
    let problem = OptimalControlProblem::new(&Effort, &[0.0, 0.0], &[1.0, 0.0], 1.0, 10);
    let error = problem
        .clone()
        .with_terminal_cost(&NotTerminal)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(matches!(error.failure, Failure::Invalid(_)), "{error}");
    let error = problem
        .with_free_end(&[2])
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(matches!(error.failure, Failure::Invalid(_)), "{error}");
}

/// Every end component free: the straight lines q = a + b t cost nothing, so the minimum is
/// flat along them (a singular reduced Hessian without negative directions). It is certified
/// as a minimum, not a strict one (smallest eigenvalue 0), not refused as a saddle.
#[test]
fn a_problem_flat_along_its_free_ends_is_a_minimum() {
    for steps in [2, 3, 20] {
        let plan = OptimalControlProblem::new(&Effort, &[0.0, 0.0], &[1.0, 0.0], 1.0, steps)
            .with_free_end(&[0, 1])
            .with_free_start(&[0, 1])
            .solve(PlanGuess::Spline)
            .unwrap_or_else(|e| panic!("N = {steps}: {e}"));
        assert!(plan.cost.abs() < 1e-20, "N = {steps}: J = {}", plan.cost);
        let c = &plan.certificate;
        assert_eq!(c.negative_directions, 0);
        assert_eq!(c.min_reduced_hessian_eig, 0.0, "N = {steps}");
    }
}
