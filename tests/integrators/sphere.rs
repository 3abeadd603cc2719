//! Systems on the sphere S^2 (`#[higher_order_lagrangian(order = k, sphere)]`, `retract::sphere`):
//! the Riemannian cubic L = 1/2 |D_t q'|^2 written in ambient coordinates, stepped by the
//! paper's maps of S^2 in moving gnomonic charts. The state stays on the sphere, the step is
//! symplectic (in a fixed chart) and the same whichever chart computes it, the Noether
//! momentum of rotations is conserved to rounding and equals q x J - V x A, and the midpoint
//! maps converge with order 2 (the initial-point map with order 1) to an independent RK4
//! solution of the embedded Euler-Lagrange equation D_t^3 V + R(D_t V, V) V = 0.

use retract::bvp::{OptimalControlProblem, Plan, PlanGuess, PlanOptions};
use retract::diagnostics::canonical_structure;
use retract::higher_order_lagrangian;
use retract::map;
use retract::nalgebra::{SVector, Vector2, Vector3};
use retract::sphere::{
    self, Chart, ExponentialMidpoint, ProjectionInitial, ProjectionMidpoint, SphereMap,
    SphereState, SphereSystem,
};
use retract::{Error, NewtonOptions};

type State = SphereState<2, 8>;

#[path = "../../examples/common/sphere_cubic.rs"]
mod sphere_cubic;
use sphere_cubic::{Cubic, OutsideCap, data, jet, on_equator, reference};

#[higher_order_lagrangian(order = 1, sphere)]
fn geodesic(_q: [f64; 3], dq: [f64; 3]) -> f64 {
    0.5 * (dq[0].powi(2) + dq[1].powi(2) + dq[2].powi(2))
}

#[test]
fn geodesics_stay_on_the_sphere_and_on_their_great_circle_for_a_million_steps() {
    // from q = x with q' = y: the great circle in the xy-plane, period 2 pi, conserved
    // momentum z (|q'| = 1); 10^6 steps of 0.1 are about 16 000 turns
    let system = Geodesic::new();
    let (q, v) = (Vector3::x(), Vector3::y());
    let mut s = SphereState::<1, 4>::from_ambient(&system, &[q, v]).expect("on the sphere");
    let m0 = s.momentum();
    assert!((m0 - Vector3::z()).amax() < 1e-15, "{m0}");
    let options = NewtonOptions::default();
    let mut worst = [0.0_f64; 3];
    for _ in 0..1_000_000 {
        s = sphere::step(&system, &ProjectionMidpoint, &s, 0.1, &options)
            .expect("regular")
            .0;
        let q = s.point();
        worst[0] = worst[0].max((q.norm() - 1.0).abs());
        worst[1] = worst[1].max(q[2].abs());
        worst[2] = worst[2].max((s.momentum() - m0).amax());
    }
    assert!(worst[0] < 1e-15, "| |q| - 1 | = {:e}", worst[0]);
    assert!(worst[1] < 1e-12, "off the great circle by {:e}", worst[1]);
    assert!(worst[2] < 1e-11, "momentum drift {:e}", worst[2]);
}

fn start() -> State {
    SphereState::from_ambient(&Cubic::new(), &jet(data())).expect("a jet on the sphere")
}

/// `steps` steps of size `h` with `map`.
fn run<Map: SphereMap<2>>(map: &Map, h: f64, steps: usize) -> Result<Vec<State>, Error> {
    let options = NewtonOptions::default();
    let mut states = vec![start()];
    for _ in 0..steps {
        let last = states[states.len() - 1];
        states.push(sphere::step(&Cubic::new(), map, &last, h, &options)?.0);
    }
    Ok(states)
}

