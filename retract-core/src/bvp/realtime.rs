//! Real-time iterations in two phases, as acados' RTI ([`RealTimeIteration`]): a preparation
//! that linearises and factorises the subproblem at the iterate before the new start is
//! measured ([`OptimalControlProblem::prepare`]), and a feedback that embeds the measured
//! start and takes one full Newton step ([`OptimalControlProblem::feedback`]), so that the
//! first input after a disturbance already answers it.

use std::cell::Cell;
use std::time::Instant;

use nalgebra::SVector;

use super::constraints::{Inequality, Source, Variable};
use super::dynamics::Dynamics;
use super::iterate::Iterate;
use super::options::PlanGuess;
use super::plan::{Failure, PlanError};
use super::problem::OptimalControlProblem;
use super::sqp::{Linearization, Sqp};
use super::workspace::Workspace;
use crate::{Error, Lagrangian, LiftedSystem};

/// The state of a real-time iteration (Diehl, Bock and Schlöder 2005; acados' RTI) on one
/// [`OptimalControlProblem`]: the iterate (jets $x_i$, top derivatives $u_i$, the stage
/// equalities' multipliers), the subproblem prepared at it, and the workspace its vectors
/// come from (a period allocates nothing once the first has sized it).
///
/// Each control period:
/// 1. [`OptimalControlProblem::feedback`] with the measured start $a$: the subproblem
///    prepared at the iterate, with $\delta x_0 = a - x_0$, solved by the forward pass of its
///    Riccati factorisation, and the full step taken (no line search). The input to apply is
///    the new iterate's first ([`Self::x`], [`Self::u`]). Optionally more iterations:
///    [`OptimalControlProblem::prepare`] and `feedback` again with the same start.
/// 2. [`Self::shift`] (the iterate one period on) and [`OptimalControlProblem::prepare`]
///    (models, factorisation and the backward pass of the solve at the shifted iterate,
///    none of which needs the next start), while the system moves.
///
/// [`OptimalControlProblem::control`] makes step 1 a safeguarded control period: it chooses
/// the input to apply (the re-plan's, or the shifted plan's when the re-plan failed), clamps
/// it to the problem's bounds on the top derivative and says how it was chosen
/// ([`ControlStatus`](super::ControlStatus)).
///
/// The full step of the tangential predictor is a Newton step of the KKT conditions with the
/// start as a parameter: from an iterate that solves the problem for the predicted start $a$
/// it is, to first order in the change of $a$, the solution for the measured one.
///
/// ```
/// use retract_core::bvp::{OptimalControlProblem, PlanGuess};
/// use retract_core::models::PlanarBarrier;
///
/// // quadratic cost, linear dynamics: one feedback step from any iterate is the minimum
/// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
/// let goal = [3.0, 1.0, 0.0, 0.0];
/// let problem = OptimalControlProblem::new(&system, &[2.0, 0.0, 0.0, 0.0], &goal, 1.0, 40);
/// let mut rti = problem.real_time_iteration(PlanGuess::Spline)?;
/// problem.prepare(&mut rti)?;
/// let measured = [2.1, 0.0, 0.5, 0.0];
/// problem.feedback(&mut rti, &measured)?;
/// let moved = OptimalControlProblem::new(&system, &measured, &goal, 1.0, 40);
/// let plan = moved.solve(PlanGuess::Spline)?;
/// for (a, b) in rti.x().iter().zip(&plan.x) {
///     assert!((a - b).amax() < 1e-9);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct RealTimeIteration<const N: usize, const X: usize> {
    pub(super) iterate: Iterate<N, X>,
    /// The stage equalities' multipliers.
    pub(super) y: Vec<SVector<f64, N>>,
    pub(super) linearization: Option<Linearization<N, X>>,
    /// The inertia correction of the last preparation.
    pub(super) rho: f64,
    h: f64,
    theta: f64,
    pub(super) workspace: Workspace<N, X>,
}

