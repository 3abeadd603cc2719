//! `#[mechanical_system]`: the inverse dynamics derived from T - V against the torques of the
//! swing-up suite and of the n-link chain written by hand (with friction too), the mass
//! matrix against finite differences of dl/dq', the input and the passive equality of an
//! actuation matrix against the quadrotor's by hand, the swing-ups planned from the energy
//! against the plans of the hand-written Lagrangians (and through B against `actuated`), and
//! the energy balance of the forced, damped plant.

use std::f64::consts::PI;

use retract::nalgebra::{SMatrix, SVector};
use retract::{
    JetFunction, Lagrangian, LiftedSystem, MechanicalSystem, OptimalControlProblem, PlanGuess,
    TorqueComponent,
};

use crate::cart_pole::{
    CartForce, CartPole, CartPoleEnergy, DampedCartPole, PoleTorque, PushedCartPole, cart_force,
    pole_torque,
};
use crate::common::{Noise, fd};
use crate::mechanical_models::{DoublePendulumEnergy, QuadrotorEnergy};
use crate::pendulum::{Plant, TorqueCost, torque};

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

/// The largest relative gap of the costs and the largest gap of the states of two plans.
fn plan_gaps(got: &retract::bvp::Plan<2, 4>, want: &retract::bvp::Plan<2, 4>) -> (f64, f64) {
    let cost_gap = (got.cost - want.cost).abs() / want.cost;
    let state_gap = got
        .x
        .iter()
        .zip(&want.x)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max);
    println!(
        "J = {} (reference {}), relative {cost_gap:e}; states {state_gap:e}; iterations {} vs {}",
        got.cost, want.cost, got.iterations, want.iterations
    );
    assert_eq!(got.certificate.negative_directions, 0);
    (cost_gap, state_gap)
}

/// The swing-up planned from the energy is the plan of the hand-written cost 1/2 F^2 and
/// constraint tau_pole = 0; driven through the actuation matrix B = (1, 0) it is the same
/// plan again.
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
    let (cost_gap, state_gap) = plan_gaps(&got, &want);
    assert!(cost_gap <= 1e-10, "cost: {cost_gap:e}");
    assert!(state_gap <= 1e-9, "states: {state_gap:e}");
    let pushed = PushedCartPole::new(1.0, 0.3, 0.5, 9.81);
    let passive = pushed.unactuated_torques();
    let through_b = OptimalControlProblem::new(&pushed, &[0.0; 4], &goal, t_end, steps)
        .with_equalities(&passive)
        .solve(PlanGuess::Spline)
        .unwrap();
    let (cost_gap, state_gap) = plan_gaps(&through_b, &got);
    assert!(cost_gap <= 1e-10, "through B, cost: {cost_gap:e}");
    assert!(state_gap <= 1e-9, "through B, states: {state_gap:e}");
}

