//! The termination phase: the KKT residuals and the errors of the problem and of the barrier
//! problem (the convergence and acceptance tests of the loop compare them with the
//! tolerances), the end of the iteration at a converged point (the second-order check and
//! the plan), the certification of a point reached by a full step without a solve of its own,
//! and the naming of a failure at an infeasible point.

use nalgebra::SVector;

use super::state::{Models, Sqp, Subproblem};
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::{Iterate, blocks};
use crate::bvp::kkt::residuals::kkt_residuals;
use crate::bvp::kkt::riccati::Direction;
use crate::bvp::plan::duals::Duals;
use crate::bvp::plan::{Certificate, Failure, Plan};
use crate::{Lagrangian, LiftedSystem};

/// The smallest barrier parameter, for a KKT tolerance $\varepsilon$: $\varepsilon / 2$ (so
/// that $z s \approx \mu$ is below the tolerance). Lower, an active inequality's slack
/// $s = \mu / z$ falls toward the rounding of its constraint's value and the barrier Hessian
/// $h z / s$ toward $10^{12}$ of the rest: the subproblem's multipliers lose their digits and
/// the residuals stall.
pub(super) fn barrier_floor(tolerance: f64) -> f64 {
    tolerance / 2.0
}

/// The $\ell_1$ norm and the number of the components of the stage equalities' multipliers
/// `y` and of the `momenta`: their share of IPOPT's scale $s_d$ ([`Barrier::error_scales`]).
fn multiplier_sum<const N: usize, const X: usize>(
    y: &[SVector<f64, N>],
    momenta: &[SVector<f64, X>],
) -> (f64, usize) {
    let sum = y.iter().map(|y| y.lp_norm(1)).sum::<f64>()
        + momenta.iter().map(|p| p.lp_norm(1)).sum::<f64>();
    (sum, y.len() * N + momenta.len() * X)
}

/// How [`Sqp::finish`] ended: a certified plan, a failed second-order check, or not yet (a
/// constraint violated beyond the tolerance where it is imposed).
#[allow(clippy::large_enum_variant)] // (made once per solve, and moved at once)
pub(super) enum Finished<const N: usize, const X: usize> {
    Plan(Plan<N, X>),
    Failed(Failure, Certificate, Subproblem<N, X>),
    Not(Subproblem<N, X>),
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The certificate's residuals at the iterate of `models` with the multipliers of the
    /// subproblem solution `direction` ([`kkt_residuals`] with the gradients of $h L - h z^T
    /// g^{\ge}$, the constraint violation, $\max z g$), its negative directions those of
    /// `riccati`; the momenta; and the scale $\sigma$ of the relative stationarity (its
    /// absolute value, per unit time, is $\sigma$ times the relative one): $\sigma = \max(1,
    /// |\nabla L|_\infty, s_d)$, with IPOPT's $s_d$ ([`Barrier::error_scales`]) from the
    /// stage equalities' multipliers, the momenta and $z$.
    pub(super) fn residuals(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        negative_directions: usize,
        direction: &Direction<N, X>,
        z: &[f64],
    ) -> (Vec<SVector<f64, X>>, Certificate, f64) {
        self.residuals_with(models, barrier, negative_directions, (direction, None), z)
    }

