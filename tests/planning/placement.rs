//! Where constraints hold: a constraint of the jet alone at every node and every evaluation
//! point, the plan's report of its violations, the refusals of problems that no point
//! satisfies (naming the constraint), vector bounds, and the second-order certificate with an
//! active state constraint at theta = 0 and 1.

use retract::bvp::{
    ConstraintKind, Failure, Location, OptimalControlProblem, Placement, Plan, PlanGuess,
    PlanOptions, Variable,
};
use retract::{JetFunction, higher_order_lagrangian, jet_function};

/// Minimum acceleration in the plane, 1/2 |q''|^2.
#[higher_order_lagrangian(order = 2)]
fn planar_effort(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1])
}

/// Clearance of the disc of radius r about (cx, cy): |q - c|^2 - r^2 (a function of q alone).
#[jet_function(order = 2)]
fn clearance(q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], cx: f64, cy: f64, r: f64) -> f64 {
    (q[0] - cx) * (q[0] - cx) + (q[1] - cy) * (q[1] - cy) - r * r
}

/// Minimum acceleration on the line, 1/2 q''^2.
#[higher_order_lagrangian(order = 2)]
fn line_effort(_q: [f64; 1], _dq: [f64; 1], ddq: [f64; 1]) -> f64 {
    0.5 * ddq[0] * ddq[0]
}

const START: [f64; 4] = [-2.0, 0.0, 0.0, 0.0];
const GOAL: [f64; 4] = [2.0, 0.0, 0.0, 0.0];

/// The disc of radius 0.5 just below the straight line from START to GOAL (it crosses it).
fn disc() -> Clearance {
    Clearance::new(0.0, -0.1, 0.5)
}

/// The clearance at every node and every evaluation point of a plan, by the test's own
/// evaluation.
fn clearances(plan: &Plan<2, 4>, disc: &Clearance) -> (f64, f64) {
    let at = |x: &retract::nalgebra::SVector<f64, 4>| {
        let b = [
            x.fixed_rows::<2>(0).into_owned(),
            x.fixed_rows::<2>(2).into_owned(),
        ];
        disc.value(&b, &retract::nalgebra::SVector::zeros())
    };
    let nodes = plan.x.iter().map(at).fold(f64::INFINITY, f64::min);
    let midpoints = (0..plan.u.len())
        .map(|i| at(&((plan.x[i] + plan.x[i + 1]) * 0.5)))
        .fold(f64::INFINITY, f64::min);
    (nodes, midpoints)
}

/// A clearance constraint of q alone holds at every node and every evaluation point: at no N
/// is a plan certified with a node or a midpoint inside the disc, and from N = 4 on the
/// solve succeeds. The report matches the test's own evaluation.
#[test]
fn a_keep_out_disc_holds_at_nodes_and_midpoints_at_every_n() {
    let (system, disc) = (PlanarEffort::new(), disc());
    for steps in [2, 3, 4, 8] {
        let result = OptimalControlProblem::new(&system, &START, &GOAL, 4.0, steps)
            .with_inequality(&disc)
            .solve(PlanGuess::Spline);
        match result {
            Ok(plan) => {
                let (nodes, midpoints) = clearances(&plan, &disc);
                assert!(
                    nodes >= -1e-9 && midpoints >= -1e-9,
                    "N = {steps}: {nodes:e}"
                );
                assert!(plan.violations.nodes <= 1e-9 && plan.violations.midpoints <= 1e-9);
                assert!((plan.violations.nodes - (-nodes).max(0.0)).abs() < 1e-12);
                // the plan goes around (above: the disc is below the line)
                assert!(plan.x[steps / 2][1] > 0.3, "N = {steps}");
            }
            Err(e) => assert!(steps < 4, "N = {steps}: {e}"),
        }
    }
}

