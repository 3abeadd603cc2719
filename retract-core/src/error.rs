//! The one error type of the runtime.

use core::fmt;

/// Which domain condition of the Lagrangian a step violated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum DomainKind {
    /// A denominator changed sign or vanished.
    Denominator,
    /// The argument of `sqrt` became negative.
    SqrtArgument,
    /// The argument of `ln` left $(0, \infty)$.
    LnArgument,
    /// The base of `powf` left $(0, \infty)$.
    PowfBase,
    /// The argument of `asin` or `acos` left $(-1, 1)$ (the guarded expression is
    /// $1 - x^2$, which must stay positive).
    AsinArgument,
}

/// A guarded expression of the Lagrangian that left its domain during a step.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DomainViolation {
    /// The expression as written in the Lagrangian.
    pub expression: &'static str,
    /// The condition it violated.
    pub kind: DomainKind,
    /// For an expression inside a loop over a slice parameter: the element's index.
    pub element: Option<usize>,
}

impl fmt::Display for DomainViolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let expression = self.expression;
        match self.kind {
            DomainKind::Denominator => {
                write!(f, "denominator `{expression}` changed sign or vanished")?
            }
            DomainKind::SqrtArgument => {
                write!(f, "argument `{expression}` of sqrt became negative")?
            }
            DomainKind::LnArgument => write!(f, "argument `{expression}` of ln left (0, inf)")?,
            DomainKind::PowfBase => write!(f, "base `{expression}` of powf left (0, inf)")?,
            DomainKind::AsinArgument => {
                write!(f, "argument `{expression}` of asin or acos left (-1, 1)")?
            }
        }
        element(f, self)
    }
}

/// " for element k of the parameter list", for a guard inside a loop over a slice parameter.
fn element(f: &mut fmt::Formatter<'_>, violation: &DomainViolation) -> fmt::Result {
    if let Some(k) = violation.element {
        write!(f, " for element {k} of the parameter list")?;
    }
    Ok(())
}

/// What a guarded expression of this kind is, in words.
fn kind_name(kind: DomainKind) -> &'static str {
    match kind {
        DomainKind::Denominator => "denominator",
        DomainKind::SqrtArgument => "sqrt argument",
        DomainKind::LnArgument => "ln argument",
        DomainKind::PowfBase => "powf base",
        DomainKind::AsinArgument => "asin or acos argument",
    }
}

/// The message of a given state (`data`) outside the domain.
fn outside_domain(f: &mut fmt::Formatter<'_>, data: &str, error: &Error) -> fmt::Result {
    write!(f, "the {data} lies outside the domain of the Lagrangian: ")?;
    if let Some(violation) = error.violation() {
        at_point(f, &violation)?;
    }
    write!(
        f,
        " there (e.g. it is inside an obstacle), so no guess or step size can fix it: move the \
         {data} into the domain or change the parameters"
    )
}

/// [`Error::SolutionOutsideDomain`]: the step, its guard's violation and what to do.
fn solution_outside_domain(f: &mut fmt::Formatter<'_>, step: u32, error: &Error) -> fmt::Result {
    write!(
        f,
        "the solution's step {step} leaves the domain of the Lagrangian"
    )?;
    if let Some(violation) = error.violation() {
        write!(f, " ({violation})")?;
    }
    write!(
        f,
        ": a pole lies on it, so this is not a plan; use more steps or a guess that stays clear \
         of the singular set (around an obstacle, not through it)"
    )
}

/// A violation at a single point (no step): the condition that fails there.
fn at_point(f: &mut fmt::Formatter<'_>, violation: &DomainViolation) -> fmt::Result {
    let expression = violation.expression;
    match violation.kind {
        DomainKind::Denominator => {
            write!(f, "denominator `{expression}` vanishes or is not finite")?
        }
        DomainKind::SqrtArgument => write!(f, "argument `{expression}` of sqrt is negative")?,
        DomainKind::LnArgument => write!(f, "argument `{expression}` of ln is not positive")?,
        DomainKind::PowfBase => write!(f, "base `{expression}` of powf is not positive")?,
        DomainKind::AsinArgument => write!(
            f,
            "argument `{expression}` of asin or acos is outside (-1, 1)"
        )?,
    }
    element(f, violation)
}

