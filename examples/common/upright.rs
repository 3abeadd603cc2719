//! The receding-horizon benchmark of docs/benchmarks.md ("Receding horizon", BENCHMARKS.md
//! of the project): the double pendulum of `pendulum.rs` held upright at q = (pi, 0) by
//! re-plans of the stage cost 1/2 |tau|^2 + 50 |q - (pi, 0)|^2 + |q'|^2 ([`UprightCost`])
//! over T = 1 s, N = 50 steps, one re-plan a control period h = 0.02 s; the plant stepped with
//! the torque held; its velocity kicked at t = 0.5 s. Shared by `examples/mpc.rs` and the
//! tests (by path, beside `pendulum.rs` as the crate's `pendulum`).
//!
//! Three ways to re-plan ([`Mode`]): real-time iterations as acados' RTI
//! ([`RealTimeIteration`]: the subproblem prepared at the shifted iterate while the plant
//! moves, then, once the state is measured, its full Newton step with the state embedded,
//! one or two a period) and full solves from the shifted plan.
#![allow(dead_code)] // each user takes a subset

use std::f64::consts::PI;
use std::time::Instant;

use crate::pendulum::{HORIZON, Plant, STEPS, UprightCost, plant_step, upright_models};
use retract::LiftedSystem;
use retract::bvp::{
    Control, ControlOptions, ControlStatus, Fallback, InputSource, OptimalControlProblem, Plan,
    PlanGuess, PlanOptions, RealTimeIteration, Workspace,
};
use retract::nalgebra::SVector;

/// The upright rest state.
pub const UPRIGHT: [f64; 4] = [PI, 0.0, 0.0, 0.0];
/// The period of the kick (t = 0.5 s).
pub const KICK_PERIOD: usize = 25;
/// The periods simulated (5 s).
pub const PERIODS: usize = 250;
/// The settling threshold on |q - (pi, 0)|.
pub const SETTLED: f64 = 1e-3;

/// How the controller re-plans.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Real-time iterations: this many feedback steps a period (the first from the
    /// preparation made during the last period).
    Rti(usize),
    /// Solved to the default tolerance from the shifted plan.
    Full,
}

impl Mode {
    /// The benchmark's name of the mode.
    pub fn name(self) -> String {
        match self {
            Mode::Rti(n) => format!("rti{n}"),
            Mode::Full => "full".into(),
        }
    }
}

/// The torque of a first step at its midpoint: tau((x_0 + x_1) / 2, u_0).
pub fn first_torque(
    model: &UprightCost,
    (x0, x1): (&SVector<f64, 4>, &SVector<f64, 4>),
    u0: &SVector<f64, 2>,
) -> [f64; 2] {
    let x = (x0 + x1) * 0.5;
    let jet = [
        x.fixed_rows::<2>(0).into_owned(),
        x.fixed_rows::<2>(2).into_owned(),
    ];
    model.tau(&jet, u0)
}

/// A receding-horizon controller of the benchmark: one problem, its real-time iteration and
/// the last full plan, in one workspace. Every period says how its input was chosen (the
/// library's [`ControlStatus`]): a re-plan that is not converged is never applied silently,
/// a failed one falls back to the previous plan shifted by a period, and the applied input
/// q'' is clamped to the problem's input bounds ([`Self::with_input_limit`]; none by default,
/// as in the benchmark). The torque applied is the one of that input ([`Period::tau`]).
pub struct Controller<'m> {
    model: &'m UprightCost,
    problem: OptimalControlProblem<'m, UprightCost, 2, 2, 4>,
    mode: Mode,
    options: ControlOptions,
    rti: RealTimeIteration<2, 4>,
    plan: Plan<2, 4>,
    workspace: Workspace<2, 4>,
    /// The measured jet of the last period.
    start: [f64; 4],
}

