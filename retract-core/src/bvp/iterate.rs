//! The optimizer's unknowns: the jets $x_0, \dots, x_N$ and the top derivatives
//! $u_0, \dots, u_{N-1}$ of an iterate, and a jet read as its blocks. Imports nothing of the
//! planner: every other module may use it.

use nalgebra::SVector;

/// $x$ as blocks $(x_0, \dots, x_{k-1})$.
pub(crate) fn blocks<const N: usize, const K: usize, const X: usize>(
    x: &SVector<f64, X>,
) -> [SVector<f64, N>; K] {
    core::array::from_fn(|j| SVector::from_fn(|a, _| x[j * N + a]))
}

/// The iterate of the optimizer.
#[derive(Clone)]
pub(super) struct Iterate<const N: usize, const X: usize> {
    pub x: Vec<SVector<f64, X>>,
    pub u: Vec<SVector<f64, N>>,
}
