//! Order 4 with unrolled loops over literal ranges and a const from the crate.
use retract::higher_order_lagrangian;

const DIM: usize = 3;

#[higher_order_lagrangian(order = 4)]
fn snap(q: [f64; 3], dq: [f64; 3], ddq: [f64; 3], dddq: [f64; 3], d4q: [f64; 3], k: [f64; 3]) -> f64 {
    let mut l = 0.0;
    for i in 0..3 {
        l += 0.5 * d4q[i].powi(2) + 0.5 * k[i] * q[i].powi(2);
    }
    l + 0.0 * (dq[0] + ddq[0] + dddq[0]) * (DIM as f64)
}

fn main() {
    assert_eq!(Snap::ORDER, 4);
    assert_eq!(Snap::STATE, 24);
    let _ = Snap::new([1.0, 2.0, 3.0]);
}
