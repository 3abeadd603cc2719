//! A controller crate without std: a generated integrator, stepped without allocation, and a
//! generated stage constraint evaluated without allocation.
//! CI checks it alone (`cargo clippy -p retract-no-std-check`), so `retract` has no `std`.
#![no_std]
#![forbid(unsafe_code)]

use retract::nalgebra::SVector;
use retract::{Error, JetFunction, LiftedSystem, StepOptions, step};
use retract::{higher_order_lagrangian, jet_function};

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

/// A stage constraint linear in q'' (no Lagrangian could be): heading rate times a speed,
/// with transcendental terms and a run-time list.
#[jet_function(order = 2)]
pub fn heading(q: [f64; 3], dq: [f64; 3], ddq: [f64; 3], discs: &[[f64; 3]]) -> f64 {
    let mut s = ddq[2] * (dq[0].powi(2) + dq[1].powi(2)).sqrt() + q[2].sin().atan2(1.0);
    for d in discs {
        s += (-(q[0] - d[0]).powi(2)).exp();
    }
    s
}

/// g(x, u) and dg/du_2 + d2g/du_2^2 at (x, u): all three generated methods, without std.
pub fn constraint(g: &Heading<'_>, x: &[SVector<f64, 3>; 2], u: &SVector<f64, 3>) -> (f64, f64) {
    (
        g.value(x, u),
        g.gradient(x, u).u[2] + g.hessian(x, u).uu[(2, 2)],
    )
}
