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
