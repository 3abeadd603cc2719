//! The expansions behind `#[higher_order_lagrangian]`, `#[jet_function]`,
//! `#[discretization_map]` and `#[mechanical_system]`, as ordinary functions over `proc_macro2` tokens so that they can be
//! unit-tested, fuzzed and benchmarked.
//!
//! It reads a Lagrangian written as a plain Rust function, differentiates it symbolically and
//! emits straight-line code for the `retract_core` traits. The modules, in the order the
//! stages run:
//!
//! - `attribute`: the entry points, one module per attribute (`lagrangian`, `jet_function`,
//!   `map`, `mechanical`, `helper` with the re-entry of an attribute that names helpers);
//! - `front`: the attribute's options and the signature (`signature`: order, dimension,
//!   parameters, space), the body lowered to the expression graph (`lower`);
//! - `ir`: the hash-consed expression graph (`graph`) and its differentiation (`diff`);
//! - `charts`: the spaces, each behind one trait `Chart` (`flat`: R^n; `sphere`: gnomonic;
//!   `so3`: Gibbs; `se3`: the product chart), registered in `Space`: a function on a manifold
//!   is composed with its space's chart, so that the later stages see R^n;
//! - `mechanics`: gradient, Hessian, momenta, the scheme and its Jacobians, the reduced step,
//!   the separable form (`separable`); for a discretization map its conditions
//!   (`map_conditions`) and its lift by total derivatives (`lift`);
//! - `emit`: the generated items, one module each over a shared context, their code written by
//!   `codegen` (one `let` per shared node).
//!
//! `pipeline` chains the stages, once for every attribute. Helpers used by several stages
//! (`util`: the error context, token text) import none of them.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod attribute;
mod charts;
mod emit;
mod front;
mod ir;
mod mechanics;
mod pipeline;
mod util;

pub mod samples;

pub use attribute::expand_with_helpers;
pub use attribute::helper::expand_helper;
pub use attribute::jet_function::{expand_jet_function, try_expand_jet_function};
pub use attribute::lagrangian::{ExpansionStats, expand, expansion_stats, try_expand};
pub use attribute::map::{expand_discretization_map, try_expand_discretization_map};
pub use attribute::mechanical::{expand_mechanical_system, try_expand_mechanical_system};
