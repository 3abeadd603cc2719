//! Dense LU with partial pivoting on statically sized matrices.
//!
//! nalgebra's `lu()` needs type-level bounds that a generic `const M` cannot meet, so the
//! runtime carries its own: Doolittle elimination with row pivoting, $P A = L U$, no heap.

use nalgebra::SMatrix;

/// Solves $A X = B$ in place (`b` becomes $X$) by Gaussian elimination with partial
/// pivoting. Returns `false`, leaving `b` unspecified, if a pivot is zero or the result is
/// not finite.
///
/// Column-oriented (the storage is column-major): each update runs down a contiguous column,
/// and columns of $A$ or $B$ with a zero multiplier are skipped, so block-sparse systems
/// cost less.
pub fn solve_in_place<const M: usize, const C: usize>(
    a: SMatrix<f64, M, M>,
    b: &mut SMatrix<f64, M, C>,
) -> bool {
    solve_columns(a, M, b.as_mut_slice(), &mut [])
}

/// Solves $A X = B$ and $A Y = D$ in place with one factorisation, as [`solve_in_place`].
pub fn solve_pair_in_place<const M: usize, const C: usize, const E: usize>(
    a: SMatrix<f64, M, M>,
    b: &mut SMatrix<f64, M, C>,
    d: &mut SMatrix<f64, M, E>,
) -> bool {
    solve_leading_in_place(a, M, b, d)
}

/// As [`solve_pair_in_place`], by Cramer's rule for `M` = 1 or 2 (a core of one or two
/// variables, where the general elimination's bookkeeping costs more than the arithmetic).
/// Returns `false` for a zero determinant or a non-finite result.
pub fn solve_small_pair_in_place<const M: usize, const C: usize, const E: usize>(
    a: SMatrix<f64, M, M>,
    b: &mut SMatrix<f64, M, C>,
    d: &mut SMatrix<f64, M, E>,
) -> bool {
    let (b, d) = (b.as_mut_slice(), d.as_mut_slice());
    match M {
        1 => {
            let inverse = 1.0 / a[(0, 0)];
            for v in b.iter_mut().chain(d.iter_mut()) {
                *v *= inverse;
            }
        }
        2 => {
            let det = a[(0, 0)] * a[(1, 1)] - a[(0, 1)] * a[(1, 0)];
            let inverse = 1.0 / det;
            for column in b.chunks_exact_mut(2).chain(d.chunks_exact_mut(2)) {
                let (x0, x1) = (column[0], column[1]);
                column[0] = (a[(1, 1)] * x0 - a[(0, 1)] * x1) * inverse;
                column[1] = (a[(0, 0)] * x1 - a[(1, 0)] * x0) * inverse;
            }
        }
        _ => return solve_columns(a, M, b, d),
    }
    // 0 * v is NaN exactly for the non-finite v
    b.iter().chain(d.iter()).fold(0.0, |acc, v| acc + v * 0.0) == 0.0
}

/// As [`solve_pair_in_place`] for the leading `n x n` block of `a` and the first `n` rows of
/// `b` and `d` (`n <= M`; the other entries are not read, and rows `n..` of `b` and `d` are
/// left as they are).
pub fn solve_leading_in_place<const M: usize, const C: usize, const E: usize>(
    a: SMatrix<f64, M, M>,
    n: usize,
    b: &mut SMatrix<f64, M, C>,
    d: &mut SMatrix<f64, M, E>,
) -> bool {
    n <= M && solve_columns(a, n, b.as_mut_slice(), d.as_mut_slice())
}

/// The elimination on the leading `n x n` block (`n <= M`) with right-hand sides given as
/// column-major slices (columns of length `M`, of which the first `n` rows are used) in two
/// parts.
pub(crate) fn solve_columns<const M: usize>(
    mut a: SMatrix<f64, M, M>,
    n: usize,
    b: &mut [f64],
    d: &mut [f64],
) -> bool {
    solve_columns_overwriting(&mut a, n, b, d)
}

/// [`solve_columns`] with `a` overwritten by its factors (no copy of `a`; entries outside the
/// leading `n x n` block are neither read nor written).
pub(crate) fn solve_columns_overwriting<const M: usize>(
    a: &mut SMatrix<f64, M, M>,
    n: usize,
    b: &mut [f64],
    d: &mut [f64],
) -> bool {
    let mut pivots = Pivots::new();
    if !factor_overwriting(a, n, &mut pivots, b, d) {
        return false;
    }
    back_substitute(a, n, &pivots, b) && back_substitute(a, n, &pivots, d)
}

/// The row interchanges and the reciprocal pivots of an LU factorisation by
/// [`factor_overwriting`], for later right-hand sides ([`solve_factored`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Pivots<const M: usize> {
    /// The row swapped with row `col` at elimination step `col`.
    rows: [usize; M],
    /// $1 / u_{col, col}$.
    inverse: [f64; M],
}

