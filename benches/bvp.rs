//! Boundary-value solve time against the number of steps N (expected linear), and the
//! warm-started re-solve after a shift by one step (receding horizon). SE(2) scene with one
//! disc, T = 4, residual tolerance 1e-10, from the spline guess.
//!
//! First a table timed in one run (best of repeated solves): the reduced condensed solve
//! (`solve_reduced`) for N = 100 .. 3200, the three linear solvers at N = 400 as ratios, and
//! the warm re-solve; then criterion. Run: `cargo bench --bench bvp`.

use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use retract::bvp::{BoundaryValueProblem, BvpOptions, Guess, LinearSolver};
use retract::higher_order_lagrangian;

#[higher_order_lagrangian(order = 2)]
fn scene(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, obstacles: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2));
    for o in obstacles {
        l += tau / ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]);
    }
    l
}

const OBSTACLES: [[f64; 3]; 1] = [[0.0, -0.6, 1.0]];
const START: [f64; 6] = [-2.0, 0.5, 0.0, 0.0, 0.0, 0.0];
const GOAL: [f64; 6] = [2.0, 0.5, 1.0, 0.0, 0.0, 0.0];

/// Best wall time in milliseconds over `repeats` calls.
fn best_ms<T>(repeats: usize, mut f: impl FnMut() -> T) -> f64 {
    (0..repeats)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(f());
            t.elapsed().as_secs_f64() * 1e3
        })
        .fold(f64::INFINITY, f64::min)
}

fn print_table(system: &Scene<'_>) {
    // warm-up for about a second: the first solves of a run are slower (clock, caches)
    let problem = BoundaryValueProblem::new(system, &START, &GOAL, 4.0, 400);
    let start = Instant::now();
    while start.elapsed().as_secs_f64() < 1.0 {
        std::hint::black_box(problem.solve_reduced(Guess::Spline).map(|s| s.cost)).ok();
    }
    println!("\nSE(2), one disc, T = 4, to residual 1e-10 from the spline guess:");
    println!("| N | Newton iterations | solve_reduced |");
    println!("|---|---|---|");
    for steps in [100, 200, 400, 800, 1600, 3200] {
        let problem = BoundaryValueProblem::new(system, &START, &GOAL, 4.0, steps);
        let s = problem.solve_reduced(Guess::Spline).expect("solvable");
        let ms = best_ms(20, || problem.solve_reduced(Guess::Spline).map(|s| s.cost));
        println!("| {steps} | {} | {ms:.2} ms |", s.iterations);
    }
    let problem = |solver| {
        BoundaryValueProblem::new(system, &START, &GOAL, 4.0, 400)
            .with_options(BvpOptions::default().with_linear_solver(solver))
    };
    let reduced = best_ms(20, || {
        problem(LinearSolver::Condensed).solve_reduced(Guess::Spline)
    });
    let condensed = best_ms(20, || problem(LinearSolver::Condensed).solve(Guess::Spline));
    let banded = best_ms(20, || problem(LinearSolver::Banded).solve(Guess::Spline));
    println!("\nN = 400, the linear solvers (ratio = time / solve_reduced):");
    for (name, ms) in [
        ("condensed, reduced step maps (solve_reduced)", reduced),
        ("condensed, dense step maps (solve)", condensed),
        ("banded LU of the whole Jacobian", banded),
    ] {
        println!("  {name:<46} {ms:>7.2} ms  {:>5.1}x", ms / reduced);
    }
    let cold = problem(LinearSolver::Condensed)
        .solve_reduced(Guess::Spline)
        .expect("solvable");
    let shifted = cold.shifted(system);
    let start: Vec<f64> = shifted.states[0].as_slice()[..6].to_vec();
    let warm = BoundaryValueProblem::new(system, &start, &GOAL, 4.0, 400);
    let s = warm
        .solve_reduced(Guess::Solution(&shifted))
        .expect("solvable");
    let ms = best_ms(20, || warm.solve_reduced(Guess::Solution(&shifted)));
    println!(
        "\nwarm re-solve after a shift by one step, N = 400: {} Newton iterations, {ms:.2} ms\n",
        s.iterations
    );
}

fn solve(c: &mut Criterion) {
    let system = Scene {
        tau: 0.05,
        obstacles: &OBSTACLES,
    };
    print_table(&system);
    let mut group = c.benchmark_group("bvp");
    group.sample_size(10);
    for steps in [100, 200, 400, 800, 1600, 3200] {
        let problem = BoundaryValueProblem::new(&system, &START, &GOAL, 4.0, steps);
        group.bench_function(
            BenchmarkId::new("solve_reduced", format!("se2_obstacle_N{steps}")),
            |b| b.iter(|| problem.solve_reduced(Guess::Spline).map(|s| s.cost)),
        );
    }
    let problem = BoundaryValueProblem::new(&system, &START, &GOAL, 4.0, 400);
    group.bench_function(BenchmarkId::new("solve", "se2_obstacle_N400"), |b| {
        b.iter(|| problem.solve(Guess::Spline).map(|s| s.cost))
    });
    let cold = problem.solve_reduced(Guess::Spline).expect("solvable");
    let shifted = cold.shifted(&system);
    let start: Vec<f64> = shifted.states[0].as_slice()[..6].to_vec();
    let warm = BoundaryValueProblem::new(&system, &start, &GOAL, 4.0, 400);
    group.bench_function(BenchmarkId::new("warm_resolve", "se2_obstacle_N400"), |b| {
        b.iter(|| {
            warm.solve_reduced(Guess::Solution(&shifted))
                .map(|s| s.cost)
        })
    });
    group.finish();
}

criterion_group!(benches, solve);
criterion_main!(benches);
