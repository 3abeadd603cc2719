//! The optimizer's iteration: SQP on the direct transcription of the lifted-midpoint scheme.
//!
//! The boundary-value problem of the scheme is the KKT system of
//!
//! $$\min_{x, u}\ J = \sum_{i<N} h\thinspace L(x_{\theta,i}, u_i) \quad \text{s.t.} \quad
//!   x_{i+1} - x_i = h A x_{\theta,i} + h B u_i, \quad x_0 = a, \quad x_N = b,$$
//!
//! with $x_{\theta,i} = (1-\theta) x_i + \theta x_{i+1}$, $A$ the block shift
//! ($x_j' = x_{j+1}$), $B$ the last block ($x_{k-1}' = u$), and the momenta the multipliers:
//! $p_{\theta,i} = \theta p_i + (1-\theta) p_{i+1} = \mu_i$, the multiplier of step $i$. The
//! constraints are linear, so the Hessian of the Lagrangian is the Hessian of $J$, formed from
//! the generated Hessian of $L$ in $(x, u)$.
//!
//! Each iteration solves the quadratic subproblem by a Riccati recursion ([`super::kkt::riccati`],
//! $O(N)$), counts the negative eigenvalues of the reduced Hessian on the way and, while there
//! are any, adds $h \rho I$ to every stage Hessian (inertia correction as in IPOPT: $\rho$ from
//! $10^{-4}$, times 8 until the count is 0, a third of the last value at the next iteration),
//! so every direction descends and iterates are drawn to minima. The step length comes from
//! IPOPT's filter line search on the barrier cost and the constraint violation, and where the
//! filter finds no step, from backtracking on the exact penalty $J + \pi \Vert c\Vert_1$ ($c$:
//! all constraints), $\pi$ raised so that the direction descends, and where neither makes
//! progress from IPOPT's feasibility restoration phase (`restoration`); a trial point whose
//! steps leave the domain of $L$ (the generated singularity guard at both ends and the
//! evaluation point of every step, and on pieces of its chord no longer than `chord_spacing`
//! unless its guards are quadratic, as [`crate::step::check_step_domain`]) is rejected. A
//! point is returned only when the KKT residuals are below the tolerance and the reduced
//! Hessian is positive definite without correction; its [`Certificate`](super::Certificate) holds the residuals and the
//! smallest eigenvalue of the reduced Hessian (Lanczos on the inverse,
//! [`super::kkt::residuals`]).
//!
//! One iteration runs the phases in turn, each a module of methods of [`Sqp`] (`state.rs`
//! holds it and what the phases pass each other): `models` (the stage models at the
//! iterate), `direction` (the subproblem: the inertia-corrected Riccati solve of
//! [`super::kkt`]), `termination` (the KKT and barrier errors, which the loop tests against
//! the tolerances; at a converged point the second-order check of `second_order` and the
//! plan; `acceptable`, the acceptable-level exit at a point kept before the barrier's
//! floor), `line_search` (IPOPT's filter, `filter`, with the exact-penalty fallback and the
//! restoration phase, `restoration`) and the step. A phase calls only the phases before it
//! in the order `models`, `second_order`, `termination`, `direction`, `acceptable`,
//! `restoration`, `line_search`; this module holds the loop ([`Sqp::run`]) and the first
//! barrier, and calls them all. The vectors come from the workspace's pool, kept
//! from one solve to the next ([`super::Workspace`]).

use nalgebra::SVector;

use crate::bvp::BarrierUpdate;
use crate::bvp::barrier::Barrier;
use crate::bvp::constraints::slack_push;
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::residuals::step_multipliers;
use crate::bvp::plan::duals::Duals;
use crate::bvp::plan::{Failure, Plan, PlanError};
use crate::{Lagrangian, LiftedSystem};

mod acceptable;
mod adaptive;
mod at_solution;
mod correction;
mod direction;
mod escape;
mod feedback;
mod filter;
mod first_multipliers;
mod line_search;
mod models;
mod restoration;
mod second_order;
mod state;
mod termination;

