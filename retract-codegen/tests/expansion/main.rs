//! Tests of the expansion as a function on tokens (one test crate: each module was a crate
//! of its own): limits of the expansion, a grammar-based fuzzer, random inputs that must
//! never panic, and the robustness items of issue 14.

mod expansion_limits;
mod grammar_fuzz;
mod never_panics;
mod robustness_items;
