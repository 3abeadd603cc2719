//! The cart-pole of the swing-up suite (`../shared/BENCHMARKS.md`): cart mass mc, pole point
//! mass mp at length l, q = (x, theta) with theta from the downward vertical; the cart force
//! F is actuated, the pole's torque must vanish. Shared by `examples/swing_up.rs` and
//! `examples/constrained.rs` (by path).
#![allow(dead_code)] // each user takes a subset

use retract::{higher_order_lagrangian, jet_function};

/// Cost 1/2 F^2 on the cart force
/// F = (mc + mp) x'' + mp l cos(th) th'' - mp l sin(th) th'^2.
#[higher_order_lagrangian(order = 2)]
pub fn cart_pole(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], mc: f64, mp: f64, l: f64) -> f64 {
    let force =
        (mc + mp) * ddq[0] + mp * l * q[1].cos() * ddq[1] - mp * l * q[1].sin() * dq[1] * dq[1];
    0.5 * force * force
}

/// The pole's generalized force, which no actuator supplies: it must vanish at every step,
/// tau_p = mp l cos(th) x'' + mp l^2 th'' + mp g l sin(th).
#[jet_function(order = 2)]
pub fn pole_torque(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], mp: f64, l: f64, g: f64) -> f64 {
    mp * l * q[1].cos() * ddq[0] + mp * l * l * ddq[1] + mp * g * l * q[1].sin()
}

/// The cart force F of [`cart_pole`] (to bound it).
#[jet_function(order = 2)]
pub fn cart_force(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], mc: f64, mp: f64, l: f64) -> f64 {
    (mc + mp) * ddq[0] + mp * l * q[1].cos() * ddq[1] - mp * l * q[1].sin() * dq[1] * dq[1]
}
