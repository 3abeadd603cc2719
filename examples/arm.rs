//! Minimum-torque motion of a planar two-link arm: L = 1/2 |tau|^2 with the joint torques
//! tau = M(q) q'' + c(q, q') + g(q) (inertia matrix, Coriolis/centrifugal terms, gravity).
//! L is quadratic in q'' with a configuration-dependent Hessian M(q)^T M(q), so the generated
//! Legendre inverse is a 2x2 solve. The midpoint rule integrates the optimality conditions
//! from an initial jet; the example prints a table and plots joint angles and torques.
//!
//! Parameters: a = I1 + I2 + m2 l1^2 = 3, b = m2 l1 lc2 = 1, d = I2 = 1.2,
//! g1 = (m1 lc1 + m2 l1) g = 2, g2 = m2 lc2 g = 0.7.
//! Initial jet: q = (-0.5, 1.0), q' = (0.8, -0.5), q'' = (0.2, 0.1), q''' = (0, 0).
//!
//! Run: `cargo run --release --example arm [figure.svg]` (default `docs/arm.svg`).

mod common;

use retract::diagnostics::energy_error;
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::plot::{self, Scale};
use retract::{Lagrangian, LiftedSystem, StepOptions, trajectory};

/// Joint torques tau = M(q) q'' + c(q, q') + g(q) of the two-link arm.
#[allow(clippy::too_many_arguments)]
fn torques(
    q: [f64; 2],
    dq: [f64; 2],
    ddq: [f64; 2],
    a: f64,
    b: f64,
    d: f64,
    g1: f64,
    g2: f64,
) -> [f64; 2] {
    let (c2, s2) = (q[1].cos(), q[1].sin());
    let (m11, m12, m22) = (a + 2.0 * b * c2, d + b * c2, d);
    let c1 = -b * s2 * (2.0 * dq[0] * dq[1] + dq[1].powi(2));
    let cc2 = b * s2 * dq[0].powi(2);
    let gr1 = g1 * q[0].cos() + g2 * (q[0] + q[1]).cos();
    let gr2 = g2 * (q[0] + q[1]).cos();
    [
        m11 * ddq[0] + m12 * ddq[1] + c1 + gr1,
        m12 * ddq[0] + m22 * ddq[1] + cc2 + gr2,
    ]
}

/// The minimum-torque Lagrangian, 1/2 |tau|^2, written out for the macro.
#[higher_order_lagrangian(order = 2)]
fn arm(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], a: f64, b: f64, d: f64, g1: f64, g2: f64) -> f64 {
    let c2 = q[1].cos();
    let s2 = q[1].sin();
    let m11 = a + 2.0 * b * c2;
    let m12 = d + b * c2;
    let t1 = m11 * ddq[0] + m12 * ddq[1] - b * s2 * (2.0 * dq[0] * dq[1] + dq[1].powi(2))
        + g1 * q[0].cos()
        + g2 * (q[0] + q[1]).cos();
    let t2 = m12 * ddq[0] + d * ddq[1] + b * s2 * dq[0].powi(2) + g2 * (q[0] + q[1]).cos();
    0.5 * (t1 * t1 + t2 * t2)
}

const H: f64 = 0.01;
const STEPS: usize = 200;

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let figure = std::env::args()
        .nth(1)
        .map(Into::into)
        .unwrap_or_else(|| common::docs_path("arm.svg"));
    let (a, b, d, g1, g2) = (3.0, 1.0, 1.2, 2.0, 0.7);
    let system = Arm { a, b, d, g1, g2 };
    let jet = SVector::<f64, 8>::from_column_slice(&[-0.5, 1.0, 0.8, -0.5, 0.2, 0.1, 0.0, 0.0]);
    let z0 = system.legendre(&jet);
    let run = trajectory(&system, &z0, H, STEPS, &StepOptions::default())?;
    let mut angles = [Vec::new(), Vec::new()];
    let mut torque = [Vec::new(), Vec::new()];
    println!("| t | q1 | q2 | tau1 | tau2 |");
    println!("|---|---|---|---|---|");
    for (i, z) in run.states.iter().enumerate() {
        let t = i as f64 * H;
        let (x, p) = retract::lifted::split::<2, 2, 8>(z);
        let u = system.top_derivative(&x, &p[1], &p[1])?;
        let tau = torques([z[0], z[1]], [z[2], z[3]], [u[0], u[1]], a, b, d, g1, g2);
        for j in 0..2 {
            angles[j].push((t, z[j]));
            torque[j].push((t, tau[j]));
        }
        if i % 40 == 0 {
            println!(
                "| {t:.1} | {:.5} | {:.5} | {:.5} | {:.5} |",
                z[0], z[1], tau[0], tau[1]
            );
        }
    }
    println!(
        "\nNewton iterations max / mean: {} / {:.2}; max |H - H(0)|: {:.2e}",
        run.max_iterations(),
        run.mean_iterations(),
        energy_error(&system, &run.states)?
    );
    let [q1, q2] = angles;
    let [t1, t2] = torque;
    plot::panels(
        &figure,
        "Minimum-torque two-link arm, midpoint rule, h = 0.01",
        "t",
        &[
            (
                "joint angle [rad]",
                vec![plot::Curve::new("q1", q1), plot::Curve::new("q2", q2)],
            ),
            (
                "torque",
                vec![plot::Curve::new("tau1", t1), plot::Curve::new("tau2", t2)],
            ),
        ],
        Scale::Linear,
    )?;
    println!("figure: {}", figure.display());
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
