//! Structure of the integrator, through `#[higher_order_lagrangian]` (what a user gets):
//! order, symplecticity, Noether momentum, bounded energy error against RK4's drift, and
//! agreement with exact polynomial splines for k = 3 and k = 4.

use crate::common;

use common::models::{PaisUhlenbeck, RigidBody, bounded_pais_uhlenbeck};
use retract::diagnostics::{component_drift, rk4_step, symplecticity_error};
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, step, trajectory};

/// Minimum jerk in R^2: L = 1/2 |q'''|^2 (exact solutions: quintics).
#[higher_order_lagrangian(order = 3)]
fn jerk_spline(_q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], dddq: [f64; 2]) -> f64 {
    0.5 * (dddq[0].powi(2) + dddq[1].powi(2))
}

/// Minimum snap in R^2: L = 1/2 |q''''|^2 (exact solutions: degree-7 polynomials).
#[higher_order_lagrangian(order = 4)]
fn snap_spline(_q: [f64; 2], _dq: [f64; 2], _ddq: [f64; 2], _dddq: [f64; 2], d4q: [f64; 2]) -> f64 {
    0.5 * (d4q[0].powi(2) + d4q[1].powi(2))
}

/// (q, q', q'', q''') at t = 0: passing the disc 0.2 to 0.3 above it while turning.
const PASSING: [f64; 12] = [
    -2.0, 1.2, 0.0, 1.0, 0.0, 0.5, 0.1, -0.2, 0.3, 0.0, 0.1, -0.2,
];

fn rigid(tau: f64) -> RigidBody {
    RigidBody { tau, r: 1.0 }
}

#[test]
fn obstacle_system_has_order_two_at_midpoint_and_one_otherwise() {
    let system = rigid(0.5);
    let z0 = system.legendre(&SVector::from_column_slice(&PASSING));
    let reference = common::rk4_final(&system, &z0, 1.0, 10_000);
    let sweep = [20, 40, 80, 160, 320];
    let midpoint = common::observed_orders(&system, &z0, &reference, 1.0, 0.5, &sweep);
    common::assert_orders(&midpoint, 1.85..2.15, "theta = 1/2");
    let euler = common::observed_orders(&system, &z0, &reference, 1.0, 0.0, &sweep);
    common::assert_orders(&euler[2..], 0.9..1.15, "theta = 0");
}

#[test]
fn obstacle_step_map_is_symplectic() {
    let system = rigid(0.5);
    // close to the disc, where the barrier's Hessian is large
    let z0 = system.legendre(&SVector::from_column_slice(&[
        -0.9, 0.7, 0.3, 1.0, -0.2, 0.5, 0.1, -0.2, 0.3, 0.0, 0.1, -0.2,
    ]));
    for theta in [0.0, 0.25, 0.5, 1.0] {
        let options = StepOptions::default().with_theta(theta);
        let err = symplecticity_error(&system, &z0, 0.05, &options).unwrap();
        assert!(err < 1e-12, "theta {theta}: {err:e}");
    }
}

#[test]
fn theta_momentum_is_conserved_noether() {
    // V does not depend on theta, so the theta component of p_0 (index K N + 2 = 8) is a
    // conserved momentum of the exact flow and of the scheme.
    let system = rigid(1e-2);
    let z0 = system.legendre(&SVector::from_column_slice(&[
        -3.0, 2.0, 0.0, 0.5, 0.1, 0.5, 0.0, 0.0, 0.1, 0.0, 0.0, 0.01,
    ]));
    assert!(z0[8].abs() > 1e-3, "the test needs a non-zero momentum");
    let run = trajectory(&system, &z0, 0.01, 10_000, &StepOptions::default()).unwrap();
    let clearance = run
        .states
        .iter()
        .map(|z| z[0].hypot(z[1]) - 1.0)
        .fold(f64::INFINITY, f64::min);
    assert!(clearance > 0.5, "clearance {clearance}");
    let drift = component_drift(&run.states, 8);
    assert!(drift <= 1e-12, "p_0,theta drift {drift:e}");
    // while the x component is not conserved: the barrier pushes
    assert!(component_drift(&run.states, 6) > 1e-6);
}

/// max |H - H(0)| over the first and the last tenth of `n` steps of `advance`.
fn energy_trend(
    system: &PaisUhlenbeck,
    z0: SVector<f64, 8>,
    n: usize,
    mut advance: impl FnMut(&SVector<f64, 8>) -> SVector<f64, 8>,
) -> (f64, f64) {
    let h0 = system.hamiltonian(&z0).unwrap();
    let (mut first, mut last) = (0.0f64, 0.0f64);
    let mut z = z0;
    for i in 0..n {
        z = advance(&z);
        let e = (system.hamiltonian(&z).unwrap() - h0).abs();
        if i < n / 10 {
            first = first.max(e);
        }
        if i >= n - n / 10 {
            last = last.max(e);
        }
    }
    (first, last)
}

