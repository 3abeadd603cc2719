#![allow(unused)]
use retract::{helper, mechanical_system};

// Q_nc has one component per coordinate: a number is not the forces on two coordinates
#[helper]
fn drag(dq: [f64; 2], c: f64) -> f64 {
    -c * dq[0]
}

#[mechanical_system(forces = drag)]
fn cart(q: [f64; 2], dq: [f64; 2], c: f64) -> f64 {
    0.5 * dq[0] * dq[0] + 0.5 * dq[1] * dq[1] - q[1].cos()
}

// the forces' arguments are taken by name from the system's: it has no `speed`
#[mechanical_system(forces = friction)]
fn sled(q: [f64; 2], dq: [f64; 2], c: f64) -> f64 {
    fn friction(speed: [f64; 2], c: f64) -> [f64; 2] {
        [-c * speed[0], -c * speed[1]]
    }
    0.5 * dq[0] * dq[0] + 0.5 * dq[1] * dq[1] - q[1].cos()
}

fn main() {}
