#![allow(unused)]
use retract::higher_order_lagrangian;

// a misspelt jet argument: `dqq` for `ddq`
#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + dqq[1] * dqq[1])
}

fn main() {}
