//! The one error type of the runtime.

use core::fmt;

/// Which domain condition of the Lagrangian a step violated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DomainKind {
    /// A denominator changed sign or vanished.
    Denominator,
    /// The argument of `sqrt` became negative.
    SqrtArgument,
    /// The argument of `ln` left $(0, \infty)$.
    LnArgument,
    /// The base of `powf` left $(0, \infty)$.
    PowfBase,
}

/// A guarded expression of the Lagrangian that left its domain during a step.
#[derive(Clone, Copy, Debug, PartialEq)]
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
        }
        if let Some(k) = self.element {
            write!(f, " for element {k} of the parameter list")?;
        }
        Ok(())
    }
}

/// Why a solve or a step failed.
///
/// Every variant carries the data needed to act on it; the [`Display`](fmt::Display)
/// text says what went wrong and what to try.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
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
    /// The Newton matrix had a zero pivot (or its solve overflowed) at `iteration`.
    SingularJacobian {
        /// Newton iteration at which the factorisation failed.
        iteration: usize,
    },
    /// The iteration cap was reached; `residual_norm` is max|F| at the last iterate.
    NoConvergence {
        /// Newton iterations performed.
        iterations: usize,
        /// max-norm of the residual at the last iterate.
        residual_norm: f64,
    },
    /// Backtracking could not decrease |F|^2 along the Newton direction.
    LineSearchFailed {
        /// Newton iteration whose line search failed.
        iteration: usize,
        /// max-norm of the residual at the last accepted iterate.
        residual_norm: f64,
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
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
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
                 Lagrangian (e.g. entered an obstacle); the states before it are valid"
            ),
            Error::InvalidArgument { name, requirement } => {
                write!(f, "invalid argument `{name}`: {requirement}")
            }
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
        ]
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
