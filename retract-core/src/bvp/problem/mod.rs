//! The optimal-control problem ([`OptimalControlProblem`]): its data, the builders of its
//! ends, stage systems, terminal cost and options, and its inequalities by where they are
//! imposed; `constrain` adds its constraints, `validate` checks it before a solve and an
//! iterate against the system's domain, `measure` measures an iterate's violations. Solving
//! it is `solve`'s ([`super::solve`]).

use std::sync::OnceLock;

use nalgebra::SVector;

use super::constraints::{Inequality, Placement, Sample};
use super::options::PlanOptions;
use crate::{JetFunction, Lagrangian};

mod constrain;
mod measure;
mod validate;

/// An optimal-control problem: minimise $\sum_i h\thinspace L(x_{\theta,i}, u_i)$ over the lifted
/// scheme from the jet $a$ to the jet $b$ in time $T$ with $N$ steps.
///
/// `N` is the dimension $n$, `K` the order $k$ and `X` $= nk$ the length of a jet; `S` and
/// `M` are those of the system's [`LiftedSystem`](crate::LiftedSystem) (used for its singularity guard).
pub struct OptimalControlProblem<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize> {
    pub(in crate::bvp) system: &'a Sys,
    /// One system per step ([`Self::with_stage_systems`]), else `system` at every step.
    pub(in crate::bvp) stage_systems: Option<&'a [&'a Sys]>,
    /// The terminal cost $\Phi(x_N)$ ([`Self::with_terminal_cost`]).
    pub(in crate::bvp) terminal_cost: Option<&'a (dyn JetFunction<N, K> + Sync)>,
    /// 1 for the components of $x_N$ the goal fixes, 0 for the free ones
    /// ([`Self::with_free_end`]).
    pub(in crate::bvp) fixed_end: SVector<f64, X>,
    /// 1 for the components of $x_0$ the start fixes, 0 for the free ones
    /// ([`Self::with_free_start`]).
    pub(in crate::bvp) fixed_start: SVector<f64, X>,
    /// Components given to [`Self::with_free_end`] or [`Self::with_free_start`] that are out
    /// of range (an error at solve).
    pub(in crate::bvp) bad_free_component: bool,
    pub(in crate::bvp) equalities: Vec<&'a (dyn JetFunction<N, K> + Sync)>,
    /// The scalar inequalities (a two-sided constraint gives two).
    pub(in crate::bvp) inequalities: Vec<Inequality<'a, N, K>>,
    /// Function inequalities and bounds added so far (their indices in messages).
    pub(in crate::bvp) function_inequalities: usize,
    pub(in crate::bvp) bounds: usize,
    pub(in crate::bvp) start: SVector<f64, X>,
    pub(in crate::bvp) goal: SVector<f64, X>,
    pub(in crate::bvp) t_end: f64,
    pub(in crate::bvp) steps: usize,
    pub(in crate::bvp) options: PlanOptions,
    /// The inequalities by where they are imposed, made at the first solve (a builder that
    /// adds an inequality or sets the options empties it; a clone starts without).
    pub(in crate::bvp) placed: OnceLock<Placed<'a, N, K>>,
}