/// What one period's re-plan gave.
#[derive(Clone, Copy, Debug)]
pub struct Period {
    /// The torque to apply (finite): the plan's torque at its first step's midpoint,
    /// tau((x_0 + x_1) / 2, u_0), for an applied re-plan's unclamped input; otherwise (a
    /// clamped or fallback input, no longer consistent with the plan's jets) the torque that
    /// gives the input's accelerations at the measured jet, tau(x_measured, u).
    pub tau: [f64; 2],
    /// The input applied (q'' of the first step, within the problem's input bounds).
    pub input: SVector<f64, 2>,
    /// The chosen plan's input before clamping.
    pub planned: SVector<f64, 2>,
    /// The time from the measured state to the torque (us).
    pub feedback_us: f64,
    /// How the input was chosen.
    pub status: ControlStatus,
}

impl Period {
    /// Whether the re-plan failed (the input is the shifted plan's).
    pub fn failed(&self) -> bool {
        !self.status.replanned()
    }
}

/// The benchmark's problem: upright to upright, with |q''_a| <= `limit` when given.
fn upright_problem(
    model: &UprightCost,
    limit: Option<f64>,
) -> OptimalControlProblem<'_, UprightCost, 2, 2, 4> {
    let problem = OptimalControlProblem::new(model, &UPRIGHT, &UPRIGHT, HORIZON, STEPS);
    match limit {
        Some(a) => problem.with_input_bounds([-a; 2], [a; 2]),
        None => problem,
    }
}

impl<'m> Controller<'m> {
    /// A controller at upright rest: solved there, its real-time iteration prepared.
    ///
    /// # Errors
    /// The first solve or preparation failing.
    pub fn new(model: &'m UprightCost, mode: Mode) -> Result<Self, Box<dyn std::error::Error>> {
        Self::bounded(model, mode, None)
    }

    /// [`Self::new`] with the problem's input bounds |q''_a| <= `limit` (the re-plans' inputs
    /// clamped to them).
    ///
    /// # Errors
    /// The first solve or preparation failing.
    pub fn with_input_limit(
        model: &'m UprightCost,
        mode: Mode,
        limit: f64,
    ) -> Result<Self, Box<dyn std::error::Error>> {
        Self::bounded(model, mode, Some(limit))
    }

    fn bounded(
        model: &'m UprightCost,
        mode: Mode,
        limit: Option<f64>,
    ) -> Result<Self, Box<dyn std::error::Error>> {
        let problem = upright_problem(model, limit);
        let mut workspace = Workspace::new();
        let plan = problem.solve_with(PlanGuess::Spline, &mut workspace)?;
        let mut rti = problem.real_time_iteration(PlanGuess::Plan(&plan))?;
        problem.prepare(&mut rti)?;
        let iterations = match mode {
            Mode::Rti(n) => n,
            Mode::Full => 1,
        };
        Ok(Self {
            model,
            problem,
            mode,
            options: ControlOptions::default().with_iterations(iterations),
            rti,
            plan,
            workspace,
            start: UPRIGHT,
        })
    }

    /// The controller with a wall-time budget for each solve or preparation
    /// ([`PlanOptions::with_max_time`]; a solve that runs out of it fails and its period
    /// falls back to the shifted plan).
    pub fn with_time_budget(mut self, budget: std::time::Duration) -> Self {
        let options = PlanOptions::default().with_max_time(budget);
        self.problem = self.problem.with_options(options);
        self
    }

    /// The controller with the real-time re-plans applied only while their Newton steps are
    /// at most `step` ([`ControlOptions::max_step`]).
    pub fn with_max_step(mut self, step: f64) -> Self {
        self.options = self.options.with_max_step(step);
        self
    }

