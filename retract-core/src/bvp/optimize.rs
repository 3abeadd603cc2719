//! The optimizer: SQP on the direct transcription of the lifted-midpoint scheme.
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
//! Each iteration solves the quadratic subproblem by a Riccati recursion ([`super::riccati`],
//! $O(N)$), counts the negative eigenvalues of the reduced Hessian on the way and, while there
//! are any, adds $h \rho I$ to every stage Hessian (inertia correction as in IPOPT: $\rho$ from
//! $10^{-4}$, times 8 until the count is 0, a third of the last value at the next iteration),
//! so every direction descends and iterates are drawn to minima. The step length comes from a
//! backtracking line search on the exact penalty $J + \pi \Vert c\Vert_1$ ($c$: all constraints),
//! $\pi$ raised so that the direction descends; a trial point whose steps leave the domain of
//! $L$ (the generated singularity guard at both ends and the evaluation point of every step,
//! and on pieces of its chord no longer than `chord_spacing` unless its guards are quadratic,
//! as [`crate::step::check_step_domain`]) is rejected. A point is returned only
//! when the KKT residuals are below the tolerance and the reduced Hessian is positive definite
//! without correction; its [`Certificate`](super::Certificate) holds the residuals and the smallest eigenvalue of
//! the reduced Hessian (Lanczos on the inverse, [`super::certificate`]).

use std::sync::OnceLock;
use std::time::{Duration, Instant};

use nalgebra::SVector;

use super::constraints::{Inequality, Placement, SAMPLE_MAX_ORDER, Sample};
use super::curve::Curve;
use super::dynamics::Dynamics;
use super::guess::Hermite;
use super::iterate::{Iterate, blocks};
use super::plan::{Failure, Plan, PlanError, RealTime};
use super::sqp::Sqp;
use super::workspace::Workspace;
use crate::{DomainViolation, Error, JetFunction, Lagrangian, LiftedSystem};

/// Options of [`OptimalControlProblem::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PlanOptions {
    /// The scheme parameter $\theta$ (1/2: midpoint).
    pub theta: f64,
    /// Converged when the relative stationarity ([`Certificate::stationarity`](super::Certificate::stationarity)) and the
    /// constraint violation are both below this.
    pub tolerance: f64,
    /// Accepted instead of `tolerance` when the line search has made only rounding-level
    /// progress for three iterations (ill-conditioning near active inequalities), as IPOPT's
    /// acceptable level; the certificate reports the residuals reached.
    pub acceptable: f64,
    /// Iteration budget; 3000 by default (IPOPT's): the hard problems of the constrained
    /// suite need a few hundred to a few thousand iterations (`examples/constrained.rs`).
    pub max_iterations: usize,
    /// Wall-time budget, counted from the call to `solve`; `None` for none. The clock is read
    /// between the phases of an iteration (models, each factorisation of the inertia
    /// correction, each line-search trial) and every 1024 steps inside the model build and
    /// the factorisation, so a solve returns [`Failure::TimeLimit`] with the iterate reached
    /// about one such piece after the budget; the checks of the first guess before the first
    /// iteration (about 20 ms at 65 536 steps) are not interrupted.
    pub max_time: Option<Duration>,
    /// The chord of a step longer than this (max-norm of $x_{i+1} - x_i$) is checked by the
    /// singularity guard in pieces of at most this length, as
    /// [`crate::StepOptions::chord_spacing`]; 0.02 by default.
    pub chord_spacing: f64,
    /// The most pieces a step's chord is cut into, as
    /// [`crate::StepOptions::max_chord_pieces`]; 16 by default.
    pub max_chord_pieces: u32,
    /// Armijo constant of the line search.
    pub armijo: f64,
    /// Step halvings per line search.
    pub max_backtracks: usize,
    /// Initial barrier parameter $\mu_0$ of the inequalities, in the units of the transcribed
    /// problem (IPOPT's `mu_init`, whose default 0.1 it shares): its barrier term is $\mu_0
    /// \sum \ln s$ over the slacks of every inequality at every node and step.
    pub initial_barrier: f64,
    /// Also compute [`Certificate::min_reduced_hessian_eig`](super::Certificate::min_reduced_hessian_eig) (Lanczos on the final
    /// factorisation, less than one iteration's time); on by default, off in
    /// [`OptimalControlProblem::solve_real_time`]. The inertia count that proves the reduced
    /// Hessian positive definite is always done.
    pub min_eigenvalue: bool,
    /// Interior sample points per step (0 by default, at most
    /// [`MAX_INTERIOR_SAMPLES`]): each constraint placed at the nodes (of the jet alone) is
    /// also imposed at $t_i + \tau h$, $\tau = j / (m + 1)$, $j = 1, \dots, m$, inside every
    /// step, on the plan's interpolant written in the step's $(x_\theta, u)$ (exact where the
    /// scheme's equations hold; a sample at the evaluation point itself is skipped). With
    /// $m = 15$ the samples are the points [`super::Violations::interpolant`] checks, so a
    /// certified plan's interpolant violation is within the tolerance there. Orders $k \le 4$.
    #[cfg_attr(feature = "serde", serde(default))]
    pub interior_samples: usize,
}

