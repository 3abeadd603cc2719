//! Property tests of the generated code at 100 random points per Lagrangian, against
//! fourth-order central finite differences (error O(eps^4), relative tolerance 1e-8):
//! gradient (of `lagrangian`), Hessian (of `gradient`), momenta (by differentiating the
//! momenta in time along the polynomial curve with the given jet), H(Leg(jet)) = E_L(jet),
//! the vector field = J grad H, and the scheme's Jacobians (of `residual`); for the
//! systems of `#[higher_order_lagrangian]` and those of `#[mechanical_system]` with their
//! plants.

#![allow(clippy::needless_range_loop)] // index loops mirror the formulas

use crate::common;

use common::{close, fd, grad_entry, hess_entry, shifted};

use proptest::prelude::*;
use retract::higher_order_lagrangian;
use retract::nalgebra::{SMatrix, SVector};
use retract::{Lagrangian, LiftedSystem, smooth_max, smooth_min};

// ---- the Lagrangians --------------------------------------------------------------------

/// k = 1, nonlinear potential (pendulum + quartic) on R^2.
#[higher_order_lagrangian(order = 1)]
fn pendulum(q: [f64; 2], dq: [f64; 2], m: f64, g: f64) -> f64 {
    0.5 * m * (dq[0].powi(2) + dq[1].powi(2)) + m * g * q[0].cos() - 0.25 * q[1].powi(4)
}

/// k = 1 on R (scalar jet).
#[higher_order_lagrangian(order = 1)]
fn anharmonic(q: f64, dq: f64, w: f64) -> f64 {
    0.5 * dq * dq - 0.5 * w * w * q * q - 0.1 * q.powi(4)
}

/// k = 2, the obstacle barrier on the SE(2) chart (x, y, theta), any number of obstacles
/// (cx, cy, r) in a run-time loop.
#[higher_order_lagrangian(order = 2)]
fn se2_barrier(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, obstacles: &[[f64; 3]]) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2));
    for o in obstacles {
        l += tau / ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]);
    }
    l
}

/// k = 2, minimum torque of a planar two-link arm: L = 1/2 |M(q) q'' + c(q, q') + g(q)|^2.
#[higher_order_lagrangian(order = 2)]
fn arm(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], a: f64, b: f64, d: f64, g1: f64, g2: f64) -> f64 {
    let c2 = q[1].cos();
    let s2 = q[1].sin();
    let m11 = a + 2.0 * b * c2;
    let m12 = d + b * c2;
    let m22 = d;
    let c1 = -b * s2 * (2.0 * dq[0] * dq[1] + dq[1].powi(2));
    let cc2 = b * s2 * dq[0].powi(2);
    let gr1 = g1 * q[0].cos() + g2 * (q[0] + q[1]).cos();
    let gr2 = g2 * (q[0] + q[1]).cos();
    let t1 = m11 * ddq[0] + m12 * ddq[1] + c1 + gr1;
    let t2 = m12 * ddq[0] + m22 * ddq[1] + cc2 + gr2;
    0.5 * (t1 * t1 + t2 * t2)
}

/// k = 3, minimum jerk with a potential.
#[higher_order_lagrangian(order = 3)]
fn jerk(q: [f64; 2], dq: [f64; 2], _ddq: [f64; 2], dddq: [f64; 2], kappa: f64) -> f64 {
    0.5 * (dddq[0].powi(2) + dddq[1].powi(2)) + kappa * (q[0] * q[1]).sin() + 0.1 * dq[0].powi(2)
}

/// k = 4, minimum snap in R^3.
#[higher_order_lagrangian(order = 4)]
fn snap(q: [f64; 3], dq: [f64; 3], ddq: [f64; 3], dddq: [f64; 3], d4q: [f64; 3]) -> f64 {
    let mut l = 0.0;
    for i in 0..3 {
        l += 0.5 * d4q[i].powi(2) + 0.01 * ddq[i] * dddq[i] + 0.05 * q[i].powi(2) * dq[i];
    }
    l
}

/// k = 2 with atan2, exp and sqrt, and a configuration-dependent Hessian in q''.
#[higher_order_lagrangian(order = 2)]
fn transcendental(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], alpha: f64) -> f64 {
    let weight = 1.0 + 0.1 * (0.3 * q[0]).exp();
    0.5 * weight * (ddq[0].powi(2) + ddq[1].powi(2))
        + 0.2 * ddq[0] * ddq[1] * q[1].atan2(q[0]).cos()
        + alpha * q[1].atan2(q[0])
        + (1.0 + q[0].powi(2) + dq[1].powi(2)).sqrt()
}

