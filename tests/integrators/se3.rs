//! Lagrangians written on SE(3) in body coordinates (`#[higher_order_lagrangian(order = k,
//! se3)]`) and moving product charts (`retract::se3`): the macro's chart composition is the
//! pose (C Q(y), c + C x) and its body velocity (by differences of a curve); the body form of
//! the flight's effort equals the hand-composed chart form in every chart; the change of
//! chart is the left translation; the free rigid body stepped by the left-invariant map in
//! moving charts stays on the group, conserves its spatial momentum and converges with order
//! 2, and its compositions with orders 4, 6 and 8; and a pose-dependent Lagrangian steps the same in moving charts as in one chart.

use retract::diagnostics::canonical_structure;
use retract::map;
use retract::nalgebra::{Isometry3, Matrix3, SVector, Translation3, UnitQuaternion, Vector3};
use retract::se3::{
    Se3ExpMidpoint1, Se3ExpMidpoint2, Se3Midpoint1, Se3Midpoint2, Se3System, centre_pose, centred,
    chart_point, pose, recentre_system, spatial_momentum, transition,
};
use retract::so3::{chart_quaternion, rotation};
use retract::{
    JetFunction, Lagrangian, LiftedSystem, NewtonOptions, higher_order_lagrangian, jet_function,
};

use super::so3::attitude;
use super::so3_body::{random, unskew};
use super::so3_moving::jacobian;

/// A linear probe of the arguments: sum a_e g_e + b . xi + c . xi'.
#[jet_function(order = 2, se3)]
fn probe(g: [f64; 12], xi: [f64; 6], dxi: [f64; 6], a: [f64; 12], b: [f64; 6], c: [f64; 6]) -> f64 {
    let mut acc = 0.0;
    for e in 0..12 {
        acc += a[e] * g[e];
    }
    for i in 0..6 {
        acc += b[i] * xi[i] + c[i] * dxi[i];
    }
    acc
}

/// A heavy top on a spring: the free body with the potential k/2 |p|^2 + mgl (R e_z) . e_z,
/// invariant under rotations about the world z axis through the origin.
#[higher_order_lagrangian(order = 1, se3)]
fn sprung_top(g: [f64; 12], xi: [f64; 6], j1: f64, j2: f64, j3: f64, k: f64, mgl: f64) -> f64 {
    0.5 * (j1 * xi[0] * xi[0] + j2 * xi[1] * xi[1] + j3 * xi[2] * xi[2])
        + 0.5 * (xi[3] * xi[3] + xi[4] * xi[4] + xi[5] * xi[5])
        - 0.5 * k * (g[9] * g[9] + g[10] * g[10] + g[11] * g[11])
        - mgl * g[8]
}

/// A pseudo-random pose.
fn random_pose(seed: u64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(random(seed, 3.0)),
        UnitQuaternion::from_scaled_axis(random(seed + 1, 2.5)),
    )
}

/// The vector of 6 with rotation part `y` and position part `x`.
fn six(y: &Vector3<f64>, x: &Vector3<f64>) -> SVector<f64, 6> {
    SVector::<f64, 6>::from_iterator(y.iter().chain(x.iter()).copied())
}

