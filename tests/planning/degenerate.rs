//! Degenerate constraints: a stage equality that leaves a combination of the coordinates
//! without control authority, so the goal's conditions on it are not independent of the
//! dynamics (a rank-deficient constraint Jacobian).

use retract::bvp::{Failure, OptimalControlProblem, PlanGuess};
use retract::{higher_order_lagrangian, jet_function};

#[higher_order_lagrangian(order = 2)]
fn effort(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1])
}

/// $d'' + 0.1 \sin d = 0$ for $d = q_0 - q_1$: the difference moves on its own.
#[jet_function(order = 2)]
fn coupled(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    ddq[0] - ddq[1] + 0.1 * (q[0] - q[1]).sin()
}

/// Start and goal both at $d = d' = 0$, consistent with the equality ($d \equiv 0$): the
/// Jacobian of the goal and the equalities is rank-deficient, the problem is not. The plan is
/// the common coordinate's rest-to-rest minimum, $q_0 = q_1$ with $J = 2 \cdot 6/T^3$ in the
/// limit, certified.
#[test]
fn a_rank_deficient_goal_consistent_with_the_equality_is_solved() {
    let (t_end, steps) = (1.0, 40);
    let plan = OptimalControlProblem::new(
        &Effort::new(),
        &[0.0; 4],
        &[1.0, 1.0, 0.0, 0.0],
        t_end,
        steps,
    )
    .with_equality(&Coupled::new())
    .solve(PlanGuess::Spline)
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(plan.certificate.negative_directions, 0);
    assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
    for x in &plan.x {
        assert!((x[0] - x[1]).abs() < 1e-8, "{x:?}");
    }
    assert!((plan.cost - 12.0).abs() < 0.05, "{}", plan.cost);
}

/// The goal asks for $d = 0.5$ at rest, which the equality's own motion from $d = d' = 0$
/// never reaches: no plan exists, and the failure says that the goal cannot be reached,
/// naming a component it fixes (not an inertia or regularisation failure, and within a few
/// iterations, not at the iteration limit).
#[test]
fn a_goal_the_equality_cannot_reach_is_named_unreachable() {
    let err = OptimalControlProblem::new(&Effort::new(), &[0.0; 4], &[1.0, 0.5, 0.0, 0.0], 1.0, 40)
        .with_equality(&Coupled::new())
        .solve(PlanGuess::Spline)
        .expect_err("no plan reaches the goal");
    assert!(
        matches!(
            err.failure,
            Failure::UnreachableGoal {
                component: 0 | 1,
                ..
            }
        ),
        "{}",
        err.failure
    );
    let last = err.last.expect("the last iterate");
    assert!(last.iterations < 20, "{}", last.iterations);
}
