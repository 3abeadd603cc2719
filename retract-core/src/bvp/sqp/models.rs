//! The models phase: the quadratic model of every stage at an iterate (the Hessian of the
//! Lagrangian with the constraints' curvature and the barrier's terms, the gradient, the
//! defect, the stage equalities), the cost and the terminal cost, and the inequalities
//! linearised where they are imposed.

use nalgebra::{SMatrix, SVector};

use super::state::{Models, Sqp};
use crate::bvp::barrier::Barrier;
use crate::bvp::constraints::{Linearized, flat_hessian};
use crate::bvp::iterate::{Iterate, blocks};
use crate::bvp::kkt::model::{StageModel, Terminal};
use crate::bvp::kkt::riccati::STEPS_PER_CLOCK_CHECK;
use crate::bvp::plan::Failure;
use crate::newton::all_finite;
use crate::{Lagrangian, LiftedSystem};

/// A stage's equality rows: $\partial g / \partial x_\theta$, $\partial g / \partial u$ and $g$.
type EqualityRows<const N: usize, const X: usize> =
    (SMatrix<f64, N, X>, SMatrix<f64, N, N>, SVector<f64, N>);

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The model of stage `i`: the Hessian of the Lagrangian $\sigma h L + y^T g^{=} - h y_g^T
    /// g^{\ge}$ ($\sigma$: [`Sqp::scale`]
    /// ($y_g$: the multipliers of $g - s = 0$, [`Barrier::y`]),
    /// the gradient of $h L$, the defect and the equalities with their Jacobians (the barrier's
    /// own terms are added by [`Barrier::add_to_stage`]), pushed onto `stages`; returned: $L$
    /// at the stage ([`Lagrangian::derivatives`]: one call for $L$, its gradient and its
    /// Hessian).
    #[inline(always)]
    pub(super) fn push_stage(
        &self,
        stages: &mut Vec<StageModel<N, X>>,
        (iterate, i): (&Iterate<N, X>, usize),
        y: &SVector<f64, N>,
        barrier: &Barrier,
    ) -> f64 {
        let (h, system) = (self.dynamics.h, self.problem.system_at(i));
        let u = &iterate.u[i];
        let xt = self.x_theta(iterate, i);
        let xb = blocks::<N, K, X>(&xt);
        let derivatives = system.derivatives(&xb, u);
        let (g, weight) = (&derivatives.gradient, h * self.scale);
        let (mut hxx, mut hux, mut huu) = flat_hessian::<N, K, X>(&derivatives.hessian, weight);
        let mut stage = StageModel {
            hxx,
            hux,
            huu,
            gx: SVector::from_fn(|r, _| weight * g.x[r / N][r % N]),
            gu: g.u * weight,
            defect: self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1],
            constraints: self.problem.equalities.len(),
            cx: SMatrix::zeros(),
            cu: SMatrix::zeros(),
            value: SVector::zeros(),
            node: None,
        };
        // (the rows of `equality_rows` and the curvature in one loop: the receding horizon's
        // re-plan measured 3 % faster than with a call to it)
        for (j, c) in self.problem.equalities.iter().enumerate() {
            let grad = c.gradient(&xb, u);
            stage.value[j] = c.value(&xb, u);
            for r in 0..X {
                stage.cx[(j, r)] = grad.x[r / N][r % N];
            }
            for a in 0..N {
                stage.cu[(j, a)] = grad.u[a];
            }
            if y[j] != 0.0 {
                let (cxx, cux, cuu) = flat_hessian::<N, K, X>(&c.hessian(&xb, u), y[j]);
                hxx += cxx;
                hux += cux;
                huu += cuu;
            }
        }
        for (j, c) in self.at_steps.iter().enumerate() {
            let y = barrier.y[i * barrier.count + j];
            if let Some((cxx, cux, cuu)) = c.weighted_hessian(&xt, u, -h * y) {
                hxx += cxx;
                hux += cux;
                huu += cuu;
            }
        }
        (stage.hxx, stage.hux, stage.huu) = (hxx, hux, huu);
        stages.push(stage);
        // (the node's terms set in place, and only where there are node inequalities: an
        // option of a few hundred bytes, it was copied twice even when `None`)
        if let Some(stage) = stages.last_mut().filter(|_| !self.at_nodes.is_empty()) {
            stage.node = self.node_curvature(iterate, i, barrier);
        }
        derivatives.value
    }

    /// The stage equalities' rows at the point `(xb, u)`: the Jacobians
    /// $\partial g / \partial x_\theta$, $\partial g / \partial u$ and the values $g$, in
    /// the first `equalities.len()` rows (the rest zero).
    pub(super) fn equality_rows(
        &self,
        xb: &[SVector<f64, N>; K],
        u: &SVector<f64, N>,
    ) -> EqualityRows<N, X> {
        let (mut cx, mut cu, mut value) = (SMatrix::zeros(), SMatrix::zeros(), SVector::zeros());
        for (j, c) in self.problem.equalities.iter().enumerate() {
            let grad = c.gradient(xb, u);
            value[j] = c.value(xb, u);
            for r in 0..X {
                cx[(j, r)] = grad.x[r / N][r % N];
            }
            for a in 0..N {
                cu[(j, a)] = grad.u[a];
            }
        }
        (cx, cu, value)
    }

    /// The curvature $-h y \nabla^2 g$ of the inequalities at node `i` (interior nodes
    /// only), as node terms with a zero gradient; `None` where there are none.
    pub(super) fn node_curvature(
        &self,
        iterate: &Iterate<N, X>,
        i: usize,
        barrier: &Barrier,
    ) -> Option<(SMatrix<f64, X, X>, SVector<f64, X>)> {
        if self.at_nodes.is_empty() || i == 0 || i >= iterate.u.len() {
            return None;
        }
        let (h, zero) = (self.dynamics.h, SVector::<f64, N>::zeros());
        let mut hessian = SMatrix::<f64, X, X>::zeros();
        for (j, c) in self.at_nodes.iter().enumerate() {
            let y = barrier.y[barrier.node_index(i, j)];
            if let Some((cxx, _, _)) = c.weighted_hessian(&iterate.x[i], &zero, -h * y) {
                hessian += cxx;
            }
        }
        Some((hessian, SVector::zeros()))
    }

    /// The values of every inequality at `iterate` into `values`, in the barrier's order:
    /// those at the steps (step-major), then those at the interior nodes (node-major).
    pub(super) fn inequality_values(&self, iterate: &Iterate<N, X>, values: &mut Vec<f64>) {
        values.clear();
        for (i, u) in iterate.u.iter().enumerate() {
            let xt = self.x_theta(iterate, i);
            values.extend(self.at_steps.iter().map(|c| c.value(&xt, u)));
        }
        self.node_values(iterate, values);
    }

    /// Appends the values of the node inequalities at the interior nodes (node-major).
    pub(super) fn node_values(&self, iterate: &Iterate<N, X>, values: &mut Vec<f64>) {
        let zero = SVector::<f64, N>::zeros();
        let steps = iterate.u.len();
        for x in iterate.x.iter().take(steps).skip(1) {
            values.extend(self.at_nodes.iter().map(|c| c.value(x, &zero)));
        }
    }

    /// The models of every stage with the constraint multipliers `y`; [`Failure::NonFinite`]
    /// if anything is not finite, [`Failure::TimeLimit`] if the budget runs out (the clock is
    /// read every [`STEPS_PER_CLOCK_CHECK`] steps).
    pub(super) fn models(
        &self,
        iterate: &Iterate<N, X>,
        y: &[SVector<f64, N>],
        barrier: &Barrier,
    ) -> Result<Models<N, X>, Failure> {
        let steps = iterate.u.len();
        let inequalities = self.inequalities(iterate);
        let (mut stages, mut cost_gradient) = {
            let mut pool = self.pool.borrow_mut();
            (pool.stages.take(steps), pool.gradients.take(steps))
        };
        let filled = self.fill_stages(
            (iterate, y, barrier),
            &inequalities,
            &mut stages,
            &mut cost_gradient,
        );
        let give_back = |stages, inequalities, cost_gradient, failure| {
            let mut pool = self.pool.borrow_mut();
            pool.stages.give(stages);
            pool.linearized.give(inequalities);
            pool.gradients.give(cost_gradient);
            Err(failure)
        };
        let cost = match filled {
            Ok(cost) => cost,
            Err(failure) => return give_back(stages, inequalities, cost_gradient, failure),
        };
        let r0 = (self.problem.start - iterate.x[0]).component_mul(&self.problem.fixed_start);
        let last = &iterate.x[iterate.x.len() - 1];
        let fixed = self.problem.fixed_end;
        let r_end = (self.problem.goal - last).component_mul(&fixed);
        let (log, slack_l1) =
            barrier.current_terms(&inequalities, self.dynamics.h, self.violation_weights);
        let slack_violation = (slack_l1, barrier.residual(&inequalities));
        let (phi, terminal_gradient, hessian) = self.terminal_model(last);
        let cost = cost + phi;
        let barrier_cost = cost + log;
        let finite =
            barrier_cost.is_finite() && all_finite(&terminal_gradient) && all_finite(&hessian);
        if !finite {
            return give_back(stages, inequalities, cost_gradient, Failure::NonFinite);
        }
        Ok(Models {
            stages,
            cost,
            barrier_cost,
            r0,
            r_end,
            inequalities,
            cost_gradient,
            slack_violation,
            terminal: Terminal {
                hessian,
                fixed,
                start_fixed: self.problem.fixed_start,
            },
            terminal_gradient,
        })
    }

    /// Builds the stage models of [`Self::models`] into `stages` (with the cost gradients
    /// into `cost_gradient`, before the barrier terms are added) and returns
    /// $J = \sum_i h L(x_{i+\theta}, u_i)$; [`Failure::NonFinite`] if a model is not finite,
    /// [`Failure::TimeLimit`] if the budget runs out.
    fn fill_stages(
        &self,
        (iterate, y, barrier): (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        inequalities: &[Linearized<N, X>],
        stages: &mut Vec<StageModel<N, X>>,
        cost_gradient: &mut Vec<(SVector<f64, X>, SVector<f64, N>)>,
    ) -> Result<f64, Failure> {
        let h = self.dynamics.h;
        let steps = iterate.u.len();
        let mut cost = 0.0;
        for i in 0..steps {
            if i % STEPS_PER_CLOCK_CHECK == STEPS_PER_CLOCK_CHECK - 1 && self.out_of_time() {
                return Err(Failure::TimeLimit);
            }
            let count = barrier.count;
            let own = &inequalities[i * count..(i + 1) * count];
            cost += h * self.scale * self.push_stage(stages, (iterate, i), &y[i], barrier);
            let stage = stages.last_mut().ok_or(Failure::NonFinite)?;
            cost_gradient.push((stage.gx, stage.gu));
            barrier.add_to_stage(stage, i, own, h);
            if stage.node.is_some() {
                let from = barrier.node_index(i, 0);
                barrier.add_to_node(stage, i, &inequalities[from..from + barrier.nodes], h);
            }
            if !stage.is_finite() {
                return Err(Failure::NonFinite);
            }
        }
        Ok(cost)
    }

    /// The gradients of the Lagrangian $h L - h z^T g^{\ge}$ at every step with the
    /// inequality multipliers `z` (a copy of the models' cost gradients from the pool, which
    /// the caller gives back); `None` without inequalities at the steps, where they are the
    /// cost gradients themselves.
    pub(super) fn lagrangian_gradients(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        z: &[f64],
    ) -> Option<Vec<(SVector<f64, X>, SVector<f64, N>)>> {
        (barrier.at_steps() > 0).then(|| {
            let mut g = self
                .pool
                .borrow_mut()
                .gradients
                .take(models.cost_gradient.len());
            g.extend_from_slice(&models.cost_gradient);
            barrier.lagrangian_gradients(&mut g, &models.inequalities, z, self.dynamics.h);
            g
        })
    }

    /// IPOPT's gradient-based scale of the cost at `iterate` (the first iterate of a solve,
    /// [`super::PlanOptions::scaling_max_gradient`] $= g_{\max}$): $\sigma = \max(10^{-8},
    /// \min(1, g_{\max} / |\nabla J|_\infty))$, the gradient of $J = \sum_i h L(x_{\theta,i},
    /// u_i) + \Phi(x_N)$ in every node (the ends included: $x_i$ gets $(1-\theta) h
    /// \nabla_x L_i + \theta h \nabla_x L_{i-1}$) and every top derivative ($h \nabla_u L_i$);
    /// 1 where it is not finite or $g_{\max} = \infty$.
    pub(in crate::bvp) fn objective_scale(&self, iterate: &Iterate<N, X>) -> f64 {
        let max_gradient = self.options.scaling_max_gradient;
        let steps = iterate.u.len();
        if max_gradient == f64::INFINITY || iterate.x.len() != steps + 1 {
            return 1.0;
        }
        let (h, theta) = (self.dynamics.h, self.dynamics.theta);
        let (mut largest, mut carried) = (0.0_f64, SVector::<f64, X>::zeros());
        for (i, u) in iterate.u.iter().enumerate() {
            let xb = blocks::<N, K, X>(&self.x_theta(iterate, i));
            let g = self.problem.system_at(i).gradient(&xb, u);
            let gx = SVector::<f64, X>::from_fn(|r, _| h * g.x[r / N][r % N]);
            let node = carried + gx * (1.0 - theta);
            largest = largest.max(node.amax()).max((g.u * h).amax());
            carried = gx * theta;
        }
        let terminal = self.problem.terminal_cost.map_or(SVector::zeros(), |phi| {
            let g = phi.gradient(&blocks::<N, K, X>(&iterate.x[steps]), &SVector::zeros());
            SVector::<f64, X>::from_fn(|r, _| g.x[r / N][r % N])
        });
        largest = largest.max((carried + terminal).amax());
        if !largest.is_finite() || largest <= max_gradient {
            return 1.0;
        }
        (max_gradient / largest).max(1e-8)
    }

    /// $\sigma \Phi(x_N)$ (0 without a terminal cost; $\sigma$: [`Sqp::scale`]).
    pub(super) fn terminal_value(&self, last: &SVector<f64, X>) -> f64 {
        self.problem.terminal_cost.map_or(0.0, |phi| {
            self.scale * phi.value(&blocks::<N, K, X>(last), &SVector::zeros())
        })
    }

    /// $\sigma \Phi(x_N)$, its gradient and its Hessian in $x_N$ (zeros without a terminal
    /// cost; $\sigma$: [`Sqp::scale`]).
    pub(super) fn terminal_model(
        &self,
        last: &SVector<f64, X>,
    ) -> (f64, SVector<f64, X>, SMatrix<f64, X, X>) {
        let Some(phi) = self.problem.terminal_cost else {
            return (0.0, SVector::zeros(), SMatrix::zeros());
        };
        let (x, u) = (blocks::<N, K, X>(last), SVector::<f64, N>::zeros());
        let (g, scale) = (phi.gradient(&x, &u), self.scale);
        let (hxx, _, _) = flat_hessian::<N, K, X>(&phi.hessian(&x, &u), scale);
        let gradient = SVector::from_fn(|r, _| scale * g.x[r / N][r % N]);
        (scale * phi.value(&x, &u), gradient, hxx)
    }

    /// Every inequality linearised where it is imposed, in the order of [`Barrier`]: those
    /// of the steps (step-major), then those of the interior nodes (node-major).
    pub(super) fn inequalities(&self, iterate: &Iterate<N, X>) -> Vec<Linearized<N, X>> {
        let steps = iterate.u.len();
        let count = steps * self.at_steps.len() + steps.saturating_sub(1) * self.at_nodes.len();
        let mut out = self.pool.borrow_mut().linearized.take(count);
        if !self.at_steps.is_empty() {
            for (i, u) in iterate.u.iter().enumerate() {
                let xt = self.x_theta(iterate, i);
                out.extend(self.at_steps.iter().map(|c| c.linearize(&xt, u)));
            }
        }
        let zero = SVector::<f64, N>::zeros();
        for x in iterate.x.iter().take(steps).skip(1) {
            out.extend(self.at_nodes.iter().map(|c| c.linearize(x, &zero)));
        }
        out
    }
}
