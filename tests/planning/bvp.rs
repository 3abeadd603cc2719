//! The optimal-control boundary-value solver: exactness on splines up to O(h^2),
//! self-convergence with obstacles, agreement with shooting, and hard cases that end in
//! convergence or a typed error (never NaN, never a panic).

use crate::common;

use common::largest_gap;
use common::models::Scene;
use retract::bvp::root_finder::{
    BoundaryValueProblem, BvpOptions, BvpSolution, Guess, LinearSolver, continuation,
};
use retract::higher_order_lagrangian;
use retract::nalgebra::{DMatrix, DVector, SVector};
use retract::{Error, StepOptions, trajectory};

/// Minimum jerk in R^2 (quintic splines).
#[higher_order_lagrangian(order = 3)]
fn jerk(_q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], dddq: [f64; 2]) -> f64 {
    0.5 * (dddq[0].powi(2) + dddq[1].powi(2))
}

type Sol = BvpSolution<12, 15>;

/// Signed distance of (x, y) to each disc.
fn clearance_of(obstacles: &[[f64; 3]]) -> impl Fn(&SVector<f64, 12>, &mut [f64]) + '_ {
    move |z, out| {
        for (o, c) in obstacles.iter().zip(out.iter_mut()) {
            *c = (z[0] - o[0]).hypot(z[1] - o[1]) - o[2];
        }
    }
}

fn solve_scene(
    obstacles: &[[f64; 3]],
    tau: f64,
    start: &[f64; 6],
    goal: &[f64; 6],
    t_end: f64,
    steps: usize,
) -> Result<Sol, Error> {
    let system = Scene { tau, obstacles };
    let clearance = clearance_of(obstacles);
    BoundaryValueProblem::new(&system, start, goal, t_end, steps)
        .with_clearance(obstacles.len(), &clearance)
        .solve(Guess::Spline)
}

fn assert_sane(solution: &Sol) {
    assert!(
        solution.residual_norm <= 1e-10,
        "residual {:e}",
        solution.residual_norm
    );
    assert!(
        solution
            .states
            .iter()
            .all(|z| z.iter().all(|v| v.is_finite()))
    );
    assert!(solution.cost.is_finite());
    assert!(
        solution.clearance.iter().all(|&c| c >= 0.0),
        "{:?}",
        solution.clearance
    );
}

/// The quintic (k = 3) Hermite interpolant's value at t per component, from (q, q', q'') at
/// 0 and T, via a dense solve (independent of the solver's own spline code).
fn quintic(a: &[f64], b: &[f64], t_end: f64, t: f64, component: usize) -> f64 {
    let n = 2;
    let row = |t: f64, j: usize| -> Vec<f64> {
        (0..6)
            .map(|m| {
                if m < j {
                    0.0
                } else {
                    let f: f64 = ((m - j + 1)..=m).map(|v| v as f64).product();
                    f * t.powi((m - j) as i32)
                }
            })
            .collect()
    };
    let mut rows = Vec::new();
    let mut rhs = Vec::new();
    for j in 0..3 {
        rows.extend(row(0.0, j));
        rhs.push(a[j * n + component]);
        rows.extend(row(t_end, j));
        rhs.push(b[j * n + component]);
    }
    let m = DMatrix::from_row_slice(6, 6, &rows);
    let c = m.lu().solve(&DVector::from_vec(rhs)).unwrap();
    (0..6).map(|i| c[i] * t.powi(i as i32)).sum()
}

#[test]
fn without_potential_the_solution_is_the_interpolating_spline_up_to_h2() {
    let start = [0.0, 0.0, 1.0, 0.5, 0.0, 0.2];
    let goal = [1.0, 2.0, 0.0, -0.5, 0.3, 0.0];
    let t_end = 2.0;
    let errors: Vec<f64> = [20, 40, 80]
        .iter()
        .map(|&steps| {
            let s = BoundaryValueProblem::new(&Jerk {}, &start, &goal, t_end, steps)
                .solve(Guess::Spline)
                .unwrap();
            assert!(s.residual_norm < 1e-10);
            s.states
                .iter()
                .enumerate()
                .map(|(i, z)| {
                    let t = i as f64 * s.h;
                    (0..2)
                        .map(|c| (z[c] - quintic(&start, &goal, t_end, t, c)).abs())
                        .fold(0.0, f64::max)
                })
                .fold(0.0, f64::max)
        })
        .collect();
    assert!(
        errors[0] > 1e-8,
        "the scheme is not exact on quintics: {errors:?}"
    );
    for e in errors.windows(2) {
        let order = (e[0] / e[1]).log2();
        assert!((1.9..2.1).contains(&order), "order {order} from {errors:?}");
    }
}

