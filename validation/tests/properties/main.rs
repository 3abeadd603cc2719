//! Property tests of the generated code (one test crate: each module was a crate of its own):
//! the derivatives, mechanics and scheme of generated Lagrangians, and generated jet
//! functions, against finite differences at random points.

#[path = "../../../tests/common/mod.rs"]
mod common;

mod derivatives;
mod jet_function;
