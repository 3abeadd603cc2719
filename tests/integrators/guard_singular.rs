//! The singularity guard covers every singular operation the macro accepts
//! (`/`, `/=`, `recip`, `powi` and `powf` with a negative exponent, `powf` with a fractional
//! one, `ln`, `sqrt`, `tan`, `atan2`, `hypot`), and a guarded expression that vanishes
//! without changing sign (an even power, a sum of squares) is caught as well as one that
//! changes sign. For each: a step that crosses the singular point is an error naming the
//! expression, and a step that ends near it, but before it, is Ok. `abs` is a kink, not a
//! singularity (its derivative is bounded), and is not guarded.
//!
//! The singular terms carry a tiny weight, so the motion is free to rounding: q(t) = q(0) +
//! q'(0) t (order 1) or q'(t) = q'(0) + q''(0) t (order 2).

use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{DomainKind, Error, LiftedSystem, StepOptions, step};

#[higher_order_lagrangian(order = 1)]
fn negative_powi(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * q.powi(-2)
}

#[higher_order_lagrangian(order = 1)]
fn negative_powf(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * q.powf(-2.0)
}

#[higher_order_lagrangian(order = 1)]
fn fractional_negative_powf(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * q.powf(-0.5)
}

#[higher_order_lagrangian(order = 1)]
fn with_recip(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * q.recip()
}

#[higher_order_lagrangian(order = 1)]
fn div_assign(q: f64, dq: f64) -> f64 {
    let mut v = 1e-9;
    v /= q * q * q;
    0.5 * dq * dq + v
}

#[higher_order_lagrangian(order = 1)]
fn with_tan(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * q.tan()
}

#[higher_order_lagrangian(order = 1)]
fn ln_of_square(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * (q * q).ln()
}

#[higher_order_lagrangian(order = 1)]
fn sqrt_of_square(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * (q * q).sqrt()
}

#[higher_order_lagrangian(order = 1)]
fn with_abs(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 1e-9 * q.abs()
}

/// The forward-speed barrier on a line: |q'|^2 = q'^2 touches 0 where q' changes sign.
#[higher_order_lagrangian(order = 2)]
fn speed_barrier_1d(_q: f64, dq: f64, ddq: f64, tau: f64) -> f64 {
    0.5 * ddq * ddq + tau / (dq * dq)
}

/// The forward-speed barrier in the plane: |q'|^2 vanishes without changing sign.
#[higher_order_lagrangian(order = 2)]
fn speed_barrier(_q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (dq[0].powi(2) + dq[1].powi(2))
}

#[higher_order_lagrangian(order = 1)]
fn with_atan2(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * (dq[0].powi(2) + dq[1].powi(2)) + 1e-9 * q[1].atan2(q[0])
}

#[higher_order_lagrangian(order = 1)]
fn with_hypot(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * (dq[0].powi(2) + dq[1].powi(2)) + 1e-9 * q[0].hypot(q[1])
}

/// One step of size `h` from the jet `jet`.
fn one_step<Sys: LiftedSystem<S, M>, const S: usize, const M: usize>(
    system: &Sys,
    jet: [f64; S],
    h: f64,
) -> Result<(), Error> {
    let z0 = system.legendre(&SVector::from(jet));
    step(system, &z0, h, &StepOptions::default()).map(|_| ())
}

/// A step crossing the singular point must fail with `kind` naming `expression`; a step
/// ending short of it must pass.
fn crosses_and_nears(
    cross: Result<(), Error>,
    near: Result<(), Error>,
    kind: DomainKind,
    expression: &str,
) {
    match cross {
        Err(Error::Domain(v)) => {
            assert_eq!(v.kind, kind, "{v}");
            assert_eq!(v.expression, expression, "{v}");
        }
        other => panic!("the crossing step must be a {kind:?} error at `{expression}`: {other:?}"),
    }
    assert!(
        near.is_ok(),
        "the step short of the singular point must pass: {near:?}"
    );
}

/// Order 1 on R: q(0) = 0.05, q' = -1. A step of 0.06 crosses q = 0 at t = 0.05 (its
/// evaluation point, q = 0.02, is regular); a step of 0.045 ends at q = 0.005.
fn towards_zero<Sys: LiftedSystem<2, 3>>(system: &Sys, kind: DomainKind, expression: &str) {
    crosses_and_nears(
        one_step(system, [0.05, -1.0], 0.06),
        one_step(system, [0.05, -1.0], 0.045),
        kind,
        expression,
    );
}

#[test]
fn a_negative_powi_is_guarded_at_zero() {
    towards_zero(&NegativePowi {}, DomainKind::Denominator, "q");
}

