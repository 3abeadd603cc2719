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
//! $L$ (the generated singularity guard, at both ends, the evaluation point and
//! `chord_samples` points of the chord of every step) is rejected. A point is returned only
//! when the KKT residuals are below the tolerance and the reduced Hessian is positive definite
//! without correction; its [`Certificate`] holds the residuals and the smallest eigenvalue of
//! the reduced Hessian (Lanczos on the inverse, [`super::certificate`]).

use std::time::{Duration, Instant};

use nalgebra::{SMatrix, SVector};

use super::certificate::{kkt_residuals, min_reduced_eigenvalue};
use super::guess::Hermite;
use super::riccati::{Dynamics, Riccati, StageModel};
use crate::{DomainViolation, Error, Lagrangian, LiftedSystem};

/// Options of [`OptimalControlProblem::solve`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct PlanOptions {
    /// The scheme parameter $\theta$ (1/2: midpoint).
    pub theta: f64,
    /// Converged when the stationarity residual (per unit time) and the constraint violation
    /// are both below this.
    pub tolerance: f64,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Wall-time budget; `None` for none.
    pub max_time: Option<Duration>,
    /// Points of the chord of every step, besides its ends and evaluation point, at which the
    /// singularity guard is checked.
    pub chord_samples: usize,
    /// Armijo constant of the line search.
    pub armijo: f64,
    /// Step halvings per line search.
    pub max_backtracks: usize,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            theta: 0.5,
            tolerance: 1e-9,
            max_iterations: 200,
            max_time: None,
            chord_samples: 3,
            armijo: 1e-4,
            max_backtracks: 40,
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
    /// Sets the number of chord points checked by the singularity guard per step.
    pub fn with_chord_samples(mut self, chord_samples: usize) -> Self {
        self.chord_samples = chord_samples;
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
    /// A previous plan with the same number of steps (warm start).
    Plan(&'a Plan<N, X>),
    /// Jets $x_0, \dots, x_N$ and top derivatives $u_0, \dots, u_{N-1}$ chosen by the caller.
    Path {
        /// $x_i = (q, \dots, q^{(k-1)})(t_i)$.
        x: &'a [SVector<f64, X>],
        /// $u_i = q^{(k)}$ at the evaluation point of step $i$.
        u: &'a [SVector<f64, N>],
    },
}

/// What a returned plan is certified to satisfy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Certificate {
    /// Max-norm of the gradient of the Lagrangian of the transcription divided by $h$
    /// (stationarity per unit time), with the multipliers of the last subproblem.
    pub stationarity: f64,
    /// Max-norm of the constraint violation (dynamics defects, boundary data).
    pub feasibility: f64,
    /// Negative eigenvalues of the reduced Hessian (0 for a returned plan).
    pub negative_directions: usize,
    /// The smallest eigenvalue of $Z^T \nabla^2 J\, Z$, $Z$ an orthonormal basis of the null
    /// space of the constraint Jacobian in the variables $(x_1, \dots, x_{N-1}, u_0, \dots,
    /// u_{N-1})$; positive for a strict local minimum. NaN when not computed.
    pub min_reduced_hessian_eig: f64,
}

/// A plan: a certified local minimum of the transcription.
#[derive(Clone, Debug, PartialEq)]
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
    /// $J = \sum_i h\,L(x_{\theta,i}, u_i)$.
    pub cost: f64,
    /// SQP iterations.
    pub iterations: usize,
    /// Residuals and curvature at this point.
    pub certificate: Certificate,
}

/// Why the optimizer stopped without a certified plan.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
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
    /// The KKT conditions hold but the reduced Hessian has negative (or zero) curvature: a
    /// saddle, not a minimum.
    NotAMinimum {
        /// Negative eigenvalues of the reduced Hessian.
        negative_directions: usize,
    },
}

