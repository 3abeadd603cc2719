//! Speed of one step of the paper's SE(2) obstacle system (tau = 1e-2, h = 0.01, midpoint)
//! near its closest approach to the disc, and of the 400-step run, for the variants of
//! `retract_validation::step_speed`: generated reduced (with and without the domain check)
//! and general steps, and the hand-written peers (`retract_validation::peers`: dense 12x12
//! Newton with the Jacobian by hand, by dual numbers or by finite differences; the reduced
//! 3x3 Newton, the limit, with and without the domain check).
//!
//! The tables, timed in one run in interleaved rounds (best of the rounds), are printed
//! first (the same as `examples/report.rs` prints); then criterion times each step. Run:
//! `cargo bench -p retract-validation --bench step`.

use std::hint::black_box;
use std::io::Write;

use criterion::{Criterion, criterion_group, criterion_main};
use retract::{ReducedStepper, StepOptions, step};
use retract_validation::peers::{DenseJacobian, dense_step, hand_reduced_step};
use retract_validation::step_speed;
use retract_validation::systems::{H, closest_approach, paper_system};

/// Rounds of the interleaved tables.
const ROUNDS: usize = 60;

fn benches(c: &mut Criterion) {
    let system = paper_system();
    let z = closest_approach(&system).expect("the paper's run");
    step_speed::check_variants(&system, &z).expect("the variants agree");
    let mut out = std::io::stdout();
    let newton = step_speed::newton_systems(&system, &z, 20).expect("regular");
    println!("\nNewton system (residual + Jacobian), SE(2) obstacle, h = 0.01:");
    for (name, ns) in newton {
        println!("  {name:<48} {ns:>9.1} ns");
    }
    println!();
    let steps = step_speed::steps(&system, &z, ROUNDS, 2000);
    step_speed::write_steps(&mut out, &steps, ROUNDS).expect("stdout");
    let runs = step_speed::paper_runs(&system, 200, 3).expect("the paper's run");
    step_speed::write_runs(&mut out, &runs, 200).expect("stdout");
    out.flush().expect("stdout");
    let options = StepOptions::default();
    let mut group = c.benchmark_group("step/se2_obstacle");
    let mut reduced = ReducedStepper::new(&system);
    group.bench_function("generated_reduced", |b| {
        b.iter(|| reduced.step(black_box(&z), H, &options).map(|s| s.0[0]))
    });
    group.bench_function("generated_general", |b| {
        b.iter(|| step(&system, black_box(&z), H, &options).map(|s| s.0[0]))
    });
    for (name, jacobian) in [
        ("hand_dense_12", DenseJacobian::Hand),
        ("dual_dense_12", DenseJacobian::Dual),
        ("fd_dense_12", DenseJacobian::FiniteDifferences),
    ] {
        group.bench_function(name, |b| {
            b.iter(|| dense_step(black_box(&z), jacobian).map(|z| z[0]))
        });
    }
    group.bench_function("hand_reduced_3", |b| {
        b.iter(|| hand_reduced_step(black_box(&z)).map(|z| z[0]))
    });
    group.finish();
}

criterion_group!(step_benches, benches);
criterion_main!(step_benches);