impl Error {
    /// [`Error::SolutionOutsideDomain`] at `step` for `violation` (the root finder's, with
    /// `std`).
    #[cfg(feature = "std")]
    pub(crate) fn solution_outside_domain(step: usize, violation: DomainViolation) -> Self {
        let index = |k: usize| u32::try_from(k).unwrap_or(u32::MAX);
        Error::SolutionOutsideDomain {
            step: index(step),
            expression: violation.expression,
            kind: violation.kind,
            element: violation.element.map(index),
        }
    }
}

/// Why a solve or a step failed.
///
/// Every variant carries the data needed to act on it; the [`Display`](fmt::Display)
/// text says what went wrong and what to try.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Error {
    /// A NaN or infinite value appeared in `location` ("initial guess", "residual",
    /// "Jacobian", "vector field", ...) at Newton iteration `iteration` (0: before the first
    /// iteration, or outside a Newton solve).
    NonFinite {
        /// Newton iteration at which the value appeared.
        iteration: usize,
        /// The quantity that was not finite.
        location: &'static str,
    },
    /// A parameter of the system is NaN or infinite (reported by
    /// [`LiftedSystem::check_parameters`](crate::LiftedSystem::check_parameters) when a step or
    /// solve meets a non-finite value, or before a solve starts).
    NonFiniteParameter {
        /// The parameter's name, as written in the Lagrangian.
        name: &'static str,
        /// For a parameter list (`&[[f64; M]]`): the element (saturated at `u32::MAX`).
        element: Option<u32>,
        /// For an array: the component.
        index: Option<u32>,
    },
    /// The Newton matrix had a zero pivot (or its solve overflowed) at `iteration`.
    SingularJacobian {
        /// Newton iteration at which the factorisation failed.
        iteration: usize,
    },
    /// The iteration cap of a Newton solve (a step of the scheme) was reached;
    /// `residual_norm` is max|F| at the last iterate. The boundary-value solver reports
    /// [`Error::BoundaryValueNoConvergence`] instead.
    NoConvergence {
        /// Newton iterations performed.
        iterations: usize,
        /// max-norm of the residual at the last iterate.
        residual_norm: f64,
    },
    /// Backtracking could not decrease |F|^2 along the Newton direction of a Newton solve (a
    /// step of the scheme). The boundary-value solver reports
    /// [`Error::BoundaryValueLineSearchFailed`] instead.
    LineSearchFailed {
        /// Newton iteration whose line search failed.
        iteration: usize,
        /// max-norm of the residual at the last accepted iterate.
        residual_norm: f64,
    },
    /// A converged step's energy balance is off by more than its tolerance
    /// ([`StepOptions::energy_tolerance`](crate::StepOptions::energy_tolerance)): the root
    /// continues a step too long to resolve the motion (a fast rotation over a few radians,
    /// landing at another energy), not the motion itself.
    UnresolvedStep {
        /// $|H(z_1) - H(z_0) - W|$, the energy the step created ($W$: the work of a force).
        energy_error: f64,
        /// The energy the step exchanged, $E = \sum_i |p_i'||\Delta x_i| + |x_i'||\Delta p_i|$
        /// (derivatives at $z_0$).
        exchanged: f64,
    },
    /// A boundary-value solution passes through obstacle `obstacle`: its clearance at state
    /// `step` is `clearance` < 0 (or NaN).
    ThroughObstacle {
        /// Index of the obstacle.
        obstacle: usize,
        /// Index of the first state inside it.
        step: usize,
        /// The clearance there.
        clearance: f64,
    },
    /// A converged boundary-value solution's step `step` leaves the domain of the Lagrangian
    /// (the step's singularity guard, [`crate::scheme::step::check_step_domain`]: a pole at its
    /// evaluation point or between its nodes, e.g. a path through an obstacle whose barrier
    /// is a term of $L$): the solution is not a plan.
    /// (The violation's fields are held flat, the indices as `u32`, so that an error stays
    /// small enough to be returned by value: [`Self::violation`] gives it whole.)
    SolutionOutsideDomain {
        /// Index of the step (saturated at `u32::MAX`).
        step: u32,
        /// The guarded expression as written in the Lagrangian.
        expression: &'static str,
        /// The condition it violated.
        kind: DomainKind,
        /// For an expression inside a loop over a slice parameter: the element's index.
        element: Option<u32>,
    },
    /// The first guess of a boundary-value solve passes through obstacle `obstacle` (at
    /// state `step`), so Newton cannot pick a side of it.
    GuessThroughObstacle {
        /// Index of the obstacle.
        obstacle: usize,
        /// Index of the first guessed state inside it.
        step: usize,
        /// The clearance there.
        clearance: f64,
    },
    /// The step left the domain of the Lagrangian (a singular point lies inside it): the
    /// states after it are not to be trusted.
    Domain(DomainViolation),
    /// An argument was outside its domain, e.g. theta outside [0, 1] or a non-finite step.
    InvalidArgument {
        /// Name of the argument.
        name: &'static str,
        /// What is required of it.
        requirement: &'static str,
    },
    /// The Newton iteration of a boundary-value problem
    /// ([`BoundaryValueProblem`](crate::bvp::root_finder::BoundaryValueProblem)) reached its iteration
    /// cap; `residual_norm` is max|R| at the last iterate.
    BoundaryValueNoConvergence {
        /// Newton iterations performed.
        iterations: usize,
        /// max-norm of the residual at the last iterate.
        residual_norm: f64,
    },
    /// Backtracking could not decrease |R|^2 along the Newton direction of a boundary-value
    /// problem ([`BoundaryValueProblem`](crate::bvp::root_finder::BoundaryValueProblem)).
    BoundaryValueLineSearchFailed {
        /// Newton iteration whose line search failed.
        iteration: usize,
        /// max-norm of the residual at the last accepted iterate.
        residual_norm: f64,
    },
    /// The initial state of a trajectory lies outside the domain of the Lagrangian (e.g.
    /// inside an obstacle): a guarded expression fails at that state alone (a denominator
    /// vanishes or is not finite, a `sqrt` argument is negative, an `ln` argument or `powf`
    /// base is not positive), so no step size can help. The fields are those of a
    /// [`DomainViolation`] ([`Error::violation`] returns it).
    InitialStateOutsideDomain {
        /// The expression as written in the Lagrangian.
        expression: &'static str,
        /// The condition it violates.
        kind: DomainKind,
        /// For an expression inside a loop over a slice parameter: the element's index
        /// (saturated at `u32::MAX`; a `u32` keeps [`Error`] as small as before).
        element: Option<u32>,
    },
    /// The start jet of a boundary-value or optimal-control problem lies outside the domain of
    /// the Lagrangian, as for [`Error::InitialStateOutsideDomain`]: no guess can help.
    StartOutsideDomain {
        /// The expression as written in the Lagrangian.
        expression: &'static str,
        /// The condition it violates.
        kind: DomainKind,
        /// For an expression inside a loop over a slice parameter: the element's index
        /// (saturated at `u32::MAX`; a `u32` keeps [`Error`] as small as before).
        element: Option<u32>,
    },
    /// The goal jet of a boundary-value or optimal-control problem lies outside the domain of
    /// the Lagrangian, as for [`Error::InitialStateOutsideDomain`]: no guess can help.
    GoalOutsideDomain {
        /// The expression as written in the Lagrangian.
        expression: &'static str,
        /// The condition it violates.
        kind: DomainKind,
        /// For an expression inside a loop over a slice parameter: the element's index
        /// (saturated at `u32::MAX`; a `u32` keeps [`Error`] as small as before).
        element: Option<u32>,
    },
    /// The start and the goal of a boundary-value or optimal-control problem lie on opposite
    /// sides of a singularity of the Lagrangian: a guarded expression (e.g. the denominator of
    /// an obstacle's barrier) has opposite signs at them, typically because one of them is
    /// inside an obstacle. Every path between them crosses the singularity, so no guess can
    /// help. The fields are those of a [`DomainViolation`] ([`Error::violation`] returns it).
    BoundariesSeparated {
        /// The expression as written in the Lagrangian.
        expression: &'static str,
        /// The condition it violates.
        kind: DomainKind,
        /// For an expression inside a loop over a slice parameter: the element's index
        /// (saturated at `u32::MAX`; a `u32` keeps [`Error`] as small as before).
        element: Option<u32>,
    },
    /// The start or the goal of a boundary-value problem is inside obstacle `obstacle` (its
    /// clearance is `clearance` < 0, or NaN), so no guess can help.
    BoundaryInObstacle {
        /// Which end: `"start"` or `"goal"`.
        end: &'static str,
        /// Index of the obstacle.
        obstacle: usize,
        /// The clearance there.
        clearance: f64,
    },
}

