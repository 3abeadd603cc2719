//! Richardson extrapolation of plans over $N$, $2N$ and $4N$ steps
//! ([`Extrapolated`], [`OptimalControlProblem::solve_extrapolated`]).

use std::time::Instant;

use nalgebra::SVector;

use super::options::PlanGuess;
use super::plan::{Failure, Plan, PlanError};
use super::problem::OptimalControlProblem;
use super::workspace::Workspace;
use crate::{Error, Lagrangian, LiftedSystem};

/// A plan extrapolated to $h \to 0$ from the plans with $N$, $2N$ and $4N$ steps
/// ([`OptimalControlProblem::solve_extrapolated`]).
///
/// The midpoint scheme ($\theta = 1/2$) is symmetric, so a quantity $Q_h$ of its plan with
/// step $h$ (the cost, a jet at a fixed time, a boundary momentum) expands in even powers,
/// $Q_h = Q + c_2 h^2 + c_4 h^4 + O(h^6)$. With $Q_N, Q_{2N}, Q_{4N}$ the values at
/// $h, h/2, h/4$, the first level removes the $h^2$ term and the second the $h^4$ term:
///
/// $$R_1(N, 2N) = \frac{4 Q_{2N} - Q_N}{3}, \qquad
///   R_2 = \frac{16 R_1(2N, 4N) - R_1(N, 2N)}{15} = \frac{64 Q_{4N} - 20 Q_{2N} + Q_N}{45},$$
///
/// so $R_2 = Q + O(h^6)$. The error estimate is the difference of the last two levels,
/// $|R_2 - R_1(2N, 4N)| = |R_1(2N, 4N) - R_1(N, 2N)| / 15$: asymptotically the error of
/// $R_1(2N, 4N)$ ($O(h^4)$), an upper estimate of the error of $R_2$ once the expansion holds
/// (a pessimistic one: on the one-disc scene of the tests about $10^3$ times the actual
/// error at $N = 100$).
///
/// The finer solves start from the coarser plan refined onto the finer grid: each component
/// of the jets and of the top derivatives is interpolated by the cubic through the four
/// nearest coarse values (nodes at $t_j = j h$, top derivatives at the evaluation points
/// $(j + \theta) h$), the coarse nodes kept as they are. The $4N$ guess is the refinement of
/// the $2N$ plan corrected by the first Richardson level, $v_{2N} + (v_{2N} - g_{2N}) / 4$
/// ($g_{2N}$ the $2N$ guess, the $N$ plan refined): the $h^2$ term of $v_{4N} - v_{2N}$,
/// so that guess is $O(h^4)$ from the $4N$ plan.
///
/// The expansion assumes a smooth continuous minimiser and $\theta = 1/2$ (with another
/// $\theta$ the scheme has an $h$ term and the formulas do not apply). The extrapolation is
/// no more accurate than the three solves: choose
/// [`PlanOptions::tolerance`](super::PlanOptions::tolerance) below the accuracy wanted (a
/// finer solve whose warm start already meets the tolerance takes no iteration and returns
/// the warm start).
///
/// Every value below is $R_2$ of the three plans' values and every error estimate is
/// $|R_2 - R_1(2N, 4N)|$, componentwise.
///
/// A value read by serde is checked as it is read ([`Extrapolated::validate`]): a file whose
/// plans do not fit an extrapolation, or whose values are not those of its plans, does not
/// read.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(try_from = "ExtrapolatedFields<N, X>"))]
pub struct Extrapolated<const N: usize, const X: usize> {
    /// The coarse step $h = T/N$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub h: f64,
    /// The extrapolated cost.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub cost: f64,
    /// Its error estimate.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub cost_error: f64,
    /// The extrapolated jets at the coarse nodes $t_i = i h$, $i = 0, \dots, N$ (from the
    /// nodes $i$, $2i$ and $4i$ of the three plans).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub x: Vec<SVector<f64, X>>,
    /// Their error estimates (at the fixed ends at the level of the solves' feasibility).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub x_error: Vec<SVector<f64, X>>,
    /// The extrapolated momenta at the coarse nodes; `momenta[0]` and `momenta[N]` are the
    /// boundary momenta $p(0)$ and $p(T)$ ([`Extrapolated::boundary_momenta`]).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub momenta: Vec<SVector<f64, X>>,
    /// Their error estimates.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub momenta_error: Vec<SVector<f64, X>>,
    /// The plans with $N$, $2N$ and $4N$ steps.
    pub plans: [Plan<N, X>; 3],
}