#[test]
fn the_state_stays_on_the_sphere_and_the_momentum_is_conserved() {
    // a cubic's speed grows with time: T = 20
    let states = run(&ProjectionMidpoint, 0.001, 20_000).expect("regular steps");
    let m0 = states[0].momentum();
    let mut worst = [0.0_f64; 3];
    for s in &states {
        let [q, dq] = s.ambient_jet();
        worst[0] = worst[0].max((q.norm() - 1.0).abs());
        worst[1] = worst[1].max(q.dot(&dq).abs());
        worst[2] = worst[2].max((s.momentum() - m0).amax());
    }
    // the point is phi(y) of a chart at every step, and the map and chart changes are
    // rotation-equivariant: all three are rounding
    assert!(worst[0] < 1e-15, "| |q| - 1 | = {:e}", worst[0]);
    assert!(worst[1] < 1e-14, "q . q' = {:e}", worst[1]);
    assert!(
        worst[2] < 1e-11 * m0.norm(),
        "momentum drift {:e}",
        worst[2]
    );
    // the path moved: it is not conserved because nothing happened
    let far = states
        .iter()
        .map(|s| (s.point() - states[0].point()).norm())
        .fold(0.0, f64::max);
    assert!(far > 1.0, "{far}");
}

#[test]
fn the_noether_momentum_is_q_cross_j_minus_v_cross_a() {
    // the momentum map <p, omega x x> = omega . (q x p_0 + V x p_1) with p_1 = A and
    // p_0 = -J (tangentially) is -(q x J - V x A): the conserved m up to its sign convention
    let m = sphere_cubic::momentum(data());
    let mu = start().momentum();
    assert!((mu + m).amax() < 1e-12 * m.norm(), "{mu} against -{m}");
}

#[test]
fn the_hamiltonian_is_j_dot_v_minus_half_a_squared() {
    // H = p_0 . q' + p_1 . q'' - L with p_1 = A, p_0 = -J (tangentially), L = |A|^2 / 2
    let [_, v, a, j] = data();
    let h = start().hamiltonian(&Cubic::new()).expect("finite");
    let expected = -(j.dot(&v)) + 0.5 * a.dot(&a);
    assert!((h - expected).abs() < 1e-12, "{h} against {expected}");
}

#[test]
fn every_map_conserves_the_momentum() {
    let m0 = start().momentum();
    let initial = run(&ProjectionInitial, 0.02, 500).expect("regular steps");
    let exponential = run(&ExponentialMidpoint, 0.02, 500).expect("regular steps");
    for states in [&initial, &exponential] {
        let drift = states
            .iter()
            .map(|s| (s.momentum() - m0).amax())
            .fold(0.0, f64::max);
        assert!(drift < 1e-12 * m0.norm(), "{drift:e}");
    }
    // the maps differ: the initial-point map is of order 1
    let gap = (initial[500].point() - exponential[500].point()).norm();
    assert!(gap > 1e-4, "{gap:e}");
}

/// A step computed in a given chart.
type StepIn<'a> = &'a dyn Fn(&Chart, &SVector<f64, 8>) -> SVector<f64, 8>;

/// The step map z0 -> z1 in the fixed chart `chart` (no chart change).
fn step_in_chart<Map: SphereMap<2>>(
    map: &Map,
    chart: &Chart,
    z: &SVector<f64, 8>,
    h: f64,
) -> SVector<f64, 8> {
    let params = chart.params();
    let system = Cubic::new().with_chart(params);
    map::step(
        &system,
        &map.in_chart(params),
        z,
        h,
        &NewtonOptions::default(),
    )
    .expect("regular step")
    .0
}

