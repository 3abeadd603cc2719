//! Dense LU with partial pivoting on statically sized matrices.
//!
//! nalgebra's `lu()` needs type-level bounds that a generic `const M` cannot meet, so the
//! runtime carries its own: Doolittle elimination with row pivoting, $P A = L U$, no heap.

use nalgebra::SMatrix;

/// Solves $A X = B$ in place (`b` becomes $X$) by Gaussian elimination with partial
/// pivoting. Returns `false`, leaving `b` unspecified, if a pivot is zero or the result is
/// not finite.
pub fn solve_in_place<const M: usize, const C: usize>(
    mut a: SMatrix<f64, M, M>,
    b: &mut SMatrix<f64, M, C>,
) -> bool {
    for col in 0..M {
        let mut pivot_row = col;
        let mut pivot_abs = a[(col, col)].abs();
        for row in col + 1..M {
            let v = a[(row, col)].abs();
            if v > pivot_abs {
                pivot_abs = v;
                pivot_row = row;
            }
        }
        if pivot_abs == 0.0 || !pivot_abs.is_finite() {
            return false;
        }
        if pivot_row != col {
            a.swap_rows(pivot_row, col);
            b.swap_rows(pivot_row, col);
        }
        let pivot = a[(col, col)];
        for row in col + 1..M {
            let factor = a[(row, col)] / pivot;
            if factor == 0.0 {
                continue;
            }
            for k in col + 1..M {
                a[(row, k)] -= factor * a[(col, k)];
            }
            for k in 0..C {
                b[(row, k)] -= factor * b[(col, k)];
            }
        }
    }
    for col in (0..M).rev() {
        let pivot = a[(col, col)];
        for k in 0..C {
            let mut v = b[(col, k)];
            for j in col + 1..M {
                v -= a[(col, j)] * b[(j, k)];
            }
            b[(col, k)] = v / pivot;
        }
    }
    b.iter().all(|v| v.is_finite())
}

/// Solves $A X = B$, or `None` when [`solve_in_place`] reports a singular matrix.
pub fn solve<const M: usize, const C: usize>(
    a: &SMatrix<f64, M, M>,
    b: &SMatrix<f64, M, C>,
) -> Option<SMatrix<f64, M, C>> {
    let mut x = *b;
    solve_in_place(*a, &mut x).then_some(x)
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
    fn singular_matrix_is_reported() {
        let a = Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 0.0, 1.0, 1.0);
        assert!(solve(&a, &Vector3::new(1.0, 1.0, 1.0)).is_none());
    }
}
