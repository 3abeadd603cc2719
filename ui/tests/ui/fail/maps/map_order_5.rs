#![allow(unused)]
use retract::discretization_map;

// Lifts are supported for k = 1..4.
#[discretization_map(order = 5)]
fn midpoint(q: f64, v: f64) -> (f64, f64) {
    (q - 0.5 * v, q + 0.5 * v)
}

fn main() {}
