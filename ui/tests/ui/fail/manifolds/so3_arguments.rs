// `so3` takes the rotation R as [f64; 9] (row major), then Omega, ..., Omega^(k-1) as
// [f64; 3]; the chart's centre `so3_centre` is a reserved parameter name.
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2, so3)]
fn body(q: [f64; 3], w: [f64; 3], dw: [f64; 2], so3_centre: f64) -> f64 {
    0.5 * (dw[0] * dw[0] + dw[1] * dw[1] + w[0] * w[0] + q[0] * so3_centre)
}

fn main() {}
