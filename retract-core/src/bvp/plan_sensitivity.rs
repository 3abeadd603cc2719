//! Sensitivities of a plan of a full solve, with its inequalities: the KKT system factorised
//! at the plan ([`OptimalControlProblem::sensitivities`], [`PlanSensitivities`]), its forward
//! directions in the start and in a parameter of the Lagrangian, and the adjoint (the
//! gradient of one function of the plan in the start and in several parameters, by one
//! solve).
//!
//! The system is the KKT system of the problem with the plan's active inequalities as
//! equalities and the inactive ones dropped, which at a solution with strict complementarity
//! has the plan's derivative as its solution (the module `sqp::at_solution`: the active
//! inequalities as penalties in the factorisation, held exactly by the method of
//! multipliers). Each solve is refined twice.

use std::cell::Cell;
use std::time::Instant;

use nalgebra::SVector;

use super::barrier::Slot;
use super::dynamics::Dynamics;
use super::iterate::Iterate;
use super::kkt::model::StageModel;
use super::kkt::refine::{refine, start_multiplier};
use super::kkt::riccati::Direction;
use super::plan::{Failure, Plan};
use super::problem::OptimalControlProblem;
use super::sensitivity::{Parameter, ParameterSensitivity, ParameterTerms, Sensitivity};
use super::sqp::{AtSolution, Sqp};
use super::workspace::Workspace;
use crate::{Error, Lagrangian, LiftedSystem};

/// The refinement steps of each solve.
const REFINEMENTS: usize = 2;

/// The relative size of $\nabla g_k^T \delta y$ below which the active inequalities count
/// as held, and the most solves of the method of multipliers.
const HELD: f64 = 1e-14;
const MULTIPLIER_UPDATES: usize = 6;

/// The gradient of a scalar function $\varphi$ of a plan: $\partial \varphi / \partial x_i$
/// ($i = 0, \dots, N$) and $\partial \varphi / \partial u_i$ ($i < N$).
#[derive(Clone, Copy, Debug)]
pub struct PlanGradient<'g, const N: usize, const X: usize> {
    /// $\partial \varphi / \partial x_i$.
    pub x: &'g [SVector<f64, X>],
    /// $\partial \varphi / \partial u_i$.
    pub u: &'g [SVector<f64, N>],
}

/// The gradient of a function $\varphi$ of a plan with respect to the start and to
/// parameters ([`PlanSensitivities::adjoint`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Adjoint<const X: usize> {
    /// $d\varphi / da$ for the start $a$ (zero on its free components).
    pub start: SVector<f64, X>,
    /// $d\varphi / dp_j$ for each parameter given.
    pub parameters: Vec<f64>,
}

