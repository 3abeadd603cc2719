//! Compile-time cost of `#[higher_order_lagrangian]`: expansion time (and, printed once per
//! case, the generated line count) for second-order Lagrangians growing in dimension and in
//! unrolled obstacle terms, and for one long sum (`sum_terms<m>`: an order-1 Lagrangian on R
//! with m terms `c[i] * (q * (i + 1)).sin()` unrolled from a loop, so that the Lagrangian, its
//! gradient and its Hessian are sums of m terms). Run:
//! `cargo bench -p retract-codegen --bench expansion`.
//!
//! The sum-length axis, measured (release build of the same expansion, one run each, shared
//! 2-core machine; `sum_terms` in `cargo bench`'s units):
//!
//! | terms m | 100 | 200 | 400 | 800 | 1000 | 2000 | 5000 | 10 000 | 20 000 |
//! |---|---|---|---|---|---|---|---|---|---|
//! | before (cubic chains) | 37 ms | 100 ms | 385 ms | 2.25 s | | | | | |
//! | now | 37 ms | 84 ms | 161 ms | 0.43 s | 0.36 s | 0.78 s | 1.8 s | 4.3 s | 9.8 s |
//!
//! Linear in m up to the log factor of the balancing heap: about 0.4 ms per term, 0.3 kB of
//! tokens per term in memory (287 MB peak at 10 000 terms, 571 MB at 20 000), where the
//! balancing of each chain used to cost O(m^2) per node of the chain (800 terms: 2.3 s,
//! 1000 terms about a minute in a debug build).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use proc_macro2::TokenStream;
use retract_codegen::samples::obstacle_field;
use retract_codegen::try_expand;

fn lines(n: usize, obstacles: usize) -> usize {
    let (attr, item) = obstacle_field(n, obstacles);
    try_expand(attr, item).map_or(0, |t| {
        syn::parse2::<syn::File>(t).map_or(0, |f| prettyplease::unparse(&f).lines().count())
    })
}

/// An order-1 Lagrangian on R whose value is a sum of `m` terms.
fn long_sum(m: usize) -> (TokenStream, TokenStream) {
    let item = format!(
        "fn long_sum(q: f64, dq: f64, c: [f64; {m}]) -> f64 {{
            let mut l = 0.5 * dq * dq;
            for i in 0..{m} {{ l += c[i] * (q * (i as f64 + 1.0)).sin(); }}
            l
        }}"
    );
    (
        "order = 1".parse().unwrap_or_default(),
        item.parse().unwrap_or_default(),
    )
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

    // one long sum: seconds per case at the end, so few samples
    let mut group = c.benchmark_group("expand");
    group.sample_size(10);
    for m in [10, 100, 1000, 2000, 5000, 10_000] {
        group.bench_function(BenchmarkId::from_parameter(format!("sum_terms{m}")), |b| {
            b.iter(|| {
                let (attr, item) = long_sum(m);
                try_expand(attr, item).is_ok()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, expansion);
criterion_main!(benches);
