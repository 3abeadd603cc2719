//! Second-order corrections of the line search (Wächter and Biegler, Math. Program. 106,
//! 2006, §2.4, Algorithm A steps 5.5-5.10): where the full step is rejected and raises the
//! constraint violation (the Maratos effect of curved constraints), the step is recomputed
//! with the same factorisation for the accumulated residual of the nonlinear constraints,
//! up to [`crate::bvp::PlanOptions::second_order_corrections`] times (IPOPT's $p_{\max}$; 0,
//! none, by default) while each reduces the violation by [`KAPPA_SOC`].
//!
//! The dynamics and the boundary data are linear, so their residual at the corrected step is
//! the first one's: only the stage equalities $g^{=}$ and the inequalities' $g - s$ change.
//! With $c$ those residuals, $c_{\rm soc} = \alpha c(x_k) + c(x_k + \alpha d)$ at the first
//! correction and $c_{\rm soc} \leftarrow \alpha_{\rm soc} c_{\rm soc} + c(x_{\rm soc})$
//! after each; the corrected direction solves the subproblem with $c_{\rm soc}$ in place of
//! $c(x_k)$.

use nalgebra::SVector;

use super::state::{Models, Sqp};
use crate::bvp::barrier::{Barrier, Slot};
use crate::bvp::iterate::{Iterate, blocks};
use crate::bvp::kkt::riccati::{Direction, Riccati};
use crate::{Lagrangian, LiftedSystem};

/// IPOPT's $\kappa_{\rm soc}$: a correction is followed by another only if it reduced the
/// violation to at most this factor of the last one.
const KAPPA_SOC: f64 = 0.99;

/// A corrected step: the direction and the slack steps that go with it.
pub(super) struct Corrected<const N: usize, const X: usize> {
    pub direction: Direction<N, X>,
    pub ds: Vec<f64>,
}

/// The residuals of the nonlinear constraints: $g - s$ of every inequality and $g^{=}$ of
/// every step.
struct Residuals<const N: usize> {
    inequalities: Vec<f64>,
    equalities: Vec<SVector<f64, N>>,
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The line search's second-order correction after the rejected first trial `first`
    /// (step length `alpha` along the direction with slack steps `ds`): the accepted
    /// corrected point (by `accepts` on its $(\theta, \varphi)$), its step length and its
    /// step; `None` if no correction is accepted. `factor` is the subproblem's factorisation
    /// with its inertia correction $h \rho$.
    pub(super) fn second_order_correction(
        &self,
        (iterate, models): (&Iterate<N, X>, &Models<N, X>),
        factor: (&Riccati<N, X>, f64),
        (barrier, ds, alpha): (&Barrier, &[f64], f64),
        first: &Iterate<N, X>,
        accepts: &mut dyn FnMut(f64, f64) -> bool,
    ) -> Option<(Iterate<N, X>, f64, Corrected<N, X>)> {
        let mut soc = self.residuals_at(first, barrier, (ds, alpha));
        for (k, c) in models.inequalities.iter().enumerate() {
            soc.inequalities[k] += alpha * (c.value - barrier.s[k]);
        }
        for (e, stage) in soc.equalities.iter_mut().zip(&models.stages) {
            *e += stage.value * alpha;
        }
        let mut theta_old = models.violation_l1();
        let mut accepted = None;
        let most = self.options.second_order_corrections;
        for p in 1..=most {
            let corrected = self.corrected_direction(models, factor, barrier, &soc);
            let alpha_soc = barrier.max_step(&corrected.ds);
            let (trial, parts) = self.trial(
                iterate,
                &corrected.direction,
                (barrier, &corrected.ds),
                alpha_soc,
            );
            let Some((phi_t, theta_t)) = parts else {
                self.give_iterate(trial);
                self.give_corrected(corrected);
                break;
            };
            if accepts(theta_t, phi_t) {
                accepted = Some((trial, alpha_soc, corrected));
                break;
            }
            let go_on = p < most && theta_t <= KAPPA_SOC * theta_old;
            if go_on {
                let next = self.residuals_at(&trial, barrier, (&corrected.ds, alpha_soc));
                for (c, n) in soc.inequalities.iter_mut().zip(&next.inequalities) {
                    *c = alpha_soc * *c + n;
                }
                for (c, n) in soc.equalities.iter_mut().zip(&next.equalities) {
                    *c = *c * alpha_soc + n;
                }
                self.give_residuals(next);
                theta_old = theta_t;
            }
            self.give_iterate(trial);
            self.give_corrected(corrected);
            if !go_on {
                break;
            }
        }
        self.give_residuals(soc);
        accepted
    }

