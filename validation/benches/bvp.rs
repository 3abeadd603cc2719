//! Boundary-value solve time against the number of steps N (expected linear), the
//! warm-started re-solve after a shift by one step (receding horizon), and the optimizer
//! (`OptimalControlProblem`) against the root finder (`solve_reduced`).
//!
//! First a table timed in one run (best of repeated solves): the reduced condensed solve
//! (`solve_reduced`) on the SE(2) scene (one disc, T = 4, residual tolerance 1e-10, from the
//! spline guess) for N = 100 .. 3200, the three linear solvers at N = 400 as ratios, and the
//! warm re-solve. Then the optimizer against the root finder, timed interleaved (the two
//! alternate round by round, best of `ROUNDS` each, so a change of machine speed hits both):
//! the one-disc scene of `../shared/BENCHMARKS.md` from its bump guess and the SE(2) scene
//! from the spline guess, cold and warm (after a shift by one step), with the iteration counts
//! and the costs both reach. Then criterion. Run: `cargo bench -p retract-validation --bench bvp`.

use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use retract::LiftedSystem;
use retract::bvp::{
    BoundaryValueProblem, BvpOptions, Guess, LinearSolver, OptimalControlProblem, PlanGuess,
    PlanOptions,
};
use retract::nalgebra::SVector;
use retract_validation::models::{DISC_GOAL, DISC_START, OneDisc, Scene};

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

const DISC_T: f64 = 4.0;
const DISC_STEPS: usize = 400;

/// Rounds of the interleaved optimizer / root-finder timings (best of this many each).
const ROUNDS: usize = 25;

/// The root finder's states, the optimizer's jets and its top derivatives.
type BumpGuess = (
    Vec<SVector<f64, 8>>,
    Vec<SVector<f64, 4>>,
    Vec<SVector<f64, 2>>,
);

/// The one-disc scene's feasible guess: the Hermite cubic between the boundary jets (here the
/// straight line at unit speed) plus the bump 1.3 * 16 s^2 (1 - s)^2 in y, s = t / T. Returns
/// the root finder's states z_i = (x_i, p_i) (the Legendre map of the guess's derivative data
/// (q, q', q'', q''') at t_i) and the optimizer's jets x_i = (q, q')(t_i) and top derivatives
/// u_i = q'' at the step midpoints.
fn bump_guess(system: &OneDisc, steps: usize) -> BumpGuess {
    let h = DISC_T / steps as f64;
    // the bump and its first three derivatives in t
    let bump = |t: f64| {
        let (s, c) = (t / DISC_T, 1.3 * 16.0);
        [
            c * s * s * (1.0 - s).powi(2),
            c * (2.0 * s - 6.0 * s * s + 4.0 * s.powi(3)) / DISC_T,
            c * (2.0 - 12.0 * s + 12.0 * s * s) / DISC_T.powi(2),
            c * (-12.0 + 24.0 * s) / DISC_T.powi(3),
        ]
    };
    // (q, q', q'', q''') in blocks of 2
    let derivatives = |t: f64| {
        let b = bump(t);
        SVector::<f64, 8>::from([-2.0 + t, 0.2 + b[0], 1.0, b[1], 0.0, b[2], 0.0, b[3]])
    };
    let times = (0..=steps).map(|i| i as f64 * h);
    let states = times
        .clone()
        .map(|t| system.legendre(&derivatives(t)))
        .collect();
    let x = times
        .map(|t| derivatives(t).fixed_rows::<4>(0).into_owned())
        .collect();
    let u = (0..steps)
        .map(|i| SVector::from([0.0, bump((i as f64 + 0.5) * h)[2]]))
        .collect();
    (states, x, u)
}

/// Wall time in milliseconds of one call.
fn time_ms<T>(f: &mut impl FnMut() -> T) -> f64 {
    let t = Instant::now();
    std::hint::black_box(f());
    t.elapsed().as_secs_f64() * 1e3
}