#[test]
fn the_step_is_symplectic_and_the_same_in_every_chart() {
    let s0 = start();
    let h = 0.1;
    let other = Chart::at(&(s0.point() + Vector3::new(0.3, 0.2, -0.1))).unwrap();
    let maps: [StepIn<'_>; 3] = [
        &|c, z| step_in_chart(&ProjectionInitial, c, z, h),
        &|c, z| step_in_chart(&ProjectionMidpoint, c, z, h),
        &|c, z| step_in_chart(&ExponentialMidpoint, c, z, h),
    ];
    for step in maps {
        // the same step computed in the chart of the state and in another chart
        let z0_other = s0.in_chart(&other).unwrap().z;
        let here = State {
            chart: s0.chart,
            z: step(&s0.chart, &s0.z),
        };
        let there = State {
            chart: other,
            z: step(&other, &z0_other),
        };
        let gap = (here.in_chart(&other).unwrap().z - there.z).amax();
        assert!(gap < 1e-12, "chart dependence {gap:e}");
    }
    // symplecticity of the step in the other chart (off-centre coordinates)
    let z0 = s0.in_chart(&other).unwrap().z;
    let params = other.params();
    let system = Cubic::new().with_chart(params);
    let j = canonical_structure::<8>();
    for error in [
        sym(
            &system,
            &SphereMap::<2>::in_chart(&ProjectionMidpoint, params),
            &z0,
            h,
            &j,
        ),
        sym(
            &system,
            &SphereMap::<2>::in_chart(&ExponentialMidpoint, params),
            &z0,
            h,
            &j,
        ),
        sym(
            &system,
            &SphereMap::<2>::in_chart(&ProjectionInitial, params),
            &z0,
            h,
            &j,
        ),
    ] {
        assert!(error < 1e-12, "|DPsi^T J DPsi - J| = {error:e}");
    }
}

/// |DPsi^T J DPsi - J| of the map's step.
fn sym<Map: map::DiscretizationMap<2, 2>>(
    system: &Cubic,
    m: &Map,
    z0: &SVector<f64, 8>,
    h: f64,
    j: &retract::nalgebra::SMatrix<f64, 8, 8>,
) -> f64 {
    let d = map::step_map_derivative(system, m, z0, h, &NewtonOptions::default()).expect("regular");
    (d.transpose() * j * d - j).amax()
}

#[test]
fn the_midpoint_maps_have_order_2_and_the_initial_point_map_order_1() {
    let t = 1.0;
    let exact = reference(data(), t, 20_000)[0];
    let error = |map: &dyn Fn(f64, usize) -> State, steps: usize| {
        (map(t / steps as f64, steps).point() - exact).norm()
    };
    let last = |states: Vec<State>| states[states.len() - 1];
    let midpoint = |h: f64, n: usize| last(run(&ProjectionMidpoint, h, n).unwrap());
    let exponential = |h: f64, n: usize| last(run(&ExponentialMidpoint, h, n).unwrap());
    let initial = |h: f64, n: usize| last(run(&ProjectionInitial, h, n).unwrap());
    for (name, map, order) in [
        (
            "projection midpoint",
            &midpoint as &dyn Fn(f64, usize) -> State,
            2.0,
        ),
        ("exponential midpoint", &exponential, 2.0),
        ("projection initial point", &initial, 1.0),
    ] {
        let errors: Vec<f64> = [40, 80, 160].iter().map(|&n| error(map, n)).collect();
        for pair in errors.windows(2) {
            let observed = (pair[0] / pair[1]).log2();
            assert!(
                (observed - order).abs() < 0.15,
                "{name}: order {observed} ({errors:?})"
            );
        }
    }
}

#[test]
fn bad_jets_and_far_charts_are_errors() {
    let mut bad = jet(data());
    bad[0] *= 1.1;
    assert!(matches!(
        SphereState::<2, 8>::from_ambient(&Cubic::new(), &bad),
        Err(Error::InvalidArgument { name: "jet", .. })
    ));
    assert!(SphereState::<2, 8>::from_ambient(&Cubic::new(), &jet(data())[..3]).is_err());
    let s = start();
    let opposite = Chart::at(&-s.point()).unwrap();
    assert!(matches!(
        s.in_chart(&opposite),
        Err(Error::InvalidArgument { name: "chart", .. })
    ));
}

