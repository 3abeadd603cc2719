//! Speed against error on the paper's obstacle IVP (SE(2), tau = 1e-2,
//! q(0) = (-2, 1.05, 0), q'(0) = (1, 0, 0.5), T = 4): final error against a tight reference
//! versus wall time for the midpoint rule and its compositions of order 4, 6, 8 (all on the
//! generated reduced step), the explicit splitting methods (`retract::split_stepper`):
//! Strang's splitting and its compositions of order 4, 6, 8 with fused free flows (and the
//! order-6 one as per-stage `split::split_step` calls, the form before), Blanes and Moan's RKN
//! methods SRKN6b (order 4), SRKN11b and SRKN14a (order 6), and SRKN14a without the
//! singularity guard; and classical RK4 and adaptive DOP853 (ode_solvers) on the plain
//! first-order system y' = (q', q'', q''', -grad V) (their best form, no checks,
//! [`crate::peers::Plain`]).
//!
//! Every point of every sweep is timed in the same interleaved rounds ([`crate::timing`]);
//! its time is the best over the rounds. [`write_at_target`] prints the lines
//! `work-precision 1e-8: best=<method> <t> us, DOP853 <t> us, ratio <best/DOP853>` (over the
//! `retract` methods with the guard on) and `work-precision 1e-8 without the guard: ...`.

use std::hint::black_box;
use std::io::Write;

use retract::compose::compose;
use retract::split::split_step;
use retract::split_methods::SplittingMethod;
use retract::split_stepper::SplitStepper;
use retract::{LiftedSystem, ReducedStepper, StepOptions};

use crate::Error;
use crate::peers::{Plain, dop853};
use crate::systems::{RigidBody, TAU, Z, paper_jet, paper_system};
use crate::timing::{Timed, interleaved};

/// How a sweep integrates.
#[derive(Clone, Debug)]
pub enum Method {
    /// The midpoint rule (order 2) or its composition of `order` on the reduced stepper.
    Composed(u32),
    /// Strang's splitting composed to `order`, each stage a full `split_step` call.
    SplitPerStage(u32),
    /// A splitting method on the `SplitStepper`, the guard on or off.
    Split(Box<SplittingMethod>, bool),
    /// RK4 on the plain first-order system.
    Rk4,
    /// DOP853 on the plain first-order system; the points are tolerances.
    Dop853,
}

impl Method {
    /// [`Method::Split`] with `method`, the guard on or off.
    pub fn split(method: SplittingMethod, guard: bool) -> Self {
        Method::Split(Box::new(method), guard)
    }

    /// Whether this is a `retract` method with the singularity guard on (the best of these is
    /// compared with DOP853).
    pub fn guarded(&self) -> bool {
        match self {
            Method::Composed(_) | Method::SplitPerStage(_) => true,
            Method::Split(_, guard) => *guard,
            Method::Rk4 | Method::Dop853 => false,
        }
    }
}

/// One method's sweep: its label, method and points (step counts, or tolerances for DOP853).
#[derive(Clone, Debug)]
pub struct Series {
    /// The label in the tables and the figure.
    pub label: &'static str,
    /// The method.
    pub method: Method,
    /// Step counts, or tolerances for [`Method::Dop853`].
    pub points: Vec<f64>,
}

