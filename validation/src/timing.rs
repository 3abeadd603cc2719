//! Timing: closures run in interleaved rounds (each round runs every closure once, in an
//! order that alternates from round to round), so that a change of the machine's speed during
//! a measurement hits all alike; the figure of each is the best or the median over the rounds.

use std::io::Write;
use std::time::Instant;

/// The per-call times (ns) of one closure over the rounds of [`interleaved`].
#[derive(Clone, Debug, Default)]
pub struct Samples(pub Vec<f64>);

impl Samples {
    /// The shortest time.
    pub fn best(&self) -> f64 {
        self.0.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The median time (NaN without samples).
    pub fn median(&self) -> f64 {
        let mut sorted = self.0.clone();
        sorted.sort_by(f64::total_cmp);
        match sorted.len() {
            0 => f64::NAN,
            n if n % 2 == 1 => sorted[n / 2],
            n => 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]),
        }
    }
}

/// A named closure to time and how many calls make one sample of it.
pub struct Timed<'a> {
    /// What it does, for the tables.
    pub name: &'static str,
    /// Calls per sample (the time per call is the sample's time over this).
    pub calls: usize,
    /// The work.
    pub run: &'a mut dyn FnMut(),
}

impl<'a> Timed<'a> {
    /// `calls` calls of `run` per sample, named `name`.
    pub fn new(name: &'static str, calls: usize, run: &'a mut dyn FnMut()) -> Self {
        Self { name, calls, run }
    }
}

/// The median over the rounds of `a`'s time over `b`'s in the same round, for two closures
/// timed in the same [`interleaved`] rounds (a slower machine in some rounds cancels); the
/// ratio of the best times if the samples do not pair up.
pub fn paired_ratio(a: &Samples, b: &Samples) -> f64 {
    if a.0.is_empty() || a.0.len() != b.0.len() {
        return a.best() / b.best();
    }
    Samples(a.0.iter().zip(&b.0).map(|(a, b)| a / b).collect()).median()
}

/// A timed closure's name and its per-call times (ns).
#[derive(Clone, Debug)]
pub struct Row {
    /// What was timed.
    pub name: &'static str,
    /// Its per-call times over the rounds.
    pub samples: Samples,
}

/// The best time (ns) of the row named `name` (NaN if absent).
pub fn best_of(rows: &[Row], name: &str) -> f64 {
    rows.iter()
        .find(|r| r.name == name)
        .map_or(f64::NAN, |r| r.samples.best())
}

/// Time per call (ns) of each closure over `rounds` rounds; in each round every closure runs
/// `calls` times in a row, the closures in turn, forwards in even rounds and backwards in odd
/// ones.
pub fn interleaved(rounds: usize, closures: &mut [Timed<'_>]) -> Vec<Row> {
    let mut samples = vec![Samples::default(); closures.len()];
    let count = closures.len();
    for round in 0..rounds {
        for turn in 0..count {
            let i = if round % 2 == 0 {
                turn
            } else {
                count - 1 - turn
            };
            let timed = &mut closures[i];
            let calls = timed.calls.max(1);
            let start = Instant::now();
            for _ in 0..calls {
                (timed.run)();
            }
            samples[i]
                .0
                .push(start.elapsed().as_nanos() as f64 / calls as f64);
        }
    }
    closures
        .iter()
        .zip(samples)
        .map(|(timed, samples)| Row {
            name: timed.name,
            samples,
        })
        .collect()
}

/// Writes the head of a markdown table: `| a | b | ... |` and its rule `|---|---|...`.
///
/// # Errors
/// The writer's.
pub fn write_head(out: &mut dyn Write, columns: &[&str]) -> std::io::Result<()> {
    writeln!(out, "| {} |", columns.join(" | "))?;
    writeln!(out, "|{}", "---|".repeat(columns.len()))
}

/// Writes `rows` as a markdown table headed `| <what> | time |`, best times.
///
/// # Errors
/// The writer's.
pub fn write_rows(out: &mut dyn Write, what: &str, rows: &[Row]) -> std::io::Result<()> {
    write_head(out, &[what, "time"])?;
    for row in rows {
        writeln!(out, "| {} | {} |", row.name, format_ns(row.samples.best()))?;
    }
    Ok(())
}

/// A time in ns as "77 ns", "3.6 µs", "655 µs" or "1.43 ms".
pub fn format_ns(ns: f64) -> String {
    if ns < 1e3 {
        format!("{ns:.0} ns")
    } else if ns < 1e5 {
        format!("{:.1} µs", ns / 1e3)
    } else if ns < 1e6 {
        format!("{:.0} µs", ns / 1e3)
    } else {
        format!("{:.2} ms", ns / 1e6)
    }
}

/// Best time per call (ns) over `batches` batches of `calls` calls of `f`.
pub fn best_ns(batches: usize, calls: usize, mut f: impl FnMut()) -> f64 {
    interleaved(batches, &mut [Timed::new("", calls, &mut f)])[0]
        .samples
        .best()
}
