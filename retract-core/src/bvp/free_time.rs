//! A free final time: the horizon $T$ as a decision variable ([`FreeTime`],
//! [`OptimalControlProblem::solve_free_time`], [`FreeTimePlan`]).
//!
//! With $N$ fixed and $h = T/N$, the problem
//!
//! $$\min_{T \in [T_{\min}, T_{\max}]} \; w\thinspace T + J^*(T), \qquad
//!   J^*(T) = \min \sum_{i<N} h\thinspace L(x_{\theta,i}, u_i) \text{ over the plans of horizon } T,$$
//!
//! is solved in its reduced form: the inner minimum $J^*(T)$ is a fixed-horizon solve, and
//! the outer function $\varphi(T) = w T + J^*(T)$ of one variable is minimised by Brent's
//! method (parabolic interpolation safeguarded by golden-section steps, Brent 1973, ch. 5) on
//! $[T_{\min}, T_{\max}]$, starting at the problem's own $T$. Each fixed-horizon solve starts
//! from the best plan so far stretched to the new horizon, with its multipliers and slacks
//! (a warm start as [`PlanGuess::Plan`]): the lifted scheme is covariant under
//! $t \mapsto s t$ (the jets' $j$-th block scaled by $s^{-j}$, the top derivative by $s^{-k}$,
//! the nodes kept), so the stretched plan satisfies the dynamics of the new horizon exactly.
//! A horizon whose solve fails counts as $\varphi = +\infty$ (also the first: the search
//! goes on from there).
//!
//! **Certificate.** The joint problem in (plan, $T$) has a strict local minimum where the
//! fixed-horizon plan is one (its own certificate) and, inside $(T_{\min}, T_{\max})$, the
//! Schur complement of the joint reduced Hessian, which is $\varphi''(T)$, is positive; at a
//! bound, $\varphi$ must increase into the interval. Both are checked at the end by two more
//! solves at $T \pm \delta$, $\delta = 10^{-3} T$: the second difference
//! $(\varphi(T + \delta) - 2\varphi(T) + \varphi(T - \delta))/\delta^2$ is
//! [`FreeTimePlan::curvature`]; a non-positive one is [`Failure::NotAMinimum`]. Where a probe
//! finds a lower $\varphi$ ($\varphi$ is not unimodal where the fixed-horizon solves end in
//! different local minima), Brent's method runs again on $[0.9 T, 1.1 T]$ about it, up to
//! 4 rounds. Where the probe past the best $T$ fails (the edge of the horizons whose problem
//! is solvable: shorter ones cannot meet the bounds), the minimum is that edge and the
//! curvature is NaN, as at a bound.

use super::options::PlanGuess;
use super::plan::{Failure, Plan, PlanError};
use super::problem::OptimalControlProblem;
use super::workspace::Workspace;
use crate::{Error, Lagrangian, LiftedSystem};

/// The horizon as a decision variable ([`OptimalControlProblem::solve_free_time`]):
/// $T \in$ [`lower`](Self::lower), [`upper`](Self::upper)] with the cost
/// $w T$ ([`time_weight`](Self::time_weight)) added to the plan's.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FreeTime {
    /// $T_{\min} > 0$.
    pub lower: f64,
    /// $T_{\max} \ge T_{\min}$, finite.
    pub upper: f64,
    /// $w \ge 0$: the cost of a unit of time (1 for minimum time plus the effort).
    pub time_weight: f64,
    /// The solve stops when the bracket of the minimising $T$ is below this relative width
    /// (default $10^{-6}$).
    pub tolerance: f64,
}

impl FreeTime {
    /// $T \in [$`lower`, `upper`$]$ at the cost `time_weight` per unit of time, the
    /// default tolerance $10^{-6}$.
    #[must_use]
    pub fn new(lower: f64, upper: f64, time_weight: f64) -> Self {
        Self {
            lower,
            upper,
            time_weight,
            tolerance: 1e-6,
        }
    }

