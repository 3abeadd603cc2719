#![allow(unused)]
use retract::mechanical_system;

// a mechanical Lagrangian is l(q, q'): order 1; the attribute derives the terms in q''
#[mechanical_system(order = 2)]
fn pendulum(q: f64, dq: f64, m: f64) -> f64 {
    0.5 * m * dq * dq + q.cos()
}

// an argument q'' after q and q' (the Lagrangian would depend on the acceleration)
#[mechanical_system]
fn cart(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], m: f64) -> f64 {
    0.5 * m * (dq[0] * dq[0] + dq[1] * dq[1]) + ddq[0] * q[1]
}

fn main() {}
