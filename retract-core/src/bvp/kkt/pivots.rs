//! The dense pivots of the Riccati recursion: the inverse of a small symmetric matrix with
//! the count of its negative eigenvalues (the inertia), by $L D L^T$ or, where a pivot is too
//! small for that, by the Jacobi eigendecomposition.

use nalgebra::{SMatrix, SVector};

/// Inverts a symmetric matrix and counts its negative eigenvalues; `None` if (nearly)
/// singular or not finite. An $L D L^T$ factorisation without pivoting first (a congruence, so
/// by Sylvester's law the signs of the pivots are those of the eigenvalues), the
/// eigendecomposition when a pivot is too small for that to be reliable.
#[inline]
pub(super) fn invert_counting<const D: usize>(
    m: SMatrix<f64, D, D>,
) -> Option<(SMatrix<f64, D, D>, usize)> {
    ldlt_inverse(&m).or_else(|| invert_by_eigen(&m))
}

/// The fallback of [`invert_counting`]: the inverse and the negative eigenvalues from the
/// symmetric eigendecomposition; `None` if an eigenvalue is below $10^{-13}$ of the largest
/// in magnitude or a value is not finite.
#[cold]
#[inline(never)]
pub(super) fn invert_by_eigen<const D: usize>(
    m: &SMatrix<f64, D, D>,
) -> Option<(SMatrix<f64, D, D>, usize)> {
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let (eigenvalues, vectors) = jacobi_eigen(m);
    let scale = eigenvalues.amax().max(f64::MIN_POSITIVE);
    if eigenvalues
        .iter()
        .any(|l| l.abs() <= 1e-13 * scale || !l.is_finite())
    {
        return None;
    }
    let negative = eigenvalues.iter().filter(|l| **l < 0.0).count();
    let inv_diag = SMatrix::<f64, D, D>::from_diagonal(&eigenvalues.map(|l| 1.0 / l));
    Some((vectors * inv_diag * vectors.transpose(), negative))
}

/// The eigenvalues and eigenvectors (columns) of the symmetric matrix `m` by cyclic Jacobi
/// rotations ($A \leftarrow P^T A P$ with $\tan\phi = \mathrm{sgn}(\vartheta) / (|\vartheta| +
/// \sqrt{\vartheta^2 + 1})$, $\vartheta = (a_{qq} - a_{pp}) / 2 a_{pq}$, zeroing $a_{pq}$), until
/// the off-diagonal part is below $10^{-15}$ of the whole (at most 64 sweeps).
pub(super) fn jacobi_eigen<const D: usize>(
    m: &SMatrix<f64, D, D>,
) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
    let mut a = (m + m.transpose()) * 0.5;
    let mut v = SMatrix::<f64, D, D>::identity();
    let total = a.norm_squared();
    for _ in 0..64 {
        let diagonal: f64 = (0..D).map(|i| a[(i, i)] * a[(i, i)]).sum();
        if total - diagonal <= 1e-30 * total {
            break;
        }
        for p in 0..D {
            for q in p + 1..D {
                let apq = a[(p, q)];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[(q, q)] - a[(p, p)]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                let rotate = |x: f64, y: f64| (c * x - s * y, s * x + c * y);
                for k in 0..D {
                    (a[(k, p)], a[(k, q)]) = rotate(a[(k, p)], a[(k, q)]);
                }
                for k in 0..D {
                    (a[(p, k)], a[(q, k)]) = rotate(a[(p, k)], a[(q, k)]);
                }
                for k in 0..D {
                    (v[(k, p)], v[(k, q)]) = rotate(v[(k, p)], v[(k, q)]);
                }
            }
        }
    }
    (a.diagonal(), v)
}

/// $M^{-1}$ and the number of negative pivots of $M = L D L^T$ ($L$ unit lower triangular),
/// or `None` if a pivot is below $10^{-10}$ of the largest diagonal entry in magnitude or a
/// value is not finite.
#[inline]
fn ldlt_inverse<const D: usize>(m: &SMatrix<f64, D, D>) -> Option<(SMatrix<f64, D, D>, usize)> {
    let scale = (0..D).fold(0.0_f64, |s, i| s.max(m[(i, i)].abs()));
    let mut l = SMatrix::<f64, D, D>::identity();
    let mut d = [0.0_f64; D];
    // the pivots' reciprocals: one division per pivot
    let mut d_inv = [0.0_f64; D];
    for j in 0..D {
        let mut pivot = m[(j, j)];
        for k in 0..j {
            pivot -= l[(j, k)] * l[(j, k)] * d[k];
        }
        // (a NaN pivot fails the comparison too)
        if pivot.abs().partial_cmp(&(1e-10 * scale)) != Some(core::cmp::Ordering::Greater) {
            return None;
        }
        d[j] = pivot;
        d_inv[j] = 1.0 / pivot;
        for i in j + 1..D {
            let mut v = m[(i, j)];
            for k in 0..j {
                v -= l[(i, k)] * l[(j, k)] * d[k];
            }
            l[(i, j)] = v * d_inv[j];
        }
    }
    // M^{-1} = L^{-T} D^{-1} L^{-1}, column by column
    let mut inv = SMatrix::<f64, D, D>::zeros();
    for c in 0..D {
        let mut y = [0.0_f64; D];
        for i in 0..D {
            let mut v = if i == c { 1.0 } else { 0.0 };
            for k in 0..i {
                v -= l[(i, k)] * y[k];
            }
            y[i] = v;
        }
        for i in (0..D).rev() {
            let mut v = y[i] * d_inv[i];
            for k in i + 1..D {
                v -= l[(k, i)] * inv[(k, c)];
            }
            inv[(i, c)] = v;
        }
    }
    let negative = d.iter().filter(|p| **p < 0.0).count();
    inv.iter().all(|v| v.is_finite()).then_some((inv, negative))
}