/// Interior samples: a bound q <= 0.3 on the line that the unbounded plan (from q' = 2 to
/// q' = -2 back at 0 in T = 2) would pass. At N = 8 the plan holds it at the nodes and
/// midpoints but its interpolant peaks above it between them (by about 1e-2); with 3 samples
/// a step less, and with the 15 that `Violations::interpolant` checks not at all (within the
/// tolerance), each at a higher cost. The test's own evaluation of the plan's interpolant,
/// on a grid finer than the samples, agrees.
#[test]
fn interior_samples_hold_the_interpolant_between_the_nodes() {
    let system = LineEffort::new();
    let solve = |samples| {
        OptimalControlProblem::new(&system, &[0.0, 2.0], &[0.0, -2.0], 2.0, 8)
            .with_bounds(Variable::Jet(0), f64::NEG_INFINITY, 0.3)
            .with_options(PlanOptions::default().with_interior_samples(samples))
            .solve(PlanGuess::Spline)
            .expect("a certified plan")
    };
    let plans = [solve(0), solve(3), solve(15)];
    let between = plans.each_ref().map(|p| p.violations.interpolant);
    assert!(between[0] > 5e-3, "{between:?}");
    assert!(between[1] < between[0] / 10.0, "{between:?}");
    assert!(between[2] <= 1e-9, "{between:?}");
    assert!(plans[0].cost < plans[1].cost && plans[1].cost < plans[2].cost);
    for plan in &plans {
        assert!(plan.violations.imposed() <= 1e-9);
    }
    let peak = |plan: &Plan<1, 2>| {
        (0..=8 * 64)
            .map(|j| plan.evaluate(2.0 * j as f64 / 512.0).expect("inside")[0])
            .fold(f64::NEG_INFINITY, f64::max)
    };
    assert!(peak(&plans[0]) > 0.3 + 5e-3);
    // at the samples within the tolerance, between them by O((h / 16)^2)
    assert!(peak(&plans[2]) <= 0.3 + 1e-4, "{}", peak(&plans[2]));
}

/// Placed at the midpoints only, the same constraint leaves the nodes free: the coarse plan
/// puts a node inside the disc, and the plan says so ([`retract::bvp::Violations::nodes`]),
/// while the midpoints hold.
#[test]
fn a_midpoint_placement_is_reported_at_the_nodes() {
    let (system, disc) = (PlanarEffort::new(), disc());
    let plan = OptimalControlProblem::new(&system, &START, &GOAL, 4.0, 4)
        .with_inequality_at(&disc, Placement::Midpoints)
        .solve(PlanGuess::Spline)
        .expect("a certified plan");
    let (nodes, midpoints) = clearances(&plan, &disc);
    assert!(midpoints >= -1e-9, "{midpoints:e}");
    assert!(nodes < -0.01, "a node inside the disc: {nodes:e}");
    // (the node report covers the constraints placed at the nodes: none here)
    assert_eq!(plan.violations.nodes, 0.0);
    let both = OptimalControlProblem::new(&system, &START, &GOAL, 4.0, 4)
        .with_inequality_at(&disc, Placement::NodesAndMidpoints)
        .solve(PlanGuess::Spline)
        .expect("a certified plan");
    assert!(clearances(&both, &disc).0 >= -1e-9);
    assert!(both.cost > plan.cost, "{} vs {}", both.cost, plan.cost);
}

/// The failure of a problem no point satisfies names its constraint and where.
fn infeasibility<const N: usize, const X: usize>(
    result: Result<Plan<N, X>, retract::bvp::PlanError<N, X>>,
) -> retract::bvp::Infeasibility {
    match result {
        Err(e) => match e.failure {
            Failure::Infeasible(infeasibility) => {
                assert!(e.last.is_none());
                assert!(e.to_string().starts_with("infeasible: "), "{e}");
                infeasibility
            }
            other => panic!("not an infeasibility: {other}"),
        },
        Ok(plan) => panic!("a plan of an infeasible problem: cost {}", plan.cost),
    }
}

