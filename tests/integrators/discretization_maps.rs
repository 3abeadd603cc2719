//! The integrator of a general discretization map (`retract::map`, paper Prop. 5.1): the
//! theta map reproduces the built-in scheme for k = 1..4, nonlinear maps give symplectic
//! steps of order 2 when symmetric and 1 otherwise, and the Newton Jacobian is the derivative
//! of the residual.

use crate::common;

use common::models::bounded_pais_uhlenbeck;

use retract::diagnostics::{canonical_structure, rk4_step};
use retract::lifted::Blocks;
use retract::map::{
    self, BlockMatrix, CovectorHessian, DiscretizationMap, MapJacobians, MapScheme, ThetaMap,
};
use retract::nalgebra::{SMatrix, SVector};
use retract::newton::Problem;
use retract::{Error, LiftedSystem, NewtonOptions, StepOptions, higher_order_lagrangian};

/// k = 1: two coupled pendulums, L = 1/2 |q'|^2 + cos q0 + 1/2 cos(q0 - q1).
#[higher_order_lagrangian(order = 1)]
fn pendulums(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * (dq[0].powi(2) + dq[1].powi(2)) + q[0].cos() + 0.5 * (q[0] - q[1]).cos()
}

/// k = 3: minimum jerk with a potential.
#[higher_order_lagrangian(order = 3)]
fn jerk(q: [f64; 2], dq: [f64; 2], _ddq: [f64; 2], dddq: [f64; 2], kappa: f64) -> f64 {
    0.5 * (dddq[0].powi(2) + dddq[1].powi(2)) + kappa * (q[0] * q[1]).sin() + 0.1 * dq[0].powi(2)
}

/// k = 4: minimum snap on a line with a quartic potential.
#[higher_order_lagrangian(order = 4)]
fn snap(q: [f64; 1], _dq: [f64; 1], ddq: [f64; 1], _dddq: [f64; 1], d4q: [f64; 1]) -> f64 {
    0.5 * d4q[0].powi(2) + 0.2 * ddq[0].powi(2) - 0.1 * q[0].powi(4)
}

fn zeros<const N: usize, const K: usize>() -> BlockMatrix<N, K> {
    [[SMatrix::zeros(); K]; K]
}

fn identity<const N: usize, const K: usize>(c: f64) -> BlockMatrix<N, K> {
    let mut m = zeros::<N, K>();
    for (j, row) in m.iter_mut().enumerate() {
        row[j] = SMatrix::identity() * c;
    }
    m
}

/// The quadratic maps lifted to k <= 2: with Q(xi) = (v o v, 2 v o v') (o: entrywise),
/// symmetric: R1 = x - xi/2 + c Q, R2 = x + xi/2 + c Q (R_d(x, -xi) = (R2, R1)(x, xi));
/// one-sided: R1 = x, R2 = x + xi + c Q.
struct Quadratic {
    c: f64,
    symmetric: bool,
}

impl Quadratic {
    fn quad<const N: usize, const K: usize>(xi: &Blocks<N, K>) -> Blocks<N, K> {
        core::array::from_fn(|j| match j {
            0 => xi[0].component_mul(&xi[0]),
            _ => xi[0].component_mul(&xi[1]) * 2.0,
        })
    }

    /// dQ/dxi.
    fn quad_jacobian<const N: usize, const K: usize>(xi: &Blocks<N, K>) -> BlockMatrix<N, K> {
        let mut m = zeros::<N, K>();
        m[0][0] = SMatrix::from_diagonal(&(xi[0] * 2.0));
        if K > 1 {
            m[1][0] = SMatrix::from_diagonal(&(xi[1] * 2.0));
            m[1][1] = SMatrix::from_diagonal(&(xi[0] * 2.0));
        }
        m
    }
}

impl<const N: usize, const K: usize> DiscretizationMap<N, K> for Quadratic {
    fn points(&self, x: &Blocks<N, K>, xi: &Blocks<N, K>) -> (Blocks<N, K>, Blocks<N, K>) {
        assert!(K <= 2);
        let q = Self::quad(xi);
        if self.symmetric {
            (
                core::array::from_fn(|j| x[j] - xi[j] * 0.5 + q[j] * self.c),
                core::array::from_fn(|j| x[j] + xi[j] * 0.5 + q[j] * self.c),
            )
        } else {
            (*x, core::array::from_fn(|j| x[j] + xi[j] + q[j] * self.c))
        }
    }

