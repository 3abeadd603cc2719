//! The speed report: every figure of the "Speed against error" section of `docs/benchmarks.md`
//! and the planner's speed figures from one run, the peers timed interleaved with `retract`
//! (`examples/report.rs`).
//!
//! It writes, as markdown ready to paste: a header with the date (UTC) and the machine; the
//! one-step table ([`crate::step_speed`]); the paper's 400-step run; the singularity guard
//! ([`crate::guard_cost`]); the work-precision sweeps on the obstacle IVP with the times at
//! a final error of 1e-8 and the line
//! `work-precision 1e-8: best=<method> <t> us, DOP853 <t> us, ratio <best/DOP853>`
//! ([`crate::work_precision`]); the long run ([`crate::long_run`]); and the planner
//! ([`crate::planner_speed`]): solve time against N, the linear solvers and the warm re-solve
//! at N = 400, the optimizer against the root finder with the line
//! `ratios: one-disc cold <r>x, one-disc warm <r>x, se2 cold <r>x, se2 warm <r>x (target <= 1.2)`,
//! and Richardson extrapolation; and the compile-time cost of the expansion
//! ([`crate::expansion_cost`]), with the lines `chain n=<n> expand_ms=<t> lines=<l>` of the
//! n-link chain written as T - V; the plans across cores ([`crate::batch_speed`], lines
//! `batch <name> threads=<t> plans_per_s=<p> scaling=<s>`), the receding horizon
//! ([`crate::receding_horizon`], the lines of `--example mpc`) and the Riemannian cubic on
//! $S^2$ against de Casteljau ([`crate::sphere_cubic`], lines
//! `sphere cubic error=<e> time_us=<t> method=<retract|decasteljau>`).

use std::io::Write;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use crate::Error;
use crate::systems::{closest_approach, paper_system};
use crate::{
    batch_speed, expansion_cost, guard_cost, long_run, planner_speed, step_speed, work_precision,
};
use crate::{receding_horizon, sphere_cubic};

/// How much the report measures: rounds and calls per sample of each part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Size {
    /// Interleaved rounds of the one-step table.
    pub step_rounds: usize,
    /// Calls per sample of the cheapest steps (the dense ones make a twentieth of that).
    pub step_calls: usize,
    /// Interleaved rounds of the 400-step runs and of the guard.
    pub run_rounds: usize,
    /// Runs per sample of the 400-step runs.
    pub run_calls: usize,
    /// Interleaved rounds of the work-precision sweeps.
    pub sweep_rounds: usize,
    /// The horizon of the long run.
    pub long_run_end: f64,
    /// Interleaved rounds of the planner's solve times against N and at N = 400.
    pub planner_rounds: usize,
    /// Interleaved rounds of the optimizer against the root finder and of the extrapolation.
    pub race_rounds: usize,
    /// Expansions of each case of the compile-time cost.
    pub expansion_rounds: usize,
    /// Plans per thread of the most threads measured in each batch of the thread scaling
    /// (the batch holds that many times the machine's thread count, so that each thread of
    /// the largest pool has as many plans), and its interleaved rounds.
    pub batch: (usize, usize),
}

impl Size {
    /// The full report (10 to 30 s on a shared 2-core machine, the planner 2 to 9 s of it).
    pub fn full() -> Self {
        Self {
            step_rounds: 300,
            step_calls: 2000,
            run_rounds: 300,
            run_calls: 3,
            sweep_rounds: 200,
            long_run_end: 1e5,
            planner_rounds: 60,
            race_rounds: 200,
            expansion_rounds: 5,
            batch: (16, 5),
        }
    }

    /// The same lines at reduced size (a few seconds): for tests and CI; its figures are
    /// noisy.
    pub fn quick() -> Self {
        Self {
            step_rounds: 3,
            step_calls: 200,
            run_rounds: 3,
            run_calls: 1,
            sweep_rounds: 2,
            long_run_end: 1e3,
            planner_rounds: 2,
            race_rounds: 2,
            expansion_rounds: 1,
            batch: (1, 1),
        }
    }
}

