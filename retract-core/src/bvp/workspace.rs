//! The optimizer's workspace: the vectors of one solve, kept with their capacity for the
//! next solve of the same size, so that a re-solve allocates nothing
//! ([`super::OptimalControlProblem::solve_with`]).

use core::cell::RefCell;

use nalgebra::SVector;

use super::constraints::Linearized;
use super::plan::Plan;
use super::riccati::{Backward, StageFactor, StageModel, TailFactor};

/// Vectors of one element type, each handed out empty with at least the capacity asked for
/// and given back when its contents are no longer needed.
pub(super) struct Stack<T>(Vec<Vec<T>>);

impl<T> Default for Stack<T> {
    fn default() -> Self {
        Self(Vec::new())
    }
}

impl<T> Stack<T> {
    /// An empty vector with capacity at least `len`: the smallest kept one that holds it, else
    /// the largest kept one grown (a new one if none is kept).
    pub fn take(&mut self, len: usize) -> Vec<T> {
        let fits = (self.0.iter().enumerate())
            .filter(|(_, v)| v.capacity() >= len)
            .min_by_key(|(_, v)| v.capacity());
        let pick = fits
            .or_else(|| self.0.iter().enumerate().max_by_key(|(_, v)| v.capacity()))
            .map(|(i, _)| i);
        let mut v = pick.map_or_else(Vec::new, |i| self.0.swap_remove(i));
        v.clear();
        v.reserve(len);
        v
    }

    /// Keeps `v` (emptied) for a later [`Self::take`] (unless it has no capacity).
    pub fn give(&mut self, mut v: Vec<T>) {
        if v.capacity() > 0 {
            v.clear();
            self.0.push(v);
        }
    }
}

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
}

impl<const N: usize, const X: usize> Pool<N, X> {
    /// The number of vectors kept.
    fn kept(&self) -> usize {
        self.reals.0.len()
            + self.jets.0.len()
            + self.tops.0.len()
            + self.gradients.0.len()
            + self.stages.0.len()
            + self.linearized.0.len()
            + self.factors.0.len()
            + self.tails.0.len()
            + self.backward.0.len()
            + self.pairs.0.len()
            + self.lanczos.0.len()
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
