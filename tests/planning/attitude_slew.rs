//! Planning on SO(3) (`examples/attitude.rs` at reduced size): the minimum-torque slew by 170
//! degrees, written in body coordinates (`so3`) and planned in the Gibbs chart centred halfway,
//! free and around the sun keep-out cone. The chart Lagrangians (body form, hand-composed
//! Gibbs form, Euler angles) are checked against torques from the rotation curve itself.

use retract::Lagrangian;
use retract::bvp::{Failure, OptimalControlProblem, Plan, PlanGuess, PlanOptions};
use retract::nalgebra::{Quaternion, SVector, UnitQuaternion, Vector3};
use retract::so3::chart_quaternion;

use crate::attitude::{
    self, BORESIGHT, CONE_DEGREES, euler_body, gibbs_body, gibbs_problem, gibbs_slew, slew_body,
    slew_cone, slew_ends, sun,
};
use crate::common::assert_strict_minimum;

/// Omega and Omega' of the rotation curve `g(t)` at t = 0, from Omega = 2 vec(g^-1 g') by
/// central differences of step `e`.
fn body_rates(g: impl Fn(f64) -> UnitQuaternion<f64>, e: f64) -> (Vector3<f64>, Vector3<f64>) {
    let omega = |t: f64| {
        let dq: Quaternion<f64> = (g(t + e).into_inner() - g(t - e).into_inner()) / (2.0 * e);
        (g(t).into_inner().conjugate() * dq).imag() * 2.0
    };
    (omega(0.0), (omega(e) - omega(-e)) / (2.0 * e))
}

/// 1/2 |J Omega' + Omega x J Omega|^2.
fn cost_of(omega: &Vector3<f64>, domega: &Vector3<f64>) -> f64 {
    let j = Vector3::from(attitude::INERTIA);
    (domega.component_mul(&j) + omega.cross(&omega.component_mul(&j))).norm_squared() / 2.0
}

#[test]
fn chart_lagrangians_are_the_minimum_torque_cost() {
    let (gibbs, euler) = (gibbs_body(), euler_body());
    let body = slew_body(&UnitQuaternion::identity());
    for seed in 0..8 {
        let v = |k: u64| {
            Vector3::from_fn(|r, _| {
                (((seed * 3 + k) * 7 + r as u64) as f64 * 0.618_034).fract() - 0.5
            })
        };
        let (q, dq, ddq) = (v(0), v(1) * 2.0, v(2) * 2.0);
        let curve = |t: f64| q + dq * t + ddq * (t * t / 2.0);
        let expected = cost_of_curve(|t| chart_quaternion(&curve(t)));
        let got = gibbs.lagrangian(&[q, dq], &ddq);
        assert!(
            (got - expected).abs() < 1e-6 * (1.0 + expected),
            "Gibbs {got} vs {expected}"
        );
        let got = body.lagrangian(&[q, dq], &ddq);
        assert!(
            (got - expected).abs() < 1e-6 * (1.0 + expected),
            "body coordinates {got} vs {expected}"
        );
        let expected = cost_of_curve(|t| {
            let a = curve(t);
            UnitQuaternion::from_euler_angles(a[2], a[1], a[0])
        });
        let got = euler.lagrangian(&[q, dq], &ddq);
        assert!(
            (got - expected).abs() < 1e-6 * (1.0 + expected),
            "Euler {got} vs {expected}"
        );
    }
}

/// The minimum-torque cost of the rotation curve at t = 0.
fn cost_of_curve(g: impl Fn(f64) -> UnitQuaternion<f64>) -> f64 {
    let (omega, domega) = body_rates(g, 1e-4);
    cost_of(&omega, &domega)
}

/// The boresight's angle from the sun (degrees) at the steps' midpoints.
fn sun_angles(centre: &UnitQuaternion<f64>, plan: &Plan<3, 6>) -> Vec<f64> {
    let angle = |y: &SVector<f64, 6>| {
        let b = centre
            * chart_quaternion(&y.fixed_rows::<3>(0).into_owned())
            * Vector3::from(BORESIGHT);
        b.dot(&sun()).clamp(-1.0, 1.0).acos().to_degrees()
    };
    // the cone is a constraint of the jet alone: it holds at the nodes and the midpoints
    let midpoints = plan.x.windows(2).map(|w| angle(&((w[0] + w[1]) / 2.0)));
    midpoints.chain(plan.x.iter().map(angle)).collect()
}

