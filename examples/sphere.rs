//! Riemannian cubics on the sphere S^2: L = 1/2 |D_t q'|^2 written in ambient coordinates
//! (`#[higher_order_lagrangian(order = 2, sphere)]`), and Riemannian polynomials of order 3,
//! L = 1/2 |D_t^2 q'|^2 (`order = 3`).
//!
//! 1. Initial-value problems: the paper's maps of S^2 in moving gnomonic charts
//!    (`retract::sphere`) against the midpoint rule in one fixed chart (what a chart-based
//!    code does), all against an RK4 solution of the embedded Euler-Lagrange equation
//!    (`examples/common/sphere_cubic.rs`, `sphere_poly3.rs`): error at T, invariants and time
//!    per step, for k = 2 and k = 3.
//! 2. Invariants over a long run: | |q| - 1 |, q . q', the Noether momentum and the energy.
//! 3. A boundary-value problem with the optimizer: the cubic between two points of the
//!    equator with given velocities, free and around a keep-out cap (a hard constraint
//!    `#[jet_function(order = 2, sphere)]`), drawn to `docs/sphere.svg`.
//!
//! Run: `cargo run --release --example sphere [-- figure.svg]`

mod common;
#[path = "common/sphere_cubic.rs"]
mod sphere_cubic;
#[path = "common/sphere_poly3.rs"]
mod sphere_poly3;

use std::time::Instant;

use retract::bvp::{OptimalControlProblem, Plan, PlanGuess, PlanOptions};
use retract::nalgebra::{SVector, Vector2, Vector3};
use retract::plot;
use retract::sphere::{
    self, Chart, ExponentialMidpoint, ProjectionInitial, ProjectionMidpoint, SphereMap,
    SphereState, SphereSystem,
};
use retract::{Lagrangian, LiftedSystem, NewtonOptions, StepOptions, step};
use sphere_cubic::{Cubic, OutsideCap, on_equator};
use sphere_poly3::Poly3;

/// One run: the final point, the largest momentum change and the time per step in
/// microseconds.
struct Run {
    point: Vector3<f64>,
    momentum_drift: f64,
    us_per_step: f64,
}

/// An initial-value problem on the sphere: the system, the ambient jet
/// (q, ..., q^(2k-1)) at t = 0 and the final time.
struct Ivp<'a, Sys> {
    system: Sys,
    jet: &'a [Vector3<f64>],
    t: f64,
}

/// `steps` steps to T with a map of S^2 in moving charts (best time of 3 runs).
fn moving<Sys, Map, const K: usize, const S: usize, const M: usize>(
    ivp: &Ivp<'_, Sys>,
    map: &Map,
    steps: usize,
) -> Run
where
    Sys: SphereSystem + Lagrangian<2, K> + LiftedSystem<S, M>,
    Map: SphereMap<K>,
{
    let start = SphereState::<K, S>::from_ambient(&ivp.system, ivp.jet).expect("on the sphere");
    let (h, options) = (ivp.t / steps as f64, NewtonOptions::default());
    let mut best = f64::INFINITY;
    let mut state = start;
    let mut drift: f64 = 0.0;
    for _ in 0..3 {
        let clock = Instant::now();
        state = start;
        drift = 0.0;
        for _ in 0..steps {
            state = sphere::step(&ivp.system, map, &state, h, &options)
                .expect("step")
                .0;
            drift = drift.max((state.momentum() - start.momentum()).amax());
        }
        best = best.min(clock.elapsed().as_secs_f64());
    }
    Run {
        point: state.point(),
        momentum_drift: drift,
        us_per_step: best / steps as f64 * 1e6,
    }
}

