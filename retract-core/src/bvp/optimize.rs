//! The optimizer: SQP on the direct transcription of the lifted-midpoint scheme.
//!
//! The boundary-value problem of the scheme is the KKT system of
//!
//! $$\min_{x, u}\ J = \sum_{i<N} h\,L(x_{\theta,i}, u_i) \quad \text{s.t.} \quad
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
//! backtracking line search on the exact penalty $J + \pi \|c\|_1$ ($c$: all constraints),
//! $\pi$ raised so that the direction descends; a trial point whose steps leave the domain of
//! $L$ (the generated singularity guard at both ends and the evaluation point of every step,
//! and on pieces of its chord no longer than `chord_spacing` unless its guards are quadratic,
//! as [`crate::step::check_step_domain`]) is rejected. A point is returned only
//! when the KKT residuals are below the tolerance and the reduced Hessian is positive definite
//! without correction; its [`Certificate`] holds the residuals and the smallest eigenvalue of
//! the reduced Hessian (Lanczos on the inverse, [`super::certificate`]).

use std::time::{Duration, Instant};

use nalgebra::SVector;

use super::constraints::{Inequality, Placement};
use super::curve::Curve;
use super::duals::Duals;
use super::guess::Hermite;
use super::riccati::Dynamics;
use super::sqp::Sqp;
use super::violations::{Infeasibility, Violations};
use crate::{DomainViolation, Error, JetFunction, Lagrangian, LiftedSystem};

/// Options of [`OptimalControlProblem::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PlanOptions {
    /// The scheme parameter $\theta$ (1/2: midpoint).
    pub theta: f64,
    /// Converged when the relative stationarity ([`Certificate::stationarity`]) and the
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
    /// Also compute [`Certificate::min_reduced_hessian_eig`] (Lanczos on the final
    /// factorisation, less than one iteration's time); on by default, off in
    /// [`OptimalControlProblem::solve_real_time`]. The inertia count that proves the reduced
    /// Hessian positive definite is always done.
    pub min_eigenvalue: bool,
}

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
    /// derivatives, and its [`Duals`] where they fit the problem's inequalities (else the
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

/// What a returned plan is certified to satisfy.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Certificate {
    /// Max-norm of the gradient of the Lagrangian of the transcription, with the multipliers
    /// of the last subproblem, divided by $h \max(1, |\nabla L|_\infty)$: stationarity per
    /// unit time relative to the size of the gradient of $L$.
    pub stationarity: f64,
    /// Max-norm of the constraint violation (dynamics defects, boundary data, stage
    /// equalities).
    pub feasibility: f64,
    /// $\max_j z_j g_j$ over the inequalities $g_j \ge 0$ with their multipliers $z_j$ (0
    /// without inequalities): how far the interior-point iterate is from complementarity.
    pub complementarity: f64,
    /// Negative eigenvalues of the reduced Hessian (0 for a returned plan).
    pub negative_directions: usize,
    /// The smallest eigenvalue of $Z^T \nabla^2 J\thinspace Z$, $Z$ an orthonormal basis of the
    /// null space of the constraint Jacobian in the variables $(x_1, \dots, x_{N-1}, u_0, \dots,
    /// u_{N-1})$; positive for a strict local minimum. With inequalities, the active ones
    /// enter as the penalties of the second-order check (a lower bound on the value on their
    /// null space too). Exactly 0 where the reduced Hessian is positive semidefinite and
    /// singular: a minimum, but not a strict one (the cost is flat to second order along
    /// some direction, e.g. ends that nothing fixes).
    /// NaN if [`PlanOptions::min_eigenvalue`] is off or the end $x_N$ has free
    /// components (the inertia count proves positivity either way).
    /// With `serde`, NaN is written as "none" (JSON `null`) and read back as NaN.
    #[cfg_attr(feature = "serde", serde(with = "nan_as_none"))]
    pub min_reduced_hessian_eig: f64,
}

/// An `f64` that may be NaN as an `Option<f64>` (`None` for NaN): formats without NaN, as
/// JSON, write it as `null` and read it back.
#[cfg(feature = "serde")]
mod nan_as_none {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, serializer: S) -> Result<S::Ok, S::Error> {
        (!v.is_nan()).then_some(*v).serialize(serializer)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(deserializer)?.unwrap_or(f64::NAN))
    }
}

