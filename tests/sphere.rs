//! Systems on the sphere S^2 (`#[higher_order_lagrangian(order = k, sphere)]`, `retract::sphere`):
//! the Riemannian cubic L = 1/2 |D_t q'|^2 written in ambient coordinates, stepped by the
//! paper's maps of S^2 in moving gnomonic charts. The state stays on the sphere, the step is
//! symplectic (in a fixed chart) and the same whichever chart computes it, the Noether
//! momentum of rotations is conserved to rounding and equals q x J - V x A, and the midpoint
//! maps converge with order 2 (the initial-point map with order 1) to an independent RK4
//! solution of the embedded Euler-Lagrange equation D_t^3 V + R(D_t V, V) V = 0.

use retract::diagnostics::canonical_structure;
use retract::higher_order_lagrangian;
use retract::map;
use retract::nalgebra::{SVector, Vector3};
use retract::sphere::{
    self, Chart, ExponentialMidpoint, ProjectionInitial, ProjectionMidpoint, SphereMap,
    SphereState, SphereSystem,
};
use retract::{Error, NewtonOptions};

#[higher_order_lagrangian(order = 2, sphere)]
fn cubic(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3]) -> f64 {
    // the covariant acceleration D_t q' = q'' - (q'' . q) q on the unit sphere
    let a = q[0] * ddq[0] + q[1] * ddq[1] + q[2] * ddq[2];
    0.5 * ((ddq[0] - a * q[0]).powi(2) + (ddq[1] - a * q[1]).powi(2) + (ddq[2] - a * q[2]).powi(2))
}

type State = SphereState<2, 8>;

/// The tangent data (q, V, A, J) of the test cubic: q a unit vector, V, A, J tangent at q.
fn data() -> [Vector3<f64>; 4] {
    let q = Vector3::new(0.3, -0.4, 0.8).normalize();
    let tangent = |v: Vector3<f64>| v - q * q.dot(&v);
    [
        q,
        tangent(Vector3::new(0.9, 0.5, -0.2)),
        tangent(Vector3::new(-0.4, 0.7, 0.6)),
        tangent(Vector3::new(0.2, -0.3, 0.5)),
    ]
}

/// The ambient jet (q, q', q'', q''') of the cubic through (q, V, A, J) (see `rhs`):
/// q'' = A - |V|^2 q and q''' = J - 3 (A . V) q - |V|^2 V.
fn jet([q, v, a, j]: [Vector3<f64>; 4]) -> [Vector3<f64>; 4] {
    let vv = v.dot(&v);
    [q, v, a - q * vv, j - q * (3.0 * a.dot(&v)) - v * vv]
}

/// The embedded Euler-Lagrange equation of the cubic on the unit sphere, for tangent fields
/// along q (D_t W = W' + (W . V) q, curvature R(X, Y) Z = (Y . Z) X - (X . Z) Y):
/// q' = V, V' = A - |V|^2 q, A' = J - (A . V) q, J' = D_t J - (J . V) q with
/// D_t J = -R(A, V) V = -(|V|^2 A - (A . V) V).
fn rhs([q, v, a, j]: [Vector3<f64>; 4]) -> [Vector3<f64>; 4] {
    let (vv, av) = (v.dot(&v), a.dot(&v));
    let dj = -(a * vv - v * av);
    [v, a - q * vv, j - q * av, dj - q * j.dot(&v)]
}

/// The reference solution at `t` by classical RK4 with `steps` steps.
fn reference(t: f64, steps: usize) -> [Vector3<f64>; 4] {
    let h = t / steps as f64;
    let mut y = data();
    let add = |y: &[Vector3<f64>; 4], k: &[Vector3<f64>; 4], c: f64| -> [Vector3<f64>; 4] {
        core::array::from_fn(|i| y[i] + k[i] * c)
    };
    for _ in 0..steps {
        let k1 = rhs(y);
        let k2 = rhs(add(&y, &k1, h / 2.0));
        let k3 = rhs(add(&y, &k2, h / 2.0));
        let k4 = rhs(add(&y, &k3, h));
        y = core::array::from_fn(|i| {
            y[i] + (k1[i] + k2[i] * 2.0 + k3[i] * 2.0 + k4[i]) * (h / 6.0)
        });
    }
    y
}

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
    let [q, v, a, j] = data();
    let m = q.cross(&j) - v.cross(&a);
    let mu = start().momentum();
    assert!((mu + m).amax() < 1e-12 * m.norm(), "{mu} against -{m}");
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
    let exact = reference(t, 20_000)[0];
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
