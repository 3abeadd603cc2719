//! The constrained suite C1-C5 of `../shared/BENCHMARKS.md`, solved by the optimizer at its
//! default options from the suite's first guesses: the cart-pole with a force bound, the planar
//! quadrotor past a disc with thrust limits, parallel parking in a slot, chains of 3 and 7
//! links with joint limits, and the cart-pole's minimum-time swing-up (a free final time,
//! from its energy). One line per problem:
//! `<name> J=<J> iterations=<n> time_ms=<t> max_violation=<v> min_reduced_hessian_eig=<e>`,
//! with `T=<T>` after `J` for the free final time (its `iterations` those of all its
//! fixed-horizon solves).
//!
//! Run: `cargo run --release --example constrained` (add `-- quick` for a smaller version of
//! each problem: a tenth of the steps; `cargo test --example constrained` runs that as a test,
//! and `cargo test --workspace` with it; add `adaptive` for the adaptive barrier update,
//! [`BarrierUpdate::Adaptive`], a suite's name for that suite alone, and `steps=N` for N steps
//! on every fixed horizon instead of 100 per unit time, as the IPOPT reference's `NSTEPS`).

use std::f64::consts::PI;
use std::time::Instant;

use retract::bvp::{
    BarrierUpdate, Curve, FreeTime, OptimalControlProblem, Placement, Plan, PlanError, PlanGuess,
    PlanOptions, Variable,
};
use retract::higher_order_lagrangian;

#[path = "common/cart_pole.rs"]
mod cart_pole;
use cart_pole::{CartForce, CartPole, MinTimeCartPole, PoleTorque};

#[path = "common/parking.rs"]
mod parking;
use parking::{CarEffort, SideSlip, Turning};

#[path = "common/quadrotor.rs"]
mod quadrotor;
use quadrotor::{Clearance, Lateral, Quadrotor, Rotors};

const G: f64 = 9.81;

/// What a suite returns: an error for its first failure.
type Outcome = Result<(), Box<dyn std::error::Error>>;

/// A suite of problems, run at full or reduced size.
type Suite = fn(bool) -> Outcome;

/// The options of every solve: the defaults, with the adaptive barrier update when the
/// command line says `adaptive`.
fn options() -> PlanOptions {
    let adaptive = std::env::args().any(|a| a == "adaptive");
    let update = if adaptive {
        BarrierUpdate::Adaptive
    } else {
        BarrierUpdate::Monotone
    };
    PlanOptions::default().with_barrier_update(update)
}

/// The planar n-link chain's cost 1/2 |tau|^2, tau the Euler-Lagrange torques of T - V (unit
/// lengths and masses at the link ends, joint angles relative, q_1 from the downward vertical):
/// with absolute angles phi_a = q_1 + ... + q_a, the torque on phi_a is the sum over the
/// masses j >= a and the links b <= j of cos(phi_a - phi_b) phi_b'' + sin(phi_a - phi_b)
/// phi_b'^2, plus g (n - a + 1) sin(phi_a), and tau_i = sum_{a >= i} of those.
macro_rules! chain {
    ($name:ident, $n:literal) => {
        #[doc = concat!("The ", stringify!($n), "-link chain (see the macro's docs).")]
        #[higher_order_lagrangian(order = 2)]
        fn $name(q: [f64; $n], dq: [f64; $n], ddq: [f64; $n]) -> f64 {
            let mut cost = 0.0;
            let mut tau = 0.0;
            // link a = n - 1 - r, from the tip: the joint torques accumulate
            for r in 0..$n {
                let mut phi_a = 0.0;
                for i in 0..$n - r {
                    phi_a += q[i];
                }
                // masses j >= a, each pulling on the links b <= j
                let mut torque = 9.81 * ((r + 1) as f64) * phi_a.sin();
                for j in $n - 1 - r..$n {
                    for b in 0..j + 1 {
                        let (mut phi_b, mut dphi_b, mut ddphi_b) = (0.0, 0.0, 0.0);
                        for i in 0..b + 1 {
                            phi_b += q[i];
                            dphi_b += dq[i];
                            ddphi_b += ddq[i];
                        }
                        let d = phi_a - phi_b;
                        torque += d.cos() * ddphi_b + d.sin() * dphi_b * dphi_b;
                    }
                }
                tau += torque;
                cost += 0.5 * tau * tau;
            }
            cost
        }
    };
}
chain!(chain3, 3);
chain!(chain7, 7);