/// k = 2 with every method beyond the elementary ones: asin, acos, atan, sinh, cosh, cbrt,
/// ln_1p, exp_m1, log2, log10, mul_add, smooth_max and smooth_min, in q, q' and q'' (the
/// arguments kept inside their domains at the sample points).
#[higher_order_lagrangian(order = 2)]
fn special(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], eps: f64) -> f64 {
    let weight = 1.0 + 0.1 * (0.2 * q[0]).sinh().powi(2) + 0.05 * (0.3 * q[1]).cosh();
    0.5 * weight * (ddq[0].powi(2) + ddq[1].powi(2))
        + 0.1 * ddq[0] * (0.4 * q[1]).atan()
        + (0.3 * q[0]).asin() * (0.2 * dq[1]).acos()
        + (2.0 + q[0].powi(2)).cbrt()
        + (q[1].powi(2) + dq[0].powi(2)).ln_1p()
        + (0.2 * dq[0] * q[1]).exp_m1()
        + (3.0 + q[0] * q[1]).log2()
        + (2.0 + dq[1].powi(2)).log10()
        + q[0].mul_add(dq[1], 0.5 * q[1])
        + smooth_max(q[0], dq[1], eps)
        - smooth_min(q[1], dq[0], eps)
}

/// n = 7 (above nalgebra's `SVector::new`, n <= 6), constant weights on q' with a coupling:
/// the closed-form Legendre inverse.
#[higher_order_lagrangian(order = 1)]
fn chain7(q: [f64; 7], dq: [f64; 7], kappa: f64) -> f64 {
    let mut l = 0.0;
    for i in 0..7 {
        l += 0.5 * (1.0 + 0.25 * i as f64) * dq[i].powi(2) + kappa * q[i].cos();
    }
    for i in 0..6 {
        l += 0.1 * dq[i] * dq[i + 1] - 0.5 * (q[i + 1] - q[i]).powi(2);
    }
    l
}

/// n = 12, k = 2, constant weights on q'' and a nonlinear potential.
#[higher_order_lagrangian(order = 2)]
fn chain12(q: [f64; 12], dq: [f64; 12], ddq: [f64; 12], kappa: f64) -> f64 {
    let mut l = 0.0;
    for i in 0..12 {
        l += 0.5 * (2.0 - 0.05 * i as f64) * ddq[i].powi(2) + 0.05 * dq[i].powi(2);
    }
    for i in 0..11 {
        l += 0.2 * ddq[i] * ddq[i + 1] - kappa * (q[i] * q[i + 1]).sin();
    }
    l
}

/// n = 24, constant weights on q'.
#[higher_order_lagrangian(order = 1)]
fn chain24(q: [f64; 24], dq: [f64; 24], kappa: f64) -> f64 {
    let mut l = 0.0;
    for i in 0..24 {
        l += 0.5 * (1.0 + 0.1 * i as f64) * dq[i].powi(2) - kappa * q[i].powi(4);
    }
    for i in 0..23 {
        l += 0.05 * dq[i] * dq[i + 1] - 0.5 * kappa * (q[i + 1] * q[i]).cos();
    }
    l
}

/// The mechanical systems from their energy (`#[mechanical_system]`): the planar n-link
/// chain of `examples/common/mechanical.rs` (its order-2 effort and its plant, whose mass
/// matrix varies, are both built structurally: the Hessian, the momenta and the Legendre
/// inverse evaluate the Hessian-vector product at run time).
#[path = "../../../examples/common/mechanical.rs"]
mod mechanical;

crate::energy_chain!(chain_three, 3);

/// A particle in a well with damping, every coordinate driven, as its energy: the mass
/// matrix is constant, so the effort's A = d2L/du2 is (the closed-form Legendre inverse) and
/// the plant keeps the symbolic scheme.
#[retract::mechanical_system(forces = damping)]
fn well(q: [f64; 2], dq: [f64; 2], c: f64) -> f64 {
    fn damping(dq: [f64; 2], c: f64) -> [f64; 2] {
        [-c * dq[0], -c * dq[1] * dq[1]]
    }
    0.5 * (dq[0] * dq[0] + 2.0 * dq[1] * dq[1]) - q[0].cos() * q[1].powi(2) - 0.1 * q[1].powi(4)
}