    fn jacobians(&self, _x: &Blocks<N, K>, xi: &Blocks<N, K>) -> MapJacobians<N, K> {
        let dq = Self::quad_jacobian(xi);
        let plus = |m: BlockMatrix<N, K>| -> BlockMatrix<N, K> {
            core::array::from_fn(|i| core::array::from_fn(|j| m[i][j] + dq[i][j] * self.c))
        };
        let (r1_xi, r2_xi) = if self.symmetric {
            (plus(identity(-0.5)), plus(identity(0.5)))
        } else {
            (zeros(), plus(identity(1.0)))
        };
        MapJacobians {
            r1_x: identity(1.0),
            r1_xi,
            r2_x: identity(1.0),
            r2_xi,
        }
    }

    fn covector_hessian(
        &self,
        _x: &Blocks<N, K>,
        _xi: &Blocks<N, K>,
        w1: &Blocks<N, K>,
        w2: &Blocks<N, K>,
    ) -> CovectorHessian<N, K> {
        // the curvature is that of c d . Q(xi), d = w2 - w1 (symmetric) or w2 (one-sided)
        let d: Blocks<N, K> =
            core::array::from_fn(|j| if self.symmetric { w2[j] - w1[j] } else { w2[j] });
        let mut xi_xi = zeros::<N, K>();
        xi_xi[0][0] = SMatrix::from_diagonal(&(d[0] * (2.0 * self.c)));
        if K > 1 {
            xi_xi[0][1] = SMatrix::from_diagonal(&(d[1] * (2.0 * self.c)));
            xi_xi[1][0] = xi_xi[0][1];
        }
        CovectorHessian {
            xx: zeros(),
            x_xi: zeros(),
            xi_xi,
        }
    }
}

/// A symmetric map that depends on the base point, k = 1:
/// R_a = q -/+ v/2 + c sin(q_0) (v o v); its Jacobian in q is not symmetric.
struct Bent {
    c: f64,
}

impl<const N: usize> DiscretizationMap<N, 1> for Bent {
    fn points(&self, x: &Blocks<N, 1>, xi: &Blocks<N, 1>) -> (Blocks<N, 1>, Blocks<N, 1>) {
        let bend = xi[0].component_mul(&xi[0]) * (self.c * x[0][0].sin());
        ([x[0] - xi[0] * 0.5 + bend], [x[0] + xi[0] * 0.5 + bend])
    }

    fn jacobians(&self, x: &Blocks<N, 1>, xi: &Blocks<N, 1>) -> MapJacobians<N, 1> {
        let mut r_x = SMatrix::<f64, N, N>::identity();
        let column = xi[0].component_mul(&xi[0]) * (self.c * x[0][0].cos());
        r_x.set_column(0, &(r_x.column(0) + column));
        let dv = SMatrix::from_diagonal(&(xi[0] * (2.0 * self.c * x[0][0].sin())));
        let half = SMatrix::<f64, N, N>::identity() * 0.5;
        MapJacobians {
            r1_x: [[r_x]],
            r1_xi: [[dv - half]],
            r2_x: [[r_x]],
            r2_xi: [[dv + half]],
        }
    }

    fn covector_hessian(
        &self,
        x: &Blocks<N, 1>,
        xi: &Blocks<N, 1>,
        w1: &Blocks<N, 1>,
        w2: &Blocks<N, 1>,
    ) -> CovectorHessian<N, 1> {
        // phi = (w2 - w1) . q + (w2 + w1) . v / 2 + c sin(q_0) sum_a d_a v_a^2
        let d = w2[0] - w1[0];
        let (s, c) = (x[0][0].sin(), x[0][0].cos());
        let mut xx = SMatrix::<f64, N, N>::zeros();
        xx[(0, 0)] = -self.c * s * d.dot(&xi[0].component_mul(&xi[0]));
        let mut x_xi = SMatrix::<f64, N, N>::zeros();
        x_xi.set_row(
            0,
            &(d.component_mul(&xi[0]) * (2.0 * self.c * c)).transpose(),
        );
        CovectorHessian {
            xx: [[xx]],
            x_xi: [[x_xi]],
            xi_xi: [[SMatrix::from_diagonal(&(d * (2.0 * self.c * s)))]],
        }
    }
}

