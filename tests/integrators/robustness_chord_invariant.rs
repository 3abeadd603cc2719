//! The domain check samples the chord of a step, and the reduced step conserves the angular
//! momentum of a rotation-invariant system.

use crate::common;

use retract::nalgebra::SVector;
use retract::{
    DomainKind, Error, LiftedSystem, ReducedStepper, StepOptions, higher_order_lagrangian, step,
};

type Z = SVector<f64, 12>;

/// The SE(2) body with a disc obstacle (cx, cy, r) written through its distance: the guarded
/// denominator |q - c| - r is not quadratic along a chord, so the quadratic fit of the three
/// points of `check_domain` (exact for |q - c|^2 - r^2) does not see a disc between them.
#[higher_order_lagrangian(order = 2)]
fn distance_scene(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, disc: [f64; 3]) -> f64 {
    let distance = ((q[0] - disc[0]).powi(2) + (q[1] - disc[1]).powi(2)).sqrt();
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2)) + tau / (distance - disc[2])
}

type Scene = DistanceScene;

/// The SE(2) body at (x, y) moving at speed 3 along +x (no rotation), past the obstacles.
fn moving_at(system: &Scene, x: f64, y: f64) -> Z {
    let jet = [x, y, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    system.legendre(&Z::from_column_slice(&jet))
}

/// The general and the reduced step of size `h` from `z0`.
fn both_steps(system: &Scene, z0: &Z, h: f64, options: &StepOptions) -> [Result<Z, Error>; 2] {
    let general = step(system, z0, h, options).map(|(z, _)| z);
    let reduced = ReducedStepper::new(system)
        .step(z0, h, options)
        .map(|(z, _)| z);
    [general, reduced]
}

#[test]
fn a_step_jumping_over_a_small_obstacle_is_an_error() {
    // a disc of radius 0.05 at (-0.075, 0.03); the step of h = 0.1 at speed 3 goes from
    // x = -0.15 to x = 0.15 along y = 0, 0.08 of it inside the disc: x0, the midpoint x = 0
    // and x1 are all 0.08 or more from the centre, and the quadratic fit of the denominator
    // |q - c| - r through them stays positive, so the three points saw nothing
    let system = Scene {
        tau: 1e-6,
        disc: [-0.075, 0.03, 0.05],
    };
    let z0 = moving_at(&system, -0.15, 0.0);
    let h = 0.1;
    let three_points = StepOptions::default().with_chord_check(f64::INFINITY, 0);
    for (which, result) in
        ["general", "reduced"]
            .iter()
            .zip(both_steps(&system, &z0, h, &three_points))
    {
        let z1 = result.unwrap_or_else(|e| panic!("{which}: the three points miss it: {e}"));
        assert!((z1[0] - 0.15).abs() < 1e-3, "{which}: x1 = {}", z1[0]);
    }
    // the chord check (spacing 0.02: 15 pieces, points 0.01 apart) finds it, in both steps
    let options = StepOptions::default();
    for (which, result) in ["general", "reduced"]
        .iter()
        .zip(both_steps(&system, &z0, h, &options))
    {
        match result {
            Err(Error::Domain(v)) => assert_eq!(v.kind, DomainKind::Denominator, "{which}"),
            other => panic!("{which}: a step through the obstacle returned {other:?}"),
        }
    }
    // a coarser spacing still finds it as long as the gap between checked points,
    // 0.3 / (2 m) for m pieces, is below the 0.08 of the chord inside the disc: m = 2
    let coarse = StepOptions::default().with_chord_check(0.15, 16);
    assert!(matches!(
        step(&system, &z0, h, &coarse),
        Err(Error::Domain(_))
    ));
    // a cap of 1 piece is the three points again, and misses it, as documented (the gap is
    // then 0.15)
    let capped = StepOptions::default().with_chord_check(0.02, 1);
    assert!(step(&system, &z0, h, &capped).is_ok());
}

#[test]
fn a_step_passing_near_an_obstacle_stays_ok() {
    // the same step 0.06 beside the disc's centre (0.01 outside its radius) is accepted,
    // with the full chord check, by both steps, and so is a trajectory along it
    let system = Scene {
        tau: 1e-6,
        disc: [-0.075, 0.06, 0.05],
    };
    let z0 = moving_at(&system, -0.15, 0.0);
    let options = StepOptions::default();
    for (which, result) in ["general", "reduced"]
        .iter()
        .zip(both_steps(&system, &z0, 0.1, &options))
    {
        let z1 = result.unwrap_or_else(|e| panic!("{which}: a clear step failed: {e}"));
        assert!(
            (z1[0] - 0.15).abs() < 1e-3 && z1[1].abs() < 1e-3,
            "{which}: {z1:?}"
        );
    }
    let run = retract::trajectory(&system, &moving_at(&system, -0.6, 0.0), 0.05, 20, &options)
        .expect("a clear run");
    assert!((run.states[20][0] - 2.4).abs() < 1e-3);
    // invalid settings are typed errors
    for bad in [
        StepOptions::default().with_chord_check(0.0, 16),
        StepOptions::default().with_chord_check(f64::NAN, 16),
        StepOptions::default().with_chord_check(0.02, retract::step::MAX_CHORD_PIECES + 1),
    ] {
        assert!(matches!(
            step(&system, &z0, 0.1, &bad),
            Err(Error::InvalidArgument {
                name: "chord_spacing",
                ..
            })
        ));
    }
}

/// q x p_0 + q' x p_1 of the planar Pais-Uhlenbeck state (q, q', p_0, p_1).
fn angular_momentum(z: &SVector<f64, 8>) -> f64 {
    let cross = |a: usize, b: usize| z[a] * z[b + 1] - z[a + 1] * z[b];
    cross(0, 4) + cross(2, 6)
}

#[test]
fn the_reduced_step_conserves_angular_momentum_over_1e7_steps() {
    // The midpoint rule conserves the angular momentum of a rotation-invariant Lagrangian
    // exactly; solved by the general step it stays within 9e-13 (relative) over 1e7 steps, a
    // random walk of rounding errors. The reduced step drifted linearly, 6.5e-17 per step
    // (6.5e-11 at 1e6 steps, 6.5e-10 at 1e7; any Newton tolerance, closed form or LU alike):
    // its cached propagator T = -A^{-1} B (and the forced columns of A^{-1}) are rounded once,
    // so every step applied the same slightly non-symplectic linear map. The factors now carry
    // their rounding errors, T_lo = -A^{-1}(A T + B) and A^{-1}(E - A a_inv) (residuals summed
    // compensated), and the recovery adds T_lo z0 - a_inv_lo n to the terms of n first and
    // those to the others (`sum_folded`), inside the one rounding of each entry of w (added
    // after that rounding, a correction below the last bit is lost: the drift stayed 6.5e-11
    // at 1e6). Measured (h = 0.1, relative, worst over the run): 3.8e-13 at 1e6 steps and
    // 1.8e-12 at 1e7; with the exact last addition in every row (`sum_corrected`) 4.2e-13 and
    // 2.1e-12; 3.5e-12 at 1e7 without the A^{-1} correction; 1.6e-13 and 6.3e-13 with each
    // row summed fully compensated (Dot2), which made the step 3x slower. Bound: 1e-11, five
    // times the measured 1.8e-12 and 65 times below the drift before; 1e7 reduced steps take
    // about a second in the test profile.
    let (system, z0) = common::models::bounded_pais_uhlenbeck();
    let j0 = angular_momentum(&z0);
    let options = StepOptions::default();
    let mut stepper = ReducedStepper::new(&system);
    let mut z = z0;
    let mut worst: f64 = 0.0;
    for i in 0..10_000_000 {
        z = stepper
            .step(&z, 0.1, &options)
            .unwrap_or_else(|e| panic!("step {i}: {e}"))
            .0;
        if i % 10_000 == 0 {
            worst = worst.max(((angular_momentum(&z) - j0) / j0).abs());
        }
    }
    worst = worst.max(((angular_momentum(&z) - j0) / j0).abs());
    assert!(
        worst < 1e-11,
        "relative drift of the angular momentum {worst:e}"
    );
}

#[test]
fn the_uncompensated_reduced_step_is_the_same_map_but_lets_the_momentum_drift() {
    // StepOptions::compensated off: each entry of w one rounded sum of T z0 - A^{-1} n. Step
    // by step it agrees with the compensated step to rounding; over 1e6 steps its angular
    // momentum drifts linearly (6.5e-17 a step: about 6.5e-11), the compensated one stays at
    // rounding (3.8e-13, measured in the test above). The bounds sit between the two; the
    // lower one on the plain step's drift is what shows that the option really takes the
    // plain recovery.
    let (system, z0) = common::models::bounded_pais_uhlenbeck();
    let j0 = angular_momentum(&z0);
    let (on, off) = (
        StepOptions::default(),
        StepOptions::default().with_compensation(false),
    );
    let (mut compensated, mut plain) = (ReducedStepper::new(&system), ReducedStepper::new(&system));
    let (mut a, mut b) = (z0, z0);
    let (mut worst_a, mut worst_b): (f64, f64) = (0.0, 0.0);
    for i in 0..1_000_000 {
        if i < 100 {
            // one step from the same state: the same map to rounding
            let (x, y) = (
                compensated.step(&b, 0.1, &on).unwrap().0,
                plain.step(&b, 0.1, &off).unwrap().0,
            );
            assert!((x - y).amax() <= 1e-15 * (1.0 + b.amax()), "step {i}");
        }
        a = compensated.step(&a, 0.1, &on).unwrap().0;
        b = plain.step(&b, 0.1, &off).unwrap().0;
        if i % 10_000 == 9_999 {
            worst_a = worst_a.max(((angular_momentum(&a) - j0) / j0).abs());
            worst_b = worst_b.max(((angular_momentum(&b) - j0) / j0).abs());
        }
    }
    assert!(worst_a < 5e-12, "compensated: {worst_a:e}");
    assert!(worst_b > 2e-11, "plain: {worst_b:e}");
}
