#![allow(unused)]
use retract::{discretization_map, higher_order_lagrangian, stumpff};

// the order of a Stumpff function must be an integer literal: it picks the function
#[higher_order_lagrangian(order = 1)]
fn variable_order(q: [f64; 1], dq: [f64; 1]) -> f64 {
    let k = 2;
    stumpff(k, dq[0] * dq[0]) * q[0]
}

// and at most 100
#[discretization_map(order = 1)]
fn huge_order(q: [f64; 1], v: [f64; 1]) -> ([f64; 1], [f64; 1]) {
    ([q[0] - 0.5 * v[0] * stumpff(101, v[0])], [q[0] + 0.5 * v[0]])
}

// with two arguments
#[higher_order_lagrangian(order = 1)]
fn one_argument(q: [f64; 1], dq: [f64; 1]) -> f64 {
    stumpff(dq[0]) * q[0]
}

fn main() {}