impl<const M: usize> Pivots<M> {
    /// No interchanges and unit pivots (to be written by [`factor_overwriting`]).
    pub(crate) fn new() -> Self {
        Self {
            rows: core::array::from_fn(|i| i),
            inverse: [1.0; M],
        }
    }
}

/// $P A = L U$ of the leading `n x n` block of `a` in place (`n <= M`; $L$ unit lower
/// triangular below the diagonal, $U$ on and above it, the interchanges and $1/u_{ii}$ in
/// `pivots`), with the same interchanges and elimination applied to the right-hand sides
/// `b` and `d` (column-major, columns of length `M`, the first `n` rows used): after it they
/// hold $L^{-1} P$ times themselves. Column-oriented (the storage is column-major): each update
/// runs down a contiguous column, and columns with a zero multiplier are skipped. Returns
/// `false` for a zero or non-finite pivot.
pub(crate) fn factor_overwriting<const M: usize>(
    a: &mut SMatrix<f64, M, M>,
    n: usize,
    pivots: &mut Pivots<M>,
    b: &mut [f64],
    d: &mut [f64],
) -> bool {
    if n > M {
        return false;
    }
    // column-major storage: entry (r, c) at c * M + r
    let a = a.as_mut_slice();
    for col in 0..n {
        let pivot_column = &a[col * M..col * M + n];
        let mut pivot_row = col;
        let mut pivot_abs = pivot_column[col].abs();
        for (row, v) in pivot_column.iter().enumerate().skip(col + 1) {
            if v.abs() > pivot_abs {
                pivot_abs = v.abs();
                pivot_row = row;
            }
        }
        if pivot_abs == 0.0 || !pivot_abs.is_finite() {
            return false;
        }
        pivots.rows[col] = pivot_row;
        if pivot_row != col {
            for part in [&mut a[..n * M], &mut *b, &mut *d] {
                for column in part.chunks_exact_mut(M) {
                    column.swap(pivot_row, col);
                }
            }
        }
        // multipliers l = a[col+1.., col] / pivot, stored in place (times the reciprocal pivot,
        // which is kept for the back substitution)
        let (left, right) = a.split_at_mut((col + 1) * M);
        let pivot_column = &mut left[col * M..col * M + n];
        let inverse = 1.0 / pivot_column[col];
        pivots.inverse[col] = inverse;
        for v in &mut pivot_column[col + 1..] {
            *v *= inverse;
        }
        let l = &pivot_column[col + 1..];
        for part in [&mut right[..(n - col - 1) * M], &mut *b, &mut *d] {
            for column in part.chunks_exact_mut(M) {
                eliminate(&mut column[col..n], l);
            }
        }
    }
    true
}

/// Solves $U X = Y$ in place for the columns $Y$ of `x` (column-major, columns of length `M`,
/// the first `n` rows used), $U$ from [`factor_overwriting`]; all-zero columns are skipped.
/// Returns whether every solved entry is finite.
fn back_substitute<const M: usize>(
    a: &SMatrix<f64, M, M>,
    n: usize,
    pivots: &Pivots<M>,
    x: &mut [f64],
) -> bool {
    let a = a.as_slice();
    for x in x.chunks_exact_mut(M) {
        let x = &mut x[..n];
        if x.iter().all(|&v| v == 0.0) {
            continue;
        }
        for col in (0..n).rev() {
            let u = &a[col * M..col * M + col];
            let v = x[col] * pivots.inverse[col];
            x[col] = v;
            if v != 0.0 {
                for (xi, ui) in x[..col].iter_mut().zip(u) {
                    *xi -= ui * v;
                }
            }
        }
    }
    x.chunks_exact(M)
        .all(|x| x[..n].iter().all(|v| v.is_finite()))
}

/// Solves $A X = Y$ in place for the columns $Y$ of `x` (as in [`back_substitute`]) with the
/// factors of $A$ from [`factor_overwriting`]: the same interchanges and elimination, then the
/// back substitution, so a column gives the same result, to the bit, as a right-hand side of
/// the factorisation. Returns whether every solved entry is finite.
pub(crate) fn solve_factored<const M: usize>(
    a: &SMatrix<f64, M, M>,
    n: usize,
    pivots: &Pivots<M>,
    x: &mut [f64],
) -> bool {
    let factors = a.as_slice();
    for column in x.chunks_exact_mut(M) {
        // the stored multipliers carry the later interchanges: all of them first (as LAPACK's
        // getrs), then the same updates as during the factorisation, in the same order
        for (col, &row) in pivots.rows[..n].iter().enumerate() {
            column.swap(row, col);
        }
        for col in 0..n {
            eliminate(
                &mut column[col..n],
                &factors[col * M + col + 1..col * M + n],
            );
        }
    }
    back_substitute(a, n, pivots, x)
}

/// `column[1..] -= column[0] * l` (one elimination update below a pivot), skipped when the
/// pivot-row entry is zero.
#[inline]
fn eliminate(column: &mut [f64], l: &[f64]) {
    if let Some((head, tail)) = column.split_first_mut() {
        let head = *head;
        if head != 0.0 {
            for (t, li) in tail.iter_mut().zip(l) {
                *t -= li * head;
            }
        }
    }
}

