//! The optimizer (`OptimalControlProblem`): its plans satisfy the lifted scheme, its
//! certificate agrees with a dense computation, it descends where the root finder stops at a
//! saddle, it never returns a path through an obstacle, and its failures carry the iterate.

use crate::common;

use common::models::{DISC_GOAL, DISC_START, DoublePendulum, OneDisc, disc_bump_guess};

use std::f64::consts::PI;

use retract::bvp::root_finder::BoundaryValueProblem;
use retract::bvp::{Failure, OptimalControlProblem, Plan, PlanGuess, PlanOptions};
use retract::nalgebra::{DMatrix, SVector};
use retract::{JetFunction, Lagrangian, LiftedSystem, higher_order_lagrangian, jet_function};

fn solve_disc(
    steps: usize,
    options: PlanOptions,
) -> Result<Plan<2, 4>, retract::bvp::PlanError<2, 4>> {
    let system = OneDisc { tau: 1e-2 };
    let (x, u) = disc_bump_guess(steps);
    OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps)
        .with_options(options)
        .solve(PlanGuess::Path { x: &x, u: &u })
}

/// The state z_i = (x_i, p_i) of a plan.
fn plan_state(plan: &Plan<2, 4>, i: usize) -> SVector<f64, 8> {
    SVector::<f64, 8>::from_fn(|r, _| {
        if r < 4 {
            plan.x[i][r]
        } else {
            plan.momenta[i][r - 4]
        }
    })
}

/// The largest residual of the lifted midpoint scheme over a plan's steps.
fn scheme_residual(system: &OneDisc, plan: &Plan<2, 4>) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..plan.u.len() {
        let next = plan_state(plan, i + 1);
        let w = SVector::<f64, 10>::from_fn(|r, _| if r < 8 { next[r] } else { plan.u[i][r - 8] });
        let f = system.residual(&plan_state(plan, i), &w, plan.h, 0.5);
        worst = worst.max(f.amax());
    }
    worst
}

/// The plan's states z_i = (x_i, p_i) and top derivatives satisfy the lifted midpoint scheme
/// (the discrete necessary conditions the root finder solves), so the momenta recovered from
/// the multipliers are the scheme's momenta.
#[test]
fn plan_satisfies_the_lifted_scheme() {
    let system = OneDisc { tau: 1e-2 };
    let plan = solve_disc(400, PlanOptions::default().with_min_eigenvalue(true)).unwrap();
    assert_eq!(plan.certificate.negative_directions, 0);
    let worst = scheme_residual(&system, &plan);
    assert!(worst < 1e-9, "scheme residual {worst:e}");
    // the root finder, started from these states, stays at this point
    let states: Vec<_> = (0..=400).map(|i| plan_state(&plan, i)).collect();
    let root = BoundaryValueProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, 400)
        .solve(retract::bvp::root_finder::Guess::States(&states))
        .unwrap();
    for i in 0..=400 {
        assert!(
            (root.states[i] - plan_state(&plan, i)).amax() < 1e-7,
            "state {i}"
        );
    }
    assert!((root.cost - plan.cost).abs() < 1e-9 * plan.cost.abs());
}

/// The pendulum swing-up from rest at q = 0 to rest at (pi, 0) in `t_end`.
fn pendulum_problem(
    system: &DoublePendulum,
    t_end: f64,
    steps: usize,
) -> OptimalControlProblem<'_, DoublePendulum, 2, 2, 4> {
    const GOAL: [f64; 4] = [PI, 0.0, 0.0, 0.0];
    OptimalControlProblem::new(system, &[0.0; 4], &GOAL, t_end, steps)
}

/// The smallest eigenvalue of Z^T (sum_i T_i^T h D^2 L T_i) Z with Z an orthonormal null-space
/// basis of the scheme's x-equations, formed densely (SVD) in the variables
/// (x_1, ..., x_{N-1}, u_0, ..., u_{N-1}).
fn dense_min_reduced_eigenvalue<Sys: Lagrangian<2, 2>>(system: &Sys, plan: &Plan<2, 4>) -> f64 {
    dense_min_reduced_eigenvalue_free(system, plan, (&[], &[]))
}

