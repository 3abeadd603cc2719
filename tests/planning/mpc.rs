//! The receding-horizon loop of `examples/mpc_swing_up.rs` at reduced size: the double pendulum swung
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
/// starts hanging, pi away), and once there the real-time iterations converge (Newton steps
/// at most 1e-6).
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
        "{} converged plans",
        summary.converged
    );
}

/// A kick of (20, -20) to the plant's momenta spins it at about 140 rad/s: one control period
/// (h = 0.02, about 2.8 rad) converges to a root at twice the energy (a step too long for the
/// motion). The energy check (tolerance 0.05) refuses that step, and a trajectory that may
/// halve resolves it to within 2 % of the energy 16 substeps reach.
#[test]
fn a_kicked_plant_step_is_refused_and_halving_resolves_it() {
    use retract::forced::forced_step;
    use retract::{Error, LiftedSystem, StepOptions, step, trajectory};
    let (_, plant) = pendulum::models();
    let energy = |z: &SVector<f64, 4>| plant.hamiltonian(z).expect("energy");
    let z0 = SVector::from([0.5, 0.0, 20.0, -20.0]);
    let h = pendulum::HORIZON / pendulum::STEPS as f64;
    let checked = StepOptions::default().with_energy_tolerance(0.05);
    // 16 substeps, each accepted by the check
    let mut fine = z0;
    for _ in 0..16 {
        fine = step(&plant, &fine, h / 16.0, &checked).expect("resolved").0;
    }
    let reference = energy(&fine);
    assert!((reference - energy(&z0)).abs() < 0.01 * reference);
    // without the check (the default), the root of the whole period is at twice the energy
    let unchecked = StepOptions::default();
    let far = step(&plant, &z0, h, &unchecked).expect("converges").0;
    assert!(energy(&far) > 1.8 * reference, "{}", energy(&far));
    // with it, refused, with and without a force
    let refused = |result: Result<(SVector<f64, 4>, retract::StepReport), Error>| match result {
        Err(Error::UnresolvedStep {
            energy_error,
            exchanged,
        }) => energy_error > 0.2 * exchanged && energy_error > 0.5 * reference,
        _ => false,
    };
    assert!(refused(step(&plant, &z0, h, &checked)));
    assert!(refused(forced_step(
        &plant,
        &z0,
        &SVector::from([1.0, -1.0]),
        h,
        &checked
    )));
    // halved until resolved: 2^m pieces, the energy within 2 % of the reference
    let run = trajectory(&plant, &z0, h, 1, &checked.with_max_halvings(8)).expect("halved");
    let (halvings, end) = (run.reports[0].halvings, energy(&run.states[1]));
    assert!((2..=4).contains(&halvings), "{halvings}");
    assert!(
        (end - reference).abs() < 0.02 * reference,
        "{end} against {reference}"
    );
}

/// The receding-horizon benchmark (`examples/mpc.rs`): after the (+2, -2) rad/s kick, real-time
/// iterations with one feedback step a period hold the pendulum as full solves do (largest
/// deviation and settling time within 1.2 times theirs: the first torque after the kick
/// already answers it); after the (+8, -8) kick every mode brings it back upright (to 1e-3)
/// with no failed re-plan.
#[test]
fn real_time_iterations_answer_a_kick_as_full_solves_do() {
    use crate::upright::{Mode, run};
    let rti = run(2.0, Mode::Rti(1)).expect("rti1");
    let full = run(2.0, Mode::Full).expect("full");
    assert!(full.max_dev > 0.05, "the kick moved it: {}", full.max_dev);
    assert!(
        rti.max_dev <= 1.2 * full.max_dev,
        "{} vs {}",
        rti.max_dev,
        full.max_dev
    );
    assert!(
        rti.settle_s <= 1.2 * full.settle_s,
        "{} vs {}",
        rti.settle_s,
        full.settle_s
    );
    assert_eq!((rti.failures, full.failures), (0, 0));
    for mode in [Mode::Rti(1), Mode::Rti(2), Mode::Full] {
        let out = run(8.0, mode).expect("runs");
        assert!(out.max_dev > 0.5, "{mode:?}: {}", out.max_dev);
        assert!(out.settle_s.is_finite(), "{mode:?} does not settle");
        assert_eq!(out.failures, 0, "{mode:?}");
    }
}