/// Which given data a domain check at single points concerns (the constructor of the
/// variants of [`Error`] that carry a [`DomainViolation`]'s fields).
#[cfg_attr(not(feature = "std"), allow(dead_code))]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Given {
    /// [`Error::InitialStateOutsideDomain`].
    InitialState,
    /// [`Error::StartOutsideDomain`].
    Start,
    /// [`Error::GoalOutsideDomain`].
    Goal,
    /// [`Error::BoundariesSeparated`].
    Separated,
}

impl Error {
    /// The error of `given` data for which the domain check found `violation`.
    #[cfg_attr(not(feature = "std"), allow(dead_code))]
    pub(crate) fn given(given: Given, violation: DomainViolation) -> Self {
        let DomainViolation {
            expression,
            kind,
            element,
        } = violation;
        let element = element.map(|k| u32::try_from(k).unwrap_or(u32::MAX));
        match given {
            Given::InitialState => Error::InitialStateOutsideDomain {
                expression,
                kind,
                element,
            },
            Given::Start => Error::StartOutsideDomain {
                expression,
                kind,
                element,
            },
            Given::Goal => Error::GoalOutsideDomain {
                expression,
                kind,
                element,
            },
            Given::Separated => Error::BoundariesSeparated {
                expression,
                kind,
                element,
            },
        }
    }

