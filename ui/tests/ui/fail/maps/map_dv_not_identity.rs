#![allow(unused)]
use retract::discretization_map;

// d_v R2 - d_v R1 = I at v = 0: here it is 1/2 in component 0 (R1 should be q - v/2).
#[discretization_map(order = 1)]
fn half_step(q: [f64; 2], v: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let bend = q[1].sin() * v[0] * v[0];
    ([q[0] + bend, q[1] - 0.5 * v[1]], [q[0] + 0.5 * v[0] + bend, q[1] + 0.5 * v[1]])
}

fn main() {}
