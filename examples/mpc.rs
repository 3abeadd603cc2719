//! The receding-horizon benchmark (docs/benchmarks.md, "Receding horizon"): the double
//! pendulum held upright at q = (pi, 0) by re-plans of 1/2 |tau|^2 + 50 |q - (pi, 0)|^2 +
//! |q'|^2 over T = 1 s, N = 50, one every control period of 0.02 s, the plant stepped with
//! the torque held and its velocity kicked by (+k, -k) rad/s at t = 0.5 s (the loop is in
//! `examples/common/upright.rs`). For each kick (2, 8) and each mode (real-time iterations
//! with one and two feedback steps a period, `rti1` and `rti2`; full solves from the shifted
//! plan, `full`) it prints exactly
//!
//! `kick=<k> mode=<rti1|rti2|full> max_dev=<d> settle_s=<s> median_us=<m> p99_us=<p> failures=<f>`
//!
//! (`max_dev`: the largest |q - (pi, 0)| after the kick; `settle_s`: the time from the kick
//! after which it stays below 1e-3, `inf` if it does not by t = 5 s; the times: a period's
//! re-plan, feedback and preparation; `failures`: periods whose re-plan failed), then for the
//! real-time modes the feedback phase alone:
//!
//! `feedback kick=<k> mode=<rti1|rti2> median_us=<m> p99_us=<p> max_us=<x>`
//!
//! Run: `cargo run --release --example mpc`.

#[path = "common/pendulum.rs"]
mod pendulum;
#[path = "common/upright.rs"]
mod upright;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    for line in upright::lines()? {
        println!("{line}");
    }
    Ok(())
}
