//! The SQP iteration of [`super::OptimalControlProblem`]: stage models, the inertia-corrected
//! Riccati solve, the convergence test and the second-order check; the filter line search in
//! its own module (`line_search`).

use std::cell::RefCell;
use std::time::Instant;

use nalgebra::{SMatrix, SVector};

use super::barrier::Barrier;
use super::certificate::{kkt_residuals, min_reduced_eigenvalue};
use super::constraints::{Inequality, Linearized, flat_hessian, slack_push};
use super::duals::Duals;
use super::optimize::{Iterate, OptimalControlProblem, PlanOptions, blocks};
use super::plan::{Certificate, Failure, Plan, PlanError};
use super::refine::refine;
use super::riccati::{Direction, Dynamics, Riccati, STEPS_PER_CLOCK_CHECK, StageModel, Terminal};
use super::workspace::Pool;
use crate::newton::all_finite;
use crate::{Lagrangian, LiftedSystem};

mod line_search;
use line_search::Filter;

/// The error below which a full step's factorisation is kept for a simplified Newton step
/// at the next iterate.
const CHORD_ERROR: f64 = 1e-3;

/// The smallest barrier parameter, for a KKT tolerance $\varepsilon$: $\varepsilon / 2$ (so
/// that $z s \approx \mu$ is below the tolerance). Lower, an active inequality's slack
/// $s = \mu / z$ falls toward the rounding of its constraint's value and the barrier Hessian
/// $h z / s$ toward $10^{12}$ of the rest: the subproblem's multipliers lose their digits and
/// the residuals stall.
fn barrier_floor(tolerance: f64) -> f64 {
    tolerance / 2.0
}

/// The ratio $z / s$ of an inequality above which the subproblem's solution is refined
/// ([`refine`]), and the number of refinement steps.
const REFINE_RATIO: f64 = 1e6;
const REFINEMENTS: usize = 2;

/// Consecutive iterations at which the goal stays out of the subproblems' reach
/// ([`Sqp::unreachable_goal`]) before the solve ends with [`Failure::UnreachableGoal`].
const UNREACHABLE_ITERATIONS: usize = 5;

/// The penalty weights of the active inequalities in the second-order check
/// ([`Sqp::certify`]), relative to the largest entry of the stage Hessians (and to
/// $|\nabla g|^2$), tried in turn.
const FINSLER_WEIGHTS: [f64; 3] = [1e2, 1e4, 1e6];

/// The shift of the stage Hessians, relative to their largest entry, under which a singular
/// reduced Hessian without negative directions counts as positive semidefinite
/// ([`Sqp::shifted_factor`]): a few hundred roundings of the largest entry.
const SEMIDEFINITE_SHIFT: f64 = 1e-13;

/// One run of the SQP iteration.
pub(super) struct Sqp<
    'p,
    'a,
    Sys: ?Sized,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
> {
    pub problem: &'p OptimalControlProblem<'a, Sys, N, K, X>,
    pub dynamics: Dynamics<N, X>,
    pub started: Instant,
    /// The inequalities placed at the steps' evaluation points.
    pub at_steps: &'p [Inequality<'a, N, K>],
    /// The inequalities placed at the nodes (imposed at the interior ones).
    pub at_nodes: &'p [Inequality<'a, N, K>],
    /// The vectors kept between iterations and solves.
    pub pool: &'p RefCell<Pool<N, X>>,
    /// The options of this run (the problem's, or those of a real-time iteration).
    pub options: PlanOptions,
    /// A real-time iteration: the iterate at the iteration limit is a result, not a failure.
    pub real_time: bool,
}

/// The models of all stages at one iterate.
struct Models<const N: usize, const X: usize> {
    stages: Vec<StageModel<N, X>>,
    /// $J$.
    cost: f64,
    /// $J - h \mu \sum \ln g$.
    barrier_cost: f64,
    r0: SVector<f64, X>,
    r_end: SVector<f64, X>,
    /// The inequalities at every step (step-major).
    inequalities: Vec<Linearized<N, X>>,
    /// The gradient of $h L$ alone at every step (the models hold the barrier's too).
    cost_gradient: Vec<(SVector<f64, X>, SVector<f64, N>)>,
    /// $\sum |g - s|$ and $\max |g - s|$ over the inequalities.
    slack_violation: (f64, f64),
    /// The end: the terminal cost's Hessian and the fixed components of $x_N$.
    terminal: Terminal<X>,
    /// $\nabla\Phi(x_N)$ (zero without a terminal cost).
    terminal_gradient: SVector<f64, X>,
}

