//! Stage constraints of the optimizer: equalities $g(x_\theta, u) = 0$ and inequalities
//! $g(x_\theta, u) \ge 0$ at the evaluation point of every step, either a [`JetFunction`]
//! written as plain Rust (differentiated by `#[jet_function]`) or a bound on one variable.

use nalgebra::{SMatrix, SVector};

use super::optimize::blocks;
use crate::{Hessian, JetFunction};

/// A variable of a step that a bound applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variable {
    /// Entry `r` of the jet $x = (q, q', \dots, q^{(k-1)})$ (blocks of $n$: entry $j n + a$
    /// is $q_a^{(j)}$), at the step's evaluation point $x_\theta$.
    Jet(usize),
    /// Component `a` of the top derivative $u = q^{(k)}$.
    Top(usize),
}

/// One scalar stage constraint.
#[derive(Clone, Copy)]
pub(super) enum StageConstraint<'a, const N: usize, const K: usize> {
    /// $g(x_\theta, u)$.
    Function(&'a (dyn JetFunction<N, K> + Sync)),
    /// $\pm(v - \text{value})$: the variable above (sign +1) or below (sign -1) a value.
    Bound {
        variable: Variable,
        value: f64,
        sign: f64,
    },
}

/// Value, gradient $(\partial_x, \partial_u)$ of a stage constraint at $(x_\theta, u)$.
pub(super) struct Linearized<const N: usize, const X: usize> {
    pub value: f64,
    pub gx: SVector<f64, X>,
    pub gu: SVector<f64, N>,
}

impl<const N: usize, const K: usize> StageConstraint<'_, N, K> {
    /// The constraint's value alone.
    pub fn value<const X: usize>(&self, x: &SVector<f64, X>, u: &SVector<f64, N>) -> f64 {
        match *self {
            StageConstraint::Function(g) => g.value(&blocks::<N, K, X>(x), u),
            StageConstraint::Bound {
                variable,
                value,
                sign,
            } => sign * (read(variable, x, u) - value),
        }
    }

    /// Value and gradient.
    pub fn linearize<const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
    ) -> Linearized<N, X> {
        match *self {
            StageConstraint::Function(g) => {
                let xb = blocks::<N, K, X>(x);
                let grad = g.gradient(&xb, u);
                Linearized {
                    value: g.value(&xb, u),
                    gx: SVector::from_fn(|r, _| grad.x[r / N][r % N]),
                    gu: grad.u,
                }
            }
            StageConstraint::Bound {
                variable,
                value,
                sign,
            } => {
                let (mut gx, mut gu) = (SVector::zeros(), SVector::zeros());
                match variable {
                    Variable::Jet(r) => gx[r] = sign,
                    Variable::Top(a) => gu[a] = sign,
                }
                Linearized {
                    value: sign * (read(variable, x, u) - value),
                    gx,
                    gu,
                }
            }
        }
    }

    /// `weight` times the Hessian blocks $(H_{xx}, H_{ux}, H_{uu})$ (zero for a bound).
    pub fn weighted_hessian<const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
        weight: f64,
    ) -> Option<(SMatrix<f64, X, X>, SMatrix<f64, N, X>, SMatrix<f64, N, N>)> {
        match self {
            StageConstraint::Function(g) if weight != 0.0 => Some(flat_hessian::<N, K, X>(
                &g.hessian(&blocks::<N, K, X>(x), u),
                weight,
            )),
            _ => None,
        }
    }

    /// Whether the constraint is well formed for jets of length `X`.
    pub fn valid<const X: usize>(&self) -> bool {
        match *self {
            StageConstraint::Function(_) => true,
            StageConstraint::Bound {
                variable, value, ..
            } => {
                let inside = match variable {
                    Variable::Jet(r) => r < X,
                    Variable::Top(a) => a < N,
                };
                inside && value.is_finite()
            }
        }
    }
}

fn read<const N: usize, const X: usize>(
    variable: Variable,
    x: &SVector<f64, X>,
    u: &SVector<f64, N>,
) -> f64 {
    match variable {
        Variable::Jet(r) => x[r],
        Variable::Top(a) => u[a],
    }
}

/// `scale` times the Hessian blocks of a function of $(x, u)$ as $(H_{xx}, H_{ux}, H_{uu})$
/// over the flat jet.
#[inline(always)]
pub(super) fn flat_hessian<const N: usize, const K: usize, const X: usize>(
    hs: &Hessian<N, K>,
    scale: f64,
) -> (SMatrix<f64, X, X>, SMatrix<f64, N, X>, SMatrix<f64, N, N>) {
    let mut hxx = SMatrix::<f64, X, X>::zeros();
    let mut hux = SMatrix::<f64, N, X>::zeros();
    // block by block with constant bounds (the compiler unrolls the copies)
    for (i, row) in hs.xx.iter().enumerate() {
        for (j, block) in row.iter().enumerate() {
            for b in 0..N {
                for a in 0..N {
                    hxx[(i * N + a, j * N + b)] = scale * block[(a, b)];
                }
            }
        }
    }
    for (j, block) in hs.xu.iter().enumerate() {
        for b in 0..N {
            for a in 0..N {
                hux[(b, j * N + a)] = scale * block[(a, b)];
            }
        }
    }
    (hxx, hux, hs.uu * scale)
}
