#![allow(unused)]
use retract::higher_order_lagrangian;

// 2^63 iterations: neither dropped (`end + 1` wrapping to i64::MIN) nor unrolled
#[higher_order_lagrangian(order = 1)]
fn endless(q: f64, dq: f64) -> f64 {
    let mut l = 0.5 * dq * dq;
    for _ in 0..=9223372036854775807i64 {
        l += q;
    }
    l
}

// 2^64 - 1 iterations (`end - start` overflowing i64 made this loop hang)
#[higher_order_lagrangian(order = 1)]
fn hanging(q: f64, dq: f64) -> f64 {
    let mut l = 0.5 * dq * dq;
    for _ in (-9223372036854775807i64 - 1)..9223372036854775807 {
        l += q;
    }
    l
}

fn main() {}