/// The inputs as functions of the jet (`input_functions = true`): their values are `input`,
/// their gradients and Hessians those of finite differences, with actuated coordinates and
/// through the actuation matrix.
#[test]
fn the_input_functions_are_the_input_with_its_derivatives() {
    let actuated = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81);
    let through_b = PushedCartPole::new(1.0, 0.3, 0.5, 9.81);
    let (first, second) = (actuated.input_functions(), through_b.input_functions());
    let functions: [&dyn JetFunction<2, 2>; 2] = [&first[0], &second[0]];
    let mut noise = Noise::new(17);
    for _ in 0..50 {
        let [q, dq, ddq] = point(&mut noise).map(SVector::from);
        let x = [q, dq];
        let want = actuated.input(&q, &dq, &ddq)[0];
        assert!((want - cart_force(q.into(), dq.into(), ddq.into(), 1.0, 0.3, 0.5)).abs() < 1e-12);
        for (which, f) in functions.iter().enumerate() {
            assert!(
                (f.value(&x, &ddq) - want).abs() <= 1e-12 * (1.0 + want.abs()),
                "{which}"
            );
            // the jet (q, q', q'') as one vector of 6: the value, the gradient and the Hessian
            // there, flattened in that order
            let split = |v: &[f64; 6]| {
                let x = [SVector::from([v[0], v[1]]), SVector::from([v[2], v[3]])];
                (x, SVector::from([v[4], v[5]]))
            };
            let gradient_at = |v: &[f64; 6]| {
                let (x, u) = split(v);
                let g = f.gradient(&x, &u);
                [g.x[0][0], g.x[0][1], g.x[1][0], g.x[1][1], g.u[0], g.u[1]]
            };
            let v0 = [q[0], q[1], dq[0], dq[1], ddq[0], ddq[1]];
            let hessian = f.hessian(&x, &ddq);
            let block = |i: usize, j: usize| match (i / 2, j / 2) {
                (2, 2) => hessian.uu[(i % 2, j % 2)],
                (a, 2) => hessian.xu[a][(i % 2, j % 2)],
                (2, b) => hessian.xu[b][(j % 2, i % 2)],
                (a, b) => hessian.xx[a][b][(i % 2, j % 2)],
            };
            let moved = |i: usize, e: f64| {
                let mut v = v0;
                v[i] += e;
                v
            };
            for (i, &generated) in gradient_at(&v0).iter().enumerate() {
                let g_fd = fd(
                    |e| {
                        let (x, u) = split(&moved(i, e));
                        f.value(&x, &u)
                    },
                    1e-4,
                );
                assert!(
                    (generated - g_fd).abs() <= 1e-7 * (1.0 + g_fd.abs()),
                    "{which} d{i}: {generated} vs {g_fd}"
                );
                for j in 0..6 {
                    let h_fd = fd(|e| gradient_at(&moved(j, e))[i], 1e-4);
                    assert!(
                        (block(i, j) - h_fd).abs() <= 1e-6 * (1.0 + h_fd.abs()),
                        "{which} d{i}d{j}: {} vs {h_fd}",
                        block(i, j)
                    );
                }
            }
        }
    }
}

/// A bound on the cart force written through the generated input function is the bound on
/// the hand-written force: the same plan (the constrained suite's |F| <= 12 at T = 2, fewer
/// steps), with the bound active.
#[test]
fn a_bound_on_the_generated_input_is_the_hand_written_bound() {
    let (t_end, steps, limit) = (2.0, 50, 12.0);
    let goal = [0.0, PI, 0.0, 0.0];
    let (hand, hand_torque, hand_force) = (
        CartPole::new(1.0, 0.3, 0.5),
        PoleTorque::new(0.3, 0.5, 9.81),
        CartForce::new(1.0, 0.3, 0.5),
    );
    let want = OptimalControlProblem::new(&hand, &[0.0; 4], &goal, t_end, steps)
        .with_equality(&hand_torque)
        .with_function_bounds(&hand_force, -limit, limit)
        .solve(PlanGuess::Spline)
        .unwrap();
    let system = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81);
    let (passive, inputs) = (system.unactuated_torques(), system.input_functions());
    let got = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
        .with_equalities(&passive)
        .with_function_bounds(&inputs[0], -limit, limit)
        .solve(PlanGuess::Spline)
        .unwrap();
    let (cost_gap, state_gap) = plan_gaps(&got, &want);
    assert!(cost_gap <= 1e-10, "cost: {cost_gap:e}");
    assert!(state_gap <= 1e-9, "states: {state_gap:e}");
    // the bound is active and holds at every step's midpoint
    let forces: Vec<f64> = (0..steps)
        .map(|i| {
            let x = (got.x[i] + got.x[i + 1]) * 0.5;
            let (q, dq) = (SVector::from([x[0], x[1]]), SVector::from([x[2], x[3]]));
            system.input(&q, &dq, &got.u[i])[0]
        })
        .collect();
    let largest = forces.iter().fold(0.0_f64, |m, f| m.max(f.abs()));
    assert!(largest <= limit + 1e-6, "largest force {largest}");
    assert!(
        largest >= limit - 1e-3,
        "the bound is not active: {largest}"
    );
}

