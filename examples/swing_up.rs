//! Swing-up suite (`../shared/BENCHMARKS.md`): rest-to-rest minimum-torque swing-ups on the
//! lifted-midpoint transcription with N = 100 T steps from the smoothstep guess, solved by the
//! optimizer (`OptimalControlProblem`). One line per problem:
//! `<problem> T=<T> N=<N> J=<J> iterations=<n> time_ms=<t> min_reduced_hessian_eig=<e>`.
//!
//! Run: `cargo run --release --example swing_up` (add `-- quick` for T = 1 only, as the tests
//! do).

use std::f64::consts::PI;
use std::time::Instant;

use retract::bvp::{OptimalControlProblem, PlanGuess, PlanOptions};
use retract::{higher_order_lagrangian, jet_function};

#[path = "common/pendulum.rs"]
mod pendulum;
use pendulum::TorqueCost;

/// Cart-pole: cost 1/2 F^2 on the cart force
/// F = (mc + mp) x'' + mp l cos(th) th'' - mp l sin(th) th'^2, q = (x, th), th from the
/// downward vertical.
#[higher_order_lagrangian(order = 2)]
fn cart_pole(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], mc: f64, mp: f64, l: f64) -> f64 {
    let force =
        (mc + mp) * ddq[0] + mp * l * q[1].cos() * ddq[1] - mp * l * q[1].sin() * dq[1] * dq[1];
    0.5 * force * force
}

/// The pole's generalized force, which no actuator supplies: it must vanish at every step,
/// tau_p = mp l cos(th) x'' + mp l^2 th'' + mp g l sin(th).
#[jet_function(order = 2)]
fn pole_torque(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], mp: f64, l: f64, g: f64) -> f64 {
    mp * l * q[1].cos() * ddq[0] + mp * l * l * ddq[1] + mp * g * l * q[1].sin()
}

/// Prints the suite's line for one plan.
fn report(name: &str, t_end: f64, steps: usize, plan: &retract::bvp::Plan<2, 4>, ms: f64) {
    println!(
        "{name} T={t_end} N={steps} J={:.6} iterations={} time_ms={ms:.1} min_reduced_hessian_eig={:.3e}",
        plan.cost, plan.iterations, plan.certificate.min_reduced_hessian_eig
    );
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let quick = std::env::args().any(|a| a == "quick");
    let horizons: &[f64] = if quick { &[1.0] } else { &[2.0, 3.0, 4.0] };
    let pendulum = TorqueCost::new(1.0, 1.0, 1.0, 1.0, 9.81);
    // the line reports the smallest eigenvalue, so compute it (the inertia alone certifies)
    let options = PlanOptions::default().with_min_eigenvalue(true);
    for &t_end in horizons {
        let steps = (100.0 * t_end) as usize;
        let problem =
            OptimalControlProblem::new(&pendulum, &[0.0; 4], &[PI, 0.0, 0.0, 0.0], t_end, steps)
                .with_options(options);
        let start = Instant::now();
        let plan = problem.solve(PlanGuess::Spline)?;
        report(
            "pendulum",
            t_end,
            steps,
            &plan,
            start.elapsed().as_secs_f64() * 1e3,
        );
    }
    let cart = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, 9.81);
    for &t_end in horizons {
        let steps = (100.0 * t_end) as usize;
        let problem =
            OptimalControlProblem::new(&cart, &[0.0; 4], &[0.0, PI, 0.0, 0.0], t_end, steps)
                .with_equality(&unactuated)
                .with_options(options);
        let start = Instant::now();
        let plan = problem.solve(PlanGuess::Spline)?;
        report(
            "cart-pole",
            t_end,
            steps,
            &plan,
            start.elapsed().as_secs_f64() * 1e3,
        );
    }
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