const ONE_DISC: [[f64; 3]; 1] = [[0.0, -0.6, 1.0]];
const START: [f64; 6] = [-2.0, 0.5, 0.0, 0.0, 0.0, 0.0];
const GOAL: [f64; 6] = [2.0, 0.5, 1.0, 0.0, 0.0, 0.0];

#[test]
fn obstacle_solution_converges_at_order_two_as_n_doubles() {
    let solutions: Vec<Sol> = [50, 100, 200, 400]
        .iter()
        .map(|&n| solve_scene(&ONE_DISC, 0.05, &START, &GOAL, 4.0, n).unwrap())
        .collect();
    for s in &solutions {
        assert_sane(s);
    }
    // the barrier bends the path up, away from the straight line y = 0.5
    assert!(
        solutions[3].states[200][1] > 0.55,
        "{}",
        solutions[3].states[200][1]
    );
    // differences at the common times t = 0, 0.08, ...
    let diffs: Vec<f64> = solutions
        .windows(2)
        .map(|pair| {
            (0..=50)
                .map(|i| {
                    (pair[0].states[i * (pair[0].states.len() - 1) / 50]
                        - pair[1].states[i * (pair[1].states.len() - 1) / 50])
                        .amax()
                })
                .fold(0.0, f64::max)
        })
        .collect();
    for d in diffs.windows(2) {
        let order = (d[0] / d[1]).log2();
        assert!(
            (1.8..2.2).contains(&order),
            "self-convergence order {order} from {diffs:?}"
        );
    }
}

#[test]
fn initial_momenta_agree_with_shooting() {
    // Shooting: find p(0) such that N steps of the same scheme from (a, p(0)) reach x = b.
    let obstacles = ONE_DISC;
    let system = Scene {
        tau: 0.05,
        obstacles: &obstacles,
    };
    let (t_end, steps) = (1.0, 40);
    let start = [-1.5, 0.5, 0.0, 1.0, 0.2, 0.0];
    let goal = [-0.4, 0.9, 0.3, 1.0, 0.0, 0.0];
    let bvp = BoundaryValueProblem::new(&system, &start, &goal, t_end, steps)
        .solve(Guess::Spline)
        .unwrap();
    let h = t_end / steps as f64;
    let end_of = |p: &DVector<f64>| -> DVector<f64> {
        let mut z0 = SVector::<f64, 12>::zeros();
        z0.as_mut_slice()[..6].copy_from_slice(&start);
        z0.as_mut_slice()[6..].copy_from_slice(p.as_slice());
        let run = trajectory(&system, &z0, h, steps, &StepOptions::default()).unwrap();
        DVector::from_iterator(6, (0..6).map(|j| run.states[steps][j] - goal[j]))
    };
    let mut p = DVector::<f64>::zeros(6);
    for _ in 0..30 {
        let f = end_of(&p);
        if f.amax() < 1e-11 {
            break;
        }
        let jac = DMatrix::from_fn(6, 6, |r, c| {
            let eps = 1e-6;
            let (mut plus, mut minus) = (p.clone(), p.clone());
            plus[c] += eps;
            minus[c] -= eps;
            (end_of(&plus)[r] - end_of(&minus)[r]) / (2.0 * eps)
        });
        p -= jac.lu().solve(&f).unwrap();
    }
    assert!(end_of(&p).amax() < 1e-9, "shooting did not converge");
    let from_bvp = &bvp.states[0].as_slice()[6..];
    for c in 0..6 {
        assert!(
            (from_bvp[c] - p[c]).abs() < 1e-7,
            "p0[{c}]: bvp {} shooting {}",
            from_bvp[c],
            p[c]
        );
    }
}

