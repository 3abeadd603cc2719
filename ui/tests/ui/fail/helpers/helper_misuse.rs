#![allow(unused)]
// helper calls that are not Rust either: the macro's message comes first, then rustc's
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    fn square(x: f64) -> f64 {
        x * x
    }
    fn pair(a: f64) -> [f64; 2] {
        [a, 2.0 * a]
    }
    fn wrong(x: f64) -> [f64; 3] {
        [x, x]
    }
    let a = square(q[0], q[1]); // two arguments for one
    let b = square(dq); // an array for a number
    let c = pair(ddq[0]) + 1.0; // an array used as a number
    let e = wrong(1.0)[0];
    let f = pair(1.0)[2];
    let (g, h) = (1.0, 2.0, 3.0);
    0.5 * ddq[0].powi(2) + a + b + c + e + f + g + h
}

fn main() {}
