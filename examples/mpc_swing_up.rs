//! Receding-horizon control of the double pendulum with the plant in the loop
//! (`examples/common/pendulum.rs` has the loop): from the hanging rest state, swing up and
//! hold upright, re-planning every control period h = T / N (N = 50, T = 1 s) from the
//! plant's state with two real-time iterations (feedback steps of the library's
//! `RealTimeIteration`, started from a full solve). Prints exactly one line:
//! `re-plans=<n> failures=<f> median_us=<m> p99_us=<p> max_us=<x>` (a failure is a re-plan
//! that fell back to the shifted plan or a preparation that failed; the times are those of
//! the re-plans alone, with the shift and the next preparation).
//!
//! Run: `cargo run --release --example mpc_swing_up` (1000 re-plans, 20 s of simulated time; add a
//! number for another count).

#[path = "common/pendulum.rs"]
mod pendulum;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let replans = match std::env::args().nth(1) {
        Some(count) => count.parse()?,
        None => 1000,
    };
    let summary = pendulum::run(replans)?;
    println!(
        "re-plans={} failures={} median_us={:.1} p99_us={:.1} max_us={:.1}",
        summary.replans,
        summary.failures,
        summary.quantile_us(0.5),
        summary.quantile_us(0.99),
        summary.quantile_us(1.0),
    );
    Ok(())
}