// ---- finite differences -----------------------------------------------------------------

fn blocks<const N: usize, const K: usize>(v: &[f64]) -> [SVector<f64, N>; K] {
    core::array::from_fn(|j| SVector::from_fn(|i, _| v[j * N + i]))
}

/// Gradient and Hessian of L at (x, u) against finite differences.
fn check_derivatives<L: Lagrangian<N, K>, const N: usize, const K: usize>(
    l: &L,
    x: &[SVector<f64, N>; K],
    u: &SVector<f64, N>,
) {
    let eps = 1e-3;
    let m = N * (K + 1);
    let g = l.gradient(x, u);
    let h = l.hessian(x, u);
    let g_scale = (0..m).map(|c| grad_entry(&g, c).abs()).fold(0.0, f64::max);
    let h_scale = (0..m * m)
        .map(|e| hess_entry(&h, e / m, e % m).abs())
        .fold(0.0, f64::max);
    for c in 0..m {
        let want = fd(
            |t| {
                let (x, u) = shifted(x, u, c, t);
                l.lagrangian(&x, &u)
            },
            eps,
        );
        close(&format!("dL/dv{c}"), grad_entry(&g, c), want, g_scale);
        for b in 0..m {
            let want = fd(
                |t| {
                    let (x, u) = shifted(x, u, b, t);
                    grad_entry(&l.gradient(&x, &u), c)
                },
                eps,
            );
            close(
                &format!("d2L/dv{c}dv{b}"),
                hess_entry(&h, c, b),
                want,
                h_scale,
            );
        }
    }
}

/// The jet at time t of the polynomial curve with derivative data `jet` at t = 0
/// (q^(j)(t) = sum_i jet[j + i] t^i / i!).
fn jet_at<const N: usize, const S: usize>(jet: &SVector<f64, S>, t: f64) -> SVector<f64, S> {
    let orders = S / N;
    SVector::from_fn(|r, _| {
        let (j, i) = (r / N, r % N);
        let mut v = 0.0;
        let mut factor = 1.0;
        for m in 0..orders - j {
            if m > 0 {
                factor *= t / m as f64;
            }
            v += jet[(j + m) * N + i] * factor;
        }
        v
    })
}

/// Momenta, energy and vector field of a system at derivative data `jet`.
fn check_mechanics<Sys, const N: usize, const K: usize, const S: usize, const M: usize>(
    sys: &Sys,
    jet: &SVector<f64, S>,
) where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
{
    let eps = 1e-3;
    let z = sys.legendre(jet);
    let (x, p) = retract::lifted::split::<N, K, S>(&z);
    let u = SVector::<f64, N>::from_fn(|i, _| jet[K * N + i]);
    let g = sys.gradient(&x, &u);
    // p_{k-1} = dL/du; p_{j-1} = dL/dx_j - d/dt p_j along the curve
    let scale = z.amax();
    for i in 0..N {
        close("p_{k-1}", p[K - 1][i], g.u[i], scale);
    }
    for j in 1..K {
        for i in 0..N {
            let dp = fd(
                |t| sys.legendre(&jet_at::<N, S>(jet, t))[(K + j) * N + i],
                eps,
            );
            close(&format!("p_{}", j - 1), p[j - 1][i], g.x[j][i] - dp, scale);
        }
    }
    // H(Leg(jet)) = E_L = sum_j p_j . q^(j+1) - L
    let mut energy = -sys.lagrangian(&x, &u);
    for j in 0..K {
        energy += p[j].dot(&SVector::<f64, N>::from_fn(|i, _| jet[(j + 1) * N + i]));
    }
    let h = sys.hamiltonian(&z).expect("H at a regular point");
    close("H(Leg(jet)) - E_L", h, energy, energy.abs() + scale);
    // vector field = J grad H
    let f = sys
        .vector_field(&z)
        .expect("vector field at a regular point");
    let half = S / 2;
    for c in 0..S {
        let partner = if c < half { c + half } else { c - half };
        let sign = if c < half { 1.0 } else { -1.0 };
        let dh = fd(
            |t| {
                let mut w = z;
                w[partner] += t;
                sys.hamiltonian(&w).unwrap()
            },
            eps,
        );
        close(&format!("z'[{c}] = J grad H"), f[c], sign * dh, f.amax());
    }
}