/// A plan: a certified local minimum of the transcription.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Plan<const N: usize, const X: usize> {
    /// Step size $h = T/N$.
    pub h: f64,
    /// The scheme parameter.
    pub theta: f64,
    /// Jets $x_i = (q, \dots, q^{(k-1)})(t_i)$, $i = 0, \dots, N$.
    pub x: Vec<SVector<f64, X>>,
    /// Top derivatives $u_i$ at the evaluation points, $i < N$.
    pub u: Vec<SVector<f64, N>>,
    /// Ostrogradsky momenta $p_i$ recovered from the multipliers: $z_i = (x_i, p_i)$ is the
    /// state of the lifted scheme.
    pub momenta: Vec<SVector<f64, X>>,
    /// $J = \sum_i h\thinspace L(x_{\theta,i}, u_i)$.
    pub cost: f64,
    /// SQP iterations.
    pub iterations: usize,
    /// Residuals and curvature at this point.
    pub certificate: Certificate,
    /// The largest constraint violation at the nodes, at the evaluation points and along the
    /// interpolant ([`Violations`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub violations: Violations,
    /// The multipliers, slacks and barrier parameter at this point: a warm start from this
    /// plan ([`PlanGuess::Plan`]) starts from them too.
    #[cfg_attr(feature = "serde", serde(default))]
    pub duals: Duals<N>,
}

impl<const N: usize, const X: usize> Plan<N, X> {
    /// The times $t_i = i h$ of the jets $x_i$, $i = 0, \dots, N$.
    pub fn times(&self) -> Vec<f64> {
        (0..self.x.len()).map(|i| i as f64 * self.h).collect()
    }

    /// The state $z_i = (x_i, p_i)$ by blocks ([`crate::State`]: $q^{(j)}$, $p_j$ by name), or
    /// `None` past the end; `X` $= nk$ is checked at compile time.
    pub fn state<const K: usize>(&self, i: usize) -> Option<crate::State<N, K>> {
        const { assert!(N * K == X, "X must equal N K") };
        Some(crate::State {
            x: blocks::<N, K, X>(self.x.get(i)?),
            p: blocks::<N, K, X>(self.momenta.get(i)?),
        })
    }

    /// The jet $x(t) = (q, \dots, q^{(k-1)})(t)$ at any $t \in [0, T]$, $T = N h$: on the step
    /// $t_i \le t \le t_{i+1}$ the Hermite interpolant of degree $2k-1$ in each coordinate
    /// that matches the plan's jets $x_i$ at $t_i$ and $x_{i+1}$ at $t_{i+1}$ (for $k = 2$,
    /// with $s = (t - t_i)/h$: $q(t) = (2s^3 - 3s^2 + 1) q_i + (s^3 - 2s^2 + s) h q'_i +
    /// (3s^2 - 2s^3) q_{i+1} + (s^3 - s^2) h q'_{i+1}$). It reproduces polynomials of degree
    /// $2k-1$ exactly and is $C^{k-1}$ across the nodes, where it equals the plan's jets.
    ///
    /// ```
    /// use retract_core::bvp::{OptimalControlProblem, PlanGuess};
    /// use retract_core::models::PlanarBarrier;
    ///
    /// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
    /// let problem = OptimalControlProblem::new(&system, &[0.0; 4], &[1.0, 2.0, 0.0, 0.0], 1.0, 40);
    /// let plan = problem.solve(PlanGuess::Spline)?;
    /// // the continuous optimum from rest to rest is the smoothstep q(T) (3 s^2 - 2 s^3)
    /// let x = plan.evaluate(0.3)?;
    /// let smooth = 3.0 * 0.3f64.powi(2) - 2.0 * 0.3f64.powi(3);
    /// assert!((x[0] - smooth).abs() < 1e-3 && (x[1] - 2.0 * smooth).abs() < 1e-3);
    /// assert_eq!(plan.evaluate(plan.times()[20])?, plan.x[20]); // a node: the plan's jet
    /// assert!(plan.evaluate(1.5).is_err()); // outside [0, T]
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for $t$ outside $[0, T]$ (beyond a relative $10^{-12}$ for
    /// rounding), not finite, or a plan without steps.
    pub fn evaluate(&self, t: f64) -> Result<SVector<f64, X>, Error> {
        let steps = self.x.len().saturating_sub(1);
        let t_end = self.h * steps as f64;
        let slack = 1e-12 * t_end.abs();
        if steps == 0 || N == 0 || !X.is_multiple_of(N) || !(self.h.is_finite() && self.h > 0.0) {
            return Err(Error::InvalidArgument {
                name: "plan",
                requirement: "a plan to evaluate needs at least one step of finite h > 0",
            });
        }
        if !(t >= -slack && t <= t_end + slack) {
            return Err(Error::InvalidArgument {
                name: "t",
                requirement: "a plan is evaluated at times 0 <= t <= T = N h",
            });
        }
        let t = t.clamp(0.0, t_end);
        if t == t_end {
            return Ok(self.x[steps]);
        }
        // the step holding t; at a node (t = i h up to the rounding of t / h) the one it starts
        let mut i = ((t / self.h) as usize).min(steps - 1);
        if i + 1 < steps && (i + 1) as f64 * self.h <= t {
            i += 1;
        }
        let local = t - i as f64 * self.h;
        let piece = Hermite::new(
            self.x[i].as_slice(),
            self.x[i + 1].as_slice(),
            self.h,
            N,
            X / N,
        )?;
        Ok(SVector::from_fn(|r, _| piece.jet_entry(r, local)))
    }

    /// The plan shifted one step forward in time, for a receding-horizon warm start
    /// ([`PlanGuess::Plan`]): $x_i \leftarrow x_{i+1}$, $u_i \leftarrow u_{i+1}$, the last
    /// top derivative repeated and the new last jet one step of the scheme's $x$-equations
    /// from the old end with it. The momenta and the duals are shifted alike (the last ones
    /// repeated); the certificate is that of the unshifted plan.
    pub fn shifted(&self) -> Self {
        let mut out = self.clone();
        let (Some(&last_x), Some(&last_u)) = (self.x.last(), self.u.last()) else {
            return out;
        };
        let dynamics = Dynamics::<N, X>::new(self.h, self.theta);
        out.x.remove(0);
        out.x.push(dynamics.next(&last_x, &last_u));
        out.u.remove(0);
        out.u.push(last_u);
        if let Some(&last_p) = self.momenta.last() {
            out.momenta.remove(0);
            out.momenta.push(last_p);
        }
        out.duals = self.duals.shifted(self.u.len());
        out
    }
}

/// The result of [`OptimalControlProblem::solve_real_time`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RealTime<const N: usize, const X: usize> {
    /// The last iterate (a certified minimum only if `converged`).
    pub plan: Plan<N, X>,
    /// Whether the KKT and second-order conditions hold at `plan`.
    pub converged: bool,
}