#[test]
fn the_chart_composition_is_the_pose_and_its_body_velocity() {
    for seed in 0..10 {
        let centre = random_pose(seed);
        let c = centre.rotation.to_rotation_matrix().into_inner();
        let jet: [SVector<f64, 6>; 3] = core::array::from_fn(|j| {
            let s = [0.6, 1.0, 1.0][j];
            six(
                &random(seed + 10 * j as u64 + 10, s),
                &random(seed + 10 * j as u64 + 15, 2.0 * s),
            )
        });
        let chart = |t: f64| jet[0] + jet[1] * t + jet[2] * (t * t);
        let r = |t: f64| c * rotation(&chart(t).fixed_rows::<3>(0).into_owned());
        let p = |t: f64| centre.translation.vector + c * chart(t).fixed_rows::<3>(3).into_owned();
        // xi = (Omega, v) from R^T R' and R^T p', and xi' from differences of xi (step e)
        let e = 1e-4;
        let xi = |t: f64| {
            let omega = unskew(&(r(t).transpose() * (r(t + e) - r(t - e)) / (2.0 * e)));
            let v = r(t).transpose() * (p(t + e) - p(t - e)) / (2.0 * e);
            six(&omega, &v)
        };
        let (xi0, dxi0) = (xi(0.0), (xi(e) - xi(-e)) / (2.0 * e));
        let a: [f64; 12] = core::array::from_fn(|i| random(seed + 40 + i as u64 / 3, 1.0)[i % 3]);
        let (b, d) = (
            six(&random(seed + 60, 1.0), &random(seed + 61, 1.0)),
            six(&random(seed + 62, 1.0), &random(seed + 63, 1.0)),
        );
        let probe = centred(&Probe::new(a, b.into(), d.into()), &centre);
        let (r0, p0) = (r(0.0), p(0.0));
        let expected = (0..9).map(|i| a[i] * r0[(i / 3, i % 3)]).sum::<f64>()
            + (0..3).map(|i| a[9 + i] * p0[i]).sum::<f64>()
            + b.dot(&xi0)
            + d.dot(&dxi0);
        let value = probe.value(&[jet[0], jet[1]], &(2.0 * jet[2]));
        // (nested central differences: about 1e-7)
        assert!(
            (value - expected).abs() < 1e-6,
            "seed {seed}: {value} vs {expected}"
        );
    }
}

#[test]
fn the_body_flight_equals_the_hand_composed_chart_form_in_every_chart() {
    let hand = attitude::se3_body();
    let spheres = attitude::SPHERES;
    for seed in 0..20 {
        let centre = random_pose(seed);
        let body = centred(&attitude::flight_body(), &centre);
        let x = [
            six(&random(seed + 1, 0.8), &random(seed + 2, 2.0)),
            six(&random(seed + 3, 1.0), &random(seed + 4, 1.0)),
        ];
        let u = six(&random(seed + 5, 1.0), &random(seed + 6, 1.0));
        // left-invariant: the same Lagrangian in every chart
        let (l, expected) = (body.lagrangian(&x, &u), hand.lagrangian(&x, &u));
        assert!(
            (l - expected).abs() <= 1e-13 * expected.abs().max(1.0),
            "seed {seed}"
        );
        let (g, expected) = (
            Lagrangian::gradient(&body, &x, &u),
            Lagrangian::gradient(&hand, &x, &u),
        );
        for (a, b) in
            g.x.iter()
                .chain([&g.u])
                .zip(expected.x.iter().chain([&expected.u]))
        {
            assert!((a - b).amax() <= 1e-12 * b.amax().max(1.0), "seed {seed}");
        }
        // the sphere's clearance at the pose's position, c + C x
        let (centre_of, radius) = spheres[seed as usize % spheres.len()];
        let sphere = centred(&attitude::ClearOfSphere::new(centre_of, radius), &centre);
        let mut z = SVector::<f64, 12>::zeros();
        z.fixed_rows_mut::<6>(0).copy_from(&x[0]);
        let position = pose::<1, 12>(&centre, &z).translation.vector;
        let expected = (position - Vector3::from(centre_of)).norm_squared() - radius * radius;
        assert!((sphere.value(&x, &u) - expected).abs() < 1e-12 * expected.abs().max(1.0));
    }
    // at the identity the body form's chart is the hand form's
    let identity = Isometry3::identity();
    assert_eq!(centre_pose(&identity), attitude::flight_body().centre());
}

#[test]
fn the_change_of_chart_is_the_left_translation() {
    for seed in 0..20 {
        let (centre, a, b) = (
            random_pose(seed),
            random(seed + 1, 0.7),
            random(seed + 2, 2.0),
        );
        let z = SVector::<f64, 24>::from_fn(|i, _| random(seed + 3 + i as u64 / 3, 1.0)[i % 3]);
        let moved = transition::<2, 24>(&a, &b, &z).expect("finite");
        let new_centre =
            centre * Isometry3::from_parts(Translation3::from(b), chart_quaternion(&a));
        // the same pose in both charts
        let (g0, g1) = (
            pose::<2, 24>(&centre, &z),
            pose::<2, 24>(&new_centre, &moved),
        );
        assert!(g0.rotation.angle_to(&g1.rotation) < 1e-13, "seed {seed}");
        assert!(
            (g0.translation.vector - g1.translation.vector).amax() < 1e-12,
            "seed {seed}"
        );
        // chart_point inverts pose
        let point = chart_point(&new_centre, &g0).expect("within the chart");
        assert!(
            (point - moved.fixed_rows::<6>(0)).amax() < 1e-12,
            "seed {seed}"
        );
        // a symplectic change of coordinates conserves the spatial momentum
        let (l0, p0) = spatial_momentum::<2, 24>(&centre, &z);
        let (l1, p1) = spatial_momentum::<2, 24>(&new_centre, &moved);
        assert!((l0 - l1).amax() < 1e-11 * l0.amax().max(1.0), "seed {seed}");
        assert!((p0 - p1).amax() < 1e-12 * p0.amax().max(1.0), "seed {seed}");
    }
}

