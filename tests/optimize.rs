//! The optimizer (`OptimalControlProblem`): its plans satisfy the lifted scheme, its
//! certificate agrees with a dense computation, it descends where the root finder stops at a
//! saddle, it never returns a path through an obstacle, and its failures carry the iterate.

mod common;

use std::f64::consts::PI;

use retract::bvp::{
    BoundaryValueProblem, Failure, OptimalControlProblem, Plan, PlanGuess, PlanOptions,
};
use retract::nalgebra::{DMatrix, SVector};
use retract::{Lagrangian, LiftedSystem, higher_order_lagrangian};

/// The double pendulum of the swing-up suite (`../shared/BENCHMARKS.md`).
#[higher_order_lagrangian(order = 2)]
fn double_pendulum(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    let c2 = q[1].cos();
    let s2 = q[1].sin();
    let m11 = 3.0 + 2.0 * c2;
    let m12 = 1.0 + c2;
    let g1 = 2.0 * g * q[0].sin() + g * (q[0] + q[1]).sin();
    let g2 = g * (q[0] + q[1]).sin();
    let tau1 = m11 * ddq[0] + m12 * ddq[1] - s2 * (2.0 * dq[0] * dq[1] + dq[1] * dq[1]) + g1;
    let tau2 = m12 * ddq[0] + ddq[1] + s2 * dq[0] * dq[0] + g2;
    0.5 * (tau1 * tau1 + tau2 * tau2)
}

/// The one-disc scene of `../shared/BENCHMARKS.md`.
#[higher_order_lagrangian(order = 2)]
fn one_disc(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
}

const DISC_START: [f64; 4] = [-2.0, 0.2, 1.0, 0.0];
const DISC_GOAL: [f64; 4] = [2.0, 0.2, 1.0, 0.0];

/// The scene's feasible guess: the Hermite cubic (here the straight line at unit speed) plus a
/// bump 1.3 * 16 s^2 (1 - s)^2 in y, with its derivatives.
fn bump_guess(steps: usize) -> (Vec<SVector<f64, 4>>, Vec<SVector<f64, 2>>) {
    let t_end = 4.0;
    let h = t_end / steps as f64;
    let y = |s: f64| {
        (
            1.3 * 16.0 * s * s * (1.0 - s).powi(2),
            1.3 * 16.0 * (2.0 * s - 6.0 * s * s + 4.0 * s.powi(3)) / t_end,
            1.3 * 16.0 * (2.0 - 12.0 * s + 12.0 * s * s) / (t_end * t_end),
        )
    };
    let x = (0..=steps)
        .map(|i| {
            let t = i as f64 * h;
            let (b, db, _) = y(t / t_end);
            SVector::from([-2.0 + t, 0.2 + b, 1.0, db])
        })
        .collect();
    let u = (0..steps)
        .map(|i| {
            let (_, _, ddb) = y((i as f64 + 0.5) * h / t_end);
            SVector::from([0.0, ddb])
        })
        .collect();
    (x, u)
}

fn solve_disc(
    steps: usize,
    options: PlanOptions,
) -> Result<Plan<2, 4>, retract::bvp::PlanError<2, 4>> {
    let system = OneDisc { tau: 1e-2 };
    let (x, u) = bump_guess(steps);
    OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps)
        .with_options(options)
        .solve(PlanGuess::Path { x: &x, u: &u })
}

/// The plan's states z_i = (x_i, p_i) and top derivatives satisfy the lifted midpoint scheme
/// (the discrete necessary conditions the root finder solves), so the momenta recovered from
/// the multipliers are the scheme's momenta.
#[test]
fn plan_satisfies_the_lifted_scheme() {
    let system = OneDisc { tau: 1e-2 };
    let plan = solve_disc(400, PlanOptions::default()).unwrap();
    assert_eq!(plan.certificate.negative_directions, 0);
    assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
    let z = |i: usize| {
        SVector::<f64, 8>::from_fn(|r, _| {
            if r < 4 {
                plan.x[i][r]
            } else {
                plan.momenta[i][r - 4]
            }
        })
    };
    let mut worst: f64 = 0.0;
    for i in 0..400 {
        let w =
            SVector::<f64, 10>::from_fn(|r, _| if r < 8 { z(i + 1)[r] } else { plan.u[i][r - 8] });
        let f = system.residual(&z(i), &w, plan.h, 0.5);
        worst = worst.max(f.amax());
    }
    assert!(worst < 1e-9, "scheme residual {worst:e}");
    // the root finder, started from these states, stays at this point
    let states: Vec<_> = (0..=400).map(z).collect();
    let root = BoundaryValueProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, 400)
        .solve(retract::bvp::Guess::States(&states))
        .unwrap();
    for i in 0..=400 {
        assert!((root.states[i] - z(i)).amax() < 1e-7, "state {i}");
    }
    assert!((root.cost - plan.cost).abs() < 1e-9 * plan.cost.abs());
}