/// Why the optimizer stopped without a certified plan.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Failure {
    /// Invalid input (no iterate).
    Invalid(Error),
    /// The first guess leaves the domain of $L$ (e.g. passes through an obstacle) at step
    /// `step`.
    GuessOutsideDomain {
        /// The step.
        step: usize,
        /// What was violated.
        violation: DomainViolation,
    },
    /// A model value (cost, gradient, Hessian) was not finite.
    NonFinite,
    /// The iteration budget ran out.
    IterationLimit,
    /// The wall-time budget ran out.
    TimeLimit,
    /// No step along the (descent) direction was accepted.
    LineSearch,
    /// The inertia correction reached its cap without making the reduced Hessian definite.
    Regularization,
    /// A constraint the interior-point iteration cannot satisfy (refused before iterating):
    /// its own data contradict themselves or leave no interior (equal sides: write an
    /// equality), or the fixed start or goal violates it at the node.
    Infeasible(Infeasibility),
    /// The iteration stalled at a point that violates a constraint (the inertia correction or
    /// the line search failed there): the constraint violated most at the last iterate, where,
    /// and by how much. The constraints may contradict each other there (a point of local
    /// infeasibility), or the guess meets an obstacle head on, with no side to pass it
    /// preferred.
    StalledInfeasible(Infeasibility),
    /// The KKT conditions hold but the reduced Hessian has negative curvature: a saddle, not
    /// a minimum. (With 0 negative directions: the second-order check could not be made,
    /// the stage constraints being dependent at the point. A reduced Hessian that is only
    /// singular, positive semidefinite, is a minimum flat along some direction: certified
    /// with [`Certificate::min_reduced_hessian_eig`] 0.)
    NotAMinimum {
        /// Negative eigenvalues of the reduced Hessian.
        negative_directions: usize,
    },
}

/// A failed solve: the reason and, where there was one, the last iterate with its residuals
/// (its `certificate` describes it; it is not a minimum). Its `Debug` output summarises the
/// iterate instead of listing it.
#[derive(Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PlanError<const N: usize, const X: usize> {
    /// Why.
    pub failure: Failure,
    /// The last iterate (the best by the merit function).
    pub last: Option<Box<Plan<N, X>>>,
}

