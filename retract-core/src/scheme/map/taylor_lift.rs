//! The lift of a discretization map to $T^{(k-1)}Q$ computed at run time, by Taylor
//! arithmetic, for any order: no generated code, whose size grows fast with $k$.
//!
//! Along the curves $q(t) = \sum_j q^{(j)} t^j / j!$ and $v(t) = \sum_j v^{(j)} t^j / j!$ the
//! lift's component $j$ is $D^j R_a = \frac{d^j}{dt^j} R_a(q(t), v(t))|_0$: the series of
//! $R_a$ evaluated on [`Taylor`] numbers. Its derivatives follow from those of the base map
//! along the same curves, by Leibniz's rule on $\partial q(t) / \partial q^{(i)} = t^i / i!$:
//!
//! $$\frac{\partial D^j R}{\partial z^{(i)}} = \frac{j!}{i!}\thinspace c_{j-i}[\partial R], \qquad
//!   \frac{\partial^2 D^j R}{\partial z^{(i)} \partial z^{(l)}} = \frac{j!}{i!\thinspace l!}\thinspace
//!   c_{j-i-l}[\partial^2 R],$$
//!
//! with $z$ either $q$ or $v$, $c_m[f] = \frac{1}{m!} D^m f$ the Taylor coefficients of the
//! base map's gradient and Hessian in $(q, v)$, and zero when $i > j$ (or $i + l > j$). One
//! evaluation of the base map on `Taylor<Hyper<2n>, k>` gives all of them.

use nalgebra::SVector;

use super::{BlockMatrix, CovectorHessian, DiscretizationMap, MapJacobians};
use crate::numeric::taylor::{Dual, Hyper, Scalar, Taylor};
use crate::scheme::lifted::Blocks;

/// A discretization map $R_d(q, v) = (R_1, R_2)$ on $\mathbb{R}^n$ written once over a
/// [`Scalar`], so that it can be evaluated on Taylor and dual numbers.
pub trait BaseMap<const N: usize> {
    /// $(R_1(q, v), R_2(q, v))$.
    fn base<T: Scalar>(&self, q: [T; N], v: [T; N]) -> ([T; N], [T; N]);
}

/// The lift of a [`BaseMap`] to $T^{(k-1)}Q$, a [`DiscretizationMap`] at every order $k$
/// (module docs), for $n \le 3$. Where the base map is not finite (a division by zero, such
/// as a chart's edge for the maps of a sphere), neither are the results: [`super::step`]
/// reports that as an error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaylorLift<B>(pub B);

/// $j! / i!$ for $i \le j$.
pub(crate) fn falling(j: usize, i: usize) -> f64 {
    (i + 1..=j).map(|m| m as f64).product()
}

/// $1 / l!$.
fn inverse_factorial(l: usize) -> f64 {
    1.0 / (1..=l).map(|m| m as f64).product::<f64>()
}

/// The lift of `x` to a curve's series: component $a$ has coefficients $x^{(j)}_a / j!$, the
/// constant one the variable `offset + a` (`variable(value, index)`).
pub(crate) fn curve<T: Scalar, const N: usize, const K: usize>(
    x: &Blocks<N, K>,
    offset: usize,
    variable: impl Fn(f64, usize) -> T,
) -> [Taylor<T, K>; N] {
    core::array::from_fn(|a| {
        let mut series = Taylor::from_derivatives(core::array::from_fn(|j| x[j][a]))
            .c
            .map(T::constant);
        series[0] = variable(x[0][a], offset + a);
        Taylor { c: series }
    })
}

/// The base map's series along the curves of `x` and `xi`, with its gradient and Hessian in
/// $(q, v)$ (variables $0..n$ and $n..2n$).
#[allow(clippy::type_complexity)]
fn series<B: BaseMap<N>, const N: usize, const K: usize, const V: usize>(
    map: &B,
    x: &Blocks<N, K>,
    xi: &Blocks<N, K>,
) -> ([Taylor<Hyper<V>, K>; N], [Taylor<Hyper<V>, K>; N]) {
    map.base(curve(x, 0, Hyper::variable), curve(xi, N, Hyper::variable))
}

