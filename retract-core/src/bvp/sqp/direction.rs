//! The direction phase: the subproblem at the models of an iterate, solved by the Riccati
//! factorisation with the inertia correction (or, near a solution, the kept factorisation
//! of the last iterate: a simplified Newton step), refined where the barrier makes it
//! ill-conditioned, with the multipliers, residuals and errors that go with it.

use nalgebra::SVector;

use super::state::{Models, Sqp, Subproblem};
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::model::StageModel;
use crate::bvp::kkt::refine::{needs_refinement, refine};
use crate::bvp::kkt::riccati::Riccati;
use crate::bvp::plan::{Certificate, Failure};
use crate::{Lagrangian, LiftedSystem};

/// The ratio $z / s$ of an inequality above which the subproblem's solution is refined
/// ([`refine`]), and the number of refinement steps.
const REFINE_RATIO: f64 = 1e6;
const REFINEMENTS: usize = 2;
/// The most refinement steps of a solve with a regularised terminal pivot (IPOPT's
/// `max_refinement_steps`), each only while [`needs_refinement`] says so.
const REGULARIZED_REFINEMENTS: usize = 10;

/// IPOPT's first inertia correction $\bar\delta_w^0$ (`first_hessian_perturbation`), in the
/// transcribed problem's units: $h \rho$.
const FIRST_CORRECTION: f64 = 1e-4;

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The models at the point `(iterate, y, barrier)` and the subproblem solved there (from
    /// the `kept` factorisation if any); on a failure, the failure and the point's cost and
    /// certificate (`None` where the models could not be formed: nothing to report), an
    /// inertia-correction or line-search failure named by [`Self::name_infeasibility`].
    #[allow(clippy::type_complexity, clippy::result_large_err)] // (once an iteration)
    pub(super) fn model_and_solve(
        &self,
        (iterate, y, barrier): (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        kept: Option<(Riccati<N, X>, f64)>,
        rho_last: f64,
    ) -> Result<(Models<N, X>, Subproblem<N, X>), (Failure, Option<(f64, Certificate)>)> {
        let mut models = match self.models(iterate, y, barrier) {
            Ok(models) => models,
            Err(Failure::TimeLimit) => {
                let (cost, certificate) = self.interrupted_certificate(iterate, barrier);
                return Err((Failure::TimeLimit, Some((cost, certificate))));
            }
            Err(failure) => return Err((failure, None)),
        };
        match self.subproblem(&mut models, barrier, kept, rho_last) {
            Ok(sub) => Ok((models, sub)),
            Err(failure) => {
                let (failure, certificate) = if matches!(failure, Failure::TimeLimit) {
                    // (no least-squares multipliers: they would cost another factorisation)
                    (failure, Self::unsolved_certificate(&models, barrier))
                } else {
                    let partial = self.failure_certificate(&models, barrier);
                    (
                        self.name_infeasibility(failure, (iterate, &models), None),
                        partial,
                    )
                };
                let cost = models.cost;
                self.give_models(models);
                Err((failure, Some((cost, certificate))))
            }
        }
    }

    /// The subproblem at `models`. With the factorisation `kept` of the previous iterate
    /// (whose error was $e_{\rm prev}$), a simplified Newton step: taken if its predicted error
    /// from here, about $e^2 / e_{\rm prev}$ (the kept factorisation is off by about the last
    /// step, $e_{\rm prev}$), is below the tolerance. Otherwise, or without `kept`, a new
    /// inertia-corrected factorisation ([`Self::factor_corrected`], whose failure is
    /// returned). (A kept factorisation was positive definite without correction, so the
    /// negative directions reported with it, 0, are those of the previous iterate.)
    pub(super) fn subproblem(
        &self,
        models: &mut Models<N, X>,
        barrier: &Barrier,
        kept: Option<(Riccati<N, X>, f64)>,
        rho_last: f64,
    ) -> Result<Subproblem<N, X>, Failure> {
        if let Some((riccati, e_prev)) = kept {
            let sub = self.solved((models, barrier), riccati, 0.0, true);
            let tolerance = self.options.tolerance;
            if sub.error <= tolerance || sub.error * sub.error <= tolerance * e_prev {
                return Ok(sub);
            }
            self.give_subproblem(sub);
        }
        let (riccati, rho) = self.factor_corrected(models, barrier, rho_last)?;
        Ok(self.solved((models, barrier), riccati, rho, false))
    }

    /// The subproblem solved with the factorisation `riccati` (inertia correction `rho`;
    /// `stale` if it is the previous iterate's): its direction (refined [`REFINEMENTS`] times
    /// where an active inequality's barrier Hessian $h z / s \nabla g \nabla g^T$ is
    /// [`REFINE_RATIO`] above the rest: it costs the solve digits; else, where the refinement
    /// check is on or the terminal pivot was regularised, while [`needs_refinement`] says so),
    /// the multipliers and residuals that go with it, and the errors of the problem and of the
    /// barrier problem.
    pub(super) fn solved(
        &self,
        (models, barrier): (&Models<N, X>, &Barrier),
        riccati: Riccati<N, X>,
        rho: f64,
        stale: bool,
    ) -> Subproblem<N, X> {
        let ill_conditioned =
            (barrier.z.iter().zip(&barrier.s)).any(|(z, s)| *z > REFINE_RATIO * s);
        let (r0, end) = (&models.r0, (&models.r_end, &models.terminal_gradient));
        let rho_h = self.dynamics.h * rho;
        let mut pool = self.pool.borrow_mut();
        let stages = &models.stages;
        let mut direction = riccati.solve(&self.dynamics, stages, r0, end, &mut *pool);
        let model = (&models.stages[..], &models.terminal);
        if ill_conditioned {
            for _ in 0..REFINEMENTS {
                let d = (&mut direction, &mut *pool);
                refine(&riccati, &self.dynamics, model, rho_h, r0, end, d);
            }
        } else if self.check_refinement.get() || riccati.regularized {
            // (a regularised terminal pivot solves the dependent rows only approximately:
            // refinement, IPOPT's ten steps at most, recovers a consistent system's solution)
            let steps = if riccati.regularized {
                REGULARIZED_REFINEMENTS
            } else {
                REFINEMENTS
            };
            for _ in 0..steps {
                if !needs_refinement(&self.dynamics, model, rho_h, r0, end, &direction) {
                    break;
                }
                let d = (&mut direction, &mut *pool);
                refine(&riccati, &self.dynamics, model, rho_h, r0, end, d);
            }
        }
        // the multipliers of the inequalities that go with the subproblem's solution: the
        // primal-dual step's, near a solution z + dz = (mu - z ds) / s (with the current z
        // the residual would measure dz, whose rounding z/s eps |g| swamps it there)
        let (ds, mut z) = (
            pool.reals.take(barrier.s.len()),
            pool.reals.take(barrier.s.len()),
        );
        drop(pool);
        let ds = barrier.slack_steps(&models.inequalities, &direction, self.dynamics.theta, ds);
        barrier.predicted(&ds, &mut z);
        let (momenta, certificate, _) =
            self.residuals(models, barrier, riccati.negative, &direction, &z);
        let barrier_error = self.barrier_error(models, barrier, (&direction, None), (&z, &momenta));
        let mut pool = self.pool.borrow_mut();
        pool.reals.give(ds);
        pool.reals.give(z);
        let error = certificate.stationarity.max(certificate.feasibility);
        Subproblem {
            riccati,
            rho,
            stale,
            direction,
            momenta,
            certificate,
            error,
            barrier_error,
        }
    }

    /// The Riccati factorisation with an inertia correction $\rho$ (per unit time: $h \rho$
    /// is added to the Hessian) that makes the reduced Hessian positive definite, IPOPT's
    /// (Wächter and Biegler 2006, §3.1): none first (in a real-time iteration, and without
    /// inequalities, only where `last` is below $10^{-8}$: a correction there decays
    /// geometrically instead of dropping to 0 where the Hessian is barely definite, whose
    /// long step the fixed iteration count cannot take back, and the pendulum of
    /// `tests/no_alloc.rs` kicked by (+8, -8) rad/s fell without it; without inequalities the
    /// extra factorisation per corrected iteration made the swing-up suite 1.2 to 2.2 times
    /// slower); then $h \rho = 10^{-4}$
    /// ([`FIRST_CORRECTION`]) if no correction was needed before (`last` = 0), else a third of
    /// the `last` positive one, growing by 100 (the first growth, or where the trial exceeds
    /// $10^5$ times `last`) or else by 8 until the inertia is right; with inequalities the correction shifts
    /// the eliminated slacks' Hessian too, as IPOPT's ([`Barrier::shift_slacks`]: the stages
    /// of `models` are left shifted by the correction found, for the solve that follows).
    /// Fails with [`Failure::Regularization`]
    /// past $\rho = 10^{40}$, or [`Failure::TimeLimit`] when the budget runs out between
    /// factorisations.
    pub(super) fn factor_corrected(
        &self,
        models: &mut Models<N, X>,
        barrier: &Barrier,
        last: f64,
    ) -> Result<(Riccati<N, X>, f64), Failure> {
        let h = self.dynamics.h;
        // (with inequalities a correction also shifts the eliminated slacks' Hessian: the
        // unshifted stages are kept from the first correction on, to shift each trial afresh)
        let mut base: Option<Vec<StageModel<N, X>>> = None;
        let mut factor = |rho: f64| {
            let mut pool = self.pool.borrow_mut();
            if rho > 0.0 && !barrier.s.is_empty() {
                let base = base.get_or_insert_with(|| {
                    let mut base = pool.stages.take(models.stages.len());
                    base.extend_from_slice(&models.stages);
                    base
                });
                models.stages.clone_from_slice(base);
                barrier.shift_slacks(
                    &mut models.stages,
                    &models.inequalities,
                    rho,
                    self.violation_weights,
                );
            }
            let (stages, end) = (&models.stages, &models.terminal);
            let clock = (self.deadline(), true, &mut *pool);
            let riccati = Riccati::factor_until(&self.dynamics, stages, rho, end, clock);
            if riccati.interrupted {
                riccati.recycle(&mut *pool);
                return Err(Failure::TimeLimit);
            }
            if riccati.positive_definite() {
                return Ok(Some(riccati));
            }
            riccati.recycle(&mut *pool);
            Ok(None)
        };
        // (no correction first; then rho growing until the inertia is right, or a failure)
        let mut found = if (!self.real_time && !barrier.s.is_empty()) || last < 1e-8 {
            factor(0.0).map(|r| r.map(|r| (r, 0.0)))
        } else {
            Ok(None)
        };
        let mut rho = if last > 0.0 {
            last / 3.0
        } else {
            FIRST_CORRECTION / h
        };
        while matches!(found, Ok(None)) && rho < 1e40 {
            found = factor(h * rho).map(|r| r.map(|r| (r, rho)));
            rho *= if last == 0.0 || 1e5 * last < rho {
                100.0
            } else {
                8.0
            };
        }
        if let Some(base) = base {
            self.pool.borrow_mut().stages.give(base);
        }
        found?.ok_or(Failure::Regularization)
    }
}