/// The scheme's Jacobians against finite differences of its residual.
fn check_scheme<Sys, const S: usize, const M: usize>(
    sys: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    theta: f64,
) where
    Sys: LiftedSystem<S, M>,
{
    let eps = 1e-4;
    let w = sys.predictor(z0, h, theta).expect("predictor");
    let jac: SMatrix<f64, M, M> = sys.jacobian(z0, &w, h, theta);
    let jac0: SMatrix<f64, M, S> = sys.jacobian_initial(z0, &w, h, theta);
    let scale = jac.amax().max(jac0.amax());
    for r in 0..M {
        for c in 0..M {
            let want = fd(
                |t| {
                    let mut v = w;
                    v[c] += t;
                    sys.residual(z0, &v, h, theta)[r]
                },
                eps,
            );
            close(&format!("dF{r}/dw{c}"), jac[(r, c)], want, scale);
        }
        for c in 0..S {
            let want = fd(
                |t| {
                    let mut v = *z0;
                    v[c] += t;
                    sys.residual(&v, &w, h, theta)[r]
                },
                eps,
            );
            close(&format!("dF{r}/dz0_{c}"), jac0[(r, c)], want, scale);
        }
    }
}

/// Runs every check for one system at a random point.
fn check_all<Sys, const N: usize, const K: usize, const S: usize, const M: usize>(
    sys: &Sys,
    values: &[f64],
    h: f64,
    theta: f64,
) where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
{
    let x = blocks::<N, K>(values);
    let u = SVector::<f64, N>::from_fn(|i, _| values[N * K + i]);
    check_derivatives(sys, &x, &u);
    let jet = SVector::<f64, S>::from_column_slice(&values[..S]);
    check_mechanics(sys, &jet);
    check_scheme(sys, &sys.legendre(&jet), h, theta);
}

fn point(len: usize, lo: f64, hi: f64) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(lo..hi, len)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(100))]

    #[test]
    fn pendulum_k1(v in point(4, -1.5, 1.5), m in 0.5..2.0, h in 0.01..0.2, theta in 0.0..1.0) {
        check_all(&Pendulum { m, g: 9.81 }, &v, h, theta);
    }

    #[test]
    fn anharmonic_scalar_k1(v in point(2, -1.5, 1.5), w in 0.5..2.0, h in 0.01..0.2, theta in 0.0..1.0) {
        check_all(&Anharmonic { w }, &v, h, theta);
    }

    #[test]
    fn se2_barrier_k2(mut v in point(12, -1.0, 1.0), tau in 0.01..1.0, h in 0.01..0.1, theta in 0.0..1.0) {
        v[0] += 3.0; // keep q clear of the obstacles below
        let obstacles = [[0.0, 0.0, 1.0], [1.0, -1.5, 0.5]];
        check_all(&Se2Barrier { tau, obstacles: &obstacles }, &v, h, theta);
    }

    #[test]
    fn two_link_arm_k2(v in point(8, -1.0, 1.0), h in 0.01..0.1, theta in 0.0..1.0) {
        check_all(&Arm { a: 3.0, b: 1.0, d: 1.2, g1: 2.0, g2: 0.7 }, &v, h, theta);
    }

    #[test]
    fn minimum_jerk_k3(v in point(12, -1.0, 1.0), kappa in 0.1..2.0, h in 0.01..0.1, theta in 0.0..1.0) {
        check_all(&Jerk { kappa }, &v, h, theta);
    }

    #[test]
    fn minimum_snap_k4(v in point(24, -1.0, 1.0), h in 0.01..0.1, theta in 0.0..1.0) {
        check_all(&Snap {}, &v, h, theta);
    }

    #[test]
    fn special_functions_k2(v in point(8, -1.0, 1.0), eps in 0.25..0.5, h in 0.01..0.1, theta in 0.0..1.0) {
        check_all(&Special { eps }, &v, h, theta);
    }

    #[test]
    fn mechanical_chain_and_its_plant(v in point(12, -1.0, 1.0), h in 0.01..0.1, theta in 0.0..1.0) {
        let chain = ChainThree::new();
        check_all(&chain, &v, h, theta);
        check_all(&chain.plant(), &v, h, theta);
    }

    #[test]
    fn mechanical_well_and_its_plant(v in point(8, -1.0, 1.0), c in 0.0..1.0, h in 0.01..0.1, theta in 0.0..1.0) {
        let well = Well::new(c);
        check_all(&well, &v, h, theta);
        check_all(&well.plant(), &v, h, theta);
    }

    #[test]
    fn atan2_exp_sqrt_k2(mut v in point(8, -1.0, 1.0), alpha in -1.0..1.0, h in 0.01..0.1, theta in 0.0..1.0) {
        v[0] += 2.0; // away from the atan2 branch point at the origin
        check_all(&Transcendental { alpha }, &v, h, theta);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// n >= 7 with constant weights on the top derivative compiles (the closed-form Legendre
    /// inverse), and all derivatives match finite differences.
    #[test]
    fn dimension_seven_and_more_matches_finite_differences_and_inverts_the_momentum(v in point(48, -1.0, 1.0), kappa in 0.1..1.0, h in 0.01..0.1, theta in 0.0..1.0) {
        check_all(&Chain7 { kappa }, &v, h, theta);
        check_all(&Chain12 { kappa }, &v, h, theta);
        check_all(&Chain24 { kappa }, &v, h, theta);
        // the closed-form inverse inverts the momentum map: u = A^{-1} (p - dL/du(x, 0))
        let x = blocks::<24, 1>(&v);
        let u = SVector::<f64, 24>::from_fn(|i, _| v[24 + i]);
        let sys = Chain24 { kappa };
        let p = sys.gradient(&x, &u).u;
        let back = sys.top_derivative(&x, &p, &SVector::zeros()).expect("closed form");
        prop_assert!((back - u).amax() < 1e-12 * (1.0 + u.amax()), "{}", (back - u).amax());
    }
}

