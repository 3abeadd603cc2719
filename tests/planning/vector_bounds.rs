//! Vector constraint functions (`#[jet_function]` returning `[f64; m]`) with one bound per
//! component: their components and derivatives, a solve that matches the scalar bounds they
//! replace, the placement decided per component, and failures that name the component.

use std::f64::consts::PI;

use retract::bvp::{
    ConstraintKind, Failure, Location, OptimalControlProblem, PlanGuess, PlanOptions,
};
use retract::nalgebra::SVector;
use retract::{Error, JetFunction, VectorJetFunction, jet_function};

use crate::pendulum::{ShoulderTorque, TorqueCost};

/// The torques (tau1, tau2) of the double pendulum with unit masses and lengths
/// (`crate::pendulum::torque`), one function with two components (the value from a helper).
#[jet_function(order = 2)]
fn torques(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> [f64; 2] {
    fn pair(first: f64, second: f64) -> [f64; 2] {
        [first, second]
    }
    let (c2, s2) = (q[1].cos(), q[1].sin());
    let gravity = g * (q[0] + q[1]).sin();
    let tau1 = (3.0 + 2.0 * c2) * ddq[0] + (1.0 + c2) * ddq[1]
        - s2 * (2.0 * dq[0] * dq[1] + dq[1] * dq[1])
        + 2.0 * g * q[0].sin()
        + gravity;
    let tau2 = (1.0 + c2) * ddq[0] + ddq[1] + s2 * dq[0] * dq[0] + gravity;
    pair(tau1, tau2)
}

/// (q0^2 + sin q1, q1'' q0 + q0''): a component of the jet alone and one of the top derivative.
#[jet_function(order = 2)]
fn mixed(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> [f64; 2] {
    [q[0] * q[0] + q[1].sin(), ddq[1] * q[0] + ddq[0]]
}

type Blocks = [SVector<f64, 2>; 2];

/// A model of the pendulum with unit masses and lengths under gravity 9.81.
fn unit<T>(new: fn(f64, f64, f64, f64, f64) -> T) -> T {
    new(1.0, 1.0, 1.0, 1.0, 9.81)
}

/// Pseudo-random points in [-2, 2]^6 (a linear congruential sequence).
fn points(count: usize) -> Vec<(Blocks, SVector<f64, 2>)> {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        4.0 * ((seed >> 11) as f64 / (1u64 << 53) as f64) - 2.0
    };
    (0..count)
        .map(|_| {
            let x = [
                SVector::from_fn(|_, _| next()),
                SVector::from_fn(|_, _| next()),
            ];
            (x, SVector::from_fn(|_, _| next()))
        })
        .collect()
}

/// The flat coordinates (x_0, x_1, u) of a point moved by `e` along entry `r`.
fn moved(x: &Blocks, u: &SVector<f64, 2>, r: usize, e: f64) -> (Blocks, SVector<f64, 2>) {
    let (mut x, mut u) = (*x, *u);
    match r {
        0..=3 => x[r / 2][r % 2] += e,
        _ => u[r - 4] += e,
    }
    (x, u)
}

/// Entry `r` of a gradient in the flat coordinates.
fn flat(g: &retract::Gradient<2, 2>, r: usize) -> f64 {
    match r {
        0..=3 => g.x[r / 2][r % 2],
        _ => g.u[r - 4],
    }
}

/// Component 0 is tau1 (the shared model's value and gradient), component 1 tau2; each
/// component's gradient and Hessian agree with central differences of its value and gradient
/// at random points; past the last component the value is NaN.
#[test]
fn components_and_their_derivatives_agree_with_the_function_and_differences() {
    let (torques, shoulder) = (Torques::new(9.81), unit(ShoulderTorque::new));
    assert_eq!(torques.components(), 2);
    assert_eq!(VectorJetFunction::name(&torques), "Torques");
    let e = 1e-6;
    for (x, u) in points(20) {
        let tau1 = torques.component_value(0, &x, &u);
        assert!((tau1 - shoulder.value(&x, &u)).abs() <= 1e-12 * (1.0 + tau1.abs()));
        let (s, g0) = (
            shoulder.gradient(&x, &u),
            torques.component_gradient(0, &x, &u),
        );
        for r in 0..6 {
            assert!((flat(&s, r) - flat(&g0, r)).abs() <= 1e-12 * (1.0 + flat(&s, r).abs()));
        }
        let tau2 = written(&x, &u)[1];
        assert!((torques.component_value(1, &x, &u) - tau2).abs() <= 1e-12 * (1.0 + tau2.abs()));
        for c in 0..2 {
            let gradient = torques.component_gradient(c, &x, &u);
            let hessian = flat_hessian(&torques.component_hessian(c, &x, &u));
            for (r, row) in hessian.iter().enumerate() {
                let (xp, up) = moved(&x, &u, r, e);
                let (xm, um) = moved(&x, &u, r, -e);
                let fd = (torques.component_value(c, &xp, &up)
                    - torques.component_value(c, &xm, &um))
                    / (2.0 * e);
                assert!((fd - flat(&gradient, r)).abs() <= 1e-6 * (1.0 + fd.abs()));
                let (gp, gm) = (
                    torques.component_gradient(c, &xp, &up),
                    torques.component_gradient(c, &xm, &um),
                );
                for (s, &exact) in row.iter().enumerate() {
                    let fd = (flat(&gp, s) - flat(&gm, s)) / (2.0 * e);
                    assert!(
                        (fd - exact).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "component {c}, entry ({r}, {s}): {exact} against {fd}"
                    );
                }
            }
        }
        assert!(torques.component_value(2, &x, &u).is_nan());
    }
    let mixed = Mixed::new();
    assert!(!mixed.component_involves_top(0));
    assert!(mixed.component_involves_top(1));
}

/// The value of `torques` from the user's function as written.
fn written(x: &Blocks, u: &SVector<f64, 2>) -> [f64; 2] {
    let arr = |v: &SVector<f64, 2>| [v[0], v[1]];
    torques(arr(&x[0]), arr(&x[1]), arr(u), 9.81)
}

/// The 6 x 6 Hessian in the flat coordinates (x_0, x_1, u).
fn flat_hessian(h: &retract::Hessian<2, 2>) -> [[f64; 6]; 6] {
    let mut out = [[0.0; 6]; 6];
    for (r, row) in out.iter_mut().enumerate() {
        for (s, entry) in row.iter_mut().enumerate() {
            *entry = match (r, s) {
                (0..=3, 0..=3) => h.xx[r / 2][s / 2][(r % 2, s % 2)],
                (0..=3, _) => h.xu[r / 2][(r % 2, s - 4)],
                (_, 0..=3) => h.xu[s / 2][(s % 2, r - 4)],
                _ => h.uu[(r - 4, s - 4)],
            };
        }
    }
    out
}

/// |tau1| <= 10 on the swing-up (T = 2, N = 50) as the first component of the vector of
/// torques (the second unbounded) gives the plan of the scalar bound on tau1: the same cost to
/// 1e-9 (the barrier sees the same two sides). Not the same iterations: the two formulations
/// evaluate the torque in different orders, their iterates, equal to 11 digits for two
/// iterations, part at 3e-9 at the third (a rounding difference that a step of size 200
/// amplifies), and this problem's end phase, where the limit's barrier weights reach 1e8 and
/// cost the Riccati recursion digits (`inequalities.rs`), takes 45 and 66 iterations.
#[test]
fn a_vector_bound_solves_as_the_scalar_bound_it_replaces() {
    let system = unit(TorqueCost::new);
    let (torques, shoulder) = (Torques::new(9.81), unit(ShoulderTorque::new));
    let goal = [PI, 0.0, 0.0, 0.0];
    let problem = || OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 50);
    let scalar = problem()
        .with_function_bounds(&shoulder, -10.0, 10.0)
        .solve(PlanGuess::Spline)
        .expect("certified");
    let vector = problem()
        .with_vector_bounds(
            &torques,
            &[-10.0, f64::NEG_INFINITY],
            &[10.0, f64::INFINITY],
        )
        .solve(PlanGuess::Spline)
        .expect("certified");
    assert!(
        (scalar.cost - vector.cost).abs() <= 1e-9 * scalar.cost,
        "{} vs {}",
        scalar.cost,
        vector.cost
    );
    // the bound is active: the unbounded swing-up peaks above 11
    let peak = (0..vector.u.len())
        .map(|i| {
            let xt = (vector.x[i] + vector.x[i + 1]) * 0.5;
            let b = [xt.fixed_rows::<2>(0).into(), xt.fixed_rows::<2>(2).into()];
            torques.component_value(0, &b, &vector.u[i]).abs()
        })
        .fold(0.0, f64::max);
    assert!((peak - 10.0).abs() <= 1e-6, "peak {peak}");
}

