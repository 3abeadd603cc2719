//! Products with the scheme's constant matrices, which are polynomials in the block shift.
//!
//! With $S$ the block shift on jets ($(S x)_j = x_{j+1}$, blocks of $n$), the matrices of the
//! lifted scheme's $x$-equations are $\bar A = \sum_d a_d S^d$, $E = \sum_d e_d S^d$,
//! $W = \sum_d w_d S^d$ (scalar coefficients, $d < k$) and $\bar B = \sum_d b_d S^d B$, whose
//! block row $j$ is $b_{k-1-j} I$. A product with them costs $O(k)$ block operations instead
//! of a dense $nk \times nk$ one.

use nalgebra::SMatrix;

/// $I + \sum_{d \ge 1} c_d S^d$ on jets of $X = nk$ entries in blocks of `N`: every
/// polynomial of the scheme ($W$, $\bar A$, $E$) starts with the identity, so the products
/// below start from a copy and add the shifted terms only.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockPoly<const N: usize, const X: usize> {
    /// $c_d$ for $1 \le d < k$ ($c_0 = 1$; zero beyond).
    c: [f64; X],
}

/// A matrix $X \times N$ whose block row $j$ is $b_j I$ (such as $\bar B$).
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockColumn<const N: usize, const X: usize> {
    b: [f64; X],
}

// The products index the column-major storage `data.0[column][row]` with constant bounds,
// so the compiler unrolls them completely.

impl<const N: usize, const X: usize> BlockPoly<N, X> {
    /// The coefficients of a matrix known to be a polynomial in $S$ with $c_0 = 1$: its first
    /// block row.
    pub fn of(m: &SMatrix<f64, X, X>) -> Self {
        debug_assert!((m[(0, 0)] - 1.0).abs() < 1e-14, "c_0 = {}", m[(0, 0)]);
        Self {
            c: core::array::from_fn(|d| if d * N < X { m[(0, d * N)] } else { 0.0 }),
        }
    }

    /// $M P(S)$: column block $j$ is column block $j$ of $M$ plus $\sum_{1 \le d \le j}
    /// c_d$ times column block $j - d$.
    #[inline(always)]
    pub fn right<const R: usize>(&self, m: &SMatrix<f64, R, X>) -> SMatrix<f64, R, X> {
        let (src, mut out) = (&m.data.0, *m);
        let dst = &mut out.data.0;
        for j in 1..X / N {
            for d in 1..=j {
                for col in 0..N {
                    for r in 0..R {
                        dst[j * N + col][r] += self.c[d] * src[(j - d) * N + col][r];
                    }
                }
            }
        }
        out
    }

    /// $P(S)^T M$: row block $j$ is row block $j$ of $M$ plus $\sum_{1 \le d \le j} c_d$
    /// times row block $j - d$.
    #[inline(always)]
    pub fn left_t<const C: usize>(&self, m: &SMatrix<f64, X, C>) -> SMatrix<f64, X, C> {
        let (src, mut out) = (&m.data.0, *m);
        let dst = &mut out.data.0;
        for col in 0..C {
            for j in 1..X / N {
                for d in 1..=j {
                    for a in 0..N {
                        dst[col][j * N + a] += self.c[d] * src[col][(j - d) * N + a];
                    }
                }
            }
        }
        out
    }

    /// $P(S) M$: row block $j$ is row block $j$ of $M$ plus $\sum_{1 \le d,\ j + d < k}
    /// c_d$ times row block $j + d$.
    #[inline(always)]
    pub fn left<const C: usize>(&self, m: &SMatrix<f64, X, C>) -> SMatrix<f64, X, C> {
        let k = X / N;
        let (src, mut out) = (&m.data.0, *m);
        let dst = &mut out.data.0;
        for col in 0..C {
            for j in 0..k {
                for d in 1..k - j {
                    for a in 0..N {
                        dst[col][j * N + a] += self.c[d] * src[col][(j + d) * N + a];
                    }
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
        let (src, mut out) = (&m.data.0, SMatrix::<f64, R, N>::zeros());
        let dst = &mut out.data.0;
        for j in 0..X / N {
            for col in 0..N {
                for r in 0..R {
                    dst[col][r] += self.b[j] * src[j * N + col][r];
                }
            }
        }
        out
    }

    /// $\bar B^T M = \sum_j b_j$ (row block $j$ of $M$).
    #[inline(always)]
    pub fn left_t<const C: usize>(&self, m: &SMatrix<f64, X, C>) -> SMatrix<f64, N, C> {
        let (src, mut out) = (&m.data.0, SMatrix::<f64, N, C>::zeros());
        let dst = &mut out.data.0;
        for col in 0..C {
            for j in 0..X / N {
                for a in 0..N {
                    dst[col][a] += self.b[j] * src[col][j * N + a];
                }
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
    use super::super::Dynamics;
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
