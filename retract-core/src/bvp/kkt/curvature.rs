//! The spectrum of the reduced Hessian $Z^T \nabla^2 J\thinspace Z$ of a factorised subproblem
//! through its solution operator: the smallest eigenvalue a plan is certified with (Lanczos on
//! the inverse).

use nalgebra::SVector;

use super::model::{StageLinear, Terminal};
use super::riccati::{Riccati, Vectors};
use crate::bvp::dynamics::Dynamics;

/// The smallest eigenvalue of the reduced Hessian $Z^T \nabla^2 J\thinspace Z$ ($Z$ orthonormal) of
/// a positive definite factorisation, by Lanczos on its inverse: the subproblem's solution
/// operator $v \mapsto \delta$ (min $\tfrac12 \delta^T \nabla^2 J \delta - v^T \delta$ subject
/// to the homogeneous constraints) is $Z (Z^T \nabla^2 J Z)^{-1} Z^T$, whose largest
/// eigenvalue is the reciprocal of the one sought. The variables ([`Packing`]) are the free
/// components of $x_0$ (`end`'s `start_fixed` 0), the interior nodes, the free components of
/// $x_N$ (`fixed` 0) and the top derivatives. $+\infty$ where the constraints (the scheme's
/// $N X$ rows and the stages' `equalities` rows) leave no direction: the minimum over an
/// empty set (e.g. $N = k$ steps between fixed ends, where the plan is the one path that
/// meets the ends). That count holds for independent rows only: where the goal and the stage
/// equalities are dependent (the factorisation's terminal pivot needed its $\delta_c$ shift,
/// [`Riccati::regularized`]) fewer rows bind than are counted, and Lanczos runs whatever the
/// count. Lanczos stops when the Ritz residual of
/// the top Ritz value $\vartheta$ is below $10^{-3}\vartheta$ (the eigenvalue then has about
/// six digits; 2 to 12 solves on the constrained suite and the swing-ups, less than one SQP
/// iteration). NaN if the start vector vanishes.
pub(crate) fn min_reduced_eigenvalue<const N: usize, const X: usize>(
    riccati: &Riccati<N, X>,
    dynamics: &Dynamics<N, X>,
    (end, equalities): (&Terminal<X>, usize),
    pool: &mut impl Vectors<N, X>,
) -> f64 {
    let packing = Packing::new(riccati.steps(), end);
    let dim = packing.dim::<N>();
    if dim <= riccati.steps() * X + equalities && !riccati.regularized {
        return f64::INFINITY;
    }
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // a start vector in the null space: the operator applied to a fixed pseudo-random vector
    let mut seed = pool.lanczos().take(dim);
    seed.extend(start_vector(dim));
    let mut q = pool.lanczos().take(dim);
    apply_inverse(riccati, dynamics, &packing, &seed, &mut q, pool);
    let (mut q_prev, mut w) = (seed, pool.lanczos().take(dim));
    q_prev.iter_mut().for_each(|x| *x = 0.0);
    let (mut alphas, mut betas) = (
        pool.lanczos().take(LANCZOS_STEPS),
        pool.lanczos().take(LANCZOS_STEPS),
    );
    let norm = dot(&q, &q).sqrt();
    let mut largest = f64::NAN;
    if norm > 0.0 && norm.is_finite() {
        q.iter_mut().for_each(|x| *x /= norm);
        let mut beta = 0.0;
        for m in 0..dim.min(LANCZOS_STEPS) {
            apply_inverse(riccati, dynamics, &packing, &q, &mut w, pool);
            for (wi, pi) in w.iter_mut().zip(&q_prev) {
                *wi -= beta * pi;
            }
            let alpha = dot(&w, &q);
            for (wi, qi) in w.iter_mut().zip(&q) {
                *wi -= alpha * qi;
            }
            beta = dot(&w, &w).sqrt();
            alphas.push(alpha);
            betas.push(beta);
            if m >= 2 || beta <= 1e-14 * alpha.abs() {
                let (top, last) = tridiagonal_top(&alphas, &betas[..m]);
                largest = top;
                if beta * last <= 1e-3 * top.abs() || beta <= 1e-14 * alpha.abs() || top.is_nan() {
                    break;
                }
            }
            core::mem::swap(&mut q_prev, &mut q);
            core::mem::swap(&mut q, &mut w);
            q.iter_mut().for_each(|x| *x /= beta);
        }
    }
    for v in [q, q_prev, w, alphas, betas] {
        pool.lanczos().give(v);
    }
    1.0 / largest
}

