//! Energy over a long horizon: the bounded Pais-Uhlenbeck oscillator (MATH.md; w1 = 1,
//! w2 = sqrt 2, eps = -0.05) over steps of h = 0.1 to `t_end` (10^5 in the figure of
//! `docs/benchmarks.md`): max |H - H(0)| so far against time for the midpoint rule, the
//! order-4 composition at 3h (the same number of implicit solves), RK4 (on `retract`'s vector
//! field) and DOP853 with their step size or tolerance chosen to cost about as much as the
//! midpoint run. One run each (the runs are long; matched cost is what matters).

use std::io::Write;
use std::time::Instant;

use retract::compose::compose;
use retract::diagnostics::rk4_step;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, ReducedStepper, StepOptions};

use crate::Error;
use crate::peers::{Hamilton, dop853};
use crate::systems::{PaisUhlenbeck, bounded_pais_uhlenbeck};

/// One method's long run.
#[derive(Clone, Debug)]
pub struct LongRun {
    /// The method.
    pub name: &'static str,
    /// Its step size or tolerance.
    pub detail: String,
    /// Its number of steps.
    pub steps: usize,
    /// Its wall time in seconds.
    pub time: f64,
    /// (t, max |H - H(0)| up to t), sampled at t = 10^(k/4).
    pub record: Vec<(f64, f64)>,
}

impl LongRun {
    /// The energy error so far at the last sample at or before `t`.
    pub fn at(&self, t: f64) -> f64 {
        self.record
            .iter()
            .rfind(|p| p.0 <= t * 1.001)
            .map_or(0.0, |p| p.1)
    }
}

/// The record of max |H - H(0)| so far, sampled at t = 10^(k/4), over the states `(t, z)`.
fn record_energy(
    system: &PaisUhlenbeck,
    states: impl IntoIterator<Item = Result<(f64, SVector<f64, 8>), retract::Error>>,
    h0: f64,
) -> Result<Vec<(f64, f64)>, retract::Error> {
    let mut worst: f64 = 1e-17;
    let mut record = Vec::new();
    let mut next_sample = 1.0;
    for state in states {
        let (t, z) = state?;
        worst = worst.max((system.hamiltonian(&z)? - h0).abs());
        if t >= next_sample {
            record.push((t, worst));
            next_sample *= 10f64.powf(0.25);
        }
    }
    Ok(record)
}

/// `steps` steps of `advance` from `z0` with step `h`: the wall time (seconds, energy
/// evaluations included) and the energy record.
fn energy_run(
    system: &PaisUhlenbeck,
    z0: &SVector<f64, 8>,
    h: f64,
    steps: usize,
    mut advance: impl FnMut(&SVector<f64, 8>) -> Result<SVector<f64, 8>, retract::Error>,
) -> Result<(f64, Vec<(f64, f64)>), retract::Error> {
    let h0 = system.hamiltonian(z0)?;
    let started = Instant::now();
    let mut z = *z0;
    let states = (1..=steps).map(|i| {
        z = advance(&z)?;
        Ok((i as f64 * h, z))
    });
    let record = record_energy(system, states, h0)?;
    Ok((started.elapsed().as_secs_f64(), record))
}

