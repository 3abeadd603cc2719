#![allow(unused)]
use retract::higher_order_lagrangian;

// `_2d_arm` in UpperCamelCase is `2dArm`, which is not a type name
#[higher_order_lagrangian(order = 2)]
fn _2d_arm(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2))
}

// `self_` would give `Self`, a keyword
#[higher_order_lagrangian(order = 1)]
fn self_(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq
}

fn main() {}
