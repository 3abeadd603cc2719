//! SO(3) with moving charts (`retract::so3::{recentre, transition, ...}`): the chart
//! transition is the left translation, moves jets along their curves and momenta
//! symplectically, and commutes with the Cayley midpoint step; with a recentring after every
//! step the free rigid body turns through many half-turns with its rotation orthogonal and its
//! spatial momentum conserved to rounding, converging with order 2; the minimum-torque body
//! (k = 2, L = 1/2 |J Omega' + Omega x J Omega|^2) conserves its spatial momentum the same way.

use retract::diagnostics::canonical_structure;
use retract::map::{self, DiscretizationMap, TaylorLift};
use retract::nalgebra::{Matrix3, SMatrix, SVector, UnitQuaternion, Vector3};
use retract::so3::{
    CayleyMidpoint, CayleyMidpoint1, CayleyMidpoint2, chart_point, chart_quaternion, orientation,
    recentre, transition, translate, world_momentum,
};
use retract::taylor::Taylor;
use retract::{LiftedSystem, NewtonOptions};

/// The free rigid body with inertia `J` in a Gibbs chart (as in the one-chart tests).
fn body() -> super::so3::attitude::GibbsFree {
    super::so3::system()
}

/// A pseudo-random vector of entries in (-scale, scale).
fn random(seed: u64, scale: f64) -> Vector3<f64> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    Vector3::from_fn(|_, _| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
    })
}

/// The state of order `K` with jet blocks `jet` and momenta `momenta`.
fn state<const K: usize, const S: usize>(
    jet: [Vector3<f64>; K],
    momenta: [Vector3<f64>; K],
) -> SVector<f64, S> {
    retract::lifted::join::<3, K, S>(&jet, &momenta)
}

#[test]
fn the_transition_is_the_left_translation() {
    // (seeds from 20 on: points and centres far apart, some with 1 + a . y < 0, where only
    // the quaternion representative changes sign)
    for seed in 0..40 {
        let scale = if seed < 20 { 0.8 } else { 2.5 };
        let (a, y) = (random(seed, scale), random(seed + 100, scale));
        let moved = Vector3::from(translate(&a, [y[0], y[1], y[2]]));
        let expected = chart_quaternion(&a).inverse() * chart_quaternion(&y);
        let angle = chart_quaternion(&moved).angle_to(&expected);
        assert!(angle < 1e-14, "seed {seed}: {angle:e}");
        // and chart_point inverts the chart
        let centre = UnitQuaternion::from_scaled_axis(random(seed + 200, 2.0));
        let g = centre * chart_quaternion(&y);
        let back = chart_point(&centre, &g).expect("less than a half-turn");
        assert!((back - y).amax() < 1e-14);
    }
}

/// Omega and its derivatives along the curve of a jet (coefficients of the series).
fn body_velocity_series(jet: &[Vector3<f64>; 3]) -> [[f64; 3]; 3] {
    let y: [Taylor<f64, 3>; 3] =
        core::array::from_fn(|c| Taylor::from_derivatives(core::array::from_fn(|j| jet[j][c])));
    let dy: [Taylor<f64, 3>; 3] = core::array::from_fn(|c| {
        // the derivative of the series: coefficients (j + 1) c_{j+1}
        Taylor {
            c: core::array::from_fn(|j| {
                if j < 2 {
                    (j + 1) as f64 * y[c].c[j + 1]
                } else {
                    0.0
                }
            }),
        }
    });
    let norm = y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + 1.0;
    let cross = [
        y[1] * dy[2] - y[2] * dy[1],
        y[2] * dy[0] - y[0] * dy[2],
        y[0] * dy[1] - y[1] * dy[0],
    ];
    core::array::from_fn(|c| ((dy[c] - cross[c]) * 2.0 / norm).c)
}

#[test]
fn the_transition_moves_jets_along_their_curves() {
    // Omega(t) is chart-independent: its series (to the order the jet determines) agrees
    for seed in 0..10 {
        let a = random(seed, 0.6);
        let jet = [
            random(seed + 1, 0.6),
            random(seed + 2, 1.0),
            random(seed + 3, 1.0),
        ];
        let z = state::<3, 18>(jet, [Vector3::zeros(); 3]);
        let moved = transition::<3, 18>(&a, &z).expect("inside the chart");
        let (new_jet, _) = retract::lifted::split::<3, 3, 18>(&moved);
        let (before, after) = (body_velocity_series(&jet), body_velocity_series(&new_jet));
        // a jet of order 3 fixes Omega and Omega' (the series' first two coefficients)
        for c in 0..3 {
            for j in 0..2 {
                let gap = (before[c][j] - after[c][j]).abs();
                assert!(
                    gap < 1e-13,
                    "seed {seed}, component {c}, order {j}: {gap:e}"
                );
            }
        }
    }
}