/// The four long runs to `t_end` (module docs).
///
/// # Errors
/// A failed step or DOP853 run.
pub fn long_runs(t_end: f64) -> Result<Vec<LongRun>, Error> {
    let (system, z0) = bounded_pais_uhlenbeck();
    let options = StepOptions::default();
    let mut runs = Vec::new();
    let mut stepper = ReducedStepper::new(&system);
    let h = 0.1;
    let steps = (t_end / h) as usize;
    let (midpoint_time, record) = energy_run(&system, &z0, h, steps, |z| {
        Ok(stepper.step(z, h, &options)?.0)
    })?;
    runs.push(LongRun {
        name: "midpoint",
        detail: format!("h = {h}"),
        steps,
        time: midpoint_time,
        record,
    });
    let h4 = 3.0 * h;
    let n4 = (t_end / h4) as usize;
    let (time, record) = energy_run(&system, &z0, h4, n4, |z| {
        Ok(compose(|z, s| stepper.step(z, s, &options), z, h4, 4)?.0)
    })?;
    runs.push(LongRun {
        name: "composition, order 4",
        detail: format!("h = {h4:.1}"),
        steps: n4,
        time,
        record,
    });
    // RK4: a step costs less than an implicit one; use the step count that costs the same
    // the probe: best of three runs of a fiftieth of the midpoint's steps (the first is slow)
    let probe = (steps / 50).max(1);
    let mut rk_probe = f64::INFINITY;
    for _ in 0..3 {
        let (time, _) = energy_run(&system, &z0, h, probe, |z| rk4_step(&system, z, h))?;
        rk_probe = rk_probe.min(time);
    }
    let rk_steps = ((probe as f64 * midpoint_time / rk_probe).min(1e7) as usize).max(1);
    let h_rk = t_end / rk_steps as f64;
    let (time, record) = energy_run(&system, &z0, h_rk, rk_steps, |z| rk4_step(&system, z, h_rk))?;
    runs.push(LongRun {
        name: "RK4",
        detail: format!("h = {h_rk:.3}"),
        steps: rk_steps,
        time,
        record,
    });
    runs.push(dop853_matched(&system, &z0, t_end, midpoint_time)?);
    Ok(runs)
}

/// DOP853 with the tolerance (of 1e-6, 1e-8, 1e-10, 1e-12) whose run costs closest to
/// `matched` seconds (on a log scale), and its energy record.
///
/// # Errors
/// A failed DOP853 run or energy evaluation.
fn dop853_matched(
    system: &PaisUhlenbeck,
    z0: &SVector<f64, 8>,
    t_end: f64,
    matched: f64,
) -> Result<LongRun, Error> {
    let mut best: Option<(f64, f64)> = None;
    for tol in [1e-6, 1e-8, 1e-10, 1e-12] {
        let started = Instant::now();
        dop853(Hamilton::<_, 10>(system), z0, t_end, tol, t_end)?;
        let time = started.elapsed().as_secs_f64();
        let distance = |t: f64| (t.ln() - matched.ln()).abs();
        if best.is_none_or(|(_, t)| distance(time) < distance(t)) {
            best = Some((tol, time));
        }
    }
    let tol = best.map_or(1e-6, |(tol, _)| tol);
    let started = Instant::now();
    let run = dop853(Hamilton::<_, 10>(system), z0, t_end, tol, t_end)?;
    let time = started.elapsed().as_secs_f64();
    let h0 = system.hamiltonian(z0)?;
    let record = record_energy(system, run.states.iter().map(|&s| Ok(s)), h0)?;
    Ok(LongRun {
        name: "DOP853 (adaptive)",
        detail: format!("tol {tol:.0e}"),
        steps: run.accepted_steps as usize,
        time,
        record,
    })
}

/// Writes the long runs as a markdown table.
///
/// # Errors
/// [`Error::Io`].
pub fn write_long_runs(out: &mut dyn Write, runs: &[LongRun], t_end: f64) -> Result<(), Error> {
    writeln!(
        out,
        "\nPais-Uhlenbeck, T = {t_end:.0e}: energy error at matched cost (one run each)\n"
    )?;
    writeln!(
        out,
        "| method | step size / tol | steps | wall time | max abs(H - H0) at T = 1e3 | at T = \
         {t_end:.0e} |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    for run in runs {
        writeln!(
            out,
            "| {} | {} | {} | {:.3} s | {:.2e} | {:.2e} |",
            run.name,
            run.detail,
            run.steps,
            run.time,
            run.at(1e3),
            run.at(t_end)
        )?;
    }
    Ok(())
}