/// The double pendulum's swing-up planned from its energy is the plan of the hand-written
/// minimum-torque Lagrangian 1/2 |tau|^2 of the swing-up suite.
#[test]
fn the_double_pendulum_swing_up_from_its_energy_is_the_hand_written_plan() {
    let (t_end, steps) = (2.0, 50);
    let goal = [PI, 0.0, 0.0, 0.0];
    let hand = TorqueCost::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let want = OptimalControlProblem::new(&hand, &[0.0; 4], &goal, t_end, steps)
        .solve(PlanGuess::Spline)
        .unwrap();
    let system = DoublePendulumEnergy::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let got = OptimalControlProblem::new(&system, &[0.0; 4], &goal, t_end, steps)
        .solve(PlanGuess::Spline)
        .unwrap();
    let (cost_gap, state_gap) = plan_gaps(&got, &want);
    assert!(cost_gap <= 1e-10, "cost: {cost_gap:e}");
    assert!(state_gap <= 1e-9, "states: {state_gap:e}");
}

/// The largest |H(z_i) - H(z_0) - W_i| along the forced midpoint path of the double pendulum
/// over t in [0, 2] in `steps` steps, W_i the work of the input f = B u along the discrete
/// path, sum over the steps of f . (q_{j+1} - q_j), u at each step's midpoint time.
fn energy_balance_error(steps: usize) -> f64 {
    use retract::forced::forced_step;
    let system = DoublePendulumEnergy::new(1.0, 1.0, 1.0, 1.0, 9.81);
    let plant = system.plant();
    let h = 2.0 / steps as f64;
    let mut z = plant.legendre(&SVector::from([0.5, -0.3, 0.0, 0.0]));
    let start = plant.hamiltonian(&z).unwrap();
    let (mut work, mut worst) = (0.0, 0.0f64);
    for i in 0..steps {
        let t = (i as f64 + 0.5) * h;
        let u = SVector::from([(3.0 * t).sin(), 2.0 * (2.0 * t).cos()]);
        let q: SVector<f64, 2> = z.fixed_rows::<2>(0).into();
        let force = system.input_force(&q, &u);
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
    let force = CartPoleEnergy::new(1.0, 0.3, 0.5, 9.81)
        .input_force(&SVector::from([0.3, 1.0]), &SVector::from([2.0]));
    assert_eq!(force, SVector::from([2.0, 0.0]));
}

/// With friction, tau gains -Q_nc = (bc x', bp th') on the hand-written torques, the cost is
/// 1/2 tau_0^2 plus the user's C = k/2 x'^2 + k u x with u = tau_0, and the pole's equality
/// includes its friction.
#[test]
fn friction_and_the_users_cost_enter_tau_and_the_lagrangian() {
    let mut noise = Noise::new(11);
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let [q, dq, ddq] = point(&mut noise);
        let (mc, mp, l, g) = (
            1.0 + 0.5 * noise.next(),
            0.3 + 0.2 * noise.next(),
            0.5,
            9.81,
        );
        let (bc, bp, k) = (0.5 + 0.4 * noise.next(), 0.1 + 0.05 * noise.next(), 0.7);
        let system = DampedCartPole::new(mc, mp, l, g, bc, bp, k);
        let want = [
            cart_force(q, dq, ddq, mc, mp, l) + bc * dq[0],
            pole_torque(q, dq, ddq, mp, l, g) + bp * dq[1],
        ];
        let tau = system.tau(&q.into(), &dq.into(), &ddq.into());
        worst = worst.max(relative(&tau, want));
        let force = system.nonconservative_force(&q.into(), &dq.into());
        assert_eq!(force, SVector::from([-bc * dq[0], -bp * dq[1]]));
        let (x, u) = ([SVector::from(q), SVector::from(dq)], SVector::from(ddq));
        let cost = 0.5 * want[0] * want[0] + 0.5 * k * dq[0] * dq[0] + k * want[0] * q[0];
        let got = system.lagrangian(&x, &u);
        assert!(
            (got - cost).abs() <= 1e-12 * cost.abs().max(1.0),
            "{got} vs {cost}"
        );
        let [passive] = system.unactuated_torques();
        let pole = passive.value(&x, &u);
        assert!((pole - want[1]).abs() <= 1e-12 * want[1].abs().max(1.0));
    }
    println!("tau with friction, relative error {worst:e}");
    assert!(worst <= 1e-12, "{worst:e}");
}