/// The sweeps of the comparison, in the order of the tables.
///
/// # Errors
/// [`Error::Retract`] if a composition's coefficients are missing.
pub fn series() -> Result<Vec<Series>, Error> {
    let steps = |n: &[usize]| n.iter().map(|&n| n as f64).collect::<Vec<_>>();
    let composition = SplittingMethod::composition;
    let s = |label, method, points: &[usize]| Series {
        label,
        method,
        points: steps(points),
    };
    Ok(vec![
        s(
            "midpoint",
            Method::Composed(2),
            &[100, 200, 400, 800, 1600, 3200, 6400],
        ),
        s(
            "composition, order 4",
            Method::Composed(4),
            &[20, 40, 80, 160, 320, 640],
        ),
        s(
            "composition, order 6",
            Method::Composed(6),
            &[10, 20, 40, 80, 160],
        ),
        s(
            "composition, order 8",
            Method::Composed(8),
            &[5, 10, 20, 40, 80],
        ),
        s(
            "splitting, order 6, per-stage steps",
            Method::SplitPerStage(6),
            &[20, 40, 80, 160, 320],
        ),
        s(
            "splitting",
            Method::split(composition(2)?, true),
            &[200, 400, 800, 1600, 3200, 6400, 12800],
        ),
        s(
            "splitting, order 4",
            Method::split(composition(4)?, true),
            &[40, 80, 160, 320, 640, 1280],
        ),
        s(
            "splitting, order 6",
            Method::split(composition(6)?, true),
            &[20, 40, 80, 160, 320],
        ),
        s(
            "splitting, order 8",
            Method::split(composition(8)?, true),
            &[10, 20, 40, 80, 160],
        ),
        s(
            "splitting, BM SRKN6b",
            Method::split(SplittingMethod::blanes_moan_4(), true),
            &[20, 40, 80, 160, 320, 640],
        ),
        s(
            "splitting, BM SRKN11b",
            Method::split(SplittingMethod::blanes_moan_6(), true),
            &[10, 20, 40, 80, 160],
        ),
        s(
            "splitting, BM SRKN14a",
            Method::split(SplittingMethod::blanes_moan_6a(), true),
            &[10, 20, 40, 80, 160],
        ),
        // the peers check nothing: the best splitting without the singularity guard, for scale
        s(
            "BM SRKN14a, guard off",
            Method::split(SplittingMethod::blanes_moan_6a(), false),
            &[10, 20, 40, 80],
        ),
        s("RK4", Method::Rk4, &[100, 200, 400, 800, 1600, 3200]),
        Series {
            label: "DOP853",
            method: Method::Dop853,
            points: vec![1e-4, 1e-6, 1e-8, 1e-10, 1e-12],
        },
    ])
}

/// The obstacle IVP: the system, its plain form, the initial jet and state, the horizon.
pub struct Ivp {
    /// The generated system.
    pub system: RigidBody,
    /// The peers' plain first-order system.
    pub plain: Plain,
    /// The initial jet (q, q', q'', q''').
    pub jet: Z,
    /// The initial state (its Legendre map).
    pub z0: Z,
    /// The horizon.
    pub t_end: f64,
}

impl Ivp {
    /// The paper's obstacle IVP to T = 4.
    pub fn paper() -> Self {
        let system = paper_system();
        let jet = paper_jet();
        Self {
            system,
            plain: Plain { tau: TAU, r: 1.0 },
            jet,
            z0: system.legendre(&jet),
            t_end: 4.0,
        }
    }

    /// The final state (x, p) of `method` at `point` (a step count, or DOP853's tolerance).
    ///
    /// # Errors
    /// A step that fails; DOP853's failure.
    pub fn run(&self, method: &Method, point: f64) -> Result<Z, Error> {
        let (system, t_end) = (&self.system, self.t_end);
        let steps = point as usize;
        let h = t_end / steps as f64;
        let options = StepOptions::default();
        Ok(match method {
            &Method::Composed(order) => {
                let mut stepper = ReducedStepper::new(system);
                repeat(&self.z0, steps, |z| {
                    Ok(compose(|z, h| stepper.step(z, h, &options), z, h, order)?.0)
                })?
            }
            &Method::SplitPerStage(order) => repeat(&self.z0, steps, |z| {
                Ok(compose(|z, h| split_step(system, z, h, &options), z, h, order)?.0)
            })?,
            Method::Split(method, guard) => {
                let options = options.with_domain_check(*guard);
                let mut stepper = SplitStepper::<_, 3, 2, 12>::new(system, **method)?;
                repeat(&self.z0, steps, |z| Ok(stepper.step(z, h, &options)?.0))?
            }
            Method::Rk4 => system.legendre(&self.plain.rk4(&self.jet, t_end, steps)),
            Method::Dop853 => {
                let run = dop853(self.plain, &self.jet, t_end, point, t_end)?;
                system.legendre(&run.end()?)
            }
        })
    }
}

