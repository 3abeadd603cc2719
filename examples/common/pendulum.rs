//! The double pendulum: the planner's model (minimum torque, with its torque as the named
//! output `tau`), the acrobot's cost and constraint, the plant (T - V), and receding-horizon
//! control with the plant simulated in the loop. Shared by
//! `examples/swing_up.rs`, `examples/mpc_swing_up.rs`, `examples/mpc.rs` (the receding-horizon
//! benchmark's cost, [`upright_cost`]) and `tests/planning/mpc.rs` (by path).
//!
//! Every control period h the planner re-plans from the plant's measured state (q, q') to the
//! upright equilibrium over a fixed horizon T = N h: the minimum-torque problem
//! L = 1/2 |tau|^2 on the lifted-midpoint transcription, by `ITERATIONS` real-time iterations
//! (feedback steps of the subproblem prepared at its last plan shifted by one step). The
//! plant, the mechanical Lagrangian T - V, takes one forced-midpoint step (discrete
//! Lagrange-d'Alembert) under the torque of the plan's first step at its midpoint. From the
//! hanging rest state the loop swings the pendulum up, then holds it upright.
#![allow(dead_code)] // each user takes a subset

use std::f64::consts::PI;
use std::time::Instant;

use retract::bvp::{
    Control, ControlOptions, InputSource, OptimalControlProblem, PlanGuess, RealTimeIteration,
};
use retract::forced::forced_step;
use retract::nalgebra::SVector;
use retract::{
    Lagrangian, LiftedSystem, StepOptions, helper, higher_order_lagrangian, jet_function,
};

/// Horizon steps.
pub const STEPS: usize = 50;
/// Horizon length (s); the control period is `HORIZON / STEPS`.
pub const HORIZON: f64 = 1.0;
/// Real-time iterations (feedback steps) per re-plan.
pub const ITERATIONS: usize = 2;
/// Masses, lengths and gravity of both models.
const M1: f64 = 1.0;
const M2: f64 = 1.0;
const L1: f64 = 1.0;
const L2: f64 = 1.0;
const G: f64 = 9.81;

/// The torques tau = M(q) q'' + C(q, q') q' + G(q) of the double pendulum, angles from the
/// downward vertical, the second relative to the first (point masses at the rod ends): one
/// formula for the planner's cost, the acrobot's cost and its constraint.
#[helper]
pub fn torque(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
) -> [f64; 2] {
    let c2 = q[1].cos();
    let m11 = (m1 + m2) * l1 * l1 + m2 * l2 * l2 + 2.0 * m2 * l1 * l2 * c2;
    let m12 = m2 * l2 * l2 + m2 * l1 * l2 * c2;
    let m22 = m2 * l2 * l2;
    let b = m2 * l1 * l2 * q[1].sin();
    let g1 = (m1 + m2) * g * l1 * q[0].sin() + m2 * g * l2 * (q[0] + q[1]).sin();
    let g2 = m2 * g * l2 * (q[0] + q[1]).sin();
    [
        m11 * ddq[0] + m12 * ddq[1] - b * (2.0 * dq[0] * dq[1] + dq[1] * dq[1]) + g1,
        m12 * ddq[0] + m22 * ddq[1] + b * dq[0] * dq[0] + g2,
    ]
}

/// The planner's model: L = 1/2 |tau|^2 ([`torque`]), with tau also a method
/// (`TorqueCost::tau(&self, x, u)`: the torque a plan asks of the plant).
#[higher_order_lagrangian(order = 2, helpers = [torque])]
pub fn torque_cost(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
) -> f64 {
    #[output]
    let tau = torque(q, dq, ddq, m1, m2, l1, l2, g);
    0.5 * (tau[0] * tau[0] + tau[1] * tau[1])
}

/// The receding-horizon benchmark's stage cost (docs/benchmarks.md, "Receding horizon"):
/// L = 1/2 |tau|^2 + w_q |q - (q_up, 0)|^2 + w_v |q'|^2 ([`torque`]), with tau also a method
/// (`UprightCost::tau(&self, x, u)`).
#[higher_order_lagrangian(order = 2, helpers = [torque])]
pub fn upright_cost(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
    w_q: f64,
    w_v: f64,
    q_up: f64,
) -> f64 {
    #[output]
    let tau = torque(q, dq, ddq, m1, m2, l1, l2, g);
    let e = q[0] - q_up;
    0.5 * (tau[0] * tau[0] + tau[1] * tau[1])
        + w_q * (e * e + q[1] * q[1])
        + w_v * (dq[0] * dq[0] + dq[1] * dq[1])
}