    /// [`Self::residuals`] with the $x$-equations' multipliers `carried` in place of those
    /// formed from the direction's costates, where given ([`kkt_residuals`]).
    fn residuals_with(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        negative_directions: usize,
        (direction, carried): (&Direction<N, X>, Option<&[SVector<f64, X>]>),
        z: &[f64],
    ) -> (Vec<SVector<f64, X>>, Certificate, f64) {
        let h = self.dynamics.h;
        // the gradients of the Lagrangian: those of h L, less h z^T grad g with inequalities
        let with_inequalities = self.lagrangian_gradients(models, barrier, z);
        let mut pool = self.pool.borrow_mut();
        let gradients = with_inequalities.as_ref().unwrap_or(&models.cost_gradient);
        let end = (
            &models.terminal_gradient,
            &models.terminal.fixed,
            &models.terminal.start_fixed,
        );
        let mut nodes = pool.jets.take(barrier.steps + 1);
        barrier.node_gradients(&models.inequalities, z, h, &mut nodes);
        let momenta = pool.jets.take(models.stages.len() + 1);
        let stages = &models.stages;
        let (momenta, stationarity, scale) = kkt_residuals(
            &self.dynamics,
            stages,
            gradients,
            (direction, carried),
            &nodes,
            end,
            momenta,
        );
        if let Some(g) = with_inequalities {
            pool.gradients.give(g);
        }
        pool.jets.give(nodes);
        // IPOPT's s_d from these multipliers: the stationarity relative to the larger of the
        // gradient's size and the multipliers' (a residual of large multipliers' rounding
        // does not hold the test up)
        let (s_d, _) = barrier.error_scales(z, h, multiplier_sum(&direction.multipliers, &momenta));
        let (stationarity, scale) = (stationarity * scale / scale.max(s_d), scale.max(s_d));
        let complementarity = z
            .iter()
            .zip(&barrier.s)
            .fold(0.0_f64, |m, (z, s)| m.max(z * s));
        let certificate = Certificate {
            stationarity,
            feasibility: models.violation_max(),
            complementarity,
            negative_directions,
            min_reduced_hessian_eig: f64::NAN,
        };
        (momenta, certificate, scale)
    }

    /// The certificate at the iterate of `models` where no subproblem could be solved (the
    /// inertia-corrected factorisation failed): the residuals with the least-squares
    /// multipliers ([`Self::least_squares_direction`]: the stationarity is the smallest the
    /// equalities' multipliers allow there), or where those cannot be computed (a
    /// rank-deficient Jacobian of the equalities) a stationarity of $\infty$; never NaN.
    pub(super) fn failure_certificate(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
    ) -> Certificate {
        let Some(direction) = self.least_squares_direction(models, barrier, false) else {
            return Self::unsolved_certificate(models, barrier);
        };
        let (momenta, certificate, _) = self.residuals(models, barrier, 0, &direction, &barrier.z);
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(momenta);
        direction.recycle(&mut *pool);
        certificate
    }

    /// The certificate at the iterate of `models` without a stationarity (not computed:
    /// $\infty$): the feasibility of the models and the barrier's complementarity. For a
    /// budget that ran out in the factorisation, where the least-squares multipliers of
    /// [`Self::failure_certificate`] would cost another factorisation.
    pub(super) fn unsolved_certificate(models: &Models<N, X>, barrier: &Barrier) -> Certificate {
        let mut certificate = crate::bvp::plan::certificate::unknown_certificate();
        certificate.stationarity = f64::INFINITY;
        certificate.feasibility = models.violation_max();
        certificate.complementarity = barrier.complementarity().0;
        certificate
    }