/// A state whose point is not on the unit sphere is refused by a step: chart coordinates so
/// large that the point overflows to (0, 0, 0) (issue 33, item 8), non-finite ones, and a
/// chart whose frame is not orthonormal.
#[test]
fn a_step_refuses_a_state_off_the_sphere() {
    let options = NewtonOptions::default();
    let s = start();
    let step =
        |state: &State| sphere::step(&Cubic::new(), &ProjectionMidpoint, state, 0.01, &options);
    assert!(step(&s).is_ok());
    // at rest there, the geodesic's step returned Ok with the state unchanged
    let geodesic = Geodesic::new();
    let first = SphereState::<1, 4>::from_ambient(&geodesic, &[Vector3::x(), Vector3::y()])
        .expect("on the sphere");
    for y in [[1e200, 0.0], [1e200, 1e200], [0.0, -1e160]] {
        let mut far = first;
        far.z = SVector::from([y[0], y[1], 0.0, 0.0]);
        let result = sphere::step(&geodesic, &ProjectionMidpoint, &far, 0.1, &options);
        assert!(
            matches!(result, Err(Error::InvalidArgument { name: "state", .. })),
            "{y:?}: {result:?}"
        );
    }
    for y in [1e200, -1e200, 1e160, f64::MAX] {
        let mut far = s;
        far.z[0] = y;
        assert!(far.point().norm() < 0.5, "{y:e}: {}", far.point());
        let error = step(&far).expect_err("a point off the sphere");
        assert!(
            matches!(error, Error::InvalidArgument { name: "state", .. }),
            "{y:e}: {error:?}"
        );
        assert!(error.to_string().contains("unit sphere"), "{error}");
    }
    for bad in [f64::NAN, f64::INFINITY] {
        for index in [1, 5] {
            let mut broken = s;
            broken.z[index] = bad;
            let error = step(&broken).expect_err("a non-finite state");
            assert!(
                matches!(
                    error,
                    Error::NonFinite { .. } | Error::InvalidArgument { .. }
                ),
                "{error:?}"
            );
        }
    }
    let mut skewed = s;
    skewed.chart.centre *= 2.0;
    let error = step(&skewed).expect_err("a frame that is not orthonormal");
    assert!(
        matches!(error, Error::InvalidArgument { name: "chart", .. }),
        "{error:?}"
    );
    // far but representable: a point near the chart's equator is still a point of the sphere
    let mut wide = s;
    wide.z[0] = 1e6;
    assert!((wide.point().norm() - 1.0).abs() < 1e-15);
}

/// The chart jet (y, y') of an ambient (q, q') as the optimizer's boundary data.
fn boundary(chart: &Chart, jet: &[Vector3<f64>; 2]) -> [f64; 4] {
    let [y, dy] = chart.coordinates(jet).expect("in the chart");
    [y[0], y[1], dy[0], dy[1]]
}

/// The cubic from 60 degrees west to 60 degrees east on the equator in T = 2, N = 80 steps,
/// in the chart centred between them, with the inequalities `caps`.
fn plan_on_equator(caps: &[&OutsideCap]) -> (Chart, Plan<2, 4>) {
    let chart = Chart::at(&Vector3::x()).unwrap();
    let system = Cubic::new().with_chart(chart.params());
    let (a, b) = (on_equator(-60.0, 0.5), on_equator(60.0, 0.5));
    let (start, goal) = (boundary(&chart, &a), boundary(&chart, &b));
    let charted: Vec<OutsideCap> = caps.iter().map(|c| c.with_chart(chart.params())).collect();
    let mut problem = OptimalControlProblem::new(&system, &start, &goal, 2.0, 80)
        .with_options(PlanOptions::default().with_min_eigenvalue(true));
    for c in &charted {
        problem = problem.with_inequality(c);
    }
    let plan = problem
        .solve(PlanGuess::Spline)
        .expect("a certified minimum");
    assert_eq!(plan.certificate.negative_directions, 0);
    assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
    (chart, plan)
}

