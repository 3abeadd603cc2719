//! The KKT system at a plan, factorised for its sensitivities: the stage models of the
//! Lagrangian at the plan with the active inequalities as penalties, their Riccati
//! factorisation without inertia correction, and the active inequalities for the method of
//! multipliers that holds them as equalities.
//!
//! At a solution with strict complementarity the active set does not change under a small
//! perturbation, so the derivative of the plan is that of the problem with the active
//! inequalities as equalities and the inactive ones dropped (Fiacco's sensitivity theorem).
//! The inequality $k$ counts as active where its slack is below its multiplier, $s_k < z_k$
//! (their product is the final barrier parameter $\mu$: strict complementarity separates
//! them by orders of magnitude). The barrier problem's own matrix, with weights $h z / s
//! \approx z^2 / \mu$ up to $10^{14}$ times the rest, costs the Riccati solve its digits; here
//! an active inequality weighs $\sigma_k \nabla g_k \nabla g_k^T$ with $\sigma_k$
//! [`PENALTY`] times the scale of the stage Hessians over $|\nabla g_k|^2$, and the method of
//! multipliers (the multiplier estimate $\nu_k \leftarrow \nu_k + \sigma_k \nabla g_k^T
//! \delta y$ between solves) removes the penalty's error $O(1 / \text{[`PENALTY`]})$ at
//! every solve. A weakly active inequality, $s$ and $z$ both near $\sqrt\mu$, has no
//! derivative: it is refused ([`Failure::WeaklyActive`]).

use nalgebra::SVector;

use super::state::Sqp;
use crate::bvp::Location;
use crate::bvp::barrier::{Barrier, Slot};
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::model::{StageModel, Terminal};
use crate::bvp::kkt::riccati::Riccati;
use crate::bvp::plan::Failure;
use crate::bvp::plan::duals::Duals;
use crate::{Error, Lagrangian, LiftedSystem};

/// The ratio of an inequality's slack and multiplier (either way) within which it counts as
/// weakly active ([`Sqp::at_solution`]): both within a factor 10 of $\sqrt\mu$.
pub(in crate::bvp) const WEAK_RATIO: f64 = 100.0;

/// The weight of an active inequality's penalty relative to the largest entry of the stage
/// Hessians (and to $|\nabla g|^2$): the method of multipliers gains about this factor per
/// solve, and the Riccati solve loses about as many digits.
pub(in crate::bvp) const PENALTY: f64 = 1e6;

/// An active inequality: where it lives, its gradient in the step's $(x_\theta, u)$ (or in
/// the node's $x_i$) and its penalty weight $\sigma$.
#[derive(Clone, Copy, Debug)]
pub(in crate::bvp) struct Active<const N: usize, const X: usize> {
    pub slot: Slot,
    pub gx: SVector<f64, X>,
    pub gu: SVector<f64, N>,
    pub sigma: f64,
}

