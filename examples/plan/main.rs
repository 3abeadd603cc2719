//! Optimal-control planning for a planar rigid body on the SE(2) chart (x, y, theta) among
//! disc obstacles: minimise int 1/2 |q''|^2 + sum_j tau / (|(x, y) - c_j|^2 - r_j^2) dt with
//! position and velocity given at both ends. The obstacles are a run-time list (a slice
//! parameter of the generated Lagrangian), so one compiled planner serves every scene.
//!
//! Scene files (TOML, parsed strictly and checked by `scene.rs`: an unknown key or a value
//! out of range is an error naming the key, and the example exits with status 1):
//!
//! ```toml
//! horizon = 4.0            # T (at least 0.01)
//! steps = 400              # N (h = T / N)
//! barrier = 1e-2           # tau of the final solve
//! continuation = [1.0, 0.1] # optional: barrier weights solved first, each a warm start
//! [start]                  # q(0) and q'(0): (x, y, theta)
//! position = [-2.0, 0.3, 0.0]
//! velocity = [1.0, 0.0, 0.0]
//! [goal]                   # q(T) and q'(T)
//! position = [2.0, 0.3, 1.57]
//! velocity = [1.0, 0.0, 0.0]
//! [[obstacles]]            # any number of discs (`center` is accepted for `centre`)
//! centre = [0.0, 0.0]
//! radius = 1.0
//! ```
//!
//! The first guess is the cubic Hermite path between the boundary data, pushed around every
//! disc it would cross: away from the centre, or, for a disc centred on the path, to the left
//! of the direction of travel (a deterministic choice). The optimizer solves the barrier
//! weights in turn, each warm-started from the plan of the last, and returns only certified
//! local minima; its line search never steps into a disc, where the barrier has its pole.
//!
//! Run: `cargo run --release --example plan [scene.toml] [figure.svg]`
//! (defaults: `examples/scenes/slalom.toml`, `docs/plan.svg`).

#[path = "../common/mod.rs"]
mod common;
mod scene;

use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;

use retract::bvp::{Curve, OptimalControlProblem, Plan, PlanGuess};
use retract::higher_order_lagrangian;
use retract::nalgebra::Vector2;
use retract::plot;
use scene::Scene;

/// The planner's Lagrangian: minimum acceleration plus a barrier per disc (cx, cy, r).
#[higher_order_lagrangian(order = 2)]
fn planar_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, obstacles: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2));
    for o in obstacles {
        l += tau / ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]);
    }
    l
}

/// Cubic Hermite interpolation of (position, velocity) at 0 and T, component `i`.
fn hermite(scene: &Scene, i: usize, t: f64) -> f64 {
    let (t_end, s) = (scene.horizon, t / scene.horizon);
    let (p0, v0) = (scene.start.position[i], scene.start.velocity[i] * t_end);
    let (p1, v1) = (scene.goal.position[i], scene.goal.velocity[i] * t_end);
    let (s2, s3) = (s * s, s * s * s);
    (2.0 * s3 - 3.0 * s2 + 1.0) * p0
        + (s3 - 2.0 * s2 + s) * v0
        + (-2.0 * s3 + 3.0 * s2) * p1
        + (s3 - s2) * v1
}