/// A failed solve: the reason and, where there was one, the last iterate with its residuals
/// (its `certificate` describes it; it is not a minimum).
#[derive(Clone, Debug, PartialEq)]
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
                "no certified minimum within the iteration budget; the last iterate is \
                 attached (raise max_iterations, or start from a better guess)"
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
            Failure::NotAMinimum {
                negative_directions,
            } => write!(
                f,
                "the KKT point found is not a minimum: its reduced Hessian has \
                 {negative_directions} non-positive eigenvalue(s); start from another guess"
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
        }
        Ok(())
    }
}

impl<const N: usize, const X: usize> std::error::Error for PlanError<N, X> {}

/// An optimal-control problem: minimise $\sum_i h\,L(x_{\theta,i}, u_i)$ over the lifted
/// scheme from the jet $a$ to the jet $b$ in time $T$ with $N$ steps.
///
/// `N` is the dimension $n$, `K` the order $k$ and `X` $= nk$ the length of a jet; `S` and
/// `M` are those of the system's [`LiftedSystem`] (used for its singularity guard).
pub struct OptimalControlProblem<'a, Sys: ?Sized, const N: usize, const X: usize> {
    system: &'a Sys,
    start: SVector<f64, X>,
    goal: SVector<f64, X>,
    t_end: f64,
    steps: usize,
    options: PlanOptions,
}

impl<'a, Sys: ?Sized, const N: usize, const X: usize> OptimalControlProblem<'a, Sys, N, X> {
    /// The problem from `start` $= (q, \dots, q^{(k-1)})(0)$ to `goal` at $T$ = `t_end` in
    /// `steps` steps (jets in blocks of $n$).
    pub fn new(
        system: &'a Sys,
        start: &[f64; X],
        goal: &[f64; X],
        t_end: f64,
        steps: usize,
    ) -> Self {
        Self {
            system,
            start: SVector::from_column_slice(start),
            goal: SVector::from_column_slice(goal),
            t_end,
            steps,
            options: PlanOptions::default(),
        }
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
        if !(o.tolerance.is_finite() && o.tolerance > 0.0) || o.max_iterations == 0 {
            return invalid(
                "options",
                "need a finite tolerance > 0 and max_iterations >= 1",
            );
        }
        if !(o.armijo > 0.0 && o.armijo < 0.5) || o.chord_samples > 64 {
            return invalid("options", "need 0 < armijo < 1/2 and chord_samples <= 64");
        }
        Ok(())
    }
}

/// $x$ as blocks $(x_0, \dots, x_{k-1})$.
pub(crate) fn blocks<const N: usize, const K: usize, const X: usize>(
    x: &SVector<f64, X>,
) -> [SVector<f64, N>; K] {
    core::array::from_fn(|j| SVector::from_fn(|a, _| x[j * N + a]))
}

/// The iterate of the optimizer.
#[derive(Clone)]
struct Iterate<const N: usize, const X: usize> {
    x: Vec<SVector<f64, X>>,
    u: Vec<SVector<f64, N>>,
}

