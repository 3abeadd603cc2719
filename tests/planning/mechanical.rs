//! `#[mechanical_system]`: the inverse dynamics derived from T - V against the torques of the
//! swing-up suite written by hand, the mass matrix against finite differences of dl/dq', and
//! the cart-pole swing-up planned from its energy against the plan of the hand-written
//! Lagrangian and constraint.

use std::f64::consts::PI;

use retract::nalgebra::{SMatrix, SVector};
use retract::{
    Lagrangian, MechanicalSystem, OptimalControlProblem, PlanGuess, TorqueComponent,
    mechanical_system,
};

use crate::cart_pole::{CartPole, PoleTorque, cart_force, pole_torque};
use crate::common::{Noise, fd};
use crate::pendulum::{Plant, torque};

/// The cart-pole of the swing-up suite as its energy: cart x, pole angle th from the downward
/// vertical, point mass mp at length l; only the cart is driven.
#[mechanical_system(actuated = [0])]
fn cart_pole_energy(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64, g: f64) -> f64 {
    let kinetic = 0.5 * (mc + mp) * dq[0] * dq[0]
        + mp * l * q[1].cos() * dq[0] * dq[1]
        + 0.5 * mp * l * l * dq[1] * dq[1];
    let potential = -mp * g * l * q[1].cos();
    kinetic - potential
}

/// The double pendulum of the swing-up suite as its energy (angles from the downward
/// vertical, the second relative to the first, point masses at the rod ends): fully actuated.
#[mechanical_system]
fn double_pendulum_energy(
    q: [f64; 2],
    dq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
) -> f64 {
    // the positions of the two masses, differentiated by hand only for their velocities
    let (a, b) = (q[0], q[0] + q[1]);
    let (da, db) = (dq[0], dq[0] + dq[1]);
    let v1 = [l1 * a.cos() * da, l1 * a.sin() * da];
    let v2 = [v1[0] + l2 * b.cos() * db, v1[1] + l2 * b.sin() * db];
    let kinetic =
        0.5 * m1 * (v1[0] * v1[0] + v1[1] * v1[1]) + 0.5 * m2 * (v2[0] * v2[0] + v2[1] * v2[1]);
    let potential = -(m1 + m2) * g * l1 * a.cos() - m2 * g * l2 * b.cos();
    kinetic - potential
}

/// |got - want|_inf / |want|_inf.
fn relative(got: &SVector<f64, 2>, want: [f64; 2]) -> f64 {
    let want = SVector::from(want);
    (got - want).amax() / want.amax()
}

/// A random point: q in [-pi, pi]^2, q' in [-3, 3]^2, q'' in [-10, 10]^2.
fn point(noise: &mut Noise) -> [[f64; 2]; 3] {
    let mut v = |scale: f64| [scale * noise.next(), scale * noise.next()];
    [v(PI), v(3.0), v(10.0)]
}

#[test]
fn tau_from_the_energy_equals_the_hand_written_torques() {
    let mut noise = Noise::new(32);
    let (mut worst_cart, mut worst_pendulum) = (0.0f64, 0.0f64);
    for _ in 0..1000 {
        let [q, dq, ddq] = point(&mut noise);
        let (mc, mp, l, g) = (
            1.0 + 0.5 * noise.next(),
            0.3 + 0.2 * noise.next(),
            0.5 + 0.2 * noise.next(),
            9.81,
        );
        let cart = CartPoleEnergy::new(mc, mp, l, g);
        let tau = cart.tau(&q.into(), &dq.into(), &ddq.into());
        let want = [
            cart_force(q, dq, ddq, mc, mp, l),
            pole_torque(q, dq, ddq, mp, l, g),
        ];
        worst_cart = worst_cart.max(relative(&tau, want));

        let (m1, m2, l1, l2) = (
            1.0 + 0.5 * noise.next(),
            1.0 + 0.5 * noise.next(),
            1.0 + 0.5 * noise.next(),
            1.0 + 0.5 * noise.next(),
        );
        let pendulum = DoublePendulumEnergy::new(m1, m2, l1, l2, g);
        let tau = pendulum.tau(&q.into(), &dq.into(), &ddq.into());
        let want = torque(q, dq, ddq, m1, m2, l1, l2, g);
        worst_pendulum = worst_pendulum.max(relative(&tau, want));
    }
    println!("tau relative error: cart-pole {worst_cart:e}, double pendulum {worst_pendulum:e}");
    assert!(worst_cart <= 1e-12, "cart-pole: {worst_cart:e}");
    assert!(
        worst_pendulum <= 1e-12,
        "double pendulum: {worst_pendulum:e}"
    );
}