/// The guessed path: the Hermite path plus a smooth push away from each disc it would cross.
fn guess_path(scene: &Scene) -> impl Fn(f64) -> [f64; 3] + '_ {
    let t_end = scene.horizon;
    let at = |t: f64| Vector2::new(hermite(scene, 0, t), hermite(scene, 1, t));
    let mut pushes = Vec::new();
    for o in &scene.obstacles {
        let c = Vector2::new(o.centre[0], o.centre[1]);
        let (t_near, d) = (0..=1000)
            .map(|i| {
                let t = i as f64 * t_end / 1000.0;
                (t, (at(t) - c).norm())
            })
            .fold(
                (0.0, f64::INFINITY),
                |best, x| if x.1 < best.1 { x } else { best },
            );
        let wanted = o.radius * 1.4;
        if d >= wanted {
            continue;
        }
        let away = at(t_near) - c;
        let direction = if away.norm() > 1e-9 {
            away.normalize()
        } else {
            let v = (at(t_near + 1e-3) - at(t_near - 1e-3)).normalize();
            Vector2::new(-v[1], v[0]) // left of the direction of travel
        };
        let speed = ((at(t_near + 1e-3) - at(t_near - 1e-3)) / 2e-3)
            .norm()
            .max(1e-3);
        let width = 1.5 * wanted / speed;
        pushes.push((t_near, width, direction * (wanted - d)));
    }
    move |t: f64| {
        let mut q = [
            hermite(scene, 0, t),
            hermite(scene, 1, t),
            hermite(scene, 2, t),
        ];
        let window = (std::f64::consts::PI * t / t_end).sin().powi(2);
        for &(t_near, width, push) in &pushes {
            let bump = (-((t - t_near) / width).powi(2)).exp() * window;
            q[0] += push[0] * bump;
            q[1] += push[1] * bump;
        }
        q
    }
}

fn run() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let scene_path: PathBuf = args.next().map_or_else(
        || concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/slalom.toml").into(),
        Into::into,
    );
    let figure = args
        .next()
        .map(Into::into)
        .unwrap_or_else(|| common::docs_path("plan.svg"));
    let scene = scene::load(&scene_path)?;
    let discs: Vec<[f64; 3]> = scene
        .obstacles
        .iter()
        .map(|o| [o.centre[0], o.centre[1], o.radius])
        .collect();
    let (start, goal) = (scene.start.jet(), scene.goal.jet());
    let guess = Curve::from_fn(guess_path(&scene));
    let weights: Vec<f64> = scene
        .continuation
        .iter()
        .copied()
        .chain([scene.barrier])
        .collect();

    // each barrier weight warm-started from the plan of the last, the first from the guess
    let started = Instant::now();
    let mut plan: Option<Plan<3, 6>> = None;
    for &tau in &weights {
        let system = PlanarBody {
            tau,
            obstacles: &discs,
        };
        let problem =
            OptimalControlProblem::new(&system, &start, &goal, scene.horizon, scene.steps);
        let guess = plan
            .as_ref()
            .map_or(PlanGuess::Curve(&guess), PlanGuess::Plan);
        plan = Some(problem.solve(guess).map_err(|e| e.to_string())?);
    }
    let elapsed = started.elapsed();
    let plan = plan.ok_or("no barrier weight")?;

    println!("scene: {}", scene_path.display());
    println!(
        "T = {}, N = {}, barrier weights {:?}, {} obstacles",
        scene.horizon,
        scene.steps,
        weights,
        discs.len()
    );
    println!("cost J = {:.6}", plan.cost);
    for (j, d) in discs.iter().enumerate() {
        let clearance = plan
            .x
            .iter()
            .map(|x| (x[0] - d[0]).hypot(x[1] - d[1]) - d[2])
            .fold(f64::INFINITY, f64::min);
        println!("min clearance to obstacle {j} (at the nodes): {clearance:.4}");
    }
    let certificate = &plan.certificate;
    println!(
        "iterations (last solve): {}, stationarity {:.1e}, smallest reduced-Hessian eigenvalue \
         {:.2e}, total solve time {elapsed:.1?}",
        plan.iterations, certificate.stationarity, certificate.min_reduced_hessian_eig
    );
    let path = plot::Curve::new(
        "optimal path",
        plan.x.iter().map(|x| (x[0], x[1])).collect(),
    );
    let times = plan.times();
    let path_of_guess = guess_path(&scene);
    let first = plot::Curve::new(
        "first guess",
        times
            .iter()
            .map(|&t| (path_of_guess(t)[0], path_of_guess(t)[1]))
            .collect(),
    );
    let circles: Vec<(f64, f64, f64)> = discs.iter().map(|d| (d[0], d[1], d[2])).collect();
    plot::plane(
        &figure,
        "Optimal-control plan (SE(2), midpoint rule)",
        &[path, first],
        &circles,
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
