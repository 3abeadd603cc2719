//! The planner's speed (`retract_validation::planner_speed`, the measurements of the report's
//! planner part): boundary-value solve time against the number of steps N (expected linear),
//! the linear solvers and the warm re-solve after a shift by one step at N = 400, the
//! optimizer (`OptimalControlProblem`) against the root finder (`solve_reduced`) cold and
//! warm, and Richardson extrapolation.
//!
//! First the report's planner tables, timed in interleaved rounds as the report times them
//! (`cargo run --release -p retract-validation --example report` prints the same); then the
//! same closures under criterion, one benchmark each (ids `bvp/<solver>/<scene>_N<steps>`).
//! Run: `cargo bench -p retract-validation --bench bvp`.

use std::collections::HashSet;

use criterion::{Criterion, criterion_group, criterion_main};
use retract_validation::planner_speed::{
    self, Measure, against_n, at_400, extrapolation, measure_all, races,
};
use retract_validation::report::Size;
use retract_validation::timing::{Row, Timed};

fn solve(c: &mut Criterion) {
    let size = Size::full();
    let speed =
        measure_all(size.planner_rounds, size.race_rounds).expect("the planner's problems solve");
    planner_speed::write_all(&mut std::io::stdout(), &speed).expect("stdout");
    println!();
    let mut group = c.benchmark_group("bvp");
    group.sample_size(10);
    // a closure timed by two measurements (the SE(2) solve at N = 400) is benched once
    let mut seen = HashSet::new();
    let mut criterion = |closures: &mut [Timed<'_>]| -> Vec<Row> {
        for timed in closures.iter_mut().filter(|t| seen.insert(t.name)) {
            group.bench_function(timed.name, |b| b.iter(|| (timed.run)()));
        }
        Vec::new()
    };
    let measure: Measure<'_> = &mut criterion;
    against_n(measure).expect("solvable");
    at_400(measure).expect("solvable");
    races(measure).expect("solvable");
    extrapolation(measure).expect("solvable");
    group.finish();
}

criterion_group!(benches, solve);
criterion_main!(benches);
