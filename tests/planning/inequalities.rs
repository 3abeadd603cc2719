//! Hard inequality constraints of the optimizer (interior point): bounds on the top
//! derivative against a closed-form optimal control, a torque limit that is active at the
//! optimum, and the errors for a guess outside an inequality.

use std::f64::consts::PI;

use crate::common::models::DoublePendulum;

use retract::bvp::{
    BarrierUpdate, Failure, OptimalControlProblem, Plan, PlanGuess, PlanOptions, Variable,
};
use retract::{JetFunction, higher_order_lagrangian, jet_function};

/// limit - tau1 >= 0 (sign = 1) or limit + tau1 >= 0 (sign = -1): the shoulder torque limit.
#[jet_function(order = 2)]
fn shoulder_limit(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64, limit: f64, sign: f64) -> f64 {
    let c2 = q[1].cos();
    let s2 = q[1].sin();
    let tau1 = (3.0 + 2.0 * c2) * ddq[0] + (1.0 + c2) * ddq[1]
        - s2 * (2.0 * dq[0] * dq[1] + dq[1] * dq[1])
        + 2.0 * g * q[0].sin()
        + g * (q[0] + q[1]).sin();
    limit - sign * tau1
}

/// tau1 at the evaluation point of every step of a plan.
fn shoulder_torques(plan: &retract::bvp::Plan<2, 4>) -> Vec<f64> {
    let torque = ShoulderLimit {
        g: 9.81,
        limit: 0.0,
        sign: -1.0,
    };
    (0..plan.u.len())
        .map(|i| {
            let xt = (plan.x[i] + plan.x[i + 1]) * 0.5;
            let b = [
                xt.fixed_rows::<2>(0).into_owned(),
                xt.fixed_rows::<2>(2).into_owned(),
            ];
            torque.value(&b, &plan.u[i])
        })
        .collect()
}

/// A shoulder torque limit of 10 (the unconstrained T = 2 swing-up peaks near 12): the plan
/// keeps |tau1| <= 10 at every step, the limit is active, the cost is IPOPT's on the same
/// transcription and guess (`NSTEPS=50 python3 validation/ipopt/constrained_suite.py
/// pendulum-tau10 ends=eq endguess=curve bound_relax_factor=0`: 81.8984006730 in 28
/// iterations), and the point is certified, at the acceptable level: with the limit active
/// over several steps and its slacks near 1e-8, the barrier's weights h z / s near 1e8 cost
/// the Riccati recursion the digits of the small curvature along the limit (IPOPT's reduced
/// Hessian there is positive definite, smallest eigenvalue 6.7e-4, and its last iterations
/// need no inertia correction; here each needs one), and the last iterations do not reach the
/// barrier's floor.
#[test]
fn a_torque_limit_holds_and_is_active() {
    let system = DoublePendulum { g: 9.81 };
    let goal = [PI, 0.0, 0.0, 0.0];
    let (t_end, steps) = (2.0, 50);
    let free = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
        .solve(PlanGuess::Spline)
        .unwrap();
    let free_peak = shoulder_torques(&free)
        .iter()
        .fold(0.0_f64, |m, t| m.max(t.abs()));
    assert!(free_peak > 11.0, "unconstrained peak {free_peak}");
    let upper = ShoulderLimit {
        g: 9.81,
        limit: 10.0,
        sign: 1.0,
    };
    let lower = ShoulderLimit {
        g: 9.81,
        limit: 10.0,
        sign: -1.0,
    };
    let plan = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
        .with_inequality(&upper)
        .with_inequality(&lower)
        .with_options(PlanOptions::default().with_min_eigenvalue(true))
        .solve(PlanGuess::Spline)
        .unwrap();
    let peak = shoulder_torques(&plan)
        .iter()
        .fold(0.0_f64, |m, t| m.max(t.abs()));
    assert!(peak <= 10.0 + 1e-9, "peak torque {peak}");
    assert!(
        peak > 10.0 - 1e-6,
        "the limit should be active: peak {peak}"
    );
    assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
    assert!(plan.certificate.complementarity <= 1e-6);
    let ipopt = 81.8984006730;
    assert!(
        (plan.cost - ipopt).abs() <= 1e-8 * ipopt,
        "J = {} against IPOPT's {ipopt}",
        plan.cost
    );
    // the limit costs something: without it, descent from this plan lowers the cost
    let released = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
        .solve(PlanGuess::Plan(&plan))
        .unwrap();
    assert!(
        released.cost < plan.cost - 1e-6,
        "{} vs {}",
        released.cost,
        plan.cost
    );
}

/// x'' = u from rest at 0 to rest at 1 in T = 1 with |u| <= U, cost int 1/2 u^2.
#[higher_order_lagrangian(order = 2)]
fn double_integrator(_q: f64, _dq: f64, ddq: f64) -> f64 {
    0.5 * ddq * ddq
}