/// The acrobot's cost: only the elbow is actuated, L = 1/2 tau_2^2; the shoulder's torque is
/// constrained to zero by [`shoulder_torque`].
#[higher_order_lagrangian(order = 2, helpers = [torque])]
pub fn elbow_cost(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
) -> f64 {
    0.5 * torque(q, dq, ddq, m1, m2, l1, l2, g)[1].powi(2)
}

/// The acrobot's passive shoulder: tau_1 = 0 at every step.
#[jet_function(order = 2, helpers = [torque])]
pub fn shoulder_torque(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
) -> f64 {
    torque(q, dq, ddq, m1, m2, l1, l2, g)[0]
}

/// The plant: L = T - V of the same pendulum, T = 1/2 q'^T M(q) q',
/// V = -(m1 + m2) g l1 cos q0 - m2 g l2 cos(q0 + q1).
#[higher_order_lagrangian(order = 1)]
pub fn plant(q: [f64; 2], dq: [f64; 2], m1: f64, m2: f64, l1: f64, l2: f64, g: f64) -> f64 {
    let c2 = q[1].cos();
    let m11 = (m1 + m2) * l1 * l1 + m2 * l2 * l2 + 2.0 * m2 * l1 * l2 * c2;
    let m12 = m2 * l2 * l2 + m2 * l1 * l2 * c2;
    let m22 = m2 * l2 * l2;
    let kinetic = 0.5 * (m11 * dq[0] * dq[0] + 2.0 * m12 * dq[0] * dq[1] + m22 * dq[1] * dq[1]);
    let potential = -(m1 + m2) * g * l1 * q[0].cos() - m2 * g * l2 * (q[0] + q[1]).cos();
    kinetic - potential
}

/// What a run of the loop measured.
pub struct Summary {
    /// Re-plans made.
    pub replans: usize,
    /// Re-plans that returned an error.
    pub failures: usize,
    /// Wall time of every re-plan (microseconds), in order.
    pub times_us: Vec<f64>,
    /// Re-plans whose last Newton step was at most 1e-6.
    pub converged: usize,
    /// The plant's jet (q, q') after the last step.
    pub last: [f64; 4],
    /// The largest |tau| applied.
    pub max_torque: f64,
}

impl Summary {
    /// The `p`-quantile (0..=1) of the re-plan times, nearest rank.
    pub fn quantile_us(&self, p: f64) -> f64 {
        let mut sorted = self.times_us.clone();
        sorted.sort_by(f64::total_cmp);
        let rank = ((p * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len());
        sorted[rank - 1]
    }
}

/// The torque of a first step at its midpoint: tau((x_0 + x_1) / 2, u_0).
fn first_torque(
    model: &TorqueCost,
    [x0, x1]: &[SVector<f64, 4>; 2],
    u0: &SVector<f64, 2>,
) -> [f64; 2] {
    let x = (x0 + x1) * 0.5;
    let jet = [
        x.fixed_rows::<2>(0).into_owned(),
        x.fixed_rows::<2>(2).into_owned(),
    ];
    model.tau(&jet, u0)
}

/// The receding-horizon controller: one problem and its real-time iteration (as acados'
/// RTI), started from a full solve; each period [`ITERATIONS`] feedback steps from the
/// measured state (the library's [`OptimalControlProblem::control`], which applies the
/// shifted plan's input if a re-plan fails), then the iterate shifted by a period and its
/// subproblem prepared for the next one (no allocation a period).
pub struct Controller<'m> {
    model: &'m TorqueCost,
    problem: OptimalControlProblem<'m, TorqueCost, 2, 2, 4>,
    rti: RealTimeIteration<2, 4>,
    options: ControlOptions,
    /// The last period's applied first step.
    applied: Control<2, 4>,
}

/// How a re-plan ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Replan {
    /// The re-plan applied, converged (its last Newton step at most 1e-6).
    Converged,
    /// The re-plan applied, not converged (the tangential predictor).
    Unfinished,
    /// The re-plan failed (the shifted plan's input applied) or the next preparation did.
    Failed,
}

