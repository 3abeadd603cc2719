//! Optimal control: the two-point boundary-value problem of the discrete necessary conditions.
//!
//! Given the jet $x = (q, \dots, q^{(k-1)})$ at both ends, $x(0) = a$ and $x(T) = b$, and
//! $N$ steps of $h = T/N$, the unknowns are the whole discrete trajectory
//! $v = (z_0, u_0, z_1, u_1, \dots, u_{N-1}, z_N)$ and the equations
//!
//! $$x(z_0) = a, \qquad F(z_i, (z_{i+1}, u_i)) = 0 \ (i < N), \qquad x(z_N) = b,$$
//!
//! with $F$ the theta-scheme residual of [`LiftedSystem`]. Newton's method with backtracking
//! on $|R|^2$ solves them; its matrix is banded with $k_l = k_u = nk + M - 1$ in this ordering,
//! so each iteration costs $O(N)$ ([`crate::banded`]).
//!
//! The first guess is the Hermite polynomial of degree $2k - 1$ between the boundary jets
//! (the $V = 0$ spline), mapped through the system's Legendre map, or a previous solution
//! (warm start, [`BvpSolution::shifted`] for receding horizons, [`continuation`] in a
//! parameter). A solution whose clearance to an obstacle is negative is an error
//! ([`Error::ThroughObstacle`]): inside an obstacle the cost is unbounded below, so such a
//! stationary point is not a plan.

use nalgebra::{DMatrix, DVector, SVector};

use crate::banded::BandMatrix;
use crate::{Error, LiftedSystem};

/// Options of the boundary-value solve.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct BvpOptions {
    /// The scheme parameter $\theta$ (1/2: midpoint).
    pub theta: f64,
    /// Converged when $|R|_\infty \le$ this.
    pub residual_tolerance: f64,
    /// Newton iteration cap.
    pub max_iterations: usize,
    /// Armijo constant of the backtracking line search.
    pub armijo: f64,
    /// Step halvings per iteration.
    pub max_backtracks: usize,
}

impl Default for BvpOptions {
    fn default() -> Self {
        Self {
            theta: 0.5,
            residual_tolerance: 1e-10,
            max_iterations: 50,
            armijo: 1e-4,
            max_backtracks: 40,
        }
    }
}

impl BvpOptions {
    /// Sets the residual tolerance.
    pub fn with_residual_tolerance(mut self, tolerance: f64) -> Self {
        self.residual_tolerance = tolerance;
        self
    }

    /// Sets the iteration cap.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Sets $\theta$.
    pub fn with_theta(mut self, theta: f64) -> Self {
        self.theta = theta;
        self
    }
}