macro_rules! taylor_lift {
    ($n:literal, $v:literal) => {
        impl<B: BaseMap<$n>, const K: usize> DiscretizationMap<$n, K> for TaylorLift<B> {
            /// $(D^j R_1, D^j R_2)_{j < k}$ from the series of the base map (no derivatives).
            fn points(
                &self,
                x: &Blocks<$n, K>,
                xi: &Blocks<$n, K>,
            ) -> (Blocks<$n, K>, Blocks<$n, K>) {
                let along = |b: &Blocks<$n, K>| -> [Taylor<f64, K>; $n] {
                    core::array::from_fn(|a| {
                        Taylor::from_derivatives(core::array::from_fn(|j| b[j][a]))
                    })
                };
                let (r1, r2) = self.0.base(along(x), along(xi));
                let blocks = |r: [Taylor<f64, K>; $n]| -> Blocks<$n, K> {
                    let d = r.map(|s| s.derivatives());
                    core::array::from_fn(|j| SVector::from_fn(|c, _| d[c][j]))
                };
                (blocks(r1), blocks(r2))
            }

            /// $\partial D^j R / \partial z^{(i)} = (j!/i!)\thinspace c_{j-i}[\partial R]$.
            fn jacobians(&self, x: &Blocks<$n, K>, xi: &Blocks<$n, K>) -> MapJacobians<$n, K> {
                // first-order duals: the Hessian is not needed here
                let (r1, r2) = self.0.base(
                    curve::<Dual<$v>, $n, K>(x, 0, Dual::variable),
                    curve::<Dual<$v>, $n, K>(xi, $n, Dual::variable),
                );
                let jacobian = |r: &[Taylor<Dual<$v>, K>; $n],
                                offset: usize|
                 -> BlockMatrix<$n, K> {
                    core::array::from_fn(|j| {
                        core::array::from_fn(|i| {
                            if i > j {
                                return nalgebra::SMatrix::zeros();
                            }
                            let scale = falling(j, i);
                            nalgebra::SMatrix::from_fn(|c, a| scale * r[c].c[j - i].g[offset + a])
                        })
                    })
                };
                MapJacobians {
                    r1_x: jacobian(&r1, 0),
                    r1_xi: jacobian(&r1, $n),
                    r2_x: jacobian(&r2, 0),
                    r2_xi: jacobian(&r2, $n),
                }
            }

            /// $\sum_{j, c} (w_{2,jc}\thinspace \partial^2 D^j R_{2,c} - w_{1,jc}\thinspace \partial^2 D^j R_{1,c})$
            /// with $\partial^2 D^j R / \partial z^{(i)} \partial z^{(l)} = j!/(i!\thinspace l!)\thinspace
            /// c_{j-i-l}[\partial^2 R]$.
            fn covector_hessian(
                &self,
                x: &Blocks<$n, K>,
                xi: &Blocks<$n, K>,
                w1: &Blocks<$n, K>,
                w2: &Blocks<$n, K>,
            ) -> CovectorHessian<$n, K> {
                let (r1, r2) = series::<B, $n, K, $v>(&self.0, x, xi);
                // m = j - i - l: the weighted Hessian coefficients sum_c w_jc c_m[d2 R_c]
                let weighted = |j: usize, m: usize| -> [[f64; $v]; $v] {
                    core::array::from_fn(|a| {
                        core::array::from_fn(|b| {
                            (0..$n)
                                .map(|c| {
                                    w2[j][c] * r2[c].c[m].h[a][b] - w1[j][c] * r1[c].c[m].h[a][b]
                                })
                                .sum()
                        })
                    })
                };
                let mut out = CovectorHessian {
                    xx: [[nalgebra::SMatrix::zeros(); K]; K],
                    x_xi: [[nalgebra::SMatrix::zeros(); K]; K],
                    xi_xi: [[nalgebra::SMatrix::zeros(); K]; K],
                };
                for j in 0..K {
                    for i in 0..=j {
                        for l in 0..=j - i {
                            let h = weighted(j, j - i - l);
                            let scale = falling(j, i) * inverse_factorial(l);
                            for a in 0..$n {
                                for b in 0..$n {
                                    out.xx[i][l][(a, b)] += scale * h[a][b];
                                    out.x_xi[i][l][(a, b)] += scale * h[a][$n + b];
                                    out.xi_xi[i][l][(a, b)] += scale * h[$n + a][$n + b];
                                }
                            }
                        }
                    }
                }
                out
            }
        }
    };
}