impl<const N: usize, const X: usize> Extrapolated<N, X> {
    /// The extrapolation of the three plans (with $N$, $2N$ and $4N$ steps, in this order).
    ///
    /// # Errors
    /// [`Failure::Invalid`] if a plan fails [`Plan::validate`] (e.g. read back from a damaged
    /// file), if the plans' lengths are not those of $N$, $2N$ and $4N$ steps with their
    /// momenta, if their steps are not $h$, $h/2$ and $h/4$ (to a relative $10^{-12}$) or
    /// their $\theta$ not $1/2$ (the expansion above), if a cost is not finite, or if a value
    /// or an estimate of the extrapolation is not finite (plans' values near the largest
    /// double overflow $4 Q_{2N}$ or $64 Q_{4N}$).
    pub fn from_plans(plans: [Plan<N, X>; 3]) -> Result<Self, PlanError<N, X>> {
        let invalid = |error| PlanError {
            failure: Failure::Invalid(error),
            last: None,
        };
        check_plans(&plans).map_err(invalid)?;
        let [coarse, fine, finest] = &plans;
        let nodes = |field: fn(&Plan<N, X>) -> &Vec<SVector<f64, X>>| {
            let (values, errors): (Vec<_>, Vec<_>) = field(coarse)
                .iter()
                .zip(field(fine).iter().step_by(2))
                .zip(field(finest).iter().step_by(4))
                .map(|((a, b), c)| richardson_vector(a, b, c))
                .unzip();
            (values, errors)
        };
        let (x, x_error) = nodes(|plan| &plan.x);
        let (momenta, momenta_error) = nodes(|plan| &plan.momenta);
        let (cost, cost_error) = richardson(coarse.cost, fine.cost, finest.cost);
        let extrapolated = Self {
            h: coarse.h,
            cost,
            cost_error,
            x,
            x_error,
            momenta,
            momenta_error,
            plans,
        };
        let finite = |v: &[SVector<f64, X>]| v.iter().all(|v| v.iter().all(|e| e.is_finite()));
        let Self {
            x,
            x_error,
            momenta,
            momenta_error,
            ..
        } = &extrapolated;
        if !(cost.is_finite()
            && cost_error.is_finite()
            && [x, x_error, momenta, momenta_error]
                .iter()
                .all(|v| finite(v)))
        {
            return Err(invalid(Error::InvalidArgument {
                name: "plans",
                requirement: "extrapolation needs plans whose extrapolation is finite (4 Q_2N \
                              and 64 Q_4N must not overflow)",
            }));
        }
        Ok(extrapolated)
    }