/// A solved problem's report line, or the failure.
fn report<const N: usize, const X: usize>(
    name: &str,
    start: Instant,
    result: Result<Plan<N, X>, PlanError<N, X>>,
) -> Outcome {
    let ms = start.elapsed().as_secs_f64() * 1e3;
    match result {
        Ok(plan) => {
            println!(
                "{name} J={:.8} iterations={} time_ms={ms:.1} max_violation={:.1e} \
                 min_reduced_hessian_eig={:.3e}",
                plan.cost,
                plan.iterations,
                plan.violations.imposed(),
                plan.certificate.min_reduced_hessian_eig
            );
            Ok(())
        }
        Err(e) => {
            println!("{name} failed after {ms:.1} ms: {e}");
            Err(format!("{name}: {e}").into())
        }
    }
}

/// The number of steps for a horizon: 100 T, a tenth of it in the quick run, or the command
/// line's `steps=N` ([`given_steps`]).
fn steps(t_end: f64, quick: bool) -> usize {
    let full = (100.0 * t_end).round() as usize;
    given_steps()
        .and_then(Result::ok)
        .unwrap_or(if quick { full / 10 } else { full })
}

/// The command line's `steps=N`, if any: `N` if it is a positive integer, else the text.
fn given_steps() -> Option<Result<usize, String>> {
    let text = std::env::args().find_map(|a| a.strip_prefix("steps=").map(str::to_owned))?;
    Some(text.parse().ok().filter(|&n| n > 0).ok_or(text))
}

fn cart_pole_suite(quick: bool) -> Outcome {
    // (every problem runs; the first failure is returned)
    let mut outcome: Outcome = Ok(());
    let (mc, mp, l) = (1.0, 0.3, 0.5);
    let system = CartPole::new(mc, mp, l);
    let unactuated = PoleTorque::new(mp, l, G);
    let force = CartForce::new(mc, mp, l);
    for (t_end, limit) in [(2.0, 12.0), (2.0, 10.0), (3.0, 6.0)] {
        let name = format!("cartpole-T{t_end}-F{limit}");
        let start = Instant::now();
        let result = OptimalControlProblem::new(
            &system,
            &[0.0; 4],
            &[0.0, PI, 0.0, 0.0],
            t_end,
            steps(t_end, quick),
        )
        .with_equality(&unactuated)
        .with_function_bounds(&force, -limit, limit)
        .with_options(options())
        .solve(PlanGuess::Spline);
        outcome = outcome.and(report(&name, start, result));
    }
    outcome
}

/// C5: the cart-pole from rest hanging to rest upright in the least T + int 0.01 1/2 F^2,
/// T in [0.5, 5], |F| <= 10 at the midpoints, |x| <= 1 at nodes and midpoints, N = 100, from
/// the smoothstep of T = 3.
fn min_time_suite(quick: bool) -> Outcome {
    let system = MinTimeCartPole::new(1.0, 0.3, 0.5, G);
    let (passive, force) = (system.unactuated_torques(), system.input_functions());
    let steps = if quick { 10 } else { 100 };
    let start = Instant::now();
    let result = OptimalControlProblem::new(&system, &[0.0; 4], &[0.0, PI, 0.0, 0.0], 3.0, steps)
        .with_equalities(&passive)
        .with_function_bounds(&force[0], -10.0, 10.0)
        .with_bounds(Variable::Jet(0), -1.0, 1.0)
        .with_options(options())
        .solve_free_time(FreeTime::new(0.5, 5.0, 1.0), PlanGuess::Spline);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    match result {
        Ok(free) => {
            println!(
                "cartpole-mintime J={:.8} T={:.8} iterations={} time_ms={ms:.1} \
                 max_violation={:.1e} min_reduced_hessian_eig={:.3e}",
                free.cost,
                free.t_end,
                free.iterations,
                free.plan.violations.imposed(),
                free.plan.certificate.min_reduced_hessian_eig
            );
            Ok(())
        }
        Err(e) => {
            println!("cartpole-mintime failed after {ms:.1} ms: {e}");
            Err(format!("cartpole-mintime: {e}").into())
        }
    }
}

