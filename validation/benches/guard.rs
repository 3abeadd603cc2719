//! Cost of the singularity guard on the paper's run: 400 midpoint steps of h = 0.01 on the
//! SE(2) obstacle system (tau = 1e-2), with the domain check on and off; and one check at the
//! paper's closest approach: the three points, the step's check with the chord rule (a step of
//! h = 0.01 is shorter than the default spacing 0.02: no pieces), and the chord of a long step
//! (h = 0.1, 16 pieces at a spacing of 0.005).
//! Run: `cargo bench -p retract-validation --bench guard`.

use criterion::{Criterion, criterion_group, criterion_main};
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, trajectory};

#[higher_order_lagrangian(order = 2)]
fn rigid_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
        + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

fn guard(c: &mut Criterion) {
    let system = RigidBody { tau: 1e-2, r: 1.0 };
    let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let z0 = system.legendre(&SVector::from_column_slice(&jet));
    let mut group = c.benchmark_group("paper_run");
    for (name, on) in [
        ("guard_off", false),
        ("guard_on", true),
        ("guard_off_again", false),
    ] {
        let options = StepOptions::default().with_domain_check(on);
        group.bench_function(name, |b| {
            b.iter(|| trajectory(&system, &z0, 0.01, 400, &options).map(|t| t.states.len()))
        });
    }
    group.finish();
    // one step against one domain check at the paper's closest approach
    let run = trajectory(&system, &z0, 0.01, 200, &StepOptions::default()).expect("regular");
    let z = run.states[200];
    let options = StepOptions::default().with_domain_check(false);
    let w = system.predictor(&z, 0.01, 0.5).expect("regular");
    let (w, _) = retract::step::solve_step(&system, &z, w, 0.01, &options).expect("regular");
    let mut group = c.benchmark_group("per_step");
    group.bench_function("step_unchecked", |b| {
        b.iter(|| retract::step(&system, std::hint::black_box(&z), 0.01, &options).map(|s| s.0[0]))
    });
    group.bench_function("check_domain", |b| {
        b.iter(|| system.check_domain(std::hint::black_box(&z), std::hint::black_box(&w), 0.5))
    });
    let checked = StepOptions::default();
    group.bench_function("check_step_domain_short", |b| {
        b.iter(|| {
            retract::step::check_step_domain(
                &system,
                std::hint::black_box(&z),
                std::hint::black_box(&w),
                &checked,
            )
        })
    });
    let long = system.predictor(&z, 0.1, 0.5).expect("regular");
    let (long, _) = retract::step::solve_step(&system, &z, long, 0.1, &options).expect("regular");
    let fine = StepOptions::default().with_chord_check(0.005, 16);
    let length = (0..6).map(|i| (long[i] - z[i]).abs()).fold(0.0, f64::max);
    assert!(
        length > 16.0 * 0.005,
        "the long step must be cut into 16 pieces"
    );
    retract::step::check_step_domain(&system, &z, &long, &fine).expect("clear of the disc");
    group.bench_function("check_step_domain_16_pieces", |b| {
        b.iter(|| {
            retract::step::check_step_domain(
                &system,
                std::hint::black_box(&z),
                std::hint::black_box(&long),
                &fine,
            )
        })
    });
    group.finish();
}

criterion_group!(benches, guard);
criterion_main!(benches);