/// `steps` steps to T with the built-in midpoint rule in the gnomonic chart centred at the
/// start point (no chart change); the momentum is not a quantity of this scheme.
fn fixed_chart<Sys, const S: usize, const M: usize>(ivp: &Ivp<'_, Sys>, steps: usize) -> Run
where
    Sys: SphereSystem + LiftedSystem<S, M>,
{
    let chart = Chart::at(&ivp.jet[0]).expect("a point");
    let system = ivp.system.with_chart(chart.params());
    let mut jet = [Vector3::zeros(); 6];
    jet[..S / 2].copy_from_slice(ivp.jet);
    let y = chart.coordinates(&jet).expect("in the chart");
    let z0 = system.legendre(&SVector::<f64, S>::from_fn(|r, _| y[r / 2][r % 2]));
    let (h, options) = (ivp.t / steps as f64, StepOptions::default());
    let mut best = f64::INFINITY;
    let mut z = z0;
    for _ in 0..3 {
        let clock = Instant::now();
        z = z0;
        for _ in 0..steps {
            z = step(&system, &z, h, &options).expect("step").0;
        }
        best = best.min(clock.elapsed().as_secs_f64());
    }
    Run {
        point: chart.point(&Vector2::new(z[0], z[1])),
        momentum_drift: f64::NAN,
        us_per_step: best / steps as f64 * 1e6,
    }
}

/// The table of one initial-value problem: every map in moving charts and the midpoint rule
/// in one fixed chart, for each step count of `sweep`, against the point `exact` at T.
fn print_ivp_table<Sys, const K: usize, const S: usize, const M: usize>(
    ivp: &Ivp<'_, Sys>,
    exact: &Vector3<f64>,
    sweep: &[usize],
) where
    Sys: SphereSystem + Lagrangian<2, K> + LiftedSystem<S, M>,
    ProjectionMidpoint: SphereMap<K>,
    ExponentialMidpoint: SphereMap<K>,
    ProjectionInitial: SphereMap<K>,
{
    println!("| method | N | error | observed order | momentum drift | us/step |");
    println!("|---|---|---|---|---|---|");
    let methods: [(&str, &dyn Fn(usize) -> Run); 4] = [
        ("projection midpoint", &|n| {
            moving(ivp, &ProjectionMidpoint, n)
        }),
        ("exponential midpoint", &|n| {
            moving(ivp, &ExponentialMidpoint, n)
        }),
        ("projection initial point", &|n| {
            moving(ivp, &ProjectionInitial, n)
        }),
        ("midpoint in one fixed chart", &|n| fixed_chart(ivp, n)),
    ];
    for (name, method) in methods {
        let mut previous: Option<f64> = None;
        for &steps in sweep {
            let run = method(steps);
            let error = (run.point - exact).norm();
            let order =
                previous.map_or(String::from("-"), |p| format!("{:.2}", (p / error).log2()));
            let drift = if run.momentum_drift.is_nan() {
                String::from("n/a")
            } else {
                format!("{:.1e}", run.momentum_drift)
            };
            println!(
                "| {name} | {steps} | {error:.2e} | {order} | {drift} | {:.2} |",
                run.us_per_step
            );
            previous = Some(error);
        }
    }
}

/// The IVP tables: the Riemannian cubic (k = 2) to T = 1 and the Riemannian polynomial of
/// order 3 (k = 3, maps lifted at run time) to T = 0.5.
fn print_ivp_tables() {
    let cubic_jet = sphere_cubic::jet(sphere_cubic::data());
    let exact = sphere_cubic::reference(sphere_cubic::data(), 1.0, 100_000)[0];
    println!("Riemannian cubic, T = 1, error |q(T) - q_ref(T)| (reference: RK4 of the embedded");
    println!(
        "Euler-Lagrange equation, 10^5 steps), momentum drift max|m_i - m_0|, time per step:\n"
    );
    let cubic = Ivp {
        system: Cubic::new(),
        jet: &cubic_jet,
        t: 1.0,
    };
    print_ivp_table(&cubic, &exact, &[10, 20, 40, 80, 160]);
    let poly_jet = sphere_poly3::jet(sphere_poly3::data());
    let exact = sphere_poly3::reference(sphere_poly3::data(), 0.5, 100_000)[0];
    println!(
        "\nRiemannian polynomial of order 3 (k = 3), T = 0.5, the same columns (reference: RK4"
    );
    println!("of D_t^5 V + R(D_t^3 V, V) V - R(D_t^2 V, D_t V) V = 0, 10^5 steps):\n");
    let poly = Ivp {
        system: Poly3::new(),
        jet: &poly_jet,
        t: 0.5,
    };
    print_ivp_table(&poly, &exact, &[10, 20, 40, 80]);
}

/// 10^6 steps of the geodesic flow-free cubic at h = 10^-4 (T = 100) with the projection
/// midpoint map: the largest | |q| - 1 |, |q . q'|, momentum change and energy change.
fn print_invariants() {
    let jet = sphere_cubic::jet(sphere_cubic::data());
    let system = Cubic::new();
    let mut state = SphereState::<2, 8>::from_ambient(&system, &jet).expect("on the sphere");
    let (m0, e0) = (
        state.momentum(),
        state.hamiltonian(&system).expect("finite"),
    );
    let options = NewtonOptions::default();
    let mut worst = [0.0_f64; 4];
    let steps = 1_000_000;
    for _ in 0..steps {
        state = sphere::step(&system, &ProjectionMidpoint, &state, 1e-4, &options)
            .expect("step")
            .0;
        let [q, dq] = state.ambient_jet();
        let energy = state.hamiltonian(&system).expect("finite");
        worst[0] = worst[0].max((q.norm() - 1.0).abs());
        worst[1] = worst[1].max(q.dot(&dq).abs());
        worst[2] = worst[2].max((state.momentum() - m0).amax() / m0.norm());
        worst[3] = worst[3].max((energy - e0).abs() / e0.abs());
    }
    println!("\nInvariants over {steps} steps of h = 1e-4 (projection midpoint, T = 100):\n");
    println!("| max abs(abs(q) - 1) | max abs(q . q') | momentum, relative | energy, relative |");
    println!("|---|---|---|---|");
    println!(
        "| {:.1e} | {:.1e} | {:.1e} | {:.1e} |",
        worst[0], worst[1], worst[2], worst[3]
    );
}

/// The cubic from 60 degrees west to 60 degrees east on the equator (speed 0.5 east at both
/// ends), T = 2, N = 80, in the chart centred between them, with the inequality `cap`.
fn plan(chart: &Chart, cap: Option<&OutsideCap>) -> (Plan<2, 4>, f64) {
    let system = Cubic::new().with_chart(chart.params());
    let boundary = |jet: [Vector3<f64>; 2]| {
        let [y, dy] = chart.coordinates(&jet).expect("in the chart");
        [y[0], y[1], dy[0], dy[1]]
    };
    let (start, goal) = (
        boundary(on_equator(-60.0, 0.5)),
        boundary(on_equator(60.0, 0.5)),
    );
    let charted = cap.map(|c| c.with_chart(chart.params()));
    let mut problem = OptimalControlProblem::new(&system, &start, &goal, 2.0, 80)
        .with_options(PlanOptions::default().with_min_eigenvalue(true));
    if let Some(c) = &charted {
        problem = problem.with_inequality(c);
    }
    let clock = Instant::now();
    let plan = problem
        .solve(PlanGuess::Spline)
        .expect("a certified minimum");
    (plan, clock.elapsed().as_secs_f64() * 1e3)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    print_ivp_tables();
    print_invariants();

    let chart = Chart::at(&Vector3::x())?;
    let axis = Vector3::new(1.0, 0.0, 5f64.to_radians().tan()).normalize();
    let radius = 20f64.to_radians();
    let cap = OutsideCap::new(axis.into(), radius.cos());
    println!("\nBoundary problem: from 60 W to 60 E on the equator, T = 2, N = 80, optimizer:\n");
    println!(
        "| problem | J | iterations | time_ms | min_reduced_hessian_eig | closest to the cap |"
    );
    println!("|---|---|---|---|---|---|");
    let mut curves = Vec::new();
    for (name, constraint) in [("free", None), ("around the cap", Some(&cap))] {
        let (plan, ms) = plan(&chart, constraint);
        let points: Vec<[f64; 3]> = plan
            .x
            .iter()
            .map(|x| chart.point(&Vector2::new(x[0], x[1])).into())
            .collect();
        let closest = points
            .iter()
            .map(|p| {
                Vector3::from(*p)
                    .dot(&axis)
                    .clamp(-1.0, 1.0)
                    .acos()
                    .to_degrees()
            })
            .fold(f64::INFINITY, f64::min);
        println!(
            "| {name} | {:.6} | {} | {ms:.1} | {:.2e} | {closest:.2} deg (radius 20) |",
            plan.cost, plan.iterations, plan.certificate.min_reduced_hessian_eig
        );
        curves.push((format!("{name}: J = {:.3}", plan.cost), points));
    }
    let path = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| common::docs_path("sphere.svg"));
    plot::sphere(
        &path,
        "Riemannian cubics on S^2 from 60 W to 60 E: free and around a keep-out cap",
        [1.0, -0.25, 0.45],
        &curves,
        &[(axis.into(), radius)],
    )?;
    println!("\nfigure: {}", path.display());
    Ok(())
}
