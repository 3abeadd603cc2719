//! Order k = 3 on the sphere: the Riemannian polynomial L = 1/2 |D_t^2 q'|^2, stepped by the
//! maps of S^2 lifted at run time (`map::TaylorLift`). The lift equals the generated one at
//! orders 1 and 2. At order 3 the state stays on the sphere, the Noether momentum is
//! conserved, the energy error is O(h^2), the step is symplectic, and the midpoint maps
//! converge with order 2 (the initial-point map with order 1) to an RK4 solution of the
//! embedded Euler-Lagrange equation D_t^5 V + R(D_t^3 V, V) V - R(D_t^2 V, D_t V) V = 0.

use retract::diagnostics::canonical_structure;
use retract::lifted::Blocks;
use retract::map::{self, DiscretizationMap, TaylorLift};
use retract::nalgebra::{SVector, Vector3};
use retract::sphere::{
    self, Chart, ExponentialMidpoint, ProjectionInitial, ProjectionMidpoint, SphereMap,
    SphereState, SphereSystem, in_chart,
};
use retract::{Error, NewtonOptions};

use crate::common::assert_orders;

#[path = "../../examples/common/sphere_poly3.rs"]
mod sphere_poly3;
use sphere_poly3::{Poly3, data, jet, reference};

type State = SphereState<3, 12>;

fn start() -> State {
    SphereState::from_ambient(&Poly3::new(), &jet(data())).expect("a jet on the sphere")
}

/// `steps` steps of size `h` with `map`, from [`start`].
fn run<Map: SphereMap<3>>(map: &Map, h: f64, steps: usize) -> Result<Vec<State>, Error> {
    let options = NewtonOptions::default();
    let mut states = vec![start()];
    for _ in 0..steps {
        let last = states[states.len() - 1];
        states.push(sphere::step(&Poly3::new(), map, &last, h, &options)?.0);
    }
    Ok(states)
}

/// Blocks with entries of size about `scale`, different for each `seed`.
fn blocks<const K: usize>(seed: f64, scale: f64) -> Blocks<2, K> {
    core::array::from_fn(|j| {
        SVector::from_fn(|a, _| scale * (seed * (1.0 + j as f64) + 0.61 * a as f64).sin())
    })
}

/// The largest difference between two maps' points, Jacobians and covector Hessians at one
/// point of an off-centre chart.
fn gap<A, B, const K: usize>(a: &A, b: &B) -> f64
where
    A: DiscretizationMap<2, K>,
    B: DiscretizationMap<2, K>,
{
    let (x, xi) = (blocks::<K>(0.4, 0.5), blocks::<K>(1.3, 0.2));
    let (w1, w2) = (blocks::<K>(2.1, 1.0), blocks::<K>(-0.8, 1.0));
    let (pa, pb) = (a.points(&x, &xi), b.points(&x, &xi));
    let (ja, jb) = (a.jacobians(&x, &xi), b.jacobians(&x, &xi));
    let (ha, hb) = (
        a.covector_hessian(&x, &xi, &w1, &w2),
        b.covector_hessian(&x, &xi, &w1, &w2),
    );
    let mut worst = 0.0_f64;
    for i in 0..K {
        worst = worst.max((pa.0[i] - pb.0[i]).amax().max((pa.1[i] - pb.1[i]).amax()));
        for j in 0..K {
            for (ma, mb) in [
                (ja.r1_x[i][j], jb.r1_x[i][j]),
                (ja.r1_xi[i][j], jb.r1_xi[i][j]),
                (ja.r2_x[i][j], jb.r2_x[i][j]),
                (ja.r2_xi[i][j], jb.r2_xi[i][j]),
                (ha.xx[i][j], hb.xx[i][j]),
                (ha.x_xi[i][j], hb.x_xi[i][j]),
                (ha.xi_xi[i][j], hb.xi_xi[i][j]),
            ] {
                worst = worst.max((ma - mb).amax());
            }
        }
    }
    worst
}

#[test]
fn maps_lifted_at_run_time_equal_the_generated_ones() {
    let chart = Chart::at(&Vector3::new(0.3, -0.5, 0.8)).unwrap().params();
    let gaps = [
        gap::<_, _, 1>(
            &in_chart::k1::ProjectionInitial::new(chart),
            &TaylorLift(in_chart::any::ProjectionInitial { chart }),
        ),
        gap::<_, _, 2>(
            &in_chart::k2::ProjectionInitial::new(chart),
            &TaylorLift(in_chart::any::ProjectionInitial { chart }),
        ),
        gap::<_, _, 1>(
            &in_chart::k1::ProjectionMidpoint::new(chart),
            &TaylorLift(in_chart::any::ProjectionMidpoint { chart }),
        ),
        gap::<_, _, 2>(
            &in_chart::k2::ProjectionMidpoint::new(chart),
            &TaylorLift(in_chart::any::ProjectionMidpoint { chart }),
        ),
        gap::<_, _, 1>(
            &in_chart::k1::ExponentialMidpoint::new(chart),
            &TaylorLift(in_chart::any::ExponentialMidpoint { chart }),
        ),
        gap::<_, _, 2>(
            &in_chart::k2::ExponentialMidpoint::new(chart),
            &TaylorLift(in_chart::any::ExponentialMidpoint { chart }),
        ),
    ];
    for (i, g) in gaps.iter().enumerate() {
        assert!(*g < 1e-12, "map {i}: {g:e}");
    }
}

