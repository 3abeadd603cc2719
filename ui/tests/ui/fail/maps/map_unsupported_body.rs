#![allow(unused)]
use retract::discretization_map;

// The body must end with the pair of points as array literals.
#[discretization_map(order = 1)]
fn midpoint(q: [f64; 2], v: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let r1 = [q[0] - 0.5 * v[0], q[1] - 0.5 * v[1]];
    let r2 = [q[0] + 0.5 * v[0], q[1] + 0.5 * v[1]];
    (r1, r2)
}

fn main() {}
