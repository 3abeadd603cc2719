//! First guesses: the Hermite polynomial between two boundary jets.

use nalgebra::{DMatrix, DVector};

use crate::Error;

/// The Hermite polynomial of degree $2k - 1$ in each of the $n$ coordinates that matches the
/// jets `start` $= (q, \dots, q^{(k-1)})(0)$ and `goal` at $T = $ `t_end` (blocks of $n$): the
/// $V = 0$ spline. For $k = 2$ between states at rest it is the smoothstep
/// $q_0 + (q_T - q_0)(3s^2 - 2s^3)$, $s = t/T$.
pub(crate) struct Hermite {
    n: usize,
    /// `coefficients[i][m]`: coefficient of $t^m$ in coordinate $i$.
    coefficients: Vec<Vec<f64>>,
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
        Ok(Self { n, coefficients })
    }

    /// $q_i^{(j)}(t)$.
    pub fn derivative(&self, i: usize, j: usize, t: f64) -> f64 {
        let c = &self.coefficients[i];
        (j..c.len())
            .map(|m| c[m] * falling(m, j) * t.powi((m - j) as i32))
            .sum()
    }

    /// Entry `r` of the derivative data $(q, q', \dots)$ at $t$ (blocks of $n$).
    pub fn jet_entry(&self, r: usize, t: f64) -> f64 {
        self.derivative(r % self.n, r / self.n, t)
    }
}