/// Contradictory bounds, a lower side above the upper side, equal sides and a start inside a
/// keep-out disc are refused before iterating, each naming the constraint.
#[test]
fn contradictions_are_refused_naming_the_constraint() {
    let (system, disc) = (PlanarEffort::new(), disc());
    let problem = || OptimalControlProblem::new(&system, &START, &GOAL, 4.0, 20);
    // q0 >= 1 and q0 <= -1: the second bound (index 1) is named
    let both = infeasibility(
        problem()
            .with_bounds(Variable::Jet(0), 1.0, f64::INFINITY)
            .with_bounds(Variable::Jet(0), f64::NEG_INFINITY, -1.0)
            .solve(PlanGuess::Spline),
    );
    assert_eq!(
        both.constraint.kind,
        ConstraintKind::Bound(Variable::Jet(0))
    );
    assert_eq!(both.constraint.index, 1);
    assert_eq!(both.location, Location::Definition);
    assert_eq!(both.violation, 2.0);
    // lower > upper in one call
    let reversed = infeasibility(
        problem()
            .with_bounds(Variable::Top(1), 3.0, 2.0)
            .solve(PlanGuess::Spline),
    );
    assert_eq!(reversed.constraint.index, 0);
    assert_eq!(reversed.violation, 1.0);
    // equal sides: an inequality without interior
    let equal = infeasibility(
        problem()
            .with_function_bounds(&disc, 0.5, 0.5)
            .solve(PlanGuess::Spline),
    );
    assert_eq!(equal.constraint.kind, ConstraintKind::Inequality);
    assert_eq!(equal.constraint.name, "Clearance");
    assert_eq!(equal.violation, 0.0);
    // a side infinite the wrong way (q0 >= +inf)
    let infinite = infeasibility(
        problem()
            .with_bounds(Variable::Jet(0), f64::INFINITY, f64::INFINITY)
            .solve(PlanGuess::Spline),
    );
    assert!(infinite.violation.is_infinite());
    // node constraints with a free end are refused (not silently left out at the end)
    let free = problem()
        .with_inequality(&disc)
        .with_free_end(&[2])
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(matches!(free.failure, Failure::Invalid(_)), "{free}");
    // the start inside the disc: a node constraint at the fixed start
    let inside = [0.0, -0.2, 0.0, 0.0];
    let start = infeasibility(
        OptimalControlProblem::new(&system, &inside, &GOAL, 4.0, 20)
            .with_inequality(&disc)
            .solve(PlanGuess::Spline),
    );
    assert_eq!(start.location, Location::Start);
    assert_eq!(start.constraint.name, "Clearance");
    assert!((start.violation - (0.25 - 0.01)).abs() < 1e-12);
    // a goal outside a bound on q, named as a bound of the jet at the goal
    let goal = infeasibility(
        problem()
            .with_state_bounds(0, [-3.0, -3.0], [1.5, 3.0])
            .solve(PlanGuess::Spline),
    );
    assert_eq!(goal.location, Location::Goal);
    assert_eq!(
        goal.constraint.kind,
        ConstraintKind::Bound(Variable::Jet(0))
    );
    assert!((goal.violation - 0.5).abs() < 1e-12);
}

/// A solve that stalls at an infeasible point names the constraint violated most there:
/// contradictory equalities (u0 = 1 and u0 = 2) at the first iteration, and a keep-out disc
/// centred on the straight path of the guess (its centre a node of it: violated by r^2 there;
/// by symmetry no step leaves the line, and the restoration phase's steps stall inside the
/// disc), with the last iterate attached.
#[test]
fn a_solve_stalled_at_an_infeasible_point_names_the_constraint() {
    /// u0 - v.
    #[jet_function(order = 2)]
    fn forcing(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], v: f64) -> f64 {
        ddq[0] - v
    }
    let stalled = |result: Result<Plan<2, 4>, retract::bvp::PlanError<2, 4>>| match result {
        Err(e) => match e.failure {
            Failure::StalledInfeasible(infeasibility) => {
                let last = e.last.as_ref().expect("the last iterate");
                assert!(
                    last.certificate.feasibility >= infeasibility.violation,
                    "{e}"
                );
                assert!(
                    e.to_string().contains("stalled at an infeasible point"),
                    "{e}"
                );
                infeasibility
            }
            other => panic!("not a stalled infeasibility: {other}"),
        },
        Ok(plan) => panic!("a plan of an infeasible problem: cost {}", plan.cost),
    };
    let system = PlanarEffort::new();
    let (one, two) = (Forcing::new(1.0), Forcing::new(2.0));
    let contradiction = stalled(
        OptimalControlProblem::new(&system, &START, &GOAL, 4.0, 40)
            .with_equality(&one)
            .with_equality(&two)
            .solve(PlanGuess::Spline),
    );
    assert_eq!(contradiction.constraint.kind, ConstraintKind::Equality);
    assert!(contradiction.violation > 0.5, "{contradiction}");
    let (radius, disc) = (0.5, Clearance::new(0.0, 0.0, 0.5));
    for steps in [8, 40] {
        let problem =
            OptimalControlProblem::new(&system, &START, &GOAL, 4.0, steps).with_inequality(&disc);
        // with the restoration phase (the default) the iterate leaves the straight line
        // before it stalls, still inside the disc
        let restored = stalled(problem.solve(PlanGuess::Spline));
        assert_eq!(restored.constraint.kind, ConstraintKind::Inequality);
        assert_eq!(restored.constraint.index, 0);
        assert!(restored.violation > 0.1, "N = {steps}: {restored}");
        // without it, at the straight guess's centre node, within 1e-3 of its full depth r^2
        // (the first steps move the iterate a little before it stalls)
        let options = PlanOptions::default().with_restoration(false);
        let head_on = stalled(problem.with_options(options).solve(PlanGuess::Spline));
        assert_eq!(head_on.constraint.kind, ConstraintKind::Inequality);
        assert_eq!(head_on.constraint.index, 0);
        assert_eq!(head_on.location, Location::Node(steps / 2), "N = {steps}");
        assert!(
            (head_on.violation - radius * radius).abs() < 1e-3,
            "{head_on}"
        );
    }
}