/// A deterministic pseudo-random number in [-1, 1).
fn noise(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

fn random_blocks<const N: usize, const K: usize>(seed: &mut u64, scale: f64) -> Blocks<N, K> {
    core::array::from_fn(|_| SVector::from_fn(|_, _| scale * noise(seed)))
}

fn flat<const N: usize, const K: usize>(m: &BlockMatrix<N, K>, r: usize, c: usize) -> f64 {
    m[r / N][c / N][(r % N, c % N)]
}

/// The map's Jacobians and covector Hessian against central differences of its points.
fn check_map_derivatives<const N: usize, const K: usize>(map: &impl DiscretizationMap<N, K>) {
    let mut seed = 7;
    let x = random_blocks::<N, K>(&mut seed, 1.0);
    let xi = random_blocks::<N, K>(&mut seed, 0.3);
    let (w1, w2) = (random_blocks(&mut seed, 1.0), random_blocks(&mut seed, 1.0));
    let jac = map.jacobians(&x, &xi);
    let hess = map.covector_hessian(&x, &xi, &w1, &w2);
    let eps = 1e-6;
    let bump = |b: &Blocks<N, K>, c: usize, e: f64| {
        let mut out = *b;
        out[c / N][c % N] += e;
        out
    };
    // the gradient of phi = w2 . R2 - w1 . R1 in (x, xi) from the Jacobians
    let gradient = |x: &Blocks<N, K>, xi: &Blocks<N, K>| {
        let j = map.jacobians(x, xi);
        let g = |a: &BlockMatrix<N, K>, b: &BlockMatrix<N, K>, r: usize| {
            (0..N * K)
                .map(|i| flat(b, i, r) * w2[i / N][i % N] - flat(a, i, r) * w1[i / N][i % N])
                .sum::<f64>()
        };
        let gx: Vec<f64> = (0..N * K).map(|r| g(&j.r1_x, &j.r2_x, r)).collect();
        let gxi: Vec<f64> = (0..N * K).map(|r| g(&j.r1_xi, &j.r2_xi, r)).collect();
        (gx, gxi)
    };
    for c in 0..N * K {
        for (wrt_xi, fd_jac) in [
            (false, [&jac.r1_x, &jac.r2_x]),
            (true, [&jac.r1_xi, &jac.r2_xi]),
        ] {
            let (plus, minus) = if wrt_xi {
                (
                    map.points(&x, &bump(&xi, c, eps)),
                    map.points(&x, &bump(&xi, c, -eps)),
                )
            } else {
                (
                    map.points(&bump(&x, c, eps), &xi),
                    map.points(&bump(&x, c, -eps), &xi),
                )
            };
            for r in 0..N * K {
                for (a, (p, m)) in [(plus.0, minus.0), (plus.1, minus.1)].iter().enumerate() {
                    let fd = (p[r / N][r % N] - m[r / N][r % N]) / (2.0 * eps);
                    let exact = flat(fd_jac[a], r, c);
                    assert!(
                        (fd - exact).abs() < 1e-7,
                        "dR{}/d{}: {fd} vs {exact}",
                        a + 1,
                        c
                    );
                }
            }
            let (gp, gm) = if wrt_xi {
                (
                    gradient(&x, &bump(&xi, c, eps)),
                    gradient(&x, &bump(&xi, c, -eps)),
                )
            } else {
                (
                    gradient(&bump(&x, c, eps), &xi),
                    gradient(&bump(&x, c, -eps), &xi),
                )
            };
            for r in 0..N * K {
                // row x_r or xi_r of the Hessian, column c of x or xi
                let fd_x = (gp.0[r] - gm.0[r]) / (2.0 * eps);
                let fd_xi = (gp.1[r] - gm.1[r]) / (2.0 * eps);
                let (ex, exi) = if wrt_xi {
                    (flat(&hess.x_xi, r, c), flat(&hess.xi_xi, r, c))
                } else {
                    (flat(&hess.xx, r, c), flat(&hess.x_xi, c, r))
                };
                assert!((fd_x - ex).abs() < 1e-7, "phi hessian x{r}: {fd_x} vs {ex}");
                assert!(
                    (fd_xi - exi).abs() < 1e-7,
                    "phi hessian xi{r}: {fd_xi} vs {exi}"
                );
            }
        }
    }
}

#[test]
fn the_test_maps_have_the_derivatives_they_claim() {
    for symmetric in [true, false] {
        let map = Quadratic { c: 0.7, symmetric };
        check_map_derivatives::<2, 1>(&map);
        check_map_derivatives::<2, 2>(&map);
    }
    check_map_derivatives::<2, 1>(&Bent { c: 0.6 });
    check_map_derivatives::<3, 1>(&Bent { c: -0.4 });
}

/// The Newton Jacobian of the map scheme against central differences of its residual.
fn check_scheme_jacobian<Sys, Map, const N: usize, const K: usize, const M: usize>(
    system: &Sys,
    map: &Map,
) where
    Sys: retract::Lagrangian<N, K>,
    Map: DiscretizationMap<N, K>,
{
    let mut seed = 11;
    let scheme = MapScheme {
        system,
        map,
        x0: random_blocks(&mut seed, 0.5),
        p0: random_blocks(&mut seed, 0.5),
        h: 0.13,
    };
    let w = SVector::<f64, M>::from_fn(|_, _| 0.5 * noise(&mut seed));
    let jac = scheme.jacobian(&w);
    let eps = 1e-6;
    for c in 0..M {
        let mut plus = w;
        plus[c] += eps;
        let mut minus = w;
        minus[c] -= eps;
        let fd = (scheme.residual(&plus) - scheme.residual(&minus)) / (2.0 * eps);
        for r in 0..M {
            assert!(
                (fd[r] - jac[(r, c)]).abs() < 1e-6 * (1.0 + jac[(r, c)].abs()),
                "dF{r}/dw{c}: finite difference {} against {}",
                fd[r],
                jac[(r, c)]
            );
        }
    }
}

#[test]
fn the_newton_jacobian_is_the_derivative_of_the_residual() {
    let pendulums = Pendulums {};
    let (pais, _) = bounded_pais_uhlenbeck();
    for symmetric in [true, false] {
        let map = Quadratic { c: 0.7, symmetric };
        check_scheme_jacobian::<_, _, 2, 1, 6>(&pendulums, &map);
        check_scheme_jacobian::<_, _, 2, 2, 10>(&pais, &map);
    }
    check_scheme_jacobian::<_, _, 2, 1, 6>(&pendulums, &Bent { c: 0.6 });
    check_scheme_jacobian::<_, _, 2, 2, 10>(&pais, &ThetaMap { theta: 0.3 });
}

/// The theta map through `map::step` against the built-in step, step by step from the same
/// state along 20 steps of the built-in scheme.
fn theta_map_matches<Sys, const N: usize, const K: usize, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
) where
    Sys: retract::Lagrangian<N, K> + LiftedSystem<S, M>,
{
    // both solved to rounding: the residual to 1e-16 (the step test ends Newton there)
    let newton = NewtonOptions::default().with_residual_tolerance(1e-16, 0.0);
    for theta in [0.5, 0.3] {
        let mut z = *z0;
        for i in 0..20 {
            let a = map::step(system, &ThetaMap { theta }, &z, h, &newton)
                .unwrap_or_else(|e| panic!("map step {i}: {e}"))
                .0;
            let options = StepOptions::default().with_theta(theta).with_newton(newton);
            let b = retract::step(system, &z, h, &options)
                .unwrap_or_else(|e| panic!("built-in step {i}: {e}"))
                .0;
            let difference = (a - b).amax() / b.amax();
            assert!(
                difference < 1e-14,
                "k = {K}, theta = {theta}, step {i}: relative difference {difference:e}"
            );
            z = b;
        }
    }
}

