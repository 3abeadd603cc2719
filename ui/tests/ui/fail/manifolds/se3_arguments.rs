// `se3` takes the pose g = (R, p) as [f64; 12] (R row major, then p), then xi, ...,
// xi^(k-1) as [f64; 6] (xi = (Omega, v)); the chart's centre `se3_centre` is a reserved
// parameter name, and `se3` excludes `so3`.
use retract::{higher_order_lagrangian, jet_function};

#[higher_order_lagrangian(order = 2, se3)]
fn body(g: [f64; 9], xi: [f64; 3], dxi: [f64; 6], se3_centre: f64) -> f64 {
    0.5 * (dxi[0] * dxi[0] + xi[0] * xi[0] + g[0] * se3_centre)
}

#[jet_function(order = 1, so3, se3)]
fn both(g: [f64; 12], xi: [f64; 6]) -> f64 {
    g[9] + xi[0]
}

fn main() {}