/// [`dense_min_reduced_eigenvalue`] with the components `free.0` of x_0 and `free.1` of x_N
/// free (variables too, after the interior nodes' and before the top derivatives').
fn dense_min_reduced_eigenvalue_free<Sys: Lagrangian<2, 2>>(
    system: &Sys,
    plan: &Plan<2, 4>,
    free: (&[usize], &[usize]),
) -> f64 {
    let (h, theta) = (plan.h, plan.theta);
    let steps = plan.u.len();
    let ends = free.0.len() + free.1.len();
    let inner = (steps - 1) * 4 + ends;
    let dim = inner + steps * 2;
    // column of x_i entry r (None for the fixed components of x_0, x_N) and of u_i entry a
    let xcol = |i: usize, r: usize| {
        let at = |list: &[usize]| list.iter().position(|c| *c == r);
        if i == 0 {
            at(free.0)
        } else if i == steps {
            at(free.1).map(|j| free.0.len() + (steps - 1) * 4 + j)
        } else {
            Some(free.0.len() + (i - 1) * 4 + r)
        }
    };
    let ucol = |i: usize, a: usize| inner + i * 2 + a;
    let mut hessian = DMatrix::<f64>::zeros(dim, dim);
    let mut constraints = DMatrix::<f64>::zeros(steps * 4, dim);
    for i in 0..steps {
        let xt = plan.x[i] * (1.0 - theta) + plan.x[i + 1] * theta;
        let blocks = [
            xt.fixed_rows::<2>(0).into_owned(),
            xt.fixed_rows::<2>(2).into_owned(),
        ];
        let hs = system.hessian(&blocks, &plan.u[i]);
        // y = (x_theta, u) (6 entries) as a combination of the columns
        let mut t = DMatrix::<f64>::zeros(6, dim);
        for r in 0..4 {
            if let Some(c) = xcol(i, r) {
                t[(r, c)] += 1.0 - theta;
            }
            if let Some(c) = xcol(i + 1, r) {
                t[(r, c)] += theta;
            }
        }
        for a in 0..2 {
            t[(4 + a, ucol(i, a))] = 1.0;
        }
        let hy = DMatrix::<f64>::from_fn(6, 6, |r, c| match (r < 4, c < 4) {
            (true, true) => hs.xx[r / 2][c / 2][(r % 2, c % 2)],
            (true, false) => hs.xu[r / 2][(r % 2, c - 4)],
            (false, true) => hs.xu[c / 2][(c % 2, r - 4)],
            (false, false) => hs.uu[(r - 4, c - 4)],
        });
        hessian += t.transpose() * hy * &t * h;
        // x_{i+1} - x_i - h A x_theta - h B u = 0, A the block shift
        for r in 0..4 {
            let row = i * 4 + r;
            if let Some(c) = xcol(i + 1, r) {
                constraints[(row, c)] += 1.0;
            }
            if let Some(c) = xcol(i, r) {
                constraints[(row, c)] -= 1.0;
            }
            if r < 2 {
                if let Some(c) = xcol(i, r + 2) {
                    constraints[(row, c)] -= h * (1.0 - theta);
                }
                if let Some(c) = xcol(i + 1, r + 2) {
                    constraints[(row, c)] -= h * theta;
                }
            } else {
                constraints[(row, ucol(i, r - 2))] -= h;
            }
        }
    }
    let svd = constraints.transpose().svd(true, false);
    let u = svd.u.unwrap();
    // the constraints have full row rank: the null space is spanned by the left singular
    // vectors of C^T beyond the first 4N (completed by a QR of the whole space)
    let full = DMatrix::<f64>::from_fn(dim, dim, |r, c| {
        if c < u.ncols() {
            u[(r, c)]
        } else if r == c {
            1.0
        } else {
            0.0
        }
    });
    let q = full.qr().q();
    let z = q.columns(steps * 4, dim - steps * 4).into_owned();
    let reduced = z.transpose() * hessian * &z;
    reduced.symmetric_eigenvalues().min()
}

