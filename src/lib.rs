//! `retract`: structure-preserving integrators and optimal-control solvers for
//! higher-order Lagrangians.
//!
//! This facade re-exports the runtime ([`retract_core`]) and the attribute macro crate.
//! See the README for a tour.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use retract_core::*;
pub use retract_macros::higher_order_lagrangian;

#[doc(hidden)]
pub mod __private {
    pub use retract_core;
    pub use retract_core::nalgebra;
}
