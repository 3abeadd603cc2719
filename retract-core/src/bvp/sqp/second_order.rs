//! The second-order check of a KKT point: the inertia of the Lagrangian's reduced Hessian
//! with the active inequalities as penalties (Finsler's lemma), positive semidefinite where
//! a shift of the rounding's size makes it definite, and its smallest eigenvalue for the
//! certificate.

use nalgebra::SVector;

use super::state::{Models, Sqp};
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::curvature::min_reduced_eigenvalue;
use crate::bvp::kkt::model::StageModel;
use crate::bvp::kkt::riccati::Riccati;
use crate::bvp::plan::{Certificate, Failure};
use crate::{Lagrangian, LiftedSystem};

/// The penalty weights of the active inequalities in the second-order check
/// ([`Sqp::certify`]), relative to the largest entry of the stage Hessians (and to
/// $|\nabla g|^2$), tried in turn.
const FINSLER_WEIGHTS: [f64; 3] = [1e2, 1e4, 1e6];

/// The shift of the stage Hessians, relative to their largest entry, under which a singular
/// reduced Hessian, or one whose negative eigenvalues are of the rounding's size, counts as
/// positive semidefinite ([`Sqp::shifted_factor`]): a few hundred roundings of the largest
/// entry.
const SEMIDEFINITE_SHIFT: f64 = 1e-13;

