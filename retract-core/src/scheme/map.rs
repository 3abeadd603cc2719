//! General discretization maps: the integrator of paper Prop. 5.1 for any map
//! $R_d(x, \xi) = (R_1(x, \xi), R_2(x, \xi))$ on $T^{(k-1)}Q$, not only the theta family.
//!
//! A discretization map satisfies $R_d(x, 0) = (x, x)$ and
//! $\partial_\xi R_2 - \partial_\xi R_1 = I$ at $\xi = 0$. Its cotangent lift gives the
//! integrator: from $(x_0, p_0)$ find the base point $x$, its tangent vector $\xi$ and the
//! momenta $p$, $p_1$ with
//!
//! $$R_1(x, \xi) = x_0, \quad x_1 = R_2(x, \xi), \quad \xi = h\thinspace\partial_p H(x, p),$$
//! $$-h\thinspace\partial_x H(x, p) = -(\partial_x R_1)^T p_0 + (\partial_x R_2)^T p_1, \quad
//!   p = -(\partial_\xi R_1)^T p_0 + (\partial_\xi R_2)^T p_1.$$
//!
//! With the Ostrogradsky Hamiltonian, $\partial_{p_j} H = x_{j+1}$ ($j < k-1$),
//! $\partial_{p_{k-1}} H = u$ and $\partial_{x_j} H = p_{j-1} - \partial L/\partial x_j$
//! ($p_{-1} = 0$), where the top derivative $u$ solves $p_{k-1} = \partial L/\partial u$.
//! As in the built-in scheme, $u$ is an unknown instead of a Legendre inversion, and $p$ is
//! eliminated: the Newton unknowns are $w = (x, u, p_1) \in \mathbb{R}^{2nk + n}$, with
//! $\xi(x, u) = h\thinspace(x_1, \dots, x_{k-1}, u)$ and the residual
//!
//! $$F_1 = R_1(x, \xi) - x_0, \qquad
//!   F_2 = (\partial_x R_2)^T p_1 - (\partial_x R_1)^T p_0 + h\thinspace\partial_x H(x, p),$$
//! $$F_3 = p_{k-1} - \partial L/\partial u\thinspace(x, u).$$
//!
//! Its Jacobian needs the Hessian of $\phi = p_1 \cdot R_2 - p_0 \cdot R_1$ in $(x, \xi)$
//! ([`DiscretizationMap::covector_hessian`]): $\partial_x \phi$ is the first two terms of
//! $F_2$ and $p = \partial_\xi \phi$. The theta map $R_1 = x - \theta\xi$,
//! $R_2 = x + (1-\theta)\xi$ ([`ThetaMap`]) gives back the built-in scheme: $x = x_\theta$,
//! $p = \theta p_0 + (1-\theta) p_1$. The method is symplectic for every map, of order 2 when
//! the map is symmetric ($R_d(x, -\xi) = (R_2, R_1)(x, \xi)$) and 1 otherwise.
//!
//! For a $k$-th order Lagrangian the map acts on $T^{(k-1)}Q$: component $j$ of the lift of a
//! map $R_a(q, v)$ on $Q$ is the total derivative $D^j R_a(q, v)$ with
//! $D q^{(i)} = q^{(i+1)}$, $D v^{(i)} = v^{(i+1)}$; a linear map lifts block by block.
//!
//! # References
//! A. Anahory Simoes, M. Barbero Liñán, L. Colombo, D. Martín de Diego, "Higher-order
//! retraction maps and construction of numerical methods for optimal control of mechanical
//! systems", Prop. 4.1 (the cotangent lift) and Prop. 5.1 (the integrator).

use nalgebra::{SMatrix, SVector};

pub(crate) mod taylor_lift;
pub use taylor_lift::{BaseMap, TaylorLift};

use crate::numeric::newton::{self, NewtonOptions, Problem};
use crate::scheme::lifted::{Blocks, join, split};
use crate::scheme::step::StepReport;
use crate::{Error, Lagrangian, LiftedSystem};

/// An $nk \times nk$ matrix as $k \times k$ blocks of $n \times n$: `m[i][j]` is the block of
/// row block $i$ and column block $j$.
pub type BlockMatrix<const N: usize, const K: usize> = [[SMatrix<f64, N, N>; K]; K];