/// `with_input_bounds` and `with_state_bounds` are the scalar bounds per component: the same
/// plan, with the bounds active.
#[test]
fn vector_bounds_are_the_scalar_bounds() {
    let system = PlanarEffort::new();
    let (start, goal) = ([0.0; 4], [1.0, 2.0, 0.0, 0.0]);
    let problem = || OptimalControlProblem::new(&system, &start, &goal, 1.0, 40);
    let vector = problem()
        .with_input_bounds([-5.0, f64::NEG_INFINITY], [5.0, 10.0])
        .with_state_bounds(1, [f64::NEG_INFINITY; 2], [1.4, 2.8])
        .solve(PlanGuess::Spline)
        .expect("a certified plan");
    let scalar = problem()
        .with_bounds(Variable::Top(0), -5.0, 5.0)
        .with_bounds(Variable::Top(1), f64::NEG_INFINITY, 10.0)
        .with_bounds(Variable::Jet(2), f64::NEG_INFINITY, 1.4)
        .with_bounds(Variable::Jet(3), f64::NEG_INFINITY, 2.8)
        .solve(PlanGuess::Spline)
        .expect("a certified plan");
    for (a, b) in vector.x.iter().zip(&scalar.x) {
        assert!((a - b).amax() < 1e-12);
    }
    // the unconstrained optimum peaks at 1.5 |q(T)| / T in speed and 6 |q(T)| / T^2 in
    // acceleration: every bound is active
    let peak_speed = vector.x.iter().map(|x| x[2]).fold(0.0, f64::max);
    let peak_u = vector.u.iter().map(|u| u[1]).fold(0.0, f64::max);
    assert!((peak_speed - 1.4).abs() < 1e-6, "{peak_speed}");
    assert!(peak_u <= 10.0 + 1e-9, "{peak_u}");
    assert!(vector.violations.imposed() <= 1e-9);
}

/// An active bound on the speed at theta = 0 (where it constrains x_i, not u_i: no rank in u)
/// and theta = 1 (the mirrored scheme): both certified as minima with no negative
/// direction, at the same cost (the problem is symmetric in time).
#[test]
fn an_active_state_bound_is_certified_at_theta_0_and_1() {
    let system = LineEffort::new();
    let cost = |theta: f64| {
        let plan = OptimalControlProblem::new(&system, &[0.0, 0.0], &[1.0, 0.0], 1.0, 50)
            .with_bounds(Variable::Jet(1), f64::NEG_INFINITY, 1.2)
            .with_options(
                PlanOptions::default()
                    .with_theta(theta)
                    .with_min_eigenvalue(true),
            )
            .solve(PlanGuess::Spline)
            .unwrap_or_else(|e| panic!("theta = {theta}: {e}"));
        assert_eq!(plan.certificate.negative_directions, 0);
        assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
        let peak = plan.x.iter().map(|x| x[1]).fold(0.0, f64::max);
        assert!((peak - 1.2).abs() < 1e-6, "theta = {theta}: {peak}");
        plan.cost
    };
    let (j0, j1, half) = (cost(0.0), cost(1.0), cost(0.5));
    assert!((j0 - j1).abs() < 1e-8 * j0, "{j0} vs {j1}");
    // above the unconstrained 12 |q(T)|^2 / T^3 / 2 = 6
    assert!(half > 6.0 && j0 > 6.0, "{half} {j0}");
}