/// A solved subproblem: the factorisation used (`stale` if it is the previous iterate's),
/// its inertia correction, the direction, the momenta and residuals, and the error
/// $\max$(stationarity, feasibility).
struct Subproblem<const N: usize, const X: usize> {
    riccati: Riccati<N, X>,
    rho: f64,
    stale: bool,
    direction: Direction<N, X>,
    momenta: Vec<SVector<f64, X>>,
    certificate: Certificate,
    error: f64,
    /// The error of the barrier problem, IPOPT's $E_\mu$ per unit time: the absolute
    /// stationarity $\sigma \times$ the relative one over $s_d$, the feasibility and $\max |z s
    /// - \mu|$ over $s_c$ ([`Barrier::error_scales`]); see [`Sqp::barrier_error`].
    barrier_error: f64,
}

/// What the iteration carries from one iterate to the next.
struct State<const N: usize, const X: usize> {
    iterate: Iterate<N, X>,
    /// The stage equalities' multipliers.
    y: Vec<SVector<f64, N>>,
    barrier: Barrier,
    filter: Option<Filter>,
    /// The last direction, after a full step (its multipliers are the Newton estimates at the
    /// new iterate).
    full_step: Option<Direction<N, X>>,
    /// A factorisation kept for a simplified Newton step, with the error where it was made.
    kept: Option<(Riccati<N, X>, f64)>,
}

/// How [`Sqp::finish`] ended: a certified plan, a failed second-order check, or not yet (a
/// constraint violated beyond the tolerance where it is imposed).
#[allow(clippy::large_enum_variant)] // (made once per solve, and moved at once)
enum Finished<const N: usize, const X: usize> {
    Plan(Plan<N, X>),
    Failed(Failure, Certificate, Subproblem<N, X>),
    Not(Subproblem<N, X>),
}

impl<const N: usize, const X: usize> Models<N, X> {
    /// $\Vert c\Vert_1$ over defects, stage constraints and boundary data.
    fn violation_l1(&self) -> f64 {
        self.slack_violation.0
            + self
                .stages
                .iter()
                .map(|s| s.defect.lp_norm(1) + s.value.lp_norm(1))
                .sum::<f64>()
            + self.r0.lp_norm(1)
            + self.r_end.lp_norm(1)
    }
    /// $\Vert c\Vert_\infty$.
    fn violation_max(&self) -> f64 {
        self.stages
            .iter()
            .map(|s| s.defect.amax().max(s.value.amax()))
            .fold(self.r0.amax().max(self.r_end.amax()), f64::max)
            .max(self.slack_violation.1)
    }
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// An empty iterate of `steps` steps, from the pool.
    fn take_iterate(&self, steps: usize) -> Iterate<N, X> {
        let mut pool = self.pool.borrow_mut();
        Iterate {
            x: pool.jets.take(steps + 1),
            u: pool.tops.take(steps),
        }
    }

    /// Gives an iterate's vectors back to the pool.
    fn give_iterate(&self, iterate: Iterate<N, X>) {
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(iterate.x);
        pool.tops.give(iterate.u);
    }

    /// Gives a plan's vectors back to the pool.
    fn give_plan(&self, plan: Plan<N, X>) {
        self.pool.borrow_mut().give_plan(plan);
    }

    /// Gives the models' vectors back to the pool.
    fn give_models(&self, models: Models<N, X>) {
        let mut pool = self.pool.borrow_mut();
        pool.stages.give(models.stages);
        pool.linearized.give(models.inequalities);
        pool.gradients.give(models.cost_gradient);
    }

    /// Gives a subproblem's vectors back to the pool.
    fn give_subproblem(&self, sub: Subproblem<N, X>) {
        let mut pool = self.pool.borrow_mut();
        sub.riccati.recycle(&mut pool);
        sub.direction.recycle(&mut pool);
        pool.jets.give(sub.momenta);
    }

    fn x_theta(&self, iterate: &Iterate<N, X>, i: usize) -> SVector<f64, X> {
        let theta = self.dynamics.theta;
        iterate.x[i] * (1.0 - theta) + iterate.x[i + 1] * theta
    }

