//! The compile-time cost of `#[mechanical_system]` on the planar n-link chain written as
//! T - V (`retract_validation::expansion_cost::chain_expansions`): for n = 3, 5, 7, 9, 12 the
//! best of five expansions and the lines of the formatted expansion, one line each,
//! `chain n=<n> expand_ms=<t> lines=<l>` (also in the speed report, `examples/report.rs`).
//!
//! Run: `cargo run --release -p retract-validation --example chain_expansion`.

use std::process::ExitCode;

use retract_validation::expansion_cost::{chain_expansions, write_chain_expansions};

fn main() -> ExitCode {
    let written = chain_expansions(5)
        .and_then(|rows| write_chain_expansions(&mut std::io::stdout().lock(), &rows));
    match written {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