/// The most interior samples per step ([`PlanOptions::interior_samples`]).
pub const MAX_INTERIOR_SAMPLES: usize = 63;

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            theta: 0.5,
            tolerance: 1e-9,
            acceptable: 1e-6,
            max_iterations: 3000,
            max_time: None,
            chord_spacing: 0.02,
            max_chord_pieces: 16,
            armijo: 1e-4,
            max_backtracks: 40,
            initial_barrier: 0.1,
            min_eigenvalue: true,
            interior_samples: 0,
        }
    }
}

impl PlanOptions {
    /// Sets the KKT tolerance.
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }
    /// Sets the iteration budget.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }
    /// Sets the wall-time budget.
    pub fn with_max_time(mut self, max_time: Duration) -> Self {
        self.max_time = Some(max_time);
        self
    }
    /// Sets $\theta$.
    pub fn with_theta(mut self, theta: f64) -> Self {
        self.theta = theta;
        self
    }
    /// Also computes the smallest eigenvalue of the reduced Hessian for the certificate.
    pub fn with_min_eigenvalue(mut self, min_eigenvalue: bool) -> Self {
        self.min_eigenvalue = min_eigenvalue;
        self
    }
    /// Imposes the constraints of the jet alone at `samples` interior points of every step
    /// too ([`Self::interior_samples`]).
    pub fn with_interior_samples(mut self, samples: usize) -> Self {
        self.interior_samples = samples;
        self
    }
    /// Sets the chord spacing and the cap on chord pieces of the singularity guard
    /// ([`Self::chord_spacing`]).
    pub fn with_chord_check(mut self, spacing: f64, max_pieces: u32) -> Self {
        self.chord_spacing = spacing;
        self.max_chord_pieces = max_pieces;
        self
    }
}

/// Where the optimizer starts.
#[derive(Clone, Copy, Debug)]
pub enum PlanGuess<'a, const N: usize, const X: usize> {
    /// The Hermite polynomial of degree $2k-1$ between the boundary jets (for $k = 2$ at rest:
    /// the smoothstep $q_0 + (q_T - q_0)(3s^2 - 2s^3)$), $u$ its $k$-th derivative at the
    /// evaluation points.
    Spline,
    /// A previous plan with the same number of steps (warm start): its jets and top
    /// derivatives, and its [`Duals`](super::Duals) where they fit the problem's inequalities (else the
    /// barrier starts afresh).
    Plan(&'a Plan<N, X>),
    /// Jets $x_0, \dots, x_N$ and top derivatives $u_0, \dots, u_{N-1}$ chosen by the caller.
    Path {
        /// $x_i = (q, \dots, q^{(k-1)})(t_i)$.
        x: &'a [SVector<f64, X>],
        /// $u_i = q^{(k)}$ at the evaluation point of step $i$.
        u: &'a [SVector<f64, N>],
    },
    /// A path $q(t)$ ([`Curve`]: a closure, or waypoints): the library samples the jets
    /// $x_i = (q, \dots, q^{(k-1)})(t_i)$ and the top derivatives
    /// $u_i = q^{(k)}((i + \theta) h)$.
    Curve(&'a Curve<'a, N>),
}

