//! The compile-time behaviour of retract's attributes, tested by `tests/ui.rs` with trybuild:
//! the mistakes in `tests/ui/fail/<topic>/` with their messages, the programs in
//! `tests/ui/pass/` that compile and run. The library itself is empty.
#![forbid(unsafe_code)]