/// Where Newton starts.
#[derive(Clone, Copy, Debug)]
pub enum Guess<'a, const S: usize, const M: usize> {
    /// The Hermite spline of degree $2k-1$ between the boundary jets.
    Spline,
    /// A previous solution with the same number of steps (warm start).
    Solution(&'a BvpSolution<S, M>),
    /// States $z_0, \dots, z_N$ of a path chosen by the caller (e.g. around an obstacle);
    /// the top derivatives come from [`LiftedSystem::predictor`] at each state.
    States(&'a [SVector<f64, S>]),
}

/// A solved boundary-value problem.
#[derive(Clone, Debug, PartialEq)]
pub struct BvpSolution<const S: usize, const M: usize> {
    /// Step size $h = T/N$.
    pub h: f64,
    /// The scheme parameter used.
    pub theta: f64,
    /// $z_0, \dots, z_N$.
    pub states: Vec<SVector<f64, S>>,
    /// The Newton unknowns $w_i = (z_{i+1}, u_i)$ of each step.
    pub unknowns: Vec<SVector<f64, M>>,
    /// $J = \sum_i h\,L(x_{\theta,i}, u_i)$.
    pub cost: f64,
    /// Minimum clearance to each obstacle over $z_0..z_N$ (empty without a clearance function).
    pub clearance: Vec<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// $|R|_\infty$ at the solution.
    pub residual_norm: f64,
}

impl<const S: usize, const M: usize> BvpSolution<S, M> {
    /// The solution shifted one step forward in time, for a receding-horizon warm start:
    /// $z_i \leftarrow z_{i+1}$, the new last step one integrator step from the old end
    /// (repeating the last step's unknowns if that step fails).
    pub fn shifted<Sys>(&self, system: &Sys) -> Self
    where
        Sys: LiftedSystem<S, M> + ?Sized,
    {
        let mut out = self.clone();
        let (Some(&last_z), Some(&last_w)) = (self.states.last(), self.unknowns.last()) else {
            return out;
        };
        let options = crate::StepOptions::default().with_theta(self.theta);
        let next_w = system
            .predictor(&last_z, self.h, self.theta)
            .and_then(|guess| crate::step::solve_step(system, &last_z, guess, self.h, &options))
            .map(|(w, _)| w)
            .unwrap_or(last_w);
        out.states.remove(0);
        out.states.push(system.state(&next_w));
        out.unknowns.remove(0);
        out.unknowns.push(next_w);
        out
    }
}

/// Per-obstacle clearance of a state: writes one signed distance per obstacle into `out`
/// (negative inside).
pub type ClearanceFn<'a, const S: usize> = &'a dyn Fn(&SVector<f64, S>, &mut [f64]);

/// A boundary-value problem: a system, the boundary jets, the horizon and the step count.
pub struct BoundaryValueProblem<'a, Sys: ?Sized, const S: usize, const M: usize> {
    system: &'a Sys,
    start: &'a [f64],
    goal: &'a [f64],
    t_end: f64,
    steps: usize,
    options: BvpOptions,
    clearance: Option<(usize, ClearanceFn<'a, S>)>,
}

/// Index layout of the unknowns and equations.
#[derive(Clone, Copy)]
struct Layout {
    s: usize,
    m: usize,
    nk: usize,
    steps: usize,
}

impl Layout {
    fn size(&self) -> usize {
        self.steps * self.m + self.s
    }
    fn z(&self, i: usize) -> usize {
        i * self.m
    }
    fn u(&self, i: usize) -> usize {
        i * self.m + self.s
    }
    /// Column of entry `c` of w_i = (z_{i+1}, u_i).
    fn w(&self, i: usize, c: usize) -> usize {
        if c < self.s {
            self.z(i + 1) + c
        } else {
            self.u(i) + c - self.s
        }
    }
    fn row(&self, i: usize) -> usize {
        self.nk + i * self.m
    }
    fn bandwidth(&self) -> usize {
        self.nk + self.m - 1
    }
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

impl<'a, Sys, const S: usize, const M: usize> BoundaryValueProblem<'a, Sys, S, M>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    /// The problem $x(0) = $ `start`, $x(T) = $ `goal` (each $nk$ numbers: $q, q', \dots,
    /// q^{(k-1)}$, blocks of $n$) over $T = $ `t_end` with `steps` steps.
    pub fn new(
        system: &'a Sys,
        start: &'a [f64],
        goal: &'a [f64],
        t_end: f64,
        steps: usize,
    ) -> Self {
        Self {
            system,
            start,
            goal,
            t_end,
            steps,
            options: BvpOptions::default(),
            clearance: None,
        }
    }

    /// Sets the options.
    pub fn with_options(mut self, options: BvpOptions) -> Self {
        self.options = options;
        self
    }

    /// Checks the clearance to `obstacles` obstacles on every state of the solution.
    pub fn with_clearance(mut self, obstacles: usize, clearance: ClearanceFn<'a, S>) -> Self {
        self.clearance = Some((obstacles, clearance));
        self
    }

    fn layout(&self) -> Layout {
        Layout {
            s: S,
            m: M,
            nk: S / 2,
            steps: self.steps,
        }
    }

    fn h(&self) -> f64 {
        self.t_end / self.steps as f64
    }

    fn validate(&self) -> Result<(), Error> {
        let nk = S / 2;
        let invalid = |name, requirement| Err(Error::InvalidArgument { name, requirement });
        if M != S + Sys::DIMENSION {
            return invalid(
                "system",
                "the boundary-value solver needs the general unknowns w = (z_1, u)",
            );
        }
        if self.start.len() != nk || self.goal.len() != nk {
            return invalid(
                "start/goal",
                "boundary data must hold q, ..., q^(k-1): n k numbers",
            );
        }
        if !all_finite(self.start) || !all_finite(self.goal) {
            return invalid("start/goal", "boundary data must be finite");
        }
        if self.steps == 0 {
            return invalid("steps", "at least one step is needed");
        }
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return invalid("t_end", "the horizon must be finite and positive");
        }
        if !(0.0..=1.0).contains(&self.options.theta) {
            return invalid("theta", "theta must lie in [0, 1]");
        }
        let tolerance = self.options.residual_tolerance;
        if self.options.max_iterations == 0 || tolerance.is_nan() || tolerance < 0.0 {
            return invalid("options", "need max_iterations >= 1 and a tolerance >= 0");
        }
        Ok(())
    }

    /// The Hermite-spline guess, through the Legendre map.
    fn spline_guess(&self) -> Result<Vec<f64>, Error> {
        let (n, k) = (Sys::DIMENSION, Sys::ORDER);
        let t_end = self.t_end;
        // q_i(t) = sum_m c[m] t^m, degree 2k - 1; c[m] = a_m / m! for m < k
        let falling = |m: usize, j: usize| -> f64 { ((m - j + 1)..=m).map(|v| v as f64).product() };
        let mut coefficients = vec![vec![0.0; 2 * k]; n];
        for (i, c) in coefficients.iter_mut().enumerate() {
            for (m, cm) in c.iter_mut().enumerate().take(k) {
                *cm = self.start[m * n + i] / falling(m, m);
            }
            let mut a = DMatrix::<f64>::zeros(k, k);
            let mut rhs = DVector::<f64>::zeros(k);
            for j in 0..k {
                let known: f64 = (j..k)
                    .map(|m| c[m] * falling(m, j) * t_end.powi((m - j) as i32))
                    .sum();
                rhs[j] = self.goal[j * n + i] - known;
                for m in k..2 * k {
                    a[(j, m - k)] = falling(m, j) * t_end.powi((m - j) as i32);
                }
            }
            let upper = a.lu().solve(&rhs).ok_or(Error::InvalidArgument {
                name: "t_end",
                requirement: "the spline guess needs a non-degenerate horizon",
            })?;
            c[k..2 * k].copy_from_slice(upper.as_slice());
        }
        let derivative = |i: usize, j: usize, t: f64| -> f64 {
            (j..2 * k)
                .map(|m| coefficients[i][m] * falling(m, j) * t.powi((m - j) as i32))
                .sum()
        };
        let layout = self.layout();
        let h = self.h();
        let mut v = vec![0.0; layout.size()];
        for step in 0..=self.steps {
            let t = step as f64 * h;
            let jet = SVector::<f64, S>::from_fn(|r, _| derivative(r % n, r / n, t));
            let z = self.system.legendre(&jet);
            v[layout.z(step)..layout.z(step) + S].copy_from_slice(z.as_slice());
            if step < self.steps {
                let t_mid = t + self.options.theta * h;
                for i in 0..n {
                    v[layout.u(step) + i] = derivative(i, k, t_mid);
                }
            }
        }
        Ok(v)
    }

    fn guess_from_solution(&self, guess: &BvpSolution<S, M>) -> Result<Vec<f64>, Error> {
        if guess.states.len() != self.steps + 1 || guess.unknowns.len() != self.steps {
            return Err(Error::InvalidArgument {
                name: "guess",
                requirement: "a warm start needs a solution with the same number of steps",
            });
        }
        let layout = self.layout();
        let mut v = vec![0.0; layout.size()];
        for (i, z) in guess.states.iter().enumerate() {
            v[layout.z(i)..layout.z(i) + S].copy_from_slice(z.as_slice());
        }
        for (i, w) in guess.unknowns.iter().enumerate() {
            v[layout.u(i)..layout.u(i) + M - S].copy_from_slice(&w.as_slice()[S..]);
        }
        Ok(v)
    }

    fn guess_from_states(&self, states: &[SVector<f64, S>]) -> Result<Vec<f64>, Error> {
        if states.len() != self.steps + 1 {
            return Err(Error::InvalidArgument {
                name: "guess",
                requirement: "a guess needs N + 1 states",
            });
        }
        let layout = self.layout();
        let mut v = vec![0.0; layout.size()];
        for (i, z) in states.iter().enumerate() {
            v[layout.z(i)..layout.z(i) + S].copy_from_slice(z.as_slice());
            if i < self.steps {
                let w = self.system.predictor(z, self.h(), self.options.theta)?;
                v[layout.u(i)..layout.u(i) + M - S].copy_from_slice(&w.as_slice()[S..]);
            }
        }
        Ok(v)
    }

    fn state(&self, v: &[f64], i: usize) -> SVector<f64, S> {
        let at = self.layout().z(i);
        SVector::from_column_slice(&v[at..at + S])
    }

    fn unknowns(&self, v: &[f64], i: usize) -> SVector<f64, M> {
        let layout = self.layout();
        SVector::from_fn(|c, _| v[layout.w(i, c)])
    }

    fn residual(&self, v: &[f64], out: &mut [f64]) {
        let layout = self.layout();
        let (h, theta, nk) = (self.h(), self.options.theta, layout.nk);
        for j in 0..nk {
            out[j] = v[layout.z(0) + j] - self.start[j];
            out[layout.row(self.steps) + j] = v[layout.z(self.steps) + j] - self.goal[j];
        }
        for i in 0..self.steps {
            let f = self
                .system
                .residual(&self.state(v, i), &self.unknowns(v, i), h, theta);
            out[layout.row(i)..layout.row(i) + M].copy_from_slice(f.as_slice());
        }
    }

    fn jacobian(&self, v: &[f64], band: &mut BandMatrix) {
        let layout = self.layout();
        let (h, theta, nk) = (self.h(), self.options.theta, layout.nk);
        band.clear();
        for j in 0..nk {
            band.set(j, layout.z(0) + j, 1.0);
            band.set(layout.row(self.steps) + j, layout.z(self.steps) + j, 1.0);
        }
        for i in 0..self.steps {
            let (z, w) = (self.state(v, i), self.unknowns(v, i));
            let a = self.system.jacobian_initial(&z, &w, h, theta);
            let b = self.system.jacobian(&z, &w, h, theta);
            let row = layout.row(i);
            for r in 0..M {
                for c in 0..S {
                    let value = a[(r, c)];
                    if value != 0.0 {
                        band.set(row + r, layout.z(i) + c, value);
                    }
                }
                for c in 0..M {
                    let value = b[(r, c)];
                    if value != 0.0 {
                        band.set(row + r, layout.w(i, c), value);
                    }
                }
            }
        }
    }

    /// Solves the problem from `guess`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for inconsistent data; Newton failures
    /// ([`Error::NonFinite`], [`Error::SingularJacobian`], [`Error::LineSearchFailed`],
    /// [`Error::NoConvergence`]); [`Error::ThroughObstacle`] for a solution with negative
    /// clearance.
    pub fn solve(&self, guess: Guess<'_, S, M>) -> Result<BvpSolution<S, M>, Error> {
        self.validate()?;
        let mut v = match guess {
            Guess::Spline => self.spline_guess()?,
            Guess::Solution(previous) => self.guess_from_solution(previous)?,
            Guess::States(states) => self.guess_from_states(states)?,
        };
        if let Some((obstacle, step, clearance)) = self.first_collision(&v) {
            return Err(Error::GuessThroughObstacle {
                obstacle,
                step,
                clearance,
            });
        }
        let layout = self.layout();
        let size = layout.size();
        let options = &self.options;
        let mut r = vec![0.0; size];
        self.residual(&v, &mut r);
        if !all_finite(&v) || !all_finite(&r) {
            return Err(Error::NonFinite {
                iteration: 0,
                location: "boundary-value residual of the first guess",
            });
        }
        let bw = layout.bandwidth();
        let mut band = BandMatrix::zeros(size, bw, bw);
        let mut delta = vec![0.0; size];
        let mut trial = vec![0.0; size];
        let mut r_trial = vec![0.0; size];
        let mut r_norm = max_abs(&r);
        let mut iterations = 0;
        while r_norm > options.residual_tolerance {
            if iterations == options.max_iterations {
                return Err(Error::NoConvergence {
                    iterations,
                    residual_norm: r_norm,
                });
            }
            iterations += 1;
            self.jacobian(&v, &mut band);
            band.factor().map_err(|_| Error::SingularJacobian {
                iteration: iterations,
            })?;
            for (d, ri) in delta.iter_mut().zip(&r) {
                *d = -ri;
            }
            band.solve(&mut delta);
            if !all_finite(&delta) {
                return Err(Error::SingularJacobian {
                    iteration: iterations,
                });
            }
            let phi: f64 = r.iter().map(|x| x * x).sum();
            let mut alpha = 1.0;
            let mut accepted = false;
            for _ in 0..=options.max_backtracks {
                for ((t, vi), di) in trial.iter_mut().zip(&v).zip(&delta) {
                    *t = vi + alpha * di;
                }
                self.residual(&trial, &mut r_trial);
                if all_finite(&r_trial) {
                    let phi_trial: f64 = r_trial.iter().map(|x| x * x).sum();
                    if phi_trial <= (1.0 - 2.0 * options.armijo * alpha) * phi {
                        accepted = true;
                        break;
                    }
                }
                alpha *= 0.5;
            }
            if !accepted {
                return Err(Error::LineSearchFailed {
                    iteration: iterations,
                    residual_norm: r_norm,
                });
            }
            std::mem::swap(&mut v, &mut trial);
            std::mem::swap(&mut r, &mut r_trial);
            r_norm = max_abs(&r);
        }
        self.finish(&v, iterations, r_norm)
    }

    /// The first (obstacle, state, clearance) with negative (or NaN) clearance.
    fn first_collision(&self, v: &[f64]) -> Option<(usize, usize, f64)> {
        let (count, f) = self.clearance?;
        let mut buffer = vec![0.0; count];
        for step in 0..=self.steps {
            f(&self.state(v, step), &mut buffer);
            if let Some((obstacle, &c)) = buffer
                .iter()
                .enumerate()
                .find(|(_, c)| c.is_nan() || **c < 0.0)
            {
                return Some((obstacle, step, c));
            }
        }
        None
    }

    fn finish(
        &self,
        v: &[f64],
        iterations: usize,
        residual_norm: f64,
    ) -> Result<BvpSolution<S, M>, Error> {
        let (h, theta) = (self.h(), self.options.theta);
        let states: Vec<_> = (0..=self.steps).map(|i| self.state(v, i)).collect();
        let unknowns: Vec<_> = (0..self.steps).map(|i| self.unknowns(v, i)).collect();
        let cost = states
            .iter()
            .zip(&unknowns)
            .map(|(z, w)| self.system.step_cost(z, w, h, theta))
            .sum();
        if let Some((obstacle, step, clearance)) = self.first_collision(v) {
            return Err(Error::ThroughObstacle {
                obstacle,
                step,
                clearance,
            });
        }
        let mut clearance = Vec::new();
        if let Some((count, f)) = self.clearance {
            clearance = vec![f64::INFINITY; count];
            let mut buffer = vec![0.0; count];
            for z in &states {
                f(z, &mut buffer);
                for (best, &c) in clearance.iter_mut().zip(&buffer) {
                    *best = best.min(c);
                }
            }
        }
        Ok(BvpSolution {
            h,
            theta,
            states,
            unknowns,
            cost,
            clearance,
            iterations,
            residual_norm,
        })
    }
}

