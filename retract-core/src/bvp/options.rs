//! How the optimizer solves ([`PlanOptions`]) and where it starts ([`PlanGuess`]).

use std::time::Duration;

use nalgebra::SVector;

use super::curve::Curve;
use super::plan::Plan;
use crate::Error;

/// Options of [`OptimalControlProblem::solve`](crate::bvp::OptimalControlProblem::solve).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PlanOptions {
    /// The scheme parameter $\theta$ (1/2: midpoint).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub theta: f64,
    /// Converged when the relative stationarity
    /// ([`Certificate::stationarity`](super::Certificate::stationarity), scaled as IPOPT's by
    /// the multipliers' size where that is above the gradient's), the constraint violation and
    /// the complementarity $\max z s$ (not scaled: stricter than IPOPT's $s_c$) are all below
    /// this.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub tolerance: f64,
    /// Accepted instead of `tolerance` when the line search has made only rounding-level
    /// progress for three iterations (ill-conditioning near active inequalities) or the error
    /// has been below this level for fifteen consecutive iterations (IPOPT's
    /// `acceptable_iter`: an iterate converged as far as the problem's conditioning allows),
    /// as IPOPT's acceptable level; and where, at the barrier's floor, the iterate makes only
    /// rounding-level progress for ten iterations with the error above this level, or the
    /// iteration limit is reached, the last point whose barrier
    /// problem was solved with stationarity and feasibility below `tolerance` and
    /// complementarity below this level is certified and returned instead (a degenerate
    /// active inequality, whose slacks at the floor leave the multipliers without digits).
    /// The certificate reports the residuals reached.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub acceptable: f64,
    /// Iteration budget; 3000 by default (IPOPT's): the hard problems of the constrained
    /// suite need a few hundred to a few thousand iterations (`examples/constrained.rs`).
    pub max_iterations: usize,
    /// Wall-time budget, counted from the call to `solve`; `None` for none. The clock is read
    /// between the phases of an iteration (models, each factorisation of the inertia
    /// correction, each line-search trial) and every 1024 steps inside the model build and
    /// the factorisation, so a solve returns [`Failure::TimeLimit`](crate::bvp::Failure::TimeLimit) with the iterate reached
    /// about one such piece after the budget; the checks of the first guess before the first
    /// iteration (about 20 ms at 65 536 steps) are not interrupted.
    pub max_time: Option<Duration>,
    /// The chord of a step longer than this (max-norm of $x_{i+1} - x_i$) is checked by the
    /// singularity guard in pieces of at most this length, as
    /// [`crate::StepOptions::chord_spacing`]; 0.02 by default.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub chord_spacing: f64,
    /// The most pieces a step's chord is cut into, as
    /// [`crate::StepOptions::max_chord_pieces`]; 16 by default.
    pub max_chord_pieces: u32,
    /// Armijo constant of the line search.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub armijo: f64,
    /// Step halvings per line search.
    pub max_backtracks: usize,
    /// Initial barrier parameter $\mu_0$ of the inequalities, in the units of the transcribed
    /// problem (IPOPT's `mu_init`, whose default 0.1 it shares): its barrier term is $\mu_0
    /// \sum \ln s$ over the slacks of every inequality at every node and step.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub initial_barrier: f64,
    /// Also compute [`Certificate::min_reduced_hessian_eig`](super::Certificate::min_reduced_hessian_eig) (Lanczos on the final
    /// factorisation, less than one iteration's time); on by default, off in
    /// [`OptimalControlProblem::solve_real_time`](crate::bvp::OptimalControlProblem::solve_real_time). The inertia count that proves the reduced
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
    /// The most second-order corrections per line search (IPOPT's `max_soc`, and its
    /// default 4; 0 turns them off): where the full step is rejected and raises the
    /// constraint violation, the step is recomputed with the same factorisation for the
    /// accumulated residual of the nonlinear constraints ($c_{\rm soc} = \alpha c(x) + c(x +
    /// \alpha d)$), as long as each correction lowers the violation by the factor 0.99.
    /// Without them the constrained suite's quadrotor with $f_{\max} = 15$ leaves IPOPT's path
    /// at its second step (IPOPT's first trial is rejected there and its correction taken)
    /// and ends at 51.5119 instead of IPOPT's 51.3900.
    #[cfg_attr(feature = "serde", serde(default = "default_corrections"))]
    pub second_order_corrections: usize,
    /// The most escapes from saddles per solve (2 by default; 0: a saddle ends the solve in
    /// [`Failure::NotAMinimum`](super::Failure::NotAMinimum)). Where the iteration converges
    /// to a KKT point whose reduced Hessian has negative directions, it starts again (a cold
    /// start, with [`Self::max_iterations`] of its own) from a point below it along the
    /// direction of its most negative curvature; the plan's iterations count every start.
    /// Not in [`OptimalControlProblem::solve_real_time`](crate::bvp::OptimalControlProblem::solve_real_time).
    #[cfg_attr(feature = "serde", serde(default = "default_escapes"))]
    pub saddle_escapes: usize,
    /// Whether the feasibility restoration phase runs (Wächter and Biegler, sec. 3.3; on by
    /// default): where the exact-penalty search finds no step, or where its steps stay below
    /// $\gamma_\alpha \gamma_\theta = 5 \cdot 10^{-7}$ for five iterations in a row (the
    /// filter having found none), the iteration minimises the constraint violation (elastic
    /// inequality rows, a proximity term) until the filter accepts a point, or names the
    /// point locally infeasible. With it, the constrained suite's quadrotor started from the
    /// zero guess is certified at IPOPT's minimum, where without it the solve stalls
    /// (`tests/planning/restoration.rs`).
    #[cfg_attr(feature = "serde", serde(default = "default_restoration"))]
    pub restoration: bool,
    /// How the barrier parameter $\mu$ of the inequalities moves ([`BarrierUpdate`]:
    /// monotone by default).
    #[cfg_attr(feature = "serde", serde(default))]
    pub barrier_update: BarrierUpdate,
    /// The largest gradient of the cost at the first iterate before the cost is scaled
    /// (IPOPT's gradient-based scaling, `nlp_scaling_max_gradient`, whose default 100 it
    /// shares): a solve minimises $\sigma J$ with $\sigma = \min(1, g_{\max} / |\nabla
    /// J(x^0)|_\infty)$ (at least $10^{-8}$; the gradient over every node, the ends included,
    /// and every top derivative), so the tolerance, the barrier parameter and the inertia
    /// correction apply to $\sigma J$, as IPOPT's do; the plan reports $J$, its multipliers,
    /// momenta and smallest eigenvalue unscaled. Of the constrained suite, only the 7-link
    /// chain is scaled ($\sigma = 0.048$, as IPOPT's). Infinity turns it off; real-time
    /// iterations never scale.
    #[cfg_attr(feature = "serde", serde(default = "default_max_gradient"))]
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub scaling_max_gradient: f64,
}

