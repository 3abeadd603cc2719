#!/usr/bin/env bash
# The first `cargo build --release` of a user crate that depends on retract by path (the
# README's install section) and plans with the optimizer: a fresh crate in a temporary
# directory, with its own target directory, so nothing is reused from this workspace's builds.
# Prints `first release build of a user crate: <s> s` and the crate's own output.
#
# Run from anywhere: `bash validation/first_build.sh`.
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src"

cat > "$dir/Cargo.toml" <<TOML
[package]
name = "first-build"
version = "0.1.0"
edition = "2024"
publish = false

[dependencies]
retract = { path = "$repo" }

[workspace]
TOML

cat > "$dir/src/main.rs" <<'RUST'
use retract::{OptimalControlProblem, PlanGuess, higher_order_lagrangian};

/// Minimum acceleration past a disc of radius 1: L = 1/2 |q''|^2 + tau / (|q|^2 - 1).
#[higher_order_lagrangian(order = 2)]
fn obstacle(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1]) + tau / (q[0] * q[0] + q[1] * q[1] - 1.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let system = Obstacle { tau: 1e-2 };
    let (start, goal) = ([-2.0, 1.5, 0.0, 0.0], [2.0, 1.5, 0.0, 0.0]);
    let plan = OptimalControlProblem::new(&system, &start, &goal, 4.0, 100).solve(PlanGuess::Spline)?;
    println!("J = {:.6} in {} iterations", plan.cost, plan.iterations);
    Ok(())
}
RUST

cd "$dir"
started=$(date +%s%N)
cargo build --release --quiet
ended=$(date +%s%N)
ms=$(((ended - started) / 1000000))
echo "first release build of a user crate: $((ms / 1000)).$(printf %03d $((ms % 1000))) s ($(nproc) threads, load $(cut -d' ' -f1 /proc/loadavg))"
./target/release/first-build
