//! Sensitivities of plans with active inequalities (`OptimalControlProblem::sensitivities`:
//! the KKT system at the plan with the active inequalities as equalities) against central
//! differences of solves with a parameter or the start moved: the one-disc scene with its disc
//! as a hard constraint, active, and the swing-up with its input bounded, active on some
//! steps; the adjoint against the forward directions; the refusal of a weakly active bound.

use std::f64::consts::PI;

use crate::common::models::{DISC_GOAL, DISC_START, DoublePendulum, disc_bump_guess};
use crate::sensitivity::{GravityDerivative, assert_matches};
use retract::bvp::{
    Failure, OptimalControlProblem, Parameter, PlanGradient, PlanGuess, PlanOptions,
    PlanSensitivities,
};
use retract::nalgebra::SVector;
use retract::{higher_order_lagrangian, jet_function};

/// The keep-out disc of radius r about the origin: x^2 + y^2 - r^2 >= 0.
#[jet_function(order = 2)]
fn keep_out(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], r: f64) -> f64 {
    q[0] * q[0] + q[1] * q[1] - r * r
}

/// The one-disc scene's effort with two parameters: 1/2 (x''^2 + w y''^2) + f y (w = 1, f = 0:
/// the scene's 1/2 |q''|^2; the disc is a hard constraint here, not a barrier in L).
#[higher_order_lagrangian(order = 2)]
fn disc_effort(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], w: f64, f: f64) -> f64 {
    0.5 * (ddq[0] * ddq[0] + w * ddq[1] * ddq[1]) + f * q[1]
}

/// dL/df of `DiscEffort`: y.
#[jet_function(order = 2)]
fn force_derivative(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2]) -> f64 {
    q[1]
}

/// dL/dw of `DiscEffort`: 1/2 y''^2.
#[jet_function(order = 2)]
fn weight_derivative(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * ddq[1] * ddq[1]
}

/// The number of active inequalities of a plan (slack below multiplier) and their smallest
/// multiplier.
fn active(duals: &retract::bvp::Duals<2>) -> (usize, f64) {
    let pairs = (duals.step_slacks.iter().zip(&duals.step_multipliers))
        .chain(duals.node_slacks.iter().zip(&duals.node_multipliers));
    pairs
        .filter(|(s, z)| s < z)
        .fold((0, f64::INFINITY), |(n, m), (_, z)| (n + 1, m.min(*z)))
}

