#![allow(unused)]
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    let square = |x: f64| x * x;
    square(ddq[0]) + square(ddq[1])
}

fn main() {}
