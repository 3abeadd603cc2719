//! Lagrangians written on SO(3) in body coordinates (`#[higher_order_lagrangian(order = k,
//! so3)]`): the macro's chart composition is the rotation C Q(y) and its body velocity (by
//! differences of a curve), the body form of the minimum-torque body and of the sun cone
//! equal the hand-composed chart forms, a heavy top (L depends on R) recentres with its
//! centre and conserves its vertical momentum, and Riemannian cubics (L = 1/2 |nabla_t
//! gamma'|^2 for a left-invariant metric) converge with order 2, and their compositions with
//! orders 4 and 6, to the Lie quadratic Omega''' = Omega'' x Omega (J = I), and conserve
//! their spatial momentum for any J.

use retract::map;
use retract::nalgebra::{Matrix3, Quaternion, SVector, UnitQuaternion, Vector3, Vector4};
use retract::so3::{
    CayleyMidpoint1, CayleyMidpoint2, So3System, body_state, centre_matrix, centred,
    chart_derivatives, chart_quaternion, orientation, recentre_system, rotation, world_momentum,
};
use retract::{
    JetFunction, Lagrangian, LiftedSystem, NewtonOptions, higher_order_lagrangian, jet_function,
};

use super::so3::attitude;

/// A linear probe of the arguments: sum a_e R_e + b . Omega + c . Omega'.
#[jet_function(order = 2, so3)]
fn probe(r: [f64; 9], w: [f64; 3], dw: [f64; 3], a: [f64; 9], b: [f64; 3], c: [f64; 3]) -> f64 {
    let mut acc = 0.0;
    for e in 0..9 {
        acc += a[e] * r[e];
    }
    for i in 0..3 {
        acc += b[i] * w[i] + c[i] * dw[i];
    }
    acc
}

/// The heavy top: L = 1/2 Omega . J Omega - m g l (R e_z) . e_z, its centre of mass on the
/// body's z axis.
#[higher_order_lagrangian(order = 1, so3)]
fn heavy_top(r: [f64; 9], w: [f64; 3], j1: f64, j2: f64, j3: f64, mgl: f64) -> f64 {
    0.5 * (j1 * w[0] * w[0] + j2 * w[1] * w[1] + j3 * w[2] * w[2]) - mgl * r[8]
}

/// Riemannian cubics for the left-invariant metric <a, b> = a . J b: L = 1/2 A . J A with
/// the covariant acceleration A = Omega' + J^-1 (Omega x J Omega).
#[higher_order_lagrangian(order = 2, so3)]
fn cubic(_r: [f64; 9], w: [f64; 3], dw: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    let a0 = dw[0] + (w[1] * j3 * w[2] - w[2] * j2 * w[1]) / j1;
    let a1 = dw[1] + (w[2] * j1 * w[0] - w[0] * j3 * w[2]) / j2;
    let a2 = dw[2] + (w[0] * j2 * w[1] - w[1] * j1 * w[0]) / j3;
    0.5 * (j1 * a0 * a0 + j2 * a1 * a1 + j3 * a2 * a2)
}

/// A pseudo-random vector of entries in (-scale, scale).
pub(crate) fn random(seed: u64, scale: f64) -> Vector3<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03;
    Vector3::from_fn(|_, _| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) * scale
    })
}

/// The unskew of a nearly skew matrix: w with [w]x = (M - M^T) / 2.
pub(crate) fn unskew(m: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) / 2.0
}

#[test]
fn the_chart_composition_is_the_rotation_and_its_body_velocity() {
    for seed in 0..10 {
        let centre = UnitQuaternion::from_scaled_axis(random(seed, 2.5));
        let (c0, c1, c2) = (
            random(seed + 10, 0.6),
            random(seed + 20, 1.0),
            random(seed + 30, 1.0),
        );
        let y = |t: f64| c0 + c1 * t + c2 * t * t;
        let r = |t: f64| centre.to_rotation_matrix().into_inner() * rotation(&y(t));
        // Omega from R^T R' and Omega' from differences of Omega (step e)
        let e = 1e-4;
        let omega = |t: f64| unskew(&(r(t).transpose() * (r(t + e) - r(t - e)) / (2.0 * e)));
        let (omega0, domega0) = (omega(0.0), (omega(e) - omega(-e)) / (2.0 * e));
        let (a, b) = (random(seed + 40, 1.0), random(seed + 50, 1.0));
        let weights: [f64; 9] =
            core::array::from_fn(|i| random(seed + 70 + i as u64 / 3, 1.0)[i % 3]);
        let g = centred(&Probe::new(weights, a.into(), b.into()), &centre);
        let r0 = r(0.0);
        let expected = (0..9).map(|i| weights[i] * r0[(i / 3, i % 3)]).sum::<f64>()
            + a.dot(&omega0)
            + b.dot(&domega0);
        let value = g.value(&[c0, c1], &(2.0 * c2));
        // (nested central differences: about 1e-7)
        assert!(
            (value - expected).abs() < 1e-6,
            "seed {seed}: {value} vs {expected}"
        );
    }
}