use adaptive::Adaptive;
pub(super) use at_solution::AtSolution;
pub(super) use feedback::Linearization;
use filter::Filter;
use line_search::Progress;
pub(super) use state::Sqp;
use state::{Models, State, Subproblem};
use termination::{Finished, barrier_floor};

/// The end of a solve: the plan and whether it is certified (if not, the iterate of a
/// real-time iteration at its iteration limit), or the failure.
type Solved<const N: usize, const X: usize> = Result<(Plan<N, X>, bool), PlanError<N, X>>;

/// An accepted point of the line search, its slack steps and the subproblem's own
/// $x$-equation multipliers (where they are carried): [`Sqp::search`].
type Step<const N: usize, const X: usize> = (
    line_search::Accepted<N, X>,
    Vec<f64>,
    Option<Vec<SVector<f64, X>>>,
);

/// An iterate with its stage equalities' multipliers, its barrier and its carried
/// $x$-equation multipliers (where they are carried).
type Point<'s, const N: usize, const X: usize> = (
    &'s Iterate<N, X>,
    &'s [SVector<f64, N>],
    &'s Barrier,
    Option<&'s [SVector<f64, X>]>,
);

/// The error below which a full step's factorisation is kept for a simplified Newton step
/// at the next iterate.
const CHORD_ERROR: f64 = 1e-3;

/// Consecutive iterations at which the goal stays out of the subproblems' reach
/// ([`Sqp::unreachable_goal`]) before the solve ends with [`Failure::UnreachableGoal`]; where
/// the line search finds no step at such an iterate, it ends so at once
/// ([`Sqp::name_infeasibility`]).
const UNREACHABLE_ITERATIONS: usize = 5;

/// The consecutive iterations at the acceptable level after which a point is accepted there
/// (IPOPT's `acceptable_iter`): an iterate converged as far as the problem's conditioning
/// allows, whose steps no longer lower the error but are not rounding-sized either (a weakly
/// controllable system at large $N$), ends there instead of at the iteration limit.
const ACCEPTABLE_ITERATIONS: usize = 15;