#[test]
fn the_theta_map_reproduces_the_built_in_scheme_for_k_1_to_4() {
    let z1 = SVector::<f64, 4>::from([0.4, -0.3, 0.2, 0.5]);
    theta_map_matches::<_, 2, 1, 4, 6>(&Pendulums {}, &z1, 0.05);
    let (pais, z2) = bounded_pais_uhlenbeck();
    theta_map_matches::<_, 2, 2, 8, 10>(&pais, &z2, 0.05);
    let jerk = Jerk { kappa: 0.3 };
    let z3 = jerk.legendre(&SVector::<f64, 12>::from_fn(|r, _| {
        0.1 * (r as f64 + 1.0).sin()
    }));
    theta_map_matches::<_, 2, 3, 12, 14>(&jerk, &z3, 0.05);
    let z4 = Snap {}.legendre(&SVector::<f64, 8>::from_fn(|r, _| {
        0.2 * (r as f64 + 0.5).cos()
    }));
    theta_map_matches::<_, 1, 4, 8, 9>(&Snap {}, &z4, 0.05);
}

/// |DPsi^T J DPsi - J|_max of one map step.
fn symplecticity<Sys, Map, const N: usize, const K: usize, const S: usize, const M: usize>(
    system: &Sys,
    map: &Map,
    z0: &SVector<f64, S>,
    h: f64,
) -> f64
where
    Sys: retract::Lagrangian<N, K> + LiftedSystem<S, M>,
    Map: DiscretizationMap<N, K>,
{
    let d = map::step_map_derivative(system, map, z0, h, &NewtonOptions::default())
        .expect("the step converges");
    let j = canonical_structure::<S>();
    (d.transpose() * j * d - j).amax()
}

