//! The paper's obstacle-avoidance experiment (Sec. 6) on R^2: L = 1/2|q''|^2 + tau/(|q|^2 - r^2),
//! r = 1, N = 400 steps of h = 0.01 with the lifted midpoint rule, for the paper's
//! tau = 1e-20 and for tau = 1e-2.
//!
//! Initial data (documented, the paper gives none): q(0) = (-2, 1.5), q'(0) = (1, 0),
//! q''(0) = q'''(0) = 0: a straight line passing above the unit disc.
//!
//! Run: `cargo run --release --example paper`

use std::time::Instant;

use retract::diagnostics::{energy_error, symplecticity_error};
use retract::models::PlanarBarrier;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, trajectory};

const STEPS: usize = 400;
const H: f64 = 0.01;
const JET: [f64; 8] = [-2.0, 1.5, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];

fn run() -> Result<(), Box<dyn std::error::Error>> {
    println!(
        "{:>8} | {:>22} | {:>10} | {:>10} | {:>10} | {:>9} | {:>9}",
        "tau", "final q", "min clear.", "max|dH|", "sympl.err", "Newton it", "time"
    );
    for tau in [1e-20, 1e-2] {
        let system = PlanarBarrier {
            tau,
            radius: 1.0,
            mass: 1.0,
        };
        let z0 = system.legendre(&SVector::<f64, 8>::from_column_slice(&JET));
        let options = StepOptions::default();
        let started = Instant::now();
        let run = trajectory(&system, &z0, H, STEPS, &options)?;
        let elapsed = started.elapsed();
        let clearance = run
            .states
            .iter()
            .map(|z| (z[0] * z[0] + z[1] * z[1]).sqrt() - system.radius)
            .fold(f64::INFINITY, f64::min);
        let last = run.states[STEPS];
        println!(
            "{:>8.0e} | ({:>9.5}, {:>9.5}) | {:>10.3e} | {:>10.3e} | {:>10.2e} | {:>4} / {:.2} | {:>7.1?}",
            tau,
            last[0],
            last[1],
            clearance,
            energy_error(&system, &run.states)?,
            symplecticity_error(&system, &z0, H, &options)?,
            run.max_iterations(),
            run.mean_iterations(),
            elapsed,
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
