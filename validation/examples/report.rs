//! The speed report: every figure of the "Speed against error" section of `docs/benchmarks.md`
//! and of its planner speed passages (solve time against N, the optimizer against the root finder,
//! Richardson extrapolation) in one run, the peers (hand-written steps, dense and dual-number
//! Newton, finite differences, RK4 and DOP853 on plain right-hand sides) timed interleaved with
//! `retract`, printed as markdown tables with the date and the machine
//! (`retract_validation::report`).
//!
//! Run: `cargo run --release -p retract-validation --example report` (about a minute), or
//! with `-- --quick` for the same lines at reduced size in a few seconds.

use std::io::Write;
use std::process::ExitCode;

use retract_validation::Error;
use retract_validation::report::{self, Size};

fn run() -> Result<(), Error> {
    let mut size = Size::full();
    for argument in std::env::args().skip(1) {
        match argument.as_str() {
            "--quick" => size = Size::quick(),
            other => {
                return Err(Error::Io(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("unknown argument `{other}`; supported: --quick"),
                )));
            }
        }
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    report::run(&size, &mut out)?;
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
