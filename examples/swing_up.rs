//! Swing-up suite (`../shared/BENCHMARKS.md`): rest-to-rest minimum-torque swing-ups on the
//! lifted-midpoint transcription with N = 100 T steps from the smoothstep guess, solved by the
//! optimizer (`OptimalControlProblem`): the double pendulum and the cart-pole of the suite, and
//! the acrobot (the double pendulum with a passive shoulder: cost on the elbow torque, the
//! shoulder torque constrained to zero; T = 3 and 4 start from the previous horizon's plan).
//! One line per problem:
//! `<problem> T=<T> N=<N> J=<J> iterations=<n> time_ms=<t> min_reduced_hessian_eig=<e>`.
//!
//! Run: `cargo run --release --example swing_up` (add `-- quick` for T = 1 only, the acrobot
//! at T = 2).

use std::f64::consts::PI;
use std::time::Instant;

use retract::bvp::{Curve, OptimalControlProblem, PlanGuess, PlanOptions};
use retract::jet_function;

#[path = "common/cart_pole.rs"]
mod cart_pole;
#[path = "common/pendulum.rs"]
mod pendulum;
use cart_pole::{CartPole, PoleTorque};
use pendulum::{ElbowCost, ShoulderTorque, TorqueCost};

/// A bound on the cart force: `limit - sign F >= 0` (sign = +1 and -1 bound it above and
/// below; F as in [`cart_pole::cart_pole`], whose cost is 1/2 F^2).
#[jet_function(order = 2)]
fn force_margin(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    mc: f64,
    mp: f64,
    l: f64,
    limit: f64,
    sign: f64,
) -> f64 {
    let force =
        (mc + mp) * ddq[0] + mp * l * q[1].cos() * ddq[1] - mp * l * q[1].sin() * dq[1] * dq[1];
    limit - sign * force
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
    // the cart-pole at T = 2 with its cart force bounded, |F| <= 14 (the free plan needs more;
    // examples/constrained.rs has the tighter bounds of the constrained suite)
    let limit = 14.0;
    let (upper, lower) = (
        ForceMargin::new(1.0, 0.3, 0.5, limit, 1.0),
        ForceMargin::new(1.0, 0.3, 0.5, limit, -1.0),
    );
    let problem = OptimalControlProblem::new(&cart, &[0.0; 4], &[0.0, PI, 0.0, 0.0], 2.0, 200)
        .with_equality(&unactuated)
        .with_inequality(&upper)
        .with_inequality(&lower)
        .with_options(options);
    let start = Instant::now();
    let plan = problem.solve(PlanGuess::Spline)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    report(&format!("cart-pole |F|<={limit}"), 2.0, 200, &plan, ms);
    let acrobot = ElbowCost::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let passive = ShoulderTorque::new(1.0, 1.0, 1.0, 1.0, 9.81);
    // each horizon after the first starts from the previous plan stretched in time (from the
    // smoothstep guess T = 4 does not converge)
    let mut previous: Option<(f64, retract::bvp::Plan<2, 4>)> = None;
    // (at T = 1 the one actuator needs torques of hundreds of N m and the solve stalls near
    // the tolerance: the quick run takes T = 2)
    let acrobot_horizons: &[f64] = if quick { &[2.0] } else { horizons };
    for &t_end in acrobot_horizons {
        let steps = (100.0 * t_end) as usize;
        let problem =
            OptimalControlProblem::new(&acrobot, &[0.0; 4], &[PI, 0.0, 0.0, 0.0], t_end, steps)
                .with_equality(&passive)
                .with_options(options);
        let last = previous.take();
        let stretched = last.as_ref().map(|(t_last, plan)| {
            Curve::from_fn(move |t| {
                let x = plan.evaluate((t * t_last / t_end).clamp(0.0, *t_last));
                x.map_or([f64::NAN; 2], |x| [x[0], x[1]])
            })
        });
        let start = Instant::now();
        let plan = problem.solve(
            stretched
                .as_ref()
                .map_or(PlanGuess::Spline, PlanGuess::Curve),
        )?;
        report(
            "acrobot",
            t_end,
            steps,
            &plan,
            start.elapsed().as_secs_f64() * 1e3,
        );
        drop(stretched);
        previous = Some((t_end, plan));
    }
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