#[test]
fn cost_is_the_quadrature_of_the_lagrangian() {
    // V = 0, k = 2 on a straight line at constant speed: q'' = 0, so J = 0; with
    // acceleration the cost is positive.
    let start = [-2.0, 0.5, 0.0, 1.0, 0.0, 0.0];
    let still = solve_scene(&[], 0.0, &start, &[2.0, 0.5, 0.0, 1.0, 0.0, 0.0], 4.0, 40).unwrap();
    assert!(still.cost.abs() < 1e-20, "{}", still.cost);
    let moving = solve_scene(&[], 0.0, &START, &GOAL, 4.0, 40).unwrap();
    assert!(moving.cost > 0.0);
}

#[test]
fn warm_started_receding_horizon_needs_few_iterations() {
    let cold = solve_scene(&ONE_DISC, 0.05, &START, &GOAL, 4.0, 200).unwrap();
    let obstacles = ONE_DISC;
    let system = Scene {
        tau: 0.05,
        obstacles: &obstacles,
    };
    let shifted = cold.shifted(&system);
    let new_start: Vec<f64> = shifted.states[0].as_slice()[..6].to_vec();
    let new_goal: Vec<f64> = shifted.states[200].as_slice()[..6].to_vec();
    let warm = BoundaryValueProblem::new(&system, &new_start, &new_goal, 4.0, 200)
        .solve(Guess::Solution(&shifted))
        .unwrap();
    assert!(
        warm.iterations <= 1,
        "warm start took {} iterations",
        warm.iterations
    );
    assert!(cold.iterations >= 2);
}

#[test]
fn continuation_in_the_barrier_weight() {
    let obstacles = ONE_DISC;
    let clearance = clearance_of(&obstacles);
    let solution = continuation(
        |tau| Scene {
            tau,
            obstacles: &obstacles,
        },
        &[1.0, 0.3, 0.1, 0.03, 0.01],
        &START,
        &GOAL,
        4.0,
        200,
        BvpOptions::default(),
        Some((1, &clearance)),
        Guess::Spline,
    )
    .unwrap();
    assert_sane(&solution);
    let direct = solve_scene(&ONE_DISC, 0.01, &START, &GOAL, 4.0, 200).unwrap();
    let diff = largest_gap(&solution.states, &direct.states);
    assert!(
        diff < 1e-8,
        "continuation and direct solve differ by {diff:e}"
    );
}

// ---- hard cases: convergence or a typed error, never NaN or a panic -----------------------

fn converged_or_typed(result: &Result<Sol, Error>) {
    match result {
        Ok(s) => assert_sane(s),
        Err(e) => assert!(!e.to_string().is_empty()),
    }
}

