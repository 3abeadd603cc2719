#![allow(unused)]
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    ddq[0].powi(2) + ddq[1].powi(2) + q[2]
}

fn main() {}
