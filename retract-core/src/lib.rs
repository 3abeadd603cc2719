//! Runtime of `retract`: the traits a generated higher-order system implements, a damped
//! Newton solver, the lifted theta-scheme step, trajectories and structure diagnostics.
//!
//! A $k$-th order Lagrangian $L(q, \dots, q^{(k)})$ on $\mathbb{R}^n$ gives, through the
//! Ostrogradsky construction, a Hamiltonian system on $z = (x, p) \in \mathbb{R}^{2nk}$.
//! The lifted midpoint ($\theta = 1/2$) or theta-scheme with step $h$ is
//!
//! $$x_1 - x_0 = h\thinspace\partial_p H(x_\theta, p_\theta), \quad
//!   p_1 - p_0 = -h\thinspace\partial_x H(x_\theta, p_\theta),$$
//! $$x_\theta = (1-\theta) x_0 + \theta x_1, \quad p_\theta = \theta p_0 + (1-\theta) p_1,$$
//!
//! symplectic for every $\theta \in [0, 1]$, of order 2 for $\theta = 1/2$ and 1 otherwise.
//! It is solved without inverting the Legendre map, with the top derivative $u = q^{(k)}$
//! as an extra unknown ([`LiftedSystem`]).
//!
//! The crate is in layers. [`numeric`] imports none of the others, [`scheme`] imports
//! [`numeric`], [`manifold`] imports both, and the planner ([`bvp`]) all three; the interface
//! at the root ([`system`], [`state`](mod@state), [`Error`]) is shared by all of them:
//!
//! - the interface: [`Lagrangian`] and [`LiftedSystem`], what a system provides
//!   ([`system`]); [`state`](mod@state): typed derivative data ([`Jet`]) and states
//!   ([`State`]), built by the Legendre map and read by name ($q^{(j)}$, $p_j$, $u$); the
//!   [`Error`] of every failure; [`mechanical`]: a system written as its energy $T - V$
//!   (`#[mechanical_system]`), its Euler-Lagrange operator's components as stage equalities;
//! - [`numeric`]: the kernels, [`numeric::newton`] (damped Newton), [`numeric::linalg`] (dense
//!   LU), the banded LU, [`numeric::taylor`] (Taylor and dual numbers) and
//!   [`numeric::special`] (Stumpff functions);
//! - [`scheme`]: [`scheme::step`](mod@scheme::step) (one step with its singularity guard, and
//!   trajectories), [`scheme::lifted`] (the scheme assembled from a [`Lagrangian`]),
//!   [`scheme::reduced`] (the reduced step), [`scheme::compose`] (symmetric compositions),
//!   [`scheme::forced`] (a step under an external force), [`scheme::diagnostics`] (energy,
//!   symplecticity, drift, RK4), [`scheme::split`] with [`scheme::split_methods`] and
//!   [`scheme::split_stepper`] (the explicit splitting for
//!   $L = \tfrac{c}{2}|q^{(k)}|^2 + V(q)$), and [`scheme::map`] (the integrator of any
//!   discretization map, paper Prop. 5.1, lifted at any order by
//!   [`scheme::map::TaylorLift`]);
//! - [`manifold`]: moving charts of [`manifold::sphere`] ($S^2$, gnomonic charts),
//!   [`manifold::so3`] (the rotation group, Gibbs charts) and [`manifold::se3`] (the rigid
//!   motions, product charts);
//! - the planner, [`bvp`] (with `std`): the optimal-control solver and the root finder;
//! - [`models`]: a system written by hand; [`output`] (with `std`): CSV export of
//!   trajectories, plans and solutions, with a header naming every column.
//!
//! The paths of these modules before the layers (`retract_core::step`, `retract_core::so3`,
//! `retract_core::newton`, ...) still name them, for one release.
//!
//! # References
//! A. Anahory Simoes, M. Barbero Liñán, L. Colombo, D. Martín de Diego,
//! "Higher-order retraction maps and construction of numerical methods for optimal control
//! of mechanical systems" (Prop. 4.1, Prop. 5.1, Sec. 6).
//!
//! # Features
//! `std` (default): trajectories ([`trajectory`]), the boundary-value solver ([`bvp`]) and
//! the banded LU. Without it the crate is `no_std` and allocation-free: steps, Newton,
//! diagnostics and everything generated code needs; math goes through `libm`.
//!
//! `serde` (off by default): `Serialize` and `Deserialize` for the results and options
//! ([`Trajectory`], [`StepReport`], [`bvp::Plan`], [`bvp::Certificate`], [`bvp::root_finder::BvpSolution`],
//! [`State`], [`Jet`], [`manifold::sphere::SphereState`], the option structs), `Serialize` for the
//! errors ([`Error`], [`bvp::PlanError`], [`Interrupted`]). Vectors are lists of numbers
//! (nalgebra's `serde-serialize-no-std`); it builds without std too.
#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "std")]
pub mod bvp;
mod error;
pub mod manifold;
pub mod mechanical;
pub mod models;
pub mod numeric;
#[cfg(feature = "std")]
pub mod output;
pub mod scheme;
#[cfg(all(feature = "serde", feature = "std"))]
mod serde_float;
pub mod state;
pub mod system;

