//! `#[discretization_map]`: the emitted lifts against finite differences along polynomial
//! curves (k = 1..4); the theta maps written as user maps against the built-in scheme and
//! `ThetaMap`; symplecticity, derivatives and observed order of nonlinear user maps; and the
//! paper's S^2 initial-point map, whose lifts are the paper's formulas with MATH.md slip 5
//! corrected.

use crate::common;

use common::models::bounded_pais_uhlenbeck;
use common::rk4_final;

use retract::diagnostics::canonical_structure;
use retract::lifted::Blocks;
use retract::map::{self, BlockMatrix, DiscretizationMap, ThetaMap};
use retract::nalgebra::{SMatrix, SVector, Vector3};
use retract::{
    Lagrangian, LiftedSystem, NewtonOptions, StepOptions, discretization_map,
    higher_order_lagrangian,
};

/// The same nonlinear map of (q, v) on R^2 (q and v mixed, exponential in v) at order $k.
macro_rules! wavy {
    ($name:ident, $k:tt) => {
        #[discretization_map(order = $k)]
        fn $name(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {
            let s = (q[0] * q[1]).sin();
            let e = (c * v[0]).exp() - 1.0 - c * v[0];
            let m = v[0] * v[1] * q[0].cos();
            (
                [
                    q[0] - 0.5 * v[0] + c * s * v[1] * v[1],
                    q[1] - 0.5 * v[1] + m,
                ],
                [
                    q[0] + 0.5 * v[0] + c * s * v[1] * v[1] + e,
                    q[1] + 0.5 * v[1] + m * q[1],
                ],
            )
        }
    };
}

wavy!(wavy1, 1);
wavy!(wavy2, 2);
wavy!(wavy3, 3);
wavy!(wavy4, 4);

/// A deterministic pseudo-random number in [-1, 1).
fn noise(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(2862933555777941757)
        .wrapping_add(3037000493);
    (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// Weights of the central 9-point stencil for the `order`-th derivative at 0 on nodes -4..=4
/// (unit spacing): the solution of sum_i w_i x_i^p = p! [p = order], p = 0..=8.
fn stencil(order: usize) -> SVector<f64, 9> {
    let a = SMatrix::<f64, 9, 9>::from_fn(|p, i| (i as f64 - 4.0).powi(p as i32));
    let mut rhs = SVector::<f64, 9>::zeros();
    rhs[order] = (1..=order).product::<usize>() as f64;
    a.lu().solve(&rhs).expect("Vandermonde")
}

type MapFn = fn([f64; 2], [f64; 2], f64) -> ([f64; 2], [f64; 2]);

/// Along q(t) = sum_m a_m t^m and v(t) = sum_m b_m t^m (degree 4), block j of the emitted
/// lifted points at the jets of the curves at t = 0 (x_j = j! a_j, xi_j = j! b_j) against
/// the j-th t-derivative of R(q(t), v(t)) by the 9-point stencil.
fn lift_matches_curves<const K: usize>(map: &impl DiscretizationMap<2, K>, f: MapFn, c: f64) {
    let mut seed = 3 + K as u64;
    for _curve in 0..3 {
        let a: [[f64; 2]; 5] = core::array::from_fn(|_| [noise(&mut seed), noise(&mut seed)]);
        let b: [[f64; 2]; 5] =
            core::array::from_fn(|_| [0.5 * noise(&mut seed), 0.5 * noise(&mut seed)]);
        let at = |coef: &[[f64; 2]; 5], t: f64| -> [f64; 2] {
            core::array::from_fn(|i| (0..5).map(|m| coef[m][i] * t.powi(m as i32)).sum())
        };
        let factorial = |j: usize| (1..=j).product::<usize>() as f64;
        let x: Blocks<2, K> = core::array::from_fn(|j| SVector::from(a[j]) * factorial(j));
        let xi: Blocks<2, K> = core::array::from_fn(|j| SVector::from(b[j]) * factorial(j));
        let (r1, r2) = map.points(&x, &xi);
        let h = 0.02;
        for j in 0..K {
            let w = stencil(j);
            let mut fd = [[0.0; 2]; 2];
            for (i, wi) in w.iter().enumerate() {
                let t = (i as f64 - 4.0) * h;
                let (p1, p2) = f(at(&a, t), at(&b, t), c);
                for comp in 0..2 {
                    fd[0][comp] += wi * p1[comp] / h.powi(j as i32);
                    fd[1][comp] += wi * p2[comp] / h.powi(j as i32);
                }
            }
            for comp in 0..2 {
                for (side, emitted) in [(0, r1[j][comp]), (1, r2[j][comp])] {
                    let numeric = fd[side][comp];
                    assert!(
                        (numeric - emitted).abs() < 1e-7 * (1.0 + emitted.abs()),
                        "k = {K}, D^{j} R{}[{comp}]: emitted {emitted}, differences {numeric}",
                        side + 1
                    );
                }
            }
        }
    }
}

#[test]
fn lifts_are_total_derivatives_along_polynomial_curves() {
    let c = 0.7;
    lift_matches_curves(&Wavy1::new(c), wavy1, c);
    lift_matches_curves(&Wavy2::new(c), wavy2, c);
    lift_matches_curves(&Wavy3::new(c), wavy3, c);
    lift_matches_curves(&Wavy4::new(c), wavy4, c);
}

/// The theta map on R^2 as a user map, at order $k.
macro_rules! theta_map {
    ($name:ident, $k:tt) => {
        #[discretization_map(order = $k)]
        fn $name(q: [f64; 2], v: [f64; 2], theta: f64) -> ([f64; 2], [f64; 2]) {
            (
                [q[0] - theta * v[0], q[1] - theta * v[1]],
                [q[0] + (1.0 - theta) * v[0], q[1] + (1.0 - theta) * v[1]],
            )
        }
    };
}

theta_map!(theta1, 1);
theta_map!(theta2, 2);
theta_map!(theta3, 3);

/// The theta map on a line (q: f64) at order 4.
#[discretization_map(order = 4)]
fn theta_line(q: f64, v: f64, theta: f64) -> (f64, f64) {
    (q - theta * v, q + (1.0 - theta) * v)
}

/// k = 1: a quartic-coupled oscillator pair.
#[higher_order_lagrangian(order = 1)]
fn coupled(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * (dq[0] * dq[0] + dq[1] * dq[1])
        - 0.5 * (q[0] * q[0] + q[1] * q[1])
        - 0.1 * (q[0] * q[1]).powi(2)
}

/// k = 3: minimum jerk in a periodic potential.
#[higher_order_lagrangian(order = 3)]
fn jerk_wave(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], dddq: [f64; 2]) -> f64 {
    0.5 * (dddq[0] * dddq[0] + dddq[1] * dddq[1])
        + 0.3 * (q[0] + 0.5 * q[1]).cos()
        + 0.05 * ddq[1].powi(2)
}

/// k = 4: minimum snap on a line in a cosine well.
#[higher_order_lagrangian(order = 4)]
fn snap_well(q: f64, dq: f64, _ddq: f64, _dddq: f64, d4q: f64) -> f64 {
    0.5 * d4q * d4q - 0.2 * q.cos() + 0.1 * dq * dq
}

/// `map::step` with the user theta map against the built-in step, from the same state along
/// 10 built-in steps, both solved to rounding; and the user map's Jacobians and covector
/// Hessian against `ThetaMap`'s at a random point.
fn user_theta_is_built_in<
    Sys,
    Map,
    const N: usize,
    const K: usize,
    const S: usize,
    const M: usize,
>(
    system: &Sys,
    user: &Map,
    theta: f64,
    z0: &SVector<f64, S>,
) where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    Map: DiscretizationMap<N, K>,
{
    let newton = NewtonOptions::default().with_residual_tolerance(1e-16, 0.0);
    let options = StepOptions::default().with_theta(theta).with_newton(newton);
    let mut z = *z0;
    for i in 0..10 {
        let (built_in, _) = retract::step(system, &z, 0.05, &options).expect("built-in step");
        let (user_step, _) = map::step(system, user, &z, 0.05, &newton).expect("map step");
        let gap = (user_step - built_in).amax() / built_in.amax();
        assert!(gap < 1e-14, "k = {K}, step {i}: relative gap {gap:e}");
        z = built_in;
    }
    let mut seed = 17;
    let mut blocks =
        || -> Blocks<N, K> { core::array::from_fn(|_| SVector::from_fn(|_, _| noise(&mut seed))) };
    let (x, xi, w1, w2) = (blocks(), blocks(), blocks(), blocks());
    let reference = ThetaMap { theta };
    assert_eq!(user.points(&x, &xi), reference.points(&x, &xi));
    assert_eq!(user.jacobians(&x, &xi), reference.jacobians(&x, &xi));
    assert_eq!(
        user.covector_hessian(&x, &xi, &w1, &w2),
        reference.covector_hessian(&x, &xi, &w1, &w2)
    );
}

#[test]
fn theta_maps_as_user_maps_reproduce_the_built_in_scheme_for_k_1_to_4() {
    for theta in [0.5, 0.3] {
        let z1 = SVector::<f64, 4>::from([0.4, -0.3, 0.2, 0.5]);
        user_theta_is_built_in(&Coupled {}, &Theta1::new(theta), theta, &z1);
        let (pais, z2) = bounded_pais_uhlenbeck();
        user_theta_is_built_in(&pais, &Theta2::new(theta), theta, &z2);
        let jet3 = SVector::<f64, 12>::from_fn(|r, _| 0.1 * (r as f64 + 1.0).cos());
        user_theta_is_built_in(
            &JerkWave {},
            &Theta3::new(theta),
            theta,
            &JerkWave {}.legendre(&jet3),
        );
        let jet4 = SVector::<f64, 8>::from_fn(|r, _| 0.2 * (r as f64 + 0.5).sin());
        user_theta_is_built_in(
            &SnapWell {},
            &ThetaLine::new(theta),
            theta,
            &SnapWell {}.legendre(&jet4),
        );
    }
}

#[discretization_map(order = 2)]
fn bent_midpoint(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {
    let s = c * q[0].sin();
    (
        [
            q[0] - 0.5 * v[0] + s * v[0] * v[0],
            q[1] - 0.5 * v[1] + s * v[1] * v[1],
        ],
        [
            q[0] + 0.5 * v[0] + s * v[0] * v[0],
            q[1] + 0.5 * v[1] + s * v[1] * v[1],
        ],
    )
}

/// Symmetric (tanh is odd, the coupling even in v): R_d(q, -v) = (R2, R1)(q, v).
#[discretization_map(order = 2)]
fn tanh_midpoint(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {
    let t0 = (0.5 * v[0]).tanh();
    let t1 = (0.5 * v[1]).tanh();
    let even = c * q[1] * v[0] * v[1];
    (
        [q[0] - t0 + even, q[1] - t1 - even],
        [q[0] + t0 + even, q[1] + t1 - even],
    )
}

/// Not symmetric: R1 moves quadratically only, R2 by v plus terms that depend on q.
#[discretization_map(order = 2)]
fn skew(q: [f64; 2], v: [f64; 2], c: f64, d: f64) -> ([f64; 2], [f64; 2]) {
    let quad0 = c * v[0] * v[1];
    let quad1 = c * v[0] * v[0];
    let bend = d * q[1].sin();
    (
        [q[0] + quad0, q[1] + quad1],
        [
            q[0] + v[0] + quad0 + bend * v[1] * v[1],
            q[1] + v[1] + quad1 + bend * v[0] * v[1],
        ],
    )
}

/// The flat index `c` of (x, xi) in R^{2nk} moved by `e`.
fn bumped<const N: usize, const K: usize>(
    x: &Blocks<N, K>,
    xi: &Blocks<N, K>,
    c: usize,
    e: f64,
) -> (Blocks<N, K>, Blocks<N, K>) {
    let (mut x, mut xi) = (*x, *xi);
    let nk = N * K;
    let target = if c < nk { &mut x } else { &mut xi };
    target[(c % nk) / N][c % N] += e;
    (x, xi)
}

fn entry<const N: usize, const K: usize>(m: &BlockMatrix<N, K>, r: usize, c: usize) -> f64 {
    m[r / N][c / N][(r % N, c % N)]
}

/// The emitted Jacobians against central differences of `points`, and the covector Hessian
/// against second differences of phi = w2 . R2 - w1 . R1 (computed from `points` only).
fn derivatives_match_points<const N: usize, const K: usize>(map: &impl DiscretizationMap<N, K>) {
    let mut seed = 29;
    let mut blocks = |s: f64| -> Blocks<N, K> {
        core::array::from_fn(|_| SVector::from_fn(|_, _| s * noise(&mut seed)))
    };
    let (x, xi, w1, w2) = (blocks(1.0), blocks(0.4), blocks(1.0), blocks(1.0));
    let nk = N * K;
    let jac = map.jacobians(&x, &xi);
    let hess = map.covector_hessian(&x, &xi, &w1, &w2);
    let phi = |(x, xi): (Blocks<N, K>, Blocks<N, K>)| {
        let (r1, r2) = map.points(&x, &xi);
        (0..K)
            .map(|j| w2[j].dot(&r2[j]) - w1[j].dot(&r1[j]))
            .sum::<f64>()
    };
    let e = 1e-6;
    for c in 0..2 * nk {
        let plus = map.points(&bumped(&x, &xi, c, e).0, &bumped(&x, &xi, c, e).1);
        let minus = map.points(&bumped(&x, &xi, c, -e).0, &bumped(&x, &xi, c, -e).1);
        let (j1, j2) = if c < nk {
            (&jac.r1_x, &jac.r2_x)
        } else {
            (&jac.r1_xi, &jac.r2_xi)
        };
        for r in 0..nk {
            let fd1 = (plus.0[r / N][r % N] - minus.0[r / N][r % N]) / (2.0 * e);
            let fd2 = (plus.1[r / N][r % N] - minus.1[r / N][r % N]) / (2.0 * e);
            let (ex1, ex2) = (entry(j1, r, c % nk), entry(j2, r, c % nk));
            assert!(
                (fd1 - ex1).abs() < 1e-7 * (1.0 + ex1.abs()),
                "dR1[{r}]/d{c}: {fd1} vs {ex1}"
            );
            assert!(
                (fd2 - ex2).abs() < 1e-7 * (1.0 + ex2.abs()),
                "dR2[{r}]/d{c}: {fd2} vs {ex2}"
            );
        }
    }
    let e = 1e-4;
    for r in 0..2 * nk {
        for c in 0..2 * nk {
            let shifted = |a: f64, b: f64| {
                let (x1, xi1) = bumped(&x, &xi, r, a);
                phi(bumped(&x1, &xi1, c, b))
            };
            let fd =
                (shifted(e, e) - shifted(e, -e) - shifted(-e, e) + shifted(-e, -e)) / (4.0 * e * e);
            let exact = match (r < nk, c < nk) {
                (true, true) => entry(&hess.xx, r, c),
                (true, false) => entry(&hess.x_xi, r, c - nk),
                (false, true) => entry(&hess.x_xi, c, r - nk),
                (false, false) => entry(&hess.xi_xi, r - nk, c - nk),
            };
            assert!(
                (fd - exact).abs() < 1e-5 * (1.0 + exact.abs()),
                "phi hessian ({r}, {c}): {fd} vs {exact}"
            );
        }
    }
}

#[test]
fn emitted_derivatives_are_those_of_the_points() {
    derivatives_match_points(&BentMidpoint::new(0.6));
    derivatives_match_points(&TanhMidpoint::new(0.8));
    derivatives_match_points(&Skew::new(0.7, -0.5));
    derivatives_match_points(&Wavy1::new(0.7));
    derivatives_match_points(&Wavy3::new(0.7));
    derivatives_match_points(&Wavy4::new(-0.4));
}

/// |DPsi^T J DPsi - J|_max of one step of `map` on the bounded Pais-Uhlenbeck oscillator.
fn symplecticity(map: &impl DiscretizationMap<2, 2>, h: f64) -> f64 {
    let (pais, z0) = bounded_pais_uhlenbeck();
    let d = map::step_map_derivative(&pais, map, &z0, h, &NewtonOptions::default())
        .expect("the step converges");
    let j = canonical_structure::<8>();
    (d.transpose() * j * d - j).amax()
}

#[test]
fn nonlinear_user_maps_give_symplectic_steps() {
    for h in [0.1, 0.3] {
        let errors = [
            symplecticity(&BentMidpoint::new(0.6), h),
            symplecticity(&TanhMidpoint::new(0.8), h),
            symplecticity(&Skew::new(0.7, -0.5), h),
            symplecticity(&Wavy2::new(0.7), h),
        ];
        assert!(errors.iter().all(|&e| e < 1e-12), "h = {h}: {errors:?}");
    }
}

/// The observed order of `map` on the bounded Pais-Uhlenbeck oscillator at T = 1 from steps
/// h = 0.1 / 2^j, j = 0..4, against RK4 with h = 1e-3: log2 of the last error ratio.
fn observed_order(map: &impl DiscretizationMap<2, 2>) -> f64 {
    let (pais, z0) = bounded_pais_uhlenbeck();
    let reference = rk4_final(&pais, &z0, 1.0, 1000);
    let error = |steps: usize| {
        let h = 1.0 / steps as f64;
        let mut z = z0;
        for _ in 0..steps {
            z = map::step(&pais, map, &z, h, &NewtonOptions::default())
                .expect("step")
                .0;
        }
        (z - reference).amax()
    };
    (error(40) / error(80)).log2()
}

#[test]
fn symmetric_user_maps_have_order_two_and_others_order_one() {
    for (what, order, expected) in [
        (
            "bent midpoint",
            observed_order(&BentMidpoint::new(0.6)),
            2.0,
        ),
        (
            "tanh midpoint",
            observed_order(&TanhMidpoint::new(0.8)),
            2.0,
        ),
        ("skew", observed_order(&Skew::new(0.7, -0.5)), 1.0),
        ("theta 0.3", observed_order(&Theta2::new(0.3)), 1.0),
    ] {
        assert!(
            (order - expected).abs() < 0.1,
            "{what}: observed order {order}, expected {expected}"
        );
    }
}

/// The paper's initial-point map on S^2 in ambient coordinates, R_d(q, xi) = (q, (q + xi) /
/// |q + xi|): a discretization map on TS^2 only (R2(q, 0) = q / |q|), hence `check = false`.
#[discretization_map(order = 3, check = false)]
fn sphere_initial(q: [f64; 3], xi: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let r = ((q[0] + xi[0]).powi(2) + (q[1] + xi[1]).powi(2) + (q[2] + xi[2]).powi(2)).sqrt();
    (
        [q[0], q[1], q[2]],
        [(q[0] + xi[0]) / r, (q[1] + xi[1]) / r, (q[2] + xi[2]) / r],
    )
}

/// A 2-jet of a curve (q(t), xi(t)) in TS^2: |q| = 1 and q . xi = 0 with their first and
/// second derivatives, from random vectors.
fn sphere_jet(seed: &mut u64) -> ([Vector3<f64>; 3], [Vector3<f64>; 3]) {
    let mut random = || Vector3::from_fn(|_, _| noise(seed));
    let q = random().normalize();
    let tangent = |v: Vector3<f64>| v - q * q.dot(&v);
    let dq = tangent(random());
    let ddq = tangent(random()) - q * dq.norm_squared(); // q . q'' = -|q'|^2
    let xi = tangent(random()) * 0.6;
    let dxi = tangent(random()) - q * dq.dot(&xi); // q' . xi + q . xi' = 0
    let ddxi_t = tangent(random());
    // q'' . xi + 2 q' . xi' + q . xi'' = 0
    let ddxi = ddxi_t - q * (ddq.dot(&xi) + 2.0 * dq.dot(&dxi));
    ([q, dq, ddq], [xi, dxi, ddxi])
}

#[test]
fn the_sphere_initial_point_map_lifts_as_the_paper_says_with_slip_5_corrected() {
    let map = SphereInitial {};
    let mut seed = 41;
    let mut largest_printed_gap: f64 = 0.0;
    for _ in 0..20 {
        let ([q, dq, ddq], [xi, dxi, ddxi]) = sphere_jet(&mut seed);
        assert!((q.norm() - 1.0).abs() < 1e-15 && q.dot(&xi).abs() < 1e-15);
        let (r1, r2) = map.points(&[q, dq, ddq], &[xi, dxi, ddxi]);
        let (r, dr, ddr) = (q + xi, dq + dxi, ddq + ddxi);
        let rho = r.norm();
        let s = xi.dot(&dxi); // = r . r' on TS^2
        // first lift (MATH.md): (q, q', r/|r|, r'/|r| - (xi . xi') r/|r|^3)
        let first = dr / rho - r * (s / rho.powi(3));
        // second lift: the derivative of the first, with (r . r')' = |xi'|^2 + xi . xi''
        let ds = dxi.norm_squared() + xi.dot(&ddxi);
        let common = ddr / rho - dr * (2.0 * s / rho.powi(3)) - r * (ds / rho.powi(3));
        let corrected = common + r * (3.0 * s * s / rho.powi(5));
        let printed = common + r * (3.0 * s / rho.powi(5));
        assert_eq!((r1[0], r1[1], r1[2]), (q, dq, ddq));
        assert!((r2[0] - r / rho).amax() < 1e-15);
        assert!(
            (r2[1] - first).amax() < 1e-13,
            "{:e}",
            (r2[1] - first).amax()
        );
        assert!(
            (r2[2] - corrected).amax() < 1e-12,
            "{:e}",
            (r2[2] - corrected).amax()
        );
        largest_printed_gap = largest_printed_gap.max((r2[2] - printed).amax());
    }
    assert!(
        largest_printed_gap > 1e-2,
        "the printed formula: {largest_printed_gap:e}"
    );
}