/// The planar quadrotor through its actuation matrix B(q) (two rotors): the generated input
/// u = (B^T B)^{-1} B^T tau is the suite's rotor thrusts f1,2 = Th/2 -+ tq/(2a), the passive
/// equality is 2a times the lateral force fx cos(th) + fz sin(th), the cost 1/2 |u|^2, and
/// tau - B u is orthogonal to the columns of B.
#[test]
fn an_actuation_matrix_gives_the_quadrotors_thrusts_and_lateral_force() {
    let (m, inertia, arm, g) = (1.0, 0.01, 0.1, 9.81);
    let system = QuadrotorEnergy::new(m, inertia, arm, g);
    let mut noise = Noise::new(5);
    let mut v = |scale: f64| SVector::from([0.0; 3].map(|_: f64| scale * noise.next()));
    for _ in 0..1000 {
        let (q, dq, ddq) = (v(PI), v(3.0), v(10.0));
        let (s, c) = (q[2].sin(), q[2].cos());
        let (fx, fz, tq) = (m * ddq[0], m * ddq[1] + m * g, inertia * ddq[2]);
        let thrust = -fx * s + fz * c;
        let want = [
            thrust / 2.0 - tq / (2.0 * arm),
            thrust / 2.0 + tq / (2.0 * arm),
        ];
        let u = system.input(&q, &dq, &ddq);
        let scale = want[0].abs().max(want[1].abs());
        assert!(
            (u - SVector::from(want)).amax() <= 1e-12 * scale,
            "{u} vs {want:?}"
        );
        let (x, jet_u) = ([q, dq], ddq);
        let cost = 0.5 * (want[0] * want[0] + want[1] * want[1]);
        let got = system.lagrangian(&x, &jet_u);
        assert!(
            (got - cost).abs() <= 1e-12 * cost.max(1.0),
            "{got} vs {cost}"
        );
        let lateral = fx * c + fz * s;
        let [passive] = system.unactuated_torques();
        let value = passive.value(&x, &jet_u);
        assert!((value - 2.0 * arm * lateral).abs() <= 1e-12 * lateral.abs().max(1.0));
        let tau = system.tau(&q, &dq, &ddq);
        let residual = tau - system.input_force(&q, &u);
        let b = nalgebra_columns(&system, &q);
        for column in b {
            assert!(column.dot(&residual).abs() <= 1e-12 * tau.amax());
        }
    }
}

/// The columns of B(q) from `input_force` of the unit inputs.
fn nalgebra_columns(system: &QuadrotorEnergy, q: &SVector<f64, 3>) -> [SVector<f64, 3>; 2] {
    [
        system.input_force(q, &SVector::from([1.0, 0.0])),
        system.input_force(q, &SVector::from([0.0, 1.0])),
    ]
}

/// The largest |H(z_i) - H(z_0) - W_i - D_i| along the forced midpoint path of the damped
/// cart-pole over t in [0, 2] in `steps` steps: W_i the work of the input B u along the
/// discrete path, sum of f . (q_{j+1} - q_j), D_i that of the friction Q_nc at each step's
/// midpoint (q_j + q_{j+1})/2 with the discrete velocity (q_{j+1} - q_j)/h (a fixed point,
/// the force held over the step), and the dissipated work -D_N.
fn damped_balance_error(steps: usize) -> (f64, f64) {
    use retract::forced::forced_step;
    let system = DampedCartPole::new(1.0, 0.3, 0.5, 9.81, 0.8, 0.05, 0.0);
    let plant = system.plant();
    let h = 2.0 / steps as f64;
    let mut z = plant.legendre(&SVector::from([0.0, 0.5, 0.3, -1.0]));
    let start = plant.hamiltonian(&z).unwrap();
    let (mut work, mut dissipated, mut worst) = (0.0, 0.0, 0.0f64);
    for i in 0..steps {
        let t = (i as f64 + 0.5) * h;
        let q0: SVector<f64, 2> = z.fixed_rows::<2>(0).into();
        let input = system.input_force(&q0, &SVector::from([2.0 * (3.0 * t).sin()]));
        let mut friction = SVector::<f64, 2>::zeros();
        let mut next = z;
        for _ in 0..100 {
            let force = input + friction;
            next = forced_step(&plant, &z, &force, h, &Default::default())
                .unwrap()
                .0;
            let q1: SVector<f64, 2> = next.fixed_rows::<2>(0).into();
            let updated = system.nonconservative_force(&((q0 + q1) * 0.5), &((q1 - q0) / h));
            let change = (updated - friction).amax();
            friction = updated;
            if change <= 1e-13 * (1.0 + friction.amax()) {
                break;
            }
        }
        let q1: SVector<f64, 2> = next.fixed_rows::<2>(0).into();
        work += input.dot(&(q1 - q0));
        dissipated -= friction.dot(&(q1 - q0));
        z = next;
        let balance = plant.hamiltonian(&z).unwrap() - start - work + dissipated;
        worst = worst.max(balance.abs());
    }
    (worst, dissipated)
}

