//! The runtime on a system written by hand (`models::PlanarBarrier`, the paper's
//! L = 1/2|q''|^2 + tau/(|q|^2 - r^2) on R^2): order, symplecticity, the closed-form V = 0
//! solution, Jacobians against finite differences, and every error variant from a real input.

use crate::common;

use retract::diagnostics::{energy_error, rk4_step, symplecticity_error};
use retract::models::PlanarBarrier;
use retract::nalgebra::{SMatrix, SVector};
use retract::{Error, LiftedSystem, NewtonOptions, StepOptions, step, trajectory};

type State = SVector<f64, 8>;

fn barrier(tau: f64) -> PlanarBarrier {
    PlanarBarrier {
        tau,
        radius: 1.0,
        mass: 1.0,
    }
}

/// z(0) from derivative data (q, q', q'', q''').
fn start(system: &PlanarBarrier, jet: [f64; 8]) -> State {
    system.legendre(&State::from_column_slice(&jet))
}

/// Initial data passing the obstacle on the upper side, bending visibly over t in [0, 1].
const PASSING: [f64; 8] = [-2.0, 1.1, 1.0, -0.2, 0.3, -0.4, 0.1, 0.2];

/// Observed orders of the theta-scheme at t = 1 against RK4 with 1e4 steps.
fn observed_orders(theta: f64) -> Vec<f64> {
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    let reference = common::rk4_final(&system, &z0, 1.0, 10_000);
    common::observed_orders(
        &system,
        &z0,
        &reference,
        1.0,
        theta,
        &[20, 40, 80, 160, 320],
    )
}

#[test]
fn the_reference_trajectory_stays_clear_of_the_obstacle() {
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    let run = trajectory(&system, &z0, 0.01, 100, &StepOptions::default()).unwrap();
    let clearance = run
        .states
        .iter()
        .map(|z| (z[0] * z[0] + z[1] * z[1]).sqrt() - 1.0)
        .fold(f64::INFINITY, f64::min);
    assert!(clearance > 0.1, "clearance {clearance}");
    // and the barrier matters: the path differs from the free spline by more than 1e-3
    let free = trajectory(&barrier(0.0), &z0, 0.01, 100, &StepOptions::default()).unwrap();
    let gap = (run.states[100] - free.states[100]).amax();
    assert!(gap > 1e-3, "barrier effect {gap}");
}

#[test]
fn midpoint_is_second_order() {
    let orders = observed_orders(0.5);
    for (i, p) in orders.iter().enumerate() {
        assert!(
            (1.85..2.15).contains(p),
            "refinement {i}: order {p} ({orders:?})"
        );
    }
}

#[test]
fn symplectic_euler_is_first_order() {
    for theta in [0.0, 1.0] {
        let orders = observed_orders(theta);
        let last = *orders.last().unwrap();
        assert!((0.9..1.15).contains(&last), "theta {theta}: {orders:?}");
    }
}

#[test]
fn step_map_is_symplectic_for_every_theta() {
    let system = barrier(0.5);
    // close to the obstacle, so the nonlinear part of the Hessian is large
    let z0 = start(&system, [-1.1, 0.6, 1.0, -0.2, 0.3, -0.4, 0.1, 0.2]);
    for theta in [0.0, 0.25, 0.5, 1.0] {
        let options = StepOptions::default().with_theta(theta);
        let err = symplecticity_error(&system, &z0, 0.05, &options).unwrap();
        assert!(err < 1e-12, "theta {theta}: |DPsi^T J DPsi - J| = {err:e}");
    }
}

#[test]
fn a_wrong_jacobian_would_break_symplecticity() {
    // Sanity check of the diagnostic itself: a non-symplectic map (RK4's derivative,
    // by finite differences) shows an error far above rounding.
    let system = barrier(0.5);
    let z0 = start(&system, [-1.1, 0.6, 1.0, -0.2, 0.3, -0.4, 0.1, 0.2]);
    let h = 0.05;
    let eps = 1e-6;
    let d_psi = SMatrix::<f64, 8, 8>::from_fn(|r, c| {
        let mut plus = z0;
        let mut minus = z0;
        plus[c] += eps;
        minus[c] -= eps;
        (rk4_step(&system, &plus, h).unwrap()[r] - rk4_step(&system, &minus, h).unwrap()[r])
            / (2.0 * eps)
    });
    let j = retract::diagnostics::canonical_structure::<8>();
    let err = (d_psi.transpose() * j * d_psi - j).amax();
    assert!(err > 1e-8, "RK4 symplecticity error {err:e}");
}

