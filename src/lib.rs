#![doc = include_str!("../README.md")]
#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use retract_core::*;
pub use retract_macros::{higher_order_lagrangian, jet_function};

#[doc(hidden)]
pub mod __private {
    pub use retract_core;
    pub use retract_core::Float;
    pub use retract_core::nalgebra;
}