    /// The re-plan from the measured jet `jet`, up to the torque to apply.
    pub fn control(&mut self, jet: &[f64; 4]) -> Period {
        let started = Instant::now();
        self.start = *jet;
        let control = match self.mode {
            Mode::Rti(_) => self.problem.control(&mut self.rti, jet, &self.options),
            Mode::Full => self.full(jet),
        };
        let [x0, x1] = &control.x;
        let status = control.status;
        let tau = if status.replanned() && !status.clamped {
            first_torque(self.model, (x0, x1), &control.input)
        } else {
            // (the input is no longer the plan's: the torque that gives it where the plant is)
            let jet = SVector::from(*jet);
            let at = [
                jet.fixed_rows::<2>(0).into_owned(),
                jet.fixed_rows::<2>(2).into_owned(),
            ];
            self.model.tau(&at, &control.input)
        };
        Period {
            tau,
            input: control.input,
            planned: control.planned,
            feedback_us: started.elapsed().as_secs_f64() * 1e6,
            status: control.status,
        }
    }

    /// A full solve from the plan shifted by [`Self::prepare`], as a control period: the new
    /// plan's first input if it solved, else the shifted plan's; clamped to the input bounds
    /// (the status's step is 0: no Newton step is measured).
    fn full(&mut self, jet: &[f64; 4]) -> Control<2, 4> {
        self.problem.set_start(jet);
        let shifted = ([self.plan.x[0], self.plan.x[1]], self.plan.u[0]);
        let solved = (self.problem).solve_with(PlanGuess::Plan(&self.plan), &mut self.workspace);
        let (source, iterations) = match solved {
            Ok(next) => {
                let iterations = next.iterations;
                self.workspace
                    .recycle(std::mem::replace(&mut self.plan, next));
                (InputSource::Converged, iterations)
            }
            Err(_) => (InputSource::Shifted(Fallback::Failed), 0),
        };
        let first = match source {
            InputSource::Converged => ([self.plan.x[0], self.plan.x[1]], self.plan.u[0]),
            _ => shifted,
        };
        (self.problem).clamped_control(first, source, (iterations, 0.0))
    }

    /// The input q'' of the current plan's first step (between [`Self::prepare`] and
    /// [`Self::control`]: the shifted plan's, the period's fallback).
    pub fn input(&self) -> SVector<f64, 2> {
        match self.mode {
            Mode::Rti(_) => self.rti.u()[0],
            Mode::Full => self.plan.u[0],
        }
    }

    /// The torque of the current plan's first step.
    pub fn torque(&self) -> [f64; 2] {
        match self.mode {
            Mode::Rti(_) => {
                let (x, u) = (self.rti.x(), self.rti.u());
                first_torque(self.model, (&x[0], &x[1]), &u[0])
            }
            Mode::Full => {
                let (x, u) = (&self.plan.x, &self.plan.u);
                first_torque(self.model, (&x[0], &x[1]), &u[0])
            }
        }
    }

    /// The preparation for the next period: the plan shifted by a period (a plan that cannot
    /// shift is kept) and, for real-time iterations, the subproblem prepared at it; whether
    /// it failed. A failed preparation starts the real-time iteration again from the spline
    /// between the last measured jet and the goal.
    pub fn prepare(&mut self) -> bool {
        let Mode::Rti(_) = self.mode else {
            let _ = self.plan.try_shift();
            return false;
        };
        self.rti.shift();
        if self.problem.prepare(&mut self.rti).is_ok() {
            return false;
        }
        self.problem.set_start(&self.start);
        if let Ok(rti) = self.problem.real_time_iteration(PlanGuess::Spline) {
            self.rti = rti;
            let _ = self.problem.prepare(&mut self.rti);
        }
        true
    }
}

/// What a run of the benchmark measured.
pub struct Outcome {
    /// The largest |q - (pi, 0)| after the kick.
    pub max_dev: f64,
    /// The time from the kick after which |q - (pi, 0)| stays below [`SETTLED`] (infinite if
    /// it is not below at the end).
    pub settle_s: f64,
    /// Each period's re-plan time (feedback and preparation, us).
    pub replan_us: Vec<f64>,
    /// Each period's feedback time (us).
    pub feedback_us: Vec<f64>,
    /// Periods whose re-plan failed.
    pub failures: usize,
}

