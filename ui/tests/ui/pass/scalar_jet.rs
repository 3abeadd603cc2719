//! n = 1: the jet arguments are plain f64.
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, step};

#[higher_order_lagrangian(order = 1)]
fn oscillator(q: f64, dq: f64, omega: f64) -> f64 {
    0.5 * dq * dq - 0.5 * omega * omega * q * q
}

fn main() {
    let system = Oscillator { omega: 2.0 };
    let z0 = system.legendre(&SVector::<f64, 2>::new(1.0, 0.0));
    let (z1, _) = step(&system, &z0, 0.1, &StepOptions::default()).expect("a regular step");
    assert!(z1[0] < 1.0);
}
