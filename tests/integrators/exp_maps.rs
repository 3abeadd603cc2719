//! The exponential midpoint maps of SO(3) and SE(3), R_d(g, xi) = (g exp(-xi/2), g exp(xi/2)):
//! their points are the group exponential of nalgebra (the rotation vector, and the matrix
//! exponential of the twist); the generated maps are the run-time lift; and a spherical body,
//! whose motions are one-parameter subgroups, is stepped exactly, where the Cayley map errs.
//! The steps' structure (symplecticity, momentum) and orders are tested with the Cayley maps'
//! in `so3` and `se3`.

use retract::map::{self, DiscretizationMap, TaylorLift};
use retract::nalgebra::{Matrix3, Matrix4, Rotation3, SVector, Vector3};
use retract::se3::Se3ExpMidpoint1;
use retract::so3::{CayleyMidpoint, ExpMidpoint, ExpMidpoint1, ExpMidpoint2, parts, rotation};
use retract::{LiftedSystem, NewtonOptions, higher_order_lagrangian};

use super::so3_body::{random, unskew};
use super::so3_moving::generated_matches_the_lift;

/// The body vector Omega of the chart velocity v at y, from central differences of the
/// rotation: [Omega]x = R(y)^T dR/de (y + e v).
fn body_vector(y: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let e = 1e-6;
    let d = (rotation(&(y + v * e)) - rotation(&(y - v * e))) / (2.0 * e);
    unskew(&(rotation(y).transpose() * d))
}

/// exp of a rotation vector by nalgebra.
fn exp(omega: &Vector3<f64>) -> Matrix3<f64> {
    Rotation3::from_scaled_axis(*omega).into_inner()
}

/// The points of `map` at random y and v, from rest through small, moderate and large turns
/// (|Omega| up to about 3.5 rad), against R(y) exp(-+Omega/2).
fn points_are_the_exponential(map: &impl DiscretizationMap<3, 1>) {
    for seed in 0..20 {
        let y = random(seed, 0.8);
        let scale = [0.0, 1e-9, 1e-4, 0.1, 1.0, 2.0][seed as usize % 6];
        let v = random(seed + 100, scale);
        let omega = body_vector(&y, &v);
        let expected = [
            rotation(&y) * exp(&(-omega / 2.0)),
            rotation(&y) * exp(&(omega / 2.0)),
        ];
        let (r1, r2) = map.points(&[y], &[v]);
        for (r, e) in [r1, r2].iter().zip(&expected) {
            let gap = (rotation(&r[0]) - e).amax();
            assert!(gap < 1e-9 * (1.0 + scale), "seed {seed}: {gap:e}");
        }
    }
}

#[test]
fn the_so3_points_are_the_rotations_by_half_the_body_vector() {
    points_are_the_exponential(&ExpMidpoint1);
    points_are_the_exponential(&TaylorLift(ExpMidpoint));
    // the Cayley map differs at third order in the turn
    let (y, v) = (random(3, 0.8), random(4, 1.0));
    let (a, _) = ExpMidpoint1.points(&[y], &[v]);
    let (b, _) = TaylorLift(CayleyMidpoint).points(&[y], &[v]);
    assert!((a[0] - b[0]).amax() > 1e-3);
}

/// The 4x4 matrix of the pose (R, p).
fn homogeneous(r: &Matrix3<f64>, p: &Vector3<f64>) -> Matrix4<f64> {
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(p);
    m
}

/// The 4x4 matrix of the twist (omega, v).
fn twist(omega: &Vector3<f64>, v: &Vector3<f64>) -> Matrix4<f64> {
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&omega.cross_matrix());
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(v);
    m
}

#[test]
fn the_se3_points_are_the_matrix_exponential_of_half_the_twist() {
    for seed in 0..20 {
        let (y, x) = (random(seed, 0.8), random(seed + 50, 2.0));
        let scale = [0.0, 1e-9, 1e-4, 0.1, 1.0, 2.0][seed as usize % 6];
        let (vy, vx) = (random(seed + 100, scale), random(seed + 150, 3.0 * scale));
        // body velocity: Omega from the rotation, v = R^T x'
        let (omega, v) = (body_vector(&y, &vy), rotation(&y).transpose() * vx);
        let g = homogeneous(&rotation(&y), &x);
        let q = SVector::<f64, 6>::from_iterator(y.iter().chain(x.iter()).copied());
        let w = SVector::<f64, 6>::from_iterator(vy.iter().chain(vx.iter()).copied());
        let (r1, r2) = Se3ExpMidpoint1.points(&[q], &[w]);
        for (r, sign) in [(r1, -0.5), (r2, 0.5)] {
            let expected = g * (twist(&omega, &v) * sign).exp();
            let (ry, rx) = (r[0].fixed_rows::<3>(0), r[0].fixed_rows::<3>(3));
            let got = homogeneous(&rotation(&ry.into_owned()), &rx.into_owned());
            let gap = (got - expected).amax();
            assert!(gap < 1e-9 * (1.0 + scale), "seed {seed}: {gap:e}");
        }
    }
}

