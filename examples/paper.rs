//! The paper's Sec. 6 experiment: a planar rigid body on the SE(2) chart q = (x, y, theta)
//! avoiding the unit disc, L = 1/2 |q''|^2 + tau / (x^2 + y^2 - r^2), r = 1, N = 400 steps of
//! h = 0.01 with the lifted midpoint rule, for the paper's tau = 1e-20 and for tau = 1e-2.
//!
//! Initial data (the paper gives none): q(0) = (-2, 1.05, 0), q'(0) = (1, 0, 0.5),
//! q''(0) = q'''(0) = 0. The body heads along +x, aimed to pass 0.05 above the disc while
//! turning at 0.5 rad/s. With tau = 1e-20 the barrier is invisible in double precision
//! (it matters only within about 1e-10 of the circle) and the path is the free straight line;
//! with tau = 1e-2 the barrier visibly bends it away from the disc.
//!
//! Run: `cargo run --release --example paper [figure.svg]` (default `docs/paper.svg`).

mod common;

use std::time::Instant;

use retract::diagnostics::{energy_error, symplecticity_error};
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::plot;
use retract::{LiftedSystem, ReducedStepper, StepOptions, trajectory};

/// The obstacle-avoidance Lagrangian on the SE(2) chart.
#[higher_order_lagrangian(order = 2)]
fn rigid_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
        + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

const STEPS: usize = 400;
const H: f64 = 0.01;
const RADIUS: f64 = 1.0;
/// Derivative data (q, q', q'', q''') at t = 0.
const JET: [f64; 12] = [
    -2.0, 1.05, 0.0, // q
    1.0, 0.0, 0.5, // q'
    0.0, 0.0, 0.0, // q''
    0.0, 0.0, 0.0, // q'''
];

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let figure = std::env::args()
        .nth(1)
        .map(Into::into)
        .unwrap_or_else(|| common::docs_path("paper.svg"));
    println!("SE(2) obstacle avoidance, r = {RADIUS}, N = {STEPS}, h = {H}, midpoint rule\n");
    println!(
        "| tau | final (x, y, theta) | min clearance | max abs(H - H0) | max symplecticity err. | Newton it. max / mean | wall time, general | wall time, reduced |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    let mut curves = Vec::new();
    for tau in [1e-20, 1e-2] {
        let system = RigidBody { tau, r: RADIUS };
        let z0 = system.legendre(&SVector::from_column_slice(&JET));
        let options = StepOptions::default();
        let started = Instant::now();
        let run = trajectory(&system, &z0, H, STEPS, &options)?;
        let elapsed = started.elapsed();
        // the same run on the generated reduced step (Newton on the 2 core unknowns)
        let started = Instant::now();
        let fast = ReducedStepper::new(&system).trajectory(&z0, H, STEPS, &options)?;
        let elapsed_reduced = started.elapsed();
        let agreement = (fast.states[STEPS] - run.states[STEPS]).amax();
        if agreement > 1e-10 {
            return Err(format!("reduced and general runs differ by {agreement:e}").into());
        }
        let clearance = run
            .states
            .iter()
            .map(|z| z[0].hypot(z[1]) - RADIUS)
            .fold(f64::INFINITY, f64::min);
        let mut symplecticity: f64 = 0.0;
        for z in &run.states[..STEPS] {
            symplecticity = symplecticity.max(symplecticity_error(&system, z, H, &options)?);
        }
        let last = run.states[STEPS];
        println!(
            "| {tau:.0e} | ({:.5}, {:.5}, {:.5}) | {clearance:.4} | {:.2e} | {symplecticity:.1e} | {} / {:.2} | {elapsed:.1?} | {elapsed_reduced:.1?} |",
            last[0],
            last[1],
            last[2],
            energy_error(&system, &run.states)?,
            run.max_iterations(),
            run.mean_iterations(),
        );
        curves.push(plot::Curve::new(
            format!("tau = {tau:.0e}"),
            run.states.iter().map(|z| (z[0], z[1])).collect(),
        ));
    }
    plot::plane(
        &figure,
        "SE(2) obstacle avoidance, midpoint rule, N = 400, h = 0.01",
        &curves,
        &[(0.0, 0.0, RADIUS)],
    )?;
    println!("\nfigure: {}", figure.display());
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