/// The double integrator from rest at 0 to rest at 1 in T = 1 with |u| <= `bound`, in
/// `steps` steps, solved from the spline with `options`.
fn bounded_plan(steps: usize, bound: f64, options: PlanOptions) -> Plan<1, 2> {
    OptimalControlProblem::new(
        &DoubleIntegrator::new(),
        &[0.0, 0.0],
        &[1.0, 0.0],
        1.0,
        steps,
    )
    .with_bounds(Variable::Top(0), -bound, bound)
    .with_options(options)
    .solve(PlanGuess::Spline)
    .unwrap()
}

/// With |u| <= U (4 < U < 6) the optimal control saturates near both ends:
/// u = U on [0, 1/2 - a], U (1 - 2t) / (2a) in between, -U after, with a^2 = 3/4 - 3/U, and
/// J = U^2 (1 - 4a/3) / 2 (a closed form independent of the solver). The bounded plan
/// converges to it as N grows, and the bound holds at every step.
#[test]
fn bounded_control_converges_to_the_closed_form() {
    let bound: f64 = 5.0;
    let a = (0.75 - 3.0 / bound).sqrt();
    let exact = 0.5 * bound * bound * (1.0 - 4.0 * a / 3.0);
    let mut errors = Vec::new();
    for steps in [25, 50, 100, 200] {
        let plan = bounded_plan(steps, bound, PlanOptions::default());
        assert!(plan.u.iter().all(|u| u[0].abs() <= bound + 1e-9));
        assert_eq!(plan.certificate.negative_directions, 0);
        errors.push((plan.cost - exact).abs());
    }
    assert!(errors[3] < 1e-3 * exact, "errors {errors:?}");
    assert!(
        errors.windows(2).all(|w| w[1] < 0.7 * w[0]),
        "errors {errors:?}"
    );
}

/// A bound that the first guess violates everywhere is reached anyway (the slacks start
/// feasible), and infinite bounds add no constraint.
#[test]
fn bounds_need_no_feasible_guess_and_accept_infinite_sides() {
    let plan =
        OptimalControlProblem::new(&DoubleIntegrator::new(), &[0.0, 0.0], &[1.0, 0.0], 1.0, 40)
            .with_bounds(Variable::Jet(1), f64::NEG_INFINITY, 1.6)
            .solve(PlanGuess::Spline)
            .unwrap();
    // the spline's peak speed is 1.5; the free optimum's is 1.5 too, so impose 1.2 instead
    assert!(plan.x.iter().all(|x| x[1] <= 1.6 + 1e-9));
    let tight =
        OptimalControlProblem::new(&DoubleIntegrator::new(), &[0.0, 0.0], &[1.0, 0.0], 1.0, 40)
            .with_bounds(Variable::Jet(1), f64::NEG_INFINITY, 1.2)
            .solve(PlanGuess::Spline)
            .unwrap();
    let peak = (0..40)
        .map(|i| 0.5 * (tight.x[i][1] + tight.x[i + 1][1]))
        .fold(0.0, f64::max);
    assert!(
        peak <= 1.2 + 1e-9 && peak > 1.2 - 1e-6,
        "peak evaluation-point speed {peak}"
    );
    assert!(tight.cost > plan.cost);
    let invalid =
        OptimalControlProblem::new(&DoubleIntegrator::new(), &[0.0, 0.0], &[1.0, 0.0], 1.0, 40)
            .with_bounds(Variable::Top(3), -1.0, 1.0)
            .solve(PlanGuess::Spline)
            .unwrap_err();
    assert!(matches!(invalid.failure, Failure::Invalid(_)), "{invalid}");
}

/// An inactive bound costs few iterations (issue: "at most 1.3 times the unbounded
/// iteration count"): the swing-up suite's cart-pole at T = 2, 3, 4 with |F| <= 20, which its
/// unbounded plans never reach, ends at the unbounded minimum in at most 1.3 times the
/// unbounded solve's iterations.
#[test]
fn an_inactive_bound_costs_few_iterations() {
    use crate::cart_pole::{CartForce, CartPole, PoleTorque};
    let system = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, 9.81);
    let force = CartForce::new(1.0, 0.3, 0.5);
    let upright = [0.0, PI, 0.0, 0.0];
    for t in [2.0, 3.0, 4.0] {
        let steps = (50.0 * t) as usize;
        let problem = || {
            OptimalControlProblem::new(&system, &[0.0; 4], &upright, t, steps)
                .with_equality(&unactuated)
        };
        let free = problem().solve(PlanGuess::Spline).unwrap();
        let bounded = problem()
            .with_function_bounds(&force, -20.0, 20.0)
            .solve(PlanGuess::Spline)
            .unwrap();
        assert!(bounded.violations.imposed() <= 1e-9, "T = {t}");
        assert!(
            (bounded.cost - free.cost).abs() <= 1e-8 * free.cost,
            "T = {t}: the bound is active ({} against {})",
            bounded.cost,
            free.cost
        );
        assert!(
            bounded.iterations as f64 <= 1.3 * free.iterations as f64,
            "T = {t}: {} iterations bounded, {} unbounded",
            bounded.iterations,
            free.iterations
        );
    }
}