/// The Jacobians of a discretization map at $(x, \xi)$, by blocks: `r1_x[i][j]`
/// $= \partial R_{1,i} / \partial x_j$ and so on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapJacobians<const N: usize, const K: usize> {
    /// $\partial R_1 / \partial x$.
    pub r1_x: BlockMatrix<N, K>,
    /// $\partial R_1 / \partial \xi$.
    pub r1_xi: BlockMatrix<N, K>,
    /// $\partial R_2 / \partial x$.
    pub r2_x: BlockMatrix<N, K>,
    /// $\partial R_2 / \partial \xi$.
    pub r2_xi: BlockMatrix<N, K>,
}

/// The Hessian of $\phi(x, \xi) = w_2 \cdot R_2(x, \xi) - w_1 \cdot R_1(x, \xi)$ for fixed
/// covectors $w_1$, $w_2$, by blocks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CovectorHessian<const N: usize, const K: usize> {
    /// $\partial^2 \phi / \partial x \partial x$.
    pub xx: BlockMatrix<N, K>,
    /// $\partial^2 \phi / \partial x \partial \xi$ (rows $x$, columns $\xi$).
    pub x_xi: BlockMatrix<N, K>,
    /// $\partial^2 \phi / \partial \xi \partial \xi$.
    pub xi_xi: BlockMatrix<N, K>,
}

/// A discretization map $R_d = (R_1, R_2)$ on $T^{(k-1)}Q \subset \mathbb{R}^{nk}$
/// (already lifted), with the derivatives the integrator needs.
///
/// An implementation must satisfy $R_d(x, 0) = (x, x)$ and
/// $\partial_\xi R_2 - \partial_\xi R_1 = I$ at $\xi = 0$.
pub trait DiscretizationMap<const N: usize, const K: usize> {
    /// $(R_1(x, \xi), R_2(x, \xi))$.
    fn points(&self, x: &Blocks<N, K>, xi: &Blocks<N, K>) -> (Blocks<N, K>, Blocks<N, K>);

    /// The four Jacobians at $(x, \xi)$.
    fn jacobians(&self, x: &Blocks<N, K>, xi: &Blocks<N, K>) -> MapJacobians<N, K>;

    /// The Hessian of $w_2 \cdot R_2 - w_1 \cdot R_1$ in $(x, \xi)$.
    fn covector_hessian(
        &self,
        x: &Blocks<N, K>,
        xi: &Blocks<N, K>,
        w1: &Blocks<N, K>,
        w2: &Blocks<N, K>,
    ) -> CovectorHessian<N, K>;
}

/// The theta map $R_1 = x - \theta \xi$, $R_2 = x + (1 - \theta)\xi$ (its lift is itself,
/// block by block): with it [`step`] is the built-in scheme. $\theta = 1/2$ is the midpoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThetaMap {
    /// $\theta \in [0, 1]$.
    pub theta: f64,
}

/// $c I$ on the diagonal blocks, zero elsewhere.
fn scaled_identity<const N: usize, const K: usize>(c: f64) -> BlockMatrix<N, K> {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| {
            if i == j {
                SMatrix::identity() * c
            } else {
                SMatrix::zeros()
            }
        })
    })
}

impl<const N: usize, const K: usize> DiscretizationMap<N, K> for ThetaMap {
    fn points(&self, x: &Blocks<N, K>, xi: &Blocks<N, K>) -> (Blocks<N, K>, Blocks<N, K>) {
        (
            core::array::from_fn(|j| x[j] - xi[j] * self.theta),
            core::array::from_fn(|j| x[j] + xi[j] * (1.0 - self.theta)),
        )
    }

    fn jacobians(&self, _x: &Blocks<N, K>, _xi: &Blocks<N, K>) -> MapJacobians<N, K> {
        MapJacobians {
            r1_x: scaled_identity(1.0),
            r1_xi: scaled_identity(-self.theta),
            r2_x: scaled_identity(1.0),
            r2_xi: scaled_identity(1.0 - self.theta),
        }
    }

