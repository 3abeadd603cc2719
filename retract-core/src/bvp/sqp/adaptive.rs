//! The adaptive barrier update ([`BarrierUpdate::Adaptive`](crate::bvp::BarrierUpdate)):
//! IPOPT's `mu_strategy adaptive` with the LOQO oracle ([`Barrier::loqo`]) and the
//! objective-constraint filter as its globalisation (Nocedal, Wächter and Waltz, SIAM J.
//! Optim. 19, 2009, sec. 4).

use crate::bvp::barrier::Barrier;

/// The largest $\mu$ of the free mode over the first average complementarity (IPOPT's
/// `mu_max_fact`).
const MU_MAX_FACTOR: f64 = 1e3;
/// The monotone mode's first $\mu$ over the average complementarity (IPOPT's
/// `adaptive_mu_monotone_init_factor`).
const MONOTONE_START: f64 = 0.8;
/// The progress test's margin over $\min(1, E)$ (IPOPT's `filter_margin_fact`).
const MARGIN: f64 = 1e-5;

/// What the adaptive update carries between iterates: its mode, the largest $\mu$ of the
/// free mode, and the filter of (cost, constraint violation) pairs of the iterates the
/// free mode accepted.
pub(super) struct Adaptive {
    /// $\mu$ chosen by the oracle at every iterate (else the monotone update runs).
    pub free: bool,
    /// The free mode's largest $\mu$, $10^3$ times the first average complementarity ($-1$
    /// until then).
    mu_max: f64,
    /// Pairs $(J, \theta)$ no later free-mode iterate may be dominated by.
    entries: Vec<(f64, f64)>,
    /// The free mode resumed at this iterate (which passed the progress test there).
    resumed: bool,
    /// The free mode ended for good at a converged iterate: $\mu$ sits at its floor.
    finished: bool,
}

impl Adaptive {
    /// The free mode with an empty filter (its pairs kept in `entries`).
    pub fn new(mut entries: Vec<(f64, f64)>) -> Self {
        entries.clear();
        Self {
            free: true,
            mu_max: -1.0,
            entries,
            resumed: false,
            finished: false,
        }
    }

    /// Its vector of pairs (to keep for a later solve).
    pub fn into_entries(self) -> Vec<(f64, f64)> {
        self.entries
    }

    /// In the free mode, $\mu$ = the LOQO rule's value within $[\mu_{\min}, \mu_{\max}]$
    /// (`floor` is $\mu_{\min}$; $\mu_{\max}$ is set at the first call). Returns whether it
    /// set $\mu$.
    pub fn choose(&mut self, barrier: &mut Barrier, floor: f64) -> bool {
        if !self.free {
            return false;
        }
        if self.mu_max < 0.0 {
            self.mu_max = MU_MAX_FACTOR * barrier.average_complementarity().0;
        }
        barrier.mu = barrier.loqo().min(self.mu_max).max(floor);
        true
    }

    /// The progress test at an iterate of cost `cost`, violation `theta` and error `error`
    /// (with `converged` when its error and complementarity are below the tolerance), under
    /// `barrier`: the new $\mu$ where it changes (the iterate's models are then formed
    /// again). Free mode: a converged iterate ends the free mode with $\mu$ at `floor`; an
    /// iterate not dominated by the filter within the margin $10^{-5} \min(1, E)$ joins it;
    /// any other switches to the monotone mode from $\mu = 0.8 \bar c$. Monotone mode: an
    /// iterate that passes the test resumes the free mode (joining the filter).
    pub fn test(
        &mut self,
        barrier: &Barrier,
        (cost, theta, error, converged): (f64, f64, f64, bool),
        floor: f64,
    ) -> Option<f64> {
        if self.finished {
            return None;
        }
        if self.free && converged {
            self.free = false;
            self.finished = true;
            return (barrier.mu != floor).then_some(floor);
        }
        if self.free && core::mem::take(&mut self.resumed) {
            return None;
        }
        let margin = MARGIN * error.min(1.0);
        let progress =
            (self.entries.iter()).all(|(j, t)| cost + margin < *j || theta + margin < *t);
        match (self.free, progress) {
            (true, true) => {
                self.remember(cost, theta);
                None
            }
            (true, false) => {
                self.free = false;
                let average = barrier.average_complementarity().0;
                Some((MONOTONE_START * average).min(self.mu_max).max(floor))
            }
            (false, true) => {
                self.free = true;
                self.resumed = true;
                self.remember(cost, theta);
                // (the mu of the next choice: the oracle's)
                Some(barrier.mu)
            }
            (false, false) => None,
        }
    }

    /// Adds $(J, \theta)$ to the filter, dropping the pairs it dominates.
    fn remember(&mut self, cost: f64, theta: f64) {
        self.entries.retain(|(j, t)| *j < cost || *t < theta);
        self.entries.push((cost, theta));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn barrier(z: [f64; 2]) -> Barrier {
        let mut barrier = crate::bvp::barrier::one_step(&[1.0, 1.0]);
        barrier.z = z.to_vec();
        barrier
    }

    /// The free mode takes the LOQO value, switches to the monotone mode at 0.8 times the
    /// average complementarity on an iterate dominated by an earlier one, resumes where an
    /// iterate improves on the filter, and ends at the floor once converged.
    #[test]
    fn the_modes_follow_the_progress_test() {
        let mut adaptive = Adaptive::new(Vec::new());
        let mut b = barrier([1e-3, 1.0]);
        assert!(adaptive.choose(&mut b, 1e-10));
        let average = (1e-3 + 1.0) / 2.0;
        assert!((b.mu - 0.8 * average).abs() <= 1e-15);
        b.mu = 0.3;
        // the first iterate joins the empty filter; a worse one (cost and violation) ends
        // the free mode
        assert_eq!(adaptive.test(&b, (5.0, 1.0, 1.0, false), 1e-10), None);
        let fixed = adaptive.test(&b, (5.0, 1.0, 1.0, false), 1e-10);
        assert!(!adaptive.free && (fixed.unwrap() - 0.8 * average).abs() <= 1e-15);
        assert!(!adaptive.choose(&mut b, 1e-10) && b.mu == 0.3);
        // still dominated: monotone; a lower cost resumes the free mode, which then does not
        // test the same iterate again
        assert_eq!(adaptive.test(&b, (5.0, 2.0, 1.0, false), 1e-10), None);
        assert!(adaptive.test(&b, (4.0, 2.0, 1.0, false), 1e-10).is_some());
        assert!(adaptive.free);
        assert_eq!(adaptive.test(&b, (4.0, 2.0, 1.0, false), 1e-10), None);
        // the margin: a cost lower by less than 1e-5 min(1, E) is no progress
        let near = (4.0 - 1e-6, 2.0, 1.0, false);
        assert!(adaptive.test(&b, near, 1e-10).is_some() && !adaptive.free);
        // converged in the free mode: mu at its floor for good
        adaptive.free = true;
        assert_eq!(adaptive.test(&b, (0.0, 0.0, 0.0, true), 1e-10), Some(1e-10));
        assert!(!adaptive.free && !adaptive.choose(&mut b, 1e-10));
        assert_eq!(adaptive.test(&b, (9.0, 9.0, 1.0, false), 1e-10), None);
    }
}