/// An optimal-control problem: minimise $\sum_i h\thinspace L(x_{\theta,i}, u_i)$ over the lifted
/// scheme from the jet $a$ to the jet $b$ in time $T$ with $N$ steps.
///
/// `N` is the dimension $n$, `K` the order $k$ and `X` $= nk$ the length of a jet; `S` and
/// `M` are those of the system's [`LiftedSystem`] (used for its singularity guard).
pub struct OptimalControlProblem<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize> {
    pub(super) system: &'a Sys,
    /// One system per step ([`Self::with_stage_systems`]), else `system` at every step.
    pub(super) stage_systems: Option<&'a [&'a Sys]>,
    /// The terminal cost $\Phi(x_N)$ ([`Self::with_terminal_cost`]).
    pub(super) terminal_cost: Option<&'a (dyn JetFunction<N, K> + Sync)>,
    /// 1 for the components of $x_N$ the goal fixes, 0 for the free ones
    /// ([`Self::with_free_end`]).
    pub(super) fixed_end: SVector<f64, X>,
    /// 1 for the components of $x_0$ the start fixes, 0 for the free ones
    /// ([`Self::with_free_start`]).
    pub(super) fixed_start: SVector<f64, X>,
    /// Components given to [`Self::with_free_end`] or [`Self::with_free_start`] that are out
    /// of range (an error at solve).
    pub(super) bad_free_component: bool,
    pub(super) equalities: Vec<&'a (dyn JetFunction<N, K> + Sync)>,
    /// The scalar inequalities (a two-sided constraint gives two).
    pub(super) inequalities: Vec<Inequality<'a, N, K>>,
    /// Function inequalities and bounds added so far (their indices in messages).
    pub(super) function_inequalities: usize,
    pub(super) bounds: usize,
    pub(super) start: SVector<f64, X>,
    pub(super) goal: SVector<f64, X>,
    pub(super) t_end: f64,
    pub(super) steps: usize,
    pub(super) options: PlanOptions,
    /// The inequalities by where they are imposed, made at the first solve (a builder that
    /// adds an inequality or sets the options empties it; a clone starts without).
    pub(super) placed: OnceLock<Placed<'a, N, K>>,
}

