//! Tests of the expansion as a function on tokens (one test crate: each module was a crate
//! of its own): limits of the expansion, a grammar-based fuzzer, random inputs that must
//! never panic, and extreme inputs (odd names, integers at the ends of their types, large
//! indices, non-finite constants, deep recurrences).

mod expansion_limits;
mod extreme_inputs;
mod grammar_fuzz;
mod never_panics;