    fn covector_hessian(
        &self,
        _x: &Blocks<N, K>,
        _xi: &Blocks<N, K>,
        _w1: &Blocks<N, K>,
        _w2: &Blocks<N, K>,
    ) -> CovectorHessian<N, K> {
        CovectorHessian {
            xx: scaled_identity(0.0),
            x_xi: scaled_identity(0.0),
            xi_xi: scaled_identity(0.0),
        }
    }
}

/// Entry $(r, c)$ of a block matrix in flat indices.
#[inline]
fn at<const N: usize, const K: usize>(m: &BlockMatrix<N, K>, r: usize, c: usize) -> f64 {
    m[r / N][c / N][(r % N, c % N)]
}

/// $M^T v$ for a block matrix.
fn transpose_times<const N: usize, const K: usize>(
    m: &BlockMatrix<N, K>,
    v: &Blocks<N, K>,
) -> Blocks<N, K> {
    core::array::from_fn(|j| {
        let mut out = SVector::<f64, N>::zeros();
        for (i, vi) in v.iter().enumerate() {
            out += m[i][j].transpose() * vi;
        }
        out
    })
}

/// The step of a discretization map as a Newton problem in $w = (x, u, p_1)$ (module docs).
pub struct MapScheme<'a, Sys: ?Sized, Map: ?Sized, const N: usize, const K: usize> {
    /// The Lagrangian.
    pub system: &'a Sys,
    /// The discretization map on $T^{(k-1)}Q$.
    pub map: &'a Map,
    /// The jet $x_0$ of the initial state.
    pub x0: Blocks<N, K>,
    /// The momenta $p_0$ of the initial state.
    pub p0: Blocks<N, K>,
    /// The step size.
    pub h: f64,
}

/// The parts of $w = (x, u, p_1)$ and $\xi(x, u)$.
struct Unpacked<const N: usize, const K: usize> {
    x: Blocks<N, K>,
    u: SVector<f64, N>,
    p1: Blocks<N, K>,
    xi: Blocks<N, K>,
}

impl<Sys, Map, const N: usize, const K: usize> MapScheme<'_, Sys, Map, N, K>
where
    Sys: Lagrangian<N, K> + ?Sized,
    Map: DiscretizationMap<N, K> + ?Sized,
{
    fn unpack<const M: usize>(&self, w: &SVector<f64, M>) -> Unpacked<N, K> {
        const { assert!(M == 2 * N * K + N, "M must equal 2 N K + N") };
        let x: Blocks<N, K> = core::array::from_fn(|j| w.fixed_rows::<N>(j * N).into_owned());
        let u = w.fixed_rows::<N>(N * K).into_owned();
        let p1 = core::array::from_fn(|j| w.fixed_rows::<N>(N * K + N + j * N).into_owned());
        let xi = core::array::from_fn(|j| if j + 1 < K { x[j + 1] } else { u } * self.h);
        Unpacked { x, u, p1, xi }
    }

    /// $p = -(\partial_\xi R_1)^T p_0 + (\partial_\xi R_2)^T p_1$.
    fn momenta(&self, jac: &MapJacobians<N, K>, p1: &Blocks<N, K>) -> Blocks<N, K> {
        let a = transpose_times(&jac.r1_xi, &self.p0);
        let b = transpose_times(&jac.r2_xi, p1);
        core::array::from_fn(|j| b[j] - a[j])
    }

    /// $x_1 = R_2(x, \xi)$ at the solution $w$.
    pub fn end_point<const M: usize>(&self, w: &SVector<f64, M>) -> Blocks<N, K> {
        let v = self.unpack(w);
        self.map.points(&v.x, &v.xi).1
    }

    /// $\partial F / \partial (x_0, p_0)$, columns $x_0$ then $p_0$.
    pub fn jacobian_initial<const M: usize, const S: usize>(
        &self,
        w: &SVector<f64, M>,
    ) -> SMatrix<f64, M, S> {
        const { assert!(S == 2 * N * K, "S must equal 2 N K") };
        let v = self.unpack(w);
        let jac = self.map.jacobians(&v.x, &v.xi);
        let (x, h) = (N * K, self.h);
        let mut out = SMatrix::<f64, M, S>::zeros();
        for r in 0..x {
            out[(r, r)] = -1.0;
            for c in 0..x {
                // d p_s / d p0_c = -(R1_xi)_{c s}
                let dp = if r >= N {
                    -at(&jac.r1_xi, c, r - N)
                } else {
                    0.0
                };
                out[(x + r, x + c)] = -at(&jac.r1_x, c, r) + h * dp;
            }
        }
        for a in 0..N {
            for c in 0..x {
                out[(2 * x + a, x + c)] = -at(&jac.r1_xi, c, (K - 1) * N + a);
            }
        }
        out
    }

    /// The derivative of the output $(x_1, p_1) = (R_2(x, \xi(x, u)), p_1)$ in $w$.
    pub fn output_jacobian<const M: usize, const S: usize>(
        &self,
        w: &SVector<f64, M>,
    ) -> SMatrix<f64, S, M> {
        const { assert!(S == 2 * N * K, "S must equal 2 N K") };
        let v = self.unpack(w);
        let jac = self.map.jacobians(&v.x, &v.xi);
        let (x, h) = (N * K, self.h);
        let mut out = SMatrix::<f64, S, M>::zeros();
        for r in 0..x {
            for c in 0..x {
                let shift = if c >= N {
                    h * at(&jac.r2_xi, r, c - N)
                } else {
                    0.0
                };
                out[(r, c)] = at(&jac.r2_x, r, c) + shift;
            }
            for b in 0..N {
                out[(r, x + b)] = h * at(&jac.r2_xi, r, (K - 1) * N + b);
            }
            out[(x + r, x + N + r)] = 1.0;
        }
        out
    }
}

