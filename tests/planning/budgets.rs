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