/// The constrained suite's cart-pole (C1 of `../shared/BENCHMARKS.md`: T = 2, |F| <= 12 and
/// 10, and T = 3, |F| <= 6, at the midpoints, N = 100 T, the smoothstep guess) at the default
/// options: certified, at the cost IPOPT reaches on the same transcription (CasADi 3.8.2,
/// IPOPT 3.14.19, tol 1e-10: 34.13577956, 37.6490895 and 22.45335986, whose bounds it relaxes
/// by 1e-8 relative, so its costs are lower by about that), within 1.5 times its iterations
/// (13, 22 and 55). Before the curvature term of the merit penalty and the refinement near
/// active bounds this stalled at stationarity 5e-4; before the inertia correction shifted the
/// slacks' Hessian too, T = 3 took 126 iterations.
#[test]
fn the_bounded_cart_pole_converges_at_the_default_options() {
    use super::cart_pole::{CartForce, CartPole, PoleTorque};
    let (system, unactuated) = (
        CartPole::new(1.0, 0.3, 0.5),
        PoleTorque::new(0.3, 0.5, 9.81),
    );
    let force = CartForce::new(1.0, 0.3, 0.5);
    let goal = [0.0, std::f64::consts::PI, 0.0, 0.0];
    let cases = [
        (2.0, 12.0, 34.13577956, 13),
        (2.0, 10.0, 37.6490895, 22),
        (3.0, 6.0, 22.45335986, 55),
    ];
    for (t_end, limit, ipopt_cost, ipopt_iterations) in cases {
        let steps = (100.0 * t_end) as usize;
        let plan = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
            .with_equality(&unactuated)
            .with_function_bounds(&force, -limit, limit)
            .solve(PlanGuess::Spline)
            .unwrap_or_else(|e| panic!("|F| <= {limit}: {e}"));
        assert!(
            (plan.cost - ipopt_cost).abs() < 1e-6 * ipopt_cost,
            "|F| <= {limit}: {} against {ipopt_cost}",
            plan.cost
        );
        assert!(
            2 * plan.iterations <= 3 * ipopt_iterations,
            "|F| <= {limit}: {} iterations",
            plan.iterations
        );
        assert!(plan.violations.imposed() <= 1e-9);
        assert_eq!(plan.certificate.negative_directions, 0);
    }
}

/// A warm start from the plan of a nearby start around the keep-out disc (active at the
/// nodes and midpoints where the plan passes it): no more iterations than a cold start.
#[test]
fn a_plan_around_the_disc_warm_starts_a_nearby_start() {
    let (system, disc) = (PlanarEffort::new(), disc());
    let solve = |start: &[f64; 4], guess| {
        OptimalControlProblem::new(&system, start, &GOAL, 4.0, 40)
            .with_inequality(&disc)
            .solve(guess)
    };
    let first = solve(&START, PlanGuess::Spline).unwrap();
    for dy in [0.05, -0.05, 0.2] {
        let start = [START[0], START[1] + dy, 0.0, 0.0];
        let cold = solve(&start, PlanGuess::Spline).unwrap();
        let warm = solve(&start, PlanGuess::Plan(&first)).unwrap();
        crate::warm_start::assert_warm_matches_cold(&warm, &cold, 1e-9, &format!("dy = {dy}"));
        // (the plan's duals come along: 3 iterations warm against 17-19 cold)
        assert!(2 * warm.iterations <= cold.iterations, "dy = {dy}");
        assert!(clearances(&warm, &disc).0.min(clearances(&warm, &disc).1) >= -1e-9);
    }
}