#[test]
fn nonlinear_maps_give_symplectic_steps() {
    let z1 = SVector::<f64, 4>::from([0.4, -0.3, 0.2, 0.5]);
    let (pais, z2) = bounded_pais_uhlenbeck();
    for symmetric in [true, false] {
        let map = Quadratic { c: 0.7, symmetric };
        let e1 = symplecticity::<_, _, 2, 1, 4, 6>(&Pendulums {}, &map, &z1, 0.2);
        let e2 = symplecticity::<_, _, 2, 2, 8, 10>(&pais, &map, &z2, 0.2);
        assert!(e1 < 1e-12 && e2 < 1e-12, "{symmetric}: {e1:e}, {e2:e}");
    }
    let bent = symplecticity::<_, _, 2, 1, 4, 6>(&Pendulums {}, &Bent { c: 0.6 }, &z1, 0.2);
    assert!(bent < 1e-12, "{bent:e}");
}

/// The step of `Bent` on the pendulums with the transposes of the cotangent lift dropped
/// (F_2 = R2_x p1 - R1_x p0 - h L_x, p = -R1_xi p0 + R2_xi p1): a wrong lift, solved by Newton
/// on a finite-difference Jacobian.
struct Untransposed {
    map: Bent,
    x0: SVector<f64, 2>,
    p0: SVector<f64, 2>,
    h: f64,
}

impl Problem<6> for Untransposed {
    fn residual(&self, w: &SVector<f64, 6>) -> SVector<f64, 6> {
        use retract::Lagrangian;
        let (x, u, p1) = (
            [w.fixed_rows::<2>(0).into_owned()],
            w.fixed_rows::<2>(2).into_owned(),
            w.fixed_rows::<2>(4).into_owned(),
        );
        let xi = [u * self.h];
        let (r1, _) = self.map.points(&x, &xi);
        let j = self.map.jacobians(&x, &xi);
        let p = j.r2_xi[0][0] * p1 - j.r1_xi[0][0] * self.p0;
        let g = Pendulums {}.gradient(&x, &u);
        let f1 = r1[0] - self.x0;
        let f2 = j.r2_x[0][0] * p1 - j.r1_x[0][0] * self.p0 - g.x[0] * self.h;
        let f3 = p - g.u;
        SVector::from_iterator(f1.iter().chain(f2.iter()).chain(f3.iter()).copied())
    }

    fn jacobian(&self, w: &SVector<f64, 6>) -> SMatrix<f64, 6, 6> {
        let eps = 1e-7;
        SMatrix::from_fn(|r, c| {
            let mut plus = *w;
            plus[c] += eps;
            let mut minus = *w;
            minus[c] -= eps;
            (self.residual(&plus)[r] - self.residual(&minus)[r]) / (2.0 * eps)
        })
    }
}

