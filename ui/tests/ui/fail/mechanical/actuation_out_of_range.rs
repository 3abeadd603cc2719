#![allow(unused)]
use retract::mechanical_system;

// q has two coordinates, 0 and 1: the index 2 is out of range, and 0 is listed twice
#[mechanical_system(actuated = [0, 2, 0])]
fn cart_pole(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64) -> f64 {
    0.5 * (mc + mp) * dq[0] * dq[0] + mp * l * q[1].cos() * dq[0] * dq[1]
        + 0.5 * mp * l * l * dq[1] * dq[1]
}

fn main() {}
