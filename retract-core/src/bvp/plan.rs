//! What a solve returns: the plan with its certificate, the real-time result, and the
//! failures with their advice.

use nalgebra::SVector;

use super::duals::Duals;
use super::guess::Hermite;
use super::optimize::blocks;
use super::riccati::Dynamics;
use super::violations::{Infeasibility, Violations};
use crate::{DomainViolation, Error};

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
    /// NaN if [`PlanOptions::min_eigenvalue`](super::PlanOptions::min_eigenvalue) is off or the end $x_N$ has free
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
    /// plan ([`PlanGuess::Plan`](super::PlanGuess::Plan)) starts from them too.
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
    /// ([`PlanGuess::Plan`](super::PlanGuess::Plan)): $x_i \leftarrow x_{i+1}$, $u_i \leftarrow u_{i+1}$, the last
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
        out.duals.shift(self.u.len());
        out
    }
}

/// The result of [`OptimalControlProblem::solve_real_time`](super::OptimalControlProblem::solve_real_time).
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

impl<const N: usize, const X: usize> PlanError<N, X> {
    /// A failure before the first iterate was formed.
    pub(super) fn without_iterate(failure: Failure) -> Self {
        Self {
            failure,
            last: None,
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
