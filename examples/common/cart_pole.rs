//! The cart-pole of the swing-up suite (`../shared/BENCHMARKS.md`): cart mass mc, pole point
//! mass mp at length l, q = (x, theta) with theta from the downward vertical; the cart force
//! F is actuated, the pole's torque must vanish: the hand-written cost and constraint, and the
//! same system written as its energy T - V (`#[mechanical_system]`). Shared by
//! `examples/swing_up.rs`, `examples/constrained.rs` (C1 and C5), `examples/cartpole_energy.rs`
//! and the tests (by path).
#![allow(dead_code)] // each user takes a subset

use retract::{helper, higher_order_lagrangian, jet_function, mechanical_system};

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

/// The cart-pole's energy l = T - V, shared by `cart_pole_energy` and its variants.
#[helper]
pub fn cart_pole_lagrangian(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64, g: f64) -> f64 {
    let kinetic = 0.5 * (mc + mp) * dq[0] * dq[0]
        + mp * l * q[1].cos() * dq[0] * dq[1]
        + 0.5 * mp * l * l * dq[1] * dq[1];
    let potential = -mp * g * l * q[1].cos();
    kinetic - potential
}

/// The cart-pole as its energy l = T - V: cart x, pole angle th from the downward vertical,
/// point mass mp at length l; only the cart is driven (`actuated = [0]`), so the generated
/// cost is 1/2 F^2 with F = tau_0 and the pole's tau_1 = 0 is the stage equality; the force
/// F is also a function of the jet (`input_functions()`), for bounds on it.
#[mechanical_system(
    actuated = [0],
    input_functions = true,
    helpers = [cart_pole_lagrangian]
)]
pub fn cart_pole_energy(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64, g: f64) -> f64 {
    cart_pole_lagrangian(q, dq, mc, mp, l, g)
}

/// The cart-pole of the minimum-time problem (C5 of `../shared/BENCHMARKS.md`): the effort
/// 0.01 * 1/2 F^2 (`weight = 0.01`), with the cart force as a function of the jet
/// (`input_functions()`) for its bound.
#[mechanical_system(
    actuated = [0],
    weight = 0.01,
    input_functions = true,
    helpers = [cart_pole_lagrangian]
)]
pub fn min_time_cart_pole(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64, g: f64) -> f64 {
    cart_pole_lagrangian(q, dq, mc, mp, l, g)
}

/// The generalized force of the cart's input: B = (1, 0), the column of the actuation matrix.
#[helper]
pub fn cart_push() -> [f64; 2] {
    [1.0, 0.0]
}

/// The cart-pole driven through its actuation matrix B = (1, 0) (`cart_push`) instead of
/// `actuated = [0]`: u = (B^T B)^{-1} B^T tau = tau_0 and the passive equality
/// a^T tau = -tau_1 (a = (det B_(0), -det B_(1)) = (0, -1)), the same problem.
#[mechanical_system(
    input_matrix = cart_push,
    input_functions = true,
    helpers = [cart_pole_lagrangian]
)]
pub fn pushed_cart_pole(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64, g: f64) -> f64 {
    cart_pole_lagrangian(q, dq, mc, mp, l, g)
}

/// Viscous friction on the cart and at the pole's pivot: Q_nc = -(bc x', bp th').
#[helper]
pub fn friction(dq: [f64; 2], bc: f64, bp: f64) -> [f64; 2] {
    [-bc * dq[0], -bp * dq[1]]
}

/// A cost added to the effort: k/2 x'^2 on the cart's speed and k u x (the input's work
/// against a spring-like bias), C(q, q', u).
#[helper]
pub fn speed_cost(q: [f64; 2], dq: [f64; 2], u: [f64; 1], k: f64) -> f64 {
    0.5 * k * dq[0] * dq[0] + k * u[0] * q[0]
}

/// The cart-pole with friction (`friction`) and the extra cost (`speed_cost`):
/// tau = tau_conservative + (bc x', bp th'), L = 1/2 tau_0^2 + C.
#[mechanical_system(
    actuated = [0],
    forces = friction,
    cost = speed_cost,
    helpers = [cart_pole_lagrangian]
)]
pub fn damped_cart_pole(
    q: [f64; 2],
    dq: [f64; 2],
    mc: f64,
    mp: f64,
    l: f64,
    g: f64,
    bc: f64,
    bp: f64,
    k: f64,
) -> f64 {
    cart_pole_lagrangian(q, dq, mc, mp, l, g)
}
