//! Speed against error, with figures.
//!
//! 1. The paper's obstacle IVP to T = 4: final error against wall time for `retract`'s
//!    implicit compositions and explicit splittings and for RK4 and DOP853 on the plain
//!    first-order system (`retract_validation::work_precision`, which lists the methods).
//!    Prints `work-precision 1e-8: best=..., DOP853 ..., ratio ...` (over the guarded
//!    methods) and `work-precision 1e-8 without the guard: ...`.
//! 2. The bounded Pais-Uhlenbeck oscillator over 10^6 midpoint steps of h = 0.1
//!    (T = 10^5): max |H - H(0)| so far against time at matched cost
//!    (`retract_validation::long_run`).
//! 3. The Riemannian cubic on S^2: the largest geodesic distance to the exact cubic against
//!    the time of building the curve, for `retract` (order 2 and extrapolated) and the
//!    adjusted geodesic de Casteljau construction (`retract_validation::sphere_cubic`).
//!
//! Writes docs/work_precision.svg, docs/energy_long_run.svg and docs/sphere_cubic.svg and
//! prints the tables (the same as `examples/report.rs` prints, which has every other speed
//! figure too).
//! Run: `cargo run --release -p retract-validation --example work_precision`

#[path = "../../examples/common/mod.rs"]
mod common;

use retract::plot::{self, Scale};
use retract_validation::report::Size;
use retract_validation::{long_run, sphere_cubic, work_precision};

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// Writes the log-log figure `name` under docs/ (one panel of `curves`, axes labelled
/// `labels` = (x, y)) and prints its path.
fn log_figure(
    name: &str,
    title: &str,
    labels: (&str, &str),
    curves: Vec<plot::Curve>,
) -> Result<()> {
    let figure = common::docs_path(name);
    plot::panels(&figure, title, labels.0, &[(labels.1, curves)], Scale::Log)?;
    println!("\nfigure: {}", figure.display());
    Ok(())
}

/// The obstacle IVP's sweeps, the times at 1e-8 and the figure.
fn obstacle_ivp(size: &Size) -> Result<()> {
    let ivp = work_precision::Ivp::paper();
    let (reference, distance) = work_precision::reference(&ivp)?;
    println!("Obstacle IVP to T = 4; reference: order-8 composition, 4000 steps");
    println!("(its distance to DOP853 at tol 1e-14: {distance:.1e})\n");
    let sweeps = work_precision::sweeps(
        &ivp,
        &work_precision::series()?,
        &reference,
        size.sweep_rounds,
    );
    let mut out = std::io::stdout();
    work_precision::write_sweeps(&mut out, &sweeps)?;
    let at = work_precision::at_target(&sweeps, 1e-8);
    work_precision::write_at_target(&mut out, &at, size.sweep_rounds)?;
    let curves = sweeps
        .iter()
        .map(|s| plot::Curve::new(s.label, s.curve()))
        .collect();
    log_figure(
        "work_precision.svg",
        "Obstacle IVP to T = 4: final error against wall time",
        ("wall time [s]", "max-norm error at T"),
        curves,
    )
}

/// The long run's table and figure.
fn long_run(size: &Size) -> Result<()> {
    let runs = long_run::long_runs(size.long_run_end)?;
    long_run::write_long_runs(&mut std::io::stdout(), &runs, size.long_run_end)?;
    let curves = runs
        .into_iter()
        .map(|r| plot::Curve::new(r.name, r.record))
        .collect();
    log_figure(
        "energy_long_run.svg",
        "Pais-Uhlenbeck: max |H - H(0)| up to time t, matched cost",
        ("t", "max energy error"),
        curves,
    )
}

/// The cubic on S^2: its table and the figure of error against time.
fn sphere(size: &Size) -> Result<()> {
    let result = sphere_cubic::run(&mut std::io::stdout(), size.planner_rounds)?;
    let curve = |label: &str, points: &[sphere_cubic::Point]| {
        let xy = points.iter().map(|p| (p.time_ns * 1e-9, p.error)).collect();
        plot::Curve::new(label, xy)
    };
    let curves = vec![
        curve("retract, order 2", &result.retract),
        curve("retract, extrapolated (N, 2N, 4N)", &result.extrapolated),
        curve("geodesic de Casteljau", &result.decasteljau),
    ];
    log_figure(
        "sphere_cubic.svg",
        "Riemannian cubic on S^2: error against the time of building the curve",
        ("time [s]", "max geodesic distance to the exact cubic"),
        curves,
    )
}

fn main() {
    let size = Size::full();
    let all = obstacle_ivp(&size)
        .and_then(|()| long_run(&size))
        .and_then(|()| sphere(&size));
    if let Err(e) = all {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
