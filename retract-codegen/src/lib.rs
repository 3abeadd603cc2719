//! The expansions behind `#[higher_order_lagrangian]`, `#[jet_function]` and
//! `#[discretization_map]`, as ordinary functions over `proc_macro2` tokens so that they can be
//! unit-tested, fuzzed and benchmarked.
//!
//! It reads a Lagrangian written as a plain Rust function, differentiates it symbolically and
//! emits straight-line code for the `retract_core` traits. The stages, one module each:
//! `signature` (order, dimension, parameters) -> `lower` (body to a hash-consed expression
//! graph) -> `mechanics` (gradient, Hessian, momenta, scheme) -> `emit` (the generated items,
//! one module each over a shared context, their code written by `codegen`: one `let` per
//! shared node); `expand` runs them in order. `#[jet_function]` (module `jet_function`)
//! reuses them for a scalar function of the jet, emitting only its value, gradient and
//! Hessian. `#[discretization_map]` (module `map`) lowers a map (q, v) -> (R1, R2) the same
//! way, checks its conditions (`map_check`), lifts it by total derivatives and differentiates
//! it (`map_lift`), and emits a `DiscretizationMap` (`emit::map`). With `sphere`, `so3` or `se3`, the stage
//! `charts` composes the function with its space's chart between `lower` and `mechanics`: an
//! ambient Lagrangian on S^2 with a gnomonic chart (`sphere`), one in the rotation and body
//! velocity with a Gibbs chart of SO(3) (`so3`), one in the pose and body velocity with the
//! product chart of SE(3) (`se3`). Helpers used by several stages (`util`) import none
//! of them.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod charts;
mod codegen;
mod diff;
mod emit;
mod expand;
mod graph;
mod helper;
mod jet_function;
mod lower;
mod map;
mod map_check;
mod map_lift;
mod mechanics;
mod scopes;
mod se3;
mod separable;
mod signature;
mod so3;
mod sphere;
mod util;

pub mod samples;

pub use expand::{ExpansionStats, expand, expansion_stats, try_expand};
pub use helper::{expand_helper, expand_with_helpers};
pub use jet_function::{expand_jet_function, try_expand_jet_function};
pub use map::{expand_discretization_map, try_expand_discretization_map};