#[test]
fn the_generated_exponential_maps_are_the_run_time_lift_and_finite_at_rest() {
    generated_matches_the_lift::<1>(&ExpMidpoint1, &TaylorLift(ExpMidpoint));
    generated_matches_the_lift::<2>(&ExpMidpoint2, &TaylorLift(ExpMidpoint));
    // at rest (s = 0, where tan(theta/2)/theta is 0/0 in closed form) every output is finite
    let (x, rest) = ([random(1, 0.5), random(2, 0.5)], [Vector3::zeros(); 2]);
    let (r1, r2) = ExpMidpoint2.points(&x, &rest);
    assert!((r1[0] - x[0]).amax() == 0.0 && (r2[0] - x[0]).amax() == 0.0);
    let jac = ExpMidpoint2.jacobians(&x, &rest);
    let hessian = ExpMidpoint2.covector_hessian(&x, &rest, &x, &x);
    let finite = |m: &Matrix3<f64>| m.iter().all(|e| e.is_finite());
    assert!(jac.r1_x.iter().flatten().all(finite) && jac.r2_xi.iter().flatten().all(finite));
    assert!(hessian.xi_xi.iter().flatten().all(finite) && hessian.xx.iter().flatten().all(finite));
}

/// A free rigid body with inertia diag(j1, j2, j3) in one Gibbs chart, written with the
/// chart's body velocity.
#[higher_order_lagrangian(order = 1)]
fn free_body(y: [f64; 3], dy: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    let scale = 2.0 / (1.0 + y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    let w = [
        scale * (dy[0] - (y[1] * dy[2] - y[2] * dy[1])),
        scale * (dy[1] - (y[2] * dy[0] - y[0] * dy[2])),
        scale * (dy[2] - (y[0] * dy[1] - y[1] * dy[0])),
    ];
    0.5 * (j1 * w[0] * w[0] + j2 * w[1] * w[1] + j3 * w[2] * w[2])
}

/// `steps` steps of size `h` of `map` for `body` from the identity with body velocity
/// `omega`: the states.
fn run<M: DiscretizationMap<3, 1>>(
    body: &FreeBody,
    map: &M,
    omega: &Vector3<f64>,
    h: f64,
    steps: usize,
) -> Vec<SVector<f64, 6>> {
    let jet =
        SVector::<f64, 6>::from_iterator([0.0; 3].into_iter().chain((omega / 2.0).iter().copied()));
    let mut states = vec![body.legendre(&jet)];
    for _ in 0..steps {
        let z = states[states.len() - 1];
        let next = map::step(body, map, &z, h, &NewtonOptions::default()).expect("regular");
        states.push(next.0);
    }
    states
}

#[test]
fn a_spherical_body_is_stepped_exactly_and_the_cayley_map_is_not() {
    // J = I: the motion is R(t) = exp(t Omega), a one-parameter subgroup, which the
    // exponential map follows exactly at any step
    let (body, omega) = (FreeBody::new(1.0, 1.0, 1.0), Vector3::new(0.4, 0.9, -0.3));
    let (h, steps) = (0.2, 10);
    let exact = exp(&(omega * (h * steps as f64)));
    let error = |states: Vec<SVector<f64, 6>>| (rotation(&parts(&states[steps]).0) - exact).amax();
    let (exp_error, cayley_error) = (
        error(run(&body, &ExpMidpoint1, &omega, h, steps)),
        error(run(&body, &TaylorLift(CayleyMidpoint), &omega, h, steps)),
    );
    println!("spherical body, h = {h}: exp {exp_error:.1e}, Cayley {cayley_error:.1e}");
    assert!(exp_error < 1e-13, "exp map: {exp_error:e}");
    assert!(cayley_error > 1e-4, "Cayley map: {cayley_error:e}");
}
