//! The dynamics of the transcription: the lifted scheme's $x$-equations are linear in
//! $(x_i, u_i)$, one constant map per $(h, \theta)$, applied through structured products with
//! the block shift (`shift`). Imports nothing else of the planner.

use nalgebra::{SMatrix, SVector};

mod shift;
pub(crate) use shift::{BlockColumn, BlockPoly};

/// The constant linear dynamics of the lifted scheme's $x$-equations for one $(h, \theta)$:
/// $x_{i+1} = \bar A x_i + \bar B u_i$ with $\bar A = W (I + h(1-\theta) A)$, $\bar B = W h B$,
/// $W = (I - h\theta A)^{-1} = \sum_m (h \theta A)^m$, $A$ the block shift
/// ($x_j' = x_{j+1}$) and $B$ the last block ($x_{k-1}' = u$).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dynamics<const N: usize, const X: usize> {
    pub h: f64,
    pub theta: f64,
    /// $\bar A$ (dense, for the tests; the solver uses `poly_a`).
    #[cfg(test)]
    pub a: SMatrix<f64, X, X>,
    /// $\bar B$.
    pub b: SMatrix<f64, X, N>,
    /// $E = (1 - \theta) I + \theta \bar A$: $x_\theta$ as a function of $x_i$ (given $u$).
    pub e: SMatrix<f64, X, X>,
    /// $W = (I - h\theta A)^{-1}$ (dense, for the tests; the solver uses `poly_w`).
    #[cfg(test)]
    pub w: SMatrix<f64, X, X>,
    /// $\bar A$, $E$, $W$ and $\bar B$ as polynomials in the block shift ([`shift`]).
    pub poly_a: BlockPoly<N, X>,
    pub poly_e: BlockPoly<N, X>,
    pub poly_w: BlockPoly<N, X>,
    pub poly_b: BlockColumn<N, X>,
}

impl<const N: usize, const X: usize> Dynamics<N, X> {
    pub fn new(h: f64, theta: f64) -> Self {
        let k = X / N;
        let shift = SMatrix::<f64, X, X>::from_fn(|r, c| if c == r + N { 1.0 } else { 0.0 });
        let last =
            SMatrix::<f64, X, N>::from_fn(|r, c| if r == (k - 1) * N + c { 1.0 } else { 0.0 });
        let mut w = SMatrix::<f64, X, X>::identity();
        let mut power = SMatrix::<f64, X, X>::identity();
        for _ in 1..k {
            power = power * shift * (h * theta);
            w += power;
        }
        let a = w * (SMatrix::<f64, X, X>::identity() + shift * (h * (1.0 - theta)));
        let b = w * last * h;
        let e = SMatrix::<f64, X, X>::identity() * (1.0 - theta) + a * theta;
        Self {
            h,
            theta,
            #[cfg(test)]
            a,
            b,
            e,
            #[cfg(test)]
            w,
            poly_a: BlockPoly::of(&a),
            poly_e: BlockPoly::of(&e),
            poly_w: BlockPoly::of(&w),
            poly_b: BlockColumn::of(&b),
        }
    }

    /// $x_{i+1} = \bar A x_i + \bar B u_i$.
    pub fn next(&self, x: &SVector<f64, X>, u: &SVector<f64, N>) -> SVector<f64, X> {
        self.poly_a.left(x) + self.poly_b.left(u)
    }
}
