//! Compile-time cost of `#[higher_order_lagrangian]`: expansion time (and, printed once per
//! case, the generated line count) for second-order Lagrangians growing in dimension and in
//! unrolled obstacle terms. Run: `cargo bench -p retract-codegen --bench expansion`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use retract_codegen::samples::obstacle_field;
use retract_codegen::try_expand;

fn lines(n: usize, obstacles: usize) -> usize {
    let (attr, item) = obstacle_field(n, obstacles);
    try_expand(attr, item).map_or(0, |t| {
        syn::parse2::<syn::File>(t).map_or(0, |f| prettyplease::unparse(&f).lines().count())
    })
}

fn expansion(c: &mut Criterion) {
    let mut group = c.benchmark_group("expand");
    group.sample_size(10);
    let cases = [(6, 5)]
        .into_iter()
        .chain([1, 2, 3, 6, 9, 12].map(|n| (n, 1)))
        .chain([2, 5, 10, 20, 50].map(|m| (2, m)));
    for (n, obstacles) in cases {
        let name = format!("n{n}_k2_obstacles{obstacles}");
        eprintln!("{name}: {} generated lines", lines(n, obstacles));
        group.bench_function(BenchmarkId::from_parameter(&name), |b| {
            b.iter(|| {
                let (attr, item) = obstacle_field(n, obstacles);
                try_expand(attr, item).is_ok()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, expansion);
criterion_main!(benches);