/// `steps` steps of `step` from `z0`.
fn repeat(
    z0: &Z,
    steps: usize,
    mut step: impl FnMut(&Z) -> Result<Z, retract::Error>,
) -> Result<Z, retract::Error> {
    (0..steps).try_fold(*z0, |z, _| step(&z))
}

/// One point of a sweep: its step count or tolerance, and its final error and best time, or
/// why it stopped.
#[derive(Clone, Debug)]
pub struct SweepPoint {
    /// Steps, or "tol 1e-8".
    pub label: String,
    /// (final error, best wall time in seconds), or the error that stopped the run.
    pub outcome: Result<(f64, f64), String>,
}

/// A method's sweep as measured.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The method's label.
    pub label: &'static str,
    /// Whether it is a `retract` method with the guard on.
    pub guarded: bool,
    /// Its points.
    pub points: Vec<SweepPoint>,
}

impl Sweep {
    /// The (wall time in seconds, final error) of the points that ran, errors floored at
    /// 1e-16 (for a log scale).
    pub fn curve(&self) -> Vec<(f64, f64)> {
        self.points
            .iter()
            .filter_map(|p| p.outcome.as_ref().ok())
            .map(|&(error, time)| (time, error.max(1e-16)))
            .collect()
    }
}

/// The final error against `reference` of every point of every series, then their times in
/// `rounds` interleaved rounds (every point once a round), best of the rounds. A run that
/// fails is kept as a stopped point, with its error.
pub fn sweeps(ivp: &Ivp, all: &[Series], reference: &Z, rounds: usize) -> Vec<Sweep> {
    let mut out: Vec<Sweep> = Vec::new();
    let mut jobs: Vec<(usize, usize, f64)> = Vec::new();
    for (s, series) in all.iter().enumerate() {
        let mut points = Vec::new();
        for &point in &series.points {
            let label = match series.method {
                Method::Dop853 => format!("tol {point:.0e}"),
                _ => format!("{point}"),
            };
            let outcome = match ivp.run(&series.method, point) {
                Ok(end) => {
                    jobs.push((s, points.len(), point));
                    Ok(((end - reference).amax(), f64::NAN))
                }
                Err(e) => Err(e.to_string()),
            };
            points.push(SweepPoint { label, outcome });
        }
        out.push(Sweep {
            label: series.label,
            guarded: series.method.guarded(),
            points,
        });
    }
    let mut runs: Vec<Box<dyn FnMut() + '_>> = jobs
        .iter()
        .map(|&(s, _, point)| {
            let method = &all[s].method;
            Box::new(move || {
                black_box(ivp.run(method, point).ok());
            }) as Box<dyn FnMut()>
        })
        .collect();
    let mut timed: Vec<Timed<'_>> = runs
        .iter_mut()
        .zip(&jobs)
        .map(|(f, &(s, _, _))| Timed::new(all[s].label, 1, &mut **f))
        .collect();
    let rows = interleaved(rounds.max(1), &mut timed);
    for (&(s, p, _), row) in jobs.iter().zip(rows) {
        if let Ok((_, time)) = &mut out[s].points[p].outcome {
            *time = row.samples.best() * 1e-9;
        }
    }
    out
}

/// The order-8 composition with 4000 steps (the reference) and its distance to DOP853 at
/// tolerance 1e-14.
///
/// # Errors
/// A failed step or DOP853 run.
pub fn reference(ivp: &Ivp) -> Result<(Z, f64), Error> {
    let reference = ivp.run(&Method::Composed(8), 4000.0)?;
    let dop = ivp.run(&Method::Dop853, 1e-14)?;
    Ok((reference, (reference - dop).amax()))
}

