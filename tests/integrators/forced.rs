//! Plant simulation (`retract::forced`): the forced midpoint rule converges with order 2 to
//! the exact forced motion, its energy balance H(z_1) - H(z_0) = f . (q_1 - q_0) is exact for
//! a quadratic Hamiltonian, zero force is the unforced step, and bad forces are errors.

use retract::forced::forced_step;
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{Error, LiftedSystem, StepOptions, step};

#[higher_order_lagrangian(order = 1)]
fn oscillator(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq - 0.5 * q * q
}

/// Two coupled oscillators (quadratic H).
#[higher_order_lagrangian(order = 1)]
fn coupled(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * (dq[0].powi(2) + 2.0 * dq[1].powi(2))
        - 0.5 * (q[0].powi(2) + 3.0 * q[1].powi(2))
        - 0.4 * q[0] * q[1]
}

#[test]
fn the_forced_midpoint_converges_with_order_2_to_the_forced_motion() {
    // q'' = -q + f from q = 1 at rest: q(t) = f + (1 - f) cos t
    let (f, t): (f64, f64) = (0.7, 2.0);
    let exact = f + (1.0 - f) * t.cos();
    let error = |steps: usize| {
        let h = t / steps as f64;
        let mut z = Oscillator {}.legendre(&SVector::from([1.0, 0.0]));
        for _ in 0..steps {
            z = forced_step(
                &Oscillator {},
                &z,
                &SVector::from([f]),
                h,
                &StepOptions::default(),
            )
            .expect("regular")
            .0;
        }
        (z[0] - exact).abs()
    };
    let errors: Vec<f64> = [20, 40, 80].into_iter().map(error).collect();
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!((order - 2.0).abs() < 0.1, "order {order} ({errors:?})");
    }
    // the force pushes: with f = 0 the motion would be cos t
    assert!(errors[2] < 1e-3 && (exact - t.cos()).abs() > 0.5);
}

#[test]
fn the_energy_balance_is_the_work_of_the_force() {
    let system = Coupled {};
    let mut z = system.legendre(&SVector::from([0.3, -0.2, 0.5, 0.1]));
    for i in 0..200 {
        let f = SVector::from([(0.1 * i as f64).sin(), 0.5 * (0.07 * i as f64).cos()]);
        let (z1, _) = forced_step(&system, &z, &f, 0.05, &StepOptions::default()).expect("regular");
        let work = f.dot(&(z1.fixed_rows::<2>(0) - z.fixed_rows::<2>(0)));
        let gained = system.hamiltonian(&z1).unwrap() - system.hamiltonian(&z).unwrap();
        assert!(
            (gained - work).abs() < 1e-13,
            "step {i}: {gained} against {work}"
        );
        z = z1;
    }
}

#[test]
fn zero_force_is_the_unforced_step_and_bad_forces_are_errors() {
    let system = Coupled {};
    let z0 = system.legendre(&SVector::from([0.3, -0.2, 0.5, 0.1]));
    let options = StepOptions::default();
    let (forced, _) =
        forced_step(&system, &z0, &SVector::<f64, 2>::zeros(), 0.05, &options).unwrap();
    let (free, _) = step(&system, &z0, 0.05, &options).unwrap();
    assert!((forced - free).amax() < 1e-15);
    let nan = SVector::from([f64::NAN, 0.0]);
    assert!(matches!(
        forced_step(&system, &z0, &nan, 0.05, &options),
        Err(Error::InvalidArgument { name: "force", .. })
    ));
}
