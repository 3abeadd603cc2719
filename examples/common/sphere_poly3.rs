//! The Riemannian polynomial of order 3 on the unit sphere, L = 1/2 |D_t^2 q'|^2 (k = 3), and
//! an independent reference: RK4 on the embedded Euler-Lagrange equation
//! D_t^5 V + R(D_t^3 V, V) V - R(D_t^2 V, D_t V) V = 0 in ambient coordinates, started from
//! tangent data (q, V, D_t V, ..., D_t^4 V). Shared by examples/sphere.rs and the tests.
#![allow(dead_code)]

use retract::higher_order_lagrangian;
use retract::nalgebra::Vector3;
use retract::taylor::{Scalar, Taylor};

/// The Lagrangian 1/2 |D_t^2 q'|^2 in ambient coordinates: on the unit sphere
/// D_t q' = q'' + |q'|^2 q and D_t^2 q' = q''' - (q''' . q) q + |q'|^2 q'.
#[higher_order_lagrangian(order = 3, sphere)]
pub fn poly3(q: [f64; 3], dq: [f64; 3], _ddq: [f64; 3], dddq: [f64; 3]) -> f64 {
    let c = q[0] * dddq[0] + q[1] * dddq[1] + q[2] * dddq[2];
    let v2 = dq[0] * dq[0] + dq[1] * dq[1] + dq[2] * dq[2];
    0.5 * ((dddq[0] - c * q[0] + v2 * dq[0]).powi(2)
        + (dddq[1] - c * q[1] + v2 * dq[1]).powi(2)
        + (dddq[2] - c * q[2] + v2 * dq[2]).powi(2))
}

/// Tangent data (q, V, D_t V, D_t^2 V, D_t^3 V, D_t^4 V) along a curve on the sphere.
pub type Data = [Vector3<f64>; 6];

/// The test data: q a unit vector and five tangent vectors at it.
pub fn data() -> Data {
    let q = Vector3::new(0.3, -0.4, 0.8).normalize();
    let tangent = |v: Vector3<f64>| v - q * q.dot(&v);
    [
        q,
        tangent(Vector3::new(0.9, 0.5, -0.2)),
        tangent(Vector3::new(-0.4, 0.7, 0.6)),
        tangent(Vector3::new(0.2, -0.3, 0.5)),
        tangent(Vector3::new(-0.3, 0.1, 0.4)),
        tangent(Vector3::new(0.5, 0.2, -0.1)),
    ]
}

/// A vector of three numbers of any kind.
type V3<T> = [T; 3];

fn dot<T: Scalar>(a: &V3<T>, b: &V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn combine<T: Scalar>(a: &V3<T>, s: T, b: &V3<T>, t: T) -> V3<T> {
    core::array::from_fn(|i| a[i] * s + b[i] * t)
}

/// The embedded equation over any scalar, for tangent fields along q (D_t W = W' + (W . V)
/// q, curvature R(X, Y) Z = (Y . Z) X - (X . Z) Y): q' = V, (D^i V)' = D^(i+1) V -
/// (D^i V . V) q, and D^5 V = -R(D^3 V, V) V + R(D^2 V, D V) V
/// = -(|V|^2 D^3 V - (D^3 V . V) V) + (D V . V) D^2 V - (D^2 V . V) D V.
pub fn rhs_generic<T: Scalar>(y: &[V3<T>; 6]) -> [V3<T>; 6] {
    let [q, v, d1, d2, d3, d4] = y;
    let one = T::constant(1.0);
    let vv = dot(v, v);
    let first = combine(d3, -vv, v, dot(d3, v));
    let second = combine(d2, dot(d1, v), d1, -dot(d2, v));
    let d5 = combine(&first, one, &second, one);
    let along = |w: &V3<T>, next: &V3<T>| combine(next, one, q, -dot(w, v));
    [
        *v,
        along(v, d1),
        along(d1, d2),
        along(d2, d3),
        along(d3, d4),
        along(d4, &d5),
    ]
}

fn to_generic(y: &Data) -> [V3<f64>; 6] {
    y.map(|v| [v[0], v[1], v[2]])
}

fn from_generic(y: &[V3<f64>; 6]) -> Data {
    y.map(|v| Vector3::new(v[0], v[1], v[2]))
}

/// The data at time `t` from `start` by classical RK4 with `steps` steps.
pub fn reference(start: Data, t: f64, steps: usize) -> Data {
    let h = t / steps as f64;
    let rhs = |y: &Data| from_generic(&rhs_generic(&to_generic(y)));
    let add = |y: &Data, k: &Data, c: f64| -> Data { core::array::from_fn(|i| y[i] + k[i] * c) };
    let mut y = start;
    for _ in 0..steps {
        let k1 = rhs(&y);
        let k2 = rhs(&add(&y, &k1, h / 2.0));
        let k3 = rhs(&add(&y, &k2, h / 2.0));
        let k4 = rhs(&add(&y, &k3, h));
        y = core::array::from_fn(|i| {
            y[i] + (k1[i] + k2[i] * 2.0 + k3[i] * 2.0 + k4[i]) * (h / 6.0)
        });
    }
    y
}

/// The ambient jet (q, q', ..., q^(5)) of the solution through `data`: its Taylor series at
/// 0 by Picard iteration in Taylor arithmetic (each pass fixes one more coefficient,
/// c_(m+1) = rhs(y)_m / (m + 1)).
pub fn jet(data: Data) -> Data {
    type S = Taylor<f64, 6>;
    let mut y: [V3<S>; 6] =
        core::array::from_fn(|i| core::array::from_fn(|c| S::constant(data[i][c])));
    for _ in 0..6 {
        let f = rhs_generic(&y);
        for (yi, fi) in y.iter_mut().zip(&f) {
            for (s, g) in yi.iter_mut().zip(fi) {
                for m in 0..5 {
                    s.c[m + 1] = g.c[m] / (m + 1) as f64;
                }
            }
        }
    }
    let q = y[0].map(|s| s.derivatives());
    core::array::from_fn(|j| Vector3::new(q[0][j], q[1][j], q[2][j]))
}