/// The barrier parameter's update ([`PlanOptions::barrier_update`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BarrierUpdate {
    /// Fiacco and McCormick's monotone update, as IPOPT's default (`mu_strategy
    /// monotone`): $\mu$ stays until the barrier problem is solved to $10 \mu$, then
    /// $\mu \leftarrow \min(\mu / 5, \mu^{1.5})$ (in the transcribed problem's units), down to
    /// half the tolerance.
    #[default]
    Monotone,
    /// IPOPT's adaptive update (`mu_strategy adaptive` with `mu_oracle loqo` and
    /// `adaptive_mu_globalization obj-constr-filter`; Nocedal, Wächter and Waltz, SIAM J.
    /// Optim. 19, 2009): in its free mode $\mu$ is chosen afresh at every iterate by the
    /// LOQO rule, $\mu = \sigma \bar c$ with the average complementarity $\bar c$ and
    /// $\sigma = 0.1 \min(0.05 (1 - \xi)/\xi, 2)^3$ from the centrality $\xi = \min z s /
    /// \bar c$, between half the tolerance and $10^3$ times the first $\bar c$; an iterate
    /// whose cost and constraint violation are both no better than those of an earlier
    /// free-mode iterate (by a margin $10^{-5} \min(1, E)$, $E$ the error) ends the free
    /// mode, and the monotone update runs from $\mu = 0.8 \bar c$ until an iterate passes
    /// that test again; once the error and the complementarity are below the tolerance, $\mu$
    /// goes to half the tolerance for the certificate. On problems with many local minima the
    /// two updates end in different ones, as IPOPT's do: on the constrained suite the
    /// adaptive one ends at the minima of IPOPT's adaptive update with the LOQO oracle, the
    /// cart-poles and the quadrotor with $f_{\max} = 15$ where the monotone update does, the
    /// other quadrotor, the parkings and the 3-link chain higher, and it reaches the
    /// iteration limit on the 7-link chain, as IPOPT's does (the guide's section on the
    /// optimizer gives the figures).
    Adaptive,
}

/// [`PlanOptions::saddle_escapes`]'s default.
#[cfg(feature = "serde")]
fn default_escapes() -> usize {
    PlanOptions::default().saddle_escapes
}