/// A deterministic weight in [-1, 1] for entry `k`.
fn weight(k: usize) -> f64 {
    let v = (k as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11;
    2.0 * (v as f64 / (1u64 << 53) as f64) - 1.0
}

/// The adjoint of phi = sum_i w . x_i + sum_i w . u_i (weights of `weight`) in the start and
/// in `parameters` against phi's gradient times the forward directions (each start component
/// and each parameter), to 1e-8 relative; returns the largest relative error.
fn assert_adjoint<Sys: ?Sized>(
    case: &str,
    sens: &PlanSensitivities<'_, '_, Sys, 2, 2, 4>,
    parameters: &[Parameter<'_, 2, 2>],
    steps: usize,
) -> f64 {
    let gx: Vec<SVector<f64, 4>> = (0..=steps)
        .map(|i| SVector::from_fn(|r, _| weight(4 * i + r)))
        .collect();
    let gu: Vec<SVector<f64, 2>> = (0..steps)
        .map(|i| SVector::from_fn(|r, _| weight(10_000 + 2 * i + r)))
        .collect();
    let along = |x: &[SVector<f64, 4>], u: &[SVector<f64, 2>]| {
        let on_x: f64 = x.iter().zip(&gx).map(|(a, b)| a.dot(b)).sum();
        on_x + u.iter().zip(&gu).map(|(a, b)| a.dot(b)).sum::<f64>()
    };
    let gradient = PlanGradient { x: &gx, u: &gu };
    let adjoint = sens.adjoint(gradient, parameters).expect("adjoint");
    let mut worst: f64 = 0.0;
    for (j, parameter) in parameters.iter().enumerate() {
        let forward = sens.parameter(parameter).expect("forward");
        let expected = along(&forward.x, &forward.u);
        let error = (adjoint.parameters[j] - expected).abs() / expected.abs();
        eprintln!(
            "{case} parameter {j}: {} vs {expected}",
            adjoint.parameters[j]
        );
        worst = worst.max(error);
    }
    for r in 0..4 {
        let mut unit = [0.0; 4];
        unit[r] = 1.0;
        let (x, u) = sens.start(&unit).expect("start");
        let expected = along(&x, &u);
        let error = (adjoint.start[r] - expected).abs() / expected.abs();
        eprintln!("{case} start {r}: {} vs {expected}", adjoint.start[r]);
        worst = worst.max(error);
    }
    assert!(worst <= 1e-8, "{case}: {worst:e}");
    worst
}

/// The one-disc scene (N = 100, T = 4, from its bump guess) with the disc x^2 + y^2 >= 1 as a
/// hard constraint (at the nodes and evaluation points) and L = 1/2 |q''|^2 + f y, f = 0: the
/// disc is active at 4 points with multipliers above 5. The derivative of the plan and its
/// cost in f against central differences of solves at f = +- 1e-4, and in the start's height
/// against solves with it moved by +- 1e-4 (tolerance 1e-12), to 1e-6 relative; the adjoint
/// of a weighted sum of the plan in f, in the weight w of y''^2 and in the start against the
/// forward directions.
#[test]
fn the_one_disc_sensitivities_with_the_disc_active_match_central_differences() {
    let steps = 100;
    let options = PlanOptions::default().with_tolerance(1e-12);
    let (x, u) = disc_bump_guess(steps);
    let disc = KeepOut::new(1.0);
    let solve = |f: f64, start: &[f64; 4]| {
        let system = DiscEffort::new(1.0, f);
        OptimalControlProblem::new(&system, start, &DISC_GOAL, 4.0, steps)
            .with_inequality(&disc)
            .with_options(options)
            .solve(PlanGuess::Path { x: &x, u: &u })
            .expect("one disc")
    };
    let eps = 1e-4;
    let plan = solve(0.0, &DISC_START);
    let (count, smallest) = active(&plan.duals);
    eprintln!("one disc: {count} active, smallest multiplier {smallest:e}");
    assert!(count >= 3 && smallest > 1.0, "{count} {smallest:e}");
    let system = DiscEffort::new(1.0, 0.0);
    let problem = OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps)
        .with_inequality(&disc)
        .with_options(options);
    let sens = problem.sensitivities(&plan).expect("sensitivities");
    let (force, weight) = (ForceDerivative::new(), WeightDerivative::new());
    let in_force = Parameter {
        lagrangian: &force,
        equalities: &[],
    };
    let sensitivity = sens.parameter(&in_force).expect("f");
    let (plus, minus) = (solve(eps, &DISC_START), solve(-eps, &DISC_START));
    assert_matches("one disc, force", &sensitivity, (&plus, &minus), eps);
    // the start's height (the cost's derivative is not part of a start sensitivity)
    let moved = |by: f64| {
        let mut start = DISC_START;
        start[1] += by;
        solve(0.0, &start)
    };
    let (plus, minus) = (moved(eps), moved(-eps));
    let (dx, du) = sens.start(&[0.0, 1.0, 0.0, 0.0]).expect("start");
    let in_start = retract::bvp::ParameterSensitivity {
        x: dx,
        u: du,
        cost: (plus.cost - minus.cost) / (2.0 * eps),
    };
    assert_matches("one disc, start", &in_start, (&plus, &minus), eps);
    let in_weight = Parameter {
        lagrangian: &weight,
        equalities: &[],
    };
    assert_adjoint("one disc", &sens, &[in_force, in_weight], steps);
}

/// The swing-up (T = 2, N = 40) with |q''| <= 22 on both joints, active on 6 steps: the
/// derivative of the plan and its cost in gravity against central differences of solves at
/// g = 9.81 +- 1e-4 (tolerance 1e-12, each from the spline), to 1e-6 relative; the adjoint
/// against the forward directions.
#[test]
fn the_bounded_swing_up_s_gravity_sensitivity_matches_central_differences() {
    let goal = [PI, 0.0, 0.0, 0.0];
    let options = PlanOptions::default().with_tolerance(1e-12);
    let bound = 22.0;
    let solve = |g: f64, guess: PlanGuess<'_, 2, 4>| {
        let system = DoublePendulum { g };
        OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 40)
            .with_input_bounds([-bound; 2], [bound; 2])
            .with_options(options)
            .solve(guess)
            .expect("swing-up")
    };
    let (g, eps) = (9.81, 1e-4);
    let plan = solve(g, PlanGuess::Spline);
    let (count, smallest) = active(&plan.duals);
    let peak = plan.u.iter().map(|u| u.amax()).fold(0.0, f64::max);
    eprintln!("bounded swing-up: {count} active, smallest multiplier {smallest:e}, peak {peak}");
    assert!(count >= 2 && smallest > 1e-2, "{count} {smallest:e}");
    let system = DoublePendulum { g };
    let problem = OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 40)
        .with_input_bounds([-bound; 2], [bound; 2])
        .with_options(options);
    let sens = problem.sensitivities(&plan).expect("sensitivities");
    let dl = GravityDerivative::new(g);
    let parameter = Parameter {
        lagrangian: &dl,
        equalities: &[],
    };
    let sensitivity = sens.parameter(&parameter).expect("gravity");
    let plus = solve(g + eps, PlanGuess::Spline);
    let minus = solve(g - eps, PlanGuess::Spline);
    assert_matches("bounded swing-up", &sensitivity, (&plus, &minus), eps);
    // on the active steps the bound holds the input: it does not move with g
    for (i, (u, du)) in plan.u.iter().zip(&sensitivity.u).enumerate() {
        for a in 0..2 {
            if (u[a].abs() - bound).abs() < 1e-9 {
                assert!(du[a].abs() < 1e-6, "step {i}: {}", du[a]);
            }
        }
    }
    assert_adjoint("bounded swing-up", &sens, &[parameter], 40);
}

/// A bound exactly at the unbounded plan's largest input is weakly active there (value and
/// multiplier both vanish): the plan is not differentiable, and its sensitivities are
/// refused, naming the bound and the step.
#[test]
fn a_weakly_active_bound_is_refused() {
    let goal = [PI, 0.0, 0.0, 0.0];
    let options = PlanOptions::default().with_tolerance(1e-12);
    let system = DoublePendulum { g: 9.81 };
    let free = OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 40)
        .with_options(options)
        .solve(PlanGuess::Spline)
        .expect("swing-up");
    let (step, top) = (free.u.iter().enumerate())
        .map(|(i, u)| (i, u[0]))
        .fold((0, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
    let problem = OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 40)
        .with_input_bounds([f64::NEG_INFINITY; 2], [top, f64::INFINITY])
        .with_options(options);
    let plan = problem.solve(PlanGuess::Plan(&free)).expect("bounded");
    let refused = problem.sensitivities(&plan).expect_err("weakly active");
    eprintln!("{refused}");
    match refused {
        Failure::WeaklyActive {
            location,
            slack,
            multiplier,
            ..
        } => {
            assert_eq!(location, retract::bvp::Location::Step(step));
            assert!(
                slack < 1e-3 && multiplier < 1e-3,
                "{slack:e} {multiplier:e}"
            );
        }
        other => panic!("{other}"),
    }
}