/// The figures of a report the caller may want besides its text.
#[derive(Clone, Debug)]
pub struct Summary {
    /// The times at a final error of 1e-8.
    pub at_target: work_precision::AtTarget,
    /// The planner's measurements.
    pub planner: planner_speed::PlannerSpeed,
    /// Wall time of the report in seconds.
    pub seconds: f64,
}

/// Writes the one-step table of the SE(2) obstacle system and its ratios to the hand-written
/// steps ([`step_speed`]), every variant first checked against the general step.
///
/// # Errors
/// A step that fails or disagrees ([`Error`]), or [`Error::Io`].
pub fn steps(size: &Size, out: &mut dyn Write) -> Result<(), Error> {
    let system = paper_system();
    let z = closest_approach(&system)?;
    step_speed::check_variants(&system, &z)?;
    let rows = step_speed::steps(&system, &z, size.step_rounds, size.step_calls);
    step_speed::write_steps(out, &rows, size.step_rounds)
}

/// Writes the whole report to `out` (module docs).
///
/// # Errors
/// A measurement that fails ([`Error`]) or [`Error::Io`].
pub fn run(size: &Size, out: &mut dyn Write) -> Result<Summary, Error> {
    let started = Instant::now();
    writeln!(out, "{}", header(size))?;
    writeln!(
        out,
        "\nFigures are the best of several interleaved rounds (every variant once a round, the \
         order reversed every other round); ratios come from the same rounds.\n"
    )?;
    let system = paper_system();
    steps(size, out)?;
    let runs = step_speed::paper_runs(&system, size.run_rounds, size.run_calls)?;
    step_speed::write_runs(out, &runs, size.run_rounds)?;
    let guard = guard_cost::guard_costs(&system, size.run_rounds, size.step_calls)?;
    guard_cost::write_guard(out, &guard, size.run_rounds)?;
    let at_target = work_precision_part(size, out)?;
    let long = long_run::long_runs(size.long_run_end)?;
    long_run::write_long_runs(out, &long, size.long_run_end)?;
    let planner = planner_speed::measure_all(size.planner_rounds, size.race_rounds)?;
    planner_speed::write_all(out, &planner)?;
    batches(size, out)?;
    receding_horizon::write(out)?;
    sphere_cubic::run(out, size.planner_rounds)?;
    let expansions = expansion_cost::expansions(size.expansion_rounds)?;
    expansion_cost::write_expansions(out, &expansions, size.expansion_rounds)?;
    let chains = expansion_cost::chain_expansions(size.expansion_rounds)?;
    expansion_cost::write_chain_expansions(out, &chains)?;
    let seconds = started.elapsed().as_secs_f64();
    writeln!(out, "\nreport: {seconds:.1} s")?;
    Ok(Summary {
        at_target,
        planner,
        seconds,
    })
}

/// The plans-across-cores part of [`run`] alone ([`batch_speed`]): the one-disc and the
/// swing-up batches, each of `size.batch.0` plans per thread of the largest pool.
///
/// # Errors
/// A plan that is not certified ([`Error::Plan`]) or [`Error::Io`].
pub fn batches(size: &Size, out: &mut dyn Write) -> Result<(), Error> {
    let (per_thread, rounds) = size.batch;
    let plans = per_thread * batch_speed::thread_counts();
    let batches = [
        batch_speed::one_disc(plans, rounds)?,
        batch_speed::swing_up(plans, rounds)?,
    ];
    batch_speed::write_batches(out, &batches)
}