/// The Jacobian of `f` at `z` by central differences.
pub(crate) fn jacobian<const S: usize>(
    f: impl Fn(&SVector<f64, S>) -> SVector<f64, S>,
    z: &SVector<f64, S>,
) -> SMatrix<f64, S, S> {
    let eps = 1e-6;
    let mut d = SMatrix::<f64, S, S>::zeros();
    for c in 0..S {
        let mut plus = *z;
        let mut minus = *z;
        plus[c] += eps;
        minus[c] -= eps;
        d.set_column(c, &((f(&plus) - f(&minus)) / (2.0 * eps)));
    }
    d
}

#[test]
fn the_transition_is_symplectic_and_inverted_by_the_opposite_one() {
    let a = random(7, 0.7);
    let z1 = state::<1, 6>([random(8, 0.5)], [random(9, 1.0)]);
    let z2 = state::<2, 12>(
        [random(10, 0.5), random(11, 1.0)],
        [random(12, 1.0), random(13, 1.0)],
    );
    let d1 = jacobian(|z| transition::<1, 6>(&a, z).expect("inside"), &z1);
    let d2 = jacobian(|z| transition::<2, 12>(&a, z).expect("inside"), &z2);
    let e1 = (d1.transpose() * canonical_structure::<6>() * d1 - canonical_structure::<6>()).amax();
    let e2 =
        (d2.transpose() * canonical_structure::<12>() * d2 - canonical_structure::<12>()).amax();
    assert!(e1 < 1e-8 && e2 < 1e-8, "|D^T J D - J| = {e1:e}, {e2:e}");
    // the centre c Q(a) moved by Q(-a) is c again: phi_{-a} inverts phi_a
    let back =
        transition::<2, 12>(&-a, &transition::<2, 12>(&a, &z2).expect("inside")).expect("inside");
    assert!((back - z2).amax() < 1e-13);
    // the same at k = 3 with momenta
    let z3 = state::<3, 18>(
        [random(14, 0.5), random(15, 1.0), random(16, 1.0)],
        [random(17, 1.0), random(18, 1.0), random(19, 1.0)],
    );
    let back =
        transition::<3, 18>(&-a, &transition::<3, 18>(&a, &z3).expect("inside")).expect("inside");
    assert!((back - z3).amax() < 1e-12);
    // with 1 + a . y < 0 the point still has a chart there: a = (2, 0, 0) and y = (-2, 0, 0)
    // are turns by 126.87 and -126.87 deg about x, 253.74 deg apart: 106.26 = 2 atan(4/3) deg
    let far = transition::<1, 6>(
        &Vector3::new(2.0, 0.0, 0.0),
        &state::<1, 6>([Vector3::new(-2.0, 0.0, 0.0)], [Vector3::zeros()]),
    )
    .expect("not a half-turn");
    assert!((far.fixed_rows::<3>(0) - Vector3::new(4.0 / 3.0, 0.0, 0.0)).amax() < 1e-15);
    // a rotation a half-turn from the new centre has no chart there
    assert!(
        transition::<1, 6>(
            &a,
            &state::<1, 6>([-a / a.norm_squared()], [Vector3::zeros()])
        )
        .is_err()
    );
}

/// The free body's state at the identity with body velocity `omega`.
fn free_start(omega: Vector3<f64>) -> SVector<f64, 6> {
    body().legendre(&state::<1, 6>([Vector3::zeros()], [omega / 2.0]))
}

/// `steps` steps of size `h` of the generated map from the identity with body velocity
/// `omega`, recentring after each; `observe` sees the centre and state after every step. Returns the last state.
fn run_moving_with(
    h: f64,
    steps: usize,
    omega: Vector3<f64>,
    mut observe: impl FnMut(&UnitQuaternion<f64>, &SVector<f64, 6>),
) -> SVector<f64, 6> {
    let (system, map, options) = (body(), CayleyMidpoint1, NewtonOptions::default());
    let (mut centre, mut z) = (UnitQuaternion::identity(), free_start(omega));
    observe(&centre, &z);
    for _ in 0..steps {
        z = map::step(&system, &map, &z, h, &options)
            .expect("regular")
            .0;
        recentre::<1, 6>(&mut centre, &mut z).expect("finite");
        observe(&centre, &z);
    }
    z
}

/// [`run_moving_with`] keeping the orientations and world momenta.
fn run_moving(
    h: f64,
    steps: usize,
    omega: Vector3<f64>,
) -> (Vec<UnitQuaternion<f64>>, Vec<Vector3<f64>>) {
    let (mut rotations, mut momenta) = (Vec::new(), Vec::new());
    run_moving_with(h, steps, omega, |centre, z| {
        rotations.push(orientation::<1, 6>(centre, z));
        momenta.push(world_momentum::<1, 6>(centre, z));
    });
    (rotations, momenta)
}