/// The optimizer against the root finder on one problem: `optimizer` and `root` each solve it
/// and return (iterations, cost). Timed interleaved, best of `ROUNDS` each (which one goes
/// first alternates too); prints a line of times and one of costs, returns the ratio
/// optimizer / root finder.
fn race(
    label: &str,
    mut optimizer: impl FnMut() -> (usize, f64),
    mut root: impl FnMut() -> (usize, f64),
) -> f64 {
    let (opt_iterations, opt_cost) = optimizer();
    let (root_iterations, root_cost) = root();
    let (mut opt_ms, mut root_ms) = (f64::INFINITY, f64::INFINITY);
    for round in 0..ROUNDS {
        if round % 2 == 0 {
            opt_ms = opt_ms.min(time_ms(&mut optimizer));
            root_ms = root_ms.min(time_ms(&mut root));
        } else {
            root_ms = root_ms.min(time_ms(&mut root));
            opt_ms = opt_ms.min(time_ms(&mut optimizer));
        }
    }
    let ratio = opt_ms / root_ms;
    println!(
        "{label}: optimizer {opt_ms:.2} ms ({opt_iterations} it), root finder {root_ms:.2} ms \
         ({root_iterations} it), ratio {ratio:.2}x"
    );
    let difference = (opt_cost - root_cost).abs() / root_cost.abs();
    println!(
        "{label}: cost optimizer {opt_cost:.12}, root finder {root_cost:.12}, relative \
         difference {difference:.1e}"
    );
    assert!(
        difference < 1e-8,
        "{label}: the two solvers reach different costs"
    );
    ratio
}

/// The one-disc scene (N = 400) from the bump guess, cold and warm; returns the cold and warm
/// ratios.
fn race_one_disc() -> (f64, f64) {
    let system = OneDisc { tau: 1e-2 };
    let (states, x, u) = bump_guess(&system, DISC_STEPS);
    let optimizer =
        OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, DISC_T, DISC_STEPS);
    let root = BoundaryValueProblem::new(&system, &DISC_START, &DISC_GOAL, DISC_T, DISC_STEPS);
    let opt_cold = || {
        optimizer
            .solve(PlanGuess::Path { x: &x, u: &u })
            .expect("the optimizer solves the one-disc scene")
    };
    let root_cold = || {
        root.solve_reduced(Guess::States(&states))
            .expect("the root finder solves the one-disc scene")
    };
    let label = format!("one-disc N={DISC_STEPS}");
    let cold = race(
        &format!("{label} cold"),
        || {
            let p = opt_cold();
            (p.iterations, p.cost)
        },
        || {
            let s = root_cold();
            (s.iterations, s.cost)
        },
    );
    // receding horizon: each solver's solution shifted by one step, its first jet the new
    // start, the goal, T and N fixed
    let plan = opt_cold().shifted();
    let solution = root_cold().shifted(&system);
    let opt_start: [f64; 4] = plan.x[0].into();
    let root_start = solution.states[0].fixed_rows::<4>(0).into_owned();
    let opt_warm = OptimalControlProblem::new(&system, &opt_start, &DISC_GOAL, DISC_T, DISC_STEPS);
    let root_warm = BoundaryValueProblem::new(
        &system,
        root_start.as_slice(),
        &DISC_GOAL,
        DISC_T,
        DISC_STEPS,
    );
    let warm = race(
        &format!("{label} warm"),
        || {
            let p = opt_warm
                .solve(PlanGuess::Plan(&plan))
                .expect("the optimizer re-solves the one-disc scene");
            (p.iterations, p.cost)
        },
        || {
            let s = root_warm
                .solve_reduced(Guess::Solution(&solution))
                .expect("the root finder re-solves the one-disc scene");
            (s.iterations, s.cost)
        },
    );
    (cold, warm)
}

/// The SE(2) scene (N = 400) from the spline guess, cold and warm; returns the cold and warm
/// ratios.
fn race_se2(system: &Scene<'_>) -> (f64, f64) {
    let optimizer = OptimalControlProblem::new(system, &START, &GOAL, 4.0, 400);
    let root = BoundaryValueProblem::new(system, &START, &GOAL, 4.0, 400);
    let cold = race(
        "se2 N=400 cold",
        || {
            let p = optimizer
                .solve(PlanGuess::Spline)
                .expect("the optimizer solves the SE(2) scene");
            (p.iterations, p.cost)
        },
        || {
            let s = root
                .solve_reduced(Guess::Spline)
                .expect("the root finder solves the SE(2) scene");
            (s.iterations, s.cost)
        },
    );
    let plan = optimizer
        .solve(PlanGuess::Spline)
        .expect("solvable")
        .shifted();
    let solution = root
        .solve_reduced(Guess::Spline)
        .expect("solvable")
        .shifted(system);
    let opt_start: [f64; 6] = plan.x[0].into();
    let root_start = solution.states[0].fixed_rows::<6>(0).into_owned();
    let opt_warm = OptimalControlProblem::new(system, &opt_start, &GOAL, 4.0, 400);
    let root_warm = BoundaryValueProblem::new(system, root_start.as_slice(), &GOAL, 4.0, 400);
    let warm = race(
        "se2 N=400 warm",
        || {
            let p = opt_warm
                .solve(PlanGuess::Plan(&plan))
                .expect("the optimizer re-solves the SE(2) scene");
            (p.iterations, p.cost)
        },
        || {
            let s = root_warm
                .solve_reduced(Guess::Solution(&solution))
                .expect("the root finder re-solves the SE(2) scene");
            (s.iterations, s.cost)
        },
    );
    (cold, warm)
}