/// [`PlanOptions::restoration`]'s default.
#[cfg(feature = "serde")]
fn default_restoration() -> bool {
    PlanOptions::default().restoration
}

/// IPOPT's `nlp_scaling_max_gradient`, [`PlanOptions::scaling_max_gradient`]'s default.
#[cfg(feature = "serde")]
fn default_max_gradient() -> f64 {
    PlanOptions::default().scaling_max_gradient
}

/// IPOPT's `max_soc`, [`PlanOptions::second_order_corrections`]'s default.
#[cfg(feature = "serde")]
fn default_corrections() -> usize {
    PlanOptions::default().second_order_corrections
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
            second_order_corrections: 4,
            saddle_escapes: 2,
            restoration: true,
            barrier_update: BarrierUpdate::Monotone,
            scaling_max_gradient: 100.0,
        }
    }
}

impl PlanOptions {
    /// Whether these are options at all (options read back from a file hold whatever numbers
    /// they were given): $\theta \in [0, 1]$, a finite `tolerance` $> 0$, a finite
    /// `acceptable` $\ge$ `tolerance`, `max_iterations` $\ge 1$, $0 <$ `armijo` $< 1/2$, a
    /// finite `initial_barrier` $> 0$, `scaling_max_gradient` $> 0$, `chord_spacing` $> 0$ (infinity: the three points
    /// only), `max_chord_pieces` at most [`crate::step::MAX_CHORD_PIECES`] and
    /// `interior_samples` at most [`MAX_INTERIOR_SAMPLES`]. Every solve runs it first (with the
    /// checks that need the problem: $\mu_0 / h$ finite, interior samples only for orders
    /// $k \le 4$).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `theta` for $\theta$, `options` for the others, its
    /// requirement naming the field.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |name, requirement| Err(Error::InvalidArgument { name, requirement });
        if !(0.0..=1.0).contains(&self.theta) {
            return invalid("theta", "theta must lie in [0, 1]");
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) || self.max_iterations == 0 {
            return invalid(
                "options",
                "need a finite tolerance > 0 and max_iterations >= 1",
            );
        }
        if !(self.acceptable.is_finite() && self.acceptable >= self.tolerance) {
            return invalid(
                "options",
                "the acceptable level must be finite and >= the tolerance",
            );
        }
        if !(self.initial_barrier.is_finite() && self.initial_barrier > 0.0) {
            return invalid(
                "options",
                "the initial barrier parameter must be finite and > 0",
            );
        }
        if self.scaling_max_gradient.is_nan() || self.scaling_max_gradient <= 0.0 {
            return invalid(
                "options",
                "scaling_max_gradient must be > 0 (infinity: no scaling)",
            );
        }
        if !(self.armijo > 0.0 && self.armijo < 0.5) {
            return invalid("options", "need 0 < armijo < 1/2");
        }
        if !(self.chord_spacing > 0.0 && self.max_chord_pieces <= crate::step::MAX_CHORD_PIECES) {
            return invalid(
                "options",
                "the chord spacing must be > 0 (infinity: the three points only) and \
                 max_chord_pieces at most MAX_CHORD_PIECES",
            );
        }
        if self.interior_samples > MAX_INTERIOR_SAMPLES {
            return invalid(
                "options",
                "at most 63 interior samples per step, for orders k <= 4",
            );
        }
        Ok(())
    }

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
    /// Sets the most second-order corrections per line search
    /// ([`Self::second_order_corrections`]; 0 turns them off).
    pub fn with_second_order_corrections(mut self, corrections: usize) -> Self {
        self.second_order_corrections = corrections;
        self
    }
    /// Turns the feasibility restoration phase on or off ([`Self::restoration`]).
    pub fn with_restoration(mut self, restoration: bool) -> Self {
        self.restoration = restoration;
        self
    }
    /// Sets the barrier parameter's update ([`Self::barrier_update`]).
    pub fn with_barrier_update(mut self, update: BarrierUpdate) -> Self {
        self.barrier_update = update;
        self
    }
    /// Sets the most escapes from saddles per solve ([`Self::saddle_escapes`]; 0 turns them
    /// off).
    pub fn with_saddle_escapes(mut self, escapes: usize) -> Self {
        self.saddle_escapes = escapes;
        self
    }
    /// Sets the largest cost gradient before the cost is scaled
    /// ([`Self::scaling_max_gradient`]; infinity turns the scaling off).
    pub fn with_scaling_max_gradient(mut self, max_gradient: f64) -> Self {
        self.scaling_max_gradient = max_gradient;
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