/// The adaptive barrier update ([`BarrierUpdate::Adaptive`]) ends at the same minimum as the
/// monotone one on a convex problem (the bounded double integrator of
/// `bounded_control_converges_to_the_closed_form`, whose minimum is unique), certified, with
/// the bound held at every step.
#[test]
fn the_adaptive_barrier_reaches_the_monotone_minimum() {
    let bound = 5.0;
    for steps in [25, 100, 400] {
        let solve = |update| {
            let options = PlanOptions::default().with_barrier_update(update);
            bounded_plan(steps, bound, options)
        };
        let (monotone, adaptive) = (
            solve(BarrierUpdate::Monotone),
            solve(BarrierUpdate::Adaptive),
        );
        assert!(adaptive.u.iter().all(|u| u[0].abs() <= bound + 1e-9));
        assert_eq!(adaptive.certificate.negative_directions, 0);
        assert!(
            (adaptive.cost - monotone.cost).abs() <= 1e-8 * monotone.cost,
            "N = {steps}: {} against {}",
            adaptive.cost,
            monotone.cost
        );
    }
}

/// The double integrator's cost times 1000.
#[higher_order_lagrangian(order = 2)]
fn heavy_double_integrator(_q: f64, _dq: f64, ddq: f64) -> f64 {
    500.0 * ddq * ddq
}

/// The cost's scale (IPOPT's gradient-based scaling, `PlanOptions::scaling_max_gradient`)
/// is invisible in the plan: the bounded double integrator and the same problem with its cost
/// times 1000, both scaled to the largest first gradient 1e-3, iterate on the same scaled
/// problem, so the heavy plan is the light one with its cost, momenta, multipliers, barrier
/// parameter and smallest eigenvalue times 1000 (a scale left in any of them is off by
/// the factor of its own scale). With the default scaling the heavy problem's first gradients
/// exceed 100, it is scaled, and it ends at the same controls as without scaling, whose
/// cost it reports.
#[test]
fn the_cost_scale_is_invisible_in_the_plan() {
    let solve = |heavy: bool, options: PlanOptions| {
        let light = DoubleIntegrator::new();
        let weighty = HeavyDoubleIntegrator::new();
        let (start, goal) = ([0.0, 0.0], [1.0, 0.0]);
        if heavy {
            OptimalControlProblem::new(&weighty, &start, &goal, 1.0, 50)
                .with_bounds(Variable::Top(0), -5.0, 5.0)
                .with_options(options)
                .solve(PlanGuess::Spline)
                .unwrap()
        } else {
            OptimalControlProblem::new(&light, &start, &goal, 1.0, 50)
                .with_bounds(Variable::Top(0), -5.0, 5.0)
                .with_options(options)
                .solve(PlanGuess::Spline)
                .unwrap()
        }
    };
    let both = PlanOptions::default().with_scaling_max_gradient(1e-3);
    let (light, heavy) = (solve(false, both), solve(true, both));
    assert_eq!(light.iterations, heavy.iterations);
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a - b).abs() <= 1e-7 * b.abs().max(1e-12),
            "{what}: {a} against {b}"
        );
    };
    close(heavy.cost, 1000.0 * light.cost, "cost");
    for (h, l) in heavy.u.iter().zip(&light.u) {
        close(h[0], l[0], "control");
    }
    for (h, l) in heavy.momenta.iter().zip(&light.momenta) {
        for r in 0..2 {
            assert!((h[r] - 1000.0 * l[r]).abs() <= 1e-6 * (1.0 + 1000.0 * l.amax()));
        }
    }
    let (hz, lz) = (&heavy.duals.step_multipliers, &light.duals.step_multipliers);
    assert!(!lz.is_empty());
    for (h, l) in hz.iter().zip(lz) {
        assert!((h - 1000.0 * l).abs() <= 1e-6 * (1.0 + 1000.0 * l.abs()));
    }
    close(heavy.duals.barrier, 1000.0 * light.duals.barrier, "barrier");
    let (he, le) = (
        heavy.certificate.min_reduced_hessian_eig,
        light.certificate.min_reduced_hessian_eig,
    );
    assert!(
        le > 0.0 && (he - 1000.0 * le).abs() <= 1e-6 * he,
        "{he} against {le}"
    );
    // the default scaling against none, on the heavy problem
    let scaled = solve(true, PlanOptions::default());
    let unscaled = solve(
        true,
        PlanOptions::default().with_scaling_max_gradient(f64::INFINITY),
    );
    assert!((scaled.cost - unscaled.cost).abs() <= 1e-8 * unscaled.cost);
    for (s, u) in scaled.u.iter().zip(&unscaled.u) {
        assert!((s[0] - u[0]).abs() <= 1e-6, "{} against {}", s[0], u[0]);
    }
}
