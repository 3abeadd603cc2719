//! A car in the plane, q = (x, y, heading), planned by the optimizer with its nonholonomic
//! constraint as an equality on the jet and forward-only speed as a hard bound. Shared by
//! `examples/car.rs` and `tests/planning/car.rs` (by path).
#![allow(dead_code)] // each user takes a subset

use std::f64::consts::PI;

use retract::bvp::{OptimalControlProblem, Plan, PlanError, PlanGuess, PlanOptions};
use retract::nalgebra::SVector;
use retract::{JetFunction, higher_order_lagrangian, jet_function};

/// Minimum acceleration: L = 1/2 (x''^2 + y''^2 + w^2 heading''^2).
#[higher_order_lagrangian(order = 2)]
pub fn acceleration(_q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], w: f64) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1] + w * w * ddq[2] * ddq[2])
}

/// The wheels do not slip sideways: the velocity's component across the heading,
/// x' sin(heading) - y' cos(heading), is zero.
#[jet_function(order = 2)]
pub fn no_slip(q: [f64; 3], dq: [f64; 3], _ddq: [f64; 3]) -> f64 {
    dq[0] * q[2].sin() - dq[1] * q[2].cos()
}

/// The speed along the heading, x' cos(heading) + y' sin(heading) (>= 0: forward only).
#[jet_function(order = 2)]
pub fn forward_speed(q: [f64; 3], dq: [f64; 3], _ddq: [f64; 3]) -> f64 {
    dq[0] * q[2].cos() + dq[1] * q[2].sin()
}

/// A U-turn: from the origin heading +x at unit speed to (0, `width`) heading -x at unit speed,
/// in `t_end`.
pub fn u_turn(width: f64) -> ([f64; 6], [f64; 6]) {
    (
        [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        [0.0, width, PI, -1.0, 0.0, 0.0],
    )
}

/// The jet (q, q') at the evaluation point of step `i` and its top derivative.
pub fn evaluation_point(plan: &Plan<3, 6>, i: usize) -> ([SVector<f64, 3>; 2], SVector<f64, 3>) {
    let x = (plan.x[i] + plan.x[i + 1]) * 0.5;
    (
        [
            x.fixed_rows::<3>(0).into_owned(),
            x.fixed_rows::<3>(3).into_owned(),
        ],
        plan.u[i],
    )
}

/// The smallest speed and the largest sideways slip over the evaluation points.
pub fn speed_and_slip(plan: &Plan<3, 6>) -> (f64, f64) {
    (0..plan.u.len()).fold((f64::INFINITY, 0.0_f64), |(speed, slip), i| {
        let (x, u) = evaluation_point(plan, i);
        (
            speed.min(ForwardSpeed.value(&x, &u)),
            slip.max(NoSlip.value(&x, &u).abs()),
        )
    })
}

/// The U-turn of width `width` in `t_end` with `steps` steps, without slip; forward only when
/// `forward_only`.
pub fn plan_u_turn(
    width: f64,
    t_end: f64,
    steps: usize,
    forward_only: bool,
) -> Result<Plan<3, 6>, PlanError<3, 6>> {
    let system = Acceleration { w: 1.0 };
    let (start, goal) = u_turn(width);
    let problem = OptimalControlProblem::new(&system, &start, &goal, t_end, steps)
        .with_equality(&NoSlip)
        .with_options(PlanOptions::default().with_max_iterations(500));
    let problem = if forward_only {
        problem.with_inequality(&ForwardSpeed)
    } else {
        problem
    };
    problem.solve(PlanGuess::Spline)
}