/// The order-1 state at a chart's centre with body velocity (omega, v): y' = omega / 2,
/// x' = v.
fn free_start(omega: &Vector3<f64>, v: &Vector3<f64>) -> SVector<f64, 12> {
    let mut jet = SVector::<f64, 12>::zeros();
    jet.fixed_rows_mut::<6>(6)
        .copy_from(&six(&(omega / 2.0), v));
    attitude::offset_body().legendre(&jet)
}

/// The free body from the pose `start` with body velocity (omega, v), `steps` steps to `t`
/// in moving charts, each a composition of order `order` of steps of the left-invariant `map`
/// with the chart recentred after every stage: the final pose, the largest |R^T R - I| and
/// the largest relative change of the spatial momentum (angular, linear).
fn free_flight(
    start: &Isometry3<f64>,
    (omega, v): (&Vector3<f64>, &Vector3<f64>),
    t: f64,
    steps: usize,
    (order, map): (u32, &impl map::DiscretizationMap<6, 1>),
) -> (Isometry3<f64>, f64, f64) {
    let (mut system, mut centre) = (centred(&attitude::offset_body(), start), *start);
    let mut z = free_start(omega, v);
    let (l0, p0) = spatial_momentum::<1, 12>(&centre, &z);
    let (mut orthogonality, mut drift): (f64, f64) = (0.0, 0.0);
    let options = NewtonOptions::default();
    for _ in 0..steps {
        let mut stage = |z: &SVector<f64, 12>, h: f64| {
            let (mut next, report) = map::step(&system, map, z, h, &options)?;
            recentre_system::<_, 1, 12>(&mut system, &mut centre, &mut next)?;
            Ok((next, report))
        };
        z = retract::compose::compose(&mut stage, &z, t / steps as f64, order)
            .expect("regular")
            .0;
        let r = centre.rotation.to_rotation_matrix().into_inner();
        orthogonality = orthogonality.max((r.transpose() * r - Matrix3::identity()).amax());
        let (l, p) = spatial_momentum::<1, 12>(&centre, &z);
        drift = drift.max(((l - l0).amax() / l0.amax()).max((p - p0).amax() / p0.amax()));
    }
    (pose::<1, 12>(&centre, &z), orthogonality, drift)
}