impl<Sys: ?Sized, const N: usize, const X: usize> OptimalControlProblem<'_, Sys, N, X> {
    /// Solves the problem from `guess`.
    ///
    /// # Errors
    /// A [`PlanError`] with the [`Failure`] and, after the first iteration, the last iterate.
    pub fn solve<const K: usize, const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
    ) -> Result<Plan<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let invalid = |e| PlanError {
            failure: Failure::Invalid(e),
            last: None,
        };
        self.validate(N, K).map_err(invalid)?;
        if S != 2 * X || M != S + N {
            return Err(invalid(Error::InvalidArgument {
                name: "system",
                requirement: "the optimizer needs the general unknowns w = (z_1, u)",
            }));
        }
        let iterate = self.initial::<K>(guess).map_err(invalid)?;
        if let Err((step, violation)) = self.guard::<S, M>(&iterate) {
            return Err(PlanError {
                failure: Failure::GuessOutsideDomain { step, violation },
                last: None,
            });
        }
        Sqp::<Sys, N, K, X, S, M> {
            problem: self,
            dynamics: Dynamics::new(self.h(), self.options.theta),
            started: Instant::now(),
        }
        .run(iterate)
    }

    fn initial<const K: usize>(&self, guess: PlanGuess<'_, N, X>) -> Result<Iterate<N, X>, Error> {
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

    /// The singularity guard on every step: at its ends, its evaluation point and
    /// `chord_samples` interior points of its chord.
    fn guard<const S: usize, const M: usize>(
        &self,
        iterate: &Iterate<N, X>,
    ) -> Result<(), (usize, DomainViolation)>
    where
        Sys: LiftedSystem<S, M>,
    {
        let samples = self.options.chord_samples;
        for i in 0..self.steps {
            let z0 = SVector::<f64, S>::from_fn(|r, _| if r < X { iterate.x[i][r] } else { 0.0 });
            let w = SVector::<f64, M>::from_fn(|r, _| {
                if r < X {
                    iterate.x[i + 1][r]
                } else if r >= S {
                    iterate.u[i][r - S]
                } else {
                    0.0
                }
            });
            let at = |s: f64| self.system.check_domain(&z0, &w, s).map_err(|v| (i, v));
            at(self.options.theta)?;
            for j in 1..=samples {
                at(j as f64 / (samples + 1) as f64)?;
            }
        }
        Ok(())
    }
}

/// One run of the SQP iteration.
struct Sqp<
    'p,
    'a,
    Sys: ?Sized,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
> {
    problem: &'p OptimalControlProblem<'a, Sys, N, X>,
    dynamics: Dynamics<N, X>,
    started: Instant,
}

/// The models of all stages at one iterate.
struct Models<const N: usize, const X: usize> {
    stages: Vec<StageModel<N, X>>,
    cost: f64,
    r0: SVector<f64, X>,
    r_end: SVector<f64, X>,
}

impl<const N: usize, const X: usize> Models<N, X> {
    /// $\|c\|_1$ over defects and boundary data.
    fn violation_l1(&self) -> f64 {
        self.stages.iter().map(|s| s.defect.lp_norm(1)).sum::<f64>()
            + self.r0.lp_norm(1)
            + self.r_end.lp_norm(1)
    }
    /// $\|c\|_\infty$.
    fn violation_max(&self) -> f64 {
        self.stages
            .iter()
            .map(|s| s.defect.amax())
            .fold(self.r0.amax().max(self.r_end.amax()), f64::max)
    }
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    fn x_theta(&self, iterate: &Iterate<N, X>, i: usize) -> SVector<f64, X> {
        let theta = self.dynamics.theta;
        iterate.x[i] * (1.0 - theta) + iterate.x[i + 1] * theta
    }

    /// $J$ alone (line search); `None` if not finite.
    fn cost(&self, iterate: &Iterate<N, X>) -> Option<f64> {
        let h = self.dynamics.h;
        let system = self.problem.system;
        let cost: f64 = (0..iterate.u.len())
            .map(|i| h * system.lagrangian(&blocks(&self.x_theta(iterate, i)), &iterate.u[i]))
            .sum();
        cost.is_finite().then_some(cost)
    }

