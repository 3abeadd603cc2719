//! Integration tests of the integrators: the scheme, compositions, discretization maps, the
//! sphere, the macro against hand-written code, the guard on steps, messages and robustness;
//! also the SVG figures of `retract::plot`.
//!
//! One test crate per group (fewer crates build and link faster): each module was a test
//! crate of its own; `common` holds the shared helpers and Lagrangians.

#[path = "../common/mod.rs"]
mod common;

mod compositions;
mod core_scheme;
mod discretization_maps;
mod docs_figures;
mod exp_maps;
mod forced;
mod fuzz_corpus;
mod guard;
mod guard_quadratic;
mod guard_singular;
mod hard_cases;
mod helpers;
mod long_recurrence;
mod macro_robustness;
mod macro_vs_handwritten;
mod map_macro;
mod messages_runtime;
mod plot;
mod robustness_chord_invariant;
mod robustness_runtime;
mod se3;
mod so3;
mod so3_body;
mod so3_moving;
mod sphere;
mod sphere_order3;
mod splitting;
mod splitting_methods;
mod structure;
