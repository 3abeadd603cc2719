//! Boundary-value solve time against the number of steps N (expected linear), and the
//! warm-started re-solve after a shift by one step (receding horizon). SE(2) scene with one
//! disc, T = 4, residual tolerance 1e-10, from the spline guess.
//! Run: `cargo bench --bench bvp`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use retract::bvp::{BoundaryValueProblem, Guess};
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

fn solve(c: &mut Criterion) {
    let system = Scene {
        tau: 0.05,
        obstacles: &OBSTACLES,
    };
    let mut group = c.benchmark_group("bvp");
    group.sample_size(10);
    for steps in [100, 200, 400, 800, 1600, 3200] {
        let problem = BoundaryValueProblem::new(&system, &START, &GOAL, 4.0, steps);
        let s = problem.solve(Guess::Spline).expect("solvable");
        eprintln!(
            "N = {steps}: {} Newton iterations, residual {:.1e}",
            s.iterations, s.residual_norm
        );
        group.bench_function(
            BenchmarkId::new("solve", format!("se2_obstacle_N{steps}")),
            |b| b.iter(|| problem.solve(Guess::Spline).map(|s| s.cost)),
        );
    }
    let steps = 400;
    let cold = BoundaryValueProblem::new(&system, &START, &GOAL, 4.0, steps)
        .solve(Guess::Spline)
        .expect("solvable");
    let shifted = cold.shifted(&system);
    let start: Vec<f64> = shifted.states[0].as_slice()[..6].to_vec();
    let warm = BoundaryValueProblem::new(&system, &start, &GOAL, 4.0, steps);
    let s = warm.solve(Guess::Solution(&shifted)).expect("solvable");
    eprintln!(
        "warm re-solve N = {steps}: {} Newton iterations",
        s.iterations
    );
    group.bench_function(BenchmarkId::new("warm_resolve", "se2_obstacle_N400"), |b| {
        b.iter(|| warm.solve(Guess::Solution(&shifted)).map(|s| s.cost))
    });
    group.finish();
}

criterion_group!(benches, solve);
criterion_main!(benches);
