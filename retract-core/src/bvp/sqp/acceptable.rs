//! The acceptable-level exit at a point met before the barrier's floor.
//!
//! Where an active inequality is degenerate (its gradient vanishes at the solution, as a
//! car's turning-radius constraint at rest), lowering $\mu$ to its floor drives the slack
//! $s = \mu / z$ to $10^{-13}$ against a multiplier of $10^3$: the barrier Hessian $h z / s$
//! is then $10^{15}$ times the rest, the subproblem's multipliers lose their digits and the
//! stationarity wanders between $10^{-4}$ and $10^{-1}$ at a primal point that no longer
//! moves. The barrier problem solved just before (at $\mu$ a few times the floor) met the
//! tolerance in stationarity and feasibility, with complementarity $\max z s \approx \mu$
//! below the acceptable level. That point is kept when $\mu$ decreases from it; if the
//! iteration at the floor then makes only rounding-level progress for ten iterations
//! (the primal iterate has converged) with the error above the acceptable level, or
//! reaches the iteration limit, the kept point is certified instead (the second-order
//! check as for any plan) and returned: its certificate reports the complementarity
//! reached (IPOPT's acceptable level, at the point that met it).

use nalgebra::SVector;

use super::state::Sqp;
use super::termination::Finished;
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::Iterate;
use crate::bvp::plan::Plan;
use crate::{Lagrangian, LiftedSystem};

/// Consecutive iterations at the barrier's floor of only rounding-level progress (counted
/// from the floor on), with the error above the acceptable level, after which the point kept
/// before the floor is returned ([`Sqp::exit_at_kept`]). (Three end solves that would reach the
/// tolerance a few dozen iterations later; ten leave them, and end the stalls of a degenerate
/// inequality within about 35 iterations of the floor.)
const STALLED_AT_FLOOR: usize = 10;

/// A point kept for the acceptable-level exit: the iterate, the stage equalities'
/// multipliers and the barrier (its $\mu$, slacks and multipliers).
pub(super) struct Kept<const N: usize, const X: usize> {
    pub iterate: Iterate<N, X>,
    pub y: Vec<SVector<f64, N>>,
    pub barrier: Barrier,
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// A copy of the point (`iterate`, `y`, `barrier`) from the pool, replacing `kept` (whose
    /// vectors go back to the pool).
    pub(super) fn keep(
        &self,
        (iterate, y, barrier): (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        kept: &mut Option<Kept<N, X>>,
    ) {
        if let Some(old) = kept.take() {
            self.give_kept(old);
        }
        let mut copy = self.take_iterate(iterate.u.len());
        copy.x.extend_from_slice(&iterate.x);
        copy.u.extend_from_slice(&iterate.u);
        let mut pool = self.pool.borrow_mut();
        let mut ys = pool.tops.take(y.len());
        ys.extend_from_slice(y);
        let mut copy_reals = |v: &[f64]| {
            let mut out = pool.reals.take(v.len());
            out.extend_from_slice(v);
            out
        };
        let barrier = Barrier {
            s: copy_reals(&barrier.s),
            z: copy_reals(&barrier.z),
            y: copy_reals(&barrier.y),
            ..*barrier
        };
        *kept = Some(Kept {
            iterate: copy,
            y: ys,
            barrier,
        });
    }

    /// Gives a kept point's vectors back to the pool.
    pub(super) fn give_kept(&self, kept: Kept<N, X>) {
        self.give_iterate(kept.iterate);
        let mut pool = self.pool.borrow_mut();
        pool.tops.give(kept.y);
        for v in kept.barrier.into_vectors() {
            pool.reals.give(v);
        }
    }

    /// The plan at the point kept before the barrier's floor, where the iteration is stuck
    /// (the last `floor_stalled` iterations, at least [`STALLED_AT_FLOOR`], made only
    /// rounding-level progress at the floor and `error`, the current $\max$(stationarity,
    /// feasibility), is above the acceptable level) or at its limit after `iterations` (not
    /// in a real-time iteration): [`Self::finish_kept`] at the point `kept` held, which is
    /// taken (tried once) and its vectors given back to the pool; `None` otherwise.
    pub(super) fn exit_at_kept(
        &self,
        kept: &mut Option<Kept<N, X>>,
        (floor_stalled, error): (usize, f64),
        iterations: usize,
    ) -> Option<Plan<N, X>> {
        let stuck = floor_stalled >= STALLED_AT_FLOOR && error > self.options.acceptable;
        let ending = iterations == self.options.max_iterations && !self.real_time;
        if !(stuck || ending) {
            return None;
        }
        let point = kept.take()?;
        let plan = self.finish_kept(&point, iterations);
        self.give_kept(point);
        plan
    }

    /// The plan at the `kept` point after `iterations`: its subproblem solved again, and the
    /// plan of [`Self::finish`] if the error $\max$(stationarity, feasibility) and the
    /// complementarity there are at most the acceptable level and the point passes the
    /// second-order check with every imposed constraint within the tolerance; `None`
    /// otherwise.
    fn finish_kept(&self, kept: &Kept<N, X>, iterations: usize) -> Option<Plan<N, X>> {
        let point = (&kept.iterate, &kept.y[..], &kept.barrier);
        let mut models = self.models(point.0, point.1, point.2).ok()?;
        let Ok(sub) = self.subproblem(&mut models, point.2, None, 0.0) else {
            self.give_models(models);
            return None;
        };
        let complementarity = kept.barrier.complementarity().0;
        let plan = if sub.error.max(complementarity) <= self.options.acceptable {
            match self.finish(point, &models, sub, iterations) {
                Finished::Plan(plan) => Some(plan),
                Finished::Failed(_, _, sub) | Finished::Not(sub) => {
                    self.give_subproblem(sub);
                    None
                }
            }
        } else {
            self.give_subproblem(sub);
            None
        };
        self.give_models(models);
        plan
    }
}