    /// The guarded expression behind a domain error: the violation of a step
    /// ([`Error::Domain`]) or of given data ([`Error::InitialStateOutsideDomain`],
    /// [`Error::StartOutsideDomain`], [`Error::GoalOutsideDomain`],
    /// [`Error::BoundariesSeparated`]) or of a root-finder solution
    /// ([`Error::SolutionOutsideDomain`]); `None` for every other error.
    pub fn violation(&self) -> Option<DomainViolation> {
        match *self {
            Error::Domain(violation) => Some(violation),
            Error::InitialStateOutsideDomain {
                expression,
                kind,
                element,
            }
            | Error::StartOutsideDomain {
                expression,
                kind,
                element,
            }
            | Error::GoalOutsideDomain {
                expression,
                kind,
                element,
            }
            | Error::BoundariesSeparated {
                expression,
                kind,
                element,
            }
            | Error::SolutionOutsideDomain {
                expression,
                kind,
                element,
                ..
            } => Some(DomainViolation {
                expression,
                kind,
                element: element.map(|k| usize::try_from(k).unwrap_or(usize::MAX)),
            }),
            _ => None,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::NonFiniteParameter {
                name,
                element,
                index,
            } => {
                write!(f, "parameter `{name}`")?;
                if let Some(k) = element {
                    write!(f, " element {k}")?;
                }
                if let Some(i) = index {
                    write!(f, " component {i}")?;
                }
                write!(
                    f,
                    " is not finite (NaN or infinite): set it to a finite value"
                )
            }
            Error::NonFinite {
                iteration,
                location,
            } => {
                write!(f, "non-finite value in the {location}")?;
                if iteration > 0 {
                    write!(f, " at Newton iteration {iteration}")?;
                }
                write!(
                    f,
                    ": check the inputs and parameters for NaN/inf and that the state is \
                     inside the domain of the Lagrangian"
                )
            }
            Error::SingularJacobian { iteration } => write!(
                f,
                "singular Newton matrix at iteration {iteration}: the Lagrangian may be \
                 degenerate in the top derivative (d2L/du2 not invertible) or the step size \
                 too large"
            ),
            Error::NoConvergence {
                iterations,
                residual_norm,
            } => write!(
                f,
                "Newton did not converge in {iterations} iterations (last residual max-norm \
                 {residual_norm:e}): reduce the step size (or allow step halving) or raise the \
                 iteration cap"
            ),
            Error::UnresolvedStep {
                energy_error,
                exchanged,
            } => write!(
                f,
                "the step changed the energy by {energy_error:e}, more than its tolerance \
                 allows against the {exchanged:e} it exchanged: the step is too long for the \
                 motion; reduce the step size (or allow step halving)"
            ),
            Error::LineSearchFailed {
                iteration,
                residual_norm,
            } => write!(
                f,
                "line search failed at Newton iteration {iteration} (residual max-norm \
                 {residual_norm:e}): the Newton direction does not decrease the residual; \
                 reduce the step size (or allow step halving)"
            ),
            Error::ThroughObstacle {
                obstacle,
                step,
                clearance,
            } => write!(
                f,
                "the solution passes through obstacle {obstacle} (clearance {clearance:e} at \
                 state {step}); inside an obstacle the cost is unbounded below, so this is not \
                 a plan: start from a guess that goes around it or raise the barrier weight"
            ),
            Error::SolutionOutsideDomain { step, .. } => solution_outside_domain(f, step, self),
            Error::GuessThroughObstacle {
                obstacle,
                step,
                clearance,
            } => write!(
                f,
                "the first guess passes through obstacle {obstacle} (clearance {clearance:e} at \
                 state {step}), so the solver cannot choose a side: pass a guess that goes \
                 around it (Guess::States)"
            ),
            Error::Domain(violation) => write!(
                f,
                "{violation} within the step: the trajectory crossed a singularity of the \
                 Lagrangian (e.g. entered an obstacle, or left one it started inside); the \
                 states before it are valid"
            ),
            Error::InvalidArgument { name, requirement } => {
                write!(f, "invalid argument `{name}`: {requirement}")
            }
            Error::InitialStateOutsideDomain { .. } => outside_domain(f, "initial state", self),
            Error::StartOutsideDomain { .. } => outside_domain(f, "start", self),
            Error::GoalOutsideDomain { .. } => outside_domain(f, "goal", self),
            Error::BoundaryValueNoConvergence { .. }
            | Error::BoundaryValueLineSearchFailed { .. }
            | Error::BoundariesSeparated { .. }
            | Error::BoundaryInObstacle { .. } => self.fmt_boundary_value(f),
        }
    }
}

