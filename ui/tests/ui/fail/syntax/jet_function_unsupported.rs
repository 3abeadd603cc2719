#![allow(unused)]
use retract::jet_function;

// A stage constraint may be linear in q'' (no error for that), but it must be smooth
// straight-line code: both mistakes below are reported at once.
#[jet_function(order = 2)]
fn pole_torque(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], mp: f64, l: f64) -> f64 {
    let limit = |t: f64| t.min(1.0);
    if q[1] > 0.0 { mp * l * ddq[1] } else { 0.0 }
}

fn main() {}
