#![allow(unused)]
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * ddq[0].powi(2) + q[0].norm()
}

fn main() {}
