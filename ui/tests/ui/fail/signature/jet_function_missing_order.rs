#![allow(unused)]
use retract::jet_function;

#[jet_function(name = Torque)]
fn torque(q: f64, dq: f64, ddq: f64) -> f64 {
    ddq + q.sin()
}

fn main() {}
