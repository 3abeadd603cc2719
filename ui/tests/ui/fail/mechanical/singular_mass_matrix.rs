#![allow(unused)]
use retract::mechanical_system;

// T = 1/2 (q'_0 + q'_1)^2: the constant mass matrix [[1, 1], [1, 1]] is singular
#[mechanical_system]
fn sliding(q: [f64; 2], dq: [f64; 2], k: f64) -> f64 {
    0.5 * (dq[0] + dq[1]).powi(2) - 0.5 * k * (q[0] * q[0] + q[1] * q[1])
}

// no kinetic energy at all
#[mechanical_system]
fn potential_only(q: [f64; 2], dq: [f64; 2]) -> f64 {
    q[0].cos() + q[1].cos()
}

fn main() {}
