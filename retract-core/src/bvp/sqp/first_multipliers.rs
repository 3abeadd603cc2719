//! The first multipliers: IPOPT's least-squares estimate of the equality multipliers at the
//! first iterate (Wächter and Biegler 2006, §3.6), for the barrier error that decides whether
//! $\mu$ falls before the first step.

use nalgebra::{SMatrix, SVector};

use super::state::{Models, Sqp};
use crate::bvp::barrier::Barrier;
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
    /// The multipliers of every equality (the dynamics' costates and the stage equalities')
    /// that minimise the norm of the gradient of the Lagrangian at the models' iterate, with
    /// the inequality multipliers $z$ of `barrier` held: the solution of
    ///
    /// $$\begin{pmatrix} h I & C^T \\ C & 0 \end{pmatrix}
    ///   \begin{pmatrix} w \\ \lambda \end{pmatrix} =
    ///   -\begin{pmatrix} \nabla (J - h z^T g^{\ge}) \\ 0 \end{pmatrix}$$
    ///
    /// ($C$ the Jacobian of the dynamics, the stage equalities and the boundary data), by one
    /// Riccati solve with identity stage Hessians ($h I$ in $(x_\theta, u)$ and at every node)
    /// and zero constraint residuals. `None` if that factorisation is not positive definite
    /// (the equalities' Jacobian is rank-deficient), a multiplier is not finite or exceeds
    /// [`MAX_FIRST_MULTIPLIER`].
    pub(super) fn least_squares_multipliers(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
    ) -> Option<Direction<N, X>> {
        let direction = self.least_squares_direction(models, barrier)?;
        let largest = direction
            .multipliers
            .iter()
            .flat_map(|y| y.iter())
            .fold(0.0_f64, |m, y| {
                if y.is_finite() {
                    m.max(y.abs())
                } else {
                    f64::INFINITY
                }
            });
        if largest <= MAX_FIRST_MULTIPLIER {
            Some(direction)
        } else {
            direction.recycle(&mut *self.pool.borrow_mut());
            None
        }
    }

    /// The solution of [`Self::least_squares_multipliers`]' system, whatever the size of its
    /// multipliers; `None` if its factorisation is not positive definite.
    pub(super) fn least_squares_direction(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
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
            stage.hxx = SMatrix::identity() * h;
            stage.hux = SMatrix::zeros();
            stage.huu = SMatrix::identity() * h;
            (stage.gx, stage.gu) = (*gx, *gu);
            stage.defect = SVector::zeros();
            stage.value = SVector::zeros();
            let node = nodes.get(i).copied().unwrap_or_else(SVector::zeros);
            stage.node = Some((SMatrix::identity() * h, node));
            stages.push(stage);
        }
        let mut terminal = models.terminal;
        terminal.hessian = SMatrix::identity() * h;
        let riccati = Riccati::factor_with(&self.dynamics, &stages, 0.0, &terminal, &mut *pool);
        let zero = SVector::zeros();
        let end = (&zero, &models.terminal_gradient);
        let direction = riccati
            .positive_definite()
            .then(|| riccati.solve(&self.dynamics, &stages, 0.0, &zero, end, &mut *pool));
        riccati.recycle(&mut *pool);
        pool.stages.give(stages);
        pool.gradients.give(gradients);
        pool.jets.give(nodes);
        direction
    }
}
