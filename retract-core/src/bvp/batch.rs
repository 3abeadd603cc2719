//! Many plans at once: a batch of problems of one system type ([`solve_batch`]), a stream of
//! them larger than memory ([`solve_stream`]), and several first guesses of one problem
//! ([`OptimalControlProblem::solve_multistart`]).
//!
//! With the `parallel` feature (on by default) the solves run on rayon's current thread
//! pool: the global one (as many threads as cores), or the pool a caller enters with
//! `rayon::ThreadPool::install` to choose the thread count. Each piece of work rayon hands a
//! thread (a run of consecutive jobs) solves in its own [`Workspace`], reused from one solve
//! of the run to the next ([`solve_stream`]: one per job of a chunk, kept across chunks);
//! without the feature the same functions
//! solve one problem after the other in one workspace. The results come back in input order,
//! each with its own status (a failure does not stop the others), and are the same as the
//! sequential solves': a solve does not depend on the thread that runs it.

use std::collections::VecDeque;

#[cfg(feature = "parallel")]
use rayon::prelude::*;

use super::options::PlanGuess;
use super::plan::{Plan, PlanError};
use super::problem::OptimalControlProblem;
use super::workspace::Workspace;
use crate::{Lagrangian, LiftedSystem};

/// The result of one solve of a batch: a certified plan, or the failure with its last iterate.
pub type Outcome<const N: usize, const X: usize> = Result<Plan<N, X>, PlanError<N, X>>;

/// One job of a batch: a problem and the guess to start it from.
pub type Job<'a, 'g, Sys, const N: usize, const K: usize, const X: usize> =
    (OptimalControlProblem<'a, Sys, N, K, X>, PlanGuess<'g, N, X>);

/// Solves every problem of `jobs` from its guess ([`OptimalControlProblem::solve_with`]), in
/// parallel with the `parallel` feature (see the module docs): entry $i$ of the result is the
/// outcome of `jobs[i]`.
///
/// # Example
/// ```
/// use retract_core::bvp::{OptimalControlProblem, PlanGuess, solve_batch};
/// use retract_core::models::PlanarBarrier;
///
/// let system = PlanarBarrier { tau: 1e-12, radius: 1.0, mass: 1.0 };
/// let goal = [3.0, 1.0, 0.0, 0.0];
/// let starts: Vec<[f64; 4]> = (0..8).map(|i| [2.0, 0.1 * i as f64, 0.0, 0.0]).collect();
/// let jobs: Vec<_> = (starts.iter())
///     .map(|start| (OptimalControlProblem::new(&system, start, &goal, 1.0, 50), PlanGuess::Spline))
///     .collect();
/// let plans = solve_batch(&jobs);
/// assert_eq!(plans.len(), 8);
/// // from rest to rest, the optimum costs about 6 |q(T) - q(0)|^2 / T^3
/// let first = plans[0].as_ref().expect("a certified minimum");
/// assert!((first.cost - 12.0).abs() < 1e-2);
/// ```
pub fn solve_batch<
    Sys,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
>(
    jobs: &[Job<'_, '_, Sys, N, K, X>],
) -> Vec<Outcome<N, X>>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + Sync,
{
    map_in_workspaces(jobs, |workspace, (problem, guess)| {
        problem.solve_with::<S, M>(*guess, workspace)
    })
}

/// `solve(workspace, item)` for every item, in order: on rayon's pool with a workspace per
/// run of items a thread takes (`map_init`) with the `parallel` feature, else one after the
/// other in one workspace.
fn map_in_workspaces<T: Sync, R: Send, const N: usize, const X: usize>(
    items: &[T],
    solve: impl Fn(&mut Workspace<N, X>, &T) -> R + Sync + Send,
) -> Vec<R> {
    #[cfg(feature = "parallel")]
    {
        items.par_iter().map_init(Workspace::new, solve).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        let mut workspace = Workspace::new();
        items
            .iter()
            .map(|item| solve(&mut workspace, item))
            .collect()
    }
}

/// The outcomes of [`OptimalControlProblem::solve_multistart`]: one per guess, in the
/// guesses' order, and which certified plan costs least.
#[derive(Debug)]
pub struct MultiStart<const N: usize, const X: usize> {
    /// The outcome of the solve from each guess.
    pub outcomes: Vec<Outcome<N, X>>,
    /// The index of the certified plan of least cost (the first among equal costs); `None`
    /// if no solve succeeded.
    pub best: Option<usize>,
}

