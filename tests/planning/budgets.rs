//! The optimizer's budgets: a wall-time budget that holds at a large N (returning the iterate
//! reached with `TimeLimit`), and a workspace that cannot fit refused before allocating.

use std::time::{Duration, Instant};

use retract::Error;
use retract::bvp::{Failure, OptimalControlProblem, PlanGuess, PlanOptions};
use retract::higher_order_lagrangian;

/// Six coupled pendula driven at their accelerations: L = 1/2 sum_j (q_j'' + sin(q_j) +
/// q_j q_{j+1})^2 (q_7 = 0).
#[higher_order_lagrangian(order = 2)]
fn six_pendula(q: [f64; 6], _dq: [f64; 6], ddq: [f64; 6]) -> f64 {
    let t0 = ddq[0] + q[0].sin() + q[0] * q[1];
    let t1 = ddq[1] + q[1].sin() + q[1] * q[2];
    let t2 = ddq[2] + q[2].sin() + q[2] * q[3];
    let t3 = ddq[3] + q[3].sin() + q[3] * q[4];
    let t4 = ddq[4] + q[4].sin() + q[4] * q[5];
    let t5 = ddq[5] + q[5].sin();
    0.5 * (t0 * t0 + t1 * t1 + t2 * t2 + t3 * t3 + t4 * t4 + t5 * t5)
}

fn six_pendula_problem(
    system: &SixPendula,
    steps: usize,
) -> OptimalControlProblem<'_, SixPendula, 6, 2, 12> {
    let mut goal = [0.0; 12];
    goal[..6].fill(1.0);
    OptimalControlProblem::new(system, &[0.0; 12], &goal, 2.0, steps)
}

/// A 200 ms budget at N = 65 536 (where one model build and factorisation take about as
/// long): the solve returns the iterate it reached, as `TimeLimit`, within twice the budget.
/// (The clock is read between phases and every 1024 steps inside the long ones.)
#[test]
fn a_time_budget_holds_at_65536_steps() {
    let budget = Duration::from_millis(200);
    let start = Instant::now();
    let error = six_pendula_problem(&SixPendula::new(), 65_536)
        .with_options(PlanOptions::default().with_max_time(budget))
        .solve(PlanGuess::Spline)
        .unwrap_err();
    let elapsed = start.elapsed();
    assert_eq!(error.failure, Failure::TimeLimit, "{error}");
    let last = error.last.as_ref().expect("the iterate reached");
    assert_eq!((last.x.len(), last.u.len()), (65_537, 65_536));
    assert!(
        elapsed <= 2 * budget,
        "{elapsed:?} for a budget of {budget:?}"
    );
}

/// The planar effort 1/2 |q''|^2.
#[higher_order_lagrangian(order = 2)]
fn planar_effort(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1])
}

/// A budget that runs out while the first iterate's models are built (a zero budget at 4096
/// steps: the clock is read every 1024 steps of the build): the attached iterate is the first
/// guess with its cost and feasibility, not NaN. The guess is the smoothstep from 0 to
/// d = (1, -2) over T = 2: u_i = q''(t_i + h/2) = d (6 - 12 s) / T^2 gives J = sum h/2 |u_i|^2,
/// and the trapezoidal position update misses the cubic by h^3 |q'''| / 12 = h^3 |d| / T^3 at
/// every step (the velocity update is exact), so the feasibility is h^3 max|d| / T^3. The
/// stationarity, which needs the models, is not computed: infinite.
#[test]
fn a_budget_spent_in_the_first_models_reports_the_guess_cost_and_feasibility() {
    let (steps, t_end, d) = (4096, 2.0, [1.0, -2.0]);
    let h = t_end / steps as f64;
    let error = OptimalControlProblem::new(
        &PlanarEffort::new(),
        &[0.0; 4],
        &[d[0], d[1], 0.0, 0.0],
        t_end,
        steps,
    )
    .with_options(PlanOptions::default().with_max_time(Duration::ZERO))
    .solve(PlanGuess::Spline)
    .unwrap_err();
    assert_eq!(error.failure, Failure::TimeLimit, "{error}");
    let last = error.last.as_ref().expect("the iterate reached");
    let expected: f64 = (0..steps)
        .map(|i| {
            let s = (i as f64 + 0.5) * h / t_end;
            let a = (6.0 - 12.0 * s) / (t_end * t_end);
            0.5 * h * (d[0] * d[0] + d[1] * d[1]) * a * a
        })
        .sum();
    assert!(
        (last.cost - expected).abs() <= 1e-12 * expected,
        "{} against {expected}",
        last.cost
    );
    let miss = h.powi(3) * 2.0 / t_end.powi(3);
    let c = &last.certificate;
    assert!(
        (c.feasibility - miss).abs() <= 1e-3 * miss,
        "{} against {miss}",
        c.feasibility
    );
    assert_eq!(c.stationarity, f64::INFINITY);
    assert_eq!(c.complementarity, 0.0);
}

/// 2^24 steps of a system with 12 jet components need about 200 GB of workspace: refused as
/// invalid (naming the steps) before anything is allocated, instead of aborting the process.
#[test]
fn a_workspace_too_large_for_memory_is_refused_before_allocating() {
    let error = six_pendula_problem(&SixPendula::new(), 1 << 24)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(
        matches!(
            error.failure,
            Failure::Invalid(Error::InvalidArgument { name: "steps", .. })
        ),
        "{error}"
    );
    assert!(error.last.is_none());
    assert!(error.to_string().contains("fit in memory"), "{error}");
}