#[test]
fn recentred_steps_are_the_steps_of_one_chart() {
    let omega = Vector3::new(0.4, 0.9, -0.3);
    let (system, map, options) = (body(), TaylorLift(CayleyMidpoint), NewtonOptions::default());
    let mut z = free_start(omega);
    let (moving, momenta) = run_moving(0.05, 40, omega);
    for (i, rotation) in moving.iter().enumerate().skip(1) {
        z = map::step(&system, &map, &z, 0.05, &options)
            .expect("regular")
            .0;
        let fixed = orientation::<1, 6>(&UnitQuaternion::identity(), &z);
        assert!(fixed.angle_to(rotation) < 1e-12, "step {i}");
        // and the chart's momentum formula at the identity is the world momentum
        assert!(
            (world_momentum::<1, 6>(&UnitQuaternion::identity(), &z) - momenta[i]).amax() < 1e-12
        );
    }
}

#[test]
fn moving_charts_have_order_2_through_several_turns() {
    // |Omega| about 3.2 rad/s for 4 s: two turns, beyond any one chart
    let omega = Vector3::new(1.0, 3.0, -0.5);
    let t = 4.0;
    let exact = super::so3::attitude::euler_reference(omega, t, 40_000);
    let errors = [200, 400, 800].map(|n| run_moving(t / n as f64, n, omega).0[n].angle_to(&exact));
    for pair in errors.windows(2) {
        let observed = (pair[0] / pair[1]).log2();
        assert!(
            (observed - 2.0).abs() < 0.1,
            "order {observed} ({errors:?})"
        );
    }
}

#[test]
fn many_turns_keep_the_rotation_orthogonal_and_the_momentum() {
    // 10^6 steps of 0.01 s at about 3 rad/s: some 5000 turns
    let omega = Vector3::new(1.0, 3.0, -0.5);
    let m0 = world_momentum::<1, 6>(&UnitQuaternion::identity(), &free_start(omega));
    let (mut drift, mut orthogonality): (f64, f64) = (0.0, 0.0);
    let z = run_moving_with(0.01, 1_000_000, omega, |centre, z| {
        drift = drift.max((world_momentum::<1, 6>(centre, z) - m0).amax() / m0.amax());
        let r = orientation::<1, 6>(centre, z)
            .to_rotation_matrix()
            .into_inner();
        orthogonality = orthogonality.max((r.transpose() * r - Matrix3::identity()).amax());
    });
    assert!(orthogonality <= 1e-13, "|R^T R - I| = {orthogonality:e}");
    assert!(drift < 1e-10, "momentum drift {drift:e}");
    // the energy of a symplectic step: bounded, no drift
    let system = body();
    let energy = |z: &SVector<f64, 6>| system.hamiltonian(z).expect("finite");
    let e0 = energy(&free_start(omega));
    let gap = (energy(&z) - e0).abs() / e0;
    assert!(gap < 1e-3, "energy error {gap:e}");
}

#[test]
fn the_minimum_torque_body_recentres_exactly_and_conserves_its_momentum() {
    let system = super::so3::attitude::gibbs_body();
    let (map, options) = (TaylorLift(CayleyMidpoint), NewtonOptions::default());
    // at the identity with Omega = (1, 3, -0.5) and Omega' = (0.3, -0.2, 0.4)
    let jet = [
        Vector3::zeros(),
        Vector3::new(1.0, 3.0, -0.5) / 2.0,
        Vector3::new(0.3, -0.2, 0.4) / 2.0,
    ];
    let (mut centre, mut z) = (
        UnitQuaternion::identity(),
        system.legendre(&state::<2, 12>(
            [jet[0], jet[1]],
            [jet[2], Vector3::zeros()],
        )),
    );
    let m0 = world_momentum::<2, 12>(&centre, &z);
    let mut drift: f64 = 0.0;
    let mut turned = 0.0;
    // the same steps in the fixed chart at the identity, while it holds (about a radian)
    let mut fixed = z;
    // (its extremals spin up: by t = 1.5 the body turns at some 30 rad/s)
    for i in 0..300 {
        let before = orientation::<2, 12>(&centre, &z);
        z = map::step(&system, &map, &z, 0.005, &options)
            .expect("regular")
            .0;
        recentre::<2, 12>(&mut centre, &mut z).expect("finite");
        let after = orientation::<2, 12>(&centre, &z);
        if i < 60 {
            fixed = map::step(&system, &map, &fixed, 0.005, &options)
                .expect("regular")
                .0;
            let gap = orientation::<2, 12>(&UnitQuaternion::identity(), &fixed).angle_to(&after);
            assert!(gap < 1e-11, "step {i}: {gap:e}");
        }
        turned += before.angle_to(&after);
        drift = drift.max((world_momentum::<2, 12>(&centre, &z) - m0).amax() / m0.amax());
    }
    assert!(turned > 2.0 * std::f64::consts::PI, "turned {turned}");
    assert!(drift < 1e-12, "momentum drift {drift:e}");
    let d = map::step_map_derivative(&system, &map, &z, 0.005, &options).expect("regular");
    let j = canonical_structure::<12>();
    let error = (d.transpose() * j * d - j).amax();
    assert!(error < 1e-10, "|D^T J D - J| = {error:e}");
}

