//! The solve front of [`OptimalControlProblem`]: [`OptimalControlProblem::solve`] and its
//! variants (in a [`Workspace`], real-time iterations), which check the problem and the
//! first guess, build the first iterate from the [`PlanGuess`] and run the SQP iteration
//! ([`super::sqp`]) on it.

use std::cell::Cell;
use std::time::Instant;

use nalgebra::SVector;

use super::dynamics::Dynamics;
use super::guess::Hermite;
use super::iterate::Iterate;
use super::options::{PlanGuess, PlanOptions};
use super::plan::{Failure, Plan, PlanError, RealTime};
use super::problem::OptimalControlProblem;
use super::sqp::Sqp;
use super::workspace::Workspace;
use crate::{Error, Lagrangian, LiftedSystem};

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'_, Sys, N, K, X>
{
    /// Solves the problem from `guess`.
    ///
    /// # Errors
    /// A [`PlanError`] with the [`Failure`] and, after the first iteration, the last iterate.
    /// Boundary jets that no guess can repair are refused before any iteration as
    /// [`Failure::Invalid`]: a start or goal outside the domain of the Lagrangian
    /// ([`Error::StartOutsideDomain`], [`Error::GoalOutsideDomain`]) or on the other side of
    /// one of its singularities than the other end, e.g. inside an obstacle
    /// ([`Error::BoundariesSeparated`]).
    pub fn solve<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
    ) -> Result<Plan<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        self.solve_with(guess, &mut Workspace::new())
    }

    /// [`Self::solve`] in `workspace`: the solve takes its vectors from there and leaves them
    /// there for the next one. The workspace grows until it holds as many vectors as a solve
    /// of the problem needs at once (a path that holds more, e.g. a refactorisation in the
    /// certificate beside the iteration's own, grows it once); from then on a solve allocates
    /// nothing, the plan it returns included, when the plans it replaces are given back
    /// ([`Workspace::recycle`]) and the problem is reused ([`Self::set_start`]). A failure
    /// allocates its report ([`PlanError::last`]):
    ///
    /// ```
    /// # use retract::bvp::{OptimalControlProblem, PlanGuess, Workspace};
    /// # #[retract::higher_order_lagrangian(order = 2)]
    /// # fn bend(q: [f64; 1], _dq: [f64; 1], ddq: [f64; 1]) -> f64 { 0.5 * ddq[0] * ddq[0] }
    /// let system = Bend::new();
    /// let mut problem = OptimalControlProblem::new(&system, &[0.0, 0.0], &[1.0, 0.0], 1.0, 20);
    /// let mut workspace = Workspace::new();
    /// let mut plan = problem.solve_with(PlanGuess::Spline, &mut workspace)?;
    /// for start in [0.01, 0.02, 0.03] {
    ///     problem.set_start(&[start, 0.0]);
    ///     let next = problem.solve_with(PlanGuess::Plan(&plan), &mut workspace)?;
    ///     workspace.recycle(std::mem::replace(&mut plan, next));
    /// }
    /// # Ok::<(), retract::bvp::PlanError<1, 2>>(())
    /// ```
    ///
    /// # Errors
    /// As [`Self::solve`].
    pub fn solve_with<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
        workspace: &mut Workspace<N, X>,
    ) -> Result<Plan<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let solved = self.solve_under(guess, workspace, (self.options, false));
        solved.map(|(plan, _)| plan)
    }

    /// [`Self::solve_with`] under `options` (the problem's but for the iteration limit and
    /// the eigenvalue of a real-time iteration, `real_time`): the plan and whether it is
    /// certified (if not, a real-time iteration's iterate at its iteration limit).
    fn solve_under<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
        workspace: &mut Workspace<N, X>,
        (options, real_time): (PlanOptions, bool),
    ) -> Result<(Plan<N, X>, bool), PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let started = Instant::now();
        self.check_problem::<S, M>()?;
        let warm = match guess {
            PlanGuess::Plan(plan) => Some(&plan.duals),
            _ => None,
        };
        let iterate = self.first_iterate::<S, M>(guess, workspace)?;
        let placed = self.placed();
        let mut sqp = Sqp::<Sys, N, K, X, S, M> {
            problem: self,
            dynamics: Dynamics::new(self.h(), self.options.theta),
            started,
            at_steps: &placed.at_steps,
            at_nodes: &placed.at_nodes,
            violation_weights: (&placed.violation_weights.0, &placed.violation_weights.1),
            pool: &workspace.pool,
            options,
            real_time,
            scale: 1.0,
            check_refinement: Cell::new(false),
        };
        if !real_time {
            sqp.scale = sqp.objective_scale(&iterate);
        }
        sqp.run(iterate, warm)
    }

    /// The checks of a problem before any iterate: its data, the workspace's size, the
    /// system's form and parameters, the stage systems, and the contradictions and end
    /// violations of its constraints.
    ///
    /// # Errors
    /// [`Failure::Invalid`] or [`Failure::Infeasible`], without an iterate.
    pub(super) fn check_problem<const S: usize, const M: usize>(
        &self,
    ) -> Result<(), PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let invalid = |e| PlanError {
            failure: Failure::Invalid(e),
            last: None,
        };
        self.validate(N, K).map_err(invalid)?;
        self.check_workspace_fits().map_err(invalid)?;
        if S != 2 * X || M != S + N {
            return Err(invalid(Error::InvalidArgument {
                name: "system",
                requirement: "the optimizer needs the general unknowns w = (z_1, u)",
            }));
        }
        self.system.check_parameters().map_err(invalid)?;
        if self.bad_free_component {
            return Err(invalid(Error::InvalidArgument {
                name: "free end or start",
                requirement: "components of the jet x_N or x_0: indices below n k",
            }));
        }
        if let Some(systems) = self.stage_systems {
            if systems.len() != self.steps {
                return Err(invalid(Error::InvalidArgument {
                    name: "stage systems",
                    requirement: "one system per step",
                }));
            }
            for system in systems {
                system.check_parameters().map_err(invalid)?;
            }
        }
        if let Some(infeasibility) = self.contradiction().or_else(|| self.ends_violation()) {
            return Err(PlanError {
                failure: Failure::Infeasible(infeasibility),
                last: None,
            });
        }
        Ok(())
    }

    /// The first iterate from `guess` (vectors from `workspace`), checked: finite, a terminal
    /// cost of the jet alone, boundary jets in the domain and the guess inside it.
    ///
    /// # Errors
    /// [`Failure::Invalid`] or [`Failure::GuessOutsideDomain`], without an iterate.
    pub(super) fn first_iterate<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
        workspace: &mut Workspace<N, X>,
    ) -> Result<Iterate<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let invalid = |e| PlanError {
            failure: Failure::Invalid(e),
            last: None,
        };
        let mut iterate = {
            let pool = workspace.pool.get_mut();
            Iterate {
                x: pool.jets.take(self.steps + 1),
                u: pool.tops.take(self.steps),
            }
        };
        self.initial(guess, &mut iterate).map_err(invalid)?;
        self.check_terminal_cost(&iterate).map_err(invalid)?;
        self.check_ends::<S, M>(&iterate).map_err(invalid)?;
        if let Err((step, violation)) = self.guard::<S, M>(&iterate) {
            return Err(PlanError {
                failure: Failure::GuessOutsideDomain { step, violation },
                last: None,
            });
        }
        Ok(iterate)
    }

    /// Real-time iteration for receding horizons (as acados' RTI): at most `iterations` SQP
    /// iterations from `guess` (typically [`Plan::shifted`] of the last plan), whatever the
    /// residuals then. The result says whether the plan is a certified minimum
    /// ([`RealTime::converged`]); if not, its certificate holds the residuals reached. The
    /// smallest reduced-Hessian eigenvalue is not computed ([`PlanOptions::min_eigenvalue`]).
    ///
    /// # Errors
    /// As [`Self::solve`], except that running out of iterations is not an error.
    pub fn solve_real_time<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
        iterations: usize,
    ) -> Result<RealTime<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        self.solve_real_time_with(guess, iterations, &mut Workspace::new())
    }

    /// [`Self::solve_real_time`] in `workspace` (as [`Self::solve_with`]: a re-solve of the
    /// same problem allocates nothing once the workspace has served one).
    ///
    /// # Errors
    /// As [`Self::solve_real_time`].
    pub fn solve_real_time_with<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
        iterations: usize,
        workspace: &mut Workspace<N, X>,
    ) -> Result<RealTime<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let mut capped = self.options;
        capped.max_iterations = iterations.max(1);
        // (a receding horizon needs the plan now, not its curvature)
        capped.min_eigenvalue = false;
        let (plan, converged) = self.solve_under(guess, workspace, (capped, true))?;
        Ok(RealTime { plan, converged })
    }

    /// The bytes the solve will hold at once, about: per step, three stage models (the
    /// iterate's, a copy in the second-order check and its penalised copy), the
    /// factorisation, the iterate and a trial point, the direction and the momenta, and each
    /// inequality's linearisation, slack and multiplier.
    fn workspace_bytes(&self) -> usize {
        use core::mem::size_of;
        let per_step = 3 * size_of::<super::kkt::model::StageModel<N, X>>()
            + super::kkt::riccati::Riccati::<N, X>::bytes_per_step()
            + 8 * size_of::<SVector<f64, X>>()
            + 6 * size_of::<SVector<f64, N>>()
            + 2 * self.inequalities.len()
                * (size_of::<super::constraints::Linearized<N, X>>() + 4 * size_of::<f64>());
        per_step.saturating_mul(self.steps + 1)
    }

    /// Refuses a problem whose workspace ([`Self::workspace_bytes`]) the allocator will not
    /// give, before anything is allocated for it: the reservation is tried once and released
    /// (a solve that fails to allocate would abort the process instead of returning).
    /// (Below 64 MiB no probe is made: it would cost a re-plan in a receding horizon an
    /// allocation of the whole size for nothing.)
    fn check_workspace_fits(&self) -> Result<(), Error> {
        let bytes = self.workspace_bytes();
        if bytes < 1 << 26 {
            return Ok(());
        }
        let mut probe: Vec<u8> = Vec::new();
        probe
            .try_reserve_exact(bytes)
            .map_err(|_| Error::InvalidArgument {
                name: "steps",
                requirement: "the optimizer's workspace (about 3 stage models and a \
                              factorisation per step) must fit in memory: fewer steps",
            })
    }

    /// The first iterate from `guess`, into `iterate` (empty vectors).
    fn initial(
        &self,
        guess: PlanGuess<'_, N, X>,
        iterate: &mut Iterate<N, X>,
    ) -> Result<(), Error> {
        let (h, theta, steps) = (self.h(), self.options.theta, self.steps);
        let wrong = |requirement| Error::InvalidArgument {
            name: "guess",
            requirement,
        };
        match guess {
            PlanGuess::Spline => {
                let spline = Hermite::new(
                    self.start.as_slice(),
                    self.goal.as_slice(),
                    self.t_end,
                    N,
                    K,
                )?;
                (iterate.x).extend(
                    (0..=steps).map(|i| SVector::from_fn(|r, _| spline.jet_entry(r, i as f64 * h))),
                );
                iterate.u.extend((0..steps).map(|i| {
                    let t = (i as f64 + theta) * h;
                    SVector::from_fn(|a, _| spline.derivative(a, K, t))
                }));
            }
            PlanGuess::Plan(plan) => {
                if plan.x.len() != steps + 1 || plan.u.len() != steps {
                    return Err(wrong(
                        "a warm start needs a plan with the same number of steps",
                    ));
                }
                iterate.x.extend_from_slice(&plan.x);
                iterate.u.extend_from_slice(&plan.u);
            }
            PlanGuess::Curve(curve) => *iterate = curve.sample::<K, X>(self.t_end, steps, theta)?,
            PlanGuess::Path { x, u } => {
                if x.len() != steps + 1 || u.len() != steps {
                    return Err(wrong("a path guess needs N + 1 jets and N top derivatives"));
                }
                iterate.x.extend_from_slice(x);
                iterate.u.extend_from_slice(u);
            }
        }
        let finite = |v: &[f64]| v.iter().all(|e| e.is_finite());
        if !iterate.x.iter().all(|v| finite(v.as_slice()))
            || !iterate.u.iter().all(|v| finite(v.as_slice()))
        {
            return Err(wrong("the guess must be finite"));
        }
        Ok(())
    }
}