impl<'m> Controller<'m> {
    /// A controller towards the upright rest state, from the jet `jet`: the plan solved from
    /// there, its real-time iteration prepared.
    ///
    /// # Errors
    /// The first solve or preparation failing.
    pub fn new(model: &'m TorqueCost, jet: &[f64; 4]) -> Result<Self, Box<dyn std::error::Error>> {
        let goal = [PI, 0.0, 0.0, 0.0];
        let problem = OptimalControlProblem::new(model, jet, &goal, HORIZON, STEPS);
        let plan = problem.solve(PlanGuess::Spline)?;
        let mut rti = problem.real_time_iteration(PlanGuess::Plan(&plan))?;
        problem.prepare(&mut rti)?;
        let applied = (problem).clamped_control(
            ([plan.x[0], plan.x[1]], plan.u[0]),
            InputSource::Converged,
            (0, 0.0),
        );
        Ok(Self {
            model,
            problem,
            rti,
            options: ControlOptions::default().with_iterations(ITERATIONS),
            applied,
        })
    }

    /// Re-plans from the measured jet `jet` (the input to apply: [`Self::torque`]), then
    /// prepares the next period.
    pub fn replan(&mut self, jet: &[f64; 4]) -> Replan {
        self.applied = self.problem.control(&mut self.rti, jet, &self.options);
        self.rti.shift();
        let prepared = self.problem.prepare(&mut self.rti).is_ok();
        let status = self.applied.status;
        if !status.replanned() || !prepared {
            Replan::Failed
        } else if status.converged() {
            Replan::Converged
        } else {
            Replan::Unfinished
        }
    }

    /// The torque of the last re-plan's first step.
    pub fn torque(&self) -> [f64; 2] {
        first_torque(self.model, &self.applied.x, &self.applied.input)
    }
}

/// The plant: one forced-midpoint step of `h` under the torque `tau` from the canonical state
/// `z`, returning the new state and its jet.
///
/// # Errors
/// A step that fails.
pub fn plant_step(
    pendulum: &Plant,
    z: &SVector<f64, 4>,
    jet: &[f64; 4],
    tau: [f64; 2],
) -> Result<(SVector<f64, 4>, [f64; 4]), retract::Error> {
    let h = HORIZON / STEPS as f64;
    let (z, _) = forced_step(pendulum, z, &SVector::from(tau), h, &StepOptions::default())?;
    let q = SVector::<f64, 2>::from([z[0], z[1]]);
    let p = SVector::<f64, 2>::from([z[2], z[3]]);
    let dq = pendulum.top_derivative(&[q], &p, &SVector::from([jet[2], jet[3]]))?;
    Ok((z, [q[0], q[1], dq[0], dq[1]]))
}

/// The planner's model and the plant of the double pendulum.
pub fn models() -> (TorqueCost, Plant) {
    (
        TorqueCost::new(M1, M2, L1, L2, G),
        Plant::new(M1, M2, L1, L2, G),
    )
}

/// The benchmark's planner (weights 50 on the angles, 1 on the rates, upright at q = (pi, 0))
/// and the plant.
pub fn upright_models() -> (UprightCost, Plant) {
    (
        UprightCost::new(M1, M2, L1, L2, G, 50.0, 1.0, PI),
        Plant::new(M1, M2, L1, L2, G),
    )
}

/// Runs `replans` control periods from the hanging rest state.
///
/// # Errors
/// The first solve, or a plant step, failing (the re-plans' failures are counted).
pub fn run(replans: usize) -> Result<Summary, Box<dyn std::error::Error>> {
    let (model, pendulum) = models();
    let mut jet = [0.0; 4];
    let mut z = pendulum.legendre(&SVector::from(jet));
    let mut summary = Summary {
        replans,
        failures: 0,
        times_us: Vec::with_capacity(replans),
        converged: 0,
        last: jet,
        max_torque: 0.0,
    };
    let mut controller = Controller::new(&model, &jet)?;
    for _ in 0..replans {
        let started = Instant::now();
        let outcome = controller.replan(&jet);
        summary.times_us.push(started.elapsed().as_secs_f64() * 1e6);
        summary.converged += usize::from(outcome == Replan::Converged);
        summary.failures += usize::from(outcome == Replan::Failed);
        let tau = controller.torque();
        summary.max_torque = summary.max_torque.max(tau[0].abs()).max(tau[1].abs());
        (z, jet) = plant_step(&pendulum, &z, &jet, tau)?;
    }
    summary.last = jet;
    Ok(summary)
}
