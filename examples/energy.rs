//! Mechanical systems written as their energy T - V and planned through `#[mechanical_system]`
//! (`examples/common/mechanical.rs`): the double pendulum's swing-up of the swing-up suite, the
//! planar quadrotor of the constrained suite (C2) driven by its two rotors through B(q) with
//! the lateral force as the generated passive equality, past the disc, and the n-link chain
//! (C4) with its joint limits for n = 3, 7, 12 (the chain also compiles for n = 5; the growth
//! of its expansion in n is in `validation/examples/chain_expansion.rs`). One line per plan, `<name> T=<T> N=<N> J=<J> iterations=<n> time_ms=<t>
//! min_reduced_hessian_eig=<e> max_equality=<v>` (the largest passive equality along the plan's
//! midpoints; 0 where there is none).
//!
//! Run: `cargo run --release --example energy` (`-- quick`: a tenth of the steps).

use std::f64::consts::PI;
use std::time::Instant;

use retract::bvp::{Plan, Variable};
use retract::nalgebra::SVector;
use retract::{
    JetFunction, MechanicalSystem, OptimalControlProblem, PlanGuess, PlanOptions, jet_function,
};

#[path = "common/mechanical.rs"]
mod mechanical;

use mechanical::{DoublePendulumEnergy, QuadrotorEnergy};

energy_chain!(chain3, 3);
energy_chain!(chain5, 5);
energy_chain!(chain7, 7);
energy_chain!(chain12, 12);

/// Clearance of the disc of radius 0.3 about (1, 0.5): (x - 1)^2 + (z - 0.5)^2 - 0.3^2.
#[jet_function(order = 2)]
fn clearance(q: [f64; 3], _dq: [f64; 3], _ddq: [f64; 3]) -> f64 {
    (q[0] - 1.0).powi(2) + (q[1] - 0.5).powi(2) - 0.09
}

type Outcome = Result<(), Box<dyn std::error::Error>>;

/// The largest |g| of the passive equalities of `system` at the midpoints of `plan`.
fn max_equality<S: MechanicalSystem<N>, const N: usize, const X: usize>(
    system: &S,
    plan: &Plan<N, X>,
) -> f64 {
    let mut worst = 0.0f64;
    for i in 0..plan.u.len() {
        let x = (plan.x[i] + plan.x[i + 1]) * 0.5;
        let jet = [
            SVector::<f64, N>::from_fn(|r, _| x[r]),
            SVector::<f64, N>::from_fn(|r, _| x[N + r]),
        ];
        for &c in system.unactuated() {
            let g = retract::TorqueComponent { system, index: c };
            worst = worst.max(g.value(&jet, &plan.u[i]).abs());
        }
    }
    worst
}

/// Prints a plan's line.
fn report<const N: usize, const X: usize>(
    name: &str,
    t_end: f64,
    plan: &Plan<N, X>,
    ms: f64,
    equality: f64,
) {
    println!(
        "{name} T={t_end} N={} J={:.6} iterations={} time_ms={ms:.1} \
         min_reduced_hessian_eig={:.3e} max_equality={equality:.1e}",
        plan.u.len(),
        plan.cost,
        plan.iterations,
        plan.certificate.min_reduced_hessian_eig
    );
}

/// The chain C4 with `$n` links from rest at q = 0 to rest at q_i = `$goal`, |q_i| <= 2,
/// T = 2: its report line, or the error.
macro_rules! plan_chain {
    ($name:expr, $system:expr, $n:literal, $goal:expr, $steps:expr, $options:expr) => {{
        let system = $system;
        let mut end = [0.0; 2 * $n];
        end[..$n].fill($goal);
        let mut problem = OptimalControlProblem::new(&system, &[0.0; 2 * $n], &end, 2.0, $steps)
            .with_options($options);
        for joint in 0..$n {
            problem = problem.with_bounds(Variable::Jet(joint), -2.0, 2.0);
        }
        let start = Instant::now();
        let plan = problem.solve(PlanGuess::Spline)?;
        report($name, 2.0, &plan, start.elapsed().as_secs_f64() * 1e3, 0.0);
    }};
}

fn run() -> Outcome {
    let quick = std::env::args().any(|a| a == "quick");
    let steps = if quick { 20 } else { 200 };
    let options = PlanOptions::default().with_min_eigenvalue(true);

    let pendulum = DoublePendulumEnergy::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let start = Instant::now();
    let plan = OptimalControlProblem::new(&pendulum, &[0.0; 4], &[PI, 0.0, 0.0, 0.0], 2.0, steps)
        .with_options(options)
        .solve(PlanGuess::Spline)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    report("pendulum-energy", 2.0, &plan, ms, 0.0);

    let quadrotor = QuadrotorEnergy::new(1.0, 0.01, 0.1, 9.81);
    let lateral = quadrotor.unactuated_torques();
    let disc = Clearance::new();
    let goal = [2.0, 1.0, 0.0, 0.0, 0.0, 0.0];
    let start = Instant::now();
    let plan = OptimalControlProblem::new(&quadrotor, &[0.0; 6], &goal, 2.0, steps)
        .with_equalities(&lateral)
        .with_inequality(&disc)
        .with_options(options)
        .solve(PlanGuess::Spline)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    report(
        "quadrotor-energy",
        2.0,
        &plan,
        ms,
        max_equality(&quadrotor, &plan),
    );

    plan_chain!("chain3-energy", Chain3::new(), 3, 1.5, steps, options);
    plan_chain!("chain7-energy", Chain7::new(), 7, 0.5, steps, options);
    plan_chain!("chain12-energy", Chain12::new(), 12, 0.5, steps, options);
    // (compiled, not planned)
    let _ = Chain5::new();
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
