//! The planar quadrotor of the constrained suite (C2 of BENCHMARKS.md): its cost, the lateral
//! force it cannot produce, its rotor thrusts and the disc it passes. Shared by
//! `examples/constrained.rs` and the tests (by path).
#![allow(dead_code)] // each user takes a subset

use retract::{higher_order_lagrangian, jet_function};

/// Planar quadrotor, q = (x, z, theta): cost 1/2 (f1^2 + f2^2) of the rotor thrusts
/// f1,2 = Th/2 -+ tq/(2a), Th = -fx sin(theta) + fz cos(theta), fx = m x'', fz = m z'' + m g,
/// tq = I theta''.
#[higher_order_lagrangian(order = 2)]
pub fn quadrotor(
    _q: [f64; 3],
    _dq: [f64; 3],
    ddq: [f64; 3],
    m: f64,
    inertia: f64,
    arm: f64,
) -> f64 {
    let (s, c) = (_q[2].sin(), _q[2].cos());
    let thrust = -m * ddq[0] * s + (m * ddq[1] + m * 9.81) * c;
    let torque = inertia * ddq[2];
    let f1 = 0.5 * thrust - torque / (2.0 * arm);
    let f2 = 0.5 * thrust + torque / (2.0 * arm);
    0.5 * (f1 * f1 + f2 * f2)
}

/// The quadrotor's lateral body force fx cos(theta) + fz sin(theta) (two rotors cannot push
/// sideways: an equality).
#[jet_function(order = 2)]
pub fn lateral(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], m: f64) -> f64 {
    m * ddq[0] * q[2].cos() + (m * ddq[1] + m * 9.81) * q[2].sin()
}

/// The rotor thrusts (f1, f2) = Th/2 -+ tq/(2a): one function with two components, each
/// bounded to [0, fmax].
#[jet_function(order = 2)]
pub fn rotors(
    q: [f64; 3],
    _dq: [f64; 3],
    ddq: [f64; 3],
    m: f64,
    inertia: f64,
    arm: f64,
) -> [f64; 2] {
    let thrust = -m * ddq[0] * q[2].sin() + (m * ddq[1] + m * 9.81) * q[2].cos();
    let torque = inertia * ddq[2];
    [
        0.5 * thrust - torque / (2.0 * arm),
        0.5 * thrust + torque / (2.0 * arm),
    ]
}

/// Clearance of the disc of radius 0.3 about (1, 0.5): (x - 1)^2 + (z - 0.5)^2 - 0.3^2.
#[jet_function(order = 2)]
pub fn clearance(q: [f64; 3], _dq: [f64; 3], _ddq: [f64; 3]) -> f64 {
    (q[0] - 1.0).powi(2) + (q[1] - 0.5).powi(2) - 0.09
}
