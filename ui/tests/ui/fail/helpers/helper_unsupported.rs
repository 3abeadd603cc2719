#![allow(unused)]
// valid Rust that a Lagrangian does not support
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn lagrangian(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    #[allow(unconditional_recursion)]
    fn forever(x: f64) -> f64 {
        forever(x)
    }
    fn generic<T>(x: f64) -> f64 {
        x
    }
    fn early(x: f64) -> f64 {
        return x;
    }
    fn by_slice(x: &[f64]) -> f64 {
        x[0]
    }
    fn nothing(x: f64) {}
    let mut a = [q[0], q[1]];
    0.5 * ddq[0].powi(2) + forever(1.0) + early(2.0) + a[0]
}

fn main() {}
