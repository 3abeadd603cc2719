#![allow(unused)]
use retract::higher_order_lagrangian;

// the parameter `tau` written before the jet (q, dq, ddq)
#[higher_order_lagrangian(order = 2)]
fn lagrangian(tau: f64, q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1]) + tau * q[0]
}

fn main() {}
