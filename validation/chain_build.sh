#!/usr/bin/env bash
# The release build of a program that plans the n-link chain of C4 written as T - V
# (`#[mechanical_system]`, the energy of `examples/common/mechanical.rs`): a fresh crate
# depending on retract by path, its dependencies built first, then for each n the crate alone
# rebuilt and timed, and, for comparison, the same program with a one-line energy of n
# coordinates (what planning any system of that size compiles). Prints
# `chain n=<n> build_s=<s> one_line_energy_s=<s>` per n, then the plans' costs.
#
# Run: `bash validation/chain_build.sh [n ...]` (default: 3 7 12).
set -euo pipefail

repo="$(cd "$(dirname "$0")/.." && pwd)"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/src"
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(3 7 12)

cat > "$dir/Cargo.toml" <<TOML
[package]
name = "chain-build"
version = "0.1.0"
edition = "2024"
publish = false

[dependencies]
retract = { path = "$repo" }

[workspace]
TOML

# main.rs for n links; $2: the chain's energy (1) or a one-line energy (0)
program() {
  local n=$1 chain=$2 body
  if [ "$chain" = 1 ]; then
    body='let (mut phi, mut dphi) = (0.0, 0.0);
    let (mut vx, mut vz, mut height) = (0.0, 0.0, 0.0);
    let mut energy = 0.0;
    for i in 0..@N@ {
        phi += q[i];
        dphi += dq[i];
        vx += phi.cos() * dphi;
        vz += phi.sin() * dphi;
        height -= phi.cos();
        energy += 0.5 * (vx * vx + vz * vz) - 9.81 * height;
    }
    energy'
  else
    body='let mut energy = 0.0;
    for i in 0..@N@ {
        energy += 0.5 * dq[i] * dq[i] - 9.81 * q[i].cos();
    }
    energy'
  fi
  body=${body//@N@/$n}
  cat <<RUST
use retract::bvp::Variable;
use retract::{OptimalControlProblem, PlanGuess, mechanical_system};

const N: usize = $n;

#[mechanical_system]
fn chain(q: [f64; $n], dq: [f64; $n]) -> f64 {
    $body
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let start = [0.0; 2 * N];
    let mut goal = [0.0; 2 * N];
    goal[..N].fill(0.5);
    let mut problem = OptimalControlProblem::new(&Chain, &start, &goal, 2.0, 20);
    for i in 0..N {
        problem = problem.with_bounds(Variable::Jet(i), -2.0, 2.0);
    }
    let plan = problem.solve(PlanGuess::Spline)?;
    println!("n={} J={:.6} iterations={}", N, plan.cost, plan.iterations);
    Ok(())
}
RUST
}

cd "$dir"
program 3 1 > src/main.rs
cargo build --release --quiet
seconds() {
  local started ended ms
  started=$(date +%s%N)
  cargo build --release --quiet
  ended=$(date +%s%N)
  ms=$(((ended - started) / 1000000))
  echo "$((ms / 1000)).$(printf %03d $((ms % 1000)))"
}
for n in "${sizes[@]}"; do
  program "$n" 1 > src/main.rs
  chain=$(seconds)
  ./target/release/chain-build > "run-$n.txt"
  program "$n" 0 > src/main.rs
  plain=$(seconds)
  echo "chain n=$n build_s=$chain one_line_energy_s=$plain ($(nproc) threads, load $(cut -d' ' -f1 /proc/loadavg))"
done
cat run-*.txt
