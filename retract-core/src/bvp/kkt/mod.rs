//! The linear algebra of one SQP iteration: the quadratic subproblem's KKT system.
//!
//! - `model`: the subproblem's data (the stage models, the ends of the horizon);
//! - `pivots`: the small dense inverses with their inertia;
//! - `riccati`: the factorisation by a Riccati recursion with the inertia of the reduced
//!   Hessian, the subproblem's solution ([`riccati::Direction`]), and the vectors it takes
//!   from the solver's workspace ([`riccati::Vectors`]);
//! - `refine`: iterative refinement of a solution;
//! - `residuals`: the KKT residuals and momenta a plan is certified with;
//! - `curvature`: the smallest eigenvalue of the reduced Hessian (Lanczos on the
//!   factorisation).
//!
//! It imports only `dynamics` and `stack` of the planner: the workspace implements
//! [`riccati::Vectors`], so that these modules need not know it.

pub(super) mod curvature;
pub(super) mod model;
mod pivots;
pub(super) mod refine;
pub(super) mod residuals;
pub(super) mod riccati;
