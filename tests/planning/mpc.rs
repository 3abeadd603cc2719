//! The receding-horizon loop of `examples/mpc.rs` at reduced size: the double pendulum swung
//! up and held with the plant in the loop.

use std::f64::consts::PI;

use crate::pendulum::{self, TorqueCost};
use retract::Lagrangian;
use retract::nalgebra::SVector;

/// The torque the plant receives (the named output `tau` of the planner's Lagrangian) is the
/// one the planner's cost penalises: L = 1/2 |tau|^2 at random jets.
#[test]
fn the_applied_torque_is_the_planned_one() {
    let model = TorqueCost::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let mut random = crate::common::Noise::new(0x2545_f491_4f6c_dd1d_u64);
    let mut noise = move || random.next();
    for _ in 0..50 {
        let x = [
            SVector::from([3.0 * noise(), 3.0 * noise()]),
            SVector::from([2.0 * noise(), 2.0 * noise()]),
        ];
        let u = SVector::from([5.0 * noise(), 5.0 * noise()]);
        let tau = model.tau(&x, &u);
        let l = model.lagrangian(&x, &u);
        let expected = 0.5 * (tau[0] * tau[0] + tau[1] * tau[1]);
        assert!(
            (l - expected).abs() <= 1e-12 * expected.max(1.0),
            "{l} vs {expected}"
        );
    }
    // and it is the torque, by hand for unit masses and lengths: holding the arm horizontal
    // takes G = (3 g, g); from rest at q = 0, q'' = (1, 0) takes M's first column (5, 2)
    let zero = SVector::zeros();
    let held = model.tau(&[SVector::from([PI / 2.0, 0.0]), zero], &zero);
    assert!((held[0] - 3.0 * 9.81).abs() < 1e-12 && (held[1] - 9.81).abs() < 1e-12);
    let pushed = model.tau(&[zero, zero], &SVector::from([1.0, 0.0]));
    assert!((pushed[0] - 5.0).abs() < 1e-12 && (pushed[1] - 2.0).abs() < 1e-12);
}

/// 300 re-plans (6 s): no re-plan fails, the pendulum ends upright at rest (to 1e-6; it
/// starts hanging, pi away), and once there the real-time iterations certify their plans.
#[test]
fn the_loop_swings_up_and_holds() {
    let summary = pendulum::run(300).expect("the plant steps");
    assert_eq!(summary.failures, 0);
    assert_eq!(summary.times_us.len(), 300);
    let [q0, q1, dq0, dq1] = summary.last;
    let error = (q0 - PI).abs().max(q1.abs()).max(dq0.abs()).max(dq1.abs());
    assert!(error < 1e-6, "final state {:?}", summary.last);
    assert!(
        summary.converged >= 200,
        "{} certified plans",
        summary.converged
    );
}