/// A shift of the stage Hessians, relative to their largest entry, above the magnitude of
/// any eigenvalue of the reduced Hessian (that is at most a few times $X + N$ times the
/// largest entry): a negative count that remains under it does not come from curvature
/// ([`Sqp::second_order`]).
pub(super) const DECISIVE_SHIFT: f64 = 1e4;

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The second-order check at a KKT point: the Hessian of the Lagrangian must be positive
    /// definite on the null space of the constraints, the active inequalities ($s_k < z_k$:
    /// strict complementarity separates them by orders of magnitude) included and the barrier
    /// terms left out (the second-order sufficient condition; the barrier Hessian itself is
    /// too ill-conditioned near the end to count its inertia). The active inequalities enter
    /// as penalties $\sigma \nabla g \nabla g^T$ (Finsler's lemma: if $H + \sigma A^T A$ is
    /// positive definite on the null space of the other constraints, so is $H$ on that of $A$
    /// too, for any $\sigma$; and the converse holds for $\sigma$ large enough), with
    /// $\sigma$ from [`FINSLER_WEIGHTS`] times the scale of the stage Hessians until the count
    /// is right. That needs no rank of the active set: state constraints at $\theta = 0$ or
    /// more than $n$ active inequalities at a step are fine. Then the smallest eigenvalue of
    /// the penalised reduced Hessian (a lower bound on that of the constrained one) completes
    /// the certificate. `factored`: the factorisation of `models` without correction, if there
    /// is one (without inequalities it is the one checked; else it is computed here).
    pub(super) fn certify(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
        factored: Option<&Riccati<N, X>>,
        certificate: Certificate,
    ) -> Result<Certificate, (Failure, Certificate)> {
        let barrier = state.2;
        let mut refactored = None;
        let exact = if !barrier.s.is_empty() {
            refactored.insert(self.penalized_factor(state, models, 0.0))
        } else if let Some(riccati) = factored {
            riccati
        } else {
            let pool = &mut *self.pool.borrow_mut();
            let (stages, end) = (&models.stages, &models.terminal);
            refactored.insert(Riccati::factor_with(&self.dynamics, stages, 0.0, end, pool))
        };
        let result = self.second_order(state, models, exact, certificate);
        if let Some(riccati) = refactored {
            riccati.recycle(&mut *self.pool.borrow_mut());
        }
        result
    }

    /// The rest of [`Self::certify`] with the factorisation `exact` of its second-order check:
    /// its inertia, the shifted factorisation of a singular one, the smallest eigenvalue.
    pub(super) fn second_order(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
        exact: &Riccati<N, X>,
        mut certificate: Certificate,
    ) -> Result<Certificate, (Failure, Certificate)> {
        certificate.negative_directions = exact.negative;
        if !exact.positive_definite() {
            // singular, or with pivots of either sign at the rounding's size: semidefinite
            // if a shift of the rounding's size makes it definite (a minimum, flat along some
            // direction: not strict); the negative directions that remain under the shift
            // are the ones counted
            let shifted = self.shifted_factor(state, models, SEMIDEFINITE_SHIFT);
            let (definite, negative) = (shifted.positive_definite(), shifted.negative);
            shifted.recycle(&mut *self.pool.borrow_mut());
            certificate.negative_directions = negative;
            if definite {
                certificate.min_reduced_hessian_eig = 0.0;
                return Ok(certificate);
            }
            // a count that even the largest shift leaves is not curvature: the constraints'
            // Jacobian loses rank there and the check cannot be made
            let largest = self.shifted_factor(state, models, DECISIVE_SHIFT);
            if !largest.positive_definite() {
                certificate.negative_directions = 0;
            }
            largest.recycle(&mut *self.pool.borrow_mut());
            let failure = Failure::NotAMinimum {
                negative_directions: certificate.negative_directions,
            };
            return Err((failure, certificate));
        }
        if self.options.min_eigenvalue {
            let rows = models.stages.iter().map(|s| s.constraints).sum();
            let pool = &mut *self.pool.borrow_mut();
            certificate.min_reduced_hessian_eig =
                min_reduced_eigenvalue(exact, &self.dynamics, (&models.terminal, rows), pool);
        }
        Ok(certificate)
    }

    /// The factorisation of the second-order check ([`Self::certify`]) with every stage
    /// Hessian shifted by `shift` times the largest entry of the Lagrangian's stage Hessians
    /// ($h$ at least). With [`SEMIDEFINITE_SHIFT`]: positive definite where the reduced
    /// Hessian is positive semidefinite and singular, with the negative directions counted
    /// where it is not.
    pub(super) fn shifted_factor(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
        shift: f64,
    ) -> Riccati<N, X> {
        if !state.2.s.is_empty() {
            return self.penalized_factor(state, models, shift);
        }
        let shift = shift * self.hessian_scale(&models.stages);
        let pool = &mut *self.pool.borrow_mut();
        Riccati::factor_with(
            &self.dynamics,
            &models.stages,
            shift,
            &models.terminal,
            pool,
        )
    }

    /// The largest entry of the stage Hessians $H_{xx}$, $H_{uu}$, and $h$ at least.
    pub(super) fn hessian_scale(&self, stages: &[StageModel<N, X>]) -> f64 {
        stages.iter().fold(self.dynamics.h, |m, s| {
            m.max(crate::newton::max_abs(&s.hxx))
                .max(crate::newton::max_abs(&s.huu))
        })
    }

    /// The factorisation of the Lagrangian's stage models (no barrier terms) with the active
    /// inequalities as penalties, for the first weight of [`FINSLER_WEIGHTS`] that makes it
    /// positive definite (else the last one's); every stage Hessian shifted by `shift` times
    /// their scale ([`Self::hessian_scale`]).
    pub(super) fn penalized_factor(
        &self,
        (iterate, y, barrier): (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
        shift: f64,
    ) -> Riccati<N, X> {
        let steps = iterate.u.len();
        let (mut base, mut stages) = {
            let mut pool = self.pool.borrow_mut();
            (pool.stages.take(steps), pool.stages.take(steps))
        };
        for (i, y) in y.iter().enumerate().take(steps) {
            self.push_stage(&mut base, (iterate, i), y, barrier);
        }
        stages.extend_from_slice(&base);
        let scale = self.hessian_scale(&base);
        let lin = &models.inequalities;
        let mut riccati: Option<Riccati<N, X>> = None;
        let pool = &mut *self.pool.borrow_mut();
        for weight in FINSLER_WEIGHTS {
            stages.clone_from_slice(&base);
            for (k, c) in lin.iter().enumerate() {
                if barrier.s[k] >= barrier.z[k] {
                    continue;
                }
                let sigma =
                    weight * scale / c.gx.norm_squared().max(c.gu.norm_squared()).max(1e-300);
                barrier.add_outer(&mut stages, k, c, sigma);
            }
            if let Some(last) = riccati.take() {
                last.recycle(pool);
            }
            let end = &models.terminal;
            let factor = Riccati::factor_with(&self.dynamics, &stages, shift * scale, end, pool);
            let done = factor.positive_definite();
            riccati = Some(factor);
            if done {
                break;
            }
        }
        let riccati = riccati.unwrap_or_else(|| {
            Riccati::factor_with(&self.dynamics, &base, shift * scale, &models.terminal, pool)
        });
        pool.stages.give(base);
        pool.stages.give(stages);
        riccati
    }
}
