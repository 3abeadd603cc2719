//! The lifted theta-scheme assembled from a [`Lagrangian`]: every method of
//! [`LiftedSystem`](crate::LiftedSystem) as a generic function, for
//! `S = 2 N K` and `M = S + N` (checked at compile time).
//!
//! The formulas are those of the [`LiftedSystem`](crate::LiftedSystem) docs; the Jacobians
//! use the Hessian blocks of $L$ at the evaluation point $(x_\theta, u)$:
//!
//! ```text
//! dF/dw:   F_{x,j}:   I at x_{j,1},  -h theta I at x_{j+1,1}          (j < k-1)
//!          F_{x,k-1}: I at x_{k-1,1}, -h I at u
//!          F_{p,j}:   I at p_{j,1},  h (1-theta) I at p_{j-1,1} (j >= 1),
//!                     -h theta L_{x_j x_i} at x_{i,1},  -h L_{x_j u} at u
//!          F_u:       (1-theta) I at p_{k-1,1},  -theta L_{u x_i} at x_{i,1},  -L_{uu} at u
//! dF/dz0:  F_{x,j}:   -I at x_{j,0},  -h (1-theta) I at x_{j+1,0}     (j < k-1)
//!          F_{x,k-1}: -I at x_{k-1,0}
//!          F_{p,j}:   -I at p_{j,0},  h theta I at p_{j-1,0} (j >= 1),
//!                     -h (1-theta) L_{x_j x_i} at x_{i,0}
//!          F_u:       theta I at p_{k-1,0},  -(1-theta) L_{u x_i} at x_{i,0}
//! ```

use nalgebra::{SMatrix, SVector};

use crate::{Error, Lagrangian};

/// A jet or momentum: $K$ blocks of $\mathbb{R}^N$.
pub type Blocks<const N: usize, const K: usize> = [SVector<f64, N>; K];

const fn check_sizes<const N: usize, const K: usize, const S: usize, const M: usize>() {
    assert!(N > 0 && K > 0, "dimension and order must be positive");
    assert!(S == 2 * N * K, "S must equal 2 N K");
    assert!(M == S + N, "M must equal 2 N K + N");
}

/// Splits $z = (x_0, \dots, x_{K-1}, p_0, \dots, p_{K-1})$ into its two halves of blocks.
pub fn split<const N: usize, const K: usize, const S: usize>(
    z: &SVector<f64, S>,
) -> (Blocks<N, K>, Blocks<N, K>) {
    const { assert!(S == 2 * N * K, "S must equal 2 N K") };
    let x = core::array::from_fn(|j| z.fixed_rows::<N>(j * N).into_owned());
    let p = core::array::from_fn(|j| z.fixed_rows::<N>((K + j) * N).into_owned());
    (x, p)
}

/// Joins two halves of blocks into $z = (x, p)$; the inverse of [`split`].
pub fn join<const N: usize, const K: usize, const S: usize>(
    x: &Blocks<N, K>,
    p: &Blocks<N, K>,
) -> SVector<f64, S> {
    const { assert!(S == 2 * N * K, "S must equal 2 N K") };
    let mut z = SVector::<f64, S>::zeros();
    for j in 0..K {
        z.fixed_rows_mut::<N>(j * N).copy_from(&x[j]);
        z.fixed_rows_mut::<N>((K + j) * N).copy_from(&p[j]);
    }
    z
}

fn finite<const R: usize, const C: usize>(
    m: &SMatrix<f64, R, C>,
    location: &'static str,
) -> Result<(), Error> {
    if m.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Error::NonFinite {
            iteration: 0,
            location,
        })
    }
}

/// The top derivative $u$ and the vector field at $z$ (see
/// [`LiftedSystem::vector_field`](crate::LiftedSystem::vector_field)).
fn vector_field_with_u<L, const N: usize, const K: usize, const S: usize>(
    lagrangian: &L,
    z: &SVector<f64, S>,
) -> Result<(SVector<f64, N>, SVector<f64, S>), Error>
where
    L: Lagrangian<N, K> + ?Sized,
{
    finite(z, "state")?;
    let (x, p) = split::<N, K, S>(z);
    let u = lagrangian.top_derivative(&x, &p[K - 1], &p[K - 1])?;
    let g = lagrangian.gradient(&x, &u);
    let mut dx = [SVector::zeros(); K];
    let mut dp = [SVector::zeros(); K];
    dx[..K - 1].copy_from_slice(&x[1..]);
    dx[K - 1] = u;
    dp[0] = g.x[0];
    for j in 1..K {
        dp[j] = g.x[j] - p[j - 1];
    }
    let f = join::<N, K, S>(&dx, &dp);
    finite(&f, "vector field")?;
    Ok((u, f))
}