    /// The cost and the certificate at an `iterate` whose models were not built (the
    /// wall-time budget ran out during the build), from one pass over the steps without
    /// derivatives: $J$; the feasibility, the max-norm of the dynamics defects, the stage
    /// equalities, the boundary data and the inequalities' $|g - s|$ (as
    /// [`Models::violation_max`]); the complementarity $\max z s$ of `barrier`. The
    /// stationarity needs the models and a factorisation: $\infty$ (not computed), never NaN.
    pub(super) fn interrupted_certificate(
        &self,
        iterate: &Iterate<N, X>,
        barrier: &Barrier,
    ) -> (f64, Certificate) {
        let h = self.dynamics.h;
        let (mut cost, mut violation) = (0.0, 0.0_f64);
        for (i, u) in iterate.u.iter().enumerate() {
            let xb = blocks::<N, K, X>(&self.x_theta(iterate, i));
            cost += h * self.scale * self.problem.system_at(i).lagrangian(&xb, u);
            let defect = self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1];
            violation = violation.max(defect.amax());
            for g in &self.problem.equalities {
                violation = violation.max(g.value(&xb, u).abs());
            }
        }
        let mut values = self.pool.borrow_mut().reals.take(barrier.s.len());
        self.inequality_values(iterate, &mut values);
        for (g, s) in values.iter().zip(&barrier.s) {
            violation = violation.max((g - s).abs());
        }
        self.pool.borrow_mut().reals.give(values);
        let last = &iterate.x[iterate.x.len() - 1];
        let ends = [
            (self.problem.start - iterate.x[0]).component_mul(&self.problem.fixed_start),
            (self.problem.goal - last).component_mul(&self.problem.fixed_end),
        ];
        let certificate = Certificate {
            stationarity: f64::INFINITY,
            feasibility: ends.iter().fold(violation, |m, r| m.max(r.amax())),
            complementarity: barrier.complementarity().0,
            negative_directions: 0,
            min_reduced_hessian_eig: f64::NAN,
        };
        (cost + self.terminal_value(last), certificate)
    }

    /// The error of the barrier problem (IPOPT's $E_\mu$ per unit time, [`Subproblem`]'s
    /// `barrier_error`), $\max(\text{stationarity}/s_d,\ \text{feasibility}/h,\
    /// \text{complementarity}/s_c)$: the feasibility (defects, equalities, ends, $|g - s|$) is
    /// in the transcribed problem's units, where $\mu$ is $h\mu$, so it is divided by $h$ and
    /// the test $E \le 10\mu$ is IPOPT's $E \le 10 h\mu$. At the models' iterate with the
    /// subproblem's solution `direction` (its $x$-equations' multipliers those `carried`,
    /// where given, [`Self::residuals_with`]; `momenta` enter the scale $s_d$ only):
    /// the smaller of its values with the predicted inequality multipliers `z` and with the
    /// current ones (the predicted ones are off by the whole dual step when the primal step
    /// is short). $\infty$ without inequalities or with $\mu$ at its floor (it only decides
    /// when $\mu$ decreases).
    pub(super) fn barrier_error(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        (direction, carried): (&Direction<N, X>, Option<&[SVector<f64, X>]>),
        (z, momenta): (&[f64], &[SVector<f64, X>]),
    ) -> f64 {
        if barrier.s.is_empty() || barrier.mu <= barrier_floor(self.options.tolerance) {
            return f64::INFINITY;
        }
        let h = self.dynamics.h;
        let (others, count) = multiplier_sum(&direction.multipliers, momenta);
        let compl = barrier.complementarity().1;
        let error = |z: &[f64]| {
            let with = (direction, carried);
            let (momenta, certificate, scale) = self.residuals_with(models, barrier, 0, with, z);
            self.pool.borrow_mut().jets.give(momenta);
            let (s_d, s_c) = barrier.error_scales(z, h, (others, count));
            (scale * certificate.stationarity / s_d)
                .max(certificate.feasibility / h)
                .max(compl / s_c)
        };
        error(z).min(error(&barrier.z))
    }

    /// The barrier problem's error at the iterate of `models` with the multipliers IPOPT
    /// carries (its $E_\mu$ at its current iterate, per unit time as
    /// [`Self::barrier_error`]): the stage equalities' `y` and the $x$-equations' `mu`, and
    /// in the gradient of the Lagrangian the inequalities' rows $g - s = 0$ with their own
    /// multipliers, the barrier's $y$ (IPOPT's $y_d$), not $z$; the slacks' stationarity
    /// $\sum_k \sigma_k (y_k - z_k)$ per IPOPT row (one side, or the two of an interval) joins
    /// the stationarity, both over $s_d$ from all these multipliers; then the feasibility
    /// over $h$ and $\max |z s - \mu|$ over $s_c$. $\infty$ without inequalities or with $\mu$
    /// at its floor.
    pub(super) fn error_at_multipliers(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        (y, mu): (&[SVector<f64, N>], &[SVector<f64, X>]),
    ) -> f64 {
        if barrier.s.is_empty() || barrier.mu <= barrier_floor(self.options.tolerance) {
            return f64::INFINITY;
        }
        let h = self.dynamics.h;
        let carried = {
            let mut pool = self.pool.borrow_mut();
            let mut m = pool.tops.take(y.len());
            m.extend_from_slice(y);
            let (dx, du, costate) = (pool.jets.take(0), pool.tops.take(0), pool.jets.take(0));
            Direction {
                dx,
                du,
                costate,
                multipliers: m,
            }
        };
        let with = (&carried, Some(mu));
        let (momenta, certificate, scale) =
            self.residuals_with(models, barrier, 0, with, &barrier.y);
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(momenta);
        carried.recycle(&mut *pool);
        drop(pool);
        let slack = |k: usize| barrier.y[k] - barrier.z[k];
        let slack_rows = (0..barrier.s.len()).fold(0.0_f64, |m, k| {
            let row = match self.interval_partner(barrier, k) {
                Some(p) => slack(k) - slack(p),
                None => slack(k),
            };
            m.max(row.abs())
        });
        let others = y.iter().map(|y| y.lp_norm(1)).sum::<f64>()
            + mu.iter().map(|p| p.lp_norm(1)).sum::<f64>()
            + barrier.y.iter().map(|y| (h * y).abs()).sum::<f64>();
        let count = y.len() * N + mu.len() * X + barrier.y.len();
        let (s_d, s_c) = barrier.error_scales(&barrier.z, h, (others, count));
        ((scale * certificate.stationarity).max(slack_rows) / s_d)
            .max(certificate.feasibility / h)
            .max(barrier.complementarity().1 / s_c)
    }

    /// The goal's component whose miss the subproblem cannot reduce, and that miss: where the
    /// terminal pivot needed the $\delta_c$ shift (the goal and the stage equalities are
    /// dependent) and the step's linearised miss $|r_N - \delta x_N|$ of a fixed component
    /// is above [`crate::bvp::PlanOptions::acceptable`] and at least half of its miss $|r_N|$
    /// now, and that miss is itself above the acceptable level (to first order no step
    /// reaches it: a point of local infeasibility of the goal; a goal already met, whose
    /// subproblem only cannot hold it, is not named).
    pub(super) fn unreachable_goal(
        &self,
        models: &Models<N, X>,
        sub: &Subproblem<N, X>,
    ) -> Option<(usize, f64)> {
        if !sub.riccati.regularized {
            return None;
        }
        let last = sub.direction.dx.last()?;
        let predicted = (models.r_end - last).component_mul(&self.problem.fixed_end);
        let component = predicted.iamax();
        let (after, now) = (predicted[component].abs(), models.r_end[component].abs());
        let acceptable = self.options.acceptable;
        (now > acceptable && after > acceptable && after >= 0.5 * now).then_some((component, now))
    }

    /// The end of the iteration at a point whose residuals are below the tolerance (or at the
    /// acceptable level) with the barrier at its floor: the second-order check
    /// ([`Self::certify`]) and the plan, unless a constraint is violated beyond the tolerance
    /// where it is imposed (then the iteration goes on with the subproblem `sub`).
    pub(super) fn finish(
        &self,
        point: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
        mut sub: Subproblem<N, X>,
        iterations: usize,
    ) -> Finished<N, X> {
        let factored = (sub.rho == 0.0 && !sub.stale).then_some(&sub.riccati);
        match self.certify(point, models, factored, sub.certificate) {
            Ok(certificate) => {
                let momenta = core::mem::take(&mut sub.momenta);
                let mut plan = self.plan(point, models.cost, iterations, momenta, certificate);
                if plan.violations.imposed() <= self.options.tolerance {
                    self.give_subproblem(sub);
                    return Finished::Plan(plan);
                }
                sub.momenta = core::mem::take(&mut plan.momenta);
                self.give_plan(plan);
                Finished::Not(sub)
            }
            Err((failure, certificate)) => Finished::Failed(failure, certificate, sub),
        }
    }

    /// The plan at the point reached by a full step, certified with the last subproblem's
    /// multipliers (the Newton estimates here) instead of a solve of its own: if the residuals
    /// are below the tolerance with the barrier at its floor and the second-order check
    /// ([`Self::certify`]) passes; `None` (solve as usual) otherwise.
    pub(super) fn certify_without_solve(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        last: &Direction<N, X>,
        iterations: usize,
    ) -> Option<Plan<N, X>> {
        let (iterate, y, barrier) = state;
        let options = &self.options;
        if barrier.mu > barrier_floor(options.tolerance) {
            return None;
        }
        let models = self.models(iterate, y, barrier).ok()?;
        let (momenta, certificate, _) = self.residuals(&models, barrier, 0, last, &barrier.z);
        let certified = (certificate.stationarity.max(certificate.feasibility)
            <= options.tolerance)
            .then(|| self.certify(state, &models, None, certificate).ok())
            .flatten();
        let cost = models.cost;
        self.give_models(models);
        let Some(certificate) = certified else {
            self.pool.borrow_mut().jets.give(momenta);
            return None;
        };
        let plan = self.plan(state, cost, iterations, momenta, certificate);
        if plan.violations.imposed() <= options.tolerance {
            return Some(plan);
        }
        self.give_plan(plan);
        None
    }

    /// A failure at `iterate` (with its `models`) named for what stopped it: a line search
    /// that finds no step where the subproblem cannot reach the goal (`goal`: the component
    /// and its miss, [`Self::unreachable_goal`]) as [`Failure::UnreachableGoal`] (the goal
    /// stops it, not the merit function: a sideways guess for a car that cannot slip); a
    /// failure of the inertia correction or the line search at an iterate that violates a
    /// constraint beyond the tolerance as [`Failure::StalledInfeasible`] naming the
    /// constraint violated most, where, and by how much: an inequality or stage equality
    /// ([`violations`](crate::bvp::problem::OptimalControlProblem::violations)), the scheme's equations of a step or a fixed end
    /// ([`Models::worst_defect`]), whichever is larger; any other failure as it is.
    pub(super) fn name_infeasibility(
        &self,
        failure: Failure,
        (iterate, models): (&Iterate<N, X>, &Models<N, X>),
        goal: Option<(usize, f64)>,
    ) -> Failure {
        if let (Failure::LineSearch, Some((component, miss))) = (&failure, goal) {
            return Failure::UnreachableGoal { component, miss };
        }
        if !matches!(failure, Failure::Regularization | Failure::LineSearch) {
            return failure;
        }
        let (violations, constraint) = self.problem.violations(iterate, self.dynamics.theta);
        // (a NaN violation of a constraint is named before any finite defect)
        let worst = if violations.imposed().is_nan() {
            constraint
        } else {
            [constraint, models.worst_defect()]
                .into_iter()
                .flatten()
                .max_by(|a, b| a.violation.total_cmp(&b.violation))
        };
        match worst {
            Some(worst) if worst.violation.is_nan() || worst.violation > self.options.tolerance => {
                Failure::StalledInfeasible(worst)
            }
            _ => failure,
        }
    }

    /// The plan at the point `state` (iterate, stage-equality multipliers, barrier), with the
    /// iteration's cost, momenta, multipliers, barrier parameter and smallest eigenvalue
    /// (those of $\sigma J$) divided by $\sigma$ = [`Self::scale`].
    pub(super) fn plan(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        cost: f64,
        iterations: usize,
        mut momenta: Vec<SVector<f64, X>>,
        mut certificate: Certificate,
    ) -> Plan<N, X> {
        let (iterate, y, barrier) = state;
        let (h, theta) = (self.dynamics.h, self.dynamics.theta);
        let (step_slacks, node_slacks) = barrier.s.split_at(barrier.at_steps());
        let (step_multipliers, node_multipliers) = barrier.z.split_at(barrier.at_steps());
        let mut pool = self.pool.borrow_mut();
        let mut copy = |v: &[f64]| {
            let mut out = pool.reals.take(v.len());
            out.extend_from_slice(v);
            out
        };
        let (step_slacks, mut step_multipliers) = (copy(step_slacks), copy(step_multipliers));
        let (node_slacks, mut node_multipliers) = (copy(node_slacks), copy(node_multipliers));
        let (mut equalities, mut x, mut u) = (
            pool.tops.take(y.len()),
            pool.jets.take(iterate.x.len()),
            pool.tops.take(iterate.u.len()),
        );
        drop(pool);
        x.extend_from_slice(&iterate.x);
        u.extend_from_slice(&iterate.u);
        // (the iteration's multipliers, momenta, barrier parameter and curvature are those of
        // the scaled cost: reported unscaled)
        let unscale = 1.0 / self.scale;
        equalities.extend(y.iter().map(|y| y * unscale));
        momenta.iter_mut().for_each(|p| *p *= unscale);
        for z in step_multipliers
            .iter_mut()
            .chain(node_multipliers.iter_mut())
        {
            *z *= unscale;
        }
        certificate.min_reduced_hessian_eig *= unscale;
        let duals = Duals {
            equalities,
            step_slacks,
            step_multipliers,
            node_slacks,
            node_multipliers,
            barrier: barrier.mu * unscale,
        };
        Plan {
            h,
            theta,
            x,
            u,
            momenta,
            cost: cost * unscale,
            iterations,
            certificate,
            violations: self.problem.violations(iterate, theta).0,
            duals,
        }
    }
}