/// The power iterations of [`most_negative_direction`].
const POWER_STEPS: usize = 40;

/// A direction of the most negative curvature of the reduced Hessian, from a positive
/// definite factorisation of it shifted ($Z^T (\nabla^2 J + \sigma M) Z$, $M$ positive
/// definite, $\sigma$ above the magnitude of the most negative eigenvalue): the solution
/// operator's dominant eigenvector, the largest $1/(\lambda + \sigma)$, by [`POWER_STEPS`]
/// power iterations from a fixed start vector. Written into `dx` (every node, 0 at the fixed
/// end components, [`Packing`]) and `du` (both emptied first), scaled to max-norm 1; `false`
/// if it vanishes or is not finite.
pub(crate) fn most_negative_direction<const N: usize, const X: usize>(
    riccati: &Riccati<N, X>,
    dynamics: &Dynamics<N, X>,
    end: &Terminal<X>,
    (dx, du): (&mut Vec<SVector<f64, X>>, &mut Vec<SVector<f64, N>>),
    pool: &mut impl Vectors<N, X>,
) -> bool {
    let steps = riccati.steps();
    let packing = Packing::new(steps, end);
    let dim = packing.dim::<N>();
    let mut v = pool.lanczos().take(dim);
    v.extend(start_vector(dim));
    let mut w = pool.lanczos().take(dim);
    let mut found = true;
    for _ in 0..POWER_STEPS {
        apply_inverse(riccati, dynamics, &packing, &v, &mut w, pool);
        let norm = w.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        if !(norm > 0.0 && norm.is_finite()) {
            found = false;
            break;
        }
        w.iter_mut().for_each(|x| *x /= norm);
        core::mem::swap(&mut v, &mut w);
    }
    dx.clear();
    du.clear();
    if found {
        let tops = packing.offsets().2;
        for i in 0..=steps {
            let mut d = SVector::<f64, X>::zeros();
            for (j, r) in packing.node(i) {
                d[r] = v[j];
            }
            dx.push(d);
        }
        du.extend((0..steps).map(|i| SVector::<f64, N>::from_fn(|a, _| v[tops + i * N + a])));
    }
    pool.lanczos().give(v);
    pool.lanczos().give(w);
    found
}

/// The fixed pseudo-random start vector of the iterations here: entry $j$ is
/// $\mathrm{frac}((j + 1)\varphi) - \tfrac12$, $\varphi$ the golden ratio's fractional part
/// (equidistributed, so no direction of the operator is missed in practice).
fn start_vector(dim: usize) -> impl Iterator<Item = f64> {
    (0..dim).map(|j| ((j as f64 + 1.0) * 0.618_033_988_749_895).fract() - 0.5)
}

/// The most Lanczos steps of [`min_reduced_eigenvalue`].
const LANCZOS_STEPS: usize = 150;

/// Where the variables of [`min_reduced_eigenvalue`] sit in one vector: the free components
/// of $x_0$ (`start`), then the interior nodes $x_1, \dots, x_{N-1}$, the free components of
/// $x_N$ (`end`), and $u_0, \dots, u_{N-1}$.
struct Packing<const X: usize> {
    steps: usize,
    start: SVector<bool, X>,
    end: SVector<bool, X>,
}

impl<const X: usize> Packing<X> {
    fn new(steps: usize, end: &Terminal<X>) -> Self {
        Self {
            steps,
            start: end.start_fixed.map(|f| f == 0.0),
            end: end.fixed.map(|f| f == 0.0),
        }
    }

    /// The offsets of the interior nodes, the free end components and the top derivatives.
    fn offsets(&self) -> (usize, usize, usize) {
        let count = |free: &SVector<bool, X>| free.iter().filter(|f| **f).count();
        let inner = count(&self.start);
        let end = inner + (self.steps - 1) * X;
        (inner, end, end + count(&self.end))
    }

    fn dim<const N: usize>(&self) -> usize {
        self.offsets().2 + self.steps * N
    }

    /// The packed entries of node `i`'s components: the vector's indices of its free
    /// components (all of an interior node's).
    fn node(&self, i: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let (inner, end, _) = self.offsets();
        let (free, base) = if i == 0 {
            (Some(&self.start), 0)
        } else if i == self.steps {
            (Some(&self.end), end)
        } else {
            (None, inner + (i - 1) * X)
        };
        (0..X)
            .filter(move |r| free.is_none_or(|f| f[*r]))
            .enumerate()
            .map(move |(j, r)| (base + j, r))
    }
}