/// Solves $A X = B$, or `None` when [`solve_in_place`] reports a singular matrix.
pub fn solve<const M: usize, const C: usize>(
    a: &SMatrix<f64, M, M>,
    b: &SMatrix<f64, M, C>,
) -> Option<SMatrix<f64, M, C>> {
    let mut x = *b;
    let solved = if M <= 2 {
        solve_small_pair_in_place(*a, &mut x, &mut SMatrix::<f64, M, 0>::zeros())
    } else {
        solve_in_place(*a, &mut x)
    };
    solved.then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    #[test]
    fn solves_a_system_that_needs_pivoting() {
        let a = Matrix3::new(0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.0, 1.0);
        let x = Vector3::new(1.0, -2.0, 0.5);
        let got = solve(&a, &(a * x)).unwrap();
        assert!((got - x).amax() < 1e-14, "{got}");
    }

    #[test]
    fn leading_block_is_solved_and_the_rest_left_alone() {
        // the 2 x 2 leading block needs a row swap; row 2 of the right-hand sides is untouched
        let a = Matrix3::new(0.0, 2.0, 9.0, 3.0, 1.0, 9.0, 9.0, 9.0, 9.0);
        let mut b = Matrix3::new(2.0, 4.0, 0.0, 4.0, 7.0, 0.0, 5.0, 5.0, 5.0);
        let mut d = Vector3::new(2.0, 3.0, 7.0);
        assert!(solve_leading_in_place(a, 2, &mut b, &mut d));
        // [0 2; 3 1] x = (2, 4): x = (1, 1); (4, 7): x = (5/3, 2); (2, 3): x = (2/3, 1)
        let expected = Matrix3::new(1.0, 5.0 / 3.0, 0.0, 1.0, 2.0, 0.0, 5.0, 5.0, 5.0);
        assert!((b - expected).amax() < 1e-15, "{b}");
        assert!(
            (d - Vector3::new(2.0 / 3.0, 1.0, 7.0)).amax() < 1e-15,
            "{d}"
        );
        assert!(!solve_leading_in_place(a, 4, &mut b, &mut d));
    }

    #[test]
    fn small_systems_match_the_elimination() {
        let a = nalgebra::Matrix2::new(0.5, 2.0, 3.0, -1.0);
        let b = nalgebra::Matrix2x3::new(1.0, 2.0, 3.0, -4.0, 5.0, 0.5);
        let d = nalgebra::Vector2::new(0.25, -7.0);
        let (mut b1, mut d1, mut b2, mut d2) = (b, d, b, d);
        assert!(solve_small_pair_in_place(a, &mut b1, &mut d1));
        assert!(solve_pair_in_place(a, &mut b2, &mut d2));
        assert!((b1 - b2).amax() < 1e-14 && (d1 - d2).amax() < 1e-14);
        let one = nalgebra::Matrix1::new(4.0);
        let mut x = nalgebra::Matrix1::new(2.0);
        let mut y = nalgebra::Matrix1x2::new(1.0, -8.0);
        assert!(solve_small_pair_in_place(one, &mut y, &mut x));
        assert_eq!((x[0], y[1]), (0.5, -2.0));
        let singular = nalgebra::Matrix2::new(1.0, 2.0, 2.0, 4.0);
        assert!(!solve_small_pair_in_place(singular, &mut b1, &mut d1));
    }

    /// Right-hand sides solved later with the factors give the same bits as right-hand sides
    /// of the factorisation (the same interchanges and updates in the same order).
    #[test]
    fn factored_solves_equal_the_elimination() {
        // pivoting on every column; a zero column and a zero leading entry
        let a = Matrix3::new(1e-3, 2.0, -1.0, 4.0, 0.5, 3.0, -2.0, 7.0, 0.25);
        let b = Matrix3::new(1.0, 0.0, 0.3, -2.0, 0.0, 0.7, 0.5, 0.0, 0.0);
        let (mut together, mut later) = (b, b);
        let mut factors = a;
        assert!(solve_columns_overwriting(
            &mut factors,
            3,
            together.as_mut_slice(),
            &mut []
        ));
        let (mut factors, mut pivots) = (a, Pivots::new());
        assert!(factor_overwriting(
            &mut factors,
            3,
            &mut pivots,
            &mut [],
            &mut []
        ));
        assert!(solve_factored(&factors, 3, &pivots, later.as_mut_slice()));
        assert_eq!(together, later);
        assert!((a * later - b).amax() < 1e-14, "{later}");
        assert_eq!(later.column(1).amax(), 0.0);
        let singular = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        let (mut factors, mut pivots) = (singular, Pivots::new());
        assert!(!factor_overwriting(
            &mut factors,
            3,
            &mut pivots,
            &mut [],
            &mut []
        ));
    }

    #[test]
    fn singular_matrix_is_reported() {
        let a = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        assert!(solve(&a, &Vector3::new(1.0, 1.0, 1.0)).is_none());
    }
}
