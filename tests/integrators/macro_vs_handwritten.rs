//! The generated obstacle system agrees with the hand-written `models::PlanarBarrier`.

use retract::higher_order_lagrangian;
use retract::models::PlanarBarrier;
use retract::nalgebra::SVector;
use retract::{Lagrangian, LiftedSystem, StepOptions, trajectory};

#[higher_order_lagrangian(order = 2)]
fn barrier(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

#[test]
fn generated_matches_handwritten() {
    let generated = Barrier { tau: 0.5, r: 1.0 };
    let by_hand = PlanarBarrier {
        tau: 0.5,
        radius: 1.0,
        mass: 1.0,
    };
    let jet = SVector::<f64, 8>::from_column_slice(&[-2.0, 1.1, 1.0, -0.2, 0.3, -0.4, 0.1, 0.2]);
    let z0 = generated.legendre(&jet);
    assert_eq!(z0, by_hand.legendre(&jet));
    let x = [SVector::from([-1.3, 0.8]), SVector::from([0.4, -0.3])];
    let u = SVector::from([0.2, 0.7]);
    assert!((generated.lagrangian(&x, &u) - by_hand.lagrangian(&x, &u)).abs() < 1e-15);
    assert!(
        (generated.lagrangian(&x, &u) - barrier([-1.3, 0.8], [0.4, -0.3], [0.2, 0.7], 0.5, 1.0))
            .abs()
            < 1e-15
    );
    let (gg, gh) = (generated.gradient(&x, &u), by_hand.gradient(&x, &u));
    assert!((gg.x[0] - gh.x[0]).amax() < 1e-14 && (gg.u - gh.u).amax() < 1e-15);
    let (hg, hh) = (generated.hessian(&x, &u), by_hand.hessian(&x, &u));
    assert!((hg.xx[0][0] - hh.xx[0][0]).amax() < 1e-13);
    let w = generated.predictor(&z0, 0.05, 0.5).unwrap();
    for theta in [0.0, 0.5, 1.0] {
        let r = generated.residual(&z0, &w, 0.05, theta) - by_hand.residual(&z0, &w, 0.05, theta);
        assert!(r.amax() < 1e-15, "{r}");
        let j = generated.jacobian(&z0, &w, 0.05, theta) - by_hand.jacobian(&z0, &w, 0.05, theta);
        assert!(j.amax() < 1e-14, "{j}");
        let j = generated.jacobian_initial(&z0, &w, 0.05, theta)
            - by_hand.jacobian_initial(&z0, &w, 0.05, theta);
        assert!(j.amax() < 1e-14, "{j}");
    }
    let a = trajectory(&generated, &z0, 0.01, 100, &StepOptions::default()).unwrap();
    let b = trajectory(&by_hand, &z0, 0.01, 100, &StepOptions::default()).unwrap();
    assert!((a.states[100] - b.states[100]).amax() < 1e-13);
}

/// A second-order Lagrangian with shared trigonometric subexpressions (the torques of a
/// double pendulum, their squares and a coupling in q'').
#[higher_order_lagrangian(order = 2)]
fn coupled(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], g: f64) -> f64 {
    let c = q[1].cos();
    let t0 = (3.0 + 2.0 * c) * ddq[0] + (1.0 + c) * ddq[1] - q[1].sin() * dq[1] * dq[1]
        + g * (2.0 * q[0].sin() + (q[0] + q[1]).sin());
    let t1 = (1.0 + c) * ddq[0] + ddq[1] + q[1].sin() * dq[0] * dq[0] + g * (q[0] + q[1]).sin();
    0.5 * (t0 * t0 + t1 * t1) + ddq[0] * ddq[1] * (q[0] - q[1]).cos()
}

/// `Lagrangian::derivatives`, generated as one straight-line code, gives the value, gradient
/// and Hessian of the three separately generated methods (up to the reassociation of sums,
/// the last bits), on the trigonometric `coupled` and the rational `barrier`; the default of
/// a hand-written system gives them exactly.
#[test]
fn generated_derivatives_match_the_three_methods() {
    fn check<L: Lagrangian<2, 2>>(
        system: &L,
        (x, u): (&[SVector<f64, 2>; 2], &SVector<f64, 2>),
        nonzero: usize,
    ) {
        let d = system.derivatives(x, u);
        let (value, gradient, hessian) = (
            system.lagrangian(x, u),
            system.gradient(x, u),
            system.hessian(x, u),
        );
        assert!((d.value - value).abs() <= 1e-14 * value.abs().max(1.0));
        let scale = gradient.x[0].amax().max(gradient.x[1].amax()).max(1.0);
        for j in 0..2 {
            assert!((d.gradient.x[j] - gradient.x[j]).amax() <= 1e-14 * scale);
        }
        assert!((d.gradient.u - gradient.u).amax() <= 1e-14 * scale);
        let blocks = |h: &retract::Hessian<2, 2>| {
            [
                h.xx[0][0], h.xx[0][1], h.xx[1][0], h.xx[1][1], h.xu[0], h.xu[1], h.uu,
            ]
        };
        let (ours, theirs) = (blocks(&d.hessian), blocks(&hessian));
        let scale = theirs.iter().fold(1.0_f64, |m, b| m.max(b.amax()));
        for (a, b) in ours.iter().zip(&theirs) {
            assert!((a - b).amax() <= 1e-14 * scale, "{a} vs {b}");
        }
        // (the blocks the comparison sees are not zero)
        assert_eq!(theirs.iter().filter(|b| b.amax() > 0.0).count(), nonzero);
    }
    let points = [
        ([[0.3, -1.2], [0.7, 0.4]], [1.5, -0.8]),
        ([[3.0, 0.1], [-2.0, 5.0]], [-20.0, 9.0]),
    ];
    for (x, u) in points {
        let x = [SVector::from(x[0]), SVector::from(x[1])];
        let u = SVector::from(u);
        check(&Coupled { g: 9.81 }, (&x, &u), 7);
        check(&Barrier { tau: 0.5, r: 1.0 }, (&x, &u), 2);
        let by_hand = PlanarBarrier {
            tau: 0.5,
            radius: 1.0,
            mass: 1.0,
        };
        let d = by_hand.derivatives(&x, &u);
        assert_eq!(d.value, by_hand.lagrangian(&x, &u));
        assert_eq!(d.gradient, by_hand.gradient(&x, &u));
        assert_eq!(d.hessian, by_hand.hessian(&x, &u));
    }
}