#[test]
fn the_slew_keeps_out_of_the_sun_cone() {
    let steps = 60;
    let (centre, start, goal) = gibbs_slew();
    let system = slew_body(&centre);
    // the chart's ends are the slew's rotations
    let (g0, g1) = slew_ends();
    let end = |x: &[f64; 6]| centre * chart_quaternion(&Vector3::new(x[0], x[1], x[2]));
    assert!(end(&start).angle_to(&g0) < 1e-14 && end(&goal).angle_to(&g1) < 1e-14);
    let free = gibbs_problem(&system, &start, &goal, steps)
        .solve(PlanGuess::Spline)
        .unwrap();
    let cone = slew_cone(&centre);
    let avoiding = gibbs_problem(&system, &start, &goal, steps)
        .with_inequality(&cone)
        .solve(PlanGuess::Spline)
        .unwrap();
    for plan in [&free, &avoiding] {
        let c = &plan.certificate;
        assert_eq!(c.negative_directions, 0);
        assert!(c.min_reduced_hessian_eig > 0.0, "{c:?}");
    }
    // the free slew passes through the cone; the planned one stays out at every node and
    // evaluation point, touching it, at a higher cost
    let closest = |plan| {
        sun_angles(&centre, plan)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    };
    assert!(
        closest(&free) < CONE_DEGREES - 5.0,
        "free: {}",
        closest(&free)
    );
    let touching = closest(&avoiding);
    assert!(
        (touching - CONE_DEGREES).abs() < 1e-6,
        "constrained: {touching}"
    );
    assert!(avoiding.cost > free.cost);
}

#[test]
fn the_rigid_body_flies_among_spheres_in_se3() {
    let steps = 40;
    let system = attitude::flight_body();
    let (start, goal, time) = attitude::se3_flight();
    let spheres: Vec<attitude::ClearOfSphere> = attitude::SPHERES
        .iter()
        .map(|&(c, r)| attitude::ClearOfSphere::new(c, r))
        .collect();
    let problem = OptimalControlProblem::new(&system, &start, &goal, time, steps)
        .with_options(PlanOptions::default().with_min_eigenvalue(true));
    let free = problem.clone().solve(PlanGuess::Spline).unwrap();
    let mut avoiding = problem;
    for sphere in &spheres {
        avoiding = avoiding.with_inequality(sphere);
    }
    let avoiding = avoiding.solve(PlanGuess::Spline).unwrap();
    // the least clearance |p - c| - r at the evaluation points (midpoints)
    let clearance = |plan: &Plan<6, 12>| {
        plan.x
            .windows(2)
            .flat_map(|w| {
                let x = (w[0] + w[1]) / 2.0;
                let p = Vector3::new(x[3], x[4], x[5]);
                attitude::SPHERES.map(|(c, r)| (p - Vector3::from(c)).norm() - r)
            })
            .fold(f64::INFINITY, f64::min)
    };
    assert!(clearance(&free) < -0.1, "free: {}", clearance(&free));
    assert!(
        clearance(&avoiding) > -1e-9,
        "avoiding: {}",
        clearance(&avoiding)
    );
    assert!(avoiding.cost > free.cost);
    for plan in [&free, &avoiding] {
        assert_eq!(plan.certificate.negative_directions, 0);
        assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
        // the end is the goal's rotation and position
        let last = plan.x[steps];
        let turn = UnitQuaternion::from_scaled_axis(
            Vector3::new(0.2, 0.3, 1.0).normalize() * 120f64.to_radians(),
        );
        let reached = chart_quaternion(&Vector3::new(last[0], last[1], last[2]));
        assert!(reached.angle_to(&turn) < 1e-12);
        assert!((last[3] - 4.5).abs() < 1e-12 && last[4].abs() < 1e-12 && last[5].abs() < 1e-12);
    }
}