/// The benchmark's lines for every kick (2, 8) and mode (one and two real-time iterations a
/// period, full solves): one
/// `kick=<k> mode=<rti1|rti2|full> max_dev=<d> settle_s=<s> median_us=<m> p99_us=<p> failures=<f>`
/// per run, then for the real-time modes
/// `feedback kick=<k> mode=<rti1|rti2> median_us=<m> p99_us=<p> max_us=<x>`.
///
/// # Errors
/// A run that fails ([`run`]).
pub fn lines() -> Result<Vec<String>, Box<dyn std::error::Error>> {
    let modes = [Mode::Rti(1), Mode::Rti(2), Mode::Full];
    let (mut runs, mut feedback) = (Vec::new(), Vec::new());
    for kick in [2.0, 8.0] {
        for mode in modes {
            let out = run(kick, mode)?;
            runs.push(format!(
                "kick={kick} mode={} max_dev={:.4} settle_s={:.2} median_us={:.1} p99_us={:.1} \
                 failures={}",
                mode.name(),
                out.max_dev,
                out.settle_s,
                quantile(&out.replan_us, 0.5),
                quantile(&out.replan_us, 0.99),
                out.failures,
            ));
            if mode != Mode::Full {
                feedback.push(format!(
                    "feedback kick={kick} mode={} median_us={:.1} p99_us={:.1} max_us={:.1}",
                    mode.name(),
                    quantile(&out.feedback_us, 0.5),
                    quantile(&out.feedback_us, 0.99),
                    quantile(&out.feedback_us, 1.0),
                ));
            }
        }
    }
    runs.extend(feedback);
    Ok(runs)
}

/// The `p`-quantile (0..=1) of `times`, nearest rank.
pub fn quantile(times: &[f64], p: f64) -> f64 {
    let mut sorted = times.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
    sorted[rank - 1]
}

/// |q - (pi, 0)| of a jet.
pub fn deviation(jet: &[f64; 4]) -> f64 {
    (jet[0] - PI).hypot(jet[1])
}

/// Runs the benchmark: [`PERIODS`] periods from upright rest, the plant's velocity kicked by
/// (+kick, -kick) at [`KICK_PERIOD`] (the re-plan of that period sees it).
///
/// # Errors
/// The controller's first solve, or a plant step, failing.
pub fn run(kick: f64, mode: Mode) -> Result<Outcome, Box<dyn std::error::Error>> {
    let (model, plant): (UprightCost, Plant) = upright_models();
    let mut controller = Controller::new(&model, mode)?;
    let mut jet = UPRIGHT;
    let mut z = plant.legendre(&SVector::from(jet));
    let h = HORIZON / STEPS as f64;
    let mut out = Outcome {
        max_dev: 0.0,
        settle_s: 0.0,
        replan_us: Vec::with_capacity(PERIODS),
        feedback_us: Vec::with_capacity(PERIODS),
        failures: 0,
    };
    let mut last_unsettled = None;
    for period in 0..PERIODS {
        if period == KICK_PERIOD {
            jet[2] += kick;
            jet[3] -= kick;
            z = plant.legendre(&SVector::from(jet));
        }
        let started = Instant::now();
        let applied = controller.control(&jet);
        let prepare_failed = controller.prepare();
        out.replan_us.push(started.elapsed().as_secs_f64() * 1e6);
        out.feedback_us.push(applied.feedback_us);
        out.failures += usize::from(applied.failed() || prepare_failed);
        (z, jet) = plant_step(&plant, &z, &jet, applied.tau)?;
        if period >= KICK_PERIOD {
            let dev = deviation(&jet);
            out.max_dev = out.max_dev.max(dev);
            if dev >= SETTLED || dev.is_nan() {
                last_unsettled = Some(period);
            }
        }
    }
    out.settle_s = match last_unsettled {
        Some(p) if p + 1 == PERIODS => f64::INFINITY,
        // the state after period p is at t = (p + 1) h: settled from the next one on
        Some(p) => (p + 2 - KICK_PERIOD) as f64 * h,
        None => 0.0,
    };
    Ok(out)
}
