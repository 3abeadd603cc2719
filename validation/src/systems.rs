//! The systems the measurements run on: the paper's SE(2) obstacle system and the bounded
//! Pais-Uhlenbeck oscillator (both from [`crate::models`], the integration tests' models),
//! with the paper's initial state and its closest approach.

use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, trajectory};

use crate::Error;
pub use crate::models::{PaisUhlenbeck, RigidBody, bounded_pais_uhlenbeck};

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