/// Writes every point of every sweep as a markdown table.
///
/// # Errors
/// [`Error::Io`].
pub fn write_sweeps(out: &mut dyn Write, sweeps: &[Sweep]) -> Result<(), Error> {
    writeln!(out, "| method | steps / tol | final error | wall time |")?;
    writeln!(out, "|---|---|---|---|")?;
    for sweep in sweeps {
        for point in &sweep.points {
            match &point.outcome {
                Ok((error, time)) => writeln!(
                    out,
                    "| {} | {} | {error:.2e} | {:.1} us |",
                    sweep.label,
                    point.label,
                    time * 1e6
                )?,
                Err(e) => writeln!(
                    out,
                    "| {} | {} | stopped: {e} | - |",
                    sweep.label, point.label
                )?,
            }
        }
    }
    Ok(())
}

/// The figures at a final error of 1e-8.
#[derive(Clone, Debug)]
pub struct AtTarget {
    /// Each method that reaches the target within its sweep and its time there (seconds).
    pub times: Vec<(&'static str, f64)>,
    /// The fastest guarded `retract` method and its time.
    pub best: Option<(&'static str, f64)>,
    /// DOP853's time.
    pub dop853: Option<f64>,
    /// The unguarded splitting and its time.
    pub unguarded: Option<(&'static str, f64)>,
}

/// The wall time of every sweep at a final error of `target`, the best guarded `retract`
/// method, DOP853 and the unguarded splitting.
pub fn at_target(sweeps: &[Sweep], target: f64) -> AtTarget {
    let at: Vec<(&'static str, bool, f64)> = sweeps
        .iter()
        .filter_map(|s| time_at_error(&s.curve(), target).map(|t| (s.label, s.guarded, t)))
        .collect();
    let find = |f: &dyn Fn(&str, bool) -> bool| {
        at.iter()
            .filter(|(label, guarded, _)| f(label, *guarded))
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .map(|&(label, _, t)| (label, t))
    };
    AtTarget {
        times: at.iter().map(|&(label, _, t)| (label, t)).collect(),
        best: find(&|_, guarded| guarded),
        dop853: find(&|label, _| label == "DOP853").map(|(_, t)| t),
        unguarded: find(&|label, _| label.ends_with("guard off")),
    }
}

/// Writes the table of wall times at 1e-8 and the lines
/// `work-precision 1e-8: best=<method> <t> us, DOP853 <t> us, ratio <best/DOP853>` and
/// `work-precision 1e-8 without the guard: <method> <t> us, ratio <t/DOP853>`.
///
/// # Errors
/// [`Error::Io`].
pub fn write_at_target(out: &mut dyn Write, at: &AtTarget, rounds: usize) -> Result<(), Error> {
    writeln!(
        out,
        "\nWall time at a final error of 1e-8 (log-log interpolation between sweep points; each \
         point best of {rounds} interleaved rounds):\n"
    )?;
    writeln!(out, "| method | at 1e-8 |")?;
    writeln!(out, "|---|---|")?;
    for (label, time) in &at.times {
        writeln!(out, "| {label} | {:.1} µs |", time * 1e6)?;
    }
    writeln!(out)?;
    if let (Some(dop), Some((label, best))) = (at.dop853, at.best) {
        writeln!(
            out,
            "work-precision 1e-8: best={label} {:.1} us, DOP853 {:.1} us, ratio {:.2}",
            best * 1e6,
            dop * 1e6,
            best / dop
        )?;
    }
    if let (Some(dop), Some((label, time))) = (at.dop853, at.unguarded) {
        writeln!(
            out,
            "work-precision 1e-8 without the guard: {label} {:.1} us, ratio {:.2}",
            time * 1e6,
            time / dop
        )?;
    }
    Ok(())
}

/// The wall time at which a sweep of (time, error) points reaches `target`, interpolating
/// log error against log time between the two points that bracket it.
pub fn time_at_error(points: &[(f64, f64)], target: f64) -> Option<f64> {
    points.windows(2).find_map(|pair| {
        let ((t0, e0), (t1, e1)) = (pair[0], pair[1]);
        (e0 >= target && e1 <= target && e0 > e1).then(|| {
            let s = (e0 / target).ln() / (e0 / e1).ln();
            (t0.ln() + s * (t1 / t0).ln()).exp()
        })
    })
}