/// Hamilton's equations; see [`LiftedSystem::vector_field`](crate::LiftedSystem::vector_field).
///
/// # Errors
/// A failed solve for $u$, or a non-finite state or result.
pub fn vector_field<L, const N: usize, const K: usize, const S: usize>(
    lagrangian: &L,
    z: &SVector<f64, S>,
) -> Result<SVector<f64, S>, Error>
where
    L: Lagrangian<N, K> + ?Sized,
{
    vector_field_with_u::<L, N, K, S>(lagrangian, z).map(|(_, f)| f)
}

/// $H(x, p) = \sum_{j<k-1} p_j \cdot x_{j+1} + p_{k-1} \cdot u - L(x, u)$.
///
/// # Errors
/// A failed solve for $u$, or a non-finite state or result.
pub fn hamiltonian<L, const N: usize, const K: usize, const S: usize>(
    lagrangian: &L,
    z: &SVector<f64, S>,
) -> Result<f64, Error>
where
    L: Lagrangian<N, K> + ?Sized,
{
    finite(z, "state")?;
    let (x, p) = split::<N, K, S>(z);
    let u = lagrangian.top_derivative(&x, &p[K - 1], &p[K - 1])?;
    let mut h = p[K - 1].dot(&u) - lagrangian.lagrangian(&x, &u);
    for j in 0..K - 1 {
        h += p[j].dot(&x[j + 1]);
    }
    if h.is_finite() {
        Ok(h)
    } else {
        Err(Error::NonFinite {
            iteration: 0,
            location: "Hamiltonian",
        })
    }
}

/// The Legendre map $(q, \dots, q^{(2k-1)}) \mapsto (x, p)$.
pub fn legendre<L, const N: usize, const K: usize, const S: usize>(
    lagrangian: &L,
    jet: &SVector<f64, S>,
) -> SVector<f64, S>
where
    L: Lagrangian<N, K> + ?Sized,
{
    let (lower, upper) = split::<N, K, S>(jet);
    join::<N, K, S>(&lower, &lagrangian.momenta(&lower, &upper))
}

/// The evaluation point of a step: $(x_\theta, p_\theta, u)$ and the blocks of $z_0$, $z_1$.
struct Point<const N: usize, const K: usize> {
    x0: Blocks<N, K>,
    p0: Blocks<N, K>,
    x1: Blocks<N, K>,
    p1: Blocks<N, K>,
    x_th: Blocks<N, K>,
    p_th: Blocks<N, K>,
    u: SVector<f64, N>,
}

fn point<const N: usize, const K: usize, const S: usize, const M: usize>(
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    theta: f64,
) -> Point<N, K> {
    const { check_sizes::<N, K, S, M>() };
    let (x0, p0) = split::<N, K, S>(z0);
    let (x1, p1) = split::<N, K, S>(&w.fixed_rows::<S>(0).into_owned());
    let x_th = core::array::from_fn(|j| x0[j] * (1.0 - theta) + x1[j] * theta);
    let p_th = core::array::from_fn(|j| p0[j] * theta + p1[j] * (1.0 - theta));
    let u = w.fixed_rows::<N>(S).into_owned();
    Point {
        x0,
        p0,
        x1,
        p1,
        x_th,
        p_th,
        u,
    }
}

/// Row (or column) offset of block $x_j$, $p_j$ and $u$ in the flat vectors.
const fn x_at<const N: usize>(j: usize) -> usize {
    j * N
}
const fn p_at<const N: usize, const K: usize>(j: usize) -> usize {
    (K + j) * N
}

/// The residual $F(z_0, w)$ of the theta-scheme
/// (see [`LiftedSystem`](crate::LiftedSystem)).
pub fn residual<L, const N: usize, const K: usize, const S: usize, const M: usize>(
    lagrangian: &L,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    h: f64,
    theta: f64,
) -> SVector<f64, M>
where
    L: Lagrangian<N, K> + ?Sized,
{
    let pt = point::<N, K, S, M>(z0, w, theta);
    let g = lagrangian.gradient(&pt.x_th, &pt.u);
    let mut f = SVector::<f64, M>::zeros();
    for j in 0..K {
        let rate = if j + 1 < K { pt.x_th[j + 1] } else { pt.u };
        f.fixed_rows_mut::<N>(x_at::<N>(j))
            .copy_from(&(pt.x1[j] - pt.x0[j] - rate * h));
        let mut force = g.x[j];
        if j > 0 {
            force -= pt.p_th[j - 1];
        }
        f.fixed_rows_mut::<N>(p_at::<N, K>(j))
            .copy_from(&(pt.p1[j] - pt.p0[j] - force * h));
    }
    f.fixed_rows_mut::<N>(S).copy_from(&(pt.p_th[K - 1] - g.u));
    f
}

