#![allow(unused)]
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], obstacles: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2));
    for a in obstacles {
        for b in obstacles {
            l += a[0] * b[0] * q[0];
        }
    }
    l
}

fn main() {}