taylor_lift!(1, 2);
taylor_lift!(2, 4);
taylor_lift!(3, 6);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scheme::map::ThetaMap;

    /// $R_1 = q - v/2 + q_0 v_1 v$, $R_2 = q + v/2 + v_0 q_1 q / (1 + q_0^2)$: a nonlinear
    /// rational map on $\mathbb{R}^2$.
    struct Rational;

    impl BaseMap<2> for Rational {
        fn base<T: Scalar>(&self, q: [T; 2], v: [T; 2]) -> ([T; 2], [T; 2]) {
            let s = v[0] * q[1] / (q[0] * q[0] + 1.0);
            let r = q[0] * v[1];
            (
                [q[0] - v[0] * 0.5 + r * v[0], q[1] - v[1] * 0.5 + r * v[1]],
                [q[0] + v[0] / 2.0 + s * q[0], q[1] + v[1] / 2.0 + s * q[1]],
            )
        }
    }

    /// The theta map as a base map.
    struct Theta(f64);

    impl BaseMap<2> for Theta {
        fn base<T: Scalar>(&self, q: [T; 2], v: [T; 2]) -> ([T; 2], [T; 2]) {
            let t = self.0;
            (
                [q[0] - v[0] * t, q[1] - v[1] * t],
                [q[0] + v[0] * (1.0 - t), q[1] + v[1] * (1.0 - t)],
            )
        }
    }

    fn blocks<const K: usize>(seed: f64) -> Blocks<2, K> {
        core::array::from_fn(|j| {
            SVector::from_fn(|a, _| (seed * (1.0 + j as f64) + 0.37 * a as f64).sin() * 0.8)
        })
    }

    /// The lift of the theta map is the theta map on every block.
    #[test]
    fn the_lift_of_the_theta_map_is_the_theta_map() {
        let (x, xi) = (blocks::<3>(0.3), blocks::<3>(1.1));
        let lifted = TaylorLift(Theta(0.3));
        let direct = ThetaMap { theta: 0.3 };
        let (a, b) = (lifted.points(&x, &xi), direct.points(&x, &xi));
        for j in 0..3 {
            assert!((a.0[j] - b.0[j]).amax() < 1e-15 && (a.1[j] - b.1[j]).amax() < 1e-15);
        }
        let (ja, jb) = (lifted.jacobians(&x, &xi), direct.jacobians(&x, &xi));
        for (i, j) in (0..3).flat_map(|i| (0..3).map(move |j| (i, j))) {
            assert!((ja.r1_xi[i][j] - jb.r1_xi[i][j]).amax() < 1e-15);
            assert!((ja.r2_x[i][j] - jb.r2_x[i][j]).amax() < 1e-15);
        }
    }

    /// Component j of the lift is the j-th derivative of R along the curves: by differences
    /// of the points of the order-1 lift along t.
    #[test]
    fn the_lift_is_the_total_derivative_along_curves() {
        let (x, xi) = (blocks::<4>(0.3), blocks::<4>(1.1));
        let at = |t: f64| -> [SVector<f64, 2>; 2] {
            let shift = |b: &Blocks<2, 4>| {
                let mut s = b[0];
                let mut power = 1.0;
                for (j, bj) in b.iter().enumerate().skip(1) {
                    power *= t / j as f64;
                    s += bj * power;
                }
                [s]
            };
            let (r1, r2) = TaylorLift(Rational).points(&shift(&x), &shift(&xi));
            [r1[0], r2[0]]
        };
        let (r1, r2) = TaylorLift(Rational).points(&x, &xi);
        let e = 1e-3;
        let s = [-2.0, -1.0, 0.0, 1.0, 2.0].map(|k| at(k * e));
        for (side, r) in [r1, r2].iter().enumerate() {
            let d1 = (s[3][side] - s[1][side]) / (2.0 * e);
            let d2 = (s[3][side] - s[2][side] * 2.0 + s[1][side]) / (e * e);
            let d3 =
                (s[4][side] - s[3][side] * 2.0 + s[1][side] * 2.0 - s[0][side]) / (2.0 * e * e * e);
            assert!((r[0] - s[2][side]).amax() < 1e-15);
            assert!((r[1] - d1).amax() < 1e-5, "{side}: {} {d1}", r[1]);
            assert!((r[2] - d2).amax() < 1e-4, "{side}: {} {d2}", r[2]);
            assert!((r[3] - d3).amax() < 1e-3, "{side}: {} {d3}", r[3]);
        }
    }

    /// The Jacobians are the derivatives of the points, and the covector Hessian the
    /// derivative of the covector's gradient, by central differences at orders 3 and 4.
    #[test]
    fn derivatives_of_the_lift_match_differences() {
        check_derivatives::<3>();
        check_derivatives::<4>();
    }

    fn check_derivatives<const K: usize>() {
        let (x, xi) = (blocks::<K>(0.3), blocks::<K>(1.1));
        let (w1, w2) = (blocks::<K>(2.3), blocks::<K>(-0.7));
        let map = TaylorLift(Rational);
        let jac = map.jacobians(&x, &xi);
        let hess = map.covector_hessian(&x, &xi, &w1, &w2);
        // grad of phi = w2 . R2 - w1 . R1 in (x, xi) from the Jacobians
        let gradient = |x: &Blocks<2, K>, xi: &Blocks<2, K>| -> [[SVector<f64, 2>; K]; 2] {
            let j = map.jacobians(x, xi);
            let part = |r1: &BlockMatrix<2, K>, r2: &BlockMatrix<2, K>| {
                core::array::from_fn(|l| {
                    (0..K).fold(SVector::zeros(), |acc, i| {
                        acc + r2[i][l].transpose() * w2[i] - r1[i][l].transpose() * w1[i]
                    })
                })
            };
            [part(&j.r1_x, &j.r2_x), part(&j.r1_xi, &j.r2_xi)]
        };
        let e = 1e-6;
        for (i, a) in (0..K).flat_map(|i| (0..2).map(move |a| (i, a))) {
            for (on_xi, side) in [(false, 0), (true, 1)] {
                let (mut xp, mut xm, mut xip, mut xim) = (x, x, xi, xi);
                if on_xi {
                    xip[i][a] += e;
                    xim[i][a] -= e;
                } else {
                    xp[i][a] += e;
                    xm[i][a] -= e;
                }
                let (pp, pm) = (map.points(&xp, &xip), map.points(&xm, &xim));
                let column = if on_xi {
                    (&jac.r1_xi, &jac.r2_xi)
                } else {
                    (&jac.r1_x, &jac.r2_x)
                };
                for j in 0..K {
                    let d1 = (pp.0[j] - pm.0[j]) / (2.0 * e);
                    let d2 = (pp.1[j] - pm.1[j]) / (2.0 * e);
                    assert!(
                        (d1 - column.0[j][i].column(a)).amax() < 1e-8,
                        "R1 {j} {i} {a}"
                    );
                    assert!(
                        (d2 - column.1[j][i].column(a)).amax() < 1e-8,
                        "R2 {j} {i} {a}"
                    );
                }
                let (gp, gm) = (gradient(&xp, &xip), gradient(&xm, &xim));
                for l in 0..K {
                    let dx = (gp[0][l] - gm[0][l]) / (2.0 * e);
                    let dxi = (gp[1][l] - gm[1][l]) / (2.0 * e);
                    // d/dz_{i,a} of d phi/dx_l and of d phi/dxi_l
                    let (hx, hxi) = match side {
                        0 => (
                            hess.xx[i][l].row(a).transpose(),
                            hess.x_xi[i][l].row(a).transpose(),
                        ),
                        _ => (
                            hess.x_xi[l][i].column(a).into_owned(),
                            hess.xi_xi[i][l].row(a).transpose(),
                        ),
                    };
                    assert!((dx - hx).amax() < 1e-7, "xx {side} {i} {a} {l}: {dx} {hx}");
                    assert!(
                        (dxi - hxi).amax() < 1e-7,
                        "xi {side} {i} {a} {l}: {dxi} {hxi}"
                    );
                }
            }
        }
    }
}