/// $\partial F/\partial w$ of the theta-scheme (formulas in the module docs).
pub fn jacobian<L, const N: usize, const K: usize, const S: usize, const M: usize>(
    lagrangian: &L,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    h: f64,
    theta: f64,
) -> SMatrix<f64, M, M>
where
    L: Lagrangian<N, K> + ?Sized,
{
    let pt = point::<N, K, S, M>(z0, w, theta);
    let hs = lagrangian.hessian(&pt.x_th, &pt.u);
    let eye = SMatrix::<f64, N, N>::identity();
    let mut jac = SMatrix::<f64, M, M>::zeros();
    for j in 0..K {
        let row = x_at::<N>(j);
        jac.fixed_view_mut::<N, N>(row, x_at::<N>(j))
            .copy_from(&eye);
        if j + 1 < K {
            jac.fixed_view_mut::<N, N>(row, x_at::<N>(j + 1))
                .copy_from(&(eye * (-h * theta)));
        } else {
            jac.fixed_view_mut::<N, N>(row, S).copy_from(&(eye * -h));
        }
        let row = p_at::<N, K>(j);
        jac.fixed_view_mut::<N, N>(row, p_at::<N, K>(j))
            .copy_from(&eye);
        if j > 0 {
            jac.fixed_view_mut::<N, N>(row, p_at::<N, K>(j - 1))
                .copy_from(&(eye * (h * (1.0 - theta))));
        }
        for i in 0..K {
            jac.fixed_view_mut::<N, N>(row, x_at::<N>(i))
                .copy_from(&(hs.xx[j][i] * (-h * theta)));
        }
        jac.fixed_view_mut::<N, N>(row, S)
            .copy_from(&(hs.xu[j] * -h));
    }
    jac.fixed_view_mut::<N, N>(S, p_at::<N, K>(K - 1))
        .copy_from(&(eye * (1.0 - theta)));
    for i in 0..K {
        jac.fixed_view_mut::<N, N>(S, x_at::<N>(i))
            .copy_from(&(hs.xu[i].transpose() * -theta));
    }
    jac.fixed_view_mut::<N, N>(S, S).copy_from(&(-hs.uu));
    jac
}

/// $\partial F/\partial z_0$ of the theta-scheme (formulas in the module docs).
pub fn jacobian_initial<L, const N: usize, const K: usize, const S: usize, const M: usize>(
    lagrangian: &L,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    h: f64,
    theta: f64,
) -> SMatrix<f64, M, S>
where
    L: Lagrangian<N, K> + ?Sized,
{
    let pt = point::<N, K, S, M>(z0, w, theta);
    let hs = lagrangian.hessian(&pt.x_th, &pt.u);
    let eye = SMatrix::<f64, N, N>::identity();
    let mut jac = SMatrix::<f64, M, S>::zeros();
    for j in 0..K {
        let row = x_at::<N>(j);
        jac.fixed_view_mut::<N, N>(row, x_at::<N>(j))
            .copy_from(&(-eye));
        if j + 1 < K {
            jac.fixed_view_mut::<N, N>(row, x_at::<N>(j + 1))
                .copy_from(&(eye * (-h * (1.0 - theta))));
        }
        let row = p_at::<N, K>(j);
        jac.fixed_view_mut::<N, N>(row, p_at::<N, K>(j))
            .copy_from(&(-eye));
        if j > 0 {
            jac.fixed_view_mut::<N, N>(row, p_at::<N, K>(j - 1))
                .copy_from(&(eye * (h * theta)));
        }
        for i in 0..K {
            jac.fixed_view_mut::<N, N>(row, x_at::<N>(i))
                .copy_from(&(hs.xx[j][i] * (-h * (1.0 - theta))));
        }
    }
    jac.fixed_view_mut::<N, N>(S, p_at::<N, K>(K - 1))
        .copy_from(&(eye * theta));
    for i in 0..K {
        jac.fixed_view_mut::<N, N>(S, x_at::<N>(i))
            .copy_from(&(hs.xu[i].transpose() * -(1.0 - theta)));
    }
    jac
}

/// $h\thinspace L(x_\theta, u)$, the cost of one step.
pub fn step_cost<L, const N: usize, const K: usize, const S: usize, const M: usize>(
    lagrangian: &L,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    h: f64,
    theta: f64,
) -> f64
where
    L: Lagrangian<N, K> + ?Sized,
{
    let pt = point::<N, K, S, M>(z0, w, theta);
    h * lagrangian.lagrangian(&pt.x_th, &pt.u)
}