impl Error {
    /// The messages of the boundary-value failures (the root finder's and the ends'), for
    /// [`fmt::Display`].
    fn fmt_boundary_value(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::BoundaryValueNoConvergence {
                iterations,
                residual_norm,
            } => write!(
                f,
                "the boundary-value Newton iteration did not converge in {iterations} \
                 iterations (last residual max-norm {residual_norm:e}): raise \
                 BvpOptions::max_iterations, or start from a better guess (Guess::States along \
                 the expected path, or a warm start from an easier problem with \
                 bvp::root_finder::continuation)"
            ),
            Error::BoundaryValueLineSearchFailed {
                iteration,
                residual_norm,
            } => write!(
                f,
                "the boundary-value line search failed at Newton iteration {iteration} \
                 (residual max-norm {residual_norm:e}): no step along the Newton direction \
                 decreases the residual of the whole discrete trajectory; start from a better \
                 guess (Guess::States along the expected path, or a warm start from an easier \
                 problem with bvp::root_finder::continuation, e.g. a larger barrier weight), or use the \
                 optimizer (OptimalControlProblem), whose line search follows the cost"
            ),
            Error::BoundariesSeparated {
                expression, kind, ..
            } => {
                write!(
                    f,
                    "the start and the goal lie on opposite sides of a singularity of the \
                     Lagrangian: the {} `{expression}` has opposite signs at them",
                    kind_name(kind),
                )?;
                if let Some(violation) = self.violation() {
                    element(f, &violation)?;
                }
                write!(
                    f,
                    " (e.g. one of them is inside an obstacle), so every path between them \
                     crosses it and no guess can fix it: move the start or the goal"
                )
            }
            Error::BoundaryInObstacle {
                end,
                obstacle,
                clearance,
            } => write!(
                f,
                "the {end} is inside obstacle {obstacle} (clearance {clearance:e}), so no \
                 guess can fix it (a solution begins at the start and ends at the goal): move \
                 the {end} out of the obstacle"
            ),
            // (only the variants above reach here)
            _ => write!(f, "{self:?}"),
        }
    }
}