#[test]
fn certificate_eigenvalue_matches_a_dense_computation() {
    let system = DoublePendulum { g: 9.81 };
    let plan = pendulum_problem(&system, 1.0, 24)
        .with_options(PlanOptions::default().with_min_eigenvalue(true))
        .solve(PlanGuess::Spline)
        .unwrap();
    let dense = dense_min_reduced_eigenvalue(&system, &plan);
    let lanczos = plan.certificate.min_reduced_hessian_eig;
    assert!(dense > 0.0);
    assert!(
        (lanczos - dense).abs() < 1e-6 * dense.abs(),
        "Lanczos {lanczos:e}, dense {dense:e}"
    );
}

/// With free components of x_0 or x_N the certificate's smallest eigenvalue is that of the
/// reduced Hessian in those components too (a dense computation agrees to 1e-6).
#[test]
fn certificate_eigenvalue_with_free_ends_matches_a_dense_computation() {
    let system = DoublePendulum { g: 9.81 };
    let cases: [(&[usize], &[usize]); 3] = [(&[], &[2, 3]), (&[3], &[]), (&[2], &[1, 3])];
    for (start, end) in cases {
        let plan = pendulum_problem(&system, 1.0, 24)
            .with_free_start(start)
            .with_free_end(end)
            .solve(PlanGuess::Spline)
            .unwrap();
        let dense = dense_min_reduced_eigenvalue_free(&system, &plan, (start, end));
        let lanczos = plan.certificate.min_reduced_hessian_eig;
        assert!(dense > 0.0, "free {start:?} {end:?}: dense {dense:e}");
        assert!(
            (lanczos - dense).abs() < 1e-6 * dense.abs(),
            "free {start:?} {end:?}: Lanczos {lanczos:e}, dense {dense:e}"
        );
    }
}

/// With N = k steps between fixed ends the constraints leave no direction (the plan is the one
/// path that meets the ends): the certificate's smallest eigenvalue is the minimum over an
/// empty set, +infinity, not the reciprocal of a rounding error; one step more and it is
/// finite and matches a dense computation.
#[test]
fn certificate_eigenvalue_is_infinite_where_the_constraints_leave_no_direction() {
    let system = DoublePendulum { g: 9.81 };
    let plan = pendulum_problem(&system, 1.0, 2)
        .solve(PlanGuess::Spline)
        .unwrap();
    let c = &plan.certificate;
    assert!(c.stationarity <= 1e-9 && c.feasibility <= 1e-9, "{c:?}");
    assert_eq!(c.min_reduced_hessian_eig, f64::INFINITY, "{c:?}");
    let plan = pendulum_problem(&system, 1.0, 3)
        .solve(PlanGuess::Spline)
        .unwrap();
    let dense = dense_min_reduced_eigenvalue(&system, &plan);
    let lanczos = plan.certificate.min_reduced_hessian_eig;
    assert!(dense.is_finite() && dense > 0.0, "dense {dense:e}");
    assert!(
        (lanczos - dense).abs() < 1e-6 * dense.abs(),
        "Lanczos {lanczos:e}, dense {dense:e}"
    );
}