fn quadrotor_suite(quick: bool) -> Outcome {
    // (every problem runs; the first failure is returned)
    let mut outcome: Outcome = Ok(());
    let (m, inertia, arm) = (1.0, 0.01, 0.1);
    let system = Quadrotor::new(m, inertia, arm);
    let no_lateral = Lateral::new(m);
    let thrusts = Rotors::new(m, inertia, arm);
    let disc = Clearance::new();
    for fmax in [15.0, 6.0] {
        let name = format!("quadrotor-f{fmax}");
        let start = Instant::now();
        let result = OptimalControlProblem::new(
            &system,
            &[0.0; 6],
            &[2.0, 1.0, 0.0, 0.0, 0.0, 0.0],
            2.0,
            steps(2.0, quick),
        )
        .with_equality(&no_lateral)
        .with_vector_bounds(&thrusts, &[0.0; 2], &[fmax; 2])
        .with_inequality(&disc)
        .with_options(options())
        .solve(PlanGuess::Spline);
        outcome = outcome.and(report(&name, start, result));
    }
    outcome
}

fn parking_suite(quick: bool) -> Outcome {
    // (every problem runs; the first failure is returned)
    let mut outcome: Outcome = Ok(());
    use retract::bvp::Variable;
    let system = CarEffort::new();
    let (slip, turn) = (SideSlip::new(), Turning::new());
    let t_end = 6.0;
    let times = [0.0, 1.5, 3.0, 4.5, 6.0];
    let guess = Curve::through_waypoints(&times, &parking::WAYPOINTS)?;
    for xbox in [0.8, 0.4] {
        let name = format!("parking-x{xbox}");
        let start = Instant::now();
        let result = OptimalControlProblem::new(
            &system,
            &[0.0; 6],
            &[0.0, 0.5, 0.0, 0.0, 0.0, 0.0],
            t_end,
            steps(t_end, quick),
        )
        .with_equality(&slip)
        // (the turning radius at the midpoints only, as the suite defines it: a function
        // of the jet alone would otherwise be placed at the nodes too)
        .with_inequality_at(&turn, Placement::Midpoints)
        .with_bounds(Variable::Jet(0), -xbox, xbox)
        .with_options(options())
        .solve(PlanGuess::Curve(&guess));
        outcome = outcome.and(report(&name, start, result));
    }
    outcome
}

fn chain_suite(quick: bool) -> Outcome {
    use retract::bvp::Variable;
    let t_end = 2.0;
    let system = Chain3::new();
    let mut problem = OptimalControlProblem::new(
        &system,
        &[0.0; 6],
        &[1.5, 1.5, 1.5, 0.0, 0.0, 0.0],
        t_end,
        steps(t_end, quick),
    );
    for joint in 0..3 {
        problem = problem.with_bounds(Variable::Jet(joint), -2.0, 2.0);
    }
    let start = Instant::now();
    let first = report(
        "chain3",
        start,
        problem.with_options(options()).solve(PlanGuess::Spline),
    );
    let system = Chain7::new();
    let mut goal = [0.0; 14];
    goal[..7].fill(0.5);
    let mut problem =
        OptimalControlProblem::new(&system, &[0.0; 14], &goal, t_end, steps(t_end, quick));
    for joint in 0..7 {
        problem = problem.with_bounds(Variable::Jet(joint), -2.0, 2.0);
    }
    let start = Instant::now();
    first.and(report(
        "chain7",
        start,
        problem.with_options(options()).solve(PlanGuess::Spline),
    ))
}

fn main() {
    let quick = std::env::args().any(|a| a == "quick");
    if let Some(Err(text)) = given_steps() {
        eprintln!("steps={text}: give the number of steps as a positive integer");
        std::process::exit(2);
    }
    let only = (std::env::args().skip(1))
        .find(|a| a != "quick" && a != "adaptive" && !a.starts_with("steps="));
    let mut failed = false;
    let suites: [(&str, Suite); 5] = [
        ("cartpole", cart_pole_suite),
        ("quadrotor", quadrotor_suite),
        ("parking", parking_suite),
        ("chain", chain_suite),
        ("mintime", min_time_suite),
    ];
    for (name, suite) in suites {
        if only.as_ref().is_none_or(|o| o == name) {
            failed |= suite(quick).is_err();
        }
    }
    if failed {
        std::process::exit(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every problem of the suite at a tenth of its steps ends at a certified local minimum
    /// at the default options (a plan is only returned certified, with no constraint
    /// violated beyond the tolerance where it is imposed).
    #[test]
    fn the_suite_is_certified_at_a_tenth_of_its_steps() {
        for suite in [
            cart_pole_suite,
            quadrotor_suite,
            parking_suite,
            chain_suite,
            min_time_suite,
        ] {
            if let Err(e) = suite(true) {
                panic!("{e}");
            }
        }
    }
}
