//! One step of the paper's SE(2) obstacle system near its closest approach with a step size
//! that changes from step to step (as an adaptive controller's): the reduced stepper, which
//! computes new factors on each such step, against the general step and the factors alone,
//! timed in interleaved rounds (`retract_validation::step_speed::changing_step_sizes`).
//!
//! Run: `cargo run --release -p retract-validation --example changing_step` (a few seconds).

use std::io::Write;
use std::process::ExitCode;

use retract_validation::Error;
use retract_validation::step_speed;
use retract_validation::systems::{closest_approach, paper_system};

/// Interleaved rounds.
const ROUNDS: usize = 60;

fn run() -> Result<(), Error> {
    let system = paper_system();
    let z = closest_approach(&system)?;
    let (rows, misses) = step_speed::changing_step_sizes(&system, &z, ROUNDS, 2000)?;
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    step_speed::write_changing(&mut out, &rows, misses, ROUNDS)?;
    out.flush()?;
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