/// The root finder on the optimality conditions returns a stationary point of the T = 2
/// swing-up with negative curvature; the optimizer descends from the same guess to a point of
/// lower cost with a positive definite reduced Hessian, and refuses the root finder's point as
/// a minimum.
#[test]
fn the_optimizer_descends_where_the_root_finder_stops_at_a_saddle() {
    let system = DoublePendulum { g: 9.81 };
    let goal = [PI, 0.0, 0.0, 0.0];
    let root = BoundaryValueProblem::new(&system, &[0.0; 4], &goal, 2.0, 200)
        .solve(retract::bvp::root_finder::Guess::Spline)
        .unwrap();
    let plan = pendulum_problem(&system, 2.0, 200)
        .solve(PlanGuess::Spline)
        .unwrap();
    assert!(
        plan.cost < 0.5 * root.cost,
        "optimizer {} root finder {}",
        plan.cost,
        root.cost
    );
    assert_eq!(plan.certificate.negative_directions, 0);
    assert_eq!(plan.certificate.negative_directions, 0);
    // started at the root finder's point, the optimizer sees a KKT point with negative curvature
    let x: Vec<_> = root
        .states
        .iter()
        .map(|z| z.fixed_rows::<4>(0).into_owned())
        .collect();
    let u: Vec<_> = root
        .unknowns
        .iter()
        .map(|w| w.fixed_rows::<2>(8).into_owned())
        .collect();
    let without_escapes = PlanOptions::default().with_saddle_escapes(0);
    let error = pendulum_problem(&system, 2.0, 200)
        .with_options(without_escapes.with_max_iterations(1))
        .solve(PlanGuess::Path { x: &x, u: &u })
        .unwrap_err();
    let Failure::NotAMinimum {
        negative_directions,
    } = error.failure
    else {
        panic!("expected NotAMinimum, got {error}");
    };
    assert!(negative_directions > 0);
    let last = error.last.expect("the saddle is attached");
    assert!(last.certificate.stationarity < 1e-9 && last.certificate.feasibility < 1e-9);
    assert!((last.cost - root.cost).abs() < 1e-9 * root.cost);
    // with its escapes (the default) it leaves that saddle downhill to a certified minimum
    let escaped = pendulum_problem(&system, 2.0, 200)
        .solve(PlanGuess::Path { x: &x, u: &u })
        .unwrap();
    assert!(
        escaped.cost < root.cost,
        "{} vs {}",
        escaped.cost,
        root.cost
    );
    common::assert_strict_minimum(&escaped, "escaped");
}

/// Every swing-up of the suite at reduced size (N = 25 T) converges to a certified minimum;
/// the pendulum's cost decreases with the horizon (more time, less torque).
#[test]
fn swing_ups_converge_to_certified_minima() {
    let system = DoublePendulum { g: 9.81 };
    let mut previous = f64::INFINITY;
    for t_end in [2.0, 3.0, 4.0] {
        let plan = pendulum_problem(&system, t_end, (25.0 * t_end) as usize)
            .solve(PlanGuess::Spline)
            .unwrap();
        assert_eq!(plan.certificate.negative_directions, 0);
        assert!(plan.certificate.stationarity <= 1e-9 && plan.certificate.feasibility <= 1e-9);
        assert!(
            plan.cost < previous,
            "T = {t_end}: {} after {previous}",
            plan.cost
        );
        previous = plan.cost;
    }
    // the cart-pole with its unactuated pole, likewise (the cost need not fall with T here:
    // the suite's T = 3 and 4 costs are close)
    for t_end in [2.0, 3.0, 4.0] {
        let plan = OptimalControlProblem::new(
            &CartPole::new(),
            &[0.0; 4],
            &UPRIGHT,
            t_end,
            (25.0 * t_end) as usize,
        )
        .with_equality(&PoleTorque::new())
        .solve(PlanGuess::Spline)
        .unwrap();
        assert_eq!(plan.certificate.negative_directions, 0);
        assert!(plan.certificate.stationarity <= 1e-9 && plan.certificate.feasibility <= 1e-9);
    }
}