// The paths before the layers, for one release (the planner and code written against them
// name them; generated code names `__private` alone).
#[doc(hidden)]
pub use manifold::{se3, so3, sphere};
#[cfg(feature = "std")]
#[doc(hidden)]
pub use numeric::banded;
#[doc(hidden)]
pub use numeric::{linalg, newton, special, taylor};
#[doc(hidden)]
pub use scheme::{
    compose, diagnostics, forced, lifted, map, reduced, split, split_methods, split_stepper, step,
};

/// What generated code names and a user does not: the traits it implements, the functions
/// its impls call and the types they return, in one flat module that the macro's output can
/// reach by one path (as `::thiserror::__private`). Not a public API: it follows the macros
/// of the same version.
#[doc(hidden)]
pub mod __private {
    pub use crate::manifold::se3::Se3System;
    pub use crate::manifold::so3::So3System;
    pub use crate::manifold::sphere::SphereSystem;
    pub use crate::mechanical::{InputComponent, MechanicalSystem, TorqueComponent};
    pub use crate::numeric::linalg::solve;
    pub use crate::numeric::special::stumpff;
    pub use crate::scheme::guard_fit::clear_of_zero;
    pub use crate::scheme::lifted::{
        hamiltonian, jacobian, jacobian_initial, legendre, predictor, residual, step_cost,
        vector_field,
    };
    pub use crate::scheme::map::{CovectorHessian, DiscretizationMap, MapJacobians};
    pub use crate::scheme::reduced::{
        ClosedForm, ReducedFactors, ReducedScheme, sum_corrected, sum_folded, two_product, two_sum,
    };
    pub use crate::scheme::split::Separable;
    pub use crate::system::{
        Derivatives, Gradient, Hessian, JetFunction, Lagrangian, LiftedSystem, VectorJetFunction,
    };
    pub use crate::{DomainKind, DomainViolation, Error, Float, nalgebra};
}

// the optimizer at the root (the legacy root finder stays in `bvp::root_finder`)
#[cfg(feature = "std")]
pub use bvp::{
    OptimalControlProblem, Placement, Plan, PlanError, PlanGuess, PlanOptions, Variable,
};
pub use compose::composed_step;
pub use error::{DomainKind, DomainViolation, Error};
pub use mechanical::{InputComponent, MechanicalSystem, TorqueComponent};
pub use newton::NewtonOptions;
pub use reduced::{ClosedForm, ReducedFactors, ReducedScheme, ReducedStepper};
pub use state::{Jet, State};
#[cfg(feature = "std")]
pub use step::{Interrupted, Trajectory, trajectory};
pub use step::{StepOptions, StepReport, step};
pub use system::{
    Derivatives, Gradient, Hessian, JetFunction, Lagrangian, LiftedSystem, VectorJetFunction,
};

/// The linear-algebra crate of the public API, re-exported so users and generated code
/// name the same version.
pub use nalgebra;

/// The float methods (`sqrt`, `powi`, ...) for `no_std` code: generated code imports it, and
/// a `no_std` crate can too (with std the inherent methods take precedence).
pub use num_traits::Float;

pub use special::stumpff;

/// A smooth maximum, $\max_\epsilon(a, b) = \tfrac12\big(a + b + \sqrt{(a - b)^2 +
/// \epsilon^2}\big)$: within $|\epsilon|/2$ of $\max(a, b)$, smooth for $\epsilon \ne 0$. A
/// Lagrangian may call it (`#[higher_order_lagrangian]` differentiates it).
pub fn smooth_max(a: f64, b: f64, eps: f64) -> f64 {
    0.5 * (a + b + num_traits::Float::sqrt((a - b) * (a - b) + eps * eps))
}

/// A smooth minimum, $\min_\epsilon(a, b) = \tfrac12\big(a + b - \sqrt{(a - b)^2 +
/// \epsilon^2}\big)$ ([`smooth_max`] with the root's sign flipped).
pub fn smooth_min(a: f64, b: f64, eps: f64) -> f64 {
    0.5 * (a + b - num_traits::Float::sqrt((a - b) * (a - b) + eps * eps))
}