impl<Sys, Map, const N: usize, const K: usize, const M: usize> Problem<M>
    for MapScheme<'_, Sys, Map, N, K>
where
    Sys: Lagrangian<N, K> + ?Sized,
    Map: DiscretizationMap<N, K> + ?Sized,
{
    fn residual(&self, w: &SVector<f64, M>) -> SVector<f64, M> {
        let v = self.unpack(w);
        let (r1, _) = self.map.points(&v.x, &v.xi);
        let jac = self.map.jacobians(&v.x, &v.xi);
        let p = self.momenta(&jac, &v.p1);
        let g = self.system.gradient(&v.x, &v.u);
        let pull = transpose_times(&jac.r2_x, &v.p1);
        let push = transpose_times(&jac.r1_x, &self.p0);
        let mut out = SVector::<f64, M>::zeros();
        for j in 0..K {
            let hx = if j > 0 { p[j - 1] } else { SVector::zeros() } - g.x[j];
            out.fixed_rows_mut::<N>(j * N)
                .copy_from(&(r1[j] - self.x0[j]));
            out.fixed_rows_mut::<N>(N * K + j * N)
                .copy_from(&(pull[j] - push[j] + hx * self.h));
        }
        out.fixed_rows_mut::<N>(2 * N * K)
            .copy_from(&(p[K - 1] - g.u));
        out
    }

    fn jacobian(&self, w: &SVector<f64, M>) -> SMatrix<f64, M, M> {
        let v = self.unpack(w);
        let jac = self.map.jacobians(&v.x, &v.xi);
        let phi = self.map.covector_hessian(&v.x, &v.xi, &self.p0, &v.p1);
        let hs = self.system.hessian(&v.x, &v.u);
        let (x, h) = (N * K, self.h);
        let (last, u0, p1) = ((K - 1) * N, x, x + N);
        // d p_s / d(x_c, u_b, p1_c): p = d phi / d xi
        let dp_dx = |s: usize, c: usize| {
            at(&phi.x_xi, c, s)
                + if c >= N {
                    h * at(&phi.xi_xi, s, c - N)
                } else {
                    0.0
                }
        };
        let dp_du = |s: usize, b: usize| h * at(&phi.xi_xi, s, last + b);
        let dp_dp1 = |s: usize, c: usize| at(&jac.r2_xi, c, s);
        let l_xx = |r: usize, c: usize| hs.xx[r / N][c / N][(r % N, c % N)];
        let l_xu = |r: usize, b: usize| hs.xu[r / N][(r % N, b)];
        let mut out = SMatrix::<f64, M, M>::zeros();
        for r in 0..x {
            for c in 0..x {
                let shift1 = if c >= N {
                    h * at(&jac.r1_xi, r, c - N)
                } else {
                    0.0
                };
                out[(r, c)] = at(&jac.r1_x, r, c) + shift1;
                let shift2 = if c >= N {
                    h * at(&phi.x_xi, r, c - N)
                } else {
                    0.0
                };
                let hx = if r >= N { dp_dx(r - N, c) } else { 0.0 } - l_xx(r, c);
                out[(x + r, c)] = at(&phi.xx, r, c) + shift2 + h * hx;
                let hp = if r >= N { dp_dp1(r - N, c) } else { 0.0 };
                out[(x + r, p1 + c)] = at(&jac.r2_x, c, r) + h * hp;
            }
            for b in 0..N {
                out[(r, u0 + b)] = h * at(&jac.r1_xi, r, last + b);
                let hu = if r >= N { dp_du(r - N, b) } else { 0.0 } - l_xu(r, b);
                out[(x + r, u0 + b)] = h * at(&phi.x_xi, r, last + b) + h * hu;
            }
        }
        for a in 0..N {
            for c in 0..x {
                out[(2 * x + a, c)] = dp_dx(last + a, c) - l_xu(c, a);
                out[(2 * x + a, p1 + c)] = dp_dp1(last + a, c);
            }
            for b in 0..N {
                out[(2 * x + a, u0 + b)] = dp_du(last + a, b) - hs.uu[(a, b)];
            }
        }
        out
    }
}