    /// Checks that this is the extrapolation of its plans: the plans pass the checks of
    /// [`Self::from_plans`], `h` is the coarse plan's step, there is one value and one
    /// estimate per coarse node, and every value and estimate is that of the plans' values
    /// $Q_N, Q_{2N}, Q_{4N}$ to $10^{-12} \max(|Q_N|, |Q_{2N}|, |Q_{4N}|)$ (a file may hold
    /// them rounded). Run on every value read by serde.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `plan` or `plans` as [`Self::from_plans`], or named
    /// `extrapolation` for a value, an estimate, `h` or a length that is not that of the
    /// plans (a non-finite value among them).
    pub fn validate(&self) -> Result<(), Error> {
        check_plans(&self.plans)?;
        let [coarse, fine, finest] = &self.plans;
        // (NaN compares false: a non-finite value fails)
        let fits = |value: f64, error: f64, [a, b, c]: [f64; 3]| {
            let (v, e) = richardson(a, b, c);
            let tolerance = VALUE_TOLERANCE * a.abs().max(b.abs()).max(c.abs());
            (value - v).abs() <= tolerance && (error - e).abs() <= tolerance
        };
        let nodes_fit = |values: &[SVector<f64, X>],
                         errors: &[SVector<f64, X>],
                         field: fn(&Plan<N, X>) -> &Vec<SVector<f64, X>>| {
            values.len() == field(coarse).len()
                && errors.len() == values.len()
                && values
                    .iter()
                    .zip(errors)
                    .zip(field(coarse))
                    .zip(field(fine).iter().step_by(2))
                    .zip(field(finest).iter().step_by(4))
                    .all(|((((v, e), a), b), c)| {
                        (0..X).all(|r| fits(v[r], e[r], [a[r], b[r], c[r]]))
                    })
        };
        let fitting = (self.h - coarse.h).abs() <= VALUE_TOLERANCE * coarse.h
            && fits(
                self.cost,
                self.cost_error,
                [coarse.cost, fine.cost, finest.cost],
            )
            && nodes_fit(&self.x, &self.x_error, |plan| &plan.x)
            && nodes_fit(&self.momenta, &self.momenta_error, |plan| &plan.momenta);
        if fitting {
            Ok(())
        } else {
            Err(Error::InvalidArgument {
                name: "extrapolation",
                requirement: "its h, values and estimates must be those of its plans (to 1e-12 \
                              of the plans' values), one per coarse node",
            })
        }
    }

    /// The extrapolated boundary momenta $[p(0), p(T)]$; `None` without momenta.
    pub fn boundary_momenta(&self) -> Option<[SVector<f64, X>; 2]> {
        Some([*self.momenta.first()?, *self.momenta.last()?])
    }

    /// The error estimates of [`Self::boundary_momenta`].
    pub fn boundary_momenta_error(&self) -> Option<[SVector<f64, X>; 2]> {
        Some([*self.momenta_error.first()?, *self.momenta_error.last()?])
    }

    /// The SQP iterations of the plans with $N$, $2N$ and $4N$ steps.
    pub fn iterations(&self) -> [usize; 3] {
        self.plans.each_ref().map(|plan| plan.iterations)
    }
}

/// How far a value or an estimate read back may be from the one of its plans, relative to
/// the largest of the plans' values ([`Extrapolated::validate`]).
const VALUE_TOLERANCE: f64 = 1e-12;

/// The checks of [`Extrapolated::from_plans`] on its plans.
fn check_plans<const N: usize, const X: usize>(plans: &[Plan<N, X>; 3]) -> Result<(), Error> {
    let wrong = |requirement| {
        Err(Error::InvalidArgument {
            name: "plans",
            requirement,
        })
    };
    for plan in plans {
        plan.validate()?;
    }
    let [coarse, fine, finest] = plans;
    let steps = coarse.u.len();
    let lengths = |plan: &Plan<N, X>, factor: usize| {
        plan.u.len() == factor * steps
            && plan.x.len() == factor * steps + 1
            && plan.momenta.len() == factor * steps + 1
    };
    if !(lengths(coarse, 1) && lengths(fine, 2) && lengths(finest, 4)) {
        return wrong("extrapolation needs plans with N, 2N and 4N steps and their momenta");
    }
    let step = |plan: &Plan<N, X>, factor: f64| {
        (plan.h * factor - coarse.h).abs() <= 1e-12 * coarse.h && plan.theta == 0.5
    };
    if !(step(coarse, 1.0) && step(fine, 2.0) && step(finest, 4.0)) {
        return wrong("extrapolation needs plans with steps h, h/2 and h/4 and theta = 1/2");
    }
    if !plans.iter().all(|plan| plan.cost.is_finite()) {
        return wrong("extrapolation needs plans with finite costs");
    }
    Ok(())
}

