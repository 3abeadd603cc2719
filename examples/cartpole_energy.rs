//! The cart-pole from its energy to a certified swing-up: the Lagrangian T - V written once
//! (`examples/common/cart_pole.rs`, `cart_pole_energy`), `#[mechanical_system]` derives the inverse dynamics tau(q, q', q''), the minimum-force cost
//! 1/2 F^2 on the cart (the actuated coordinate) and the pole's equality tau_pole = 0; the
//! optimizer plans the rest-to-rest swing-up of the swing-up suite (`../shared/BENCHMARKS.md`:
//! mc = 1, mp = 0.3, l = 0.5, T = 2, N = 200) and certifies it. One line:
//! `cartpole-energy T=<T> N=<N> J=<J> iterations=<n> time_ms=<t> min_reduced_hessian_eig=<e>
//! max_pole_torque=<tau>`.
//!
//! Run: `cargo run --release --example cartpole_energy`.

use std::f64::consts::PI;
use std::time::Instant;

use retract::nalgebra::SVector;
use retract::{OptimalControlProblem, PlanGuess, PlanOptions};

// the energy T - V (`cart_pole_energy`), shared with the tests
#[path = "common/cart_pole.rs"]
mod cart_pole;

use cart_pole::CartPoleEnergy;

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let (t_end, steps) = (2.0, 200);
    let system = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81);
    let passive = system.unactuated_torques();
    let options = PlanOptions::default().with_min_eigenvalue(true);
    let start = Instant::now();
    let plan = OptimalControlProblem::new(&system, &[0.0; 4], &[0.0, PI, 0.0, 0.0], t_end, steps)
        .with_equalities(&passive)
        .with_options(options)
        .solve(PlanGuess::Spline)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    // the pole's torque at every step's midpoint, from the generated inverse dynamics
    let max_pole_torque = (0..steps)
        .map(|i| {
            let x = (plan.x[i] + plan.x[i + 1]) * 0.5;
            let (q, dq) = (SVector::from([x[0], x[1]]), SVector::from([x[2], x[3]]));
            system.tau(&q, &dq, &plan.u[i])[1].abs()
        })
        .fold(0.0, f64::max);
    if plan.certificate.negative_directions != 0 {
        return Err("the plan is not a certified minimum".into());
    }
    println!(
        "cartpole-energy T={t_end} N={steps} J={:.6} iterations={} time_ms={ms:.1} \
         min_reduced_hessian_eig={:.3e} max_pole_torque={max_pole_torque:.1e}",
        plan.cost, plan.iterations, plan.certificate.min_reduced_hessian_eig
    );
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
