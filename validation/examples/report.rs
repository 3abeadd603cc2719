//! The speed report: every figure of the "Speed against error" section of `docs/benchmarks.md`
//! and of its planner speed passages (solve time against N, the optimizer against the root finder,
//! Richardson extrapolation) in one run, the peers (hand-written steps, dense and dual-number
//! Newton, finite differences, RK4 and DOP853 on plain right-hand sides) timed interleaved with
//! `retract`, printed as markdown tables with the date and the machine
//! (`retract_validation::report`).
//!
//! Run: `cargo run --release -p retract-validation --example report` (about a minute), or
//! with `-- --quick` for the same lines at reduced size in a few seconds; `-- --batch` prints
//! only the plans across cores (`batch <name> threads=<t> plans_per_s=<p> scaling=<s>`),
//! `-- --steps` only the one-step table (`step ratio generated/hand-written: ...`), `-- --mpc`
//! only the receding horizon (the lines of `--example mpc` of `retract`; at full size under
//! `--quick` too, 0.1 s);
//! `-- --write docs/benchmarks.md` also writes the report into that file, between its lines
//! `<!-- report:begin ... -->` and `<!-- report:end -->`.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use retract_validation::Error;
use retract_validation::report::{self, Size};

/// Standard output, with a copy of everything written (for `--write`).
struct Tee<W> {
    stdout: W,
    text: Vec<u8>,
}

impl<W: Write> Write for Tee<W> {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let written = self.stdout.write(bytes)?;
        self.text.extend_from_slice(&bytes[..written]);
        Ok(written)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.stdout.flush()
    }
}

fn run() -> Result<(), Error> {
    let mut size = Size::full();
    let (mut only_batches, mut only_steps, mut only_mpc) = (false, false, false);
    let mut target = None;
    let mut arguments = std::env::args().skip(1);
    while let Some(argument) = arguments.next() {
        match argument.as_str() {
            "--quick" => size = Size::quick(),
            "--batch" => only_batches = true,
            "--steps" => only_steps = true,
            "--mpc" => only_mpc = true,
            "--write" => match arguments.next() {
                Some(path) => target = Some(PathBuf::from(path)),
                None => return Err(invalid("`--write` needs the path of the file to write")),
            },
            other => {
                return Err(invalid(&format!(
                    "unknown argument `{other}`; supported: --quick, --batch, --steps, --mpc, --write PATH"
                )));
            }
        }
    }
    let stdout = std::io::stdout();
    let mut out = Tee {
        stdout: stdout.lock(),
        text: Vec::new(),
    };
    if only_batches || only_steps || only_mpc {
        writeln!(out, "{}", report::header(&size))?;
        if only_steps {
            report::steps(&size, &mut out)?;
        }
        if only_batches {
            report::batches(&size, &mut out)?;
        }
        if only_mpc {
            retract_validation::receding_horizon::write(&mut out)?;
        }
    } else {
        report::run(&size, &mut out)?;
    }
    out.flush()?;
    if let Some(path) = target {
        report::write_block(&path, &String::from_utf8_lossy(&out.text))?;
    }
    Ok(())
}

/// An error about the command line.
fn invalid(message: &str) -> Error {
    Error::Io(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        message,
    ))
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
