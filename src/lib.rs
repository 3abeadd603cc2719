#![doc = include_str!("../README.md")]
#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use retract_core::*;

// the generated items name `::retract`, also inside this crate (`sphere`)
extern crate self as retract;

#[cfg(feature = "plot")]
pub mod plot;
pub mod sphere;
pub use retract_macros::{higher_order_lagrangian, jet_function};

/// A runnable example: the symmetric "bent midpoint" map lifted to order 2, stepping the
/// Pais-Uhlenbeck oscillator with [`map::step`].
///
/// ```
/// use retract::nalgebra::SVector;
/// use retract::map::{self, DiscretizationMap};
/// use retract::{LiftedSystem, NewtonOptions, discretization_map, higher_order_lagrangian};
///
/// #[discretization_map(order = 2)]
/// fn bent_midpoint(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {
///     let s = c * q[0].sin();
///     (
///         [q[0] - 0.5 * v[0] + s * v[0] * v[0], q[1] - 0.5 * v[1] + s * v[1] * v[1]],
///         [q[0] + 0.5 * v[0] + s * v[0] * v[0], q[1] + 0.5 * v[1] + s * v[1] * v[1]],
///     )
/// }
///
/// #[higher_order_lagrangian(order = 2)]
/// fn pais_uhlenbeck(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
///     0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) - 0.5 * (dq[0].powi(2) + dq[1].powi(2))
///         + 0.5 * (q[0].powi(2) + q[1].powi(2))
/// }
///
/// let map = BentMidpoint::new(0.3);
/// // block 1 of the lifted R2 is D R2 = q' + v'/2 + ...
/// let x = [SVector::from([0.1, 0.2]), SVector::from([0.3, -0.1])];
/// let xi = [SVector::zeros(), SVector::from([0.5, 0.4])];
/// let (_, r2) = map.points(&x, &xi);
/// assert!((r2[1] - (x[1] + xi[1] * 0.5)).amax() < 1e-15);
///
/// let system = PaisUhlenbeck {};
/// let z0 = system.legendre(&SVector::<f64, 8>::from_fn(|r, _| 0.1 * (r as f64 + 1.0).sin()));
/// let (z1, report) = map::step(&system, &map, &z0, 0.01, &NewtonOptions::default())?;
/// assert!((z1 - z0).amax() < 0.1 && report.iterations <= 6);
/// # Ok::<(), retract::Error>(())
/// ```
#[doc(inline)]
pub use retract_macros::discretization_map;

#[doc(hidden)]
pub mod __private {
    pub use retract_core;
    pub use retract_core::Float;
    pub use retract_core::nalgebra;
}