/// MATH.md, slip 1 with the corrected signs: the explicit midpoint update for V = 0.
#[test]
fn free_spline_matches_the_closed_form_discrete_solution() {
    let system = barrier(0.0);
    let h = 0.1;
    let z0 = start(&system, [0.3, -0.2, 1.0, 0.5, -0.7, 0.4, 1.5, -0.8]);
    let run = trajectory(&system, &z0, h, 100, &StepOptions::default()).unwrap();
    let mut z = z0;
    for (i, got) in run.states.iter().enumerate().skip(1) {
        let (q, dq, p0, p1) = (
            z.fixed_rows::<2>(0),
            z.fixed_rows::<2>(2),
            z.fixed_rows::<2>(4),
            z.fixed_rows::<2>(6),
        );
        let q1 = q + dq * h + p1 * (h * h / 2.0) - p0 * (h * h * h / 4.0);
        let dq1 = dq + p1 * h - p0 * (h * h / 2.0);
        let p11 = p1 - p0 * h;
        let mut next = z;
        next.fixed_rows_mut::<2>(0).copy_from(&q1);
        next.fixed_rows_mut::<2>(2).copy_from(&dq1);
        next.fixed_rows_mut::<2>(6).copy_from(&p11);
        z = next;
        let err = (got - z).amax() / z.amax().max(1.0);
        assert!(
            err < 1e-12,
            "step {i}: computed {got}, closed form {z}, rel err {err:e}"
        );
    }
}

#[test]
fn energy_error_shrinks_at_second_order() {
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    let err = |steps: usize| {
        let run = trajectory(
            &system,
            &z0,
            1.0 / steps as f64,
            steps,
            &StepOptions::default(),
        )
        .unwrap();
        energy_error(&system, &run.states).unwrap()
    };
    let (coarse, fine) = (err(20), err(40));
    let order = (coarse / fine).log2();
    assert!(
        coarse > 0.0 && (1.8..2.3).contains(&order),
        "{coarse:e} -> {fine:e}: {order}"
    );
}

#[test]
fn vector_field_is_hamiltons_equations() {
    let system = barrier(0.3);
    let z = start(&system, [-1.5, 0.9, 0.4, -0.3, 0.2, 0.7, -0.6, 0.1]);
    let f = system.vector_field(&z).unwrap();
    let q = z.fixed_rows::<2>(0);
    let s = q.norm_squared() - 1.0;
    let grad_v = q * (-2.0 * 0.3 / (s * s));
    let expected = [
        z[2], z[3], // q' = x_1
        z[6], z[7], // q'' = u = p_1 / m
        grad_v[0], grad_v[1], // p_0' = dL/dq
        -z[4], -z[5], // p_1' = -p_0
    ];
    for (c, e) in expected.iter().enumerate() {
        assert!((f[c] - e).abs() < 1e-14, "component {c}: {} vs {e}", f[c]);
    }
}

fn finite_difference_check<const C: usize>(
    analytic: &SMatrix<f64, 10, C>,
    column: impl Fn(usize, f64) -> SVector<f64, 10>,
) {
    for c in 0..C {
        let eps = 1e-6;
        let fd = (column(c, eps) - column(c, -eps)) / (2.0 * eps);
        let err = (fd - analytic.column(c)).amax();
        assert!(
            err < 1e-6 * (1.0 + fd.amax()),
            "column {c}: fd {fd} vs {}",
            analytic.column(c)
        );
    }
}

#[test]
fn jacobians_match_finite_differences() {
    let system = PlanarBarrier {
        tau: 0.7,
        radius: 1.0,
        mass: 1.3,
    };
    let z0 = start(&system, [-1.3, 0.8, 0.4, -0.3, 0.2, 0.7, -0.6, 0.1]);
    let h = 0.07;
    for theta in [0.0, 0.3, 0.5, 1.0] {
        let w = system.predictor(&z0, h, theta).unwrap()
            + SVector::<f64, 10>::from_fn(|i, _| 0.01 * (i as f64).sin());
        finite_difference_check(&system.jacobian(&z0, &w, h, theta), |c, eps| {
            let mut v = w;
            v[c] += eps;
            system.residual(&z0, &v, h, theta)
        });
        finite_difference_check(&system.jacobian_initial(&z0, &w, h, theta), |c, eps| {
            let mut v = z0;
            v[c] += eps;
            system.residual(&v, &w, h, theta)
        });
    }
}

#[test]
fn nan_parameter_is_a_non_finite_error() {
    let system = barrier(f64::NAN);
    let z0 = start(&barrier(0.1), PASSING);
    let e = step(&system, &z0, 0.01, &StepOptions::default()).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e:?}");
}

