//! Quadratic guards: where every guarded expression is a polynomial of degree at most 2 in
//! the jet, the three samples of `check_domain` decide a step's whole chord, and
//! `check_step_domain` skips the chord's pieces. Over random chords near a disc obstacle (a
//! fixed radius and one from a parameter list), the decision equals that of 1024 sampled
//! pieces wherever the chord does not graze the disc; a cubic guard keeps the pieces.

use retract::nalgebra::SVector;
use retract::step::check_step_domain;
use retract::{DomainViolation, LiftedSystem, StepOptions, higher_order_lagrangian};

use super::guard::{Disc, Discs};
use super::so3_body::random;

/// A wall at x = 1 seen through a cubic: not quadratic, so the pieces stay.
#[higher_order_lagrangian(order = 2)]
fn cubic_wall(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(3) - 1.0)
}

/// The chord from `z0` to `w` cut into 1024 pieces, each checked by `check_domain` at its
/// ends and midpoint, with the step's top derivative.
fn dense<Sys: LiftedSystem<8, 10>>(
    system: &Sys,
    z0: &SVector<f64, 8>,
    w: &SVector<f64, 10>,
) -> Result<(), DomainViolation> {
    let mut start = *z0;
    for j in 1..=1024 {
        let s = f64::from(j) / 1024.0;
        let end = z0.zip_map(&w.fixed_rows::<8>(0).into_owned(), |a, b| {
            (1.0 - s) * a + s * b
        });
        let mut unknowns = *w;
        unknowns.fixed_rows_mut::<8>(0).copy_from(&end);
        system.check_domain(&start, &unknowns, 0.5)?;
        start = end;
    }
    Ok(())
}

/// The smallest |q(s)|^2 - 1 along the chord of q from `a` to `b` (s in [0, 1]).
fn clearance(a: [f64; 2], b: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let dd = d[0] * d[0] + d[1] * d[1];
    let s = if dd > 0.0 {
        (-(a[0] * d[0] + a[1] * d[1]) / dd).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a[0] + s * d[0]).powi(2) + (a[1] + s * d[1]).powi(2) - 1.0
}

/// Random chords of q near the unit disc (the rest of the state random): for each, the step
/// check's decision and the dense one, the chord's clearance, and whether its three samples
/// (ends and midpoint) are all outside the disc.
fn decisions<Sys: LiftedSystem<8, 10>>(system: &Sys) -> Vec<(bool, bool, f64, bool)> {
    (0..3000)
        .map(|seed| {
            let (a, b) = (random(seed, 2.0), random(seed + 10_000, 2.0));
            let (p, u) = (random(seed + 20_000, 1.0), random(seed + 30_000, 1.0));
            let z0 = SVector::<f64, 8>::from([a[0], a[1], p[0], p[1], p[2], u[0], u[1], u[2]]);
            let mut w =
                SVector::<f64, 10>::from_fn(|i, _| random(seed + 40_000 + i as u64, 1.0)[0]);
            (w[0], w[1]) = (b[0], b[1]);
            let fast = check_step_domain(system, &z0, &w, &StepOptions::default()).is_ok();
            let slow = dense(system, &z0, &w).is_ok();
            let outside = [a, b, (a + b) / 2.0]
                .iter()
                .all(|x| x[0] * x[0] + x[1] * x[1] > 1.0);
            (fast, slow, clearance([a[0], a[1]], [b[0], b[1]]), outside)
        })
        .collect()
}

#[test]
fn quadratic_guards_decide_the_chord_as_dense_sampling_does() {
    let obstacles = [[0.0, 0.0, 1.0]];
    let (single, list) = (Disc::new(0.01, 1.0), Discs::new(0.01, &obstacles));
    assert!(single.guards_quadratic() && list.guards_quadratic());
    assert!(!CubicWall::new(0.01).guards_quadratic());
    for runs in [decisions(&single), decisions(&list)] {
        let (mut crossing, mut clear, mut between, mut disagreements) = (0, 0, 0, 0);
        for (fast, slow, clearance, outside) in runs {
            // (a chord within 1e-6 of the circle is decided by rounding either way)
            if clearance.abs() > 1e-6 {
                disagreements += usize::from(fast != slow);
                crossing += usize::from(!slow);
                clear += usize::from(slow);
                between += usize::from(!slow && outside);
            }
        }
        assert_eq!(disagreements, 0);
        // both kinds of chord occur, and many cross the disc only between their samples
        assert!(
            crossing > 500 && clear > 500 && between > 50,
            "{crossing} crossing ({between} between the samples), {clear} clear"
        );
    }
}

#[test]
fn a_chord_from_the_boundary_into_the_disc_is_rejected_and_one_leaving_it_is_not() {
    // the first sample within rounding of the circle (|q|^2 - 1 = 1e-13), where the fit
    // cannot tell a touch from rounding: a chord that dips to -0.0099 is still rejected
    let system = Disc::new(0.01, 1.0);
    let edge = 1.0 + 5e-14;
    let z0 = SVector::<f64, 8>::from([edge, 0.0, 0.1, 0.2, 0.3, 0.1, 0.2, 0.3]);
    let to = |end: [f64; 2]| {
        let mut w = SVector::<f64, 10>::from_element(0.1);
        (w[0], w[1]) = (end[0], end[1]);
        w
    };
    let inward = to([edge - 0.2, 2.0]);
    assert!(check_step_domain(&system, &z0, &inward, &StepOptions::default()).is_err());
    assert!(dense(&system, &z0, &inward).is_err());
    // leaving the circle outward (the minimum at the start) passes
    let outward = to([edge + 0.5, 0.3]);
    assert!(check_step_domain(&system, &z0, &outward, &StepOptions::default()).is_ok());
}
