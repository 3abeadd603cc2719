//! Products with the scheme's constant matrices, which are polynomials in the block shift.
//!
//! With $S$ the block shift on jets ($(S x)_j = x_{j+1}$, blocks of $n$), the matrices of the
//! lifted scheme's $x$-equations are $\bar A = \sum_d a_d S^d$, $E = \sum_d e_d S^d$,
//! $W = \sum_d w_d S^d$ (scalar coefficients, $d < k$) and $\bar B = \sum_d b_d S^d B$, whose
//! block row $j$ is $b_{k-1-j} I$. A product with them costs $O(k)$ block operations instead
//! of a dense $nk \times nk$ one.

use nalgebra::SMatrix;

/// $\sum_d c_d S^d$ on jets of $X = nk$ entries in blocks of `N`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockPoly<const N: usize, const X: usize> {
    /// $c_d$ for $d < k$ (zero beyond).
    c: [f64; X],
}

/// A matrix $X \times N$ whose block row $j$ is $b_j I$ (such as $\bar B$).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockColumn<const N: usize, const X: usize> {
    b: [f64; X],
}

/// `dst += c src`, entry by entry.
#[inline(always)]
fn axpy(dst: &mut [f64], c: f64, src: &[f64]) {
    for (d, s) in dst.iter_mut().zip(src) {
        *d += c * s;
    }
}

// The products work on the column-major storage slices: a column of an R x C matrix is
// `R` consecutive entries, and a block of `N` rows within a column is `N` consecutive
// entries, so every update is an `axpy` on contiguous runs (vectorised, bounds checked once
// per run rather than per entry).

impl<const N: usize, const X: usize> BlockPoly<N, X> {
    /// The coefficients of a matrix known to be a polynomial in $S$: its first block row.
    pub fn of(m: &SMatrix<f64, X, X>) -> Self {
        Self {
            c: core::array::from_fn(|d| if d * N < X { m[(0, d * N)] } else { 0.0 }),
        }
    }

    /// $M P(S)$: column block $j$ is $\sum_{d \le j} c_d$ times column block $j - d$ of $M$.
    #[inline(always)]
    pub fn right<const R: usize>(&self, m: &SMatrix<f64, R, X>) -> SMatrix<f64, R, X> {
        let mut out = SMatrix::<f64, R, X>::zeros();
        let (src, dst) = (m.as_slice(), out.as_mut_slice());
        let block = R * N;
        for j in 0..X / N {
            for d in 0..=j {
                let from = (j - d) * block;
                axpy(
                    &mut dst[j * block..(j + 1) * block],
                    self.c[d],
                    &src[from..from + block],
                );
            }
        }
        out
    }

    /// $P(S)^T M$: row block $j$ is $\sum_{d \le j} c_d$ times row block $j - d$ of $M$.
    #[inline(always)]
    pub fn left_t<const C: usize>(&self, m: &SMatrix<f64, X, C>) -> SMatrix<f64, X, C> {
        let mut out = SMatrix::<f64, X, C>::zeros();
        let (src, dst) = (m.as_slice(), out.as_mut_slice());
        for col in 0..C {
            let base = col * X;
            for j in 0..X / N {
                for d in 0..=j {
                    let from = base + (j - d) * N;
                    let to = base + j * N;
                    axpy(&mut dst[to..to + N], self.c[d], &src[from..from + N]);
                }
            }
        }
        out
    }

    /// $P(S) M$: row block $j$ is $\sum_{j + d < k} c_d$ times row block $j + d$ of $M$.
    #[inline(always)]
    pub fn left<const C: usize>(&self, m: &SMatrix<f64, X, C>) -> SMatrix<f64, X, C> {
        let k = X / N;
        let mut out = SMatrix::<f64, X, C>::zeros();
        let (src, dst) = (m.as_slice(), out.as_mut_slice());
        for col in 0..C {
            let base = col * X;
            for j in 0..k {
                for d in 0..k - j {
                    let from = base + (j + d) * N;
                    let to = base + j * N;
                    axpy(&mut dst[to..to + N], self.c[d], &src[from..from + N]);
                }
            }
        }
        out
    }
}

impl<const N: usize, const X: usize> BlockColumn<N, X> {
    /// The coefficients of a matrix known to have this form: the first entry of each block.
    pub fn of(m: &SMatrix<f64, X, N>) -> Self {
        Self {
            b: core::array::from_fn(|j| if j * N < X { m[(j * N, 0)] } else { 0.0 }),
        }
    }

    /// $M \bar B = \sum_j b_j$ (column block $j$ of $M$).
    #[inline(always)]
    pub fn right<const R: usize>(&self, m: &SMatrix<f64, R, X>) -> SMatrix<f64, R, N> {
        let mut out = SMatrix::<f64, R, N>::zeros();
        let (src, dst) = (m.as_slice(), out.as_mut_slice());
        let block = R * N;
        for j in 0..X / N {
            axpy(dst, self.b[j], &src[j * block..(j + 1) * block]);
        }
        out
    }

    /// $\bar B^T M = \sum_j b_j$ (row block $j$ of $M$).
    #[inline(always)]
    pub fn left_t<const C: usize>(&self, m: &SMatrix<f64, X, C>) -> SMatrix<f64, N, C> {
        let mut out = SMatrix::<f64, N, C>::zeros();
        let (src, dst) = (m.as_slice(), out.as_mut_slice());
        for col in 0..C {
            for j in 0..X / N {
                let from = col * X + j * N;
                axpy(
                    &mut dst[col * N..(col + 1) * N],
                    self.b[j],
                    &src[from..from + N],
                );
            }
        }
        out
    }

    /// $\bar B M$: row block $j$ is $b_j M$.
    #[inline(always)]
    pub fn left<const C: usize>(&self, m: &SMatrix<f64, N, C>) -> SMatrix<f64, X, C> {
        SMatrix::<f64, X, C>::from_fn(|r, col| self.b[r / N] * m[(r % N, col)])
    }
}

#[cfg(test)]
mod tests {
    use super::super::riccati::Dynamics;
    use super::*;

    /// Every structured product equals the dense one, for k = 1..3 and several theta.
    #[test]
    fn structured_products_equal_the_dense_ones() {
        fn check<const N: usize, const X: usize>() {
            for theta in [0.0, 0.3, 0.5, 1.0] {
                let d = Dynamics::<N, X>::new(0.37, theta);
                let m = SMatrix::<f64, X, X>::from_fn(|r, c| ((r * 7 + c * 3) as f64).sin());
                let v = SMatrix::<f64, N, X>::from_fn(|r, c| ((r * 5 + c) as f64).cos());
                for dense in [d.a, d.e, d.w] {
                    let p = BlockPoly::<N, X>::of(&dense);
                    assert!((p.right(&m) - m * dense).amax() < 1e-14);
                    assert!((p.right(&v) - v * dense).amax() < 1e-14);
                    assert!((p.left_t(&m) - dense.transpose() * m).amax() < 1e-14);
                    assert!((p.left(&m) - dense * m).amax() < 1e-14);
                }
                let b = BlockColumn::<N, X>::of(&d.b);
                let u = SMatrix::<f64, N, N>::from_fn(|r, c| (r + 2 * c) as f64);
                assert!((b.right(&m) - m * d.b).amax() < 1e-14);
                assert!((b.left_t(&m) - d.b.transpose() * m).amax() < 1e-14);
                assert!((b.left(&u) - d.b * u).amax() < 1e-14);
            }
        }
        check::<2, 2>();
        check::<2, 4>();
        check::<3, 6>();
        check::<1, 3>();
        check::<2, 8>();
    }
}
