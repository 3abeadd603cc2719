//! Riemannian cubics on the unit sphere, independently of `retract::sphere`: the embedded
//! Euler-Lagrange equation D_t^3 V + R(D_t V, V) V = 0 as a first-order system in
//! (q, V, A, J) (A = D_t V, J = D_t A), integrated by classical RK4; and the cubic's
//! Lagrangian, a keep-out cap and boundary data for `retract`. Shared by
//! `examples/sphere.rs` and `tests/integrators/sphere.rs` (by path).
#![allow(dead_code)] // each user takes a subset

use retract::nalgebra::Vector3;
use retract::{higher_order_lagrangian, jet_function};

/// The Riemannian cubic's Lagrangian L = 1/2 |D_t q'|^2 in ambient coordinates.
#[higher_order_lagrangian(order = 2, sphere)]
pub fn cubic(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3]) -> f64 {
    // the covariant acceleration D_t q' = q'' - (q'' . q) q on the unit sphere
    let a = q[0] * ddq[0] + q[1] * ddq[1] + q[2] * ddq[2];
    0.5 * ((ddq[0] - a * q[0]).powi(2) + (ddq[1] - a * q[1]).powi(2) + (ddq[2] - a * q[2]).powi(2))
}

/// Outside the cap of angular radius arccos(`cos_radius`) around the unit vector `axis`.
#[jet_function(order = 2, sphere)]
pub fn outside_cap(
    q: [f64; 3],
    _dq: [f64; 3],
    _ddq: [f64; 3],
    axis: [f64; 3],
    cos_radius: f64,
) -> f64 {
    cos_radius - (q[0] * axis[0] + q[1] * axis[1] + q[2] * axis[2])
}

/// A point of the equator at longitude `deg` and the velocity `speed` east there.
pub fn on_equator(deg: f64, speed: f64) -> [Vector3<f64>; 2] {
    let a = deg.to_radians();
    [
        Vector3::new(a.cos(), a.sin(), 0.0),
        Vector3::new(-a.sin(), a.cos(), 0.0) * speed,
    ]
}

/// Tangent data (q, V, A, J) along a curve on the sphere.
pub type Data = [Vector3<f64>; 4];

/// The test cubic's data: q a unit vector, V, A, J tangent at q.
pub fn data() -> Data {
    let q = Vector3::new(0.3, -0.4, 0.8).normalize();
    let tangent = |v: Vector3<f64>| v - q * q.dot(&v);
    [
        q,
        tangent(Vector3::new(0.9, 0.5, -0.2)),
        tangent(Vector3::new(-0.4, 0.7, 0.6)),
        tangent(Vector3::new(0.2, -0.3, 0.5)),
    ]
}

/// The ambient jet (q, q', q'', q''') of the curve with data (q, V, A, J) (see [`rhs`]):
/// q'' = A - |V|^2 q and q''' = J - 3 (A . V) q - |V|^2 V.
pub fn jet([q, v, a, j]: Data) -> Data {
    let vv = v.dot(&v);
    [q, v, a - q * vv, j - q * (3.0 * a.dot(&v)) - v * vv]
}

/// The conserved momentum m = q x J - V x A of a cubic.
pub fn momentum([q, v, a, j]: Data) -> Vector3<f64> {
    q.cross(&j) - v.cross(&a)
}

/// The embedded equation, for tangent fields along q (D_t W = W' + (W . V) q, curvature
/// R(X, Y) Z = (Y . Z) X - (X . Z) Y): q' = V, V' = A - |V|^2 q, A' = J - (A . V) q,
/// J' = D_t J - (J . V) q with D_t J = -R(A, V) V = -(|V|^2 A - (A . V) V).
pub fn rhs([q, v, a, j]: Data) -> Data {
    let (vv, av) = (v.dot(&v), a.dot(&v));
    let dj = -(a * vv - v * av);
    [v, a - q * vv, j - q * av, dj - q * j.dot(&v)]
}

/// The data at time `t` from `start` by classical RK4 with `steps` steps.
pub fn reference(start: Data, t: f64, steps: usize) -> Data {
    let h = t / steps as f64;
    let add = |y: &Data, k: &Data, c: f64| -> Data { core::array::from_fn(|i| y[i] + k[i] * c) };
    let mut y = start;
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