/// What a preparation found at the iterate: the largest constraint violation there (the
/// dynamics' defects, the stage equalities, the goal's miss and the start's against the
/// problem's start), the cost $J$, and the inertia correction $\rho$ the factorisation needed
/// (0: the reduced Hessian is positive definite at the iterate).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preparation {
    /// $\Vert c\Vert_\infty$ at the iterate.
    pub violation: f64,
    /// $J$ at the iterate.
    pub cost: f64,
    /// The inertia correction $\rho$ ($h \rho I$ added to every stage Hessian).
    pub regularization: f64,
}

/// What a feedback step did: the size of the step $\max_i \max(\Vert\delta
/// x_i\Vert_\infty, \Vert\delta u_i\Vert_\infty)$ and of the start's change $\Vert a -
/// x_0\Vert_\infty$ it embedded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Feedback {
    /// The step's largest entry.
    pub step: f64,
    /// The start's change.
    pub start_change: f64,
}

impl<const N: usize, const X: usize> RealTimeIteration<N, X> {
    /// The iterate's jets $x_0, \dots, x_N$.
    pub fn x(&self) -> &[SVector<f64, X>] {
        &self.iterate.x
    }

    /// The iterate's top derivatives $u_0, \dots, u_{N-1}$.
    pub fn u(&self) -> &[SVector<f64, N>] {
        &self.iterate.u
    }

    /// Moves the iterate one step on in time, as [`super::Plan::try_shift`]: $x_i \leftarrow
    /// x_{i+1}$, $u_i \leftarrow u_{i+1}$, the last top derivative (and multiplier) repeated
    /// and the new last jet one step of the scheme's $x$-equations from the old one. The
    /// prepared subproblem is dropped (prepare at the shifted iterate). No allocation.
    pub fn shift(&mut self) {
        self.drop_linearization();
        let (Some(&last_x), Some(&last_u)) = (self.iterate.x.last(), self.iterate.u.last()) else {
            return;
        };
        let next = Dynamics::<N, X>::new(self.h, self.theta).next(&last_x, &last_u);
        self.iterate.x.remove(0);
        self.iterate.x.push(next);
        self.iterate.u.remove(0);
        self.iterate.u.push(last_u);
        if let Some(&last_y) = self.y.last() {
            self.y.remove(0);
            self.y.push(last_y);
        }
    }

    /// Gives the prepared subproblem's vectors back to the workspace.
    fn drop_linearization(&mut self) {
        if let Some(lin) = self.linearization.take() {
            let pool = self.workspace.pool.get_mut();
            lin.prepared.recycle(pool);
            lin.riccati.recycle(pool);
        }
    }
}