/// M_ij = d p_i / d q'_j by the fourth-order stencil, p = dl/dq' given by `momentum`.
fn mass_by_differences(
    momentum: impl Fn(&SVector<f64, 2>) -> SVector<f64, 2>,
    dq: &SVector<f64, 2>,
) -> SMatrix<f64, 2, 2> {
    SMatrix::from_fn(|i, j| {
        fd(
            |t| {
                let mut moved = *dq;
                moved[j] += t;
                momentum(&moved)[i]
            },
            1e-3,
        )
    })
}

#[test]
fn the_mass_matrix_is_the_derivative_of_the_momenta() {
    let mut noise = Noise::new(7);
    let (m1, m2, l1, l2, g) = (1.0, 1.0, 1.0, 1.0, 9.81);
    let (pendulum, plant) = (
        DoublePendulumEnergy::new(m1, m2, l1, l2, g),
        Plant::new(m1, m2, l1, l2, g),
    );
    let (mc, mp, l) = (1.0, 0.3, 0.5);
    let cart = CartPoleEnergy::new(mc, mp, l, g);
    // p = dl/dq', written from T by hand
    let cart_momentum = |q: &SVector<f64, 2>, dq: &SVector<f64, 2>| {
        SVector::from([
            (mc + mp) * dq[0] + mp * l * q[1].cos() * dq[1],
            mp * l * q[1].cos() * dq[0] + mp * l * l * dq[1],
        ])
    };
    for _ in 0..100 {
        let [q, dq, _] = point(&mut noise);
        let (q, dq) = (SVector::from(q), SVector::from(dq));
        // the plant's gradient in u = q' is dl/dq'
        let want = mass_by_differences(|v| plant.gradient(&[q], v).u, &dq);
        let got = pendulum.mass_matrix(&q, &dq);
        assert!(
            (got - want).amax() <= 1e-8 * (1.0 + want.amax()),
            "{got} vs {want}"
        );
        assert!((got - got.transpose()).amax() == 0.0, "symmetric: {got}");
        let want = mass_by_differences(|v| cart_momentum(&q, v), &dq);
        let got = cart.mass_matrix(&q, &dq);
        assert!(
            (got - want).amax() <= 1e-8 * (1.0 + want.amax()),
            "{got} vs {want}"
        );
    }
}

/// The unactuated component of the cart-pole is the pole's torque, as a stage equality with
/// the gradient of the hand-written `PoleTorque`; the cost is 1/2 of the squared cart force.
#[test]
fn the_cost_and_the_equality_are_the_hand_written_ones() {
    use retract::JetFunction;
    let system = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81);
    let (hand_cost, hand_torque) = (
        CartPole::new(1.0, 0.3, 0.5),
        PoleTorque::new(0.3, 0.5, 9.81),
    );
    assert_eq!(CartPoleEnergy::ACTUATED, [0]);
    assert_eq!(CartPoleEnergy::UNACTUATED, [1]);
    assert_eq!(system.unactuated(), &[1]);
    let [passive] = system.unactuated_torques();
    assert_eq!(passive.index, 1);
    let mut noise = Noise::new(3);
    for _ in 0..100 {
        let [q, dq, ddq] = point(&mut noise);
        let (x, u) = ([SVector::from(q), SVector::from(dq)], SVector::from(ddq));
        let (cost, want) = (system.lagrangian(&x, &u), hand_cost.lagrangian(&x, &u));
        assert!(
            (cost - want).abs() <= 1e-12 * want.abs().max(1.0),
            "{cost} vs {want}"
        );
        let (got, want) = (passive.gradient(&x, &u), hand_torque.gradient(&x, &u));
        for j in 0..2 {
            assert!((got.x[j] - want.x[j]).amax() <= 1e-12 * (1.0 + want.x[j].amax()));
        }
        assert!((got.u - want.u).amax() <= 1e-12 * (1.0 + want.u.amax()));
        let (got, want) = (passive.hessian(&x, &u), hand_torque.hessian(&x, &u));
        assert!((got.uu - want.uu).amax() <= 1e-12 && (got.xu[0] - want.xu[0]).amax() <= 1e-12);
        // another component is no equality of this system
        let actuated = TorqueComponent {
            system: &system,
            index: 0,
        };
        assert!(actuated.value(&x, &u).is_nan());
    }
}

