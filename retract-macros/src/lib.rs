//! Procedural macros of `retract`.
#![forbid(unsafe_code)]