#[test]
fn generated_functions_stay_callable() {
    let l = pendulum([0.1, 0.2], [0.3, 0.4], 2.0, 9.81);
    let x = [SVector::from([0.1, 0.2])];
    let u = SVector::from([0.3, 0.4]);
    assert_eq!(l, Pendulum { m: 2.0, g: 9.81 }.lagrangian(&x, &u));
    assert_eq!(Se2Barrier::DIMENSION, 3);
    assert_eq!(Snap::STATE, 24);
    assert_eq!(Snap::UNKNOWNS, 27);
}

/// The reduced step (Newton on the nonlinear core) and the general step agree to 1e-13 over
/// 40 steps from the same states.
fn reduced_agrees<Sys, const S: usize, const M: usize, const R: usize>(
    sys: &Sys,
    jet: &[f64],
    h: f64,
) where
    Sys: retract::ReducedScheme<S, M, R>,
{
    let mut reduced = retract::ReducedStepper::new(sys);
    for theta in [0.5, 0.3, 1.0, 0.0] {
        let options = retract::StepOptions::default().with_theta(theta);
        let mut z = sys.legendre(&SVector::<f64, S>::from_column_slice(&jet[..S]));
        for i in 0..40 {
            let (general, _) = retract::step(sys, &z, h, &options).expect("general step");
            let (fast, report) = reduced.step(&z, h, &options).expect("reduced step");
            let err = (general - fast).amax() / (1.0 + general.amax());
            assert!(
                err < 1e-13,
                "theta {theta}, step {i}: reduced and general differ by {err:e}"
            );
            assert!(report.iterations <= 6);
            scaled_forcing_agrees(sys, &z, h, theta);
            z = general;
        }
    }
}

/// The generated `core_forcing` (the entries of K multiplied into the products of n) is
/// K n(y) as the product of the factors' K with the generated n(y), to rounding, at the
/// force-free guess y = G z0 of a step from `z`.
fn scaled_forcing_agrees<Sys, const S: usize, const M: usize, const R: usize>(
    sys: &Sys,
    z: &SVector<f64, S>,
    h: f64,
    theta: f64,
) where
    Sys: retract::ReducedScheme<S, M, R>,
{
    let factors = retract::ReducedFactors::new(sys, h, theta).expect("factors");
    let y = sys.core_offset(&factors, z);
    let n = sys.forcing(&y, h, theta);
    let scaled = sys.core_forcing(&factors, &y, h, theta);
    for m in 0..R {
        let terms = (0..M).map(|q| factors.k[(m, q)] * n[q]);
        let (expected, size) = terms.fold((0.0, 0.0), |(s, a), t| (s + t, a + t.abs()));
        assert!(
            (scaled[m] - expected).abs() <= 16.0 * f64::EPSILON * size,
            "theta {theta}, row {m}: K n(y) = {expected:e}, core_forcing {:e}",
            scaled[m]
        );
    }
}

