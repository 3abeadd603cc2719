//! Benchmarks (`benches/`), the work-precision comparison with ODE peers
//! (`examples/work_precision.rs`) and the heavier test suites of `retract` (the property
//! tests of the generated derivatives and the compile-fail tests of the macros, `tests/`).
//! This crate has no API: it exists so that `cargo run --example ...` in `retract` does not
//! build criterion, proptest, trybuild, num-dual or ode_solvers.