/// The error below which a full Newton step that does not lower it turns on the
/// refinement check ([`Sqp::watch_refinement`]).
const REFINEMENT_WATCH: f64 = 1e-2;

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
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
            let warm = (floor, self.scale, &values[..]);
            Some(Barrier::warm(duals, layout, warm, vectors, self.dynamics.h))
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
    /// Where the iteration ends at a saddle ([`Failure::NotAMinimum`] with negative
    /// directions), it starts again from a point below it ([`Self::escape`]), cold, at most
    /// [`super::PlanOptions::saddle_escapes`] times (not in a real-time iteration); the
    /// plan's iterations count every start.
    pub(in crate::bvp) fn run(
        &self,
        iterate: Iterate<N, X>,
        warm: Option<&Duals<N>>,
    ) -> Result<(Plan<N, X>, bool), PlanError<N, X>> {
        let (mut iterate, mut warm, mut before, mut escapes) = (iterate, warm, 0, 0);
        loop {
            let escaping = escapes < self.options.saddle_escapes && !self.real_time;
            let (result, below) = self.run_once(iterate, warm, escaping);
            let Some(next) = below else {
                return Self::counting(result, before);
            };
            // the saddle's iterate goes back to the workspace, its iterations are counted
            if let Err(PlanError {
                last: Some(last), ..
            }) = result
            {
                before += last.iterations;
                self.give_plan(*last);
            }
            (iterate, warm) = (next, None);
            escapes += 1;
        }
    }

    /// `result` with `before` iterations of earlier starts added to its plan's.
    fn counting(result: Solved<N, X>, before: usize) -> Solved<N, X> {
        result
            .map(|(mut plan, certified)| {
                plan.iterations += before;
                (plan, certified)
            })
            .map_err(|mut error| {
                if let Some(last) = error.last.as_mut() {
                    last.iterations += before;
                }
                error
            })
    }

    /// One start of [`Self::run`] from `iterate`: its result and, if `escaping` and it ended
    /// at a saddle, the point below it that [`Self::escape`] found (none if not `escaping`).
    fn run_once(
        &self,
        iterate: Iterate<N, X>,
        warm: Option<&Duals<N>>,
        escaping: bool,
    ) -> (Solved<N, X>, Option<Iterate<N, X>>) {
        let Some(barrier) = self.initial_barrier(&iterate, warm) else {
            self.give_iterate(iterate);
            return (Err(PlanError::without_iterate(Failure::NonFinite)), None);
        };
        // (the stage equalities' multipliers: a warm start's, scaled, if they fit and are
        // finite, else 0; a plan read back from a file may hold any numbers)
        let finite = |y: &SVector<f64, N>| y.iter().all(|v| v.is_finite());
        let steps = iterate.u.len();
        let mut y = self.pool.borrow_mut().tops.take(steps);
        match warm.map(|duals| &duals.equalities) {
            Some(given) if given.len() == steps && given.iter().all(finite) => {
                y.extend(given.iter().map(|y| y * self.scale));
            }
            _ => y.resize(steps, SVector::zeros()),
        }
        let cold = warm.is_none();
        let adaptive = (self.options.barrier_update == BarrierUpdate::Adaptive
            && !barrier.s.is_empty())
        .then(|| Adaptive::new(self.pool.borrow_mut().pairs.take(16)));
        let mut state = State {
            iterate,
            y,
            mu: None,
            barrier,
            filter: None,
            full_step: None,
            kept: None,
            acceptable: None,
            adaptive,
        };
        if cold && state.adaptive.is_none() {
            self.first_barrier_test(&mut state);
        }
        let result = self.iterate_from(&mut state);
        let saddle = |e: &PlanError<N, X>| matches!(e.failure, Failure::NotAMinimum { negative_directions } if negative_directions > 0);
        let below = match &result {
            Err(error) if escaping && saddle(error) => self.escape(&state),
            _ => None,
        };
        self.release(state);
        (result, below)
    }

    /// IPOPT's first multipliers and its test of the barrier error before the first step of a
    /// cold solve: the multipliers start at IPOPT's least-squares estimate
    /// ([`Self::least_squares_multipliers`]: the stage equalities' in `st.y`, the
    /// $x$-equations' in `st.mu` ([`Self::first_step_multipliers`]), the inequalities'
    /// curvature weights in the barrier's $y$), or at 0 where that estimate is discarded; and $\mu$ is decreased ([`Barrier::decrease`]) while the
    /// barrier error with them is at most $10 \mu$. (The loop's own test then uses the
    /// multipliers carried from these, [`Self::carried_barrier_error`]; the subproblem's
    /// Newton multipliers, which it used before, are far larger at a first guess far from
    /// stationary: on parking-x0.4 of the constrained suite they gave 698 per unit time
    /// against the threshold 100, and $\mu$ stayed at $\mu_0$ for 35 iterations.)
    fn first_barrier_test(&self, st: &mut State<N, X>) {
        if st.barrier.s.is_empty() {
            return;
        }
        let Ok(models) = self.models(&st.iterate, &st.y, &st.barrier) else {
            return;
        };
        let Some((ls, y)) = self.least_squares_multipliers(&models, &st.barrier) else {
            st.barrier.y.iter_mut().for_each(|y| *y = 0.0);
            st.y.iter_mut().for_each(|y| *y = SVector::zeros());
            let mut mu = self.pool.borrow_mut().jets.take(models.stages.len());
            mu.resize(models.stages.len(), SVector::zeros());
            st.mu = Some(mu);
            self.give_models(models);
            return;
        };
        let barrier = &st.barrier;
        let (momenta, _, _) = self.residuals(&models, barrier, 0, &ls, &barrier.z);
        let floor = barrier_floor(self.options.tolerance);
        while st.barrier.mu > floor {
            let z = &st.barrier.z;
            let error = self.barrier_error(&models, &st.barrier, (&ls, None), (z, &momenta));
            if error > 10.0 * st.barrier.mu {
                break;
            }
            st.barrier.decrease(floor, self.dynamics.h);
        }
        for (y, first) in st.y.iter_mut().zip(&ls.multipliers) {
            *y = *first;
        }
        st.mu = Some(self.first_step_multipliers(&models, &st.barrier, &ls));
        let mut pool = self.pool.borrow_mut();
        pool.reals.give(core::mem::replace(&mut st.barrier.y, y));
        pool.jets.give(momenta);
        ls.recycle(&mut *pool);
        drop(pool);
        self.give_models(models);
    }

    /// Gives the vectors of the iteration's `state` back to the pool.
    fn release(&self, state: State<N, X>) {
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(state.iterate.x);
        pool.tops.give(state.iterate.u);
        pool.tops.give(state.y);
        if let Some(mu) = state.mu {
            pool.jets.give(mu);
        }
        for v in state.barrier.into_vectors() {
            pool.reals.give(v);
        }
        if let Some(filter) = state.filter {
            pool.pairs.give(filter.into_entries());
        }
        if let Some(adaptive) = state.adaptive {
            pool.pairs.give(adaptive.into_entries());
        }
        if let Some(direction) = state.full_step {
            direction.recycle(&mut *pool);
        }
        if let Some((riccati, _)) = state.kept {
            riccati.recycle(&mut *pool);
        }
        drop(pool);
        if let Some(kept) = state.acceptable {
            self.give_kept(kept);
        }
    }

    /// The iteration of [`Self::run`] from `st`: the plan and whether it is certified (if
    /// not, the iterate of a real-time iteration at its iteration limit).
    fn iterate_from(&self, st: &mut State<N, X>) -> Result<(Plan<N, X>, bool), PlanError<N, X>> {
        let options = &self.options;
        let floor = barrier_floor(options.tolerance);
        // (the last positive inertia correction, IPOPT's: the next one starts from a third of
        // it; and whether the last subproblem needed one)
        let (mut rho_last, mut corrected) = (0.0, false);
        let (mut penalty, mut iterations, mut stalled) = (0.0, 0, 0);
        let (mut progress, mut floor_stalled, mut unreachable) = (Progress::default(), 0, 0);
        // (consecutive iterations at the acceptable level: IPOPT's acceptable_iter count)
        let mut at_acceptable = 0;
        // (the error before the last full Newton step, for the refinement's trigger)
        let mut before_full: Option<f64> = None;
        let unconstrained = (self.at_steps.is_empty() && self.at_nodes.is_empty())
            && self.problem.equalities.is_empty();
        loop {
            st.choose_barrier(floor);
            let done = iterations;
            let point = (&st.iterate, &st.y[..], &st.barrier);
            let fail = |failure, cost, certificate, momenta| PlanError {
                failure,
                last: Some(Box::new(self.plan(point, cost, done, momenta, certificate))),
            };
            // after a full step the last subproblem's multipliers are the Newton estimates
            // here: if they already certify this point, no subproblem is solved at it
            if let Some(last) = st.full_step.take() {
                let plan = (!corrected)
                    .then(|| self.certify_without_solve(point, &last, iterations))
                    .flatten();
                last.recycle(&mut *self.pool.borrow_mut());
                if let Some(plan) = plan {
                    return Ok((plan, true));
                }
            }
            let at = (&st.iterate, &st.y[..], &st.barrier);
            let (models, sub) = match self.model_and_solve(at, st.kept.take(), rho_last) {
                Ok(pair) => pair,
                Err((failure, Some((cost, certificate)))) => {
                    return Err(fail(failure, cost, certificate, vec![]));
                }
                Err((failure, None)) => return Err(PlanError::without_iterate(failure)),
            };
            // (a subproblem solved again at this iterate, for a smaller mu, starts its inertia
            // correction where this one did, as IPOPT's single factorisation per iteration)
            let rho_before = rho_last;
            self.watch_refinement(before_full.take(), &sub);
            corrected = sub.rho > 0.0;
            if corrected {
                rho_last = sub.rho;
            }
            let goal = self.unreachable_goal(&models, &sub);
            match goal {
                Some((component, miss)) if unreachable + 1 >= UNREACHABLE_ITERATIONS => {
                    let failure = Failure::UnreachableGoal { component, miss };
                    let (cost, certificate, momenta) = self.hand_back(models, sub);
                    return Err(fail(failure, cost, certificate, momenta));
                }
                Some(_) => unreachable += 1,
                None => unreachable = 0,
            }
            // converged, or at the acceptable level with no progress left but rounding
            let complementarity = st.barrier.complementarity().0;
            let within = sub.error.max(complementarity) <= options.acceptable;
            at_acceptable = if within { at_acceptable + 1 } else { 0 };
            let acceptable = within && (stalled >= 3 || at_acceptable >= ACCEPTABLE_ITERATIONS);
            let converged = sub.error.max(complementarity) <= options.tolerance || acceptable;
            let at = (&models, &sub);
            if let Some(mu) = self.adapted(&mut st.adaptive, &st.barrier, at, converged) {
                st.set_barrier(mu);
                self.give_models(models);
                self.give_subproblem(sub);
                continue;
            }
            // the barrier problem solved to 10 mu (IPOPT's test, in absolute units; the
            // adaptive update's monotone mode)
            let monotone = st.adaptive.as_ref().is_none_or(|a| !a.free);
            let barrier_error = self.carried_barrier_error(st, &models, &sub);
            if monotone && st.barrier.mu > floor && barrier_error <= 10.0 * st.barrier.mu {
                self.decrease_barrier(st, sub.error);
                rho_last = rho_before;
                self.give_models(models);
                self.give_subproblem(sub);
                continue;
            }
            let sub = if (sub.error <= options.tolerance || acceptable) && st.barrier.mu <= floor {
                match self.finish(point, &models, sub, iterations) {
                    Finished::Plan(plan) => {
                        self.give_models(models);
                        return Ok((plan, true));
                    }
                    Finished::Failed(failure, certificate, sub) => {
                        let (cost, _, momenta) = self.hand_back(models, sub);
                        return Err(fail(failure, cost, certificate, momenta));
                    }
                    Finished::Not(sub) => sub,
                }
            } else {
                sub
            };
            if let Some(plan) =
                self.exit_at_kept(&mut st.acceptable, (floor_stalled, sub.error), iterations)
            {
                self.give_models(models);
                self.give_subproblem(sub);
                return Ok((plan, true));
            }
            let out_of_time = self.out_of_time();
            if iterations == options.max_iterations || out_of_time {
                return self.stop_at_limit(st, (models, sub), done, out_of_time);
            }
            iterations += 1;
            let at = (&st.iterate, &st.y[..], &st.barrier, st.mu.as_deref());
            let globals = (&mut st.filter, &mut penalty, &mut progress);
            let searched = self.search(at, (&models, &sub), globals);
            // (the restoration phases' Newton steps count as iterations)
            iterations = (iterations + progress.take_steps()).min(options.max_iterations);
            let step = match searched {
                Ok(step) => step,
                Err(Failure::LineSearch) if sub.stale => {
                    // the simplified direction failed: solve this iterate's own subproblem
                    iterations -= 1;
                    self.give_models(models);
                    self.give_subproblem(sub);
                    continue;
                }
                Err(failure) => {
                    let failure = self.name_infeasibility(failure, (&st.iterate, &models), goal);
                    let (cost, certificate, momenta) = self.hand_back(models, sub);
                    return Err(fail(failure, cost, certificate, momenta));
                }
            };
            let (alpha, at_rounding, plain) = self.take_step(st, step, &sub);
            self.give_models(models);
            stalled = if at_rounding { stalled + 1 } else { 0 };
            if at_rounding {
                // (a stall at rounding: the solve may be missing digits)
                self.check_refinement.set(true);
            }
            let at_floor = at_rounding && st.barrier.mu <= floor;
            floor_stalled = if at_floor { floor_stalled + 1 } else { 0 };
            let full = plain && alpha == 1.0;
            before_full = (full && !sub.stale).then_some(sub.error);
            self.carry(st, sub, full, unconstrained);
        }
    }

    /// Turns on the refinement check of every later subproblem ([`Sqp::check_refinement`])
    /// where a full Newton step from an error `before` below [`REFINEMENT_WATCH`] left the
    /// error of the new subproblem `sub` no lower: near a solution the step squares the
    /// error, unless the solve misses its own equations.
    fn watch_refinement(&self, before: Option<f64>, sub: &Subproblem<N, X>) {
        if let Some(before) = before
            && before <= REFINEMENT_WATCH
            && sub.error >= before
            && !sub.stale
        {
            self.check_refinement.set(true);
        }
    }

    /// The line search along the subproblem `sub` at the iterate of `models` (with the
    /// stage equalities' multipliers `y`, the barrier and the carried $x$-equation
    /// multipliers `mu` of the state; [`Self::line_search`] with the `globals` filter,
    /// penalty and progress): the accepted point with its slack steps and, where `mu` is
    /// carried, the subproblem's own ([`step_multipliers`], which it moves towards); or the
    /// failure, the vectors given back.
    fn search(
        &self,
        (iterate, y, barrier, mu): Point<'_, N, X>,
        (models, sub): (&Models<N, X>, &Subproblem<N, X>),
        globals: (&mut Option<Filter>, &mut f64, &mut Progress),
    ) -> Result<Step<N, X>, Failure> {
        let ds = self.pool.borrow_mut().reals.take(barrier.s.len());
        let theta = self.dynamics.theta;
        let ds = barrier.slack_steps(&models.inequalities, &sub.direction, theta, ds);
        let slacks = (barrier, &ds[..]);
        let factor = (!sub.stale).then_some((&sub.riccati, self.dynamics.h * sub.rho));
        let searched = (iterate, models, &sub.direction, factor);
        let target = mu.map(|_| {
            let mut target = self.pool.borrow_mut().jets.take(models.stages.len());
            let stages = &models.stages;
            step_multipliers(&self.dynamics, stages, &sub.direction, None, &mut target);
            target
        });
        let carried = mu.zip(target.as_deref());
        match self.line_search(searched, slacks, globals, (y, carried)) {
            Ok(accepted) => Ok((accepted, ds, target)),
            Err(failure) => {
                let mut pool = self.pool.borrow_mut();
                pool.reals.give(ds);
                if let Some(target) = target {
                    pool.jets.give(target);
                }
                Err(failure)
            }
        }
    }

    /// Moves `st` to the accepted point of `step` ([`Self::advance`] along `sub`'s
    /// direction), its carried $x$-equation multipliers towards the step's by its length
    /// ([`State::carry_multipliers`]); gives the step's vectors back. Returns as
    /// [`Self::advance`].
    fn take_step(
        &self,
        st: &mut State<N, X>,
        (accepted, ds, target): Step<N, X>,
        sub: &Subproblem<N, X>,
    ) -> (f64, bool, bool) {
        let restored = accepted.restored.is_some();
        let state = (&mut st.iterate, &mut st.barrier, &mut st.y[..]);
        let (alpha, at_rounding, plain) =
            self.advance(accepted, (&sub.direction, &ds, sub.rho), state);
        let mut pool = self.pool.borrow_mut();
        if let Some(target) = target {
            st.carry_multipliers(&target, (alpha, restored), &mut pool);
            pool.jets.give(target);
        }
        pool.reals.give(ds);
        (alpha, at_rounding, plain)
    }

    /// The end of a solve at its iteration limit or out of time (`out_of_time`) after `done`
    /// iterations: a real-time iteration's plan (not certified) at its iteration limit, else
    /// [`Failure::IterationLimit`] or [`Failure::TimeLimit`] with the iterate.
    fn stop_at_limit(
        &self,
        st: &State<N, X>,
        (models, mut sub): (Models<N, X>, Subproblem<N, X>),
        done: usize,
        out_of_time: bool,
    ) -> Result<(Plan<N, X>, bool), PlanError<N, X>> {
        let point = (&st.iterate, &st.y[..], &st.barrier);
        if self.real_time && !out_of_time {
            let momenta = core::mem::take(&mut sub.momenta);
            let plan = self.plan(point, models.cost, done, momenta, sub.certificate);
            self.give_models(models);
            self.give_subproblem(sub);
            return Ok((plan, false));
        }
        let failure = if out_of_time {
            Failure::TimeLimit
        } else {
            Failure::IterationLimit
        };
        let (cost, certificate, momenta) = self.hand_back(models, sub);
        Err(PlanError {
            failure,
            last: Some(Box::new(self.plan(point, cost, done, momenta, certificate))),
        })
    }

    /// IPOPT's barrier error $E_\mu$ at the current iterate with its carried multipliers
    /// (the stage equalities' `st.y`, the $x$-equations' `st.mu`, the inequality rows' $y$
    /// and $z$ of the barrier; [`Self::error_at_multipliers`]); where they are not carried,
    /// the subproblem's own (with the Newton multipliers, `sub.barrier_error`).
    fn carried_barrier_error(
        &self,
        st: &State<N, X>,
        models: &Models<N, X>,
        sub: &Subproblem<N, X>,
    ) -> f64 {
        let Some(mu) = &st.mu else {
            return sub.barrier_error;
        };
        self.error_at_multipliers(models, &st.barrier, (&st.y, mu))
    }

    /// The adaptive barrier update's new $\mu$ at the iterate of `models` and `sub`
    /// ([`Adaptive::test`] with its cost, violation, error and whether it `converged`; a
    /// changed $\mu$ changes the models, which are then formed again); `None` with the
    /// monotone update or where $\mu$ stays.
    fn adapted(
        &self,
        adaptive: &mut Option<Adaptive>,
        barrier: &Barrier,
        (models, sub): (&Models<N, X>, &Subproblem<N, X>),
        converged: bool,
    ) -> Option<f64> {
        // (the O(N) violation only with the adaptive update: the monotone one needs none)
        let adaptive = adaptive.as_mut()?;
        let point = (models.cost, models.violation_l1(), sub.error, converged);
        adaptive.test(barrier, point, barrier_floor(self.options.tolerance))
    }

    /// $\mu$ decreased at a point `st` where the barrier problem is solved (the filter reset
    /// with it), the point first kept for the acceptable-level exit if its `error`
    /// ($\max$(stationarity, feasibility)) is below the tolerance and its complementarity
    /// below the acceptable level ([`acceptable`]).
    fn decrease_barrier(&self, st: &mut State<N, X>, error: f64) {
        let complementarity = st.barrier.complementarity().0;
        if error <= self.options.tolerance && complementarity <= self.options.acceptable {
            let point = (&st.iterate, &st.y[..], &st.barrier);
            self.keep(point, &mut st.acceptable);
        }
        let floor = barrier_floor(self.options.tolerance);
        st.barrier.decrease(floor, self.dynamics.h);
        if let Some(filter) = &mut st.filter {
            filter.reset();
        }
    }

    /// What a step along the subproblem `sub`'s direction leaves for the next iterate: after
    /// a `full` step from an error below $\sqrt{\varepsilon}$, the direction (its multipliers
    /// are the Newton estimates at the new iterate); after a full step without correction
    /// from an error below `CHORD_ERROR` on an `unconstrained` problem (no stage
    /// constraints, whose projections change with the iterate), the factorisation, for one
    /// simplified Newton step.
    fn carry(&self, st: &mut State<N, X>, sub: Subproblem<N, X>, full: bool, unconstrained: bool) {
        let Subproblem {
            riccati,
            rho,
            stale,
            direction,
            momenta,
            error,
            ..
        } = sub;
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(momenta);
        // (worth trying when Newton's quadratic convergence will take the error from here
        // to below the tolerance)
        if full && error <= self.options.tolerance.sqrt() {
            st.full_step = Some(direction);
        } else {
            direction.recycle(&mut *pool);
        }
        if full && rho == 0.0 && !stale && unconstrained && error <= CHORD_ERROR {
            st.kept = Some((riccati, error));
        } else {
            riccati.recycle(&mut *pool);
        }
    }
}