#[test]
fn narrow_gap_between_two_obstacles() {
    let obstacles = [[0.0, 1.15, 1.0], [0.0, -1.15, 1.0]];
    let r = solve_scene(
        &obstacles,
        1e-3,
        &[-3.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        &[3.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        6.0,
        300,
    );
    converged_or_typed(&r);
    let s = r.expect("the gap is wide enough for this barrier weight");
    assert!(
        s.clearance.iter().all(|&c| c > 0.0 && c < 0.16),
        "{:?}",
        s.clearance
    );
}

#[test]
fn start_a_thousandth_from_a_barrier() {
    let obstacles = [[0.0, 0.0, 1.0]];
    let start = [-1.001, 0.0, 0.0, 0.0, 1.0, 0.0];
    let r = solve_scene(
        &obstacles,
        1e-3,
        &start,
        &[-3.0, 2.0, 0.0, -1.0, 0.0, 0.0],
        3.0,
        300,
    );
    converged_or_typed(&r);
    let s = r.expect("a start outside the disc is a valid problem");
    assert!(s.clearance[0] > 0.0 && s.clearance[0] <= 1e-3 + 1e-12);
}

#[test]
fn symmetric_scene_through_the_centre_is_reported() {
    // The straight path (and the spline guess) goes through the disc centre: the solver
    // cannot choose a side by itself, and a stationary point inside the disc is not a plan.
    let obstacles = [[0.0, 0.0, 1.0]];
    let r = solve_scene(
        &obstacles,
        1e-2,
        &[-3.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        &[3.0, 0.0, 0.0, 1.0, 0.0, 0.0],
        6.0,
        300,
    );
    converged_or_typed(&r);
    match r {
        Err(Error::GuessThroughObstacle {
            obstacle: 0,
            clearance,
            ..
        }) => assert!(clearance < 0.0),
        Err(other) => panic!("expected GuessThroughObstacle, got {other}"),
        Ok(s) => panic!(
            "a solution through the centre was returned: {:?}",
            s.clearance
        ),
    }
}

#[test]
fn long_horizon() {
    let obstacles = ONE_DISC;
    let r = solve_scene(
        &obstacles,
        0.05,
        &START,
        &[2.0, 0.5, 0.0, 0.0, 0.0, 0.0],
        20.0,
        2000,
    );
    converged_or_typed(&r);
    assert_sane(&r.unwrap());
}

#[test]
fn invalid_boundary_data_is_rejected() {
    let obstacles = ONE_DISC;
    let system = Scene {
        tau: 0.05,
        obstacles: &obstacles,
    };
    let short = [0.0; 5];
    let e = BoundaryValueProblem::new(&system, &short, &GOAL, 4.0, 40).solve(Guess::Spline);
    assert!(matches!(e, Err(Error::InvalidArgument { .. })));
    let nan = [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0];
    let e = BoundaryValueProblem::new(&system, &nan, &GOAL, 4.0, 40).solve(Guess::Spline);
    assert!(matches!(e, Err(Error::InvalidArgument { .. })));
    let e = BoundaryValueProblem::new(&system, &START, &GOAL, 4.0, 0).solve(Guess::Spline);
    assert!(matches!(e, Err(Error::InvalidArgument { .. })));
}

/// The three ways to the Newton direction (condensed through dense step maps, condensed
/// through the reduced step's factors, banded LU of the whole Jacobian) give the same
/// iterates: the same iteration count and the same plan, on the scenes above.
#[test]
fn linear_solvers_agree() {
    // (obstacles, tau, start, goal, T, N)
    type Case<'a> = (&'a [[f64; 3]], f64, [f64; 6], [f64; 6], f64, usize);
    let scenes: [Case<'_>; 3] = [
        (&ONE_DISC, 0.05, START, GOAL, 4.0, 200),
        (
            &[[0.0, 1.15, 1.0], [0.0, -1.15, 1.0]],
            1e-3,
            [-3.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [3.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            6.0,
            300,
        ),
        (
            &ONE_DISC,
            0.05,
            START,
            [2.0, 0.5, 0.0, 0.0, 0.0, 0.0],
            20.0,
            2000,
        ),
    ];
    for (obstacles, tau, start, goal, t_end, steps) in scenes {
        let system = Scene { tau, obstacles };
        let problem = |solver| {
            BoundaryValueProblem::new(&system, &start, &goal, t_end, steps)
                .with_options(BvpOptions::default().with_linear_solver(solver))
        };
        let condensed = problem(LinearSolver::Condensed)
            .solve(Guess::Spline)
            .expect("condensed");
        let reduced = problem(LinearSolver::Condensed)
            .solve_reduced(Guess::Spline)
            .expect("reduced");
        let banded = problem(LinearSolver::Banded)
            .solve(Guess::Spline)
            .expect("banded");
        for other in [&reduced, &banded] {
            assert_eq!(other.iterations, condensed.iterations);
            let gap = largest_gap(&condensed.states, &other.states);
            assert!(gap < 1e-9, "T = {t_end}: solutions differ by {gap:e}");
            assert!((other.cost - condensed.cost).abs() < 1e-9 * condensed.cost.abs());
        }
    }
}

/// A converged solution whose step crosses a pole of L between its nodes is refused with the
/// step named (the guard of every step, as a step runs it), not returned as a plan: a small
/// disc between the nodes of a coarse transcription (N = 4 and 6, whose guesses and
/// solutions keep every node outside it; before, both were returned as plans).
#[test]
fn a_solution_through_a_pole_between_its_nodes_is_refused() {
    let (start, goal) = (
        [-2.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    );
    for (steps, crossing) in [(4, 2), (6, 3)] {
        match solve_scene(&[[0.7, 0.02, 0.2]], 1e-3, &start, &goal, 4.0, steps) {
            Err(error @ Error::SolutionOutsideDomain { step, .. }) => {
                assert_eq!(step, crossing);
                let violation = error.violation().expect("the violation");
                assert_eq!(violation.kind, retract::DomainKind::Denominator);
                assert_eq!(violation.element, Some(0));
                assert!(
                    error.to_string().contains(&format!("step {crossing} ")),
                    "{error}"
                );
            }
            other => panic!("N = {steps}: {other:?}"),
        }
    }
}