#[test]
fn the_free_body_stays_on_the_group_conserves_its_momentum_and_converges_with_orders_2_to_8() {
    let start = random_pose(7);
    let (omega, v) = (Vector3::new(0.1, 1.0, 0.05), Vector3::new(0.5, -0.2, 0.3));
    let t = 2.0;
    // exact: Euler's equations for the rotation (left-invariant: from the identity, then
    // translated); the centre of mass p + R r on a straight line at the world velocity
    // R0 (v + omega x r)
    let r = Vector3::from(attitude::OFFSET);
    let rotation = start.rotation * attitude::euler_reference(omega, t, 100_000);
    let mass_centre =
        start.translation.vector + start.rotation * r + start.rotation * (v + omega.cross(&r)) * t;
    let position = mass_centre - rotation * r;
    let cases = [
        ("Cayley", 2, [50, 100, 200]),
        ("Cayley", 4, [10, 20, 40]),
        ("Cayley", 6, [10, 20, 40]),
        ("Cayley", 8, [5, 10, 20]),
        ("exp", 2, [50, 100, 200]),
        ("exp", 4, [10, 20, 40]),
    ];
    for (name, order, sizes) in cases {
        let errors = sizes.map(|steps| {
            let (g, _, _) = if name == "exp" {
                free_flight(&start, (&omega, &v), t, steps, (order, &Se3ExpMidpoint1))
            } else {
                free_flight(&start, (&omega, &v), t, steps, (order, &Se3Midpoint1))
            };
            g.rotation.angle_to(&rotation) + (g.translation.vector - position).norm()
        });
        println!(
            "free body, {name}, order {order}, steps {sizes:?}: errors {:.3e}, {:.3e}, {:.3e}",
            errors[0], errors[1], errors[2]
        );
        for w in errors.windows(2) {
            let observed = (w[0] / w[1]).log2();
            assert!(
                (observed - f64::from(order)).abs() < 0.3,
                "{name}, order {order}: observed {observed} from {errors:?}"
            );
        }
    }
    for (name, run) in [
        (
            "Cayley",
            free_flight(&start, (&omega, &v), 100.0, 20_000, (2, &Se3Midpoint1)),
        ),
        (
            "exp",
            free_flight(&start, (&omega, &v), 100.0, 20_000, (2, &Se3ExpMidpoint1)),
        ),
    ] {
        let (_, orthogonality, drift) = run;
        println!(
            "{name}, 20000 steps: |R^T R - I| <= {orthogonality:.1e}, momentum drift {drift:.1e}"
        );
        assert!(
            orthogonality <= 1e-13,
            "{name}: |R^T R - I| = {orthogonality:e}"
        );
        assert!(drift < 1e-11, "{name}: spatial momentum drift {drift:e}");
    }
}

#[test]
fn a_sprung_top_steps_the_same_in_moving_charts_and_keeps_its_vertical_momentum() {
    let (h, options) = (0.01, NewtonOptions::default());
    let tilt = Isometry3::from_parts(
        Translation3::new(0.5, -0.3, 0.2),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.6, 0.2, 0.0)),
    );
    let top = SprungTop::new(1.0, 2.0, 0.5, 3.0, 2.0);
    let (mut system, mut centre) = (centred(&top, &tilt), tilt);
    let fixed_system = system;
    let mut jet = SVector::<f64, 12>::zeros();
    jet.fixed_rows_mut::<6>(6).copy_from(&six(
        &Vector3::new(0.5, -1.0, 4.0),
        &Vector3::new(0.3, 0.8, -0.4),
    ));
    let mut z = system.legendre(&jet);
    let mut fixed = z;
    let (l0, _) = spatial_momentum::<1, 12>(&centre, &z);
    let mut drift: f64 = 0.0;
    let mut turned: f64 = 0.0;
    for i in 0..2000 {
        z = map::step(&system, &Se3Midpoint1, &z, h, &options)
            .expect("regular")
            .0;
        recentre_system::<_, 1, 12>(&mut system, &mut centre, &mut z).expect("finite");
        if i < 40 {
            // (within a turn by less than pi of the tilt: one chart reaches)
            fixed = map::step(&fixed_system, &Se3Midpoint1, &fixed, h, &options)
                .expect("regular")
                .0;
            let (a, b) = (pose::<1, 12>(&centre, &z), pose::<1, 12>(&tilt, &fixed));
            assert!(a.rotation.angle_to(&b.rotation) < 1e-12, "step {i}");
            assert!(
                (a.translation.vector - b.translation.vector).amax() < 1e-12,
                "step {i}"
            );
        }
        let (l, _) = spatial_momentum::<1, 12>(&centre, &z);
        drift = drift.max((l[2] - l0[2]).abs() / l0.amax());
        turned = turned.max((l - l0).amax() / l0.amax());
    }
    assert!(drift < 1e-12, "vertical momentum drift {drift:e}");
    // (the potential turns the horizontal momentum)
    assert!(turned > 0.1, "horizontal momentum change {turned}");
}

