//! The first multipliers: IPOPT's least-squares estimate of the equality multipliers at the
//! first iterate (Wächter and Biegler 2006, §3.6), for the barrier error that decides whether
//! $\mu$ falls before the first step and as the multipliers the first step starts from.

use nalgebra::{SMatrix, SVector};

use super::state::{Models, Sqp};
use crate::bvp::barrier::{Barrier, Slot};
use crate::bvp::constraints::partner_index;
use crate::bvp::kkt::residuals::step_multipliers;
use crate::bvp::kkt::riccati::{Direction, Riccati};
use crate::{Lagrangian, LiftedSystem};

/// The largest least-squares multiplier taken (IPOPT's `constr_mult_init_max`): beyond it the
/// estimate is discarded.
const MAX_FIRST_MULTIPLIER: f64 = 1e3;

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The $x$-equations' multipliers $\mu_i$ of the least-squares estimate `ls`
    /// ([`step_multipliers`] with no step and the gradients of the Lagrangian $h L - h z^T
    /// g^{\ge}$ at the iterate of `models`, $z$ the barrier's): the multipliers IPOPT carries
    /// from its first iterate.
    pub(super) fn first_step_multipliers(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        ls: &Direction<N, X>,
    ) -> Vec<SVector<f64, X>> {
        let gradients = self.lagrangian_gradients(models, barrier, &barrier.z);
        let mut pool = self.pool.borrow_mut();
        let mut mu = pool.jets.take(models.stages.len());
        let with = Some(gradients.as_deref().unwrap_or(&models.cost_gradient));
        step_multipliers(&self.dynamics, &models.stages, ls, with, &mut mu);
        if let Some(gradients) = gradients {
            pool.gradients.give(gradients);
        }
        mu
    }

    /// IPOPT's first multipliers: the equalities' (the dynamics' costates and the stage
    /// equalities') and the inequalities' $y$ of $g - s = 0$ that minimise, jointly, the norm
    /// of the gradient of the Lagrangian in the transcribed variables and in the slacks, with
    /// the inequality multipliers $z$ of `barrier` held
    /// ([`Self::least_squares_direction`] with the slacks' rows): per IPOPT row $v$ (one
    /// side alone, or the two sides $\ell \le v \le u$ of an interval, which share one
    /// slack), $y_d = r_s + h \nabla v^T w$ with $r_s = -h \sum_k \sigma_k z_k$ its slack's
    /// gradient, which per side $g_k = \sigma_k (v - c_k)$ is $y_k = z_k - \nabla g_k^T w /
    /// m_k$ ($m_k$ the sides of the row: the two of an interval split $y_d$ evenly).
    /// Returns the direction (whose `multipliers` and costates are the equalities') and $y$ in
    /// the barrier's order; `None` if the factorisation is not positive definite, or a
    /// multiplier (IPOPT's units: $h y$ for the inequalities) is not finite or exceeds
    /// [`MAX_FIRST_MULTIPLIER`] (IPOPT then starts every multiplier at 0).
    pub(super) fn least_squares_multipliers(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
    ) -> Option<(Direction<N, X>, Vec<f64>)> {
        let h = self.dynamics.h;
        let direction = self.least_squares_direction(models, barrier, true)?;
        let y = self.pool.borrow_mut().reals.take(barrier.s.len());
        let mut y = barrier.slack_steps(&models.inequalities, &direction, self.dynamics.theta, y);
        for (k, (yk, c)) in y.iter_mut().zip(&models.inequalities).enumerate() {
            let along = *yk - (c.value - barrier.s[k]);
            let sides = if self.interval_partner(barrier, k).is_some() {
                2.0
            } else {
                1.0
            };
            *yk = barrier.z[k] - along / sides;
        }
        let stage = direction.multipliers.iter().flat_map(|v| v.iter().copied());
        let costates = direction.costate.iter().flat_map(|v| v.iter().copied());
        let largest =
            (stage.chain(costates))
                .chain(y.iter().map(|v| h * v))
                .fold(0.0_f64, |m, v| {
                    if v.is_finite() {
                        m.max(v.abs())
                    } else {
                        f64::INFINITY
                    }
                });
        if largest <= MAX_FIRST_MULTIPLIER {
            Some((direction, y))
        } else {
            let mut pool = self.pool.borrow_mut();
            pool.reals.give(y);
            direction.recycle(&mut *pool);
            None
        }
    }

    /// The index in the barrier of the other side of entry `k`'s interval, if it is one side
    /// of an interval ([`partner_index`] in its list).
    pub(super) fn interval_partner(&self, barrier: &Barrier, k: usize) -> Option<usize> {
        match barrier.slot(k) {
            Slot::Step(i) => {
                let j = k - i * barrier.count;
                partner_index(self.at_steps, j).map(|p| i * barrier.count + p)
            }
            Slot::Node(i) => {
                let j = k - barrier.node_index(i, 0);
                partner_index(self.at_nodes, j).map(|p| barrier.node_index(i, p))
            }
        }
    }

    /// The solution of the least-squares system
    ///
    /// $$\begin{pmatrix} h I & C^T \\ C & 0 \end{pmatrix}
    ///   \begin{pmatrix} w \\ \lambda \end{pmatrix} =
    ///   -\begin{pmatrix} \nabla (J - h z^T g^{\ge}) \\ 0 \end{pmatrix}$$
    ///
    /// ($C$ the Jacobian of the dynamics, the stage equalities and the boundary data; $h I$
    /// in the transcribed variables, the nodes $x_i$ and the tops $u_i$, as IPOPT's identity),
    /// by one Riccati solve with zero constraint residuals; with `slacks`, each IPOPT row $v$
    /// of the inequalities also has its slack, eliminated: $h \nabla v \nabla v^T$ added to
    /// its step's or node's Hessian (once for the two sides of an interval). `None` if the
    /// factorisation is not positive definite (the equalities' Jacobian is rank-deficient).
    pub(super) fn least_squares_direction(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        slacks: bool,
    ) -> Option<Direction<N, X>> {
        let h = self.dynamics.h;
        let mut pool = self.pool.borrow_mut();
        let mut gradients = pool.gradients.take(models.cost_gradient.len());
        gradients.extend_from_slice(&models.cost_gradient);
        barrier.lagrangian_gradients(&mut gradients, &models.inequalities, &barrier.z, h);
        let mut nodes = pool.jets.take(barrier.steps + 1);
        barrier.node_gradients(&models.inequalities, &barrier.z, h, &mut nodes);
        let mut stages = pool.stages.take(models.stages.len());
        for (i, (stage, (gx, gu))) in models.stages.iter().zip(&gradients).enumerate() {
            let mut stage = stage.clone();
            stage.hxx = SMatrix::zeros();
            stage.hux = SMatrix::zeros();
            stage.huu = SMatrix::identity() * h;
            (stage.gx, stage.gu) = (*gx, *gu);
            stage.defect = SVector::zeros();
            stage.value = SVector::zeros();
            let node = nodes.get(i).copied().unwrap_or_else(SVector::zeros);
            stage.node = Some((SMatrix::identity() * h, node));
            stages.push(stage);
        }
        if slacks {
            for (k, c) in models.inequalities.iter().enumerate() {
                if self.interval_partner(barrier, k).is_none_or(|p| p > k) {
                    barrier.add_outer(&mut stages, k, c, h);
                }
            }
        }
        let mut terminal = models.terminal;
        terminal.hessian = SMatrix::identity() * h;
        let riccati = Riccati::factor_with(&self.dynamics, &stages, 0.0, &terminal, &mut *pool);
        let zero = SVector::zeros();
        let end = (&zero, &models.terminal_gradient);
        let direction = riccati
            .positive_definite()
            .then(|| riccati.solve(&self.dynamics, &stages, &zero, end, &mut *pool));
        riccati.recycle(&mut *pool);
        pool.stages.give(stages);
        pool.gradients.give(gradients);
        pool.jets.give(nodes);
        direction
    }
}
