//! Every supported construct in one Lagrangian; the generated system takes a step.
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, step};

const WEIGHT: f64 = 0.5;

#[higher_order_lagrangian(order = 2, name = Everything)]
pub fn all_constructs(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    a: f64,
    c: [f64; 2],
    obstacles: &[[f64; 3]],
) -> f64 {
    const N: usize = 2;
    const HALF: f64 = 0.5;
    let mut acc = 0.0;
    for i in 0..N {
        acc += HALF * ddq[i].powi(2);
    }
    for i in 0..=1 {
        acc -= 0.01 * (-dq[i]) * dq[i];
    }
    let mut m = 1.0;
    m *= 2.0;
    m /= 2.0;
    m = m + 0.0;
    for o in obstacles {
        let d2 = (q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2];
        acc += a / d2;
    }
    for o in obstacles.iter() {
        acc -= 1e-3 * o[0] * q[0];
    }
    let t = 0.01
        * (q[0].sin() + q[1].cos() + (0.1 * q[0]).tan().tanh() + q[1].exp().ln()
            + q[0].hypot(q[1]) + q[1].atan2(q[0]) + q[0].abs().sqrt() + q[1].recip()
            + q[0].powf(1.5) + c[1] * std::f64::consts::PI + f64::sqrt(q[0])
            + (2 as f64) * q[1]);
    m * acc + t + WEIGHT * (q[0] - q[0])
}

fn main() {
    let obstacles = [[0.0, 0.0, 0.5], [4.0, 4.0, 0.5]];
    let system = Everything::new(0.1, [1.0, 2.0], &obstacles);
    let jet = SVector::<f64, 8>::from_column_slice(&[2.0, 1.0, 0.1, 0.2, 0.0, 0.0, 0.0, 0.0]);
    let z0 = system.legendre(&jet);
    let (z1, report) = step(&system, &z0, 0.01, &StepOptions::default()).expect("a regular step");
    assert!(report.residual_norm < 1e-12 && z1.iter().all(|v| v.is_finite()));
    let _ = all_constructs([2.0, 1.0], [0.1, 0.2], [0.0, 0.0], 0.1, [1.0, 2.0], &obstacles);
}