/// The fields of an [`Extrapolated`] as read, before [`Extrapolated::validate`] (serde reads
/// an `Extrapolated` through it).
#[cfg(feature = "serde")]
#[derive(serde::Deserialize)]
struct ExtrapolatedFields<const N: usize, const X: usize> {
    #[serde(with = "crate::serde_float")]
    h: f64,
    #[serde(with = "crate::serde_float")]
    cost: f64,
    #[serde(with = "crate::serde_float")]
    cost_error: f64,
    #[serde(with = "crate::serde_float::vectors")]
    x: Vec<SVector<f64, X>>,
    #[serde(with = "crate::serde_float::vectors")]
    x_error: Vec<SVector<f64, X>>,
    #[serde(with = "crate::serde_float::vectors")]
    momenta: Vec<SVector<f64, X>>,
    #[serde(with = "crate::serde_float::vectors")]
    momenta_error: Vec<SVector<f64, X>>,
    plans: [Plan<N, X>; 3],
}

#[cfg(feature = "serde")]
impl<const N: usize, const X: usize> ExtrapolatedFields<N, X> {
    /// The fields as an [`Extrapolated`], unchecked.
    fn unchecked(self) -> Extrapolated<N, X> {
        let Self {
            h,
            cost,
            cost_error,
            x,
            x_error,
            momenta,
            momenta_error,
            plans,
        } = self;
        Extrapolated {
            h,
            cost,
            cost_error,
            x,
            x_error,
            momenta,
            momenta_error,
            plans,
        }
    }
}

#[cfg(feature = "serde")]
impl<const N: usize, const X: usize> TryFrom<ExtrapolatedFields<N, X>> for Extrapolated<N, X> {
    type Error = Error;

    /// The fields as an [`Extrapolated`], if it passes [`Extrapolated::validate`].
    fn try_from(fields: ExtrapolatedFields<N, X>) -> Result<Self, Error> {
        let read = fields.unchecked();
        read.validate()?;
        Ok(read)
    }
}

/// $(R_2, |R_2 - R_1(2N, 4N)|)$ of the values at $N$, $2N$, $4N$ steps.
fn richardson(coarse: f64, fine: f64, finest: f64) -> (f64, f64) {
    let first_coarse = (4.0 * fine - coarse) / 3.0;
    let first_fine = (4.0 * finest - fine) / 3.0;
    let second = (16.0 * first_fine - first_coarse) / 15.0;
    (second, (second - first_fine).abs())
}

/// [`richardson`] componentwise.
fn richardson_vector<const D: usize>(
    coarse: &SVector<f64, D>,
    fine: &SVector<f64, D>,
    finest: &SVector<f64, D>,
) -> (SVector<f64, D>, SVector<f64, D>) {
    let mut value = SVector::<f64, D>::zeros();
    let mut error = SVector::<f64, D>::zeros();
    for r in 0..D {
        (value[r], error[r]) = richardson(coarse[r], fine[r], finest[r]);
    }
    (value, error)
}

/// The values on the grid of twice as many steps: `values[j]` sits at coarse position
/// $j + $ `offset` (in steps); the result has `count` values, the $m$-th at fine position
/// $(m + $ `offset`$)/2$ coarse steps, each component by the Lagrange cubic through the four
/// nearest values (all of them if there are fewer). Positions that coincide with coarse ones
/// (`offset` $= 0$, $m$ even) copy the value.
fn refine<const D: usize>(
    values: &[SVector<f64, D>],
    offset: f64,
    count: usize,
) -> Vec<SVector<f64, D>> {
    let points = values.len().min(4);
    (0..count)
        .map(|m| {
            if offset == 0.0
                && m % 2 == 0
                && let Some(v) = values.get(m / 2)
            {
                return *v;
            }
            // position in units of the coarse index
            let c = (m as f64 + offset) / 2.0 - offset;
            let first = (c.floor() as isize - 1).clamp(0, (values.len() - points) as isize);
            let first = first as usize;
            let mut out = SVector::<f64, D>::zeros();
            for (l, v) in values.iter().enumerate().skip(first).take(points) {
                let weight: f64 = (first..first + points)
                    .filter(|&j| j != l)
                    .map(|j| (c - j as f64) / (l as f64 - j as f64))
                    .product();
                out += v * weight;
            }
            out
        })
        .collect()
}