    /// The model of stage `i`: the Hessian of the Lagrangian $h L + y^T g^{=} - h y_g^T g^{\ge}$
    /// ($y_g$: the multipliers of $g - s = 0$, [`Barrier::y`]),
    /// the gradient of $h L$, the defect and the equalities with their Jacobians (the barrier's
    /// own terms are added by [`Barrier::add_to_stage`]).
    #[inline(always)]
    fn stage(
        &self,
        iterate: &Iterate<N, X>,
        i: usize,
        y: &SVector<f64, N>,
        barrier: &Barrier,
    ) -> StageModel<N, X> {
        let (h, system) = (self.dynamics.h, self.problem.system_at(i));
        let u = &iterate.u[i];
        let xt = self.x_theta(iterate, i);
        let xb = blocks::<N, K, X>(&xt);
        let g = system.gradient(&xb, u);
        let (mut hxx, mut hux, mut huu) = flat_hessian::<N, K, X>(&system.hessian(&xb, u), h);
        let mut stage = StageModel {
            hxx,
            hux,
            huu,
            gx: SVector::from_fn(|r, _| h * g.x[r / N][r % N]),
            gu: g.u * h,
            defect: self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1],
            constraints: self.problem.equalities.len(),
            cx: SMatrix::zeros(),
            cu: SMatrix::zeros(),
            value: SVector::zeros(),
            node: None,
        };
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
        stage.node = self.node_curvature(iterate, i, barrier);
        stage
    }

    /// The curvature $-h y \nabla^2 g$ of the inequalities at node `i` (interior nodes
    /// only), as node terms with a zero gradient; `None` where there are none.
    fn node_curvature(
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

    /// Appends the values of the node inequalities at the interior nodes (node-major).
    fn node_values(&self, iterate: &Iterate<N, X>, values: &mut Vec<f64>) {
        let zero = SVector::<f64, N>::zeros();
        let steps = iterate.u.len();
        for x in iterate.x.iter().take(steps).skip(1) {
            values.extend(self.at_nodes.iter().map(|c| c.value(x, &zero)));
        }
    }

    /// The models of every stage with the constraint multipliers `y`; [`Failure::NonFinite`]
    /// if anything is not finite, [`Failure::TimeLimit`] if the budget runs out (the clock is
    /// read every [`STEPS_PER_CLOCK_CHECK`] steps).
    fn models(
        &self,
        iterate: &Iterate<N, X>,
        y: &[SVector<f64, N>],
        barrier: &Barrier,
    ) -> Result<Models<N, X>, Failure> {
        let h = self.dynamics.h;
        let steps = iterate.u.len();
        let inequalities = self.inequalities(iterate);
        let (mut stages, mut cost_gradient) = {
            let mut pool = self.pool.borrow_mut();
            (pool.stages.take(steps), pool.gradients.take(steps))
        };
        let mut cost = 0.0;
        for (i, u) in iterate.u.iter().enumerate() {
            if i % STEPS_PER_CLOCK_CHECK == STEPS_PER_CLOCK_CHECK - 1 && self.out_of_time() {
                return Err(Failure::TimeLimit);
            }
            let system = self.problem.system_at(i);
            cost += h * system.lagrangian(&blocks::<N, K, X>(&self.x_theta(iterate, i)), u);
            let count = barrier.count;
            let own = &inequalities[i * count..(i + 1) * count];
            // (built in place: a stage model is a few hundred bytes)
            stages.push(self.stage(iterate, i, &y[i], barrier));
            let stage = stages.last_mut().ok_or(Failure::NonFinite)?;
            cost_gradient.push((stage.gx, stage.gu));
            barrier.add_to_stage(stage, i, own, h);
            if stage.node.is_some() {
                let from = barrier.node_index(i, 0);
                barrier.add_to_node(stage, i, &inequalities[from..from + barrier.nodes], h);
            }
            let node_finite = stage
                .node
                .as_ref()
                .is_none_or(|node| all_finite(&node.0) & all_finite(&node.1));
            // each a vectorised sum of 0 * entry (nalgebra's `sum` is one chain of dependent
            // additions: a fifth of an SQP iteration on the SE(2) scene)
            let finite = all_finite(&stage.hxx)
                & all_finite(&stage.hux)
                & all_finite(&stage.huu)
                & all_finite(&stage.gx)
                & all_finite(&stage.gu)
                & all_finite(&stage.cx)
                & all_finite(&stage.cu)
                & all_finite(&stage.value)
                & node_finite;
            if !finite {
                return Err(Failure::NonFinite);
            }
        }
        let r0 = (self.problem.start - iterate.x[0]).component_mul(&self.problem.fixed_start);
        let last = &iterate.x[iterate.x.len() - 1];
        let fixed = self.problem.fixed_end;
        let r_end = (self.problem.goal - last).component_mul(&fixed);
        let (log, slack_l1) = barrier.current_terms(&inequalities, h);
        let slack_violation = (slack_l1, barrier.residual(&inequalities));
        let (phi, terminal_gradient, hessian) = self.terminal_model(last);
        let cost = cost + phi;
        let barrier_cost = cost + log;
        let finite =
            barrier_cost.is_finite() && all_finite(&terminal_gradient) && all_finite(&hessian);
        if !finite {
            return Err(Failure::NonFinite);
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

    /// $\Phi(x_N)$ (0 without a terminal cost).
    fn terminal_value(&self, last: &SVector<f64, X>) -> f64 {
        self.problem.terminal_cost.map_or(0.0, |phi| {
            phi.value(&blocks::<N, K, X>(last), &SVector::zeros())
        })
    }

    /// $\Phi(x_N)$, its gradient and its Hessian in $x_N$ (zeros without a terminal cost).
    fn terminal_model(&self, last: &SVector<f64, X>) -> (f64, SVector<f64, X>, SMatrix<f64, X, X>) {
        let Some(phi) = self.problem.terminal_cost else {
            return (0.0, SVector::zeros(), SMatrix::zeros());
        };
        let (x, u) = (blocks::<N, K, X>(last), SVector::<f64, N>::zeros());
        let g = phi.gradient(&x, &u);
        let (hxx, _, _) = flat_hessian::<N, K, X>(&phi.hessian(&x, &u), 1.0);
        let gradient = SVector::from_fn(|r, _| g.x[r / N][r % N]);
        (phi.value(&x, &u), gradient, hxx)
    }

    /// Every inequality linearised where it is imposed, in the order of [`Barrier`]: those
    /// of the steps (step-major), then those of the interior nodes (node-major).
    pub fn inequalities(&self, iterate: &Iterate<N, X>) -> Vec<Linearized<N, X>> {
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

    /// The Riccati factorisation with an inertia correction $\rho$ (scaled by $h$) that makes
    /// the reduced Hessian positive definite: none if the last iteration needed none (or
    /// little), else from a third of the `last` one (the correction decays geometrically
    /// instead of dropping to 0 at a point where the Hessian is barely definite), growing by 8
    /// (100 from scratch) until the inertia is right; with inequalities the correction shifts
    /// the eliminated slacks' Hessian too, as IPOPT's ([`Barrier::shift_slacks`]: the stages
    /// of `models` are left shifted by the correction found, for the solve that follows).
    /// Fails with [`Failure::Regularization`]
    /// past $\rho = 10^{40}$, or [`Failure::TimeLimit`] when the budget runs out between
    /// factorisations.
    fn factor_corrected(
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
                barrier.shift_slacks(&mut models.stages, &models.inequalities, rho);
            }
            let (stages, end) = (&models.stages, &models.terminal);
            let clock = (self.deadline(), &mut *pool);
            let riccati = Riccati::factor_until(&self.dynamics, stages, rho, end, clock);
            if riccati.interrupted {
                riccati.recycle(&mut pool);
                return Err(Failure::TimeLimit);
            }
            if riccati.positive_definite() {
                return Ok(Some(riccati));
            }
            riccati.recycle(&mut pool);
            Ok(None)
        };
        // (no correction first; then rho growing until the inertia is right, or a failure)
        let mut found = if last < 1e-8 {
            factor(0.0).map(|r| r.map(|r| (r, 0.0)))
        } else {
            Ok(None)
        };
        let mut rho = if last > 0.0 { last / 3.0 } else { 1e-4 };
        while matches!(found, Ok(None)) && rho < 1e40 {
            found = factor(h * rho).map(|r| r.map(|r| (r, rho)));
            rho *= if last > 0.0 { 8.0 } else { 100.0 };
        }
        if let Some(base) = base {
            self.pool.borrow_mut().stages.give(base);
        }
        found?.ok_or(Failure::Regularization)
    }

    /// When the wall-time budget runs out: the start of the solve plus
    /// [`super::PlanOptions::max_time`].
    fn deadline(&self) -> Option<Instant> {
        let budget = self.options.max_time?;
        self.started.checked_add(budget)
    }

    /// Whether the wall-time budget ([`Self::deadline`]) has run out.
    fn out_of_time(&self) -> bool {
        self.deadline().is_some_and(|d| Instant::now() >= d)
    }

    /// The certificate's residuals at the iterate of `models` with the multipliers of the
    /// subproblem solution `direction` ([`kkt_residuals`] with the gradients of $h L - h z^T
    /// g^{\ge}$, the constraint violation, $\max z g$), its negative directions those of
    /// `riccati`; the momenta; and the scale $\sigma$ of the relative stationarity (its
    /// absolute value, per unit time, is $\sigma$ times the relative one).
    fn residuals(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        negative_directions: usize,
        direction: &Direction<N, X>,
        z: &[f64],
    ) -> (Vec<SVector<f64, X>>, Certificate, f64) {
        let h = self.dynamics.h;
        // the gradients of the Lagrangian: those of h L, less h z^T grad g with inequalities
        let mut pool = self.pool.borrow_mut();
        let with_inequalities = (barrier.at_steps() > 0).then(|| {
            let mut g = pool.gradients.take(models.cost_gradient.len());
            g.extend_from_slice(&models.cost_gradient);
            barrier.lagrangian_gradients(&mut g, &models.inequalities, z, h);
            g
        });
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
            direction,
            &nodes,
            end,
            momenta,
        );
        if let Some(g) = with_inequalities {
            pool.gradients.give(g);
        }
        pool.jets.give(nodes);
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

    /// The plan at the point `state` (iterate, stage-equality multipliers, barrier).
    fn plan(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        cost: f64,
        iterations: usize,
        momenta: Vec<SVector<f64, X>>,
        certificate: Certificate,
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
        let (step_slacks, step_multipliers) = (copy(step_slacks), copy(step_multipliers));
        let (node_slacks, node_multipliers) = (copy(node_slacks), copy(node_multipliers));
        let (mut equalities, mut x, mut u) = (
            pool.tops.take(y.len()),
            pool.jets.take(iterate.x.len()),
            pool.tops.take(iterate.u.len()),
        );
        drop(pool);
        equalities.extend_from_slice(y);
        x.extend_from_slice(&iterate.x);
        u.extend_from_slice(&iterate.u);
        let duals = Duals {
            equalities,
            step_slacks,
            step_multipliers,
            node_slacks,
            node_multipliers,
            barrier: barrier.mu,
        };
        Plan {
            h,
            theta,
            x,
            u,
            momenta,
            cost,
            iterations,
            certificate,
            violations: self.problem.violations(iterate, theta).0,
            duals,
        }
    }

    /// The barrier at the first iterate: from the `warm` start's duals if they fit the
    /// problem's inequalities ([`Barrier::warm`]), else [`Barrier::new`] with $\mu = \mu_0 / h$
    /// per unit time, $\mu_0$ = [`super::PlanOptions::initial_barrier`], and $\mu = 0$ without
    /// inequalities; `None` if an inequality is not finite there.
    fn initial_barrier(&self, iterate: &Iterate<N, X>, warm: Option<&Duals<N>>) -> Option<Barrier> {
        let lin = self.inequalities(iterate);
        let mut pool = self.pool.borrow_mut();
        let mut values = pool.reals.take(lin.len());
        values.extend(lin.iter().map(|c| c.value));
        pool.linearized.give(lin);
        let vectors = [0; 3].map(|_| pool.reals.take(values.len()));
        drop(pool);
        let layout = (self.at_steps.len(), self.at_nodes.len(), iterate.u.len());
        let fits = |d: &&Duals<N>| layout.0 + layout.1 > 0 && d.fit(layout.2, layout.0, layout.1);
        let barrier = if !values.iter().all(|v| v.is_finite()) {
            None
        } else if let Some(duals) = warm.filter(fits) {
            let floor = barrier_floor(self.options.tolerance);
            Some(Barrier::warm(duals, layout, floor, vectors))
        } else {
            Some(self.cold_barrier(&values, layout, vectors))
        };
        self.pool.borrow_mut().reals.give(values);
        barrier
    }

    /// [`Barrier::new`] for the inequalities' `values` at the first iterate.
    fn cold_barrier(
        &self,
        values: &[f64],
        layout: (usize, usize, usize),
        vectors: [Vec<f64>; 3],
    ) -> Barrier {
        let mu = if layout.0 + layout.1 > 0 {
            self.options.initial_barrier / self.dynamics.h
        } else {
            0.0
        };
        let (steps, nodes) = (slack_push(self.at_steps), slack_push(self.at_nodes));
        let at_steps = layout.0 * layout.2;
        let push = |k: usize| {
            if k < at_steps {
                steps[k % layout.0]
            } else {
                nodes[(k - at_steps) % layout.1]
            }
        };
        Barrier::new((mu, self.dynamics.h), layout, values, push, vectors)
    }

    /// Iterates from `iterate` until the KKT residuals are below the tolerance with a positive
    /// definite reduced Hessian (and, with inequalities, the barrier parameter at its floor
    /// [`barrier_floor`]), or a budget or the line search fails. After a full step from an
    /// error below $\sqrt{\varepsilon}$ the residuals at the new point are first evaluated
    /// with the last subproblem's multipliers (the Newton estimates there): if they and the
    /// inertia of the factorisation at the point certify it, it is returned without solving
    /// its own subproblem. Without stage constraints, a full step from an error below
    /// `CHORD_ERROR` keeps its factorisation for the next iterate's subproblem (a simplified
    /// Newton step, [`Self::subproblem`]); a point is never certified with a kept one.
    pub fn run(
        &self,
        iterate: Iterate<N, X>,
        warm: Option<&Duals<N>>,
    ) -> Result<(Plan<N, X>, bool), PlanError<N, X>> {
        let Some(barrier) = self.initial_barrier(&iterate, warm) else {
            self.give_iterate(iterate);
            return Err(PlanError::without_iterate(Failure::NonFinite));
        };
        // (the stage equalities' multipliers: a warm start's if they fit and are finite, else
        // 0; a plan read back from a file may hold any numbers)
        let finite = |y: &SVector<f64, N>| y.iter().all(|v| v.is_finite());
        let steps = iterate.u.len();
        let mut y = self.pool.borrow_mut().tops.take(steps);
        match warm.map(|duals| &duals.equalities) {
            Some(given) if given.len() == steps && given.iter().all(finite) => {
                y.extend_from_slice(given);
            }
            _ => y.resize(steps, SVector::zeros()),
        }
        let mut state = State {
            iterate,
            y,
            barrier,
            filter: None,
            full_step: None,
            kept: None,
        };
        let result = self.iterate_from(&mut state);
        self.release(state);
        result
    }

    /// Gives the vectors of the iteration's `state` back to the pool.
    fn release(&self, state: State<N, X>) {
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(state.iterate.x);
        pool.tops.give(state.iterate.u);
        pool.tops.give(state.y);
        for v in state.barrier.into_vectors() {
            pool.reals.give(v);
        }
        if let Some(filter) = state.filter {
            pool.pairs.give(filter.into_entries());
        }
        if let Some(direction) = state.full_step {
            direction.recycle(&mut pool);
        }
        if let Some((riccati, _)) = state.kept {
            riccati.recycle(&mut pool);
        }
    }

    /// The iteration of [`Self::run`] from `st`: the plan and whether it is certified (if
    /// not, the iterate of a real-time iteration at its iteration limit).
    fn iterate_from(&self, st: &mut State<N, X>) -> Result<(Plan<N, X>, bool), PlanError<N, X>> {
        let options = &self.options;
        let count = self.at_steps.len() + self.at_nodes.len();
        let floor = barrier_floor(options.tolerance);
        let (mut rho_last, mut penalty, mut iterations, mut stalled) = (0.0, 0.0, 0, 0);
        let mut unreachable = 0;
        // (the stage constraints' projections change with the iterate: no simplified steps)
        let unconstrained = count == 0 && self.problem.equalities.is_empty();
        loop {
            let done = iterations;
            let point = (&st.iterate, &st.y[..], &st.barrier);
            let fail = |failure, cost, certificate, momenta| PlanError {
                failure,
                last: Some(Box::new(self.plan(point, cost, done, momenta, certificate))),
            };
            // after a full step the last subproblem's multipliers are the Newton estimates
            // here: if they already certify this point, no subproblem is solved at it
            if let Some(last) = st.full_step.take() {
                let plan = (rho_last == 0.0)
                    .then(|| self.certify_without_solve(point, &last, iterations))
                    .flatten();
                last.recycle(&mut self.pool.borrow_mut());
                if let Some(plan) = plan {
                    return Ok((plan, true));
                }
            }
            let mut models = match self.models(&st.iterate, &st.y, &st.barrier) {
                Ok(models) => models,
                Err(Failure::TimeLimit) => {
                    let unknown = super::plan::unknown_certificate();
                    return Err(fail(Failure::TimeLimit, f64::NAN, unknown, vec![]));
                }
                Err(failure) => return Err(PlanError::without_iterate(failure)),
            };
            let sub = match self.subproblem(&mut models, &st.barrier, st.kept.take(), rho_last) {
                Ok(sub) => sub,
                Err(failure) => {
                    let mut partial = super::plan::unknown_certificate();
                    partial.feasibility = models.violation_max();
                    let failure = self.name_infeasibility(failure, &st.iterate);
                    return Err(fail(failure, models.cost, partial, vec![]));
                }
            };
            rho_last = sub.rho;
            match self.unreachable_goal(&models, &sub) {
                Some((component, miss)) if unreachable + 1 >= UNREACHABLE_ITERATIONS => {
                    let failure = Failure::UnreachableGoal { component, miss };
                    return Err(fail(failure, models.cost, sub.certificate, sub.momenta));
                }
                Some(_) => unreachable += 1,
                None => unreachable = 0,
            }
            // the barrier problem solved to 10 mu (IPOPT's test, in absolute units)
            if st.barrier.mu > floor && sub.barrier_error <= 10.0 * st.barrier.mu {
                st.barrier.decrease(floor, self.dynamics.h);
                if let Some(filter) = &mut st.filter {
                    filter.reset();
                }
                self.give_models(models);
                self.give_subproblem(sub);
                continue;
            }
            let complementarity = st.barrier.complementarity().0;
            // converged, or at the acceptable level with no progress left but rounding
            let acceptable = stalled >= 3 && sub.error.max(complementarity) <= options.acceptable;
            let mut sub =
                if (sub.error <= options.tolerance || acceptable) && st.barrier.mu <= floor {
                    match self.finish(point, &models, sub, iterations) {
                        Finished::Plan(plan) => {
                            self.give_models(models);
                            return Ok((plan, true));
                        }
                        Finished::Failed(failure, certificate, sub) => {
                            return Err(fail(failure, models.cost, certificate, sub.momenta));
                        }
                        Finished::Not(sub) => sub,
                    }
                } else {
                    sub
                };
            let out_of_time = self.out_of_time();
            if iterations == options.max_iterations && self.real_time && !out_of_time {
                let point = (&st.iterate, &st.y[..], &st.barrier);
                let momenta = core::mem::take(&mut sub.momenta);
                let plan = self.plan(point, models.cost, done, momenta, sub.certificate);
                self.give_models(models);
                self.give_subproblem(sub);
                return Ok((plan, false));
            }
            if iterations == options.max_iterations || out_of_time {
                let failure = if out_of_time {
                    Failure::TimeLimit
                } else {
                    Failure::IterationLimit
                };
                return Err(fail(failure, models.cost, sub.certificate, sub.momenta));
            }
            iterations += 1;
            let ds = self.pool.borrow_mut().reals.take(st.barrier.s.len());
            let theta = self.dynamics.theta;
            let ds = (st.barrier).slack_steps(&models.inequalities, &sub.direction, theta, ds);
            let (slacks, globals) = ((&st.barrier, &ds[..]), (&mut st.filter, &mut penalty));
            let searched = (&st.iterate, &models, &sub.direction);
            let accepted = match self.line_search(searched, slacks, globals) {
                Ok(accepted) => accepted,
                Err(Failure::LineSearch) if sub.stale => {
                    // the simplified direction failed: solve this iterate's own subproblem
                    iterations -= 1;
                    self.pool.borrow_mut().reals.give(ds);
                    self.give_models(models);
                    self.give_subproblem(sub);
                    continue;
                }
                Err(failure) => {
                    let failure = self.name_infeasibility(failure, &st.iterate);
                    return Err(fail(failure, models.cost, sub.certificate, sub.momenta));
                }
            };
            let state = (&mut st.iterate, &mut st.barrier, &mut st.y[..]);
            let (alpha, at_rounding) = self.advance(accepted, (&sub.direction, &ds), state);
            self.pool.borrow_mut().reals.give(ds);
            self.give_models(models);
            stalled = if at_rounding { stalled + 1 } else { 0 };
            let Subproblem {
                riccati,
                rho,
                stale,
                direction,
                momenta,
                error,
                ..
            } = sub;
            self.pool.borrow_mut().jets.give(momenta);
            // (worth trying when Newton's quadratic convergence will take the error from here
            // to below the tolerance)
            if alpha == 1.0 && error <= options.tolerance.sqrt() {
                st.full_step = Some(direction);
            } else {
                direction.recycle(&mut self.pool.borrow_mut());
            }
            // near a solution, one step with this factorisation at the next iterate
            if alpha == 1.0 && rho == 0.0 && !stale && unconstrained && error <= CHORD_ERROR {
                st.kept = Some((riccati, error));
            } else {
                riccati.recycle(&mut self.pool.borrow_mut());
            }
        }
    }

    /// The goal's component whose miss the subproblem cannot reduce, and that miss: where the
    /// terminal pivot needed the $\delta_c$ shift (the goal and the stage equalities are
    /// dependent) and the step's linearised miss $|r_N - \delta x_N|$ of a fixed component
    /// is above [`super::PlanOptions::acceptable`] and at least half of its miss $|r_N|$ now
    /// (to first order no step reaches it: a point of local infeasibility of the goal).
    fn unreachable_goal(
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
        (after > self.options.acceptable && after >= 0.5 * now).then_some((component, now))
    }

    /// The end of the iteration at a point whose residuals are below the tolerance (or at the
    /// acceptable level) with the barrier at its floor: the second-order check
    /// ([`Self::certify`]) and the plan, unless a constraint is violated beyond the tolerance
    /// where it is imposed (then the iteration goes on with the subproblem `sub`).
    fn finish(
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

    /// A failure of the inertia correction or the line search at an iterate that violates a
    /// constraint beyond the tolerance, as [`Failure::StalledInfeasible`] naming the
    /// constraint violated most (and where); any other failure as it is.
    fn name_infeasibility(&self, failure: Failure, iterate: &Iterate<N, X>) -> Failure {
        if !matches!(failure, Failure::Regularization | Failure::LineSearch) {
            return failure;
        }
        match self.problem.violations(iterate, self.dynamics.theta) {
            (violations, Some(worst))
                if violations.imposed().is_nan()
                    || violations.imposed() > self.options.tolerance =>
            {
                Failure::StalledInfeasible(worst)
            }
            _ => failure,
        }
    }

    /// The subproblem at `models`. With the factorisation `kept` of the previous iterate
    /// (whose error was $e_{\rm prev}$), a simplified Newton step: taken if its predicted error
    /// from here, about $e^2 / e_{\rm prev}$ (the kept factorisation is off by about the last
    /// step, $e_{\rm prev}$), is below the tolerance. Otherwise, or without `kept`, a new
    /// inertia-corrected factorisation ([`Self::factor_corrected`], whose failure is
    /// returned). (A kept factorisation was positive definite without correction, so the
    /// negative directions reported with it, 0, are those of the previous iterate.)
    fn subproblem(
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
    /// [`REFINE_RATIO`] above the rest: it costs the solve digits), the multipliers and
    /// residuals that go with it, and the errors of the problem and of the barrier problem.
    fn solved(
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
        let mut direction = riccati.solve(&self.dynamics, stages, rho_h, r0, end, &mut pool);
        if ill_conditioned {
            let model = (&models.stages[..], &models.terminal);
            for _ in 0..REFINEMENTS {
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
        let barrier_error = self.barrier_error(models, barrier, &direction, (&z, &momenta));
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

    /// The error of the barrier problem (IPOPT's $E_\mu$ per unit time, [`Subproblem`]'s
    /// `barrier_error`) at the models' iterate with the subproblem's solution `direction`:
    /// the smaller of its values with the predicted inequality multipliers `z` and with the
    /// current ones (the predicted ones are off by the whole dual step when the primal step
    /// is short). $\infty$ without inequalities or with $\mu$ at its floor (it only decides
    /// when $\mu$ decreases).
    fn barrier_error(
        &self,
        models: &Models<N, X>,
        barrier: &Barrier,
        direction: &Direction<N, X>,
        (z, momenta): (&[f64], &[SVector<f64, X>]),
    ) -> f64 {
        if barrier.s.is_empty() || barrier.mu <= barrier_floor(self.options.tolerance) {
            return f64::INFINITY;
        }
        let h = self.dynamics.h;
        let others = direction
            .multipliers
            .iter()
            .map(|y| y.lp_norm(1))
            .sum::<f64>()
            + momenta.iter().map(|p| p.lp_norm(1)).sum::<f64>();
        let count = direction.multipliers.len() * N + momenta.len() * X;
        let compl = barrier.complementarity().1;
        let error = |z: &[f64]| {
            let (momenta, certificate, scale) = self.residuals(models, barrier, 0, direction, z);
            self.pool.borrow_mut().jets.give(momenta);
            let (s_d, s_c) = barrier.error_scales(z, h, (others, count));
            (scale * certificate.stationarity / s_d)
                .max(certificate.feasibility)
                .max(compl / s_c)
        };
        error(z).min(error(&barrier.z))
    }

    /// The plan at the point reached by a full step, certified with the last subproblem's
    /// multipliers (the Newton estimates here) instead of a solve of its own: if the residuals
    /// are below the tolerance with the barrier at its floor and the second-order check
    /// ([`Self::certify`]) passes; `None` (solve as usual) otherwise.
    fn certify_without_solve(
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
    fn certify(
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
            riccati.recycle(&mut self.pool.borrow_mut());
        }
        result
    }

    /// The rest of [`Self::certify`] with the factorisation `exact` of its second-order check:
    /// its inertia, the shifted factorisation of a singular one, the smallest eigenvalue.
    fn second_order(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
        exact: &Riccati<N, X>,
        mut certificate: Certificate,
    ) -> Result<Certificate, (Failure, Certificate)> {
        certificate.negative_directions = exact.negative;
        if !exact.positive_definite() {
            // singular without a negative pivot: semidefinite if a shift of the rounding's
            // size makes it definite (a minimum, flat along some direction: not strict)
            let shifted = (exact.negative == 0).then(|| self.shifted_factor(state, models));
            let definite = shifted.as_ref().is_some_and(|f| f.positive_definite());
            let negative = shifted.map_or(exact.negative, |f| {
                let negative = f.negative;
                f.recycle(&mut self.pool.borrow_mut());
                negative
            });
            if definite {
                certificate.min_reduced_hessian_eig = 0.0;
                return Ok(certificate);
            }
            certificate.negative_directions = negative;
            let failure = Failure::NotAMinimum {
                negative_directions: negative,
            };
            return Err((failure, certificate));
        }
        // (the Lanczos operator takes x_N as fixed)
        if self.options.min_eigenvalue && models.terminal.fixed.iter().all(|f| *f != 0.0) {
            let pool = &mut *self.pool.borrow_mut();
            certificate.min_reduced_hessian_eig =
                min_reduced_eigenvalue(exact, &self.dynamics, pool);
        }
        Ok(certificate)
    }

    /// The factorisation of the second-order check ([`Self::certify`]) with every stage
    /// Hessian shifted by [`SEMIDEFINITE_SHIFT`] times the largest entry of the Lagrangian's
    /// stage Hessians ($h$ at least): positive definite where the reduced Hessian is
    /// positive semidefinite and singular, with the negative directions counted where it is
    /// not.
    fn shifted_factor(
        &self,
        state: (&Iterate<N, X>, &[SVector<f64, N>], &Barrier),
        models: &Models<N, X>,
    ) -> Riccati<N, X> {
        if !state.2.s.is_empty() {
            return self.penalized_factor(state, models, SEMIDEFINITE_SHIFT);
        }
        let shift = SEMIDEFINITE_SHIFT * self.hessian_scale(&models.stages);
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
    fn hessian_scale(&self, stages: &[StageModel<N, X>]) -> f64 {
        stages.iter().fold(self.dynamics.h, |m, s| {
            m.max(crate::newton::max_abs(&s.hxx))
                .max(crate::newton::max_abs(&s.huu))
        })
    }

    /// The factorisation of the Lagrangian's stage models (no barrier terms) with the active
    /// inequalities as penalties, for the first weight of [`FINSLER_WEIGHTS`] that makes it
    /// positive definite (else the last one's); every stage Hessian shifted by `shift` times
    /// their scale ([`Self::hessian_scale`]).
    fn penalized_factor(
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
        base.extend((0..steps).map(|i| self.stage(iterate, i, &y[i], barrier)));
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
