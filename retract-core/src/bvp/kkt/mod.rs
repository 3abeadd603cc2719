//! The linear algebra of one SQP iteration: the quadratic subproblem's KKT system.
//!
//! - `riccati`: the stage models, the factorisation by a Riccati recursion with the inertia
//!   of the reduced Hessian, the subproblem's solution ([`riccati::Direction`]), and the
//!   vectors it takes from the solver's workspace ([`riccati::Vectors`]);
//! - `refine`: iterative refinement of a solution;
//! - `residuals`: the KKT residuals and momenta a plan is certified with, and the smallest
//!   eigenvalue of the reduced Hessian (Lanczos on the factorisation).
//!
//! It imports only `dynamics` and `stack` of the planner: the workspace implements
//! [`riccati::Vectors`], so that these modules need not know it.

pub(super) mod refine;
pub(super) mod residuals;
pub(super) mod riccati;