/// The KKT system of a problem factorised at one of its plans, for the plan's derivatives
/// ([`OptimalControlProblem::sensitivities`]): with respect to the start
/// ([`Self::start`]), to a parameter of the Lagrangian and the stage equalities
/// ([`Self::parameter`]), and the gradient of one function of the plan in the start and in
/// several parameters at once ([`Self::adjoint`]). The plan may hold active inequalities (at
/// a solution with strict complementarity, where the active set does not change locally).
pub struct PlanSensitivities<'p, 'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize> {
    problem: &'p OptimalControlProblem<'a, Sys, N, K, X>,
    iterate: Iterate<N, X>,
    /// The stage equalities' multipliers.
    y: Vec<SVector<f64, N>>,
    at: AtSolution<N, X>,
    workspace: Workspace<N, X>,
}

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize> core::fmt::Debug
    for PlanSensitivities<'_, '_, Sys, N, K, X>
{
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PlanSensitivities")
            .field("steps", &self.iterate.u.len())
            .finish_non_exhaustive()
    }
}

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// The KKT system of this problem factorised at `plan`, a plan of it (its solve's, to a
    /// tight tolerance for accurate derivatives), for [`PlanSensitivities`]: the Hessian of
    /// the Lagrangian at the plan (with the stage equalities' and the inequalities'
    /// multipliers), the inequalities active at the plan ($s < z$ in its [`super::Duals`])
    /// held as equalities and the inactive ones dropped, and its Riccati factorisation.
    ///
    /// # Errors
    /// [`Failure::Invalid`] for a plan that is not one of this problem's (steps, $h$,
    /// $\theta$, multipliers and duals that do not fit); [`Failure::WeaklyActive`] where an
    /// inequality is weakly active (slack and multiplier within a factor 100 of each other: the plan
    /// is not differentiable there); [`Failure::NotAMinimum`] if the reduced Hessian is not
    /// positive definite without correction (not a strict local minimum);
    /// [`Failure::NonFinite`].
    pub fn sensitivities<'p, const S: usize, const M: usize>(
        &'p self,
        plan: &Plan<N, X>,
    ) -> Result<PlanSensitivities<'p, 'a, Sys, N, K, X>, Failure>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        plan.validate().map_err(Failure::Invalid)?;
        self.check_problem::<S, M>().map_err(|e| e.failure)?;
        let h = self.h();
        let fits = plan.u.len() == self.steps
            && (plan.h - h).abs() <= 1e-12 * h
            && plan.theta == self.options.theta
            && plan.duals.equalities.len() == self.steps
            && (plan.duals.equalities.iter()).all(|y| y.iter().all(|v| v.is_finite()));
        if !fits {
            return Err(Failure::Invalid(Error::InvalidArgument {
                name: "plan",
                requirement: "a plan of this problem: its steps, h, theta and the stage \
                              equalities' multipliers",
            }));
        }
        let iterate = Iterate {
            x: plan.x.clone(),
            u: plan.u.clone(),
        };
        let y = plan.duals.equalities.clone();
        let workspace = Workspace::new();
        let placed = self.placed();
        let at = Sqp::<Sys, N, K, X, S, M> {
            problem: self,
            dynamics: Dynamics::new(h, self.options.theta),
            started: Instant::now(),
            at_steps: &placed.at_steps,
            at_nodes: &placed.at_nodes,
            violation_weights: (&placed.violation_weights.0, &placed.violation_weights.1),
            pool: &workspace.pool,
            options: self.options,
            real_time: false,
            // (the plan's multipliers are unscaled: so is the cost here)
            scale: 1.0,
            check_refinement: Cell::new(false),
        }
        .at_solution(&iterate, &y, &plan.duals)?;
        Ok(PlanSensitivities {
            problem: self,
            iterate,
            y,
            at,
            workspace,
        })
    }
}

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    PlanSensitivities<'_, '_, Sys, N, K, X>
{
    /// The derivative of the plan along `direction` of its start:
    /// $(\partial x_i / \partial a\thinspace d, \partial u_i / \partial a\thinspace d)$ for
    /// $d = $ `direction` (its free start components ignored): the KKT system solved with
    /// $\delta x_0 = d$ and no other right-hand side.
    ///
    /// # Errors
    /// [`Failure::NonFinite`] if the result is not finite.
    pub fn start(&self, direction: &[f64; X]) -> Result<Sensitivity<N, X>, Failure> {
        let fixed = &self.problem.fixed_start;
        let d = SVector::<f64, X>::from_column_slice(direction).component_mul(fixed);
        let (solved, stages) = self.solve(|_, _| {}, &d, &SVector::zeros());
        let result = (solved.dx.clone(), solved.du.clone());
        self.give(solved, stages);
        let finite = |v: &[f64]| v.iter().all(|e| e.is_finite());
        let all_finite = (result.0.iter()).all(|v| finite(v.as_slice()))
            && (result.1.iter()).all(|v| finite(v.as_slice()));
        if !all_finite {
            return Err(Failure::NonFinite);
        }
        Ok(result)
    }

    /// The derivative of the plan with respect to `parameter`: the KKT system solved with,
    /// at each step's $(x_{\theta,i}, u_i)$, the stage gradient $h \nabla \partial L /
    /// \partial p + \sum_j y_{ij} \nabla \partial g_j / \partial p$ and the constraint values
    /// $\partial g_j / \partial p$ as its right-hand side (the implicit function theorem):
    /// $(\partial x_i / \partial p, \partial u_i / \partial p)$; and $dJ/dp = \sum_i
    /// (h\thinspace \partial L / \partial p + y_i^T \partial g / \partial p)$ (the envelope
    /// theorem; the inequalities do not depend on $p$).
    ///
    /// # Errors
    /// [`Failure::Invalid`] if `parameter.equalities` is neither empty nor one per stage
    /// equality; [`Failure::NonFinite`] if the result is not finite.
    pub fn parameter(
        &self,
        parameter: &Parameter<'_, N, K>,
    ) -> Result<ParameterSensitivity<N, X>, Failure> {
        self.problem.check_parameter(parameter.equalities)?;
        let fill = |i: usize, stage: &mut StageModel<N, X>| {
            let terms = self.terms(i, parameter);
            (stage.gx, stage.gu, stage.value) = (terms.gx, terms.gu, terms.constraint);
        };
        let zero = SVector::zeros();
        let (solved, stages) = self.solve(fill, &zero, &zero);
        let steps = self.iterate.u.len();
        let sensitivity = ParameterSensitivity {
            x: solved.dx.clone(),
            u: solved.du.clone(),
            cost: (0..steps).map(|i| self.terms(i, parameter).cost).sum(),
        };
        self.give(solved, stages);
        sensitivity.checked()
    }

    /// The adjoint: the gradient of a function $\varphi$ of the plan, given its gradient
    /// `gradient` at the plan, with respect to the start $a$ and to each of `parameters`, by
    /// one solve of the (symmetric) KKT system $K$: $K w = -(\nabla \varphi, 0)$, then
    /// $d\varphi / dp = w^T F_p$ for the right-hand side $F_p$ of each parameter's forward
    /// solve ([`Self::parameter`]: $\sum_i \delta x_i^T l_{x,i} + \delta u_i^T l_{u,i} +
    /// \nu_i^T \partial g / \partial p$) and $d\varphi / da$ the multiplier of the start
    /// condition in $w$ (the stationarity at $x_0$ that it takes up). The same as
    /// $\nabla\varphi^T$ times each forward direction, at the cost of one solve for any
    /// number of parameters and start components.
    ///
    /// # Errors
    /// [`Failure::Invalid`] if `gradient` does not have $N + 1$ jets and $N$ top derivatives
    /// or is not finite, or a parameter's equalities do not fit ([`Self::parameter`]);
    /// [`Failure::NonFinite`] if the result is not finite.
    pub fn adjoint(
        &self,
        gradient: PlanGradient<'_, N, X>,
        parameters: &[Parameter<'_, N, K>],
    ) -> Result<Adjoint<X>, Failure> {
        let steps = self.iterate.u.len();
        let finite = |v: &[f64]| v.iter().all(|e| e.is_finite());
        let fits = gradient.x.len() == steps + 1
            && gradient.u.len() == steps
            && (gradient.x.iter()).all(|v| finite(v.as_slice()))
            && (gradient.u.iter()).all(|v| finite(v.as_slice()));
        if !fits {
            return Err(Failure::Invalid(Error::InvalidArgument {
                name: "gradient",
                requirement: "N + 1 jets and N top derivatives, finite",
            }));
        }
        for parameter in parameters {
            self.problem.check_parameter(parameter.equalities)?;
        }
        let fill = |i: usize, stage: &mut StageModel<N, X>| {
            stage.gu = gradient.u[i];
            let hessian = stage.node.map_or_else(nalgebra::SMatrix::zeros, |n| n.0);
            stage.node = Some((hessian, gradient.x[i]));
        };
        let zero = SVector::zeros();
        let (w, stages) = self.solve(fill, &zero, &gradient.x[steps]);
        let dynamics = self.dynamics();
        let start =
            start_multiplier(&dynamics, &stages[0], &w).component_mul(&self.problem.fixed_start);
        let along = |parameter: &Parameter<'_, N, K>| {
            (0..steps)
                .map(|i| {
                    let linear = self.terms(i, parameter).linear(&dynamics);
                    w.dx[i].dot(&linear.lx)
                        + w.du[i].dot(&linear.lu)
                        + w.multipliers[i].dot(&linear.constraint)
                })
                .sum::<f64>()
        };
        let adjoint = Adjoint {
            start,
            parameters: parameters.iter().map(along).collect(),
        };
        self.give(w, stages);
        if !(finite(adjoint.start.as_slice()) && finite(&adjoint.parameters)) {
            return Err(Failure::NonFinite);
        }
        Ok(adjoint)
    }

    /// The scheme's dynamics of the problem.
    fn dynamics(&self) -> Dynamics<N, X> {
        Dynamics::new(self.problem.h(), self.problem.options.theta)
    }

    /// The terms of `parameter` at step `i` of the plan.
    fn terms(&self, i: usize, parameter: &Parameter<'_, N, K>) -> ParameterTerms<N, X> {
        let (x, theta) = (&self.iterate.x, self.problem.options.theta);
        let xt = x[i] * (1.0 - theta) + x[i + 1] * theta;
        let (u, y) = (&self.iterate.u[i], &self.y[i]);
        ParameterTerms::new::<K>(&xt, u, y, self.problem.h(), parameter)
    }

    /// The KKT system at the plan solved for the right-hand side that `fill(i, stage)`
    /// writes into a copy of each stage model whose gradients, constraint values, defect and
    /// node gradient are zero, with $\delta x_0 = $ `r0` and the terminal gradient `s_end`
    /// (on the free end components), the active inequalities held as equalities $\nabla
    /// g_k^T \delta y = 0$ by the method of multipliers: each solve (refined
    /// [`REFINEMENTS`] times) adds $\nu_k \nabla g_k$ to the gradients, then $\nu_k
    /// \leftarrow \nu_k + \sigma_k \nabla g_k^T \delta y$, until $\max_k |\nabla g_k^T
    /// \delta y|$ is below [`HELD`] times the solution's largest entry (at most
    /// [`MULTIPLIER_UPDATES`] solves). Returns the solution and the stage models of its
    /// last solve (for [`Self::give`]).
    fn solve(
        &self,
        fill: impl Fn(usize, &mut StageModel<N, X>),
        r0: &SVector<f64, X>,
        s_end: &SVector<f64, X>,
    ) -> (Direction<N, X>, Vec<StageModel<N, X>>) {
        let (dynamics, riccati) = (self.dynamics(), &self.at.riccati);
        let ends = (&SVector::zeros(), s_end);
        let active = &self.at.active;
        let mut nu = vec![0.0; active.len()];
        let mut pool = self.workspace.pool.borrow_mut();
        let mut stages = pool.stages.take(self.at.stages.len());
        let mut updates = 0;
        loop {
            stages.clear();
            stages.extend_from_slice(&self.at.stages);
            for (i, stage) in stages.iter_mut().enumerate() {
                stage.gx = SVector::zeros();
                stage.gu = SVector::zeros();
                stage.value = SVector::zeros();
                stage.defect = SVector::zeros();
                if let Some(node) = &mut stage.node {
                    node.1 = SVector::zeros();
                }
                fill(i, stage);
            }
            for (c, nu) in active.iter().zip(&nu) {
                match c.slot {
                    Slot::Step(i) => {
                        stages[i].gx += c.gx * *nu;
                        stages[i].gu += c.gu * *nu;
                    }
                    Slot::Node(i) => {
                        if let Some(node) = &mut stages[i].node {
                            node.1 += c.gx * *nu;
                        }
                    }
                }
            }
            let mut d = riccati.solve(&dynamics, &stages, r0, ends, &mut *pool);
            for _ in 0..REFINEMENTS {
                let model = (&stages[..], &self.at.terminal);
                refine(
                    riccati,
                    &dynamics,
                    model,
                    0.0,
                    r0,
                    ends,
                    (&mut d, &mut *pool),
                );
            }
            updates += 1;
            let size = (d.dx.iter().map(|v| v.amax()))
                .chain(d.du.iter().map(|v| v.amax()))
                .fold(0.0, f64::max);
            let theta = dynamics.theta;
            let mut missed: f64 = 0.0;
            for (c, nu) in active.iter().zip(nu.iter_mut()) {
                let along = match c.slot {
                    Slot::Step(i) => {
                        let dx = d.dx[i] * (1.0 - theta) + d.dx[i + 1] * theta;
                        c.gx.dot(&dx) + c.gu.dot(&d.du[i])
                    }
                    Slot::Node(i) => c.gx.dot(&d.dx[i]),
                };
                *nu += c.sigma * along;
                missed = missed.max(along.abs());
            }
            if missed <= HELD * size || !missed.is_finite() || updates >= MULTIPLIER_UPDATES {
                return (d, stages);
            }
            d.recycle(&mut *pool);
        }
    }

    /// Gives a solve's vectors back to the workspace.
    fn give(&self, d: Direction<N, X>, stages: Vec<StageModel<N, X>>) {
        let mut pool = self.workspace.pool.borrow_mut();
        d.recycle(&mut *pool);
        pool.stages.give(stages);
    }
}
