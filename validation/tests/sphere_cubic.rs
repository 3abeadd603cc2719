//! The Riemannian cubic on S^2 of the speed report (`retract_validation::sphere_cubic`): the
//! exact cubic meets its boundary data and the Euler-Lagrange equation (checked by finite
//! differences of its samples, independently of the right-hand side that made them),
//! `retract`'s curve converges to it at order 2, and the geodesic de Casteljau curve with the
//! same end points and velocities is another curve (its error stays).

use retract::nalgebra::Vector3;
use retract_validation::sphere_cubic::{
    self, Bezier, Boundary, Data, SAMPLES, SUBSTEPS, distance, exact_start, trajectory,
};

/// The exact cubic's samples at the `SAMPLES + 1` times k T / SAMPLES.
fn exact() -> (Boundary, Vec<Data>) {
    let boundary = Boundary::report();
    let start = exact_start(&boundary, SAMPLES * SUBSTEPS).expect("the shooting converges");
    let samples = trajectory(start, boundary.t_end, SAMPLES, SUBSTEPS);
    (boundary, samples)
}

/// The derivative at sample `k` of the sampled field `f` (spacing `h`) by the 8th-order
/// central difference.
fn derivative(f: &dyn Fn(usize) -> Vector3<f64>, k: usize, h: f64) -> Vector3<f64> {
    let weights = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];
    let mut d = Vector3::zeros();
    for (j, w) in weights.iter().enumerate() {
        d += (f(k + j + 1) - f(k - j - 1)) * *w;
    }
    d / h
}

#[test]
fn exact_cubic_meets_its_boundary_data_and_euler_lagrange_equation() {
    let (b, samples) = exact();
    let [q0, v0, _, _] = samples[0];
    let [q, v, _, _] = samples[SAMPLES];
    assert!((q0 - b.p0).norm() < 1e-15 && (v0 - b.v0).norm() < 1e-15);
    assert!(
        (q - b.p3).norm() < 1e-10,
        "q(T) - p3 = {:e}",
        (q - b.p3).norm()
    );
    assert!(
        (v - b.v3).norm() < 1e-10,
        "V(T) - v3 = {:e}",
        (v - b.v3).norm()
    );
    // RK4 with twice the steps moves no sample by 1e-12: the samples solve the system
    let finer = trajectory(samples[0], b.t_end, SAMPLES, 2 * SUBSTEPS);
    let moved = (samples.iter().zip(&finer))
        .flat_map(|(a, c)| (0..4).map(move |i| (a[i] - c[i]).norm()))
        .fold(0.0, f64::max);
    assert!(
        moved < 1e-12,
        "RK4 refinement moves the samples by {moved:e}"
    );
    // by finite differences of the samples: q' = V, A = D_t V, J = D_t A and the
    // Euler-Lagrange equation D_t J + R(A, V) V = 0, R(X, Y) Z = (Y . Z) X - (X . Z) Y; the
    // covariant derivative of a tangent field W along q is D_t W = W' + (W . V) q
    let h = b.t_end / SAMPLES as f64;
    let samples = &samples;
    let field = |i: usize| move |k: usize| samples[k][i];
    let (q, v, a, j) = (field(0), field(1), field(2), field(3));
    let mut worst = [0.0_f64; 4];
    for (k, &[qk, vk, ak, jk]) in samples.iter().enumerate().take(SAMPLES - 3).skip(4) {
        let residuals = [
            derivative(&q, k, h) - vk,
            derivative(&v, k, h) + qk * vk.dot(&vk) - ak,
            derivative(&a, k, h) + qk * ak.dot(&vk) - jk,
            derivative(&j, k, h) + qk * jk.dot(&vk) + ak * vk.dot(&vk) - vk * ak.dot(&vk),
        ];
        for (w, r) in worst.iter_mut().zip(residuals) {
            *w = w.max(r.norm());
        }
    }
    assert!(worst.iter().all(|w| *w < 1e-10), "residuals {worst:?}");
    // the Noether momentum of rotations, q x J - V x A, is conserved
    let momentum = |[q, v, a, j]: Data| q.cross(&j) - v.cross(&a);
    let drift = (samples.iter())
        .map(|d| (momentum(*d) - momentum(samples[0])).norm())
        .fold(0.0, f64::max);
    assert!(drift < 1e-11, "momentum drift {drift:e}");
}

#[test]
fn de_casteljau_matches_the_end_data_but_is_another_curve() {
    let (b, samples) = exact();
    let bezier = Bezier::new(&b);
    let t = b.t_end;
    assert!(distance(&bezier.at(0.0), &b.p0) < 1e-15);
    assert!(distance(&bezier.at(t), &b.p3) < 1e-15);
    // end velocities by the 4th-order central difference (the curve's formula holds for
    // parameters outside [0, T] too)
    let e = 1e-3;
    let velocity = |t: f64| {
        (bezier.at(t - 2.0 * e) - bezier.at(t + 2.0 * e)
            + (bezier.at(t + e) - bezier.at(t - e)) * 8.0)
            / (12.0 * e)
    };
    let (dv0, dv3) = ((velocity(0.0) - b.v0).norm(), (velocity(t) - b.v3).norm());
    assert!(
        dv0 < 1e-9 && dv3 < 1e-9,
        "end velocity errors {dv0:e}, {dv3:e}"
    );
    let error = (0..=SAMPLES)
        .map(|k| distance(&bezier.at(k as f64 * t / SAMPLES as f64), &samples[k][0]))
        .fold(0.0, f64::max);
    assert!(
        error > 1e-4,
        "de Casteljau's curve is within {error:e} of the cubic"
    );
}

#[test]
fn retract_converges_at_order_two_and_extrapolation_beyond() {
    let resolutions = [16, 32, 64, 128];
    let m = sphere_cubic::measure(&resolutions, 1).expect("measured");
    assert!(m.boundary_residual < 1e-10, "{m:?}");
    for pair in m.retract.windows(2) {
        let order = (pair[0].error / pair[1].error).log2();
        assert!(
            (1.8..=2.2).contains(&order),
            "observed order {order} from N = {} to {}: {m:?}",
            pair[0].steps,
            pair[1].steps
        );
    }
    // de Casteljau's error is the same at every resolution (the same curve, sampled) and
    // above every retract error from N = 16 on
    let casteljau = m.decasteljau[0].error;
    for (d, r) in m.decasteljau.iter().zip(&m.retract) {
        assert!(
            (d.error - casteljau).abs() <= 1e-12 && r.error < casteljau,
            "{m:?}"
        );
    }
    // the extrapolated nodes at least 100 times closer than the order-2 plan's, their error
    // falling at order 5 or more (6 expected) while above the reference's accuracy
    for (nodes, r) in m.extrapolated_nodes.iter().zip(&m.retract) {
        assert!(*nodes < 1e-2 * r.error, "{m:?}");
    }
    for pair in m.extrapolated_nodes.windows(2).take(2) {
        assert!((pair[0] / pair[1]).log2() >= 5.0, "{m:?}");
    }
}