/// The factors from the macro's closed form (symbolic elimination of the blocks of A) equal
/// the LU ones to rounding.
fn closed_form_agrees<Sys, const S: usize, const M: usize, const R: usize>(
    sys: &Sys,
    expected: retract::ClosedForm,
) where
    Sys: retract::ReducedScheme<S, M, R>,
{
    use retract::nalgebra::SMatrix;
    let (mut t, mut a_inv) = (SMatrix::<f64, M, S>::zeros(), SMatrix::<f64, M, M>::zeros());
    assert_eq!(
        sys.closed_form_factors(0.1, 0.5, &mut t, &mut a_inv),
        expected
    );
    for (h, theta) in [(0.01, 0.5), (0.3, 0.5), (0.05, 0.3), (0.2, 1.0), (0.1, 0.0)] {
        let closed = retract::ReducedFactors::new(sys, h, theta).expect("closed form");
        let lu = retract::ReducedFactors::factorised(sys, h, theta).expect("LU");
        let scale = 1.0 + lu.t.amax();
        assert!(
            (closed.t - lu.t).amax() < 1e-13 * scale,
            "h {h}, theta {theta}: T"
        );
        assert!((closed.a_inv - lu.a_inv).amax() < 1e-13 * (1.0 + lu.a_inv.amax()));
        assert!((closed.g - lu.g).amax() < 1e-13 * scale && (closed.k - lu.k).amax() < 1e-13);
    }
}

/// $s = \mathrm{fl}(a + b)$ and its rounding error (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let b_virtual = s - a;
    (s, (a - (s - b_virtual)) + (b - b_virtual))
}

/// $\sum_k a_k x_k + y$ in twice the working precision (every product's rounding error from a
/// fused multiply-add, every sum's from [`two_sum`]), as (high, low) parts.
fn double_double_dot(a: impl Iterator<Item = (f64, f64)>, y: f64) -> (f64, f64) {
    let (mut hi, mut lo) = (y, 0.0);
    for (a, x) in a {
        let p = a * x;
        let (s, f) = two_sum(hi, p);
        (hi, lo) = (s, lo + a.mul_add(x, -p) + f);
    }
    two_sum(hi, lo)
}

/// The factors' corrections carry their rounding errors: `t + t_lo` solves $A T = -B$ and
/// `a_inv + a_inv_lo` solves $A X = E$ (the forced unit columns) to about $u^2$, while the
/// rounded factors alone leave residuals of about $u$. Residuals in double-double: the
/// residual of $T$ is $r = A T + B$ with its low part, and that of $T + T_{lo}$ is
/// $r + A T_{lo}$; the second is below $10^{-3}$ times the first's size and below
/// $10^{-26}$ times $|A| |T| + |B|$ (the corrections from the same LU factors as the
/// factors, closed form or not).
fn corrections_solve_the_linear_part<Sys, const S: usize, const M: usize, const R: usize>(sys: &Sys)
where
    Sys: retract::ReducedScheme<S, M, R>,
{
    for (h, theta) in [(0.01, 0.5), (0.3, 0.5), (0.05, 0.3), (0.2, 1.0), (0.1, 0.0)] {
        let (a, b) = (sys.linear_part(h, theta), sys.initial_part(h, theta));
        let closed = retract::ReducedFactors::new(sys, h, theta).expect("closed form");
        let lu = retract::ReducedFactors::factorised(sys, h, theta).expect("LU");
        for f in [&closed, &lu] {
            let unit = |r: usize, q: usize| if r == q { 1.0 } else { 0.0 };
            // (x, x_lo, y) of each column: T against -B, the forced columns of A^{-1} against E
            let mut columns: Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> = (0..S)
                .map(|c| {
                    let column = |m: &SMatrix<f64, M, S>| m.column(c).iter().copied().collect();
                    (column(&f.t), column(&f.t_lo), column(&b))
                })
                .collect();
            columns.extend(Sys::FORCED.iter().map(|&q| {
                let column = |m: &SMatrix<f64, M, M>| m.column(q).iter().copied().collect();
                let e = (0..M).map(|r| -unit(r, q)).collect();
                (column(&f.a_inv), column(&f.a_inv_lo), e)
            }));
            let (mut before, mut after, mut scale) = (0.0f64, 0.0f64, 0.0f64);
            for (x, x_lo, y) in &columns {
                for i in 0..M {
                    let row = || (0..M).map(|k| a[(i, k)]);
                    let (r_hi, r_lo) = double_double_dot(row().zip(x.iter().copied()), y[i]);
                    let correction: f64 = row().zip(x_lo).map(|(a, x)| a * x).sum();
                    before = before.max(r_hi.abs());
                    after = after.max((r_hi + (r_lo + correction)).abs());
                    let size: f64 = row().zip(x).map(|(a, x)| (a * x).abs()).sum();
                    scale = scale.max(size + y[i].abs());
                }
            }
            assert!(
                after <= 1e-3 * before && after <= 1e-26 * scale,
                "h {h}, theta {theta}: residual {before:e} before the corrections, {after:e} \
                 after (scale {scale:e})"
            );
        }
    }
}

