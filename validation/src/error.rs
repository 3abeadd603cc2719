//! The one error type of the measurements: a failed step or solve of `retract`, a plan the
//! optimizer could not make, a peer that failed, two variants of a step or two planners that
//! disagree, or output that could not be written.

use std::fmt;

/// Why a measurement could not be made.
#[derive(Debug)]
pub enum Error {
    /// A step, solve or run of `retract` failed.
    Retract(retract::Error),
    /// The optimizer (`OptimalControlProblem`) failed; its message (the failure and the last
    /// iterate).
    Plan(String),
    /// A peer (ode_solvers' DOP853) failed; its message.
    Peer(String),
    /// A variant of the step computes another state than the generated general step.
    Disagree {
        /// The variant.
        variant: &'static str,
        /// Its max-norm distance to the general step.
        difference: f64,
    },
    /// The optimizer and the root finder reach costs that differ by 1e-8 (relative) or more.
    CostsDiffer {
        /// The problem.
        case: &'static str,
        /// The relative difference of the costs.
        difference: f64,
    },
    /// A reference solution (the exact curve a measurement is compared with) could not be
    /// computed; why.
    Reference(String),
    /// A hand-written step left the domain of the potential (x^2 + y^2 = 1 crossed).
    Domain(&'static str),
    /// The report could not be written.
    Io(std::io::Error),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Retract(e) => write!(f, "retract: {e}"),
            Error::Plan(message) => write!(f, "optimizer: {message}"),
            Error::Peer(message) => write!(f, "peer: {message}"),
            Error::Disagree {
                variant,
                difference,
            } => write!(
                f,
                "{variant} differs from the general step by {difference:e} (more than 1e-12)"
            ),
            Error::CostsDiffer { case, difference } => write!(
                f,
                "{case}: the optimizer's and the root finder's costs differ by {difference:e} \
                 (relative; more than 1e-8)"
            ),
            Error::Reference(message) => write!(f, "reference solution: {message}"),
            Error::Domain(variant) => write!(f, "{variant} left the domain of the potential"),
            Error::Io(e) => write!(f, "writing the report: {e}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Retract(e) => Some(e),
            Error::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<retract::Error> for Error {
    fn from(e: retract::Error) -> Self {
        Error::Retract(e)
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::Io(e)
    }
}