/// The swing-up planned from the energy is the plan of the hand-written cost 1/2 F^2 and
/// constraint tau_pole = 0.
#[test]
fn the_cart_pole_swing_up_from_its_energy_is_the_hand_written_plan() {
    let (t_end, steps) = (2.0, 50);
    let goal = [0.0, PI, 0.0, 0.0];
    let (hand, hand_torque) = (
        CartPole::new(1.0, 0.3, 0.5),
        PoleTorque::new(0.3, 0.5, 9.81),
    );
    let want = OptimalControlProblem::new(&hand, &[0.0; 4], &goal, t_end, steps)
        .with_equality(&hand_torque)
        .solve(PlanGuess::Spline)
        .unwrap();
    let system = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81);
    let passive = system.unactuated_torques();
    let got = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
        .with_equalities(&passive)
        .solve(PlanGuess::Spline)
        .unwrap();
    let cost_gap = (got.cost - want.cost).abs() / want.cost;
    let state_gap = got
        .x
        .iter()
        .zip(&want.x)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);
    println!(
        "J = {} (hand-written {}), relative {cost_gap:e}; states {state_gap:e}; iterations {} vs {}",
        got.cost, want.cost, got.iterations, want.iterations
    );
    assert_eq!(got.certificate.negative_directions, 0);
    assert!(cost_gap <= 1e-10, "cost: {cost_gap:e}");
    assert!(state_gap <= 1e-9, "states: {state_gap:e}");
}

/// The largest |H(z_i) - H(z_0) - W_i| along the forced midpoint path of the double pendulum
/// over t in [0, 2] in `steps` steps, W_i the work of the input f = B u along the discrete
/// path, sum over the steps of f . (q_{j+1} - q_j), u at each step's midpoint time.
fn energy_balance_error(steps: usize) -> f64 {
    use retract::LiftedSystem;
    use retract::forced::forced_step;
    let system = DoublePendulumEnergy::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let plant = system.plant();
    let h = 2.0 / steps as f64;
    let mut z = plant.legendre(&SVector::from([0.5, -0.3, 0.0, 0.0]));
    let start = plant.hamiltonian(&z).unwrap();
    let (mut work, mut worst) = (0.0, 0.0f64);
    for i in 0..steps {
        let t = (i as f64 + 0.5) * h;
        let force = system.input_force(&SVector::from([(3.0 * t).sin(), 2.0 * (2.0 * t).cos()]));
        let (next, _) = forced_step(&plant, &z, &force, h, &Default::default()).unwrap();
        work += force.dot(&(next.fixed_rows::<2>(0) - z.fixed_rows::<2>(0)));
        z = next;
        let balance = plant.hamiltonian(&z).unwrap() - start - work;
        worst = worst.max(balance.abs());
    }
    worst
}

/// Plant simulation from the energy: the change of energy along the forced midpoint path is
/// the work of the input up to O(h^2) (observed order 2); the unforced step is symplectic.
#[test]
fn the_plant_balances_energy_and_work_at_order_2() {
    let errors: Vec<f64> = [50, 100, 200, 400]
        .into_iter()
        .map(energy_balance_error)
        .collect();
    let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
    println!("energy balance errors {errors:?}, observed orders {orders:?}");
    for order in &orders {
        assert!((order - 2.0).abs() < 0.2, "orders {orders:?} ({errors:?})");
    }
    let plant = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81).plant();
    let z0 = SVector::from([0.2, 2.5, 0.3, -0.4]);
    let error =
        retract::diagnostics::symplecticity_error(&plant, &z0, 0.05, &Default::default()).unwrap();
    assert!(error < 1e-12, "symplecticity {error:e}");
    // the input of the cart-pole drives the cart only
    let force = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81).input_force(&SVector::from([2.0]));
    assert_eq!(force, SVector::from([2.0, 0.0]));
}