#[test]
fn energy_error_is_bounded_while_rk4_drifts() {
    let (system, z0) = bounded_pais_uhlenbeck();
    let (h, n) = (0.1, 100_000);
    let options = StepOptions::default();
    let (first, last) = energy_trend(&system, z0, n, |z| step(&system, z, h, &options).unwrap().0);
    assert!(
        last < 1.5 * first,
        "midpoint energy error grows: {first:e} -> {last:e}"
    );
    assert!(last < 1e-4, "midpoint energy error {last:e}");
    let (rk_first, rk_last) = energy_trend(&system, z0, n, |z| rk4_step(&system, z, h).unwrap());
    assert!(
        rk_last > 5.0 * rk_first,
        "RK4 should drift: {rk_first:e} -> {rk_last:e}"
    );
    assert!(
        rk_last > last,
        "RK4 {rk_last:e} vs midpoint {last:e} at the end"
    );
}

/// The exact jet at time t of the polynomial with derivative data `jet` at 0 (n = 2,
/// derivatives up to order `orders - 1`).
fn polynomial_jet<const S: usize>(jet: &SVector<f64, S>, t: f64) -> SVector<f64, S> {
    let orders = S / 2;
    SVector::from_fn(|r, _| {
        let (j, i) = (r / 2, r % 2);
        let (mut v, mut factor) = (0.0, 1.0);
        for m in 0..orders - j {
            if m > 0 {
                factor *= t / m as f64;
            }
            v += jet[(j + m) * 2 + i] * factor;
        }
        v
    })
}

/// Observed orders of the midpoint rule against the exact spline through `jet`, at t = 1.
fn spline_orders<Sys, const S: usize, const M: usize>(
    system: &Sys,
    jet: &SVector<f64, S>,
) -> Vec<f64>
where
    Sys: LiftedSystem<S, M>,
{
    let z0 = system.legendre(jet);
    let exact = system.legendre(&polynomial_jet(jet, 1.0));
    common::observed_orders(system, &z0, &exact, 1.0, 0.5, &[10, 20, 40, 80])
}

#[test]
fn jerk_splines_converge_at_order_two() {
    let jet = SVector::<f64, 12>::from_column_slice(&[
        0.1, -0.2, 1.0, 0.5, -0.3, 0.2, 0.7, -0.4, 0.5, 0.3, -0.6, 0.8,
    ]);
    common::assert_orders(&spline_orders(&JerkSpline {}, &jet), 1.9..2.1, "k = 3");
}

#[test]
fn snap_splines_converge_at_order_two() {
    let jet = SVector::<f64, 16>::from_column_slice(&[
        0.1, -0.2, 1.0, 0.5, -0.3, 0.2, 0.7, -0.4, 0.5, 0.3, -0.6, 0.8, 0.2, 0.1, -0.3, 0.4,
    ]);
    common::assert_orders(&spline_orders(&SnapSpline {}, &jet), 1.9..2.1, "k = 4");
}

#[test]
fn reduced_trajectory_matches_the_general_one() {
    use retract::ReducedStepper;
    let system = rigid(1e-2);
    let z0 = system.legendre(&SVector::from_column_slice(&[
        -2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ]));
    let options = StepOptions::default();
    let general = trajectory(&system, &z0, 0.01, 400, &options).unwrap();
    let reduced = ReducedStepper::new(&system)
        .trajectory(&z0, 0.01, 400, &options)
        .unwrap();
    for (a, b) in general.states.iter().zip(&reduced.states) {
        assert!((a - b).amax() < 1e-12, "{:e}", (a - b).amax());
    }
    // the guard and the crossing location work through the reduced driver too
    let z_in = system.legendre(&SVector::from_column_slice(&[
        -2.0, 1.19, 0.0, 1.0, -0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ]));
    let locate = options.with_crossing_location(true);
    let a = trajectory(&system, &z_in, 0.01, 300, &locate).unwrap_err();
    let b = ReducedStepper::new(&system)
        .trajectory(&z_in, 0.01, 300, &locate)
        .unwrap_err();
    assert_eq!(a.step, b.step);
    let (ta, tb) = (a.crossing_time.unwrap(), b.crossing_time.unwrap());
    assert!(
        (ta - tb).abs() < 1e-9 && (ta - 1.955).abs() < 5e-3,
        "{ta} {tb}"
    );
}
