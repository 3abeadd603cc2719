#![doc = include_str!("../README.md")]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use retract_core::*;
pub use retract_macros::higher_order_lagrangian;

#[doc(hidden)]
pub mod __private {
    pub use retract_core;
    pub use retract_core::nalgebra;
}