/// Checks the step size and the state; the initial jet and momenta.
fn start<const N: usize, const K: usize, const S: usize>(
    z0: &SVector<f64, S>,
    h: f64,
) -> Result<(Blocks<N, K>, Blocks<N, K>), Error> {
    if !(h.is_finite() && h != 0.0) {
        return Err(Error::InvalidArgument {
            name: "h",
            requirement: "the step size must be finite and non-zero",
        });
    }
    if !z0.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFinite {
            iteration: 0,
            location: "state",
        });
    }
    Ok(split::<N, K, S>(z0))
}

/// A solved step: the scheme, the root $w$ and the report.
type Solved<'a, Sys, Map, const N: usize, const K: usize, const M: usize> =
    (MapScheme<'a, Sys, Map, N, K>, SVector<f64, M>, StepReport);

/// Solves one step of the discretization-map integrator.
fn solve<'a, Sys, Map, const N: usize, const K: usize, const S: usize, const M: usize>(
    system: &'a Sys,
    map: &'a Map,
    z0: &SVector<f64, S>,
    h: f64,
    options: &NewtonOptions,
) -> Result<Solved<'a, Sys, Map, N, K, M>, Error>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
    Map: DiscretizationMap<N, K> + ?Sized,
{
    let (x0, p0) = start::<N, K, S>(z0, h)?;
    let scheme = MapScheme {
        system,
        map,
        x0,
        p0,
        h,
    };
    // the start: x = x0, u from the Legendre map at z0 (zero if that fails), p1 = p0
    let u0 = system
        .top_derivative(&x0, &p0[K - 1], &SVector::zeros())
        .unwrap_or_else(|_| SVector::zeros());
    let mut w0 = SVector::<f64, M>::zeros();
    for j in 0..K {
        w0.fixed_rows_mut::<N>(j * N).copy_from(&x0[j]);
        w0.fixed_rows_mut::<N>(N * K + N + j * N).copy_from(&p0[j]);
    }
    w0.fixed_rows_mut::<N>(N * K).copy_from(&u0);
    let solution = newton::solve(&scheme, w0, options)?;
    let report = StepReport {
        iterations: solution.iterations,
        residual_norm: solution.residual_norm,
        halvings: 0,
    };
    Ok((scheme, solution.w, report))
}

