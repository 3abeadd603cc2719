//! Minimum-acceleration (k = 2), minimum-jerk (k = 3) and minimum-snap (k = 4) splines in
//! R^3: L = 1/2 |q^(k)|^2, whose exact solutions are polynomials of degree 2k - 1. The
//! midpoint rule integrates them from the jet at t = 0 to t = 1; the table shows the error
//! against the exact polynomial and the observed order (2: the scheme is not exact on
//! splines, its cubic term is h^3/4 instead of h^3/6).
//!
//! Run: `cargo run --release --example splines`

use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, trajectory};

#[higher_order_lagrangian(order = 2)]
fn acceleration(_q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3]) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
}

#[higher_order_lagrangian(order = 3)]
fn jerk(_q: [f64; 3], _dq: [f64; 3], _ddq: [f64; 3], dddq: [f64; 3]) -> f64 {
    0.5 * (dddq[0].powi(2) + dddq[1].powi(2) + dddq[2].powi(2))
}

#[higher_order_lagrangian(order = 4)]
fn snap(_q: [f64; 3], _dq: [f64; 3], _ddq: [f64; 3], _dddq: [f64; 3], d4q: [f64; 3]) -> f64 {
    0.5 * (d4q[0].powi(2) + d4q[1].powi(2) + d4q[2].powi(2))
}

/// The jet at t of the polynomial q(t) = sum_m jet_m t^m / m! (blocks of 3).
fn exact_jet<const S: usize>(jet: &SVector<f64, S>, t: f64) -> SVector<f64, S> {
    let orders = S / 3;
    SVector::from_fn(|r, _| {
        let (j, i) = (r / 3, r % 3);
        let (mut v, mut factor) = (0.0, 1.0);
        for m in 0..orders - j {
            if m > 0 {
                factor *= t / m as f64;
            }
            v += jet[(j + m) * 3 + i] * factor;
        }
        v
    })
}

/// Prints error and observed order at t = 1 for N = 10, 20, 40, 80, 160.
fn sweep<Sys, const S: usize, const M: usize>(
    name: &str,
    system: &Sys,
) -> Result<(), retract::Interrupted<S>>
where
    Sys: LiftedSystem<S, M>,
{
    let jet = SVector::<f64, S>::from_fn(|r, _| ((r * 7 + 3) % 11) as f64 / 11.0 - 0.5);
    let z0 = system.legendre(&jet);
    let exact = system.legendre(&exact_jet(&jet, 1.0));
    let mut previous: Option<f64> = None;
    for steps in [10, 20, 40, 80, 160] {
        let run = trajectory(
            system,
            &z0,
            1.0 / steps as f64,
            steps,
            &StepOptions::default(),
        )?;
        let error = (run.states[steps] - exact).amax();
        let q_error = (run.states[steps].fixed_rows::<3>(0) - exact.fixed_rows::<3>(0)).amax();
        let order = previous.map_or(String::from("-"), |p| format!("{:.3}", (p / error).log2()));
        println!("| {name} | {steps:>3} | {q_error:.3e} | {error:.3e} | {order} |");
        previous = Some(error);
    }
    Ok(())
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    println!("| spline | N | error in q(1) | error in z(1) | observed order |");
    println!("|---|---|---|---|---|");
    sweep("k = 2 (cubic)", &Acceleration {})?;
    sweep("k = 3 (quintic)", &Jerk {})?;
    sweep("k = 4 (degree 7)", &Snap {})?;
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