/// The KKT system at a plan: the stage models (Hessians with the active inequalities'
/// penalties; their gradients are replaced by each right-hand side), the ends, the
/// factorisation and the active inequalities.
pub(in crate::bvp) struct AtSolution<const N: usize, const X: usize> {
    pub stages: Vec<StageModel<N, X>>,
    pub terminal: Terminal<X>,
    pub riccati: Riccati<N, X>,
    pub active: Vec<Active<N, X>>,
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The KKT system at `iterate` (a plan) with the stage equalities' multipliers `y` and
    /// the inequalities' `duals`, factorised.
    ///
    /// Errors: [`Failure::Invalid`] if the duals do not fit the problem's inequalities,
    /// [`Failure::WeaklyActive`] (the first such inequality), [`Failure::NonFinite`],
    /// [`Failure::NotAMinimum`] if the penalised reduced Hessian is not positive definite
    /// without correction (not a strict minimum on the active set).
    pub(in crate::bvp) fn at_solution(
        &self,
        iterate: &Iterate<N, X>,
        y: &[SVector<f64, N>],
        duals: &Duals<N>,
    ) -> Result<AtSolution<N, X>, Failure> {
        let steps = iterate.u.len();
        let layout = (self.at_steps.len(), self.at_nodes.len(), steps);
        let fits = duals.fit(steps, layout.0, layout.1) && duals.barrier >= 0.0;
        if !fits {
            return Err(Failure::Invalid(Error::InvalidArgument {
                name: "plan",
                requirement: "its duals (slacks and multipliers, positive and finite) fit the \
                              problem's inequalities",
            }));
        }
        let vectors = {
            let mut pool = self.pool.borrow_mut();
            [0; 3].map(|_| pool.reals.take(0))
        };
        let mut barrier = Barrier::at_solution(duals, layout, vectors, self.dynamics.h);
        let active_set: Vec<bool> = (barrier.s.iter().zip(&barrier.z))
            .map(|(s, z)| s < z)
            .collect();
        let checked = self.strictly_complementary(&barrier);
        // the Lagrangian's models: the inequalities' curvature with their multipliers (y),
        // no barrier weights (z = 0)
        barrier.z.iter_mut().for_each(|z| *z = 0.0);
        let models = checked.and_then(|()| self.models(iterate, y, &barrier));
        let mut models = match models {
            Ok(models) => models,
            Err(failure) => {
                self.give_barrier(barrier);
                return Err(failure);
            }
        };
        let scale = self.hessian_scale(&models.stages);
        let mut active = Vec::new();
        for (k, c) in models.inequalities.iter().enumerate() {
            if !active_set[k] {
                continue;
            }
            let sigma = PENALTY * scale / c.gx.norm_squared().max(c.gu.norm_squared()).max(1e-300);
            barrier.add_outer(&mut models.stages, k, c, sigma);
            active.push(Active {
                slot: barrier.slot(k),
                gx: c.gx,
                gu: c.gu,
                sigma,
            });
        }
        self.give_barrier(barrier);
        let riccati = {
            let pool = &mut *self.pool.borrow_mut();
            Riccati::factor_with(&self.dynamics, &models.stages, 0.0, &models.terminal, pool)
        };
        let terminal = models.terminal;
        let stages = {
            let mut pool = self.pool.borrow_mut();
            pool.linearized.give(models.inequalities);
            pool.gradients.give(models.cost_gradient);
            models.stages
        };
        if !riccati.positive_definite() {
            let mut pool = self.pool.borrow_mut();
            let negative_directions = riccati.negative;
            riccati.recycle(&mut *pool);
            pool.stages.give(stages);
            return Err(Failure::NotAMinimum {
                negative_directions,
            });
        }
        Ok(AtSolution {
            stages,
            terminal,
            riccati,
            active,
        })
    }

    /// Gives a barrier's vectors back to the pool.
    fn give_barrier(&self, barrier: Barrier) {
        let mut pool = self.pool.borrow_mut();
        for v in barrier.into_vectors() {
            pool.reals.give(v);
        }
    }

    /// [`Failure::WeaklyActive`] for the first inequality of `barrier` whose slack and
    /// multiplier are within a factor [`WEAK_RATIO`] of each other: their product is $\mu$,
    /// and strict complementarity keeps one of them of order 1 as $\mu \to 0$ while the
    /// other falls like $\mu$, so a weakly active inequality has both near $\sqrt\mu$.
    fn strictly_complementary(&self, barrier: &Barrier) -> Result<(), Failure> {
        let weak = (barrier.s.iter().zip(&barrier.z))
            .position(|(s, z)| s.min(*z) * WEAK_RATIO >= s.max(*z));
        let Some(k) = weak else {
            return Ok(());
        };
        let (inequality, location) = match barrier.slot(k) {
            Slot::Step(i) => (&self.at_steps[k % barrier.count], Location::Step(i)),
            Slot::Node(i) => {
                let j = (k - barrier.at_steps()) % barrier.nodes;
                (&self.at_nodes[j], Location::Node(i))
            }
        };
        Err(Failure::WeaklyActive {
            constraint: inequality.reference(),
            location,
            slack: barrier.s[k],
            multiplier: barrier.z[k],
        })
    }
}