impl<const N: usize, const X: usize> MultiStart<N, X> {
    /// The certified plan of least cost, if any solve succeeded.
    pub fn best_plan(&self) -> Option<&Plan<N, X>> {
        self.best.and_then(|i| self.outcomes[i].as_ref().ok())
    }

    /// The outcomes with the index of the cheapest certified plan
    /// ($\arg\min_i J_i$ over the plans returned `Ok`).
    fn new(outcomes: Vec<Outcome<N, X>>) -> Self {
        let best = (outcomes.iter().enumerate())
            .filter_map(|(i, o)| o.as_ref().ok().map(|plan| (i, plan.cost)))
            .fold(None, |best: Option<(usize, f64)>, (i, cost)| match best {
                Some((_, least)) if least <= cost => best,
                _ => Some((i, cost)),
            })
            .map(|(i, _)| i);
        Self { outcomes, best }
    }
}

impl<Sys, const N: usize, const K: usize, const X: usize> OptimalControlProblem<'_, Sys, N, K, X>
where
    Sys: Sync,
{
    /// Solves the problem from each of `guesses` (in parallel with the `parallel` feature, see
    /// [`solve_batch`]) and names the certified plan of least cost: on a problem with several
    /// local minima (an obstacle passed on either side, a chain's joint limits), the lowest of
    /// the minima the guesses reach. Every plan it returns is certified as
    /// [`Self::solve`]'s; the least cost among them is a local minimum, not a proof of a
    /// global one.
    pub fn solve_multistart<const S: usize, const M: usize>(
        &self,
        guesses: &[PlanGuess<'_, N, X>],
    ) -> MultiStart<N, X>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let outcomes = map_in_workspaces(guesses, |workspace, guess| {
            self.solve_with::<S, M>(*guess, workspace)
        });
        MultiStart::new(outcomes)
    }
}

/// The outcomes of a stream of jobs, solved `chunk` at a time ([`solve_stream`]).
pub struct Stream<I, const N: usize, const X: usize, const S: usize, const M: usize> {
    jobs: I,
    chunk: usize,
    ready: VecDeque<Outcome<N, X>>,
    /// One workspace per job of a chunk, kept from one chunk to the next.
    workspaces: Vec<Workspace<N, X>>,
}

/// Solves the jobs of an iterator `chunk` at a time (at least 1; in parallel with the
/// `parallel` feature) and yields their outcomes in the jobs' order: a batch far larger than
/// memory is read, solved and handed on without ever being held whole (at most `chunk` jobs
/// and their outcomes at a time, with `chunk` workspaces reused from one chunk to the next).
/// A `chunk` of a few times the thread count keeps every thread busy.
pub fn solve_stream<
    'a,
    'g,
    I,
    Sys,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
>(
    jobs: I,
    chunk: usize,
) -> Stream<I::IntoIter, N, X, S, M>
where
    I: IntoIterator<Item = Job<'a, 'g, Sys, N, K, X>>,
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + Sync + 'a,
{
    Stream {
        jobs: jobs.into_iter(),
        chunk: chunk.max(1),
        ready: VecDeque::new(),
        workspaces: Vec::new(),
    }
}