/// The acrobot (only the elbow actuated: cost 1/2 tau_2^2, tau_1 = 0 as an equality) swings up
/// to a certified minimum with the shoulder torque zero at every step, and costs at least the
/// fully actuated swing-up (1/2 |tau|^2) of the same horizon: its plan is a candidate there.
#[test]
fn the_acrobot_swings_up_with_a_passive_shoulder() {
    use crate::pendulum::{ElbowCost, ShoulderTorque, TorqueCost};
    use retract::JetFunction;
    let (t_end, steps) = (2.0, 50);
    let goal = [PI, 0.0, 0.0, 0.0];
    let passive = ShoulderTorque::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let plan = OptimalControlProblem::new(
        &ElbowCost::new(1.0, 1.0, 1.0, 1.0, 9.81),
        &[0.0; 4],
        &goal,
        t_end,
        steps,
    )
    .with_equality(&passive)
    .solve(PlanGuess::Spline)
    .unwrap();
    assert_eq!(plan.certificate.negative_directions, 0);
    // (stationarity at the acceptable level, 1e-6: the line search stalls at rounding near
    // 5e-9 here, the torques being ~100 N m)
    assert!(plan.certificate.stationarity <= 1e-6 && plan.certificate.feasibility <= 1e-9);
    for (i, u) in plan.u.iter().enumerate() {
        let xt = (plan.x[i] + plan.x[i + 1]) * 0.5;
        let blocks = [
            xt.fixed_rows::<2>(0).into_owned(),
            xt.fixed_rows::<2>(2).into_owned(),
        ];
        let torque = passive.value(&blocks, u);
        assert!(torque.abs() < 1e-9, "step {i}: shoulder torque {torque:e}");
    }
    let full = TorqueCost::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let actuated = OptimalControlProblem::new(&full, &[0.0; 4], &goal, t_end, steps)
        .solve(PlanGuess::Spline)
        .unwrap();
    assert!(
        plan.cost > actuated.cost,
        "acrobot {} vs fully actuated {}",
        plan.cost,
        actuated.cost
    );
}

/// At any N the plan keeps out of the disc along every chord (checked here at 200 points per
/// chord), and N <= 300 converges from the scene's feasible guess.
#[test]
fn no_plan_passes_through_the_disc_at_any_n() {
    for steps in [2, 3, 4, 5, 6, 8, 10, 20, 50, 100, 200, 300] {
        match solve_disc(steps, PlanOptions::default()) {
            Ok(plan) => {
                for (a, b) in plan.x.iter().zip(&plan.x[1..]) {
                    for j in 0..=200 {
                        let s = j as f64 / 200.0;
                        let q = a.fixed_rows::<2>(0) * (1.0 - s) + b.fixed_rows::<2>(0) * s;
                        assert!(
                            q.norm() > 1.0,
                            "N = {steps}: chord point {q} inside the disc"
                        );
                    }
                }
                assert!(plan.cost > 0.0, "N = {steps}: J = {}", plan.cost);
            }
            Err(e) => assert!(steps < 20, "N = {steps}: {e}"),
        }
    }
}

/// A failed solve carries the last iterate with its residuals and iteration count.
#[test]
fn failures_carry_the_last_iterate() {
    let system = DoublePendulum { g: 9.81 };
    let error = pendulum_problem(&system, 3.0, 60)
        .with_options(PlanOptions::default().with_max_iterations(3))
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert_eq!(error.failure, Failure::IterationLimit);
    let last = error.last.as_ref().expect("an iterate");
    assert_eq!(last.iterations, 3);
    assert_eq!(
        (last.x.len(), last.u.len(), last.momenta.len()),
        (61, 60, 61)
    );
    assert!(last.certificate.stationarity > 1e-9 && last.certificate.stationarity.is_finite());
    assert!(error.to_string().contains("after 3 iterations"), "{error}");
    let timed = pendulum_problem(&system, 3.0, 60)
        .with_options(PlanOptions::default().with_max_time(std::time::Duration::ZERO))
        .solve(PlanGuess::Spline)
        .unwrap_err();
    assert_eq!(timed.failure, Failure::TimeLimit);
    assert!(timed.last.is_some());
    // a guess through the disc is refused before any iteration
    let straight =
        OptimalControlProblem::new(&OneDisc { tau: 1e-2 }, &DISC_START, &DISC_GOAL, 4.0, 40)
            .solve(PlanGuess::Spline)
            .unwrap_err();
    assert!(
        matches!(straight.failure, Failure::GuessOutsideDomain { .. }),
        "{straight}"
    );
    // a chord spacing that is not > 0, or more pieces than the cap, is refused
    for options in [
        PlanOptions::default().with_chord_check(0.0, 16),
        PlanOptions::default().with_chord_check(f64::NAN, 16),
        PlanOptions::default().with_chord_check(0.02, retract::step::MAX_CHORD_PIECES + 1),
    ] {
        let error = solve_disc(20, options).unwrap_err();
        assert!(matches!(error.failure, Failure::Invalid(_)), "{error}");
        assert!(error.to_string().contains("chord"), "{error}");
    }
}

