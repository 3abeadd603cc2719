#![allow(unused)]
use retract::discretization_map;

// R_d(q, 0) = (q, q): here R1(q, 0) = q + (0, c), wrong in component 1.
#[discretization_map(order = 2)]
fn shifted(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {
    ([q[0] - 0.5 * v[0], q[1] - 0.5 * v[1] + c], [q[0] + 0.5 * v[0], q[1] + 0.5 * v[1]])
}

fn main() {}