/// The inequalities of a problem by where the solve imposes them.
pub(super) struct Placed<'a, const N: usize, const K: usize> {
    /// At the steps' evaluation points, then at the interior samples.
    pub at_steps: Vec<Inequality<'a, N, K>>,
    /// At the interior nodes.
    pub at_nodes: Vec<Inequality<'a, N, K>>,
    /// The weights of the interpolant inside a step
    /// ([`super::plan::violations::interpolant_weights`]).
    pub interpolant: Option<Vec<f64>>,
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
    /// ([`Plan::shifted`]): build them for the new window. Not with
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
    pub(super) fn system_at(&self, i: usize) -> &'a Sys {
        self.stage_systems.map_or(self.system, |systems| systems[i])
    }

    /// Sets the options.
    pub fn with_options(mut self, options: PlanOptions) -> Self {
        self.options = options;
        self.placed = OnceLock::new();
        self
    }

    /// The inequalities by where they are imposed ([`Placed`]), made once.
    pub(super) fn placed(&self) -> &Placed<'a, N, K> {
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
            Placed {
                at_steps,
                at_nodes,
                interpolant,
            }
        })
    }

    fn h(&self) -> f64 {
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

    fn validate(&self, n: usize, k: usize) -> Result<(), Error> {
        let invalid = |name, requirement| Err(Error::InvalidArgument { name, requirement });
        let o = &self.options;
        if n * k != X || N != n {
            return invalid("system", "the jet length X must be n k");
        }
        if !self.inequalities.iter().all(|c| c.valid::<X>()) {
            return invalid(
                "bounds",
                "bounds need values that are not NaN, a jet index < n k (a block j < k) or a \
                 top index < n, one lower and one upper value per component of a vector \
                 function, and no node placement for what involves the top derivative",
            );
        }
        let free_end = self
            .fixed_start
            .iter()
            .chain(self.fixed_end.iter())
            .any(|f| *f == 0.0);
        if free_end && self.inequalities.iter().any(|c| c.placement.at_nodes()) {
            return invalid(
                "placement",
                "constraints at the nodes need a start and a goal that fix every component (with \
                 a free end, place them at the midpoints: Placement::Midpoints)",
            );
        }
        if self.equalities.len() > n {
            return invalid(
                "equalities",
                "at most n equality constraints per step (each must fix a direction of u)",
            );
        }
        if !self
            .start
            .iter()
            .chain(self.goal.iter())
            .all(|v| v.is_finite())
        {
            return invalid("start/goal", "boundary data must be finite");
        }
        if self.steps < k || self.steps > 1 << 24 {
            return invalid("steps", "need k <= steps <= 2^24");
        }
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return invalid("t_end", "the horizon must be finite and positive");
        }
        if !(0.0..=1.0).contains(&o.theta) {
            return invalid("theta", "theta must lie in [0, 1]");
        }
        if !(o.tolerance.is_finite() && o.tolerance > 0.0 && o.acceptable >= o.tolerance)
            || o.max_iterations == 0
        {
            return invalid(
                "options",
                "need a finite tolerance > 0 and max_iterations >= 1",
            );
        }
        if o.interior_samples > MAX_INTERIOR_SAMPLES
            || (o.interior_samples > 0 && k > SAMPLE_MAX_ORDER)
        {
            return invalid(
                "options",
                "at most 63 interior samples per step, for orders k <= 4",
            );
        }
        if !(o.initial_barrier.is_finite() && o.initial_barrier > 0.0) {
            return invalid(
                "options",
                "the initial barrier parameter must be finite and > 0",
            );
        }
        if !(o.armijo > 0.0 && o.armijo < 0.5) {
            return invalid("options", "need 0 < armijo < 1/2");
        }
        if !(o.chord_spacing > 0.0 && o.max_chord_pieces <= crate::step::MAX_CHORD_PIECES) {
            return invalid(
                "options",
                "the chord spacing must be > 0 (infinity: the three points only) and \
                 max_chord_pieces at most MAX_CHORD_PIECES",
            );
        }
        Ok(())
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
        let warm = match guess {
            PlanGuess::Plan(plan) => Some(&plan.duals),
            _ => None,
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
        let placed = self.placed();
        Sqp::<Sys, N, K, X, S, M> {
            problem: self,
            dynamics: Dynamics::new(self.h(), self.options.theta),
            started,
            at_steps: &placed.at_steps,
            at_nodes: &placed.at_nodes,
            pool: &workspace.pool,
            options,
            real_time,
        }
        .run(iterate, warm)
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
        let per_step = 3 * size_of::<super::riccati::StageModel<N, X>>()
            + super::riccati::Riccati::<N, X>::bytes_per_step()
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

    /// The boundary jets against the domain of the Lagrangian
    /// ([`super::root_finder::check_boundary`], momenta zero as in [`Self::guard`], the
    /// guess's top derivatives of the first and last steps).
    fn check_ends<const S: usize, const M: usize>(
        &self,
        iterate: &Iterate<N, X>,
    ) -> Result<(), Error>
    where
        Sys: LiftedSystem<S, M>,
    {
        let state =
            |x: &SVector<f64, X>| SVector::<f64, S>::from_fn(|r, _| if r < X { x[r] } else { 0.0 });
        let (Some(first), Some(last)) = (iterate.u.first(), iterate.u.last()) else {
            return Ok(());
        };
        super::root_finder::check_boundary::<Sys, S, M>(
            self.system,
            &state(&self.start),
            &state(&self.goal),
            first.as_slice(),
            last.as_slice(),
        )
    }

    /// A terminal cost must not depend on $q^{(k)}$: its derivatives in it vanish (checked at
    /// the guess's last jet) and its value is finite there.
    fn check_terminal_cost(&self, iterate: &Iterate<N, X>) -> Result<(), Error> {
        let (Some(phi), Some(last)) = (self.terminal_cost, iterate.x.last()) else {
            return Ok(());
        };
        let x = blocks::<N, K, X>(last);
        let u = SVector::<f64, N>::zeros();
        let (gradient, hessian) = (phi.gradient(&x, &u), phi.hessian(&x, &u));
        let on_u = gradient.u.amax()
            + hessian.uu.amax()
            + hessian.xu.iter().map(|m| m.amax()).fold(0.0, f64::max);
        if on_u != 0.0 || !phi.value(&x, &u).is_finite() {
            return Err(Error::InvalidArgument {
                name: "terminal cost",
                requirement: "a finite function of x_N = (q, ..., q^(k-1)) only, not of q^(k)",
            });
        }
        Ok(())
    }

    /// The singularity guard on every step ([`crate::step::check_step_domain`]): at its ends,
    /// its evaluation point and, for a chord longer than `chord_spacing`, on its pieces (none
    /// where the guards are quadratic: the three points decide the chord).
    pub(super) fn guard<const S: usize, const M: usize>(
        &self,
        iterate: &Iterate<N, X>,
    ) -> Result<(), (usize, DomainViolation)>
    where
        Sys: LiftedSystem<S, M>,
    {
        let options = crate::StepOptions::default()
            .with_theta(self.options.theta)
            .with_chord_check(self.options.chord_spacing, self.options.max_chord_pieces);
        // (the momenta are not read by the guard: zero, set once)
        let (mut z0, mut w) = (SVector::<f64, S>::zeros(), SVector::<f64, M>::zeros());
        for i in 0..self.steps {
            z0.fixed_rows_mut::<X>(0).copy_from(&iterate.x[i]);
            w.fixed_rows_mut::<X>(0).copy_from(&iterate.x[i + 1]);
            w.fixed_rows_mut::<N>(S).copy_from(&iterate.u[i]);
            crate::step::check_step_domain(self.system_at(i), &z0, &w, &options)
                .map_err(|v| (i, v))?;
        }
        Ok(())
    }
}