impl core::fmt::Display for Failure {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Failure::Invalid(e) => write!(f, "{e}"),
            Failure::GuessOutsideDomain { step, violation } => write!(
                f,
                "the first guess leaves the domain of the Lagrangian at step {step} \
                 ({violation}): pass a guess that stays inside it, e.g. around the obstacle"
            ),
            Failure::NonFinite => write!(
                f,
                "a non-finite cost, gradient or Hessian at an iterate: check the parameters"
            ),
            Failure::IterationLimit => write!(
                f,
                "no certified minimum within the iteration budget; the last iterate is attached"
            ),
            Failure::TimeLimit => write!(
                f,
                "the wall-time budget ran out; the best iterate is attached"
            ),
            Failure::LineSearch => write!(
                f,
                "the line search found no acceptable step (the direction descends, but every \
                 trial point left the domain or did not decrease the merit function); the \
                 last iterate is attached"
            ),
            Failure::Regularization => write!(
                f,
                "the inertia correction could not make the reduced Hessian positive definite"
            ),
            Failure::Infeasible(infeasibility) => write!(f, "infeasible: {infeasibility}"),
            Failure::StalledInfeasible(infeasibility) => write!(
                f,
                "stalled at an infeasible point: {infeasibility}; check that the constraints \
                 can hold together there, or start from a guess that satisfies them (around \
                 an obstacle, not through it)"
            ),
            Failure::NotAMinimum {
                negative_directions: 0,
            } => write!(
                f,
                "the second-order check failed at the KKT point found: the stage \
                 constraints are dependent there; remove the redundant ones or start from \
                 another guess"
            ),
            Failure::NotAMinimum {
                negative_directions,
            } => write!(
                f,
                "the KKT point found is not a minimum: its reduced Hessian has \
                 {negative_directions} negative eigenvalue(s); start from another guess"
            ),
        }
    }
}

impl<const N: usize, const X: usize> core::fmt::Display for PlanError<N, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}", self.failure)?;
        if let Some(last) = &self.last {
            let c = &last.certificate;
            write!(
                f,
                " (after {} iterations: cost {:e}, stationarity {:e}, feasibility {:e})",
                last.iterations, last.cost, c.stationarity, c.feasibility
            )?;
            if matches!(self.failure, Failure::IterationLimit | Failure::TimeLimit) {
                write!(f, "; {}", advice(c, last.iterations))?;
            }
        }
        Ok(())
    }
}

/// The iterations after which a budget that ran out is not advised to be raised (the
/// constrained suite's hardest solve needs 1784).
const LONG_RUN: usize = 2000;

/// What to do about a budget that ran out, from the residuals the last iterate reached after
/// `iterations`.
fn advice(c: &Certificate, iterations: usize) -> &'static str {
    if c.feasibility <= 1e-6 && c.stationarity <= 1e-4 {
        "the iterate is feasible and nearly stationary: more iterations will not improve it \
         beyond rounding; a looser tolerance accepts it (or raise the acceptable level)"
    } else if c.feasibility.is_nan() || c.feasibility > 1e-3 {
        "the iterate is still far from feasible: start from a guess that satisfies the \
         constraints, or check that they can hold together"
    } else if iterations >= LONG_RUN {
        "the iteration is not settling: more iterations are unlikely to help; start from \
         another guess (one closer to a solution, or inside the constraints)"
    } else {
        "raise max_iterations, or start from a better guess"
    }
}

impl<const N: usize, const X: usize> core::fmt::Debug for PlanError<N, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let mut d = f.debug_struct("PlanError");
        d.field("failure", &self.failure);
        if let Some(last) = &self.last {
            d.field("steps", &last.u.len())
                .field("iterations", &last.iterations)
                .field("cost", &last.cost)
                .field("certificate", &last.certificate);
        }
        d.finish()
    }
}