#[test]
fn the_order_2_flight_recentres_exactly_and_conserves_its_spatial_momentum() {
    let (h, options) = (0.01, NewtonOptions::default());
    let start = random_pose(3);
    let (mut system, mut centre) = (centred(&attitude::flight_body(), &start), start);
    let fixed_system = system;
    let x = [
        SVector::<f64, 6>::zeros(),
        six(&Vector3::new(0.2, 0.5, -0.3), &Vector3::new(1.0, 0.2, 0.1)),
    ];
    let u = six(&Vector3::new(0.1, -0.2, 0.3), &Vector3::new(-0.5, 0.3, 0.2));
    let jet = SVector::<f64, 24>::from_iterator(
        x[0].iter()
            .chain(x[1].iter())
            .chain(u.iter())
            .chain([0.0; 6].iter())
            .copied(),
    );
    let mut z = system.legendre(&jet);
    let mut fixed = z;
    let (l0, p0) = spatial_momentum::<2, 24>(&centre, &z);
    let mut drift: f64 = 0.0;
    for i in 0..300 {
        z = map::step(&system, &Se3Midpoint2, &z, h, &options)
            .expect("regular")
            .0;
        recentre_system::<_, 2, 24>(&mut system, &mut centre, &mut z).expect("finite");
        if i < 40 {
            fixed = map::step(&fixed_system, &Se3Midpoint2, &fixed, h, &options)
                .expect("regular")
                .0;
            let (a, b) = (pose::<2, 24>(&centre, &z), pose::<2, 24>(&start, &fixed));
            assert!(a.rotation.angle_to(&b.rotation) < 1e-12, "step {i}");
            assert!(
                (a.translation.vector - b.translation.vector).amax() < 1e-12,
                "step {i}"
            );
        }
        let (l, p) = spatial_momentum::<2, 24>(&centre, &z);
        drift = drift.max(((l - l0).amax() / l0.amax()).max((p - p0).amax() / p0.amax()));
    }
    assert!(drift < 1e-11, "spatial momentum drift {drift:e}");
}

/// |D^T J D - J| of the steps of `maps` (orders 1 and 2) for the offset free body and the
/// flight at random states, and the flight's state.
fn symplecticity(
    maps: (
        &impl map::DiscretizationMap<6, 1>,
        &impl map::DiscretizationMap<6, 2>,
    ),
) -> (f64, f64, SVector<f64, 24>) {
    let options = NewtonOptions::default();
    let system = centred(&attitude::offset_body(), &random_pose(4));
    let z1 = system.legendre(&SVector::<f64, 12>::from_fn(|i, _| {
        random(20 + i as u64 / 3, 0.8)[i % 3]
    }));
    let d = map::step_map_derivative(&system, maps.0, &z1, 0.1, &options).expect("regular");
    let j12 = canonical_structure::<12>();
    let e1 = (d.transpose() * j12 * d - j12).amax();
    let flight = centred(&attitude::flight_body(), &random_pose(5));
    let z2 = flight.legendre(&SVector::<f64, 24>::from_fn(|i, _| {
        random(30 + i as u64 / 3, 0.5)[i % 3]
    }));
    let d = map::step_map_derivative(&flight, maps.1, &z2, 0.05, &options).expect("regular");
    let j24 = canonical_structure::<24>();
    (e1, (d.transpose() * j24 * d - j24).amax(), z2)
}

#[test]
fn the_steps_and_the_change_of_chart_are_symplectic() {
    // the steps of the left-invariant maps, k = 1 (offset free body) and k = 2 (the flight)
    let (e1, e2, z2) = symplecticity((&Se3Midpoint1, &Se3Midpoint2));
    assert!(
        e1 < 1e-12 && e2 < 1e-11,
        "Cayley: |D^T J D - J| = {e1:e}, {e2:e}"
    );
    let (e1, e2, _) = symplecticity((&Se3ExpMidpoint1, &Se3ExpMidpoint2));
    assert!(
        e1 < 1e-12 && e2 < 1e-11,
        "exp: |D^T J D - J| = {e1:e}, {e2:e}"
    );
    let j24 = canonical_structure::<24>();
    // the change of chart (central differences), inverted by the opposite one
    let (a, b) = (random(40, 0.7), random(41, 2.0));
    let d = jacobian(|z| transition::<2, 24>(&a, &b, z).expect("inside"), &z2);
    let e = (d.transpose() * j24 * d - j24).amax();
    assert!(e < 1e-8, "transition: |D^T J D - J| = {e:e}");
    let moved = transition::<2, 24>(&a, &b, &z2).expect("inside");
    // (C, c)(Q(a), b) (Q(-a), -Q(a)^T b) = (C, c)
    let back_b = -(chart_quaternion(&a).inverse() * b);
    let back = transition::<2, 24>(&-a, &back_b, &moved).expect("inside");
    assert!((back - z2).amax() < 1e-12);
}
