//! The schemes: one step $z_0 \mapsto z_1$ of a system on $T^*(T^{(k-1)}\mathbb{R}^n)$ and
//! what is built from it. This layer imports the numeric kernels ([`crate::numeric`]) and the
//! crate's interface ([`crate::system`], [`crate::Error`]), never a manifold or the planner.
//!
//! - [`step`](mod@step): the lifted theta-scheme step (Newton from the explicit predictor),
//!   its singularity guard on every step, halving, and trajectories;
//! - [`lifted`]: the scheme assembled from a hand-written [`Lagrangian`](crate::Lagrangian);
//! - [`reduced`]: the reduced step (Newton on the nonlinear core, cached factors, and the
//!   compensated arithmetic that carries their rounding errors);
//! - [`compose`]: symmetric compositions of the midpoint step (orders 4, 6, 8);
//! - [`forced`]: a step under an external force (discrete Lagrange-d'Alembert);
//! - [`guard_fit`]: the guard's rule between the three samples of a step;
//! - [`diagnostics`]: energy, symplecticity, momentum drift, and RK4 for comparison;
//! - [`split`], [`split_methods`], [`split_stepper`]: the explicit splitting for
//!   $L = \tfrac{c}{2}|q^{(k)}|^2 + V(q)$, its methods and their stepper;
//! - [`map`]: the integrator of any discretization map (paper Prop. 5.1), lifted at run time
//!   by [`map::TaylorLift`].

pub mod compose;
pub mod diagnostics;
pub mod forced;
pub mod guard_fit;
pub mod lifted;
pub mod map;
pub mod reduced;
pub mod split;
pub mod split_methods;
pub mod split_stepper;
pub mod step;