/// The damped plant: the change of energy is the input's work less the work dissipated by
/// friction, up to O(h^2) (observed order 2), and friction dissipates.
#[test]
fn the_damped_plant_balances_energy_input_and_dissipation_at_order_2() {
    let runs: Vec<(f64, f64)> = [50, 100, 200, 400]
        .into_iter()
        .map(damped_balance_error)
        .collect();
    let errors: Vec<f64> = runs.iter().map(|r| r.0).collect();
    let orders: Vec<f64> = errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect();
    println!(
        "damped energy balance errors {errors:?}, observed orders {orders:?}, dissipated {runs:?}"
    );
    for order in &orders {
        assert!((order - 2.0).abs() < 0.2, "orders {orders:?} ({errors:?})");
    }
    assert!(
        runs.iter().all(|r| r.1 > 0.1),
        "friction dissipates: {runs:?}"
    );
}

/// The n-link chain's torques by hand (the formula of the constrained suite's chain): with
/// absolute angles phi_a = q_0 + ... + q_a, the torque on phi_a is the sum over the masses
/// j >= a and the links b <= j of cos(phi_a - phi_b) phi_b'' + sin(phi_a - phi_b) phi_b'^2,
/// plus g (n - a) sin(phi_a) (0-based a); tau_i = sum over a >= i.
fn chain_torque<const N: usize>(q: &[f64; N], dq: &[f64; N], ddq: &[f64; N]) -> [f64; N] {
    let mut phi = [0.0; N];
    let mut dphi = [0.0; N];
    let mut ddphi = [0.0; N];
    let (mut a, mut b, mut c) = (0.0, 0.0, 0.0);
    for i in 0..N {
        (a, b, c) = (a + q[i], b + dq[i], c + ddq[i]);
        (phi[i], dphi[i], ddphi[i]) = (a, b, c);
    }
    let mut absolute = [0.0; N];
    for (ai, torque) in absolute.iter_mut().enumerate() {
        *torque = 9.81 * (N - ai) as f64 * phi[ai].sin();
        for j in ai..N {
            for bi in 0..=j {
                let d = phi[ai] - phi[bi];
                *torque += d.cos() * ddphi[bi] + d.sin() * dphi[bi] * dphi[bi];
            }
        }
    }
    let mut tau = [0.0; N];
    let mut sum = 0.0;
    for i in (0..N).rev() {
        sum += absolute[i];
        tau[i] = sum;
    }
    tau
}

/// The 7-link chain as T - V (only its tau is used here).
#[allow(dead_code)]
mod chain {
    crate::energy_chain!(chain_seven, 7);
}
use chain::ChainSeven;

/// At 1000 random points the 7-link chain's tau derived from T - V is the hand-written
/// torque to 1e-12 relative.
#[test]
fn the_chains_tau_from_its_energy_is_the_hand_written_torque() {
    let system = ChainSeven::new();
    let mut noise = Noise::new(77);
    let mut worst = 0.0f64;
    for _ in 0..1000 {
        let mut v = |scale: f64| [0.0; 7].map(|_: f64| scale * noise.next());
        let (q, dq, ddq) = (v(PI), v(3.0), v(10.0));
        let want = SVector::from(chain_torque(&q, &dq, &ddq));
        let got = system.tau(&q.into(), &dq.into(), &ddq.into());
        worst = worst.max((got - want).amax() / want.amax());
    }
    println!("chain n=7: tau relative error {worst:e}");
    assert!(worst <= 1e-12, "{worst:e}");
}