    /// The same with the relative tolerance `tolerance` on $T$.
    #[must_use]
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.tolerance = tolerance;
        self
    }

    /// The reason these data define no horizon interval containing `t0`, if any.
    fn check(&self, t0: f64) -> Option<&'static str> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !positive(self.lower) || !positive(self.upper) || self.lower > self.upper {
            Some("need finite 0 < lower <= upper")
        } else if !(self.time_weight.is_finite() && self.time_weight >= 0.0) {
            Some("need a finite time_weight >= 0")
        } else if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 0.1) {
            Some("need a tolerance in (0, 0.1)")
        } else if !(self.lower..=self.upper).contains(&t0) {
            Some("the problem's T, where the search starts, must lie in [lower, upper]")
        } else {
            None
        }
    }
}

/// A plan with its free final time ([`OptimalControlProblem::solve_free_time`]).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct FreeTimePlan<const N: usize, const X: usize> {
    /// The certified plan of the optimal horizon ($h = T/N$).
    pub plan: Plan<N, X>,
    /// The optimal horizon $T$.
    pub t_end: f64,
    /// $w T + J$, the plan's cost $J$ with the time's.
    pub cost: f64,
    /// $\varphi''(T)$ by the second difference of the module docs: positive at a minimum
    /// inside the interval; NaN at a bound.
    pub curvature: f64,
    /// Whether $T$ is at [`FreeTime::lower`] or [`FreeTime::upper`] (then $\varphi$ was
    /// checked to increase into the interval).
    pub at_bound: bool,
    /// Fixed-horizon solves made (the certificate's two included).
    pub solves: usize,
    /// SQP iterations of all solves.
    pub iterations: usize,
}

/// The golden-section ratio $(3 - \sqrt 5)/2$.
const GOLDEN: f64 = 0.381_966_011_250_105_1;

/// Most fixed-horizon solves of the search (Brent's method needs about 10-30 a round).
const MAX_SOLVES: usize = 150;

/// Most rounds of Brent's method: a round whose certificate probes find a lower value
/// (where $\varphi$ is not unimodal, e.g. the fixed-horizon solves end in different local
/// minima) is followed by one about the lower point.
const ROUNDS: usize = 4;

/// What the certificate's probes found.
enum Probed<const N: usize, const X: usize> {
    /// The result: certified, or `NotAMinimum` where the curvature is not positive.
    Done(Box<Result<FreeTimePlan<N, X>, PlanError<N, X>>>),
    /// A lower value at this horizon (now the best).
    Lower(f64),
}

/// The evaluations of $\varphi$ made so far: the best plan, and the counts.
struct Search<const N: usize, const X: usize> {
    best: Option<(f64, f64, Plan<N, X>)>,
    first_error: Option<PlanError<N, X>>,
    solves: usize,
    iterations: usize,
}

