#![allow(unused)]
use retract::{higher_order_lagrangian, jet_function};

#[higher_order_lagrangian(order = 2)]
fn nested(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    let mut l = 0.0;
    for i in 0..2 {
        #[output]
        let square = ddq[i] * ddq[i];
        l += square;
    }
    #[output]
    let (a, b) = (q[0], q[1]);
    #[output]
    let mut c = q[0];
    c += 1.0;
    0.5 * l + a * b + c
}

#[jet_function(order = 2)]
fn constraint(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    #[output]
    let x = q[0];
    x
}

#[higher_order_lagrangian(order = 2, sphere)]
fn on_sphere(q: [f64; 3], dq: [f64; 3], ddq: [f64; 3]) -> f64 {
    #[output]
    let speed = dq[0] * dq[0] + dq[1] * dq[1] + dq[2] * dq[2];
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1] + ddq[2] * ddq[2]) + speed
}

#[higher_order_lagrangian(order = 2)]
fn shadowing(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1]) -> f64 {
    #[output]
    let lagrangian = q[0] + 100.0;
    #[output]
    let new = dq[0];
    #[output(foo)]
    let force = ddq[0];
    0.5 * ddq[0] * ddq[0] + lagrangian + new + force
}

fn main() {}