/// $v + (v - g)/4$ entrywise: the $4N$ prediction from the $2N$ values $v$ and the $2N$ guess
/// $g$ refined from the $N$ plan.
fn corrected<const D: usize>(
    values: &[SVector<f64, D>],
    guess: &[SVector<f64, D>],
) -> Vec<SVector<f64, D>> {
    values
        .iter()
        .zip(guess)
        .map(|(v, g)| v + (v - g) * 0.25)
        .collect()
}

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// The same problem with `factor` times as many steps, its time budget reduced by the
    /// time elapsed since `started`.
    fn with_more_steps(
        &self,
        factor: usize,
        started: Instant,
    ) -> Result<OptimalControlProblem<'a, Sys, N, K, X>, PlanError<N, X>> {
        let steps = self.steps.checked_mul(factor).ok_or(PlanError {
            failure: Failure::Invalid(Error::InvalidArgument {
                name: "steps",
                requirement: "need k <= steps <= 2^24",
            }),
            last: None,
        })?;
        let mut finer = self.clone();
        finer.steps = steps;
        finer.options.max_time = self
            .options
            .max_time
            .map(|budget| budget.saturating_sub(started.elapsed()));
        Ok(finer)
    }

    /// Solves the problem with $N$ (its steps), $2N$ and $4N$ steps and extrapolates the
    /// cost, the jets at the coarse nodes and the momenta (among them the boundary momenta)
    /// to $h \to 0$ by two Richardson levels ([`Extrapolated`]; with $\theta = 1/2$ the
    /// scheme's error expands in $h^2, h^4, \dots$).
    ///
    /// The $N$ solve starts from `guess`; the $2N$ solve from the $N$ plan refined onto its
    /// grid (jets at the new nodes and top derivatives at the new evaluation points by local
    /// cubic interpolation), the $4N$ solve from the $2N$ plan corrected by the first
    /// Richardson level and refined (see [`Extrapolated`]), so the finer solves take few
    /// iterations. The options' time budget covers the three solves together.
    ///
    /// # Errors
    /// The [`PlanError`] of the first failing solve (its `last` iterate has that solve's
    /// number of steps), or [`Failure::Invalid`] if $4N$ steps overflow.
    pub fn solve_extrapolated<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
    ) -> Result<Extrapolated<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        self.solve_extrapolated_with(guess, &mut Workspace::new())
    }

    /// [`Self::solve_extrapolated`] with its three solves in `workspace`
    /// ([`Self::solve_with`]): sized by the $4N$ solve, it serves a later extrapolation of
    /// the same size without growing (the refined guesses and the finer problems are still
    /// allocated on each call).
    ///
    /// # Errors
    /// As [`Self::solve_extrapolated`].
    pub fn solve_extrapolated_with<const S: usize, const M: usize>(
        &self,
        guess: PlanGuess<'_, N, X>,
        workspace: &mut Workspace<N, X>,
    ) -> Result<Extrapolated<N, X>, PlanError<N, X>>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let started = Instant::now();
        let theta = self.options.theta;
        if theta != 0.5 {
            return Err(PlanError {
                failure: Failure::Invalid(Error::InvalidArgument {
                    name: "theta",
                    requirement: "Richardson extrapolation in h^2 needs the midpoint, theta = 1/2",
                }),
                last: None,
            });
        }
        if self.stage_systems.is_some() {
            return Err(PlanError {
                failure: Failure::Invalid(Error::InvalidArgument {
                    name: "stage systems",
                    requirement: "Richardson extrapolation changes the number of steps: one \
                                  system for all",
                }),
                last: None,
            });
        }
        let coarse = self.solve_with::<S, M>(guess, workspace)?;
        let steps = self.steps;
        let x2 = refine(&coarse.x, 0.0, 2 * steps + 1);
        let u2 = refine(&coarse.u, theta, 2 * steps);
        let fine = self
            .with_more_steps(2, started)?
            .solve_with::<S, M>(PlanGuess::Path { x: &x2, u: &u2 }, workspace)?;
        let x4 = refine(&corrected(&fine.x, &x2), 0.0, 4 * steps + 1);
        let u4 = refine(&corrected(&fine.u, &u2), theta, 4 * steps);
        let finest = self
            .with_more_steps(4, started)?
            .solve_with::<S, M>(PlanGuess::Path { x: &x4, u: &u4 }, workspace)?;
        Extrapolated::from_plans([coarse, fine, finest])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The refinement reproduces cubics exactly, at the nodes and between them, near the
    /// ends and with the evaluation-point offset.
    #[test]
    fn refinement_is_exact_for_cubics() {
        let cubic = |t: f64| 0.3 - 1.2 * t + 0.7 * t * t - 0.05 * t.powi(3);
        for offset in [0.0, 0.5, 0.3] {
            let values: Vec<SVector<f64, 1>> = (0..7)
                .map(|j| SVector::from([cubic(j as f64 + offset)]))
                .collect();
            let count = if offset == 0.0 { 13 } else { 14 };
            let fine = refine(&values, offset, count);
            assert_eq!(fine.len(), count);
            for (m, v) in fine.iter().enumerate() {
                let exact = cubic((m as f64 + offset) / 2.0);
                assert!((v[0] - exact).abs() < 1e-12, "offset {offset}, m {m}");
            }
        }
        // fewer than four values: the polynomial through all of them
        let line: Vec<SVector<f64, 1>> = (0..2).map(|j| SVector::from([2.0 * j as f64])).collect();
        let fine = refine(&line, 0.5, 4);
        for (m, v) in fine.iter().enumerate() {
            assert!((v[0] - ((m as f64 + 0.5) - 1.0)).abs() < 1e-14);
        }
    }

    #[test]
    fn richardson_removes_the_h2_and_h4_terms() {
        let q = |h: f64| 1.5 + 0.7 * h * h - 2.0 * h.powi(4);
        let (value, error) = richardson(q(0.1), q(0.05), q(0.025));
        assert!((value - 1.5).abs() < 1e-14);
        // the estimate is the first level's h^4 error
        let first_fine = (4.0 * q(0.025) - q(0.05)) / 3.0;
        assert!((error - (first_fine - 1.5).abs()).abs() < 1e-14);
    }

    /// A plan of `steps` steps over $T = 1$ at rest at 0, its cost $1 + h^2$.
    fn rest(steps: usize) -> Plan<1, 2> {
        let h = 1.0 / steps as f64;
        Plan::<1, 2> {
            h,
            theta: 0.5,
            x: vec![SVector::zeros(); steps + 1],
            u: vec![SVector::zeros(); steps],
            momenta: vec![SVector::zeros(); steps + 1],
            cost: 1.0 + h * h,
            iterations: 0,
            certificate: super::super::plan::certificate::unknown_certificate(),
            violations: Default::default(),
            duals: Default::default(),
        }
    }

    /// The three plans of [`rest`] with 3, 6 and 12 steps, `edit` applied to them.
    fn edited(edit: impl FnOnce(&mut [Plan<1, 2>; 3])) -> [Plan<1, 2>; 3] {
        let mut plans = [rest(3), rest(6), rest(12)];
        edit(&mut plans);
        plans
    }

    /// Plans that cannot be plans, or not the three of one extrapolation, are refused, not
    /// extrapolated to NaN or to a number of nothing (issue 33, item 7).
    #[test]
    fn plans_that_do_not_fit_an_extrapolation_are_refused() {
        let valid = Extrapolated::from_plans(edited(|_| ())).expect("three fitting plans");
        // 1 + h^2 extrapolates to 1
        assert!((valid.cost - 1.0).abs() < 1e-14, "{}", valid.cost);
        type Edit = fn(&mut [Plan<1, 2>; 3]);
        let hostile: [(&str, Edit); 9] = [
            ("h = 1e308", |p| p[2].h = 1e308),
            ("h NaN", |p| p[0].h = f64::NAN),
            ("steps not halved", |p| p[1].h = 0.2),
            ("theta 0.3", |p| {
                for plan in p {
                    plan.theta = 0.3;
                }
            }),
            ("one theta 1", |p| p[1].theta = 1.0),
            ("a NaN cost", |p| p[1].cost = f64::NAN),
            ("an infinite jet", |p| p[0].x[1][0] = f64::INFINITY),
            ("no momenta", |p| p[2].momenta.clear()),
            ("a jet missing", |p| {
                p[1].x.pop();
            }),
        ];
        for (what, edit) in hostile {
            let error = Extrapolated::from_plans(edited(edit)).expect_err(what);
            assert!(
                matches!(
                    error.failure,
                    Failure::Invalid(Error::InvalidArgument {
                        name: "plans" | "plan",
                        ..
                    })
                ),
                "{what}: {error}"
            );
        }
    }

    /// Plans read back from hostile JSON are refused by the extrapolation; the extrapolation
    /// itself round-trips.
    #[cfg(feature = "serde")]
    #[test]
    fn plans_from_hostile_json_are_refused_by_the_extrapolation() {
        let json = |plan: &Plan<1, 2>| serde_json::to_value(plan).unwrap();
        let read = |value: serde_json::Value| -> Plan<1, 2> {
            serde_json::from_value(value).expect("the JSON reads")
        };
        type Edit = fn(&mut serde_json::Value);
        let hostile: [(&str, Edit); 4] = [
            ("h = 1e308", |v| v["h"] = 1e308.into()),
            ("cost = \"inf\"", |v| v["cost"] = "inf".into()),
            ("theta = -0.5", |v| v["theta"] = (-0.5).into()),
            ("a NaN momentum", |v| v["momenta"][2][1] = "NaN".into()),
        ];
        for (what, edit) in hostile {
            let mut value = json(&rest(6));
            edit(&mut value);
            let plans = [rest(3), read(value), rest(12)];
            let result = Extrapolated::from_plans(plans);
            assert!(
                matches!(&result, Err(e) if matches!(e.failure, Failure::Invalid(_))),
                "{what}: {result:?}"
            );
        }
        // the extrapolation itself round-trips exactly (the plans' unknown certificates are NaN:
        // compared by their Debug form)
        let valid = Extrapolated::from_plans(edited(|_| ())).expect("three fitting plans");
        let text = serde_json::to_string(&valid).unwrap();
        let back: Extrapolated<1, 2> = serde_json::from_str(&text).unwrap();
        assert_eq!(format!("{back:?}"), format!("{valid:?}"));
        assert_eq!(serde_json::to_string(&back).unwrap(), text);
    }

    /// An extrapolation read from hostile JSON does not read: its plans are checked as by
    /// [`Extrapolated::from_plans`] and its values against those of its plans, and the
    /// error names the cause; [`Extrapolated::validate`] refuses the same values in memory.
    #[cfg(feature = "serde")]
    #[test]
    fn an_extrapolation_from_hostile_json_does_not_read() {
        let valid = Extrapolated::from_plans(edited(|_| ())).expect("three fitting plans");
        let json = serde_json::to_value(&valid).unwrap();
        type Edit = fn(&mut serde_json::Value);
        let hostile: [(&str, &str, Edit); 12] = [
            ("plans with mismatched steps", "plans", |v| {
                v["plans"][1]["h"] = 0.2.into()
            }),
            ("a NaN plan cost", "plans", |v| {
                v["plans"][0]["cost"] = "NaN".into()
            }),
            ("theta = 0.3 in every plan", "plans", |v| {
                for k in 0..3 {
                    v["plans"][k]["theta"] = 0.3.into();
                }
            }),
            ("a plan without jets", "plan", |v| {
                v["plans"][2]["x"] = serde_json::json!([])
            }),
            ("a plan's jet changed", "extrapolation", |v| {
                v["plans"][1]["x"][2][0] = 0.5.into()
            }),
            ("no values", "extrapolation", |v| {
                v["x"] = serde_json::json!([]);
                v["x_error"] = serde_json::json!([]);
            }),
            ("no momenta", "extrapolation", |v| {
                v["momenta"] = serde_json::json!([])
            }),
            ("a cost not the plans'", "extrapolation", |v| {
                v["cost"] = 2.0.into()
            }),
            ("a NaN cost estimate", "extrapolation", |v| {
                v["cost_error"] = "NaN".into()
            }),
            ("h = 1e308", "extrapolation", |v| v["h"] = 1e308.into()),
            ("an infinite jet estimate", "extrapolation", |v| {
                v["x_error"][1][0] = "inf".into()
            }),
            ("a momentum changed", "extrapolation", |v| {
                v["momenta"][0][1] = 0.5.into()
            }),
        ];
        for (what, name, edit) in hostile {
            let mut value = json.clone();
            edit(&mut value);
            let read = serde_json::from_value::<Extrapolated<1, 2>>(value.clone());
            let error = read.expect_err(what).to_string();
            assert!(error.contains(name), "{what}: {error}");
            // the fields as read, checked in memory
            let fields: ExtrapolatedFields<1, 2> = serde_json::from_value(value).unwrap();
            let unchecked = fields.unchecked();
            assert!(
                matches!(unchecked.validate(), Err(Error::InvalidArgument { name: n, .. }) if n == name),
                "{what}"
            );
        }
        // a value written with 14 significant digits still reads (pi + h^2 extrapolates to pi)
        let pi = Extrapolated::from_plans(edited(|p| {
            for plan in p {
                plan.cost = core::f64::consts::PI + plan.h * plan.h;
            }
        }))
        .expect("three fitting plans");
        let mut rounded = serde_json::to_value(&pi).unwrap();
        let short: f64 = format!("{:.13e}", pi.cost).parse().unwrap();
        assert!(short != pi.cost && (short - core::f64::consts::PI).abs() < 1e-12);
        rounded["cost"] = short.into();
        let read: Extrapolated<1, 2> = serde_json::from_value(rounded).expect("reads");
        assert_eq!(read.cost, short);
    }

    /// Plans whose values are finite but whose extrapolation overflows are refused, not
    /// extrapolated to NaN.
    #[test]
    fn an_overflowing_extrapolation_is_refused() {
        let plans = edited(|p| {
            for plan in p {
                plan.cost = 1e308;
            }
        });
        let error = Extrapolated::from_plans(plans).expect_err("overflows");
        assert!(
            matches!(
                error.failure,
                Failure::Invalid(Error::InvalidArgument { name: "plans", .. })
            ),
            "{error}"
        );
    }

    #[test]
    fn plans_of_the_wrong_lengths_are_refused() {
        let plan = |steps: usize| Plan::<1, 2> {
            h: 1.0 / steps as f64,
            theta: 0.5,
            x: vec![SVector::zeros(); steps + 1],
            u: vec![SVector::zeros(); steps],
            momenta: vec![SVector::zeros(); steps + 1],
            cost: 0.0,
            iterations: 0,
            certificate: super::super::plan::certificate::unknown_certificate(),
            violations: Default::default(),
            duals: Default::default(),
        };
        assert!(Extrapolated::from_plans([plan(3), plan(6), plan(12)]).is_ok());
        let error = Extrapolated::from_plans([plan(3), plan(6), plan(11)]).unwrap_err();
        assert!(matches!(error.failure, Failure::Invalid(_)));
    }
}