    /// The residuals of the nonlinear constraints at `trial`, whose slacks are $s + \alpha
    /// \delta s$ (`ds`, `alpha`): $g(x) - s - \alpha\thinspace\delta s$ of every inequality,
    /// $g^{=}$ of every step.
    fn residuals_at(
        &self,
        trial: &Iterate<N, X>,
        barrier: &Barrier,
        (ds, alpha): (&[f64], f64),
    ) -> Residuals<N> {
        let mut pool = self.pool.borrow_mut();
        let mut inequalities = pool.reals.take(barrier.s.len());
        let mut equalities = pool.tops.take(trial.u.len());
        drop(pool);
        for (i, u) in trial.u.iter().enumerate() {
            let xt = self.x_theta(trial, i);
            let xb = blocks::<N, K, X>(&xt);
            let mut value = SVector::zeros();
            for (j, g) in self.problem.equalities.iter().enumerate() {
                value[j] = g.value(&xb, u);
            }
            equalities.push(value);
            inequalities.extend(self.at_steps.iter().map(|c| c.value(&xt, u)));
        }
        self.node_values(trial, &mut inequalities);
        for (k, g) in inequalities.iter_mut().enumerate() {
            *g -= barrier.s[k] + alpha * ds[k];
        }
        Residuals {
            inequalities,
            equalities,
        }
    }

    /// The subproblem's solution with the factorisation `factor` for the residuals `soc` of
    /// the nonlinear constraints in place of those at the iterate of `models`: the barrier's
    /// gradient $-\nabla g (h \mu / s - (h z / s + w \rho_h) r)$ of each inequality with $r$
    /// from `soc` ($w \rho_h$ the slack's share of the inertia correction, as in
    /// [`Barrier::shift_slacks`]),
    /// the stage equalities' offsets from `soc`; its slack steps $\nabla g^T \delta y + r$.
    fn corrected_direction(
        &self,
        models: &Models<N, X>,
        (riccati, rho_h): (&Riccati<N, X>, f64),
        barrier: &Barrier,
        soc: &Residuals<N>,
    ) -> Corrected<N, X> {
        let h = self.dynamics.h;
        let mut pool = self.pool.borrow_mut();
        let mut stages = pool.stages.take(models.stages.len());
        stages.extend_from_slice(&models.stages);
        let weights = barrier.weights(self.violation_weights);
        for ((k, c), w) in models.inequalities.iter().enumerate().zip(weights) {
            let (s, z) = (barrier.s[k], barrier.z[k]);
            // (the inertia correction shifts the slacks' Hessian: Barrier::shift_slacks)
            let shift = (h * z / s + w * rho_h) * (soc.inequalities[k] - (c.value - s));
            match barrier.slot(k) {
                Slot::Step(i) => {
                    stages[i].gx += c.gx * shift;
                    stages[i].gu += c.gu * shift;
                }
                Slot::Node(i) => {
                    if let Some(node) = &mut stages[i].node {
                        node.1 += c.gx * shift;
                    }
                }
            }
        }
        for (stage, value) in stages.iter_mut().zip(&soc.equalities) {
            stage.value = *value;
        }
        let end = (&models.r_end, &models.terminal_gradient);
        let direction = riccati.solve(&self.dynamics, &stages, &models.r0, end, &mut *pool);
        pool.stages.give(stages);
        let ds = pool.reals.take(barrier.s.len());
        drop(pool);
        let theta = self.dynamics.theta;
        let mut ds = barrier.slack_steps(&models.inequalities, &direction, theta, ds);
        for (k, c) in models.inequalities.iter().enumerate() {
            ds[k] += soc.inequalities[k] - (c.value - barrier.s[k]);
        }
        Corrected { direction, ds }
    }

    /// Gives a corrected step's vectors back to the pool.
    pub(super) fn give_corrected(&self, corrected: Corrected<N, X>) {
        let mut pool = self.pool.borrow_mut();
        corrected.direction.recycle(&mut *pool);
        pool.reals.give(corrected.ds);
    }

    /// Gives residuals' vectors back to the pool.
    fn give_residuals(&self, residuals: Residuals<N>) {
        let mut pool = self.pool.borrow_mut();
        pool.reals.give(residuals.inequalities);
        pool.tops.give(residuals.equalities);
    }
}
