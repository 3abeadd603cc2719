#![allow(unused)]
use retract::{helper, higher_order_lagrangian};

#[helper(inline)]
fn with_option(x: f64) -> f64 {
    x
}

#[helper]
fn by_slice(x: &[f64]) -> f64 {
    x[0]
}

#[higher_order_lagrangian(order = 2, helpers = 3)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * ddq[0].powi(2) + 0.5 * ddq[1].powi(2)
}

fn main() {}
