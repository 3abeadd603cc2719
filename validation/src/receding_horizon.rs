//! The receding-horizon benchmark in the report (`docs/benchmarks.md`, "Receding horizon"):
//! the loop of `examples/common/upright.rs` (the double pendulum held upright by re-plans over
//! T = 1 s, N = 50, one every 0.02 s, its velocity kicked at t = 0.5 s), shared with
//! `examples/mpc.rs` by path, run for each kick (2, 8) and each mode (one or two real-time
//! iterations a period, full solves from the shifted plan). It writes the lines of
//! `--example mpc`, exactly:
//!
//! `kick=<k> mode=<rti1|rti2|full> max_dev=<d> settle_s=<s> median_us=<m> p99_us=<p> failures=<f>`
//!
//! then for the real-time modes `feedback kick=<k> mode=<rti1|rti2> median_us=<m> p99_us=<p>
//! max_us=<x>` (the feedback phase alone).

use std::io::Write;

use crate::Error;
use crate::upright;

/// Runs the loop for every kick and mode (`upright::lines` of `examples/common/upright.rs`)
/// and writes its lines to `out` under a heading.
///
/// # Errors
/// A re-plan that fails to set up (a plan that fails inside the loop is counted in
/// `failures=`, not an error) as [`Error::Plan`], or [`Error::Io`].
pub fn write(out: &mut dyn Write) -> Result<(), Error> {
    writeln!(
        out,
        "\n### Receding horizon\n\nThe double pendulum held upright (`examples/common/upright.rs`; \
         a period's re-plan, then the feedback phase alone):\n\n```text"
    )?;
    for line in upright::lines().map_err(|e| Error::Plan(e.to_string()))? {
        writeln!(out, "{line}")?;
    }
    writeln!(out, "```")?;
    Ok(())
}
