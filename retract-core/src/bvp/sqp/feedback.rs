//! The two phases of a real-time iteration (as acados' RTI, Diehl et al. 2005): the
//! preparation linearises and factorises the subproblem at an iterate before the start is
//! known (models, inertia-corrected Riccati factorisation and the backward pass of its
//! solve, none of which reads $\delta x_0$), and the feedback embeds the measured start as
//! $\delta x_0 = a - x_0$ and takes the full Newton step of the subproblem (one forward pass,
//! no line search).

use nalgebra::SVector;

use super::state::Sqp;
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::riccati::{Prepared, Riccati};
use crate::bvp::plan::Failure;
use crate::{Lagrangian, LiftedSystem};

/// A prepared subproblem: the factorisation at the iterate, with its inertia correction
/// $\rho$, the backward pass of its solve, the terminal residual $r_N$ and the largest
/// constraint violation at the iterate.
pub(in crate::bvp) struct Linearization<const N: usize, const X: usize> {
    pub riccati: Riccati<N, X>,
    pub prepared: Prepared<N, X>,
    pub rho: f64,
    pub r_end: SVector<f64, X>,
    pub violation: f64,
    /// $J$ at the iterate.
    pub cost: f64,
}

/// What a feedback step did: its size $\max(\Vert\delta x\Vert_\infty, \Vert\delta
/// u\Vert_\infty)$ and the size of the start's change $\Vert a - x_0\Vert_\infty$.
#[derive(Clone, Copy, Debug)]
pub(in crate::bvp) struct Step {
    pub size: f64,
    pub start_change: f64,
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The preparation phase at `iterate` with the stage equalities' multipliers `y`: the
    /// models, the factorisation with the inertia correction (from a third of `rho_last`,
    /// as [`Self::factor_corrected`]) and the backward pass of the solve. Problems without
    /// inequalities only (the caller checks): the barrier is empty.
    pub(in crate::bvp) fn linearize(
        &self,
        iterate: &Iterate<N, X>,
        y: &[SVector<f64, N>],
        rho_last: f64,
    ) -> Result<Linearization<N, X>, Failure> {
        let steps = iterate.u.len();
        let none = [Vec::new(), Vec::new(), Vec::new()];
        let barrier = Barrier::new(
            (0.0, self.dynamics.h),
            (0, 0, steps),
            &[],
            |_| (0.0, 0.0),
            none,
        );
        let mut models = self.models(iterate, y, &barrier)?;
        let factored = self.factor_corrected(&mut models, &barrier, rho_last);
        let (riccati, rho) = match factored {
            Ok(found) => found,
            Err(failure) => {
                self.give_models(models);
                return Err(failure);
            }
        };
        let ends = (&models.r_end, &models.terminal_gradient);
        let prepared = {
            let mut pool = self.pool.borrow_mut();
            riccati.prepare(&self.dynamics, &models.stages, ends, &mut *pool)
        };
        let linearization = Linearization {
            riccati,
            prepared,
            rho,
            r_end: models.r_end,
            violation: models.violation_max(),
            cost: models.cost,
        };
        self.give_models(models);
        Ok(linearization)
    }

    /// The feedback phase: the full step of the subproblem `lin` (prepared at `iterate`) with
    /// the start `start` embedded, $\delta x_0 = a - x_0$ on the fixed start components,
    /// applied to `iterate` and `y` (the stage equalities' multipliers become the
    /// subproblem's). [`Failure::NonFinite`] (and nothing changed) if the step is not finite.
    pub(in crate::bvp) fn feedback(
        &self,
        lin: &Linearization<N, X>,
        start: &SVector<f64, X>,
        (iterate, y): (&mut Iterate<N, X>, &mut [SVector<f64, N>]),
    ) -> Result<Step, Failure> {
        let fixed = &self.problem.fixed_start;
        let r0 = (start - iterate.x[0]).component_mul(fixed);
        let direction = {
            let mut pool = self.pool.borrow_mut();
            let dynamics = &self.dynamics;
            (lin.riccati).forward(dynamics, &lin.prepared, &r0, &lin.r_end, &mut *pool)
        };
        let size = (direction.dx.iter().map(|d| d.amax()))
            .chain(direction.du.iter().map(|d| d.amax()))
            .fold(0.0, f64::max);
        let finite = size.is_finite()
            && (direction.multipliers.iter()).all(|m| m.iter().all(|v| v.is_finite()));
        if finite {
            for (x, dx) in iterate.x.iter_mut().zip(&direction.dx) {
                *x += dx;
            }
            for (u, du) in iterate.u.iter_mut().zip(&direction.du) {
                *u += du;
            }
            // (the start exactly, not up to the rounding of x_0 + (a - x_0))
            for r in 0..X {
                if fixed[r] != 0.0 {
                    iterate.x[0][r] = start[r];
                }
            }
            y.copy_from_slice(&direction.multipliers);
        }
        direction.recycle(&mut *self.pool.borrow_mut());
        if !finite {
            return Err(Failure::NonFinite);
        }
        Ok(Step {
            size,
            start_change: r0.amax(),
        })
    }
}