/// Explicit Euler guess $w = (z_0 + h\thinspace z'(z_0),\ u(z_0))$.
///
/// # Errors
/// When the vector field at $z_0$ cannot be evaluated.
pub fn predictor<L, const N: usize, const K: usize, const S: usize, const M: usize>(
    lagrangian: &L,
    z0: &SVector<f64, S>,
    h: f64,
) -> Result<SVector<f64, M>, Error>
where
    L: Lagrangian<N, K> + ?Sized,
{
    const { check_sizes::<N, K, S, M>() };
    let (u, f) = vector_field_with_u::<L, N, K, S>(lagrangian, z0)?;
    let mut w = SVector::<f64, M>::zeros();
    w.fixed_rows_mut::<S>(0).copy_from(&(z0 + f * h));
    w.fixed_rows_mut::<N>(S).copy_from(&u);
    Ok(w)
}

/// Implements [`LiftedSystem`](crate::LiftedSystem) for a type that implements
/// [`Lagrangian<N, K>`](crate::Lagrangian), with the general unknowns $w = (z_1, u)$:
/// `impl_lifted_system!(MyType, n = 2, k = 2);`
#[macro_export]
macro_rules! impl_lifted_system {
    ($ty:ty, n = $n:expr, k = $k:expr) => {
        impl $crate::LiftedSystem<{ 2 * $n * $k }, { 2 * $n * $k + $n }> for $ty {
            const DIMENSION: usize = $n;
            const ORDER: usize = $k;

            fn hamiltonian(
                &self,
                z: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
            ) -> ::core::result::Result<f64, $crate::Error> {
                $crate::scheme::lifted::hamiltonian::<Self, $n, $k, { 2 * $n * $k }>(self, z)
            }

            fn vector_field(
                &self,
                z: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
            ) -> ::core::result::Result<
                $crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
                $crate::Error,
            > {
                $crate::scheme::lifted::vector_field::<Self, $n, $k, { 2 * $n * $k }>(self, z)
            }

            fn legendre(
                &self,
                jet: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
            ) -> $crate::nalgebra::SVector<f64, { 2 * $n * $k }> {
                $crate::scheme::lifted::legendre::<Self, $n, $k, { 2 * $n * $k }>(self, jet)
            }

            fn residual(
                &self,
                z0: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
                w: &$crate::nalgebra::SVector<f64, { 2 * $n * $k + $n }>,
                h: f64,
                theta: f64,
            ) -> $crate::nalgebra::SVector<f64, { 2 * $n * $k + $n }> {
                $crate::scheme::lifted::residual::<
                    Self,
                    $n,
                    $k,
                    { 2 * $n * $k },
                    { 2 * $n * $k + $n },
                >(self, z0, w, h, theta)
            }

            fn jacobian(
                &self,
                z0: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
                w: &$crate::nalgebra::SVector<f64, { 2 * $n * $k + $n }>,
                h: f64,
                theta: f64,
            ) -> $crate::nalgebra::SMatrix<f64, { 2 * $n * $k + $n }, { 2 * $n * $k + $n }> {
                $crate::scheme::lifted::jacobian::<
                    Self,
                    $n,
                    $k,
                    { 2 * $n * $k },
                    { 2 * $n * $k + $n },
                >(self, z0, w, h, theta)
            }

            fn jacobian_initial(
                &self,
                z0: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
                w: &$crate::nalgebra::SVector<f64, { 2 * $n * $k + $n }>,
                h: f64,
                theta: f64,
            ) -> $crate::nalgebra::SMatrix<f64, { 2 * $n * $k + $n }, { 2 * $n * $k }> {
                $crate::scheme::lifted::jacobian_initial::<
                    Self,
                    $n,
                    $k,
                    { 2 * $n * $k },
                    { 2 * $n * $k + $n },
                >(self, z0, w, h, theta)
            }

            fn step_cost(
                &self,
                z0: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
                w: &$crate::nalgebra::SVector<f64, { 2 * $n * $k + $n }>,
                h: f64,
                theta: f64,
            ) -> f64 {
                $crate::scheme::lifted::step_cost::<
                    Self,
                    $n,
                    $k,
                    { 2 * $n * $k },
                    { 2 * $n * $k + $n },
                >(self, z0, w, h, theta)
            }

            fn predictor(
                &self,
                z0: &$crate::nalgebra::SVector<f64, { 2 * $n * $k }>,
                h: f64,
                _theta: f64,
            ) -> ::core::result::Result<
                $crate::nalgebra::SVector<f64, { 2 * $n * $k + $n }>,
                $crate::Error,
            > {
                $crate::scheme::lifted::predictor::<
                    Self,
                    $n,
                    $k,
                    { 2 * $n * $k },
                    { 2 * $n * $k + $n },
                >(self, z0, h)
            }
        }
    };
}