/// Solves a sequence of problems whose system depends on a parameter (e.g. a barrier weight
/// from large to small), each warm-started from the previous solution, the first from
/// `first_guess`. Returns the last solution.
///
/// # Errors
/// The first failing solve's error.
#[allow(clippy::too_many_arguments)]
pub fn continuation<Sys, F, const S: usize, const M: usize>(
    make: F,
    parameters: &[f64],
    start: &[f64],
    goal: &[f64],
    t_end: f64,
    steps: usize,
    options: BvpOptions,
    clearance: Option<(usize, ClearanceFn<'_, S>)>,
    first_guess: Guess<'_, S, M>,
) -> Result<BvpSolution<S, M>, Error>
where
    Sys: LiftedSystem<S, M>,
    F: Fn(f64) -> Sys,
{
    let mut previous: Option<BvpSolution<S, M>> = None;
    for &parameter in parameters {
        let system = make(parameter);
        let mut problem =
            BoundaryValueProblem::new(&system, start, goal, t_end, steps).with_options(options);
        if let Some((count, f)) = clearance {
            problem = problem.with_clearance(count, f);
        }
        let guess = match &previous {
            Some(solution) => Guess::Solution(solution),
            None => first_guess,
        };
        previous = Some(problem.solve(guess)?);
    }
    previous.ok_or(Error::InvalidArgument {
        name: "parameters",
        requirement: "continuation needs at least one parameter value",
    })
}
