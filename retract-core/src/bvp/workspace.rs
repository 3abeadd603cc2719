//! The optimizer's workspace: the vectors of one solve, kept with their capacity for the
//! next solve of the same size, so that a re-solve allocates nothing
//! ([`super::OptimalControlProblem::solve_with`]).

use core::cell::RefCell;

use nalgebra::SVector;

use super::constraints::Linearized;
use super::kkt::model::StageModel;
use super::kkt::riccati::{Backward, StageFactor, TailFactor, Vectors};
use super::plan::Plan;
use super::stack::Stack;

/// The kept vectors of the optimizer, one [`Stack`] per element type.
#[derive(Default)]
pub(super) struct Pool<const N: usize, const X: usize> {
    pub reals: Stack<f64>,
    pub jets: Stack<SVector<f64, X>>,
    pub tops: Stack<SVector<f64, N>>,
    pub gradients: Stack<(SVector<f64, X>, SVector<f64, N>)>,
    pub stages: Stack<StageModel<N, X>>,
    pub linearized: Stack<Linearized<N, X>>,
    pub factors: Stack<StageFactor<N, X>>,
    pub tails: Stack<TailFactor<N, X>>,
    pub backward: Stack<Backward<N, X>>,
    pub pairs: Stack<(f64, f64)>,
    /// The Lanczos vectors of the certificate's eigenvalue (their own sizes).
    pub lanczos: Stack<f64>,
    /// The inequalities' values at the last trial point of a line search and its step
    /// length (written by the merit function's evaluation): the point a search accepts is
    /// the last one it evaluated, so the slack reset after the step reads them instead of
    /// evaluating the inequalities again.
    pub trial_values: (Vec<f64>, f64),
}

impl<const N: usize, const X: usize> Pool<N, X> {
    /// The number of vectors kept.
    fn kept(&self) -> usize {
        self.reals.len()
            + self.jets.len()
            + self.tops.len()
            + self.gradients.len()
            + self.stages.len()
            + self.linearized.len()
            + self.factors.len()
            + self.tails.len()
            + self.backward.len()
            + self.pairs.len()
            + self.lanczos.len()
    }

    /// Keeps the vectors of `plan`.
    pub fn give_plan(&mut self, plan: Plan<N, X>) {
        self.jets.give(plan.x);
        self.jets.give(plan.momenta);
        self.tops.give(plan.u);
        self.tops.give(plan.duals.equalities);
        for v in [
            plan.duals.step_slacks,
            plan.duals.step_multipliers,
            plan.duals.node_slacks,
            plan.duals.node_multipliers,
        ] {
            self.reals.give(v);
        }
    }
}

impl<const N: usize, const X: usize> Vectors<N, X> for Pool<N, X> {
    fn jets(&mut self) -> &mut Stack<SVector<f64, X>> {
        &mut self.jets
    }
    fn tops(&mut self) -> &mut Stack<SVector<f64, N>> {
        &mut self.tops
    }
    fn factors(&mut self) -> &mut Stack<StageFactor<N, X>> {
        &mut self.factors
    }
    fn tails(&mut self) -> &mut Stack<TailFactor<N, X>> {
        &mut self.tails
    }
    fn backward(&mut self) -> &mut Stack<Backward<N, X>> {
        &mut self.backward
    }
    fn lanczos(&mut self) -> &mut Stack<f64> {
        &mut self.lanczos
    }
}

/// What a solve keeps for the next one: the vectors of its iterates, models, factorisations,
/// directions and plans, each vector kept with its capacity. It grows until it holds as many
/// vectors as a solve of the problem needs at once; then a solve allocates nothing
/// ([`super::OptimalControlProblem::solve_with`]). One per thread of solves: a workspace is
/// borrowed mutably by one solve at a time. The receding-horizon loop of
/// [`super::OptimalControlProblem::solve_with`]'s example shows its use.
pub struct Workspace<const N: usize, const X: usize> {
    pub(super) pool: RefCell<Pool<N, X>>,
}

impl<const N: usize, const X: usize> Workspace<N, X> {
    /// An empty workspace (the first solve that uses it sizes it).
    pub fn new() -> Self {
        Self {
            pool: RefCell::new(Pool::default()),
        }
    }

    /// Keeps the vectors of `plan`, which is no longer needed, for the plans of later solves:
    /// in a receding horizon, the plan a re-solve replaced.
    pub fn recycle(&mut self, plan: Plan<N, X>) {
        self.pool.get_mut().give_plan(plan);
    }
}

impl<const N: usize, const X: usize> Default for Workspace<N, X> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize, const X: usize> core::fmt::Debug for Workspace<N, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Workspace")
            .field("kept_vectors", &self.pool.borrow().kept())
            .finish_non_exhaustive()
    }
}