#[test]
fn the_corrections_carry_the_rounding_errors_of_the_factors() {
    corrections_solve_the_linear_part(&Pendulum { m: 1.3, g: 9.81 });
    corrections_solve_the_linear_part(&Anharmonic { w: 1.5 });
    let obstacles = [[0.0, 0.0, 1.0]];
    corrections_solve_the_linear_part(&Se2Barrier {
        tau: 0.3,
        obstacles: &obstacles,
    });
    corrections_solve_the_linear_part(&Jerk { kappa: 0.7 });
    corrections_solve_the_linear_part(&Snap {});
}

#[test]
fn closed_form_factors_equal_the_lu_ones() {
    use retract::ClosedForm::{Polynomial, Rational};
    // the mass parameter m is a pivot of the elimination: a rational closed form, checked
    closed_form_agrees(&Pendulum { m: 1.3, g: 9.81 }, Rational);
    closed_form_agrees(&Anharmonic { w: 1.5 }, Polynomial);
    let obstacles = [[0.0, 0.0, 1.0]];
    closed_form_agrees(
        &Se2Barrier {
            tau: 0.3,
            obstacles: &obstacles,
        },
        Polynomial,
    );
    // lower-order quadratic terms (0.1 |q'|^2; q'' . q''') make some pivots expressions
    closed_form_agrees(&Jerk { kappa: 0.7 }, Rational);
    closed_form_agrees(&Snap {}, Rational);
}

#[test]
fn reduced_step_is_chosen_where_it_applies() {
    // the Hessian depends on q (and q' for snap), never on the top derivative
    assert_eq!(Pendulum::REDUCED_UNKNOWNS, 2);
    assert_eq!(Anharmonic::REDUCED_UNKNOWNS, 1);
    assert_eq!(Se2Barrier::REDUCED_UNKNOWNS, 2); // x and y, not theta
    assert_eq!(Jerk::REDUCED_UNKNOWNS, 2);
    assert_eq!(Snap::REDUCED_UNKNOWNS, 6);
    // the Hessian in q'' depends on the state: the general step is kept
    assert_eq!(Arm::REDUCED_UNKNOWNS, 0);
    assert_eq!(Transcendental::REDUCED_UNKNOWNS, 0);
}

#[test]
fn reduced_and_general_steps_agree() {
    let jet: Vec<f64> = (0..24)
        .map(|i| ((i * 7 + 3) % 11) as f64 / 11.0 - 0.5)
        .collect();
    reduced_agrees(&Pendulum { m: 1.3, g: 9.81 }, &jet, 0.05);
    reduced_agrees(&Anharmonic { w: 1.5 }, &jet, 0.05);
    let obstacles = [[0.0, 0.0, 1.0], [1.0, -1.5, 0.5]];
    let mut far = jet.clone();
    far[0] += 3.0;
    reduced_agrees(
        &Se2Barrier {
            tau: 0.3,
            obstacles: &obstacles,
        },
        &far,
        0.02,
    );
    reduced_agrees(&Jerk { kappa: 0.7 }, &jet, 0.02);
    reduced_agrees(&Snap {}, &jet, 0.02);
}
