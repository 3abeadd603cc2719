//! The numeric kernels: what the schemes, the manifolds and the planner solve and
//! differentiate with. Nothing here knows a Lagrangian or a step; this layer imports only the
//! crate's [`Error`](crate::Error).
//!
//! - [`newton`]: damped Newton on statically sized systems $F(w) = 0$, with its convergence
//!   test and report;
//! - [`linalg`]: dense LU with partial pivoting, $P A = L U$, without heap;
//! - [`banded`]: banded LU (LAPACK's `dgbtf2`/`dgbtrs`), the root finder's fallback (with
//!   `std`);
//! - [`taylor`]: truncated Taylor series and dual numbers, to differentiate a rational map at
//!   run time;
//! - [`special`]: the Stumpff functions $c_k(s)$ of the exponential maps.

#[cfg(feature = "std")]
pub mod banded;
pub mod linalg;
pub mod newton;
pub mod special;
pub mod taylor;