impl core::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every variant, with the words its message must contain.
    fn cases() -> Vec<(Error, Vec<&'static str>)> {
        let violation = |kind| DomainViolation {
            expression: "x * x - 1.0",
            kind,
            element: Some(3),
        };
        vec![
            (
                Error::NonFinite {
                    iteration: 2,
                    location: "residual",
                },
                vec!["non-finite", "residual", "iteration 2", "NaN"],
            ),
            (
                Error::NonFinite {
                    iteration: 0,
                    location: "vector field",
                },
                vec!["non-finite", "vector field"],
            ),
            (
                Error::SingularJacobian { iteration: 1 },
                vec!["singular", "iteration 1", "degenerate"],
            ),
            (
                Error::NoConvergence {
                    iterations: 50,
                    residual_norm: 1.5e-3,
                },
                vec!["50 iterations", "1.5e-3", "step size"],
            ),
            (
                Error::LineSearchFailed {
                    iteration: 4,
                    residual_norm: 2.0,
                },
                vec!["line search", "iteration 4", "step size"],
            ),
            (
                Error::UnresolvedStep {
                    energy_error: 2.1e3,
                    exchanged: 8.9e3,
                },
                vec!["energy", "2.1e3", "8.9e3", "step size"],
            ),
            (
                Error::ThroughObstacle {
                    obstacle: 1,
                    step: 17,
                    clearance: -0.25,
                },
                vec!["obstacle 1", "-2.5e-1", "state 17", "guess"],
            ),
            (
                Error::GuessThroughObstacle {
                    obstacle: 0,
                    step: 5,
                    clearance: -1.0,
                },
                vec!["first guess", "obstacle 0", "Guess::States"],
            ),
            (
                Error::Domain(violation(DomainKind::Denominator)),
                vec!["denominator `x * x - 1.0`", "changed sign", "element 3"],
            ),
            (
                Error::Domain(violation(DomainKind::SqrtArgument)),
                vec!["sqrt", "negative"],
            ),
            (
                Error::Domain(violation(DomainKind::LnArgument)),
                vec!["ln", "(0, inf)"],
            ),
            (
                Error::Domain(violation(DomainKind::PowfBase)),
                vec!["powf", "(0, inf)"],
            ),
            (
                Error::InvalidArgument {
                    name: "theta",
                    requirement: "theta must lie in [0, 1]",
                },
                vec!["`theta`", "[0, 1]"],
            ),
            (
                Error::BoundaryValueNoConvergence {
                    iterations: 50,
                    residual_norm: 1.5e-3,
                },
                vec![
                    "boundary-value",
                    "50 iterations",
                    "1.5e-3",
                    "max_iterations",
                ],
            ),
            (
                Error::BoundaryValueLineSearchFailed {
                    iteration: 4,
                    residual_norm: 2.0,
                },
                vec!["boundary-value line search", "iteration 4", "better guess"],
            ),
            (
                Error::given(Given::Start, violation(DomainKind::Denominator)),
                vec![
                    "the start lies outside the domain",
                    "denominator `x * x - 1.0` vanishes",
                    "element 3",
                    "no guess",
                ],
            ),
            (
                Error::given(Given::InitialState, violation(DomainKind::LnArgument)),
                vec!["the initial state lies outside", "ln is not positive"],
            ),
            (
                Error::given(Given::Goal, violation(DomainKind::SqrtArgument)),
                vec!["the goal lies outside", "sqrt is negative", "no guess"],
            ),
            (
                Error::given(Given::Separated, violation(DomainKind::Denominator)),
                vec!["opposite sides", "`x * x - 1.0`", "element 3", "no guess"],
            ),
            (
                Error::BoundaryInObstacle {
                    end: "goal",
                    obstacle: 2,
                    clearance: -0.5,
                },
                vec!["the goal is inside obstacle 2", "-5e-1", "no guess"],
            ),
        ]
    }

    #[test]
    fn the_error_stays_small() {
        // an Interrupted trajectory carries it by value (clippy's result_large_err)
        assert!(core::mem::size_of::<Error>() <= 40);
    }

    #[test]
    fn given_data_keep_their_violation() {
        for given in [
            Given::InitialState,
            Given::Start,
            Given::Goal,
            Given::Separated,
        ] {
            for element in [None, Some(7)] {
                let violation = DomainViolation {
                    expression: "q - 1.0",
                    kind: DomainKind::PowfBase,
                    element,
                };
                assert_eq!(Error::given(given, violation).violation(), Some(violation));
            }
        }
        let huge = DomainViolation {
            expression: "q",
            kind: DomainKind::Denominator,
            element: Some(usize::MAX),
        };
        let kept = Error::given(Given::Start, huge)
            .violation()
            .map(|v| v.element);
        assert_eq!(kept, Some(Some(u32::MAX as usize)));
        assert_eq!(Error::SingularJacobian { iteration: 1 }.violation(), None);
    }

    #[test]
    fn only_a_step_advises_a_smaller_step() {
        for (error, _) in cases() {
            let message = error.to_string();
            let step = matches!(
                error,
                Error::NoConvergence { .. }
                    | Error::LineSearchFailed { .. }
                    | Error::UnresolvedStep { .. }
            );
            assert_eq!(
                message.contains("step halving") || message.contains("reduce the step size"),
                step,
                "{message}"
            );
        }
    }

    #[test]
    fn every_variant_renders_an_actionable_message() {
        for (error, words) in cases() {
            let message = error.to_string();
            for word in words {
                assert!(
                    message.contains(word),
                    "{error:?}: `{message}` lacks `{word}`"
                );
            }
            let source: &dyn core::error::Error = &error;
            assert!(source.source().is_none());
        }
    }
}