/// The inequalities of a problem by where the solve imposes them.
pub(in crate::bvp) struct Placed<'a, const N: usize, const K: usize> {
    /// At the steps' evaluation points, then at the interior samples.
    pub at_steps: Vec<Inequality<'a, N, K>>,
    /// At the interior nodes.
    pub at_nodes: Vec<Inequality<'a, N, K>>,
    /// The weights of the interpolant inside a step
    /// ([`super::plan::violations::interpolant_weights`]).
    pub interpolant: Option<Vec<f64>>,
    /// The weights of `at_steps` and of `at_nodes` in the line search's constraint violation
    /// ([`super::constraints::violation_weights`]).
    pub violation_weights: (Vec<f64>, Vec<f64>),
}

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize> Clone
    for OptimalControlProblem<'_, Sys, N, K, X>
{
    fn clone(&self) -> Self {
        Self {
            system: self.system,
            stage_systems: self.stage_systems,
            terminal_cost: self.terminal_cost,
            fixed_end: self.fixed_end,
            fixed_start: self.fixed_start,
            bad_free_component: self.bad_free_component,
            equalities: self.equalities.clone(),
            inequalities: self.inequalities.clone(),
            function_inequalities: self.function_inequalities,
            bounds: self.bounds,
            start: self.start,
            goal: self.goal,
            t_end: self.t_end,
            steps: self.steps,
            options: self.options,
            placed: OnceLock::new(),
        }
    }
}

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// The problem from `start` $= (q, \dots, q^{(k-1)})(0)$ to `goal` at $T$ = `t_end` in
    /// `steps` steps (jets in blocks of $n$).
    pub fn new(system: &'a Sys, start: &[f64; X], goal: &[f64; X], t_end: f64, steps: usize) -> Self
    where
        Sys: Lagrangian<N, K>,
    {
        Self {
            system,
            stage_systems: None,
            terminal_cost: None,
            fixed_end: SVector::repeat(1.0),
            fixed_start: SVector::repeat(1.0),
            bad_free_component: false,
            equalities: Vec::new(),
            inequalities: Vec::new(),
            function_inequalities: 0,
            bounds: 0,
            start: SVector::from_column_slice(start),
            goal: SVector::from_column_slice(goal),
            t_end,
            steps,
            options: PlanOptions::default(),
            placed: OnceLock::new(),
        }
    }

    /// Moves the start to `start` (the same jets as [`Self::new`]'s): for a receding horizon
    /// that re-solves one problem from each new measured state ([`Self::solve_with`]).
    pub fn set_start(&mut self, start: &[f64; X]) {
        self.start = SVector::from_column_slice(start);
    }

    /// A Lagrangian per step: step $i$ costs $h L_i(x_{\theta,i}, u_i)$ with $L_i$ =
    /// `systems[i]`, so its parameters can vary along the horizon (a reference $r_i$ of a
    /// tracking cost $\tfrac12|q - r(t_{\theta,i})|^2$, a moving obstacle), one per step
    /// (checked by [`Self::solve`]). The system given to [`Self::new`] stays the one of the
    /// boundary checks. For a receding horizon, shift the systems with the plan
    /// ([`Plan::shifted`](crate::bvp::Plan::shifted)): build them for the new window. Not with
    /// [`Self::solve_extrapolated`] (the number of steps changes there).
    pub fn with_stage_systems(mut self, systems: &'a [&'a Sys]) -> Self {
        self.stage_systems = Some(systems);
        self
    }

    /// Adds the terminal cost $\Phi(x_N)$ to $J$, written under `#[jet_function]` as a
    /// function of the jet $x = (q, \dots, q^{(k-1)})$ only (its argument $q^{(k)}$ unused:
    /// [`Self::solve`] refuses a $\Phi$ whose derivatives in it are not zero). With a goal that
    /// fixes all of $x_N$ it is a constant; it acts on the components freed by
    /// [`Self::with_free_end`], where the plan then satisfies $p_N = -\nabla\Phi$.
    pub fn with_terminal_cost(mut self, phi: &'a (dyn JetFunction<N, K> + Sync)) -> Self {
        self.terminal_cost = Some(phi);
        self
    }

    /// Frees the components `components` of $x_N$ (indices into the jet, blocks of $n$: $q_i$
    /// is $i$, $q'_i$ is $n + i$, ...): the goal's values there are ignored and the plan
    /// chooses them (with [`Self::with_terminal_cost`], to minimise $J + \Phi$; without, the
    /// natural boundary condition $p_N = 0$ there).
    pub fn with_free_end(mut self, components: &[usize]) -> Self {
        self.bad_free_component |= !free_components(&mut self.fixed_end, components);
        self
    }

    /// Frees the components `components` of $x_0$ (indices as in [`Self::with_free_end`]):
    /// the start's values there are ignored and the plan chooses them, with the natural
    /// boundary condition $p_0 = 0$ there.
    pub fn with_free_start(mut self, components: &[usize]) -> Self {
        self.bad_free_component |= !free_components(&mut self.fixed_start, components);
        self
    }

    /// The Lagrangian of step `i`.
    pub(in crate::bvp) fn system_at(&self, i: usize) -> &'a Sys {
        self.stage_systems.map_or(self.system, |systems| systems[i])
    }

    /// Sets the options.
    pub fn with_options(mut self, options: PlanOptions) -> Self {
        self.options = options;
        self.placed = OnceLock::new();
        self
    }

    /// The inequalities by where they are imposed ([`Placed`]), made once.
    pub(in crate::bvp) fn placed(&self) -> &Placed<'a, N, K> {
        self.placed.get_or_init(|| {
            let placed = |at: fn(Placement) -> bool| {
                let list = self.inequalities.iter().filter(|c| at(c.placement));
                list.copied().collect::<Vec<_>>()
            };
            let mut at_steps = placed(Placement::at_midpoints);
            at_steps.extend(self.interior_samples(K));
            // (at theta = 0 or 1 the evaluation points are nodes: no second copy there)
            let at_nodes = if self.options.theta == 0.0 || self.options.theta == 1.0 {
                placed(|p| p == Placement::Nodes)
            } else {
                placed(Placement::at_nodes)
            };
            let interpolant = super::plan::violations::interpolant_weights(self.h(), K);
            let violation_weights = (
                super::constraints::violation_weights(&at_steps),
                super::constraints::violation_weights(&at_nodes),
            );
            Placed {
                at_steps,
                at_nodes,
                interpolant,
                violation_weights,
            }
        })
    }

    pub(in crate::bvp) fn h(&self) -> f64 {
        self.t_end / self.steps as f64
    }

    /// The constraints placed at the nodes, again at each interior sample of the steps
    /// ([`PlanOptions::interior_samples`]; sample-major), for jets of order `k`.
    fn interior_samples(&self, k: usize) -> Vec<Inequality<'a, N, K>> {
        let (m, theta) = (self.options.interior_samples, self.options.theta);
        let mut out = Vec::new();
        for j in 1..=m {
            let fraction = j as f64 / (m + 1) as f64;
            if fraction == theta {
                continue;
            }
            let Some(sample) = Sample::new(fraction, self.h(), theta, k) else {
                continue;
            };
            let nodes = self.inequalities.iter().filter(|c| c.placement.at_nodes());
            out.extend(nodes.map(|c| Inequality {
                sample: Some(sample),
                ..*c
            }));
        }
        out
    }
}

/// Sets `mask` to 0 at `components` (freed); false if one of them is out of range.
fn free_components<const X: usize>(mask: &mut SVector<f64, X>, components: &[usize]) -> bool {
    components.iter().all(|&c| match mask.get_mut(c) {
        Some(f) => {
            *f = 0.0;
            true
        }
        None => false,
    })
}
