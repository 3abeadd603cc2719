//! A controller crate without std: a generated integrator, stepped without allocation.
//! CI builds it alone (`cargo build -p retract-no-std-check`), so `retract` has no `std`.
#![no_std]
#![forbid(unsafe_code)]

use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{Error, LiftedSystem, StepOptions, step};

/// The SE(2) body with a barrier per disc of a run-time list (cx, cy, r).
#[higher_order_lagrangian(order = 2)]
pub fn body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, discs: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2));
    for d in discs {
        l += tau / ((q[0] - d[0]).powi(2) + (q[1] - d[1]).powi(2) - d[2] * d[2]);
    }
    l + (1.0 + q[2].powi(2)).sqrt() * 0.0
}

/// One control period: advances `z` by `h` in place; no heap, no panic.
///
/// # Errors
/// Any step error (non-finite data, Newton failure, a crossed obstacle).
pub fn control_period(system: &Body<'_>, z: &mut SVector<f64, 12>, h: f64) -> Result<usize, Error> {
    let (next, report) = step(system, z, h, &StepOptions::default())?;
    *z = next;
    Ok(report.iterations)
}

/// The state for a jet (q, q', q'', q''').
pub fn start(system: &Body<'_>, jet: &[f64; 12]) -> SVector<f64, 12> {
    system.legendre(&SVector::from_column_slice(jet))
}
