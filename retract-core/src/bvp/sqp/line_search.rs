//! The line search of the SQP iteration: IPOPT's filter (Wächter and Biegler, Math. Program.
//! 106, 2006) on the pair (constraint violation $\theta = \Vert c\Vert_1$, barrier cost $\varphi = J -
//! h \mu \sum \ln s$), and where the filter finds no step, backtracking on the exact penalty
//! $\varphi + \pi \theta$.
//!
//! A trial point $\alpha$ along the direction is acceptable to the filter if no stored pair
//! dominates it and, either (if $\theta \le \theta_{\min}$ and the switching condition
//! $\alpha (-\nabla\varphi^T d)^{s_\varphi} > \delta \theta^{s_\theta}$ holds) it satisfies
//! Armijo's condition on $\varphi$, or it reduces $\theta$ by a factor $1 - \gamma_\theta$ or
//! $\varphi$ by $\gamma_\varphi \theta$; in the second case the filter is augmented by
//! $((1 - \gamma_\theta) \theta, \varphi - \gamma_\varphi \theta)$. The filter is emptied when
//! $\mu$ decreases. Where neither search makes progress, the feasibility restoration phase
//! ([`super::restoration`]) looks for a point the filter accepts.

use nalgebra::SVector;

use super::correction::Corrected;
use super::filter::Filter;
use super::restoration::Restoration;
use super::state::{Models, Sqp};
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::{Iterate, blocks};
use crate::bvp::kkt::riccati::{Direction, Riccati};
use crate::bvp::plan::Failure;
use crate::{Lagrangian, LiftedSystem};

/// IPOPT's constants: $\gamma_\theta$, $\gamma_\varphi$, the switching exponents $s_\theta$,
/// $s_\varphi$ and factor $\delta$, and $\gamma_\alpha$ of the smallest step length.
const GAMMA_THETA: f64 = 1e-5;
const GAMMA_PHI: f64 = 1e-8;
const S_THETA: f64 = 1.1;
const S_PHI: f64 = 2.3;
const DELTA: f64 = 1.0;
const GAMMA_ALPHA: f64 = 0.05;
/// The feasibility restoration phase starts after this many successive steps shorter than
/// $\gamma_\alpha \gamma_\theta$ (or where no step is found at all): an isolated short step
/// is often followed by full ones.
const TINY_STEPS: usize = 5;

/// IPOPT's `max_soft_resto_iters`: the soft restoration steps in a row.
const MAX_SOFT_STEPS: usize = 10;

/// IPOPT's `soft_resto_pderror_reduction_factor`.
const SOFT_REDUCTION: f64 = 0.9999;

/// What the line search carries from one iteration to the next besides the filter and the
/// penalty: the successive steps shorter than $\gamma_\alpha \gamma_\theta$ (the trigger of
/// restoration) and the Newton steps restoration phases took since the loop last read them
/// ([`Progress::take_steps`]: they count as iterations, whatever the phase's outcome).
#[derive(Default)]
pub(super) struct Progress {
    tiny: usize,
    restoration_steps: usize,
    /// IPOPT's soft restoration: the soft steps taken in a row (0: not in that mode).
    soft: usize,
}

impl Progress {
    /// The restoration phases' Newton steps since the last call.
    pub fn take_steps(&mut self) -> usize {
        core::mem::take(&mut self.restoration_steps)
    }
}

/// An accepted trial point: the iterate, the step length, whether the decrease it was
/// accepted on is at rounding level, the corrected step it was taken along, if a
/// second-order correction was accepted, and, if the point comes from the feasibility
/// restoration phase, its slacks.
pub(super) struct Accepted<const N: usize, const X: usize> {
    pub trial: Iterate<N, X>,
    pub alpha: f64,
    pub at_rounding: bool,
    pub corrected: Option<Corrected<N, X>>,
    pub restored: Option<Vec<f64>>,
    /// The dual step length where it is the primal one (a soft restoration step).
    pub dual_alpha: Option<f64>,
}

