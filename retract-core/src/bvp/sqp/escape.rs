//! The escape from a saddle: where the second-order check finds negative curvature at a KKT
//! point, a point below it along the direction of the most negative curvature, for a new
//! start ([`Sqp::run`]).

use nalgebra::SVector;

use super::state::{Sqp, State};
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::curvature::most_negative_direction;
use crate::bvp::kkt::riccati::Riccati;
use crate::{Lagrangian, LiftedSystem};

/// The powers of ten of the shifts tried, relative to the scale of the stage Hessians (up to
/// [`super::second_order::DECISIVE_SHIFT`]).
const SHIFTS: core::ops::RangeInclusive<i32> = -8..=4;

/// The most halvings of the step along the escape direction.
const HALVINGS: i32 = 30;

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// A point below the saddle `st` (a KKT point whose reduced Hessian has negative
    /// directions): along the direction $d$ of the most negative curvature of the penalised
    /// reduced Hessian of the second-order check ([`most_negative_direction`] on
    /// [`Self::shifted_factor`] with the least shift $10^{-8}, 10^{-7}, \dots, 10^4$ times
    /// the scale of the stage Hessians that makes it positive definite; $|d|_\infty = 1$,
    /// fixed ends kept), the point $x \pm 2^{-k} d$ with the least $k \le 30$ (the plus sign
    /// first) that stays in the system's domain and lowers the cost by more than $10^{-10}
    /// \max(1, |J|)$. `None` where no shift makes it definite, no direction is found or no
    /// step lowers the cost.
    pub(super) fn escape(&self, st: &State<N, X>) -> Option<Iterate<N, X>> {
        let state = (&st.iterate, &st.y[..], &st.barrier);
        let models = self.models(state.0, state.1, state.2).ok()?;
        let mut factor: Option<Riccati<N, X>> = None;
        for power in SHIFTS {
            let shifted = self.shifted_factor(state, &models, 10f64.powi(power));
            if shifted.positive_definite() {
                factor = Some(shifted);
                break;
            }
            shifted.recycle(&mut *self.pool.borrow_mut());
        }
        let steps = st.iterate.u.len();
        let (mut dx, mut du) = {
            let mut pool = self.pool.borrow_mut();
            (pool.jets.take(steps + 1), pool.tops.take(steps))
        };
        let found = factor.is_some_and(|riccati| {
            let pool = &mut *self.pool.borrow_mut();
            let end = &models.terminal;
            let found =
                most_negative_direction(&riccati, &self.dynamics, end, (&mut dx, &mut du), pool);
            riccati.recycle(pool);
            found
        });
        self.give_models(models);
        let below = found
            .then(|| self.downhill((&st.iterate, &st.barrier), (&dx, &du)))
            .flatten();
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(dx);
        pool.tops.give(du);
        below
    }

    /// The first point $x \pm 2^{-k} d$ of [`Self::escape`] below `iterate`'s cost (the
    /// cost alone: no slack steps, so no barrier terms).
    fn downhill(
        &self,
        (iterate, barrier): (&Iterate<N, X>, &Barrier),
        (dx, du): (&[SVector<f64, X>], &[SVector<f64, N>]),
    ) -> Option<Iterate<N, X>> {
        let cost = |point: &Iterate<N, X>| {
            (self.merit_parts(point, barrier, &[], 0.0)).map(|(cost, _)| cost)
        };
        let base = cost(iterate)?;
        let enough = 1e-10 * base.abs().max(1.0);
        for k in 0..=HALVINGS {
            for sign in [1.0, -1.0] {
                let t = sign * 0.5f64.powi(k);
                let mut trial = self.take_iterate(iterate.u.len());
                (trial.x).extend(iterate.x.iter().zip(dx).map(|(x, d)| x + d * t));
                (trial.u).extend(iterate.u.iter().zip(du).map(|(u, d)| u + d * t));
                let lower = self.problem.guard::<S, M>(&trial).is_ok()
                    && cost(&trial).is_some_and(|c| c < base - enough);
                if lower {
                    return Some(trial);
                }
                self.give_iterate(trial);
            }
        }
        None
    }
}