impl<const N: usize, const X: usize> std::error::Error for PlanError<N, X> {}

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
        }
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
        self
    }

    fn h(&self) -> f64 {
        self.t_end / self.steps as f64
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
                 top index < n, and no node placement for what involves the top derivative",
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

/// $x$ as blocks $(x_0, \dots, x_{k-1})$.
pub(crate) fn blocks<const N: usize, const K: usize, const X: usize>(
    x: &SVector<f64, X>,
) -> [SVector<f64, N>; K] {
    core::array::from_fn(|j| SVector::from_fn(|a, _| x[j * N + a]))
}

/// The iterate of the optimizer.
#[derive(Clone)]
pub(super) struct Iterate<const N: usize, const X: usize> {
    pub x: Vec<SVector<f64, X>>,
    pub u: Vec<SVector<f64, N>>,
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
        let iterate = self.initial(guess).map_err(invalid)?;
        self.check_terminal_cost(&iterate).map_err(invalid)?;
        self.check_ends::<S, M>(&iterate).map_err(invalid)?;
        if let Err((step, violation)) = self.guard::<S, M>(&iterate) {
            return Err(PlanError {
                failure: Failure::GuessOutsideDomain { step, violation },
                last: None,
            });
        }
        let placed = |at: fn(Placement) -> bool| {
            let list = self.inequalities.iter().filter(|c| at(c.placement));
            list.copied().collect()
        };
        Sqp::<Sys, N, K, X, S, M> {
            problem: self,
            dynamics: Dynamics::new(self.h(), self.options.theta),
            started,
            at_steps: placed(Placement::at_midpoints),
            // (at theta = 0 or 1 the evaluation points are nodes: no second copy there)
            at_nodes: if self.options.theta == 0.0 || self.options.theta == 1.0 {
                placed(|p| p == Placement::Nodes)
            } else {
                placed(Placement::at_nodes)
            },
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
        let mut capped = self.clone();
        capped.options.max_iterations = iterations.max(1);
        // (a receding horizon needs the plan now, not its curvature)
        capped.options.min_eigenvalue = false;
        match capped.solve(guess) {
            Ok(plan) => Ok(RealTime {
                plan,
                converged: true,
            }),
            Err(PlanError {
                failure: Failure::IterationLimit,
                last: Some(plan),
            }) => Ok(RealTime {
                plan: *plan,
                converged: false,
            }),
            Err(e) => Err(e),
        }
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

    fn initial(&self, guess: PlanGuess<'_, N, X>) -> Result<Iterate<N, X>, Error> {
        let (h, theta, steps) = (self.h(), self.options.theta, self.steps);
        let wrong = |requirement| Error::InvalidArgument {
            name: "guess",
            requirement,
        };
        let iterate = match guess {
            PlanGuess::Spline => {
                let spline = Hermite::new(
                    self.start.as_slice(),
                    self.goal.as_slice(),
                    self.t_end,
                    N,
                    K,
                )?;
                let x = (0..=steps)
                    .map(|i| SVector::from_fn(|r, _| spline.jet_entry(r, i as f64 * h)))
                    .collect();
                let u = (0..steps)
                    .map(|i| {
                        let t = (i as f64 + theta) * h;
                        SVector::from_fn(|a, _| spline.derivative(a, K, t))
                    })
                    .collect();
                Iterate { x, u }
            }
            PlanGuess::Plan(plan) => {
                if plan.x.len() != steps + 1 || plan.u.len() != steps {
                    return Err(wrong(
                        "a warm start needs a plan with the same number of steps",
                    ));
                }
                Iterate {
                    x: plan.x.clone(),
                    u: plan.u.clone(),
                }
            }
            PlanGuess::Curve(curve) => curve.sample::<K, X>(self.t_end, steps, theta)?,
            PlanGuess::Path { x, u } => {
                if x.len() != steps + 1 || u.len() != steps {
                    return Err(wrong("a path guess needs N + 1 jets and N top derivatives"));
                }
                Iterate {
                    x: x.to_vec(),
                    u: u.to_vec(),
                }
            }
        };
        let finite = |v: &[f64]| v.iter().all(|e| e.is_finite());
        if !iterate.x.iter().all(|v| finite(v.as_slice()))
            || !iterate.u.iter().all(|v| finite(v.as_slice()))
        {
            return Err(wrong("the guess must be finite"));
        }
        Ok(iterate)
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

pub(super) fn unknown_certificate() -> Certificate {
    Certificate {
        stationarity: f64::NAN,
        feasibility: f64::NAN,
        complementarity: f64::NAN,
        negative_directions: 0,
        min_reduced_hessian_eig: f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::{Certificate, LONG_RUN, advice};

    fn residuals(stationarity: f64, feasibility: f64) -> Certificate {
        Certificate {
            stationarity,
            feasibility,
            complementarity: 0.0,
            negative_directions: 0,
            min_reduced_hessian_eig: f64::NAN,
        }
    }

    /// The advice after a budget ran out follows the residuals and the iterations spent: a
    /// converged iterate is not told to iterate more, an infeasible one to check its
    /// constraints, and one that has not settled in a long run not to raise the budget.
    #[test]
    fn the_advice_of_a_spent_budget_matches_the_iterate() {
        assert!(advice(&residuals(1e-6, 1e-9), 50).contains("will not improve"));
        assert!(advice(&residuals(1.0, 1e-2), 50).contains("far from feasible"));
        assert!(advice(&residuals(1.0, 1e-9), 50).contains("raise max_iterations"));
        let long = advice(&residuals(5.3, 2.7e-9), LONG_RUN);
        assert!(
            long.contains("unlikely to help") && !long.contains("raise"),
            "{long}"
        );
    }
}