/// Component 1's lower side above its upper side is refused naming the component; bounds of
/// the wrong length are invalid; a component of the jet alone is placed at the nodes too (a
/// start outside it is refused at the start), one of the top derivative at the midpoints only.
#[test]
fn failures_name_the_component_and_placement_follows_each_component() {
    let system = unit(TorqueCost::new);
    let (torques, mixed) = (Torques::new(9.81), Mixed::new());
    let goal = [PI, 0.0, 0.0, 0.0];
    let problem = || OptimalControlProblem::new(&system, &[0.0; 4], &goal, 2.0, 20);
    let error = problem()
        .with_vector_bounds(&torques, &[-10.0, 5.0], &[10.0, 4.0])
        .solve(PlanGuess::Spline)
        .unwrap_err();
    let Failure::Infeasible(infeasibility) = error.failure else {
        panic!("{error}");
    };
    assert_eq!(infeasibility.constraint.kind, ConstraintKind::Component(1));
    assert_eq!(infeasibility.location, Location::Definition);
    assert!(
        error.to_string().contains("(Torques, component 1)"),
        "{error}"
    );

    let error = problem()
        .with_vector_bounds(&torques, &[-10.0], &[10.0])
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert!(
        matches!(
            error.failure,
            Failure::Invalid(Error::InvalidArgument { name: "bounds", .. })
        ),
        "{error}"
    );

    // q0^2 + sin(q1) >= 1 fails at the start (0 at q = 0): refused there; u's component
    // (q1'' q0 + q0'' >= 1) is not checked at the ends
    let error = problem()
        .with_vector_bounds(&mixed, &[1.0, 1.0], &[f64::INFINITY; 2])
        .solve(PlanGuess::Spline)
        .unwrap_err();
    let Failure::Infeasible(infeasibility) = error.failure else {
        panic!("{error}");
    };
    assert_eq!(infeasibility.location, Location::Start);
    assert_eq!(infeasibility.constraint.kind, ConstraintKind::Component(0));
    // bounding only u's component: no refusal at the ends (it may converge or not)
    let result = problem()
        .with_vector_bounds(&mixed, &[f64::NEG_INFINITY, -50.0], &[f64::INFINITY, 50.0])
        .with_options(PlanOptions::default().with_max_iterations(5))
        .solve(PlanGuess::Spline);
    if let Err(error) = result {
        assert!(!matches!(error.failure, Failure::Infeasible(_)), "{error}");
    }
}