#[test]
fn the_body_form_equals_the_hand_composed_chart_form() {
    let hand = attitude::gibbs_body();
    let [j1, j2, j3] = attitude::INERTIA;
    let sun = attitude::sun();
    for seed in 0..20 {
        let centre = UnitQuaternion::from_scaled_axis(random(seed, 2.5));
        let body = centred(&attitude::BodyMinTorque::new(j1, j2, j3), &centre);
        let x = [random(seed + 1, 0.8), random(seed + 2, 1.0)];
        let u = random(seed + 3, 1.0);
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
        // the cone: the sun in world axes, against the chart form with the sun in the centre's
        let cos_cone = attitude::CONE_DEGREES.to_radians().cos();
        let world = centred(&attitude::SunClearance::new(sun.into(), cos_cone), &centre);
        let chart = attitude::gibbs_cone(&centre);
        let (v, expected) = (world.value(&x, &u), chart.value(&x, &u));
        assert!((v - expected).abs() < 1e-14, "seed {seed}");
        let (g, expected) = (
            JetFunction::gradient(&world, &x, &u),
            JetFunction::gradient(&chart, &x, &u),
        );
        for (a, b) in
            g.x.iter()
                .chain([&g.u])
                .zip(expected.x.iter().chain([&expected.u]))
        {
            assert!((a - b).amax() < 1e-13, "seed {seed}");
        }
    }
    assert_eq!(
        centre_matrix(&UnitQuaternion::identity()),
        attitude::BodyMinTorque::new(j1, j2, j3).centre()
    );
}

#[test]
fn a_heavy_top_recentres_with_its_centre_and_keeps_its_vertical_momentum() {
    let (h, options) = (0.01, NewtonOptions::default());
    let tilt = UnitQuaternion::from_scaled_axis(Vector3::new(0.6, 0.2, 0.0));
    let mut system = centred(&HeavyTop::new(1.0, 2.0, 0.5, 2.0), &tilt);
    let (fixed_system, mut centre) = (system, tilt);
    let mut z: SVector<f64, 6> =
        body_state::<_, 1, 6, 1>(&system, &[Vector3::new(0.3, -0.5, 4.0)]).expect("finite");
    let mut fixed = z;
    let (energy, vertical) = (
        system.hamiltonian(&z).expect("finite"),
        world_momentum::<1, 6>(&centre, &z)[2],
    );
    let (mut energy_error, mut vertical_drift): (f64, f64) = (0.0, 0.0);
    for i in 0..2000 {
        z = map::step(&system, &CayleyMidpoint1, &z, h, &options)
            .expect("regular")
            .0;
        recentre_system::<_, 1, 6>(&mut system, &mut centre, &mut z).expect("finite");
        if i < 40 {
            // (within a turn by less than pi of the tilt: one chart reaches)
            fixed = map::step(&fixed_system, &CayleyMidpoint1, &fixed, h, &options)
                .expect("regular")
                .0;
            let angle =
                orientation::<1, 6>(&centre, &z).angle_to(&orientation::<1, 6>(&tilt, &fixed));
            assert!(angle < 1e-12, "step {i}: {angle:e}");
        }
        energy_error = energy_error.max((system.hamiltonian(&z).expect("finite") - energy).abs());
        vertical_drift =
            vertical_drift.max((world_momentum::<1, 6>(&centre, &z)[2] - vertical).abs());
    }
    // gravity turns the momentum's horizontal part; the vertical part is a Noether momentum
    let turned =
        (world_momentum::<1, 6>(&centre, &z) - world_momentum::<1, 6>(&tilt, &fixed)).amax();
    assert!(turned > 0.1, "{turned}");
    assert!(
        vertical_drift < 1e-12 * vertical.abs().max(1.0),
        "{vertical_drift:e}"
    );
    assert!(
        energy_error < 1e-3 * energy.abs(),
        "{energy_error:e} of {energy}"
    );
}

/// The Lie quadratic Omega''' = Omega'' x Omega (the Riemannian cubics of the bi-invariant
/// metric, J = I) with R' = R [Omega]x from the identity with `rates` = (Omega, Omega',
/// Omega''), by RK4 with `steps` steps: the rotation at `t`.
fn lie_quadratic(rates: [Vector3<f64>; 3], t: f64, steps: usize) -> UnitQuaternion<f64> {
    type State = (Vector4<f64>, [Vector3<f64>; 3]);
    let rhs = |(q, w): &State| -> State {
        let dq = Quaternion::from(*q) * Quaternion::from_imag(w[0]) * 0.5;
        (dq.coords, [w[1], w[2], w[2].cross(&w[0])])
    };
    let axpy = |(q, w): &State, a: f64, (dq, dw): &State| -> State {
        (q + dq * a, core::array::from_fn(|i| w[i] + dw[i] * a))
    };
    let h = t / steps as f64;
    let mut s: State = (Vector4::new(0.0, 0.0, 0.0, 1.0), rates);
    for _ in 0..steps {
        let k1 = rhs(&s);
        let k2 = rhs(&axpy(&s, h / 2.0, &k1));
        let k3 = rhs(&axpy(&s, h / 2.0, &k2));
        let k4 = rhs(&axpy(&s, h, &k3));
        let sum = axpy(&axpy(&axpy(&k1, 2.0, &k2), 2.0, &k3), 1.0, &k4);
        s = axpy(&s, h / 6.0, &sum);
    }
    UnitQuaternion::new_normalize(Quaternion::from(s.0))
}