impl<'a, 'g, I, Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Iterator for Stream<I, N, X, S, M>
where
    I: Iterator<Item = Job<'a, 'g, Sys, N, K, X>>,
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + Sync + 'a,
{
    type Item = Outcome<N, X>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.ready.is_empty() {
            let jobs: Vec<_> = self.jobs.by_ref().take(self.chunk).collect();
            if self.workspaces.len() < jobs.len() {
                self.workspaces.resize_with(jobs.len(), Workspace::new);
            }
            let solve = |((problem, guess), workspace): (Job<'a, 'g, Sys, N, K, X>, _)| {
                problem.solve_with::<S, M>(guess, workspace)
            };
            #[cfg(feature = "parallel")]
            let solved: Vec<_> = (jobs.into_par_iter())
                .zip(self.workspaces.par_iter_mut())
                .map(solve)
                .collect();
            #[cfg(not(feature = "parallel"))]
            let solved: Vec<_> = jobs
                .into_iter()
                .zip(self.workspaces.iter_mut())
                .map(solve)
                .collect();
            self.ready.extend(solved);
        }
        self.ready.pop_front()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::PlanarBarrier;

    const GOAL: [f64; 4] = [3.0, 1.0, 0.0, 0.0];
    /// A barrier too weak to matter: a convex problem, one minimum per start.
    const SYSTEM: PlanarBarrier = PlanarBarrier {
        tau: 1e-12,
        radius: 1.0,
        mass: 1.0,
    };

    fn starts() -> Vec<[f64; 4]> {
        (0..7).map(|i| [2.0, 0.15 * i as f64, 0.0, 0.0]).collect()
    }

    /// A batch, a stream in chunks of 3 (the last chunk short) and the solves one by one give
    /// the same plans in the same order, bit for bit: a solve does not depend on its thread
    /// or on the workspace's history.
    #[test]
    fn a_batch_and_a_stream_give_the_sequential_plans_in_order() {
        let system = SYSTEM;
        let starts = starts();
        let jobs = || {
            (starts.iter()).map(|s| {
                (
                    OptimalControlProblem::new(&system, s, &GOAL, 1.0, 40),
                    PlanGuess::Spline,
                )
            })
        };
        let batch = solve_batch(&jobs().collect::<Vec<_>>());
        let stream: Vec<_> = solve_stream(jobs(), 3).collect();
        assert_eq!(batch.len(), starts.len());
        assert_eq!(stream.len(), starts.len());
        for (i, (problem, guess)) in jobs().enumerate() {
            let alone = problem.solve(guess);
            let (Ok(alone), Ok(b), Ok(s)) = (alone, &batch[i], &stream[i]) else {
                panic!("start {i}: not certified");
            };
            assert_eq!(alone.x, b.x, "batch, start {i}");
            assert_eq!(alone.x, s.x, "stream, start {i}");
            assert_eq!(alone.cost.to_bits(), b.cost.to_bits());
        }
        // the plans differ from start to start (the order is the input's, not a copy of one)
        assert!(batch.windows(2).all(|w| match (&w[0], &w[1]) {
            (Ok(a), Ok(b)) => a.cost != b.cost,
            _ => false,
        }));
    }

    /// A failed solve keeps its place and its status: a problem with a horizon that is not
    /// positive fails in its slot, the others are solved.
    #[test]
    fn a_failure_keeps_its_place_in_the_batch() {
        let system = SYSTEM;
        let starts = starts();
        let jobs: Vec<_> = (starts.iter().enumerate())
            .map(|(i, s)| {
                let t_end = if i == 2 { -1.0 } else { 1.0 };
                (
                    OptimalControlProblem::new(&system, s, &GOAL, t_end, 40),
                    PlanGuess::Spline,
                )
            })
            .collect();
        let outcomes = solve_batch(&jobs);
        for (i, o) in outcomes.iter().enumerate() {
            assert_eq!(o.is_ok(), i != 2, "job {i}: {:?}", o.as_ref().err());
        }
    }

    /// Multi-start solves from every guess and names the cheapest certified plan, the first
    /// among equal costs: on this convex scene (no barrier to speak of) the spline and a
    /// detour out to y = 5 reach the same minimum (to rounding); a
    /// multi-start whose every solve fails has no best. (Two distinct minima:
    /// `tests/planning/batch.rs`.)
    #[test]
    fn multistart_names_the_cheapest_certified_plan() {
        let system = SYSTEM;
        let start = [2.0, 0.0, 0.0, 0.0];
        let problem = OptimalControlProblem::new(&system, &start, &GOAL, 1.0, 40);
        let detour = crate::bvp::Curve::from_fn(|t| {
            let bump = 16.0 * t * t * (1.0 - t) * (1.0 - t);
            [2.0 + t, t + 4.0 * bump]
        });
        let guesses = [PlanGuess::Curve(&detour), PlanGuess::Spline];
        let multi = problem.solve_multistart(&guesses);
        let [Ok(first), Ok(second)] = &multi.outcomes[..] else {
            panic!("{:?}", multi.outcomes);
        };
        assert!((first.cost - second.cost).abs() < 1e-9 * second.cost);
        let least = if second.cost < first.cost { 1 } else { 0 };
        assert_eq!(multi.best, Some(least));
        let bad = OptimalControlProblem::new(&system, &start, &GOAL, -1.0, 40);
        let none = bad.solve_multistart(&guesses);
        assert!(none.best.is_none() && none.best_plan().is_none());
        assert!(none.outcomes.iter().all(|o| o.is_err()));
    }
}
