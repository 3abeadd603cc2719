//! The systems the measurements run on: the paper's SE(2) obstacle system and the bounded
//! Pais-Uhlenbeck oscillator, with the paper's initial state and its closest approach.

use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, trajectory};

use crate::Error;

/// The paper's SE(2) obstacle system: a rigid body $(x, y, \theta)$ with
/// $L = \tfrac12 |q''|^2 + \tau / (x^2 + y^2 - r^2)$.
#[higher_order_lagrangian(order = 2)]
pub fn rigid_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
        + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

/// The bounded Pais-Uhlenbeck oscillator in the plane (MATH.md), with a quartic term `eps`.
#[higher_order_lagrangian(order = 2)]
pub fn pais_uhlenbeck(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], w1: f64, w2: f64, eps: f64) -> f64 {
    let r2 = q[0].powi(2) + q[1].powi(2);
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2))
        - 0.5 * (w1 * w1 + w2 * w2) * (dq[0].powi(2) + dq[1].powi(2))
        + 0.5 * w1 * w1 * w2 * w2 * r2
        + eps * r2 * r2
}

/// The barrier weight of the paper's run.
pub const TAU: f64 = 1e-2;
/// The step size of the paper's run.
pub const H: f64 = 0.01;
/// The paper's run has 400 steps of [`H`].
pub const PAPER_STEPS: usize = 400;
/// A state $z = (x, p)$ of the obstacle system.
pub type Z = SVector<f64, 12>;
/// The paper's initial jet $(q, q', q'', q''')$: $q(0) = (-2, 1.05, 0)$,
/// $q'(0) = (1, 0, 0.5)$.
pub const PAPER_JET: [f64; 12] = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];

/// The obstacle system of the paper ($\tau$ = [`TAU`], unit disc).
pub fn paper_system() -> RigidBody {
    RigidBody { tau: TAU, r: 1.0 }
}

/// The paper's initial jet as a vector.
pub fn paper_jet() -> Z {
    Z::from_column_slice(&PAPER_JET)
}

/// The paper's initial state: the Legendre map of [`PAPER_JET`].
pub fn paper_start(system: &RigidBody) -> Z {
    system.legendre(&paper_jet())
}

/// The state after 200 steps of the paper's run, near the closest approach to the disc.
///
/// # Errors
/// [`Error::Retract`] if a step fails.
pub fn closest_approach(system: &RigidBody) -> Result<Z, Error> {
    let run = trajectory(
        system,
        &paper_start(system),
        H,
        PAPER_STEPS / 2,
        &StepOptions::default(),
    )
    .map_err(|stopped| stopped.error)?;
    run.states
        .last()
        .copied()
        .ok_or(Error::Domain("the paper's run (no states)"))
}