#[test]
fn powf_with_a_negative_integer_exponent_is_guarded_at_zero() {
    towards_zero(&NegativePowf {}, DomainKind::Denominator, "q");
}

#[test]
fn powf_with_a_negative_fractional_exponent_is_guarded_at_zero() {
    towards_zero(&FractionalNegativePowf {}, DomainKind::PowfBase, "q");
}

#[test]
fn recip_is_guarded_at_zero() {
    towards_zero(&WithRecip {}, DomainKind::Denominator, "q");
}

#[test]
fn div_assign_by_an_odd_power_is_guarded_at_zero() {
    towards_zero(&DivAssign {}, DomainKind::Denominator, "q * q * q");
}

#[test]
fn ln_of_an_even_power_is_guarded_where_it_vanishes_without_sign_change() {
    towards_zero(&LnOfSquare {}, DomainKind::LnArgument, "q * q");
}

#[test]
fn sqrt_of_an_even_power_is_guarded_where_it_vanishes_without_sign_change() {
    towards_zero(&SqrtOfSquare {}, DomainKind::SqrtArgument, "q * q");
}

#[test]
fn tan_is_guarded_where_cos_crosses_zero() {
    // q(0) = pi/2 - 0.05, q' = 1: cos q changes sign at t = 0.05
    let q0 = core::f64::consts::FRAC_PI_2 - 0.05;
    crosses_and_nears(
        one_step(&WithTan {}, [q0, 1.0], 0.06),
        one_step(&WithTan {}, [q0, 1.0], 0.045),
        DomainKind::Denominator,
        "q.cos()",
    );
    // and the step through q = pi/2 from the other side
    let q0 = core::f64::consts::FRAC_PI_2 + 0.05;
    assert!(one_step(&WithTan {}, [q0, -1.0], 0.06).is_err());
}

#[test]
fn abs_is_a_kink_not_a_singularity() {
    // documented: |q| has a bounded derivative, so crossing 0 is not a domain error
    assert!(one_step(&WithAbs {}, [0.05, -1.0], 0.06).is_ok());
}

#[test]
fn a_forward_speed_barrier_on_a_line_is_guarded_where_the_speed_vanishes() {
    // q'(0) = 0.05, q'' = -1: q' changes sign at t = 0.05, but q'^2 stays positive at the
    // start (2.5e-3), the evaluation point (4e-4) and the end (1e-4) of a step of 0.06
    let system = SpeedBarrier1d { tau: 1e-12 };
    crosses_and_nears(
        one_step(&system, [0.0, 0.05, -1.0, 0.0], 0.06),
        one_step(&system, [0.0, 0.05, -1.0, 0.0], 0.045),
        DomainKind::Denominator,
        "dq * dq",
    );
}

#[test]
fn a_forward_speed_barrier_in_the_plane_is_guarded_where_the_speed_vanishes() {
    // q' = (0.05, 0) - (t, 0): |q'|^2 touches 0 at t = 0.05 without changing sign
    let system = SpeedBarrier { tau: 1e-12 };
    let through = [0.0, 0.0, 0.05, 0.0, -1.0, 0.0, 0.0, 0.0];
    crosses_and_nears(
        one_step(&system, through, 0.06),
        one_step(&system, through, 0.045),
        DomainKind::Denominator,
        "dq[0].powi(2) + dq[1].powi(2)",
    );
    // passing the origin of the velocity plane at a distance of 1e-3: a near miss, Ok
    let beside = [0.0, 0.0, 0.05, 1e-3, -1.0, 0.0, 0.0, 0.0];
    assert!(one_step(&system, beside, 0.06).is_ok());
}

#[test]
fn atan2_and_hypot_are_guarded_at_the_origin() {
    // q = (0.05, 0) - (t, 0): through the origin, where both arguments vanish
    let through = [0.05, 0.0, -1.0, 0.0];
    let atan2 = |h: f64| one_step(&WithAtan2 {}, through, h);
    let hypot = |h: f64| one_step(&WithHypot {}, through, h);
    crosses_and_nears(
        atan2(0.06),
        atan2(0.045),
        DomainKind::Denominator,
        "q[1].hypot(q[0])",
    );
    crosses_and_nears(
        hypot(0.06),
        hypot(0.045),
        DomainKind::Denominator,
        "q[0].hypot(q[1])",
    );
    // passing the origin at a distance of 1e-3: Ok
    let beside = [0.05, 1e-3, -1.0, 0.0];
    assert!(one_step(&WithAtan2 {}, beside, 0.06).is_ok());
    assert!(one_step(&WithHypot {}, beside, 0.06).is_ok());
}