#[test]
fn the_jet_of_the_reference_data_is_on_the_sphere() {
    // q . q = 1 differentiated: q . q' = 0, q . q'' + |q'|^2 = 0, q . q''' + 3 q' . q'' = 0
    let [q, d1, d2, d3, ..] = jet(data());
    assert!((q.norm() - 1.0).abs() < 1e-15);
    assert!(q.dot(&d1).abs() < 1e-15);
    assert!((q.dot(&d2) + d1.dot(&d1)).abs() < 1e-14);
    assert!((q.dot(&d3) + 3.0 * d1.dot(&d2)).abs() < 1e-14);
}

/// The largest | |q| - 1 |, |q . q'|, relative momentum change and relative energy change
/// over `steps` steps of size `h` with the projection midpoint map.
fn invariants(h: f64, steps: usize) -> [f64; 4] {
    let states = run(&ProjectionMidpoint, h, steps).expect("regular steps");
    let m0 = states[0].momentum();
    let energy = |s: &State| s.hamiltonian(&Poly3::new()).expect("finite");
    let e0 = energy(&states[0]);
    let mut worst = [0.0_f64; 4];
    for s in &states {
        let [q, v, ..] = s.ambient_jet();
        worst[0] = worst[0].max((q.norm() - 1.0).abs());
        worst[1] = worst[1].max(q.dot(&v).abs());
        worst[2] = worst[2].max((s.momentum() - m0).amax() / m0.amax());
        worst[3] = worst[3].max((energy(s) - e0).abs() / e0.abs());
    }
    worst
}

#[test]
fn order_3_states_stay_on_the_sphere_and_conserve_the_momentum() {
    // to T = 2: 5000 steps, then 10000 of half the size
    let worst = invariants(4e-4, 5000);
    assert!(worst[0] < 1e-15, "| |q| - 1 | = {:e}", worst[0]);
    assert!(worst[1] < 1e-14, "q . q' = {:e}", worst[1]);
    assert!(worst[2] < 1e-11, "momentum drift {:e}", worst[2]);
    // the energy is not conserved exactly but its error is O(h^2), without drift
    let finer = invariants(2e-4, 10_000);
    let ratio = worst[3] / finer[3];
    assert!(
        (3.6..4.4).contains(&ratio),
        "energy errors {:e}, {:e}",
        worst[3],
        finer[3]
    );
    assert!(finer[2] < 1e-11, "momentum drift {:e}", finer[2]);
}

#[test]
fn the_order_3_step_is_symplectic_in_an_off_centre_chart() {
    let s0 = start();
    let other = Chart::at(&(s0.point() + Vector3::new(0.3, 0.2, -0.1))).unwrap();
    let z0 = s0.in_chart(&other).unwrap().z;
    let params = other.params();
    let system = Poly3::new().with_chart(params);
    let j = canonical_structure::<12>();
    let options = NewtonOptions::default();
    for (name, error) in [
        (
            "projection midpoint",
            sym(
                &system,
                &SphereMap::<3>::in_chart(&ProjectionMidpoint, params),
                &z0,
                &j,
                &options,
            ),
        ),
        (
            "exponential midpoint",
            sym(
                &system,
                &SphereMap::<3>::in_chart(&ExponentialMidpoint, params),
                &z0,
                &j,
                &options,
            ),
        ),
        (
            "projection initial point",
            sym(
                &system,
                &SphereMap::<3>::in_chart(&ProjectionInitial, params),
                &z0,
                &j,
                &options,
            ),
        ),
    ] {
        assert!(error < 1e-12, "{name}: |DPsi^T J DPsi - J| = {error:e}");
    }
}

/// |DPsi^T J DPsi - J| of a step of 0.1 with the map `m`.
fn sym<Map: DiscretizationMap<2, 3>>(
    system: &Poly3,
    m: &Map,
    z0: &SVector<f64, 12>,
    j: &retract::nalgebra::SMatrix<f64, 12, 12>,
    options: &NewtonOptions,
) -> f64 {
    let d = map::step_map_derivative(system, m, z0, 0.1, options).expect("regular");
    (d.transpose() * j * d - j).amax()
}

#[test]
fn order_3_midpoint_maps_have_order_2_and_the_initial_point_map_order_1() {
    let t = 0.5;
    let exact = reference(data(), t, 20_000)[0];
    // observed orders log2(e(h) / e(h/2)) of the final point over 40, 80, 160 steps
    let orders = |last: &dyn Fn(usize) -> State| -> Vec<f64> {
        let errors = [40, 80, 160].map(|n| (last(n).point() - exact).norm());
        errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
    };
    let end = |states: Vec<State>| states[states.len() - 1];
    let midpoint = orders(&|n| end(run(&ProjectionMidpoint, t / n as f64, n).unwrap()));
    let exponential = orders(&|n| end(run(&ExponentialMidpoint, t / n as f64, n).unwrap()));
    let initial = orders(&|n| end(run(&ProjectionInitial, t / n as f64, n).unwrap()));
    assert_orders(&midpoint, 1.85..2.15, "projection midpoint");
    assert_orders(&exponential, 1.85..2.15, "exponential midpoint");
    assert_orders(&initial, 0.85..1.15, "projection initial point");
}