/// The cubic with inertia `j` from the identity with `rates` = (Omega, Omega', Omega''):
/// `steps` steps to `t`, each a composition of order `order` of Cayley midpoint steps with
/// the chart recentred after every stage; the rotation at `t` and the largest relative
/// change of the spatial momentum.
fn cubic_run(
    j: [f64; 3],
    rates: [Vector3<f64>; 3],
    t: f64,
    steps: usize,
    order: u32,
) -> (UnitQuaternion<f64>, f64) {
    let options = NewtonOptions::default();
    let mut system = Cubic::new(j[0], j[1], j[2]);
    let mut centre = UnitQuaternion::identity();
    let mut z: SVector<f64, 12> = body_state::<_, 2, 12, 3>(&system, &rates).expect("finite");
    let m0 = world_momentum::<2, 12>(&centre, &z);
    let mut drift: f64 = 0.0;
    for _ in 0..steps {
        let mut stage = |z: &SVector<f64, 12>, h: f64| {
            let (mut next, report) = map::step(&system, &CayleyMidpoint2, z, h, &options)?;
            recentre_system::<_, 2, 12>(&mut system, &mut centre, &mut next)?;
            Ok((next, report))
        };
        z = retract::compose::compose(&mut stage, &z, t / steps as f64, order)
            .expect("regular")
            .0;
        drift = drift.max((world_momentum::<2, 12>(&centre, &z) - m0).amax() / m0.amax());
    }
    (orientation::<2, 12>(&centre, &z), drift)
}

/// Rates of a cubic that turns the body about 1.5 rad in 2 s.
fn cubic_rates() -> [Vector3<f64>; 3] {
    [
        Vector3::new(0.5, 1.0, -0.3),
        Vector3::new(0.2, -0.1, 0.3),
        Vector3::new(-0.1, 0.2, 0.1),
    ]
}

#[test]
fn riemannian_cubics_converge_to_the_lie_quadratic_with_orders_2_4_and_6() {
    let t = 2.0;
    let exact = lie_quadratic(cubic_rates(), t, 20_000);
    for (order, sizes) in [(2, [20, 40, 80]), (4, [10, 20, 40]), (6, [10, 20, 40])] {
        let errors = sizes.map(|n| {
            cubic_run([1.0; 3], cubic_rates(), t, n, order)
                .0
                .angle_to(&exact)
        });
        eprintln!("order {order}: {errors:?}");
        for pair in errors.windows(2) {
            let observed = (pair[0] / pair[1]).log2();
            assert!(
                (observed - f64::from(order)).abs() < 0.3,
                "order {order}: observed {observed} ({errors:?})"
            );
        }
    }
}

#[test]
fn riemannian_cubics_of_a_left_invariant_metric_conserve_their_spatial_momentum() {
    let (_, drift) = cubic_run(attitude::INERTIA, cubic_rates(), 10.0, 500, 2);
    assert!(drift < 1e-11, "{drift:e}");
}

#[test]
fn chart_derivatives_invert_the_body_velocity() {
    // at a chart point away from the centre, the body velocity series of the returned jet
    // (Omega = 2 (y' - y x y') / (1 + |y|^2), differentiated as a Taylor series) is `rates`
    for seed in 0..10 {
        let y = random(seed, 0.7);
        let rates = [
            random(seed + 1, 1.0),
            random(seed + 2, 1.0),
            random(seed + 3, 1.0),
        ];
        let d = chart_derivatives(&y, &rates);
        let curve = |t: f64| y + d[0] * t + d[1] * t * t / 2.0 + d[2] * t * t * t / 6.0;
        let omega = |t: f64| {
            let (p, v) = (curve(t), d[0] + d[1] * t + d[2] * t * t / 2.0);
            (v - p.cross(&v)) * (2.0 / (1.0 + p.norm_squared()))
        };
        let e = 1e-3;
        let fd = [
            omega(0.0),
            (omega(e) - omega(-e)) / (2.0 * e),
            (omega(e) - 2.0 * omega(0.0) + omega(-e)) / (e * e),
        ];
        for (i, (a, b)) in fd.iter().zip(&rates).enumerate() {
            assert!(
                (a - b).amax() < 1e-5,
                "seed {seed}, Omega^({i}): {a} vs {b}"
            );
        }
        // and the chart's quaternion moves with the body velocity: Q^-1 Q' = (0, Omega / 2)
        let q = |t: f64| chart_quaternion(&curve(t)).into_inner();
        let dq = (q(e) - q(-e)) / (2.0 * e);
        let w = (q(0.0).conjugate() * dq).imag() * 2.0;
        assert!((w - rates[0]).amax() < 1e-5, "seed {seed}");
    }
}