    /// Cost, gradients, Hessians and defects at `iterate`; `None` if anything is not finite.
    fn models(&self, iterate: &Iterate<N, X>) -> Option<Models<N, X>> {
        let (h, system) = (self.dynamics.h, self.problem.system);
        let mut stages = Vec::with_capacity(iterate.u.len());
        let mut cost = 0.0;
        for (i, u) in iterate.u.iter().enumerate() {
            let xb = blocks::<N, K, X>(&self.x_theta(iterate, i));
            let g = system.gradient(&xb, u);
            let hs = system.hessian(&xb, u);
            cost += h * system.lagrangian(&xb, u);
            let stage = StageModel {
                hxx: SMatrix::from_fn(|r, c| h * hs.xx[r / N][c / N][(r % N, c % N)]),
                hux: SMatrix::from_fn(|b, c| h * hs.xu[c / N][(c % N, b)]),
                huu: hs.uu * h,
                gx: SVector::from_fn(|r, _| h * g.x[r / N][r % N]),
                gu: g.u * h,
                defect: self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1],
            };
            let finite = stage
                .hxx
                .iter()
                .chain(stage.hux.iter())
                .chain(stage.huu.iter())
                .chain(stage.gx.iter())
                .chain(stage.gu.iter())
                .all(|v| v.is_finite());
            if !finite {
                return None;
            }
            stages.push(stage);
        }
        let r0 = self.problem.start - iterate.x[0];
        let r_end = self.problem.goal - iterate.x[iterate.x.len() - 1];
        cost.is_finite().then_some(Models {
            stages,
            cost,
            r0,
            r_end,
        })
    }

    /// The Riccati factorisation with the smallest inertia correction $\rho$ (scaled by $h$)
    /// that makes the reduced Hessian positive definite, starting from a third of `last`.
    fn factor_corrected(&self, models: &Models<N, X>, last: f64) -> Option<(Riccati<N, X>, f64)> {
        let h = self.dynamics.h;
        let riccati = Riccati::factor(&self.dynamics, &models.stages, 0.0);
        if riccati.positive_definite() {
            return Some((riccati, 0.0));
        }
        let mut rho = if last > 0.0 {
            (last / 3.0).max(1e-20)
        } else {
            1e-4
        };
        while rho < 1e40 {
            let riccati = Riccati::factor(&self.dynamics, &models.stages, h * rho);
            if riccati.positive_definite() {
                return Some((riccati, rho));
            }
            rho *= if last > 0.0 { 8.0 } else { 100.0 };
        }
        None
    }

    fn plan(
        &self,
        iterate: &Iterate<N, X>,
        cost: f64,
        iterations: usize,
        momenta: Vec<SVector<f64, X>>,
        certificate: Certificate,
    ) -> Plan<N, X> {
        Plan {
            h: self.dynamics.h,
            theta: self.dynamics.theta,
            x: iterate.x.clone(),
            u: iterate.u.clone(),
            momenta,
            cost,
            iterations,
            certificate,
        }
    }

    fn run(&self, mut iterate: Iterate<N, X>) -> Result<Plan<N, X>, PlanError<N, X>> {
        let options = &self.problem.options;
        let h = self.dynamics.h;
        let mut rho_last = 0.0;
        let mut penalty = 0.0;
        let mut iterations = 0;
        loop {
            let done = iterations;
            let fail = |failure, iterate: &Iterate<N, X>, cost, certificate, momenta| PlanError {
                failure,
                last: Some(Box::new(self.plan(
                    iterate,
                    cost,
                    done,
                    momenta,
                    certificate,
                ))),
            };
            let Some(models) = self.models(&iterate) else {
                return Err(PlanError {
                    failure: Failure::NonFinite,
                    last: None,
                });
            };
            let Some((riccati, rho)) = self.factor_corrected(&models, rho_last) else {
                return Err(fail(
                    Failure::Regularization,
                    &iterate,
                    models.cost,
                    unknown_certificate(),
                    Vec::new(),
                ));
            };
            rho_last = rho;
            let direction = riccati.solve(
                &self.dynamics,
                &models.stages,
                h * rho,
                &models.r0,
                &models.r_end,
            );
            let (momenta, stationarity) =
                kkt_residuals(&self.dynamics, &models.stages, &direction.costate);
            let mut certificate = Certificate {
                stationarity,
                feasibility: models.violation_max(),
                negative_directions: riccati.negative,
                min_reduced_hessian_eig: f64::NAN,
            };
            if stationarity <= options.tolerance && certificate.feasibility <= options.tolerance {
                if rho > 0.0 {
                    let exact = Riccati::factor(&self.dynamics, &models.stages, 0.0);
                    certificate.negative_directions = exact.negative.max(1);
                    return Err(fail(
                        Failure::NotAMinimum {
                            negative_directions: certificate.negative_directions,
                        },
                        &iterate,
                        models.cost,
                        certificate,
                        momenta,
                    ));
                }
                certificate.min_reduced_hessian_eig =
                    min_reduced_eigenvalue(&riccati, &self.dynamics, self.problem.steps);
                return Ok(self.plan(&iterate, models.cost, iterations, momenta, certificate));
            }
            if iterations == options.max_iterations {
                return Err(fail(
                    Failure::IterationLimit,
                    &iterate,
                    models.cost,
                    certificate,
                    momenta,
                ));
            }
            if options
                .max_time
                .is_some_and(|budget| self.started.elapsed() >= budget)
            {
                return Err(fail(
                    Failure::TimeLimit,
                    &iterate,
                    models.cost,
                    certificate,
                    momenta,
                ));
            }
            iterations += 1;
            match self.line_search(&iterate, &models, &direction, &mut penalty) {
                Some(next) => iterate = next,
                None => {
                    return Err(fail(
                        Failure::LineSearch,
                        &iterate,
                        models.cost,
                        certificate,
                        momenta,
                    ));
                }
            }
        }
    }

    /// Backtracking on $J + \pi \|c\|_1$ along the direction; `None` if no step is accepted.
    fn line_search(
        &self,
        iterate: &Iterate<N, X>,
        models: &Models<N, X>,
        direction: &super::riccati::Direction<N, X>,
        penalty: &mut f64,
    ) -> Option<Iterate<N, X>> {
        let options = &self.problem.options;
        let theta = self.dynamics.theta;
        // directional derivative of J and the curvature of the model along the direction
        let (mut slope, mut curvature) = (0.0, 0.0);
        for (i, stage) in models.stages.iter().enumerate() {
            let dxt = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
            let du = &direction.du[i];
            slope += stage.gx.dot(&dxt) + stage.gu.dot(du);
            curvature += dxt.dot(&(stage.hxx * dxt))
                + 2.0 * du.dot(&(stage.hux * dxt))
                + du.dot(&(stage.huu * du));
        }
        let violation = models.violation_l1();
        if violation > 0.0 {
            let needed = (slope + 0.5 * curvature.max(0.0)) / (0.9 * violation);
            if needed > *penalty {
                *penalty = needed * 1.1;
            }
        }
        let descent = slope - *penalty * violation;
        let merit0 = models.cost + *penalty * violation;
        if !descent.is_finite() {
            return None;
        }
        // a non-negative slope: the direction is at rounding level; take it as it is
        let descent = descent.min(0.0);
        let mut alpha = 1.0;
        for _ in 0..=options.max_backtracks {
            let trial = Iterate {
                x: iterate
                    .x
                    .iter()
                    .zip(&direction.dx)
                    .map(|(x, d)| x + d * alpha)
                    .collect(),
                u: iterate
                    .u
                    .iter()
                    .zip(&direction.du)
                    .map(|(u, d)| u + d * alpha)
                    .collect(),
            };
            let merit = self
                .problem
                .guard::<S, M>(&trial)
                .ok()
                .and_then(|()| self.cost(&trial))
                .map(|cost| cost + *penalty * self.violation_l1(&trial));
            if merit.is_some_and(|m| {
                m <= merit0 + options.armijo * alpha * descent + 1e-14 * merit0.abs()
            }) {
                return Some(trial);
            }
            alpha *= 0.5;
        }
        None
    }

    fn violation_l1(&self, iterate: &Iterate<N, X>) -> f64 {
        let defects: f64 = (0..iterate.u.len())
            .map(|i| {
                (self.dynamics.next(&iterate.x[i], &iterate.u[i]) - iterate.x[i + 1]).lp_norm(1)
            })
            .sum();
        defects
            + (self.problem.start - iterate.x[0]).lp_norm(1)
            + (self.problem.goal - iterate.x[iterate.x.len() - 1]).lp_norm(1)
    }
}

fn unknown_certificate() -> Certificate {
    Certificate {
        stationarity: f64::NAN,
        feasibility: f64::NAN,
        negative_directions: 0,
        min_reduced_hessian_eig: f64::NAN,
    }
}