/// The work-precision part of [`run`]: the reference, the sweeps, the times at 1e-8.
///
/// # Errors
/// A failed reference run or [`Error::Io`].
fn work_precision_part(
    size: &Size,
    out: &mut dyn Write,
) -> Result<work_precision::AtTarget, Error> {
    let ivp = work_precision::Ivp::paper();
    let (reference, distance) = work_precision::reference(&ivp)?;
    writeln!(
        out,
        "\nObstacle IVP to T = 4; reference: order-8 composition, 4000 steps (its distance to \
         DOP853 at tol 1e-14: {distance:.1e}); wall time best of {} interleaved rounds:\n",
        size.sweep_rounds
    )?;
    let sweeps = work_precision::sweeps(
        &ivp,
        &work_precision::series()?,
        &reference,
        size.sweep_rounds,
    );
    work_precision::write_sweeps(out, &sweeps)?;
    let at = work_precision::at_target(&sweeps, 1e-8);
    work_precision::write_at_target(out, &at, size.sweep_rounds)?;
    Ok(at)
}

/// `# retract speed report, <YYYY-MM-DD> UTC, <machine>` with the size (full or quick).
pub fn header(size: &Size) -> String {
    let kind = if *size == Size::full() {
        "full"
    } else {
        "quick"
    };
    format!(
        "# retract speed report, {} UTC, {} ({kind})",
        utc_date(SystemTime::now()),
        machine()
    )
}

/// The UTC date of `time` as YYYY-MM-DD ("unknown date" before 1970).
pub fn utc_date(time: SystemTime) -> String {
    let Ok(since) = time.duration_since(UNIX_EPOCH) else {
        return "unknown date".into();
    };
    let days = (since.as_secs() / 86_400) as i64;
    // Howard Hinnant's civil_from_days
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}")
}

/// The CPU model (from /proc/cpuinfo, else "unknown CPU"), the number of threads the
/// process may use and, where /proc/loadavg is readable, the one-minute load average.
pub fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, model)| model.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let threads = std::thread::available_parallelism().map_or(0, |n| n.get());
    // the one-minute load average at the start: other work beside the report slows it
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|l| l.split_whitespace().next().map(str::to_string))
        .map_or_else(String::new, |l| format!(", load {l}"));
    format!("{model}, {threads} threads{load}")
}

/// The line that opens the block of a markdown file that [`write_block`] replaces.
pub const BLOCK_BEGIN: &str =
    "<!-- report:begin (written by the speed report; edits here are overwritten) -->";
/// The line that closes that block.
pub const BLOCK_END: &str = "<!-- report:end -->";

/// `document` with the lines between [`BLOCK_BEGIN`] and [`BLOCK_END`] replaced by `report`
/// (the markers kept), or `None` if the document lacks either marker or has them out of order.
pub fn replace_block(document: &str, report: &str) -> Option<String> {
    let begin = document.find(BLOCK_BEGIN)? + BLOCK_BEGIN.len();
    let end = begin + document[begin..].find(BLOCK_END)?;
    Some(format!(
        "{}\n\n{}\n\n{}",
        &document[..begin],
        report.trim(),
        &document[end..]
    ))
}

/// `report` with its markdown headings two levels lower (`#` -> `###`), to sit under a
/// section of a page.
pub fn demoted(report: &str) -> String {
    report
        .lines()
        .map(|line| {
            if line.starts_with('#') {
                format!("##{line}")
            } else {
                line.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Writes `report`, its headings [`demoted`], into the file at `path` between its markers
/// ([`replace_block`]).
///
/// # Errors
/// [`Error::Io`] if the file cannot be read or written, or lacks the markers.
pub fn write_block(path: &std::path::Path, report: &str) -> Result<(), Error> {
    let document = std::fs::read_to_string(path)?;
    let Some(updated) = replace_block(&document, &demoted(report)) else {
        return Err(Error::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "{} lacks the lines `{BLOCK_BEGIN}` and `{BLOCK_END}` (in this order) that \
                 mark the report's block",
                path.display()
            ),
        )));
    };
    std::fs::write(path, updated)?;
    Ok(())
}