/// The subproblem a line search searches along: the iterate, its models, the direction and,
/// unless it is a kept one, the factorisation with its inertia correction $h \rho$ (for
/// second-order corrections).
pub(super) type Searched<'s, const N: usize, const X: usize> = (
    &'s Iterate<N, X>,
    &'s Models<N, X>,
    &'s Direction<N, X>,
    Option<(&'s Riccati<N, X>, f64)>,
);

/// The $x$-equations' multipliers carried from iterate to iterate and the subproblem's own
/// ([`State::mu`](super::state::State::mu), [`step_multipliers`](crate::bvp::kkt::residuals::step_multipliers)).
pub(super) type Carried<'s, const X: usize> = (&'s [SVector<f64, X>], &'s [SVector<f64, X>]);

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The barrier cost $J - h \mu \sum \ln s$ and $\Vert c\Vert_1$ (with $\sum |g - s|$) at a
    /// trial point whose slacks are $s + \alpha\thinspace\delta s$; `None` if not finite.
    /// The inequalities' values there are kept with $\alpha$ in the pool's `trial_values`
    /// (for [`Self::advance`]).
    pub(super) fn merit_parts(
        &self,
        iterate: &Iterate<N, X>,
        barrier: &Barrier,
        ds: &[f64],
        alpha: f64,
    ) -> Option<(f64, f64)> {
        let h = self.dynamics.h;
        let (mut cost, mut violation) = (0.0, 0.0);
        let (mut values, _) = core::mem::take(&mut self.pool.borrow_mut().trial_values);
        values.clear();
        for (i, u) in iterate.u.iter().enumerate() {
            let system = self.problem.system_at(i);
            let xt = self.x_theta(iterate, i);
            let xb = blocks::<N, K, X>(&xt);
            cost += h * self.scale * system.lagrangian(&xb, u);
            violation += (self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1]).lp_norm(1);
            for g in &self.problem.equalities {
                violation += g.value(&xb, u).abs();
            }
            values.extend(self.at_steps.iter().map(|c| c.value(&xt, u)));
        }
        self.node_values(iterate, &mut values);
        let (log, slack) = barrier.trial_terms(&values, (ds, alpha), h, self.violation_weights);
        self.pool.borrow_mut().trial_values = (values, alpha);
        let last = &iterate.x[iterate.x.len() - 1];
        violation += slack
            + (self.problem.start - iterate.x[0])
                .component_mul(&self.problem.fixed_start)
                .lp_norm(1)
            + (self.problem.goal - last)
                .component_mul(&self.problem.fixed_end)
                .lp_norm(1);
        let cost = cost + log + self.terminal_value(last);
        (cost.is_finite() && violation.is_finite()).then_some((cost, violation))
    }

    /// $\sum_i \delta y_i^T H_i \delta y_i$ over the stages' models (with their node terms)
    /// along the direction, $\delta y_i = (\delta x_{\theta,i}, \delta u_i)$.
    fn curvature(&self, models: &Models<N, X>, direction: &Direction<N, X>) -> f64 {
        let theta = self.dynamics.theta;
        let mut sum = 0.0;
        for (i, stage) in models.stages.iter().enumerate() {
            let dx = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
            let du = &direction.du[i];
            sum += dx.dot(&(stage.hxx * dx))
                + 2.0 * du.dot(&(stage.hux * dx))
                + du.dot(&(stage.huu * du));
            if let Some(node) = &stage.node {
                sum += direction.dx[i].dot(&(node.0 * direction.dx[i]));
            }
        }
        if let Some(last) = direction.dx.last() {
            sum += last.dot(&(models.terminal.hessian * last));
        }
        sum
    }

    /// $\nabla\varphi^T d$: the derivative of the barrier cost $J - h \mu \sum \ln s$
    /// (stages, terminal cost, slacks) along the direction.
    fn slope(
        &self,
        models: &Models<N, X>,
        direction: &Direction<N, X>,
        barrier: &Barrier,
        ds: &[f64],
    ) -> f64 {
        let theta = self.dynamics.theta;
        let mut slope = barrier.slope(ds, self.dynamics.h);
        for (i, (gx, gu)) in models.cost_gradient.iter().enumerate() {
            let dxt = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
            slope += gx.dot(&dxt) + gu.dot(&direction.du[i]);
        }
        if let Some(dx_end) = direction.dx.last() {
            slope += models.terminal_gradient.dot(dx_end);
        }
        slope
    }

    /// The point $\alpha$ along the direction and its $(\varphi, \theta)$
    /// ([`Self::merit_parts`]); `None` for these if the point leaves the system's domain or a
    /// value is not finite.
    pub(super) fn trial(
        &self,
        iterate: &Iterate<N, X>,
        direction: &Direction<N, X>,
        (barrier, ds): (&Barrier, &[f64]),
        alpha: f64,
    ) -> (Iterate<N, X>, Option<(f64, f64)>) {
        let mut trial = self.take_iterate(iterate.u.len());
        (trial.x).extend(
            iterate
                .x
                .iter()
                .zip(&direction.dx)
                .map(|(x, d)| x + d * alpha),
        );
        (trial.u).extend(
            iterate
                .u
                .iter()
                .zip(&direction.du)
                .map(|(u, d)| u + d * alpha),
        );
        let parts = self
            .problem
            .guard::<S, M>(&trial)
            .ok()
            .and_then(|()| self.merit_parts(&trial, barrier, ds, alpha));
        (trial, parts)
    }

    /// Moves to the `accepted` point along `direction` with slack steps `ds` (or along its
    /// corrected step; or, for a point of the restoration phase, to it with its slacks, the
    /// multipliers restarted by [`Barrier::restart`] and the stage equalities' kept): the
    /// iterate; the slacks and the multipliers $z$ by its step length
    /// (then the slacks far below their inequality's value reset, [`Barrier::reset_slacks`],
    /// from the values the trial's merit evaluation kept);
    /// the stage equalities' multipliers `y` toward the direction's by the same primal step
    /// length. Returns the step length, whether the decrease was at rounding level and
    /// whether the step was the direction itself (not a correction).
    pub(super) fn advance(
        &self,
        mut accepted: Accepted<N, X>,
        (direction, ds, rho): (&Direction<N, X>, &[f64], f64),
        (iterate, barrier, y): (&mut Iterate<N, X>, &mut Barrier, &mut [SVector<f64, N>]),
    ) -> (f64, bool, bool) {
        if let Some(slacks) = accepted.restored.take() {
            let left = core::mem::replace(iterate, accepted.trial);
            self.give_iterate(left);
            barrier.restart(&slacks, self.dynamics.h);
            self.pool.borrow_mut().reals.give(slacks);
            return (1.0, false, false);
        }
        let alpha = accepted.alpha;
        let corrected = accepted.corrected.take();
        let (direction, ds) = match &corrected {
            Some(c) => (&c.direction, &c.ds[..]),
            None => (direction, ds),
        };
        let left = core::mem::replace(iterate, accepted.trial);
        self.give_iterate(left);
        let dual = accepted
            .dual_alpha
            .unwrap_or_else(|| barrier.dual_step_length(ds));
        barrier.update(ds, (alpha, dual), (rho, self.violation_weights));
        if !barrier.s.is_empty() {
            // the accepted point is the last trial evaluated: its values are kept
            let (mut values, at) = core::mem::take(&mut self.pool.borrow_mut().trial_values);
            if at != alpha || values.len() != barrier.s.len() {
                self.inequality_values(iterate, &mut values);
            }
            barrier.reset_slacks(&values);
            self.pool.borrow_mut().trial_values = (values, at);
        }
        for (yi, target) in y.iter_mut().zip(&direction.multipliers) {
            *yi += (target - *yi) * alpha;
        }
        let plain = corrected.is_none();
        if let Some(c) = corrected {
            self.give_corrected(c);
        }
        (alpha, accepted.at_rounding, plain)
    }

    /// The line search: [`Self::filter_search`] with `filter` (made at the first call from
    /// the violation there); where it finds no step, [`Self::penalty_search`] with `penalty`;
    /// where that fails too, or its step is below $\gamma_\alpha \gamma_\theta$ (the largest
    /// $\alpha_{\min}$ of the filter: a step that makes no progress) for the [`TINY_STEPS`]th
    /// time in a row or later (`progress` counts them), the feasibility restoration phase
    /// ([`Self::restore`]), unless it is off ([`crate::bvp::PlanOptions::restoration`]), the
    /// iteration is a real-time one, the direction is a kept factorisation's, or the iterate
    /// is feasible to the tolerance (no elastic point can then reduce its violation): its point
    /// if it returns to one the filter accepts, [`Failure::LineSearch`] if it ends at a point
    /// of local infeasibility, [`Failure::TimeLimit`] if the budget ran out in it, and
    /// otherwise the penalty search's result. Where the $x$-equations' multipliers are
    /// `carried` (with the subproblem's own, [`Carried`]) and the restoration phase could run,
    /// IPOPT's soft restoration step ([`Self::soft_step`]) comes first while its mode lasts
    /// and after a filter search that finds no step.
    pub(super) fn line_search(
        &self,
        searched: Searched<'_, N, X>,
        slacks: (&Barrier, &[f64]),
        (filter, penalty, progress): (&mut Option<Filter>, &mut f64, &mut Progress),
        carried: (&[SVector<f64, N>], Option<Carried<'_, X>>),
    ) -> Result<Accepted<N, X>, Failure> {
        let (iterate, models, direction, factor) = searched;
        let filter = filter.get_or_insert_with(|| {
            Filter::new(models.violation_l1(), self.pool.borrow_mut().pairs.take(16))
        });
        let soft_on = self.options.restoration
            && !self.real_time
            && factor.is_some()
            && !slacks.0.s.is_empty();
        let mu = carried.1.filter(|_| soft_on);
        if let Some(mu) = mu
            && (1..=MAX_SOFT_STEPS).contains(&progress.soft)
        {
            match self.soft_step(searched, slacks, filter, (carried.0, mu)) {
                Some((accepted, satisfied)) => {
                    progress.soft = if satisfied { 0 } else { progress.soft + 1 };
                    progress.tiny = 0;
                    return Ok(accepted);
                }
                None => progress.soft = 0,
            }
        }
        if let Some(accepted) = self.filter_search(searched, slacks, filter)? {
            progress.tiny = 0;
            progress.soft = 0;
            return Ok(accepted);
        }
        if let Some(mu) = mu
            && progress.soft == 0
            && let Some((accepted, satisfied)) =
                self.soft_step(searched, slacks, filter, (carried.0, mu))
        {
            progress.soft = if satisfied { 0 } else { 1 };
            progress.tiny = 0;
            return Ok(accepted);
        }
        let fallback = self.penalty_search(iterate, models, direction, slacks, penalty);
        let too_early = match &fallback {
            Ok(accepted) if accepted.alpha >= GAMMA_ALPHA * GAMMA_THETA => {
                progress.tiny = 0;
                return fallback;
            }
            Ok(_) => {
                progress.tiny += 1;
                progress.tiny < TINY_STEPS
            }
            Err(Failure::TimeLimit) => return fallback,
            Err(_) => false,
        };
        let skipped = too_early
            || !self.options.restoration
            || self.real_time
            // (a simplified direction, of a factorisation kept from an earlier iterate, is
            // retried with the iterate's own first: see the loop)
            || factor.is_none()
            || models.violation_max() <= self.options.tolerance;
        if skipped {
            return fallback;
        }
        progress.tiny = 0;
        let restored = self.restore((iterate, models), slacks.0, filter);
        progress.restoration_steps += restored.1;
        let give = |fallback: Result<Accepted<N, X>, Failure>| {
            if let Ok(accepted) = fallback {
                self.give_iterate(accepted.trial);
            }
        };
        match restored.0 {
            Restoration::Restored(trial, s) => {
                give(fallback);
                Ok(Accepted {
                    trial,
                    alpha: 1.0,
                    at_rounding: false,
                    corrected: None,
                    restored: Some(s),
                    dual_alpha: None,
                })
            }
            _ if self.out_of_time() => {
                give(fallback);
                Err(Failure::TimeLimit)
            }
            Restoration::Infeasible => {
                give(fallback);
                Err(Failure::LineSearch)
            }
            Restoration::Unfinished => fallback,
        }
    }

    /// The filter line search from the fraction-to-the-boundary step, halving: the accepted
    /// point, or `None` once the step length falls below IPOPT's $\alpha_{\min} =
    /// \gamma_\alpha \min(\gamma_\theta, \gamma_\varphi \theta / (-\nabla\varphi^T d), \delta
    /// \theta^{s_\theta} / (-\nabla\varphi^T d)^{s_\varphi})$ (or after
    /// [`crate::bvp::PlanOptions::max_backtracks`] halvings); [`Failure::TimeLimit`] if the
    /// budget runs out between trials. Where the first trial is rejected and does not reduce
    /// $\theta$, second-order corrections are tried before halving
    /// ([`Self::second_order_correction`], with the subproblem's factorisation), if the
    /// problem has nonlinear constraints (stage equalities or inequalities: the dynamics and
    /// the boundary data are linear, and a correction would repeat the step).
    fn filter_search(
        &self,
        (iterate, models, direction, factor): Searched<'_, N, X>,
        (barrier, ds): (&Barrier, &[f64]),
        filter: &mut Filter,
    ) -> Result<Option<Accepted<N, X>>, Failure> {
        let options = &self.options;
        let slope = self.slope(models, direction, barrier, ds);
        let (theta, phi) = (models.violation_l1(), models.barrier_cost);
        if !slope.is_finite() {
            return Ok(None);
        }
        // rounding of phi and of the defects (about eps |x| each)
        let size: f64 = iterate.x.iter().map(|x| x.lp_norm(1)).sum();
        let noise = 1e-14 * phi.abs().max(1.0);
        let at_rounding = -slope <= noise && theta <= 1e-13 * size.max(1.0);
        let alpha_min = if slope < 0.0 {
            GAMMA_ALPHA
                * GAMMA_THETA
                    .min(GAMMA_PHI * theta / -slope)
                    .min(DELTA * theta.powf(S_THETA) / (-slope).powf(S_PHI))
        } else {
            GAMMA_ALPHA * GAMMA_THETA
        };
        let current = (theta, phi, slope, noise);
        let mut alpha = barrier.max_step(ds);
        for l in 0..=options.max_backtracks {
            if alpha < alpha_min && !at_rounding {
                break;
            }
            if self.out_of_time() {
                return Err(Failure::TimeLimit);
            }
            let (trial, parts) = self.trial(iterate, direction, (barrier, ds), alpha);
            let mut accepts = |t: f64, p: f64| self.filter_accepts(filter, current, (t, p), alpha);
            if parts.is_some_and(|(phi_t, theta_t)| accepts(theta_t, phi_t)) {
                return Ok(Some(Accepted {
                    trial,
                    alpha,
                    at_rounding,
                    corrected: None,
                    restored: None,
                    dual_alpha: None,
                }));
            }
            if let (0, Some((_, theta_t)), Some(factor)) = (l, parts, factor)
                && theta_t >= theta
                && theta > options.tolerance
                && options.second_order_corrections > 0
                && (!self.problem.equalities.is_empty() || !barrier.s.is_empty())
            {
                let at = (iterate, models);
                let first = (barrier, ds, alpha);
                let soc = self.second_order_correction(at, factor, first, &trial, &mut accepts);
                if let Some((corrected_trial, alpha_soc, step)) = soc {
                    self.give_iterate(trial);
                    return Ok(Some(Accepted {
                        trial: corrected_trial,
                        alpha: alpha_soc,
                        at_rounding,
                        corrected: Some(step),
                        restored: None,
                        dual_alpha: None,
                    }));
                }
            }
            self.give_iterate(trial);
            alpha *= 0.5;
        }
        Ok(None)
    }

    /// IPOPT's soft restoration step (its `TrySoftRestoStep`): the primal and dual step
    /// of the same length $\alpha = \min(\alpha_{\max}, \alpha^z_{\max})$ (the fractions to
    /// the boundary), accepted if the filter accepts it (`true`: the soft mode ends) or if it
    /// lowers the barrier problem's error at the carried multipliers (the stage
    /// equalities', the $x$-equations' and $z$, each a fraction $\alpha$ of the way to the
    /// subproblem's) by the factor [`SOFT_REDUCTION`] (`false`: the mode goes on).
    fn soft_step(
        &self,
        (iterate, models, direction, _): Searched<'_, N, X>,
        (barrier, ds): (&Barrier, &[f64]),
        filter: &mut Filter,
        (y, mu): (&[SVector<f64, N>], Carried<'_, X>),
    ) -> Option<(Accepted<N, X>, bool)> {
        let alpha = barrier.max_step(ds).min(barrier.dual_step_length(ds));
        let (trial, parts) = self.trial(iterate, direction, (barrier, ds), alpha);
        let accepted = |trial| Accepted {
            trial,
            alpha,
            at_rounding: false,
            corrected: None,
            restored: None,
            dual_alpha: Some(alpha),
        };
        let (theta, phi) = (models.violation_l1(), models.barrier_cost);
        let slope = self.slope(models, direction, barrier, ds);
        let current = (theta, phi, slope, 1e-14 * phi.abs().max(1.0));
        if slope.is_finite()
            && let Some((phi_t, theta_t)) = parts
            && self.filter_accepts(filter, current, (theta_t, phi_t), alpha)
        {
            return Some((accepted(trial), true));
        }
        let now = self.error_at_multipliers(models, barrier, (y, mu.0));
        let then = self.soft_trial_error(&trial, (barrier, ds), direction, (y, mu), alpha);
        if then <= SOFT_REDUCTION * now {
            Some((accepted(trial), false))
        } else {
            self.give_iterate(trial);
            None
        }
    }

    /// The barrier problem's error at the soft restoration step's `trial` point: with the
    /// slacks and $z$ moved by `alpha` along `ds`, and the stage equalities' multipliers and
    /// the $x$-equations' `carried` a fraction `alpha` of the way to the `direction`'s.
    fn soft_trial_error(
        &self,
        trial: &Iterate<N, X>,
        (barrier, ds): (&Barrier, &[f64]),
        direction: &Direction<N, X>,
        (y, (mu, target)): (&[SVector<f64, N>], Carried<'_, X>),
        alpha: f64,
    ) -> f64 {
        let (mut moved, mut y_t, mut c_t) = {
            let mut pool = self.pool.borrow_mut();
            let vectors = [(); 3].map(|_| pool.reals.take(barrier.s.len()));
            let moved = barrier.copy_into(vectors);
            (moved, pool.tops.take(y.len()), pool.jets.take(mu.len()))
        };
        moved.update(ds, (alpha, alpha), (0.0, self.violation_weights));
        y_t.extend(
            y.iter()
                .zip(&direction.multipliers)
                .map(|(a, b)| a + (b - a) * alpha),
        );
        c_t.extend(mu.iter().zip(target).map(|(a, b)| a + (b - a) * alpha));
        let error = match self.models(trial, &y_t, &moved) {
            Ok(models) => {
                let error = self.error_at_multipliers(&models, &moved, (&y_t, &c_t));
                self.give_models(models);
                error
            }
            Err(_) => f64::INFINITY,
        };
        let mut pool = self.pool.borrow_mut();
        pool.tops.give(y_t);
        pool.jets.give(c_t);
        for v in moved.into_vectors() {
            pool.reals.give(v);
        }
        error
    }

    /// Whether the filter accepts a trial point $(\theta_t, \varphi_t)$ at step length
    /// `alpha` from the `current` $(\theta, \varphi, \nabla\varphi^T d$, rounding of
    /// $\varphi)$: not dominated by the filter and, if $\theta \le \theta_{\min}$ and the
    /// switching condition holds, Armijo's condition on $\varphi$, else a decrease of
    /// $\theta$ or $\varphi$ (the filter is then augmented).
    fn filter_accepts(
        &self,
        filter: &mut Filter,
        (theta, phi, slope, noise): (f64, f64, f64, f64),
        (theta_t, phi_t): (f64, f64),
        alpha: f64,
    ) -> bool {
        if filter.rejects(theta_t, phi_t) {
            return false;
        }
        let switching = slope < 0.0 && alpha * (-slope).powf(S_PHI) > DELTA * theta.powf(S_THETA);
        if theta <= filter.theta_min && switching {
            phi_t <= phi + self.options.armijo * alpha * slope + noise
        } else if theta_t <= (1.0 - GAMMA_THETA) * theta || phi_t <= phi - GAMMA_PHI * theta + noise
        {
            filter.augment((1.0 - GAMMA_THETA) * theta, phi - GAMMA_PHI * theta);
            true
        } else {
            false
        }
    }

    /// Backtracking on $\varphi + \pi \Vert c\Vert_1$ along the direction (where the filter finds no
    /// step): the accepted point, the step length and whether the decrease was at rounding
    /// level; [`Failure::LineSearch`] if no step is accepted, [`Failure::TimeLimit`] if the
    /// budget runs out between trials.
    fn penalty_search(
        &self,
        iterate: &Iterate<N, X>,
        models: &Models<N, X>,
        direction: &Direction<N, X>,
        (barrier, ds): (&Barrier, &[f64]),
        penalty: &mut f64,
    ) -> Result<Accepted<N, X>, Failure> {
        let options = &self.options;
        let slope = self.slope(models, direction, barrier, ds);
        let violation = models.violation_l1();
        if violation > 0.0 {
            // the model's decrease must pay for its curvature too (Nocedal and Wright, 18.36):
            // pi >= (slope + max(0, d^T H d) / 2) / ((1 - 0.1) |c|_1), so that long steps
            // toward feasibility are not cut by the cost they add; H without the barrier's
            // h z/s grad g grad g^T, which near an active bound would make pi huge
            // (with the dynamics alone, linear, a full step is feasible: no curvature needed)
            let nonlinear = !self.problem.equalities.is_empty() || !barrier.s.is_empty();
            let curvature = if nonlinear {
                (self.curvature(models, direction)
                    - barrier.curvature(&models.inequalities, ds, self.dynamics.h))
                .max(0.0)
            } else {
                0.0
            };
            let needed = (slope + 0.5 * curvature) / (0.9 * violation);
            if needed > *penalty {
                *penalty = needed * 1.1;
            }
        }
        let descent = slope - *penalty * violation;
        let merit0 = models.barrier_cost + *penalty * violation;
        if !descent.is_finite() {
            return Err(Failure::LineSearch);
        }
        // rounding of the merit function: of J and of the defects (about eps |x| each)
        let size: f64 = iterate.x.iter().map(|x| x.lp_norm(1)).sum();
        let noise = 1e-14 * (models.barrier_cost.abs() + 2.0 * *penalty * size);
        // a non-negative slope: the direction is at rounding level; take it as it is
        let descent = descent.min(0.0);
        let mut alpha = barrier.max_step(ds);
        for _ in 0..=options.max_backtracks {
            if self.out_of_time() {
                return Err(Failure::TimeLimit);
            }
            let (trial, parts) = self.trial(iterate, direction, (barrier, ds), alpha);
            if parts.is_some_and(|(cost, violation)| {
                cost + *penalty * violation <= merit0 + options.armijo * alpha * descent + noise
            }) {
                return Ok(Accepted {
                    trial,
                    alpha,
                    at_rounding: -descent <= noise,
                    corrected: None,
                    restored: None,
                    dual_alpha: None,
                });
            }
            self.give_iterate(trial);
            alpha *= 0.5;
        }
        Err(Failure::LineSearch)
    }
}
