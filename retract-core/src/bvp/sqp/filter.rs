//! The filter of the line search (Wächter and Biegler, Math. Program. 106, 2006): the pairs
//! (constraint violation, barrier cost) a trial point must not be dominated by.

/// The filter: pairs $(\theta, \varphi)$ a trial point must not be dominated by, and the
/// bounds $\theta_{\max} = 10^4 \max(1, \theta_0)$ (no trial point above it) and
/// $\theta_{\min} = 10^{-4} \max(1, \theta_0)$ (below it, steps that only decrease
/// $\varphi$ are taken by Armijo's condition) from the violation $\theta_0$ of the first
/// iterate.
pub(super) struct Filter {
    entries: Vec<(f64, f64)>,
    theta_max: f64,
    pub theta_min: f64,
}

impl Filter {
    /// An empty filter for a first violation `theta0` (its pairs kept in `entries`).
    pub fn new(theta0: f64, mut entries: Vec<(f64, f64)>) -> Self {
        let scale = theta0.max(1.0);
        entries.clear();
        Self {
            entries,
            theta_max: 1e4 * scale,
            theta_min: 1e-4 * scale,
        }
    }

    /// Its vector of pairs (to keep for a later filter).
    pub fn into_entries(self) -> Vec<(f64, f64)> {
        self.entries
    }

    /// Empties the filter (when $\mu$ changes, the barrier cost changes with it).
    pub fn reset(&mut self) {
        self.entries.clear();
    }

    /// Whether $(\theta, \varphi)$ is dominated by a stored pair or has $\theta \ge
    /// \theta_{\max}$.
    pub fn rejects(&self, theta: f64, phi: f64) -> bool {
        theta >= self.theta_max || self.entries.iter().any(|(t, p)| theta >= *t && phi >= *p)
    }

    /// Adds $(\theta, \varphi)$, dropping the pairs it dominates.
    pub fn augment(&mut self, theta: f64, phi: f64) {
        self.entries.retain(|(t, p)| *t < theta || *p < phi);
        self.entries.push((theta, phi));
    }
}