#[test]
fn a_spline_between_points_of_the_equator_stays_on_it() {
    // the equator is a geodesic and the data are symmetric under z -> -z: so is the optimum
    let (chart, plan) = plan_on_equator(&[]);
    let off = plan
        .x
        .iter()
        .map(|x| chart.point(&Vector2::new(x[0], x[1]))[2].abs())
        .fold(0.0, f64::max);
    assert!(off < 1e-9, "{off:e}");
}

#[test]
fn a_spline_around_a_keep_out_cap_goes_around_it() {
    // a cap of radius 20 degrees around the point 5 degrees north of (1, 0, 0)
    let axis = Vector3::new(1.0, 0.0, 5f64.to_radians().tan()).normalize();
    let cap = OutsideCap::new(axis.into(), 20f64.to_radians().cos());
    let (chart, plan) = plan_on_equator(&[&cap]);
    let (free_chart, free) = plan_on_equator(&[]);
    // the constraint holds at the evaluation points (the midpoints in the chart); between
    // them, at the nodes, the path may cut the cap's edge by O(h^2)
    let point = |c: &Chart, x: &SVector<f64, 4>| c.point(&Vector2::new(x[0], x[1]));
    let inside = |x: &SVector<f64, 4>| point(&chart, x).dot(&axis) - 20f64.to_radians().cos();
    let at_midpoints = plan
        .x
        .windows(2)
        .map(|w| inside(&((w[0] + w[1]) / 2.0)))
        .fold(f64::NEG_INFINITY, f64::max);
    let at_nodes = plan.x.iter().map(inside).fold(f64::NEG_INFINITY, f64::max);
    assert!(at_midpoints <= 1e-9, "inside the cap by {at_midpoints:e}");
    assert!(at_nodes <= 1e-3, "inside the cap by {at_nodes:e} at a node");
    // the cap sits north of the equator, so the path passes south of it, and costs more
    let south = plan
        .x
        .iter()
        .map(|x| point(&chart, x)[2])
        .fold(0.0, f64::min);
    assert!(south < -0.1, "{south}");
    assert!(plan.cost > free.cost, "{} against {}", plan.cost, free.cost);
    assert_eq!(free_chart, chart);
}

/// A geodesic flow with a weak barrier around the cap q_0 > 0.9 (about 26 degrees around x).
#[higher_order_lagrangian(order = 1, sphere)]
fn with_cap(q: [f64; 3], dq: [f64; 3], tau: f64) -> f64 {
    0.5 * (dq[0].powi(2) + dq[1].powi(2) + dq[2].powi(2)) - tau / (0.9 - q[0])
}

#[test]
fn a_step_into_a_barrier_on_the_sphere_is_a_domain_error() {
    // along the equator from 60 degrees west towards x: the barrier is too weak to turn the
    // path, so a step crosses the cap's edge and the guard reports it
    let system = WithCap::new(1e-9);
    let [q, v] = on_equator(-60.0, 1.0);
    let mut s = SphereState::<1, 4>::from_ambient(&system, &[q, v]).expect("on the sphere");
    let options = NewtonOptions::default();
    let mut stopped = None;
    for i in 0..40 {
        match sphere::step(&system, &ProjectionMidpoint, &s, 0.1, &options) {
            Ok((next, _)) => s = next,
            Err(e) => {
                stopped = Some((i, e));
                break;
            }
        }
    }
    let (i, error) = stopped.expect("the path reaches the cap");
    let Error::Domain(violation) = error else {
        panic!("expected a domain error, got {error}");
    };
    assert_eq!(violation.expression, "0.9 - q[0]");
    // the edge is at longitude -25.8 degrees, 34.2 degrees = 0.597 from the start
    assert!((5..=6).contains(&i), "stopped at step {i}");
    assert!(s.point()[0] < 0.9, "the last state is outside the cap");
}