#[test]
fn start_on_the_singular_circle_is_a_non_finite_error() {
    let system = barrier(0.1);
    let z0 = start(&system, [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]);
    let e = step(&system, &z0, 0.01, &StepOptions::default()).unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e:?}");
    assert!(e.to_string().contains("non-finite"), "{e}");
}

#[test]
fn degenerate_lagrangian_is_a_singular_jacobian() {
    // m = 0: L does not depend on q'', so p_1 = dL/du cannot be inverted for u.
    let system = PlanarBarrier {
        tau: 0.1,
        radius: 1.0,
        mass: 0.0,
    };
    let z0 = start(&barrier(0.1), PASSING);
    let e = step(&system, &z0, 0.01, &StepOptions::default()).unwrap_err();
    assert!(matches!(e, Error::SingularJacobian { .. }), "{e:?}");
}

#[test]
fn iteration_cap_is_no_convergence_with_the_last_residual() {
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    let newton = NewtonOptions::default()
        .with_max_iterations(1)
        .with_residual_tolerance(1e-300, 0.0)
        .with_step_tolerance(0.0, 0.0);
    let options = StepOptions::default().with_newton(newton);
    match step(&system, &z0, 0.1, &options) {
        Err(Error::NoConvergence {
            iterations,
            residual_norm,
        }) => {
            assert_eq!(iterations, 1);
            assert!(residual_norm.is_finite() && residual_norm > 0.0);
        }
        other => panic!("expected NoConvergence, got {other:?}"),
    }
}

#[test]
fn a_line_search_failure_from_real_steps() {
    // Next to a strong barrier (tau = 50, 0.05 from the circle, moving in):
    let system = barrier(50.0);
    let z0 = start(&system, [-1.05, 0.0, 1.0, 0.3, 0.0, 0.0, 0.0, 0.0]);
    // h = 0.2: no step length along the Newton directions decreases |F| (measured: after
    // 35 iterations), with the default options;
    let e = step(&system, &z0, 0.2, &StepOptions::default()).unwrap_err();
    assert!(matches!(e, Error::LineSearchFailed { .. }), "{e:?}");
    assert!(e.to_string().contains("line search") && e.to_string().contains("step size"));
    // h = 0.4: the full Newton step overshoots when backtracking is disabled (as a hard
    // real-time controller might), while the default backtracking converges.
    let no_backtracking =
        StepOptions::default().with_newton(NewtonOptions::default().with_max_backtracks(0));
    let e = step(&system, &z0, 0.4, &no_backtracking).unwrap_err();
    assert!(matches!(e, Error::LineSearchFailed { .. }), "{e:?}");
    let (z1, _) = step(&system, &z0, 0.4, &StepOptions::default()).expect("backtracking converges");
    assert!(z1.iter().all(|v| v.is_finite()));
}

#[test]
fn an_interrupted_trajectory_keeps_the_states_before_the_failure() {
    // Heading straight at the obstacle with tau = 0: the free spline crosses the circle,
    // and with a NaN-free run but an iteration cap of 1 the first step fails.
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    let newton = NewtonOptions::default()
        .with_max_iterations(1)
        .with_residual_tolerance(1e-300, 0.0)
        .with_step_tolerance(0.0, 0.0);
    let failed = trajectory(
        &system,
        &z0,
        0.1,
        5,
        &StepOptions::default().with_newton(newton),
    )
    .unwrap_err();
    assert_eq!(failed.step, 0);
    assert_eq!(failed.trajectory.states, vec![z0]);
    assert!(failed.to_string().contains("step 0"), "{failed}");
}

#[test]
fn invalid_theta_and_step_are_rejected() {
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    for (h, theta) in [(0.01, 1.5), (0.01, -0.1), (0.0, 0.5), (f64::NAN, 0.5)] {
        let e = step(&system, &z0, h, &StepOptions::default().with_theta(theta)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidArgument { .. }),
            "h {h} theta {theta}: {e:?}"
        );
    }
}

#[test]
fn newton_reports_few_iterations_from_the_predictor() {
    let system = barrier(0.5);
    let z0 = start(&system, PASSING);
    let run = trajectory(&system, &z0, 0.01, 100, &StepOptions::default()).unwrap();
    assert!(run.max_iterations() <= 4, "max {}", run.max_iterations());
    assert!(run.mean_iterations() >= 1.0);
    assert!(run.reports.iter().all(|r| r.residual_norm < 1e-12));
}
