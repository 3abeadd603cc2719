//! Plans across cores: `retract::bvp::solve_batch` on rayon pools of 1, 2, ... threads up to
//! the machine's cores, for two batches:
//!
//! - `one-disc`: the one-disc scene of `../shared/BENCHMARKS.md` (N = 400, from the guess
//!   bumped above the disc) from starts moved up by 0.01 each (16 distinct starts, repeated);
//! - `swing-up`: the double pendulum of the swing-up suite (T = 2, N = 200, from the
//!   smoothstep) to goals $(\pi + \delta, 0)$, $\delta$ in steps of 0.01 (16 distinct goals,
//!   repeated).
//!
//! Every plan must be certified. Each thread count is timed in interleaved rounds
//! ([`crate::timing::interleaved`], one batch a sample); the figure is plans per second at the
//! best round, and the scaling is that over the one-thread figure of the same rounds.

use std::io::Write;

use retract::bvp::{Curve, OptimalControlProblem, PlanGuess, solve_batch};

use crate::Error;
use crate::models::{DISC_GOAL, DISC_START, DoublePendulum, OneDisc};
use crate::timing::{Timed, interleaved};

/// The names of the timed thread counts (at most 16 threads are measured).
const THREADS: [&str; 16] = [
    "1", "2", "3", "4", "5", "6", "7", "8", "9", "10", "11", "12", "13", "14", "15", "16",
];

/// The distinct problems of a batch: plan `i` is the `i mod DISTINCT`-th (a batch for many
/// threads repeats them rather than moving its starts or goals ever further).
const DISTINCT: usize = 16;

/// One batch's figures: plans per second for 1, 2, ... threads.
#[derive(Clone, Debug)]
pub struct BatchSpeed {
    /// The batch's name (`one-disc`, `swing-up`).
    pub name: &'static str,
    /// Plans per second at 1, 2, ... threads (the best round).
    pub plans_per_s: Vec<f64>,
}

impl BatchSpeed {
    /// Plans per second at `t + 1` threads over that at one thread.
    pub fn scaling(&self, t: usize) -> f64 {
        self.plans_per_s[t] / self.plans_per_s[0]
    }
}

/// The thread counts measured: 1 up to the machine's cores (at most 16).
pub fn thread_counts() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get().min(THREADS.len()))
}

/// Times `solve` (one whole batch of `plans` plans, checked certified by its caller) on pools
/// of every thread count, `rounds` interleaved rounds.
fn per_thread_count(
    name: &'static str,
    plans: usize,
    rounds: usize,
    solve: &(dyn Fn() + Sync),
) -> Result<BatchSpeed, Error> {
    let pools = (1..=thread_counts())
        .map(|t| rayon::ThreadPoolBuilder::new().num_threads(t).build())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| Error::Plan(format!("a thread pool could not be built: {e}")))?;
    let mut runs: Vec<Box<dyn FnMut() + '_>> = (pools.iter())
        .map(|pool| Box::new(move || pool.install(solve)) as Box<dyn FnMut()>)
        .collect();
    let mut timed: Vec<Timed<'_>> = (runs.iter_mut().zip(THREADS))
        .map(|(run, name)| Timed::new(name, 1, run.as_mut()))
        .collect();
    let rows = interleaved(rounds, &mut timed);
    let plans_per_s = rows
        .iter()
        .map(|row| plans as f64 / (row.samples.best() * 1e-9))
        .collect();
    Ok(BatchSpeed { name, plans_per_s })
}

/// The one-disc batch of `plans` starts.
///
/// # Errors
/// [`Error::Plan`] if a plan of the batch is not certified.
pub fn one_disc(plans: usize, rounds: usize) -> Result<BatchSpeed, Error> {
    let system = OneDisc { tau: 1e-2 };
    let above = Curve::from_fn(|t| {
        let s = t / 4.0;
        [-2.0 + t, 0.2 + 1.3 * 16.0 * s * s * (1.0 - s) * (1.0 - s)]
    });
    let starts: Vec<[f64; 4]> = (0..plans)
        .map(|i| {
            let mut start = DISC_START;
            start[1] += 0.01 * (i % DISTINCT) as f64;
            start
        })
        .collect();
    let jobs: Vec<_> = (starts.iter())
        .map(|s| {
            let problem = OptimalControlProblem::new(&system, s, &DISC_GOAL, 4.0, 400);
            (problem, PlanGuess::Curve(&above))
        })
        .collect();
    certified("one-disc", &solve_batch(&jobs))?;
    per_thread_count("one-disc", plans, rounds, &|| {
        std::hint::black_box(solve_batch(&jobs));
    })
}

/// The swing-up batch of `plans` goals.
///
/// # Errors
/// [`Error::Plan`] if a plan of the batch is not certified.
pub fn swing_up(plans: usize, rounds: usize) -> Result<BatchSpeed, Error> {
    let system = DoublePendulum { g: 9.81 };
    let goals: Vec<[f64; 4]> = (0..plans)
        .map(|i| {
            [
                std::f64::consts::PI + 0.01 * (i % DISTINCT) as f64,
                0.0,
                0.0,
                0.0,
            ]
        })
        .collect();
    let jobs: Vec<_> = (goals.iter())
        .map(|goal| {
            let problem = OptimalControlProblem::new(&system, &[0.0; 4], goal, 2.0, 200);
            (problem, PlanGuess::Spline)
        })
        .collect();
    certified("swing-up", &solve_batch(&jobs))?;
    per_thread_count("swing-up", plans, rounds, &|| {
        std::hint::black_box(solve_batch(&jobs));
    })
}

/// [`Error::Plan`] naming the first plan of `outcomes` that is not certified.
fn certified<const N: usize, const X: usize>(
    name: &str,
    outcomes: &[retract::bvp::Outcome<N, X>],
) -> Result<(), Error> {
    match outcomes.iter().enumerate().find(|(_, o)| o.is_err()) {
        Some((i, Err(e))) => Err(Error::Plan(format!("batch {name}, plan {i}: {e}"))),
        _ => Ok(()),
    }
}

/// Writes one line per batch and thread count:
/// `batch <name> threads=<t> plans_per_s=<p> scaling=<s>`.
///
/// # Errors
/// [`Error::Io`].
pub fn write_batches(out: &mut dyn Write, batches: &[BatchSpeed]) -> Result<(), Error> {
    writeln!(
        out,
        "\n## Plans across cores\n\n`solve_batch` on rayon pools of 1..{} threads \
         (best of interleaved rounds; scaling over one thread):\n",
        thread_counts()
    )?;
    for batch in batches {
        for (t, p) in batch.plans_per_s.iter().enumerate() {
            let scaling = batch.scaling(t);
            writeln!(
                out,
                "batch {} threads={} plans_per_s={p:.1} scaling={scaling:.2}",
                batch.name,
                t + 1
            )?;
        }
    }
    Ok(())
}