#[test]
fn compositions_of_recentred_steps_have_orders_4_6_and_8() {
    let omega = Vector3::new(1.0, 3.0, -0.5);
    let t = 4.0;
    let exact = super::so3::attitude::euler_reference(omega, t, 40_000);
    let (system, map, options) = (body(), TaylorLift(CayleyMidpoint), NewtonOptions::default());
    for (order, sizes) in [(4, [40, 80, 160]), (6, [30, 60, 120]), (8, [30, 60, 120])] {
        let errors = sizes.map(|n| {
            let (mut centre, mut z) = (UnitQuaternion::identity(), free_start(omega));
            // the stage: a step and a recentring (the centre moves with each stage)
            let mut stage = |z: &SVector<f64, 6>, h: f64| {
                let (mut next, report) = map::step(&system, &map, z, h, &options)?;
                recentre::<1, 6>(&mut centre, &mut next)?;
                Ok((next, report))
            };
            for _ in 0..n {
                z = retract::compose::compose(&mut stage, &z, t / n as f64, order)
                    .expect("regular")
                    .0;
            }
            orientation::<1, 6>(&centre, &z).angle_to(&exact)
        });
        for pair in errors.windows(2) {
            let observed = (pair[0] / pair[1]).log2();
            assert!(
                (observed - f64::from(order)).abs() < 0.3,
                "order {order}: observed {observed} ({errors:?})"
            );
        }
    }
}

/// The largest entry of a block matrix's difference.
fn block_gap<const K: usize>(a: &map::BlockMatrix<3, K>, b: &map::BlockMatrix<3, K>) -> f64 {
    let mut gap: f64 = 0.0;
    for (ra, rb) in a.iter().zip(b) {
        for (ma, mb) in ra.iter().zip(rb) {
            gap = gap.max((ma - mb).amax());
        }
    }
    gap
}

/// The generated map of order `K` against the run-time lift at random points: the points,
/// the four Jacobians and the covector Hessian agree to rounding.
pub(crate) fn generated_matches_the_lift<const K: usize>(
    generated: &impl DiscretizationMap<3, K>,
    lift: &impl DiscretizationMap<3, K>,
) {
    for seed in 0..10 {
        let blocks = |offset: u64, scale: f64| -> [Vector3<f64>; K] {
            core::array::from_fn(|j| random(seed * 40 + offset + j as u64, scale))
        };
        let (x, xi, w1, w2) = (
            blocks(0, 0.7),
            blocks(10, 0.5),
            blocks(20, 1.0),
            blocks(30, 1.0),
        );
        let (a1, a2) = generated.points(&x, &xi);
        let (b1, b2) = lift.points(&x, &xi);
        for j in 0..K {
            assert!((a1[j] - b1[j]).amax() < 1e-12 && (a2[j] - b2[j]).amax() < 1e-12);
        }
        let (ja, jb) = (generated.jacobians(&x, &xi), lift.jacobians(&x, &xi));
        let jacobians = [
            block_gap(&ja.r1_x, &jb.r1_x),
            block_gap(&ja.r1_xi, &jb.r1_xi),
            block_gap(&ja.r2_x, &jb.r2_x),
            block_gap(&ja.r2_xi, &jb.r2_xi),
        ];
        assert!(jacobians.iter().all(|g| *g < 1e-11), "{jacobians:?}");
        let (ha, hb) = (
            generated.covector_hessian(&x, &xi, &w1, &w2),
            lift.covector_hessian(&x, &xi, &w1, &w2),
        );
        let hessian = [
            block_gap(&ha.xx, &hb.xx),
            block_gap(&ha.x_xi, &hb.x_xi),
            block_gap(&ha.xi_xi, &hb.xi_xi),
        ];
        assert!(hessian.iter().all(|g| *g < 1e-10), "{hessian:?}");
    }
}

#[test]
fn the_generated_cayley_maps_are_the_run_time_lift() {
    generated_matches_the_lift::<1>(&CayleyMidpoint1, &TaylorLift(CayleyMidpoint));
    generated_matches_the_lift::<2>(&CayleyMidpoint2, &TaylorLift(CayleyMidpoint));
}
