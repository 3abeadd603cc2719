//! Typed data and guesses from a path (issue 16, items 1 and 3): `Plan::evaluate` against
//! polynomials it must reproduce and against the exact minimum-acceleration spline, named
//! accessors on trajectories and solutions, and `Curve` guesses for both solvers.

use crate::common;

use common::models::{DISC_GOAL, DISC_START, OneDisc, disc_bump_guess};

use retract::bvp::root_finder::{BoundaryValueProblem, Guess};
use retract::bvp::{Certificate, Curve, OptimalControlProblem, Plan, PlanGuess};
use retract::nalgebra::SVector;
use retract::{Error, Jet, State, StepOptions, higher_order_lagrangian, trajectory};

/// L = 1/2 |q''|^2 in the plane: between rest states the exact optimum is the cubic
/// q(t) = a + (b - a)(3 s^2 - 2 s^3), s = t / T.
#[higher_order_lagrangian(order = 2)]
fn acceleration(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2))
}

/// L = 1/2 (q''')^2 on the line (k = 3).
#[higher_order_lagrangian(order = 3)]
fn jerk(_q: f64, _dq: f64, _ddq: f64, dddq: f64) -> f64 {
    0.5 * dddq * dddq
}

fn hand_plan<const N: usize, const X: usize>(h: f64, x: Vec<SVector<f64, X>>) -> Plan<N, X> {
    let steps = x.len() - 1;
    Plan {
        h,
        theta: 0.5,
        momenta: vec![SVector::zeros(); x.len()],
        u: vec![SVector::zeros(); steps],
        x,
        cost: 0.0,
        iterations: 0,
        certificate: Certificate {
            stationarity: 0.0,
            feasibility: 0.0,
            complementarity: 0.0,
            negative_directions: 0,
            min_reduced_hessian_eig: f64::NAN,
        },
        violations: Default::default(),
        duals: Default::default(),
    }
}

/// A plan whose jets are samples of a cubic (k = 2) or a quintic (k = 3) is interpolated
/// exactly between the nodes: the Hermite interpolant of degree 2k - 1 reproduces them.
#[test]
fn evaluate_reproduces_polynomials_of_degree_2k_minus_1() {
    // k = 2, n = 2: q = (1 - t + 2 t^2 - t^3, 3 t^3 - t), on unequal-looking h = 0.37
    let cubic = |t: f64| [1.0 - t + 2.0 * t * t - t.powi(3), 3.0 * t.powi(3) - t];
    let slope = |t: f64| [-1.0 + 4.0 * t - 3.0 * t * t, 9.0 * t * t - 1.0];
    let h = 0.37;
    let x = (0..=6)
        .map(|i| {
            let t = i as f64 * h;
            let (q, dq) = (cubic(t), slope(t));
            SVector::from([q[0], q[1], dq[0], dq[1]])
        })
        .collect();
    let plan = hand_plan::<2, 4>(h, x);
    for t in [0.0, 0.05, 0.37, 0.5, 1.0, 1.11, 1.9, 2.2] {
        let x = plan.evaluate(t).unwrap();
        let (q, dq) = (cubic(t), slope(t));
        let want = [q[0], q[1], dq[0], dq[1]];
        for r in 0..4 {
            assert!(
                (x[r] - want[r]).abs() < 1e-12,
                "t = {t}, entry {r}: {} vs {}",
                x[r],
                want[r]
            );
        }
    }
    // k = 3, n = 1: q = t^5 - 2 t^2 (with q', q'' at the nodes)
    let quintic = |t: f64| {
        [
            t.powi(5) - 2.0 * t * t,
            5.0 * t.powi(4) - 4.0 * t,
            20.0 * t.powi(3) - 4.0,
        ]
    };
    let x = (0..=4)
        .map(|i| SVector::from(quintic(i as f64 * 0.25)))
        .collect();
    let plan = hand_plan::<1, 3>(0.25, x);
    for t in [0.1, 0.3, 0.62, 0.99] {
        let x = plan.evaluate(t).unwrap();
        let want = quintic(t);
        for r in 0..3 {
            assert!(
                (x[r] - want[r]).abs() < 1e-11,
                "t = {t}, q^({r}): {} vs {}",
                x[r],
                want[r]
            );
        }
    }
}