/// `plan` stretched from its horizon to `t_end` (module docs): its jets and top derivatives
/// scaled, its step $h$ that of `t_end`, its multipliers kept, for a warm start.
fn stretched<const N: usize, const X: usize>(plan: &Plan<N, X>, t_end: f64) -> Plan<N, X> {
    let k = X / N;
    let steps = plan.u.len() as f64;
    let ratio = plan.h * steps / t_end;
    let mut warm = plan.clone();
    warm.h = t_end / steps;
    for x in &mut warm.x {
        for j in 1..k {
            let scale = ratio.powi(j as i32);
            for c in 0..N {
                x[j * N + c] *= scale;
            }
        }
    }
    let scale = ratio.powi(k as i32);
    for u in &mut warm.u {
        *u *= scale;
    }
    warm
}

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// The plan and horizon $T \in [T_{\min}, T_{\max}]$ that minimise $w T + J$ (module
    /// docs), $N$ fixed; the search starts at the problem's $T$ from `guess` (a warm start:
    /// the [`FreeTimePlan::plan`] of a nearby problem, with the problem's $T$ set to its
    /// [`FreeTimePlan::t_end`]).
    ///
    /// # Errors
    /// [`Failure::Invalid`] for bad [`FreeTime`] data or a problem $T$ outside it; the
    /// first solve's error where no horizon could be solved; [`Failure::NotAMinimum`] with the
    /// plan where $\varphi'' \le 0$ at the end (or $\varphi$ decreases out of the interval at
    /// a bound), or [`Failure::FreeTimeSearch`] with the best plan where the search used its
    /// 150 solves or 4 rounds.
    pub fn solve_free_time<const S: usize, const M: usize>(
        &self,
        free: FreeTime,
        guess: PlanGuess<'_, N, X>,
    ) -> Result<FreeTimePlan<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        if let Some(requirement) = free.check(self.t_end) {
            return Err(PlanError::without_iterate(Failure::Invalid(
                Error::InvalidArgument {
                    name: "free_time",
                    requirement,
                },
            )));
        }
        let mut problem = self.clone();
        let mut workspace = Workspace::new();
        let mut search = Search {
            best: None,
            first_error: None,
            solves: 0,
            iterations: 0,
        };
        let t0 = self.t_end;
        let f0 = problem.phi(
            t0,
            Some(guess),
            free.time_weight,
            &mut workspace,
            &mut search,
        );
        let mut bracket = (free.lower, free.upper);
        for _ in 0..ROUNDS {
            // (from the start, also where its solve failed: other horizons may be solvable)
            let (t, f) = search.best.as_ref().map_or((t0, f0), |&(t, f, _)| (t, f));
            problem.brent(free, bracket, (t, f), &mut workspace, &mut search)?;
            match problem.certify(free, &mut workspace, &mut search) {
                Probed::Done(result) => return *result,
                // a probe found a lower value: search again about it
                Probed::Lower(t) => bracket = (free.lower.max(0.9 * t), free.upper.min(1.1 * t)),
            }
        }
        Err(search.failure(false))
    }

    /// $\varphi(T)$, solving at horizon `t_end` from `guess` or else from the best plan so
    /// far stretched to it; $+\infty$ where the solve fails. Keeps the best plan.
    fn phi<const S: usize, const M: usize>(
        &mut self,
        t_end: f64,
        guess: Option<PlanGuess<'_, N, X>>,
        time_weight: f64,
        workspace: &mut Workspace<N, X>,
        search: &mut Search<N, X>,
    ) -> f64
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        self.t_end = t_end;
        search.solves += 1;
        let result = match (guess, &search.best) {
            (Some(guess), _) => self.solve_with(guess, workspace),
            (None, Some((_, _, plan))) => {
                let warm = stretched(plan, t_end);
                self.solve_with(PlanGuess::Plan(&warm), workspace)
            }
            (None, None) => self.solve_with(PlanGuess::Spline, workspace),
        };
        match result {
            Ok(plan) => {
                search.iterations += plan.iterations;
                let value = time_weight * t_end + plan.cost;
                if search.best.as_ref().is_none_or(|(_, f, _)| value < *f) {
                    search.best = Some((t_end, value, plan));
                }
                value
            }
            Err(error) => {
                search.iterations += error.last.as_ref().map_or(0, |p| p.iterations);
                search.first_error.get_or_insert(error);
                f64::INFINITY
            }
        }
    }

    /// Brent's minimisation of $\varphi$ on `bracket` from `(t0, f0)` inside it, to the
    /// relative tolerance: the minimising $T$ and its plan are `search`'s best.
    fn brent<const S: usize, const M: usize>(
        &mut self,
        free: FreeTime,
        (mut a, mut b): (f64, f64),
        (t0, f0): (f64, f64),
        workspace: &mut Workspace<N, X>,
        search: &mut Search<N, X>,
    ) -> Result<(), PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        // x the best point, w the second best, v the previous w
        let (mut x, mut w, mut v) = (t0, t0, t0);
        let (mut fx, mut fw, mut fv) = (f0, f0, f0);
        // d the last step, e the one before it
        let (mut d, mut e) = (0.0_f64, 0.0_f64);
        while search.solves < MAX_SOLVES {
            let m = 0.5 * (a + b);
            let tol = free.tolerance * x.abs() + 1e-12;
            if (x - m).abs() <= 2.0 * tol - 0.5 * (b - a) {
                return Ok(());
            }
            let mut golden = true;
            if e.abs() > tol && fx.is_finite() && fw.is_finite() && fv.is_finite() {
                // the parabola through (x, fx), (w, fw), (v, fv): its vertex is x + p / q
                let r = (x - w) * (fx - fv);
                let mut q = (x - v) * (fx - fw);
                let mut p = (x - v) * q - (x - w) * r;
                q = 2.0 * (q - r);
                if q > 0.0 {
                    p = -p;
                }
                q = q.abs();
                // accept it if it falls inside (a, b) and moves less than half the step before last
                if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                    e = d;
                    d = p / q;
                    let u = x + d;
                    if u - a < 2.0 * tol || b - u < 2.0 * tol {
                        d = if m >= x { tol } else { -tol };
                    }
                    golden = false;
                }
            }
            if golden {
                e = if x >= m { a - x } else { b - x };
                d = GOLDEN * e;
            }
            let u = if d.abs() >= tol {
                x + d
            } else {
                x + tol.copysign(d)
            };
            let fu = self.phi(u, None, free.time_weight, workspace, search);
            if fu <= fx {
                if u >= x {
                    a = x;
                } else {
                    b = x;
                }
                (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
            } else {
                if u < x {
                    a = u;
                } else {
                    b = u;
                }
                if fu <= fw || w == x {
                    (v, fv, w, fw) = (w, fw, u, fu);
                } else if fu <= fv || v == x || v == w {
                    (v, fv) = (u, fu);
                }
            }
        }
        Err(search.failure(true))
    }

    /// The certificate of the module docs at `search`'s best horizon: the curvature, or the
    /// increase into the interval at a bound (or at the edge of the solvable horizons, where
    /// the probe past it fails), from two solves started from the best plan; or the lower
    /// horizon a probe found.
    fn certify<const S: usize, const M: usize>(
        &mut self,
        free: FreeTime,
        workspace: &mut Workspace<N, X>,
        search: &mut Search<N, X>,
    ) -> Probed<N, X>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        // Brent's method keeps twice its tolerance from the ends: a minimiser that close to a
        // bound is tried at the bound itself
        if let Some(&(t, _, _)) = search.best.as_ref() {
            let near = 4.0 * (free.tolerance * t + 1e-12);
            for bound in [free.lower, free.upper] {
                if (t - bound).abs() <= near && t != bound {
                    self.phi(bound, None, free.time_weight, workspace, search);
                }
            }
        }
        let Some((t_end, cost, plan)) = search.best.take() else {
            return Probed::Done(Box::new(Err(search.failure(false))));
        };
        let delta = 1e-3 * t_end;
        let (at_lower, at_upper) = (t_end == free.lower, t_end == free.upper);
        let mut probe = |t: f64, search: &mut Search<N, X>| {
            let warm = stretched(&plan, t);
            self.phi(
                t,
                Some(PlanGuess::Plan(&warm)),
                free.time_weight,
                workspace,
                search,
            )
        };
        let f_low = (!at_lower).then(|| probe(t_end - delta, search));
        let f_high = (!at_upper).then(|| probe(t_end + delta, search));
        if let Some(&(t, _, _)) = search.best.as_ref().filter(|(_, f, _)| *f < cost) {
            return Probed::Lower(t);
        }
        let (curvature, increases) = match (f_low, f_high) {
            (Some(l), Some(h)) if l.is_finite() && h.is_finite() => {
                let curvature = (l - 2.0 * cost + h) / (delta * delta);
                (curvature, curvature > 0.0)
            }
            // at a bound, or at the edge of the solvable horizons: the other side rises
            (Some(l), Some(h)) => (f64::NAN, l.min(h) >= cost),
            (None, Some(f)) | (Some(f), None) => (f64::NAN, f >= cost),
            // T_min = T_max: nothing to choose
            (None, None) => (f64::NAN, true),
        };
        Probed::Done(Box::new(if increases {
            Ok(FreeTimePlan {
                plan,
                t_end,
                cost,
                curvature,
                at_bound: at_lower || at_upper,
                solves: search.solves,
                iterations: search.iterations,
            })
        } else {
            Err(PlanError {
                failure: Failure::NotAMinimum {
                    negative_directions: 1,
                },
                last: Some(Box::new(plan)),
            })
        }))
    }
}

impl<const N: usize, const X: usize> Search<N, X> {
    /// [`Failure::FreeTimeSearch`] (its budget of solves spent if `budget_spent`, else its
    /// rounds) with the best plan so far, or the first solve's error where none succeeded.
    fn failure(&mut self, budget_spent: bool) -> PlanError<N, X> {
        let failure = Failure::FreeTimeSearch {
            solves: self.solves,
            iterations: self.iterations,
            budget_spent,
        };
        match self.best.take() {
            Some((_, _, plan)) => PlanError {
                failure,
                last: Some(Box::new(plan)),
            },
            None => self
                .first_error
                .take()
                .unwrap_or(PlanError::without_iterate(failure)),
        }
    }
}