/// The cart-pole of the swing-up suite: the cost 1/2 F^2 on the cart force.
#[higher_order_lagrangian(order = 2)]
fn cart_pole(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    let force = 1.3 * ddq[0] + 0.15 * q[1].cos() * ddq[1] - 0.15 * q[1].sin() * dq[1] * dq[1];
    0.5 * force * force
}

/// The pole's generalized force tau_p = mp l cos(th) x'' + mp l^2 th'' + mp g l sin(th).
#[jet_function(order = 2)]
fn pole_torque(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.15 * q[1].cos() * ddq[0] + 0.075 * ddq[1] + 0.15 * 9.81 * q[1].sin()
}

/// A bound on the cart force F of [`cart_pole`]: `limit - sign F >= 0`.
#[jet_function(order = 2)]
fn force_margin(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], limit: f64, sign: f64) -> f64 {
    let force = 1.3 * ddq[0] + 0.15 * q[1].cos() * ddq[1] - 0.15 * q[1].sin() * dq[1] * dq[1];
    limit - sign * force
}

/// The cart-pole swing-up (T = 2, N = 50) with its cart force bounded, |F| <= 14: the free
/// plan exceeds the bound, the bounded one keeps it at every evaluation point (to 1e-9), still
/// with the pole unactuated, at a higher cost, certified.
#[test]
fn the_cart_force_bound_holds_and_is_active() {
    let (t_end, steps, limit) = (2.0, 50, 14.0);
    let force = |plan: &Plan<2, 4>, i: usize| {
        let xt = (plan.x[i] + plan.x[i + 1]) * 0.5;
        let blocks = [
            xt.fixed_rows::<2>(0).into_owned(),
            xt.fixed_rows::<2>(2).into_owned(),
        ];
        let f = limit - ForceMargin::new(limit, 1.0).value(&blocks, &plan.u[i]);
        (f, PoleTorque::new().value(&blocks, &plan.u[i]))
    };
    let (system, unactuated) = (CartPole::new(), PoleTorque::new());
    let problem = OptimalControlProblem::new(&system, &[0.0; 4], &UPRIGHT, t_end, steps)
        .with_equality(&unactuated);
    let free = problem.clone().solve(PlanGuess::Spline).unwrap();
    let (upper, lower) = (ForceMargin::new(limit, 1.0), ForceMargin::new(limit, -1.0));
    let bounded = problem
        .with_inequality(&upper)
        .with_inequality(&lower)
        .solve(PlanGuess::Spline)
        .unwrap();
    let peak = |plan: &Plan<2, 4>| {
        (0..steps)
            .map(|i| force(plan, i).0.abs())
            .fold(0.0, f64::max)
    };
    assert!(peak(&free) > limit + 0.5, "free peak {}", peak(&free));
    assert!(
        peak(&bounded) <= limit + 1e-9,
        "bounded peak {}",
        peak(&bounded)
    );
    for i in 0..steps {
        assert!(force(&bounded, i).1.abs() < 1e-9, "step {i}: pole torque");
    }
    assert!(
        bounded.cost > free.cost,
        "{} vs {}",
        bounded.cost,
        free.cost
    );
    assert_eq!(bounded.certificate.negative_directions, 0);
}

/// The same cart-pole with the constraint as a quadratic penalty rho/2 tau_p^2 in the cost.
#[higher_order_lagrangian(order = 2)]
fn penalised_cart_pole(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], rho: f64) -> f64 {
    let force = 1.3 * ddq[0] + 0.15 * q[1].cos() * ddq[1] - 0.15 * q[1].sin() * dq[1] * dq[1];
    let torque = 0.15 * q[1].cos() * ddq[0] + 0.075 * ddq[1] + 0.15 * 9.81 * q[1].sin();
    0.5 * force * force + 0.5 * rho * torque * torque
}