/// The optimizer's plan for L = 1/2 |q''|^2 from rest to rest: the interpolant approaches the
/// exact cubic at second order in h (the midpoint scheme's nodes carry O(h^2)), is continuous
/// at the nodes, and times outside [0, T] are errors.
#[test]
fn evaluate_converges_to_the_exact_cubic() {
    let system = Acceleration {};
    let (a, b, t_end) = ([1.0, -1.0], [3.0, 0.5], 2.0);
    let exact = |t: f64| {
        let s = t / t_end;
        let (w, dw) = (
            3.0 * s * s - 2.0 * s.powi(3),
            (6.0 * s - 6.0 * s * s) / t_end,
        );
        [
            a[0] + (b[0] - a[0]) * w,
            a[1] + (b[1] - a[1]) * w,
            (b[0] - a[0]) * dw,
            (b[1] - a[1]) * dw,
        ]
    };
    let mut errors = Vec::new();
    for steps in [10, 20, 40] {
        let start = [a[0], a[1], 0.0, 0.0];
        let goal = [b[0], b[1], 0.0, 0.0];
        let plan = OptimalControlProblem::new(&system, &start, &goal, t_end, steps)
            .solve(PlanGuess::Spline)
            .unwrap();
        let mut worst: f64 = 0.0;
        for m in 0..=97 {
            let t = t_end * m as f64 / 97.0;
            let x = plan.evaluate(t).unwrap();
            let want = exact(t);
            for r in 0..4 {
                worst = worst.max((x[r] - want[r]).abs());
            }
        }
        errors.push(worst);
        // continuity at the nodes, from both sides
        let times = plan.times();
        assert_eq!(times.len(), steps + 1);
        for (i, &t) in times.iter().enumerate().skip(1).take(steps - 1) {
            for t in [t - 1e-10, t, t + 1e-10] {
                let x = plan.evaluate(t).unwrap();
                assert!((x - plan.x[i]).amax() < 1e-8, "node {i}, t = {t}");
            }
        }
        for t in [-1e-3, t_end * (1.0 + 1e-9), f64::NAN, f64::INFINITY] {
            assert!(
                matches!(
                    plan.evaluate(t),
                    Err(Error::InvalidArgument { name: "t", .. })
                ),
                "t = {t}"
            );
        }
        assert!(plan.evaluate(t_end).is_ok());
    }
    assert!(errors[2] < 1e-3, "{errors:?}");
    for pair in errors.windows(2) {
        let order = (pair[0] / pair[1]).log2();
        assert!(
            order > 1.8 && order < 2.2,
            "observed order {order}: {errors:?}"
        );
    }
}

/// The accessors name the blocks that flat indexing used to: a trajectory of the k = 3 jerk
/// Lagrangian (p_2 = q''', p_1 = -q'''', p_0 = q^(5)) read back by name.
#[test]
fn states_are_read_by_name() {
    let system = Jerk {};
    let jet = Jet::<1, 3>::new(&[[0.5], [1.0], [-0.2], [0.3], [0.1], [-0.4]]).unwrap();
    let z0 = State::from_jet(&system, &jet).unwrap();
    assert_eq!(z0.momentum(2), Some([0.3].into()));
    assert_eq!(z0.momentum(1), Some([-0.1].into()));
    assert_eq!(z0.momentum(0), Some([-0.4].into()));
    assert!((z0.top_derivative(&system).unwrap()[0] - 0.3).abs() < 1e-14);
    let run = trajectory(&system, &z0.to_vector(), 0.1, 5, &StepOptions::default()).unwrap();
    let times = run.times();
    assert_eq!(times.len(), 6);
    assert!((times[5] - 0.5).abs() < 1e-15);
    let last: State<1, 3> = run.state(5).unwrap();
    assert_eq!(last.q()[0], run.states[5][0]);
    assert_eq!(last.derivative(2).unwrap()[0], run.states[5][2]);
    assert_eq!(last.momentum(0).unwrap()[0], run.states[5][3]);
    assert!(run.state::<1, 3>(6).is_none());
}

/// Waypoints over the disc give the optimizer the same local minimum as the hand-built bump
/// guess of the other tests, and the root finder, from the same path's states, the same plan.
#[test]
fn curve_guesses_reach_the_same_plan_as_a_hand_built_guess() {
    let system = OneDisc { tau: 1e-2 };
    let steps = 200;
    let problem = OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps);
    let (x, u) = disc_bump_guess(steps);
    let reference = problem.solve(PlanGuess::Path { x: &x, u: &u }).unwrap();
    let over = Curve::through_waypoints(
        &[0.0, 1.0, 2.0, 3.0, 4.0],
        &[[-2.0, 0.2], [-1.0, 1.1], [0.0, 1.5], [1.0, 1.1], [2.0, 0.2]],
    )
    .unwrap();
    let plan = problem.solve(PlanGuess::Curve(&over)).unwrap();
    assert!((plan.cost - reference.cost).abs() < 1e-8 * reference.cost);
    for (a, b) in plan.x.iter().zip(&reference.x) {
        assert!((a - b).amax() < 1e-6);
    }
    // the root finder from the path's states (momenta by the Legendre map)
    let states = over.states(&system, 4.0, steps).unwrap();
    let root = BoundaryValueProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, steps)
        .solve(Guess::States(&states))
        .unwrap();
    assert!((root.cost - reference.cost).abs() < 1e-8 * reference.cost);
    for i in [0, 57, steps] {
        let state: State<2, 2> = root.state(i).unwrap();
        let planned: State<2, 2> = plan.state(i).unwrap();
        assert!((state.q() - planned.q()).amax() < 1e-6, "state {i}");
        assert!((state.momentum(0).unwrap() - planned.momentum(0).unwrap()).amax() < 1e-4);
    }
    let u = root.top_derivative::<2>(3).unwrap();
    assert!((u - plan.u[3]).amax() < 1e-4);
    assert!(root.top_derivative::<2>(steps).is_none());
    // a path through the disc is refused, not solved
    let through = Curve::from_fn(|t: f64| [t - 2.0, 0.2]);
    assert!(problem.solve(PlanGuess::Curve(&through)).is_err());
    // waypoints that do not span the horizon are an error
    let short = Curve::through_waypoints(&[0.0, 3.0], &[[-2.0, 0.2], [2.0, 0.2]]).unwrap();
    assert!(problem.solve(PlanGuess::Curve(&short)).is_err());
    assert!(short.states(&system, 4.0, steps).is_err());
}
