//! The Lagrangians shared by several integration tests.

use retract::higher_order_lagrangian;

/// The paper's planar rigid body on the SE(2) chart (x, y, theta) with the disc barrier:
/// L = 1/2 |q''|^2 + tau / (x^2 + y^2 - r^2).
#[higher_order_lagrangian(order = 2)]
pub fn rigid_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
        + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

/// The SE(2) chart with a run-time list of disc obstacles (cx, cy, r).
#[higher_order_lagrangian(order = 2)]
pub fn scene(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, obstacles: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2));
    for o in obstacles {
        l += tau / ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]);
    }
    l
}

/// Rotation-invariant Pais-Uhlenbeck oscillator in R^2 with a quartic term (MATH.md):
/// L = 1/2|q''|^2 - (w1^2 + w2^2)/2 |q'|^2 + w1^2 w2^2 / 2 |q|^2 + eps |q|^4.
#[higher_order_lagrangian(order = 2)]
pub fn pais_uhlenbeck(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], w1: f64, w2: f64, eps: f64) -> f64 {
    let r2 = q[0].powi(2) + q[1].powi(2);
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2))
        - 0.5 * (w1 * w1 + w2 * w2) * (dq[0].powi(2) + dq[1].powi(2))
        + 0.5 * w1 * w1 * w2 * w2 * r2
        + eps * r2 * r2
}

/// The bounded nonlinear Pais-Uhlenbeck case used in the long-run tests: w1 = 1, w2 = sqrt 2,
/// eps = -0.05 and the jet (0.3, 0), (0, 0.25), (-0.1, 0.05), (0, 0.1), whose motion stays
/// bounded (max |q| about 0.79; eps = +0.05 is not).
pub fn bounded_pais_uhlenbeck() -> (PaisUhlenbeck, retract::nalgebra::SVector<f64, 8>) {
    use retract::LiftedSystem;
    let system = PaisUhlenbeck {
        w1: 1.0,
        w2: 2f64.sqrt(),
        eps: -0.05,
    };
    let jet = [0.3, 0.0, 0.0, 0.25, -0.1, 0.05, 0.0, 0.1];
    let z0 = system.legendre(&retract::nalgebra::SVector::from_column_slice(&jet));
    (system, z0)
}