const UPRIGHT: [f64; 4] = [0.0, PI, 0.0, 0.0];

/// The swing-up with the pole torque constrained to zero keeps it zero at every evaluation
/// point, is certified, and is the limit of the quadratic-penalty problems: the force cost of
/// the penalised optimum approaches it as the weight grows (error O(1/rho)).
#[test]
fn the_cart_pole_swing_up_keeps_the_pole_unactuated() {
    let (t_end, steps) = (2.0, 50);
    let plan = OptimalControlProblem::new(&CartPole::new(), &[0.0; 4], &UPRIGHT, t_end, steps)
        .with_equality(&PoleTorque::new())
        .solve(PlanGuess::Spline)
        .unwrap();
    assert_eq!(plan.certificate.negative_directions, 0);
    for (i, u) in plan.u.iter().enumerate() {
        let xt = (plan.x[i] + plan.x[i + 1]) * 0.5;
        let blocks = [
            xt.fixed_rows::<2>(0).into_owned(),
            xt.fixed_rows::<2>(2).into_owned(),
        ];
        let torque = PoleTorque::new().value(&blocks, u);
        assert!(torque.abs() < 1e-9, "step {i}: pole torque {torque:e}");
    }
    let mut previous_gap = f64::INFINITY;
    let mut guess = None;
    for rho in [1e3, 1e4, 1e5, 1e6] {
        let system = PenalisedCartPole { rho };
        let problem = OptimalControlProblem::new(&system, &[0.0; 4], &UPRIGHT, t_end, steps);
        let penalised = match &guess {
            Some(previous) => problem.solve(PlanGuess::Plan(previous)),
            None => problem.solve(PlanGuess::Spline),
        }
        .unwrap();
        let force_cost: f64 = (0..steps)
            .map(|i| {
                let xt = (penalised.x[i] + penalised.x[i + 1]) * 0.5;
                let blocks = [
                    xt.fixed_rows::<2>(0).into_owned(),
                    xt.fixed_rows::<2>(2).into_owned(),
                ];
                plan.h * CartPole::new().lagrangian(&blocks, &penalised.u[i])
            })
            .sum();
        let gap = (force_cost - plan.cost).abs();
        println!(
            "rho {rho:e}: force cost {force_cost} vs constrained {} (gap {gap:e})",
            plan.cost
        );
        assert!(
            gap < 0.5 * previous_gap,
            "rho = {rho:e}: gap {gap:e} after {previous_gap:e}"
        );
        previous_gap = gap;
        guess = Some(penalised);
    }
    assert!(previous_gap < 1e-3 * plan.cost);
}

/// Receding horizon: after one step the shifted plan is a good start, so two real-time
/// iterations reach the new problem's minimum cost to 1e-6 (residuals below 1e-4), and a cap of one
/// iteration is reported as not converged rather than as a plan.
#[test]
fn real_time_iterations_track_a_receding_horizon() {
    let system = OneDisc { tau: 1e-2 };
    let steps = 200;
    let plan = solve_disc(steps, PlanOptions::default()).unwrap();
    let shifted = plan.shifted();
    let start: [f64; 4] = plan.x[1].into();
    let problem = OptimalControlProblem::new(&system, &start, &DISC_GOAL, 4.0, steps);
    let full = problem.solve(PlanGuess::Plan(&shifted)).unwrap();
    let quick = problem
        .solve_real_time(PlanGuess::Plan(&shifted), 2)
        .unwrap();
    let c = &quick.plan.certificate;
    assert!(c.stationarity < 1e-4 && c.feasibility < 1e-9, "{c:?}");
    assert!((quick.plan.cost - full.cost).abs() < 1e-6 * full.cost);
    let one = problem.solve_real_time(PlanGuess::Spline, 1);
    // the straight spline crosses the disc: an error, not a plan
    assert!(one.is_err());
    let capped = problem
        .solve_real_time(
            PlanGuess::Plan(&solve_disc(steps, PlanOptions::default()).unwrap()),
            1,
        )
        .unwrap();
    assert!(!capped.converged);
    assert_eq!(capped.plan.iterations, 1);
}