/// One step of size `h` of the integrator of the discretization map `map` (module docs) from
/// $z_0 = (x_0, p_0)$: returns $z_1 = (R_2(x, \xi), p_1)$.
///
/// `S` and `M` come from the system's [`LiftedSystem`] implementation (as generated by the
/// macro: $S = 2nk$, $M = S + n$).
///
/// ```
/// use nalgebra::SVector;
/// use retract_core::map::{self, ThetaMap};
/// use retract_core::{LiftedSystem, NewtonOptions, StepOptions, models::PlanarBarrier, step};
///
/// let system = PlanarBarrier { tau: 1e-2, radius: 1.0, mass: 1.0 };
/// let jet = SVector::<f64, 8>::from_column_slice(&[-2.0, 1.2, 1.0, -0.1, 0.0, 0.0, 0.0, 0.0]);
/// let z0 = system.legendre(&jet);
/// // the midpoint map gives the built-in midpoint step
/// let midpoint = ThetaMap { theta: 0.5 };
/// let (z1, report) = map::step(&system, &midpoint, &z0, 0.01, &NewtonOptions::default())?;
/// let (built_in, _) = step(&system, &z0, 0.01, &StepOptions::default())?;
/// assert!((z1 - built_in).amax() < 1e-12 && report.iterations <= 5);
/// # Ok::<(), retract_core::Error>(())
/// ```
///
/// The domain of the Lagrangian ([`LiftedSystem::check_domain`], the singularity guard) is
/// checked at $x_0$, at the midpoint of the chord from $x_0$ to $x_1$ and at $x_1$ (the rule of
/// the midpoint step; the map's own base point $x$ is not sampled).
///
/// # Errors
/// [`Error::InvalidArgument`] for a step size that is zero or not finite, [`Error::NonFinite`]
/// for a non-finite state or result, [`Error::Domain`] for a step that leaves the domain of
/// the Lagrangian, and any error of the Newton solve.
pub fn step<Sys, Map, const N: usize, const K: usize, const S: usize, const M: usize>(
    system: &Sys,
    map: &Map,
    z0: &SVector<f64, S>,
    h: f64,
    options: &NewtonOptions,
) -> Result<(SVector<f64, S>, StepReport), Error>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
    Map: DiscretizationMap<N, K> + ?Sized,
{
    let (scheme, w, report) = solve(system, map, z0, h, options)?;
    let x1 = scheme.end_point(&w);
    let p1: Blocks<N, K> = core::array::from_fn(|j| w.fixed_rows::<N>(N * K + N + j * N).into());
    let z1 = join::<N, K, S>(&x1, &p1);
    if !z1.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFinite {
            iteration: report.iterations,
            location: "state",
        });
    }
    // the guard of the Lagrangian at x_0, the chord's midpoint and x_1, with the solved u
    let mut checked = SVector::<f64, M>::zeros();
    checked.fixed_rows_mut::<S>(0).copy_from(&z1);
    checked
        .fixed_rows_mut::<N>(S)
        .copy_from(&w.fixed_rows::<N>(N * K));
    system
        .check_domain(z0, &checked, 0.5)
        .map_err(Error::Domain)?;
    Ok((z1, report))
}

/// The derivative $D\Psi$ of the one-step map $\Psi: z_0 \mapsto z_1$ of [`step`], by the
/// implicit function theorem: $D\Psi = -G\thinspace(\partial F/\partial w)^{-1}\thinspace\partial F
/// / \partial z_0$ with $G$ the derivative of the output $(R_2(x, \xi), p_1)$ in $w$, all at the
/// solution. Symplectic maps have $D\Psi^T J D\Psi = J$.
///
/// # Errors
/// As [`step`], and [`Error::SingularJacobian`] if $\partial F / \partial w$ is singular at
/// the solution.
pub fn step_map_derivative<
    Sys,
    Map,
    const N: usize,
    const K: usize,
    const S: usize,
    const M: usize,
>(
    system: &Sys,
    map: &Map,
    z0: &SVector<f64, S>,
    h: f64,
    options: &NewtonOptions,
) -> Result<SMatrix<f64, S, S>, Error>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
    Map: DiscretizationMap<N, K> + ?Sized,
{
    let (scheme, w, report) = solve(system, map, z0, h, options)?;
    let dw_dz0 = -scheme.jacobian_initial::<M, S>(&w);
    let dw = crate::numeric::linalg::solve(&Problem::<M>::jacobian(&scheme, &w), &dw_dz0).ok_or(
        Error::SingularJacobian {
            iteration: report.iterations,
        },
    )?;
    Ok(scheme.output_jacobian::<M, S>(&w) * dw)
}