/// About the axis of the largest inertia the planar turn is stationary by symmetry but not a
/// minimum: the optimizer, started on it with its escapes off, says so instead of returning
/// it; with them (the default) it leaves the saddle along its negative curvature for a
/// certified minimum below it, the minimum it reaches from a goal tilted off the symmetric
/// plane (to 1e-5: the tilt is 1e-3 rad).
#[test]
fn a_planar_turn_about_the_largest_inertia_is_a_saddle_the_optimizer_leaves() {
    let system = slew_body(&UnitQuaternion::identity());
    let goal_turn = UnitQuaternion::from_scaled_axis(Vector3::z() * 120f64.to_radians());
    let y = retract::so3::chart_point(&UnitQuaternion::identity(), &goal_turn).unwrap();
    let goal = [y[0], y[1], y[2], 0.0, 0.0, 0.0];
    let problem = gibbs_problem(&system, &[0.0; 6], &goal, 40);
    let options = PlanOptions::default().with_saddle_escapes(0);
    let error = problem
        .clone()
        .with_options(options)
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(
        matches!(error.failure, Failure::NotAMinimum { negative_directions } if negative_directions > 0),
        "{error}"
    );
    let saddle = error.last.expect("the last iterate");
    let escaped = problem.solve(PlanGuess::Spline).unwrap();
    assert!(
        escaped.cost < saddle.cost,
        "{} vs {}",
        escaped.cost,
        saddle.cost
    );
    assert_strict_minimum(&escaped, "escaped");
    assert!(escaped.iterations > saddle.iterations);
    // off the symmetric plane the optimizer descends below the saddle without an escape
    let tilted = UnitQuaternion::from_scaled_axis(
        Vector3::new(1e-3, 0.0, 1.0).normalize() * 120f64.to_radians(),
    );
    let y = retract::so3::chart_point(&UnitQuaternion::identity(), &tilted).unwrap();
    let goal = [y[0], y[1], y[2], 0.0, 0.0, 0.0];
    let plan = gibbs_problem(&system, &[0.0; 6], &goal, 40)
        .with_options(options)
        .solve(PlanGuess::Spline)
        .unwrap();
    assert!(plan.cost < saddle.cost, "{} vs {}", plan.cost, saddle.cost);
    let gap = (plan.cost - escaped.cost).abs() / plan.cost;
    assert!(gap < 1e-5, "tilted {} escaped {}", plan.cost, escaped.cost);
}

/// The escape with inequalities (the barrier's slacks and the second-order check's penalties
/// in play): with input bounds |u| <= 50 that stay inactive the saddle is left for the same
/// minimum as without; with the bound |q_x| <= 0.3 on the chart, which the minimum would
/// cross, for a certified minimum on the bound, above the unbounded one and below the saddle.
#[test]
fn the_saddle_is_left_with_inequalities_too() {
    use retract::bvp::Variable;
    let system = slew_body(&UnitQuaternion::identity());
    let goal_turn = UnitQuaternion::from_scaled_axis(Vector3::z() * 120f64.to_radians());
    let y = retract::so3::chart_point(&UnitQuaternion::identity(), &goal_turn).unwrap();
    let goal = [y[0], y[1], y[2], 0.0, 0.0, 0.0];
    let problem = gibbs_problem(&system, &[0.0; 6], &goal, 40);
    let saddle = problem
        .clone()
        .with_options(PlanOptions::default().with_saddle_escapes(0))
        .solve(PlanGuess::Spline)
        .unwrap_err()
        .last
        .expect("the saddle")
        .cost;
    let free = problem.clone().solve(PlanGuess::Spline).unwrap();
    let inputs = problem
        .clone()
        .with_bounds(Variable::Top(0), -50.0, 50.0)
        .with_bounds(Variable::Top(1), -50.0, 50.0)
        .solve(PlanGuess::Spline)
        .unwrap();
    let chart = problem
        .with_bounds(Variable::Jet(0), -0.3, 0.3)
        .solve(PlanGuess::Spline)
        .unwrap();
    assert_strict_minimum(&inputs, "input bounds");
    assert_strict_minimum(&chart, "chart bound");
    for plan in [&inputs, &chart] {
        assert!(plan.violations.imposed() <= 1e-9, "{:?}", plan.violations);
    }
    assert!((inputs.cost - free.cost).abs() < 1e-9 * free.cost);
    let peak = chart.x.iter().fold(0.0_f64, |m, x| m.max(x[0].abs()));
    assert!((peak - 0.3).abs() < 1e-6, "|q_x| peaks at {peak}");
    assert!(free.cost < chart.cost && chart.cost < saddle);
}
