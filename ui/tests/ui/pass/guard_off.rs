//! `guard = false`: no domain check is generated, so a step into the disc is not flagged.
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, step};

#[higher_order_lagrangian(order = 2, guard = false)]
fn unguarded(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
}

fn main() {
    let system = Unguarded { tau: 1e-2 };
    // just outside the unit circle, moving in fast: the step ends inside
    let jet = SVector::<f64, 8>::from_column_slice(&[-1.001, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let z0 = system.legendre(&jet);
    let (z1, _) = step(&system, &z0, 0.01, &StepOptions::default()).expect("not checked");
    assert!(z1[0].hypot(z1[1]) < 1.0);
}