/// `out` $= Z (Z^T \nabla^2 J Z)^{-1} Z^T v$ in the variables of `packing`: the subproblem's
/// solution for the linear terms $-v$, with homogeneous constraints.
fn apply_inverse<const N: usize, const X: usize>(
    riccati: &Riccati<N, X>,
    dynamics: &Dynamics<N, X>,
    packing: &Packing<X>,
    v: &[f64],
    out: &mut Vec<f64>,
    pool: &mut impl Vectors<N, X>,
) {
    let steps = riccati.steps();
    let tops = packing.offsets().2;
    let node = |i: usize| {
        let mut l = SVector::<f64, X>::zeros();
        for (j, r) in packing.node(i) {
            l[r] = -v[j];
        }
        l
    };
    let linear = |i: usize| StageLinear {
        lx: node(i),
        lu: SVector::<f64, N>::from_fn(|a, _| -v[tops + i * N + a]),
        defect: SVector::zeros(),
        constraint: SVector::zeros(),
    };
    let zero = SVector::<f64, X>::zeros();
    let s_end = node(steps);
    let d = riccati.solve_linear(dynamics, &linear, &zero, (&zero, &s_end), pool);
    out.clear();
    out.resize(packing.dim::<N>(), 0.0);
    for (i, dx) in d.dx.iter().enumerate() {
        for (j, r) in packing.node(i) {
            out[j] = dx[r];
        }
    }
    for (i, du) in d.du.iter().enumerate() {
        out[tops + i * N..tops + (i + 1) * N].copy_from_slice(du.as_slice());
    }
    d.recycle(pool);
}

/// The largest eigenvalue $\vartheta$ of the symmetric tridiagonal matrix $T$ with diagonal
/// `alpha` and off-diagonal `beta` ($T_{j,j+1} = \beta_j$; at most [`LANCZOS_STEPS`] rows),
/// and $|v_m|$, the last component of its unit eigenvector: $\vartheta$ by bisection on the
/// Sturm count (the negative pivots of $T - x I$ are the eigenvalues below $x$), $v$ by two
/// steps of inverse iteration with the shift just above $\vartheta$, where
/// $\sigma I - T$ is positive definite and its tridiagonal elimination needs no pivoting.
fn tridiagonal_top(alpha: &[f64], beta: &[f64]) -> (f64, f64) {
    let m = alpha.len().min(LANCZOS_STEPS);
    let coupling = |j: usize| beta.get(j).copied().unwrap_or(0.0);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (j, a) in alpha.iter().enumerate().take(m) {
        let radius = coupling(j).abs() + if j > 0 { coupling(j - 1).abs() } else { 0.0 };
        (lo, hi) = (lo.min(a - radius), hi.max(a + radius));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return (f64::NAN, f64::NAN);
    }
    let below = |x: f64| {
        let (mut count, mut d) = (0, 1.0);
        for (j, a) in alpha.iter().enumerate().take(m) {
            let off = if j > 0 { coupling(j - 1) } else { 0.0 };
            d = a - x - off * off / d;
            if d == 0.0 {
                d = -f64::MIN_POSITIVE;
            }
            count += usize::from(d < 0.0);
        }
        count
    };
    // the largest eigenvalue: the least x with all m eigenvalues below it
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if below(mid) == m { hi = mid } else { lo = mid }
    }
    let top = hi;
    let scale = alpha
        .iter()
        .take(m)
        .fold(0.0_f64, |s, a| s.max(a.abs()))
        .max(f64::MIN_POSITIVE);
    let sigma = top + 1e-10 * scale;
    let (mut v, mut upper) = ([1.0; LANCZOS_STEPS], [0.0; LANCZOS_STEPS]);
    for _ in 0..2 {
        // (sigma I - T) y = v by elimination from the top (diagonal pivots stay positive)
        let mut pivot = sigma - alpha[0];
        v[0] /= pivot;
        for j in 1..m {
            upper[j - 1] = -coupling(j - 1) / pivot;
            pivot = sigma - alpha[j] + coupling(j - 1) * upper[j - 1];
            v[j] = (v[j] + coupling(j - 1) * v[j - 1]) / pivot;
        }
        for j in (0..m - 1).rev() {
            v[j] -= upper[j] * v[j + 1];
        }
        let norm = v[..m].iter().map(|x| x * x).sum::<f64>().sqrt();
        v[..m].iter_mut().for_each(|x| *x /= norm);
    }
    (top, v[m - 1].abs())
}