/// |DPsi^T J DPsi - J|_max with DPsi by central differences of `step`.
fn symplecticity_by_differences(step: impl Fn(&SVector<f64, 4>) -> SVector<f64, 4>) -> f64 {
    let z0 = SVector::<f64, 4>::from([0.4, -0.3, 0.2, 0.5]);
    let eps = 1e-5;
    let mut d = SMatrix::<f64, 4, 4>::zeros();
    for c in 0..4 {
        let mut plus = z0;
        plus[c] += eps;
        let mut minus = z0;
        minus[c] -= eps;
        d.set_column(c, &((step(&plus) - step(&minus)) / (2.0 * eps)));
    }
    let j = canonical_structure::<4>();
    (d.transpose() * j * d - j).amax()
}

/// Dropping the transposes of the cotangent lift breaks symplecticity, and the measurement can
/// tell: on the same finite-difference path the right lift stays at the differencing error.
#[test]
fn the_symplecticity_test_sees_a_wrong_lift() {
    let h = 0.2;
    let newton = NewtonOptions::default().with_residual_tolerance(1e-13, 0.0);
    let right = symplecticity_by_differences(|z| {
        map::step(&Pendulums {}, &Bent { c: 0.6 }, z, h, &newton)
            .expect("step")
            .0
    });
    let wrong = symplecticity_by_differences(|z| {
        let problem = Untransposed {
            map: Bent { c: 0.6 },
            x0: z.fixed_rows::<2>(0).into_owned(),
            p0: z.fixed_rows::<2>(2).into_owned(),
            h,
        };
        let w0 = SVector::<f64, 6>::from([z[0], z[1], 0.0, 0.0, z[2], z[3]]);
        let w = retract::newton::solve(&problem, w0, &newton)
            .expect("solve")
            .w;
        let x1 = problem
            .map
            .points(
                &[w.fixed_rows::<2>(0).into_owned()],
                &[w.fixed_rows::<2>(2) * h],
            )
            .1;
        SVector::from([x1[0][0], x1[0][1], w[4], w[5]])
    });
    assert!(right < 1e-8, "the right lift: {right:e}");
    assert!(wrong > 1e-4, "the wrong lift: {wrong:e}");
}

/// The observed order of a map on the pendulums at T = 1 from steps h = 0.1 / 2^j, against
/// RK4 at h = 1e-3.
fn observed_order(map: &impl DiscretizationMap<2, 1>) -> f64 {
    let z0 = SVector::<f64, 4>::from([0.4, -0.3, 0.2, 0.5]);
    let mut reference = z0;
    for _ in 0..1000 {
        reference = rk4_step(&Pendulums {}, &reference, 1e-3).expect("rk4");
    }
    let errors: Vec<f64> = (0..4)
        .map(|j| {
            let steps = 10 << j;
            let h = 1.0 / steps as f64;
            let mut z = z0;
            for _ in 0..steps {
                z = map::step(&Pendulums {}, map, &z, h, &NewtonOptions::default())
                    .expect("step")
                    .0;
            }
            (z - reference).amax()
        })
        .collect();
    (errors[2] / errors[3]).log2()
}

#[test]
fn symmetric_maps_have_order_two_and_others_order_one() {
    for (map, expected) in [
        (
            Quadratic {
                c: 0.7,
                symmetric: true,
            },
            2.0,
        ),
        (
            Quadratic {
                c: 0.7,
                symmetric: false,
            },
            1.0,
        ),
    ] {
        let order = observed_order(&map);
        assert!(
            (order - expected).abs() < 0.1,
            "observed order {order}, expected {expected}"
        );
    }
    let order = observed_order(&Bent { c: 0.6 });
    assert!((order - 2.0).abs() < 0.1, "observed order {order}");
    let order = observed_order(&ThetaMap { theta: 0.3 });
    assert!((order - 1.0).abs() < 0.1, "observed order {order}");
}

#[test]
fn bad_input_is_an_error() {
    let z = SVector::<f64, 4>::from([0.4, -0.3, 0.2, 0.5]);
    let map = ThetaMap { theta: 0.5 };
    let newton = NewtonOptions::default();
    for h in [0.0, f64::NAN, f64::INFINITY] {
        assert!(matches!(
            map::step(&Pendulums {}, &map, &z, h, &newton),
            Err(Error::InvalidArgument { name: "h", .. })
        ));
    }
    let nan = SVector::<f64, 4>::from([f64::NAN, 0.0, 0.0, 0.0]);
    assert!(matches!(
        map::step(&Pendulums {}, &map, &nan, 0.1, &newton),
        Err(Error::NonFinite { .. })
    ));
}
