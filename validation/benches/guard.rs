//! Cost of the singularity guard on the paper's run: 400 midpoint steps of h = 0.01 on the
//! SE(2) obstacle system (tau = 1e-2), with the domain check on and off; and one check at the
//! paper's closest approach (`retract_validation::guard_cost::GuardCase`): the three points,
//! the step's check with the chord rule (a step of h = 0.01 is shorter than the default
//! spacing 0.02: no pieces), and the chord of a long step (h = 0.1, 16 pieces at a spacing of
//! 0.005). The same figures, timed interleaved, are in `examples/report.rs`.
//! Run: `cargo bench -p retract-validation --bench guard`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use retract::step::check_step_domain;
use retract::{LiftedSystem, StepOptions, trajectory};
use retract_validation::guard_cost::GuardCase;
use retract_validation::systems::{H, PAPER_STEPS, paper_start, paper_system};

fn guard(c: &mut Criterion) {
    let system = paper_system();
    let z0 = paper_start(&system);
    let mut group = c.benchmark_group("paper_run");
    for (name, on) in [
        ("guard_off", false),
        ("guard_on", true),
        ("guard_off_again", false),
    ] {
        let options = StepOptions::default().with_domain_check(on);
        group.bench_function(name, |b| {
            b.iter(|| trajectory(&system, &z0, H, PAPER_STEPS, &options).map(|t| t.states.len()))
        });
    }
    group.finish();
    // one step against one domain check at the paper's closest approach
    let case = GuardCase::new(&system).expect("the closest approach");
    let options = StepOptions::default().with_domain_check(false);
    let mut group = c.benchmark_group("per_step");
    group.bench_function("step_unchecked", |b| {
        b.iter(|| retract::step(&system, black_box(&case.z), H, &options).map(|s| s.0[0]))
    });
    group.bench_function("check_domain", |b| {
        b.iter(|| system.check_domain(black_box(&case.z), black_box(&case.w), 0.5))
    });
    let checked = StepOptions::default();
    group.bench_function("check_step_domain_short", |b| {
        b.iter(|| check_step_domain(&system, black_box(&case.z), black_box(&case.w), &checked))
    });
    group.bench_function("check_step_domain_16_pieces", |b| {
        b.iter(|| {
            check_step_domain(
                &system,
                black_box(&case.z),
                black_box(&case.long),
                &case.fine,
            )
        })
    });
    group.finish();
}

criterion_group!(benches, guard);
criterion_main!(benches);