impl<const N: usize, const X: usize> core::fmt::Debug for RealTimeIteration<N, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("RealTimeIteration")
            .field("steps", &self.iterate.u.len())
            .field("prepared", &self.linearization.is_some())
            .field("regularization", &self.rho)
            .finish_non_exhaustive()
    }
}

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// A real-time iteration of this problem from `guess` (typically the plan of a full solve,
    /// [`PlanGuess::Plan`], with its multipliers), not yet prepared. Problems with stage
    /// equalities, and inequalities only as bounds on the top derivative
    /// ([`Self::with_input_bounds`], [`Self::with_bounds`] on [`Variable::Top`]): the full step
    /// of the feedback phase has no fraction-to-the-boundary rule for slacks, so the subproblem
    /// does not see the bounds; they bound the input a control period applies, which is
    /// clamped to them ([`Self::control`], [`Self::clamp_input`]), while the iterate's later
    /// inputs may lie outside.
    ///
    /// # Errors
    /// As [`Self::solve`] before its first iteration; [`Failure::Invalid`] for a problem with
    /// other inequalities (on functions or on the jet).
    pub fn real_time_iteration<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
    ) -> Result<RealTimeIteration<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        self.check_problem::<S, M>()?;
        let input_bound =
            |c: &Inequality<'a, N, K>| matches!(c.source, Source::Variable(Variable::Top(_)));
        if !self.inequalities.iter().all(input_bound) {
            return Err(PlanError::without_iterate(Failure::Invalid(
                Error::InvalidArgument {
                    name: "problem",
                    requirement: "a real-time iteration takes full steps: stage equalities and \
                                  bounds on the top derivative, no other inequalities",
                },
            )));
        }
        let mut workspace = Workspace::new();
        let warm = match guess {
            PlanGuess::Plan(plan) => Some(&plan.duals.equalities),
            _ => None,
        };
        let iterate = self.first_iterate::<S, M>(guess, &mut workspace)?;
        let finite = |y: &SVector<f64, N>| y.iter().all(|v| v.is_finite());
        let mut y = workspace.pool.get_mut().tops.take(self.steps);
        match warm {
            Some(given) if given.len() == self.steps && given.iter().all(finite) => {
                y.extend_from_slice(given);
            }
            _ => y.resize(self.steps, SVector::zeros()),
        }
        Ok(RealTimeIteration {
            iterate,
            y,
            linearization: None,
            rho: 0.0,
            h: self.h(),
            theta: self.options.theta,
            workspace,
        })
    }

    /// The preparation phase of `rti`: the models of every stage at its iterate, the
    /// inertia-corrected Riccati factorisation of the subproblem and the backward pass of its
    /// solve (what does not depend on $\delta x_0$), kept for [`Self::feedback`].
    ///
    /// # Errors
    /// [`Failure::NonFinite`] (a model value not finite at the iterate),
    /// [`Failure::Regularization`] (no inertia correction makes the reduced Hessian
    /// definite), [`Failure::TimeLimit`] ([`super::PlanOptions::max_time`]); `rti` is then
    /// left unprepared.
    pub fn prepare<const S: usize, const M: usize>(
        &self,
        rti: &mut RealTimeIteration<N, X>,
    ) -> Result<Preparation, Failure>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        rti.drop_linearization();
        let lin = self
            .sqp::<S, M>(&rti.workspace)
            .linearize(&rti.iterate, &rti.y, rti.rho)?;
        rti.rho = lin.rho;
        let preparation = Preparation {
            violation: lin.violation,
            cost: lin.cost,
            regularization: lin.rho,
        };
        rti.linearization = Some(lin);
        Ok(preparation)
    }

    /// The feedback phase of `rti` from the measured `start` (the jets of [`Self::new`]'s
    /// start): the full Newton step of the prepared subproblem with $\delta x_0 = $ `start`
    /// $- x_0$ on the fixed start components, applied to the iterate, whose first input
    /// $u_0$ (and jets $x_0$, $x_1$) is then the one to apply. The preparation is used up
    /// (prepare again for a second iteration from the same start).
    ///
    /// # Errors
    /// [`Failure::Invalid`] if `rti` is not prepared, [`Failure::NonFinite`] if the step is
    /// not finite (the iterate is left unchanged).
    pub fn feedback<const S: usize, const M: usize>(
        &self,
        rti: &mut RealTimeIteration<N, X>,
        start: &[f64; X],
    ) -> Result<Feedback, Failure>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let Some(lin) = rti.linearization.as_ref() else {
            return Err(Failure::Invalid(Error::InvalidArgument {
                name: "real-time iteration",
                requirement: "prepared (OptimalControlProblem::prepare) before its feedback",
            }));
        };
        let start = SVector::from_column_slice(start);
        let state = (&mut rti.iterate, &mut rti.y[..]);
        let step = (self.sqp::<S, M>(&rti.workspace)).feedback(lin, &start, state);
        rti.drop_linearization();
        let step = step?;
        Ok(Feedback {
            step: step.size,
            start_change: step.start_change,
        })
    }

    /// The SQP iteration's phases over `workspace`, with the problem's options and without
    /// its inequalities (bounds on the top derivative, which clamp the applied input only).
    pub(super) fn sqp<'s, const S: usize, const M: usize>(
        &'s self,
        workspace: &'s Workspace<N, X>,
    ) -> Sqp<'s, 'a, Sys, N, K, X, S, M>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        Sqp {
            problem: self,
            dynamics: Dynamics::new(self.h(), self.options.theta),
            started: Instant::now(),
            at_steps: &[],
            at_nodes: &[],
            violation_weights: (&[], &[]),
            pool: &workspace.pool,
            options: self.options,
            real_time: true,
            scale: 1.0,
            check_refinement: Cell::new(false),
        }
    }
}