/// Problems, plans and solutions can cross threads when their parts can (issue 16, item 8):
/// the constraint and clearance references are `Sync`.
#[test]
fn public_problem_and_solution_types_are_send_and_sync() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<OptimalControlProblem<'_, OneDisc, 2, 2, 4>>();
    send_sync::<Plan<2, 4>>();
    send_sync::<retract::bvp::PlanError<2, 4>>();
    send_sync::<BoundaryValueProblem<'_, OneDisc, 8, 10>>();
    send_sync::<retract::bvp::root_finder::BvpSolution<8, 10>>();
    send_sync::<retract::Trajectory<8>>();
    send_sync::<retract::Interrupted<8>>();
    // a Lagrangian without parameters is a unit struct, a value by its name alone
    let _: DoublePendulumUnit = DoublePendulumUnit;
}

/// The double pendulum with g = 9.81 written in: no parameters.
#[higher_order_lagrangian(order = 2)]
fn double_pendulum_unit(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + 9.81 * q[0].cos()
}

/// A warm start from the shifted plan converges in a few iterations, the last of them a
/// simplified Newton step with the previous factorisation; the certificate is still that of
/// the returned point: its smallest reduced eigenvalue matches a dense computation there and
/// the plan satisfies the lifted scheme.
#[test]
fn a_warm_start_is_certified_at_the_returned_point() {
    let system = OneDisc { tau: 1e-2 };
    let steps = 100;
    let options = PlanOptions::default().with_min_eigenvalue(true);
    let plan = solve_disc(steps, options).unwrap();
    let start: [f64; 4] = plan.x[1].into();
    let warm = OptimalControlProblem::new(&system, &start, &DISC_GOAL, 4.0, steps)
        .with_options(options)
        .solve(PlanGuess::Plan(&plan.shifted()))
        .unwrap();
    assert!(warm.iterations <= 4, "{} iterations", warm.iterations);
    let c = &warm.certificate;
    assert!(c.stationarity <= 1e-9 && c.feasibility <= 1e-9, "{c:?}");
    let dense = dense_min_reduced_eigenvalue(&system, &warm);
    let lanczos = c.min_reduced_hessian_eig;
    assert!(dense > 0.0);
    assert!(
        (lanczos - dense).abs() < 1e-6 * dense.abs(),
        "Lanczos {lanczos:e}, dense {dense:e}"
    );
    let worst = scheme_residual(&system, &warm);
    assert!(worst < 1e-9, "scheme residual {worst:e}");
}

/// Second-order corrections (4, IPOPT's default) against none, on the cart-pole swing-ups whose
/// pole-torque equality curves: both reach the same certified minimum, and the corrections
/// cost no iterations overall (they replace halvings of steps that the curvature of the
/// equality would have cut).
#[test]
fn second_order_corrections_keep_the_minimum_and_save_iterations() {
    let mut counts = [0, 0];
    for t_end in [2.0, 3.0, 4.0] {
        let solve = |corrections: usize| {
            let options = PlanOptions::default().with_second_order_corrections(corrections);
            let steps = (25.0 * t_end) as usize;
            OptimalControlProblem::new(&CartPole::new(), &[0.0; 4], &UPRIGHT, t_end, steps)
                .with_equality(&PoleTorque::new())
                .with_options(options)
                .solve(PlanGuess::Spline)
                .unwrap()
        };
        let (with, without) = (solve(4), solve(0));
        for plan in [&with, &without] {
            assert_eq!(plan.certificate.negative_directions, 0);
            assert!(plan.certificate.stationarity <= 1e-9);
        }
        let gap = (with.cost - without.cost).abs() / without.cost;
        assert!(
            gap <= 1e-8,
            "T = {t_end}: {} against {}",
            with.cost,
            without.cost
        );
        counts[0] += with.iterations;
        counts[1] += without.iterations;
    }
    eprintln!("iterations with and without corrections: {counts:?}");
    assert!(counts[0] <= counts[1], "iterations {counts:?}");
}
