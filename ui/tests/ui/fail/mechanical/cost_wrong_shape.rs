#![allow(unused)]
use retract::mechanical_system;

// the cost C(q, q', u) is a number
#[mechanical_system(actuated = [0], cost = speeds)]
fn cart(q: [f64; 2], dq: [f64; 2]) -> f64 {
    fn speeds(dq: [f64; 2], u: [f64; 1]) -> [f64; 2] {
        [dq[0], u[0]]
    }
    0.5 * dq[0] * dq[0] + 0.5 * dq[1] * dq[1] - q[1].cos()
}

// `cost` names a function by its name
#[mechanical_system(actuated = [0], cost = 0.5)]
fn sled(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * dq[0] * dq[0] + 0.5 * dq[1] * dq[1] - q[1].cos()
}

fn main() {}
