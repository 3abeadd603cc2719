//! First guesses: the Hermite polynomial between two boundary jets.

use nalgebra::{DMatrix, DVector};

use crate::Error;

/// The Hermite polynomial of degree $2k - 1$ in each of the $n$ coordinates that matches the
/// jets `start` $= (q, \dots, q^{(k-1)})(0)$ and `goal` at $T = $ `t_end` (blocks of $n$): the
/// $V = 0$ spline. For $k = 2$ between states at rest it is the smoothstep
/// $q_0 + (q_T - q_0)(3s^2 - 2s^3)$, $s = t/T$.
pub(crate) struct Hermite {
    n: usize,
    /// `derivatives[j * n + i][m]`: coefficient of $t^m$ in $q_i^{(j)}$, $j < 2k$ (the
    /// polynomial's derivatives formed once, so that a value is one Horner sweep).
    derivatives: Vec<Vec<f64>>,
}

/// $m (m-1) \cdots (m-j+1)$.
fn falling(m: usize, j: usize) -> f64 {
    ((m + 1 - j)..=m).map(|v| v as f64).product()
}

impl Hermite {
    /// # Errors
    /// [`Error::InvalidArgument`] for a horizon that makes the interpolation singular.
    pub fn new(start: &[f64], goal: &[f64], t_end: f64, n: usize, k: usize) -> Result<Self, Error> {
        let mut coefficients = vec![vec![0.0; 2 * k]; n];
        for (i, c) in coefficients.iter_mut().enumerate() {
            for (m, cm) in c.iter_mut().enumerate().take(k) {
                *cm = start[m * n + i] / falling(m, m);
            }
            let mut a = DMatrix::<f64>::zeros(k, k);
            let mut rhs = DVector::<f64>::zeros(k);
            for j in 0..k {
                let known: f64 = (j..k)
                    .map(|m| c[m] * falling(m, j) * t_end.powi((m - j) as i32))
                    .sum();
                rhs[j] = goal[j * n + i] - known;
                for m in k..2 * k {
                    a[(j, m - k)] = falling(m, j) * t_end.powi((m - j) as i32);
                }
            }
            let upper = a.lu().solve(&rhs).ok_or(Error::InvalidArgument {
                name: "t_end",
                requirement: "the spline guess needs a non-degenerate horizon",
            })?;
            c[k..2 * k].copy_from_slice(upper.as_slice());
        }
        // q_i^(j) = sum_{m >= j} c_m m!/(m-j)! t^(m-j)
        let derivatives = (0..2 * k * n)
            .map(|index| {
                let (j, c) = (index / n, &coefficients[index % n]);
                (j..2 * k).map(|m| c[m] * falling(m, j)).collect()
            })
            .collect();
        Ok(Self { n, derivatives })
    }

    /// $q_i^{(j)}(t)$ (zero for $j \ge 2k$; NaN for a coordinate $i \ge n$, which the
    /// guess's finiteness check reports as an error instead of reading another derivative).
    pub fn derivative(&self, i: usize, j: usize, t: f64) -> f64 {
        if i >= self.n {
            return f64::NAN;
        }
        self.derivatives
            .get(j * self.n + i)
            .map_or(0.0, |d| d.iter().rev().fold(0.0, |acc, &c| acc * t + c))
    }

    /// Entry `r` of the derivative data $(q, q', \dots)$ at $t$ (blocks of $n$).
    pub fn jet_entry(&self, r: usize, t: f64) -> f64 {
        self.derivative(r % self.n, r / self.n, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_polynomial_matches_both_jets_and_its_derivatives_are_consistent() {
        // n = 2, k = 3: jets (q, q', q'') in blocks of two
        let start = [0.3, -1.0, 2.0, 0.5, -0.7, 1.1];
        let goal = [1.5, 0.2, -0.4, 0.9, 0.6, -2.0];
        let t_end = 1.7;
        let spline = Hermite::new(&start, &goal, t_end, 2, 3).unwrap();
        for r in 0..6 {
            assert!((spline.jet_entry(r, 0.0) - start[r]).abs() < 1e-13);
            assert!((spline.jet_entry(r, t_end) - goal[r]).abs() < 1e-12);
        }
        // q^(j+1) is the derivative of q^(j) (central differences), and q^(6) = 0
        let (t, e) = (0.61, 1e-5);
        for i in 0..2 {
            for j in 0..5 {
                let difference =
                    (spline.derivative(i, j, t + e) - spline.derivative(i, j, t - e)) / (2.0 * e);
                let exact = spline.derivative(i, j + 1, t);
                assert!(
                    (difference - exact).abs() < 1e-6 * (1.0 + exact.abs()),
                    "{i} {j}"
                );
            }
            assert_eq!(spline.derivative(i, 6, t), 0.0);
        }
        // a coordinate out of range is NaN (never another coordinate's value, never a panic)
        assert!(spline.derivative(2, 0, t).is_nan());
    }
}
