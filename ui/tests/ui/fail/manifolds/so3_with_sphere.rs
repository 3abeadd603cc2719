// A Lagrangian lives on one space: `so3` and `sphere` exclude each other.
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 1, so3, sphere)]
fn body(r: [f64; 9], w: [f64; 3]) -> f64 {
    0.5 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) + r[0]
}

fn main() {}