/// The optimizer against the root finder on both scenes, cold and warm.
fn print_comparison(system: &Scene<'_>) {
    println!(
        "the optimizer against the root finder (solve_reduced) at N = 400, interleaved, best \
         of {ROUNDS} each; ratio = optimizer / root finder:"
    );
    let (disc_cold, disc_warm) = race_one_disc();
    let (se2_cold, se2_warm) = race_se2(system);
    println!(
        "ratios: one-disc cold {disc_cold:.2}x, warm {disc_warm:.2}x; se2 cold {se2_cold:.2}x, \
         warm {se2_warm:.2}x (target <= 1.2)\n"
    );
}

/// Richardson extrapolation on the one-disc scene: for N = 40, 50, 100 the time of
/// `solve_extrapolated` (best of 10) and its cost error against an extrapolation at N = 400
/// solved to 1e-10 (the reference), with the error estimate.
fn print_extrapolation() {
    let system = OneDisc { tau: 1e-2 };
    let extrapolate = |steps: usize, tolerance: f64| {
        let (_, x, u) = bump_guess(&system, steps);
        OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, DISC_T, steps)
            .with_options(PlanOptions::default().with_tolerance(tolerance))
            .solve_extrapolated(PlanGuess::Path { x: &x, u: &u })
            .expect("the one-disc scene extrapolates")
    };
    let reference = extrapolate(400, 1e-10);
    println!("one-disc Richardson extrapolation (N, 2N, 4N), against N = 400 extrapolated:");
    for steps in [40, 50, 100] {
        let e = extrapolate(steps, 1e-9);
        let ms = best_ms(10, || extrapolate(steps, 1e-9).cost);
        let momentum_error = (e.momenta[0] - reference.momenta[0]).amax();
        println!(
            "extrapolated N={steps}: J={:.12} cost error {:.1e} (estimate {:.1e}), p(0) error \
             {momentum_error:.1e}, iterations {:?}, time {ms:.2} ms",
            e.cost,
            (e.cost - reference.cost).abs() / reference.cost,
            e.cost_error / reference.cost,
            e.iterations()
        );
    }
    println!();
}

fn solve(c: &mut Criterion) {
    let system = Scene {
        tau: 0.05,
        obstacles: &OBSTACLES,
    };
    print_table(&system);
    print_comparison(&system);
    print_extrapolation();
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
    let optimizer = OptimalControlProblem::new(&system, &START, &GOAL, 4.0, 400);
    group.bench_function(BenchmarkId::new("optimize", "se2_obstacle_N400"), |b| {
        b.iter(|| optimizer.solve(PlanGuess::Spline).map(|p| p.cost))
    });
    let plan = optimizer
        .solve(PlanGuess::Spline)
        .expect("solvable")
        .shifted();
    let start: [f64; 6] = plan.x[0].into();
    let warm = OptimalControlProblem::new(&system, &start, &GOAL, 4.0, 400);
    group.bench_function(
        BenchmarkId::new("optimize_warm", "se2_obstacle_N400"),
        |b| b.iter(|| warm.solve(PlanGuess::Plan(&plan)).map(|p| p.cost)),
    );
    let disc = OneDisc { tau: 1e-2 };
    let (states, x, u) = bump_guess(&disc, DISC_STEPS);
    let root = BoundaryValueProblem::new(&disc, &DISC_START, &DISC_GOAL, DISC_T, DISC_STEPS);
    group.bench_function(BenchmarkId::new("solve_reduced", "one_disc_N400"), |b| {
        b.iter(|| root.solve_reduced(Guess::States(&states)).map(|s| s.cost))
    });
    let optimizer = OptimalControlProblem::new(&disc, &DISC_START, &DISC_GOAL, DISC_T, DISC_STEPS);
    group.bench_function(BenchmarkId::new("optimize", "one_disc_N400"), |b| {
        b.iter(|| {
            optimizer
                .solve(PlanGuess::Path { x: &x, u: &u })
                .map(|p| p.cost)
        })
    });
    group.finish();
}

criterion_group!(benches, solve);
criterion_main!(benches);
