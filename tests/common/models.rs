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

/// The one-disc scene of `../shared/BENCHMARKS.md`: L = 1/2 |q''|^2 + tau / (x^2 + y^2 - 1).
#[higher_order_lagrangian(order = 2)]
pub fn one_disc(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
}

/// The one-disc scene's boundary jets (q, q') at t = 0 and t = 4.
pub const DISC_START: [f64; 4] = [-2.0, 0.2, 1.0, 0.0];
pub const DISC_GOAL: [f64; 4] = [2.0, 0.2, 1.0, 0.0];

/// The one-disc scene's feasible guess with `steps` steps on [0, 4]: the Hermite cubic (here
/// the straight line at unit speed) plus a bump 1.3 * 16 s^2 (1 - s)^2 in y (s = t / 4):
/// the jets (q, q') at the nodes and q'' at the step midpoints.
pub fn disc_bump_guess(
    steps: usize,
) -> (
    Vec<retract::nalgebra::SVector<f64, 4>>,
    Vec<retract::nalgebra::SVector<f64, 2>>,
) {
    use retract::nalgebra::SVector;
    let t_end = 4.0;
    let h = t_end / steps as f64;
    let y = |s: f64| {
        (
            1.3 * 16.0 * s * s * (1.0 - s).powi(2),
            1.3 * 16.0 * (2.0 * s - 6.0 * s * s + 4.0 * s.powi(3)) / t_end,
            1.3 * 16.0 * (2.0 - 12.0 * s + 12.0 * s * s) / (t_end * t_end),
        )
    };
    let x = (0..=steps)
        .map(|i| {
            let t = i as f64 * h;
            let (b, db, _) = y(t / t_end);
            SVector::from([-2.0 + t, 0.2 + b, 1.0, db])
        })
        .collect();
    let u = (0..steps)
        .map(|i| {
            let (_, _, ddb) = y((i as f64 + 0.5) * h / t_end);
            SVector::from([0.0, ddb])
        })
        .collect();
    (x, u)
}

/// The double pendulum of the swing-up suite (`../shared/BENCHMARKS.md`): unit masses and
/// rods, gravity `g`, $L = \frac12 |\tau|^2$ of the joint torques.
#[higher_order_lagrangian(order = 2)]
pub fn double_pendulum(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    let c2 = q[1].cos();
    let s2 = q[1].sin();
    let m11 = 3.0 + 2.0 * c2;
    let m12 = 1.0 + c2;
    let g1 = 2.0 * g * q[0].sin() + g * (q[0] + q[1]).sin();
    let g2 = g * (q[0] + q[1]).sin();
    let tau1 = m11 * ddq[0] + m12 * ddq[1] - s2 * (2.0 * dq[0] * dq[1] + dq[1] * dq[1]) + g1;
    let tau2 = m12 * ddq[0] + ddq[1] + s2 * dq[0] * dq[0] + g2;
    0.5 * (tau1 * tau1 + tau2 * tau2)
}
