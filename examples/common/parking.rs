//! The parallel-parking car of the constrained suite (C3 of `../shared/BENCHMARKS.md`):
//! q = (x, y, psi), cost 1/2 |q''|^2, no side slip (an equality) and a turning radius of at
//! least 1 (an inequality whose gradient vanishes at rest). Shared by
//! `examples/constrained.rs` and the tests (by path).
#![allow(dead_code)] // each user takes a subset

use retract::{higher_order_lagrangian, jet_function};

/// The car's cost 1/2 |q''|^2, q = (x, y, psi).
#[higher_order_lagrangian(order = 2)]
pub fn car_effort(_q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1] + ddq[2] * ddq[2])
}

/// No side slip: v_x sin(psi) - v_y cos(psi).
#[jet_function(order = 2)]
pub fn side_slip(q: [f64; 3], dq: [f64; 3], _ddq: [f64; 3]) -> f64 {
    dq[0] * q[2].sin() - dq[1] * q[2].cos()
}

/// Turning radius at least 1: s^2 - psi'^2 with the forward speed
/// s = v_x cos(psi) + v_y sin(psi).
#[jet_function(order = 2)]
pub fn turning(q: [f64; 3], dq: [f64; 3], _ddq: [f64; 3]) -> f64 {
    let speed = dq[0] * q[2].cos() + dq[1] * q[2].sin();
    speed * speed - dq[2] * dq[2]
}

/// The suite's first guess: the natural cubic spline through these waypoints (x, y, psi) at
/// t = 0, T/4, T/2, 3T/4, T.
pub const WAYPOINTS: [[f64; 3]; 5] = [
    [0.0, 0.0, 0.0],
    [0.3, 0.1, 0.4],
    [0.4, 0.25, 0.0],
    [0.2, 0.4, -0.4],
    [0.0, 0.5, 0.0],
];
