//! Limits of the expansion, tested on tokens: long sums expand in quasi-linear time, deep
//! inputs expand to code of bounded nesting, and inputs beyond the documented limits are
//! errors at their span, never an abort. (The work of the
//! chains is counted in `codegen`'s unit tests; a deep case is compiled in the workspace's
//! `tests/integrators/long_recurrence.rs`.)

use std::time::{Duration, Instant};

use proc_macro2::{Delimiter, TokenStream, TokenTree};
use retract_codegen::try_expand;

/// The expansion, or the error messages joined.
fn expand(attr: &str, item: &str) -> Result<TokenStream, String> {
    let attr: TokenStream = attr.parse().expect("attribute tokens");
    let item: TokenStream = item.parse().expect("item tokens");
    try_expand(attr, item).map_err(|e| {
        e.into_iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n")
    })
}

/// Runs `f` on a thread with rustc's 8 MB stack (proc macros run on rustc's main thread; a
/// test thread has 2 MB).
fn on_rustc_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(f)
        .expect("thread")
        .join()
        .expect("no panic")
}

/// Deepest nesting of parentheses in `tokens` (iterative: the input may nest deeply).
fn paren_depth(tokens: TokenStream) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(tokens, 0)];
    while let Some((tokens, depth)) = stack.pop() {
        deepest = deepest.max(depth);
        for tree in tokens {
            if let TokenTree::Group(g) = tree {
                let inner = depth + usize::from(g.delimiter() == Delimiter::Parenthesis);
                stack.push((g.stream(), inner));
            }
        }
    }
    deepest
}

/// An order-1 Lagrangian on R with `body` before `0.5 * dq * dq + tail`.
fn scalar(params: &str, body: &str, tail: &str) -> String {
    format!("fn l(q: f64, dq: f64{params}) -> f64 {{ {body} 0.5 * dq * dq + {tail} }}")
}

#[test]
fn long_sums_expand_in_quasi_linear_time() {
    // a sum of m terms (and its gradient and Hessian, sums of m terms too); the balancing of
    // each chain was cubic in m: 1000 terms took about a minute, 10 000 would take hours
    let time = |m: usize| {
        let body = format!("let mut acc = 0.0; for i in 0..{m} {{ acc += c[i] * q * q; }}");
        let item = scalar(&format!(", c: [f64; {m}]"), &body, "acc");
        let start = Instant::now();
        let out = expand("order = 1", &item).expect("expands");
        let elapsed = start.elapsed();
        assert!(paren_depth(out) <= 66, "m = {m}");
        elapsed
    };
    let small = (0..3).map(|_| time(1000)).min().unwrap_or_default();
    let large = time(10_000);
    eprintln!("1000 terms: {small:?}, 10 000 terms: {large:?}");
    // generous: 10 000 terms take about 1 s in a release build
    assert!(large < Duration::from_secs(60), "10 000 terms: {large:?}");
    // 10x the terms: about 10x the time (m log m); cubic would be 1000x, quadratic 100x
    assert!(
        large < 40 * small + Duration::from_millis(500),
        "{small:?} -> {large:?}"
    );
}

#[test]
fn deep_lets_and_long_recurrences_nest_boundedly() {
    // 1000 chained `let`s, each a few operations on the last: the value of the last inlined
    // into one expression nested about 4 parentheses per `let`, which overflowed rustc's stack
    let mut body = String::from("let a0 = q;");
    for i in 1..=1000 {
        body += &format!("let a{i} = a{} * 0.5 + q.sin() * 0.25;", i - 1);
    }
    let lets = scalar("", &body, "a1000 * a1000");
    // the same as an unrolled loop, 10 000 iterations
    let looped = scalar(
        "",
        "let mut x = q; for _ in 0..10000 { x = x * 0.999 + 0.001 * q.sin(); }",
        "x * x",
    );
    for (name, item) in [("lets", lets), ("loop", looped)] {
        let depth = on_rustc_stack(move || {
            let out = expand("order = 1", &item).expect("expands");
            paren_depth(out)
        });
        // at most MAX_DEPTH + 2 = 66 levels, of which some are not parentheses
        assert!(depth <= 66, "{name}: nesting {depth}");
    }
}

/// The error of an expansion that must fail.
fn error(attr: &str, item: &str) -> String {
    match expand(attr, item) {
        Ok(_) => panic!("expanded: {item}"),
        Err(e) => e,
    }
}

#[test]
fn sizes_beyond_the_limits_are_errors() {
    let jet = |k: usize, n: &str| {
        let args: Vec<String> = (0..=k).map(|o| format!("d{o}: [f64; {n}]")).collect();
        format!(
            "fn l({}) -> f64 {{ 0.5 * d{k}[0] * d{k}[0] }}",
            args.join(", ")
        )
    };
    // dimension: n k <= 64; n = 100 000 aborted with `capacity overflow` / out of memory
    for (k, n) in [
        (1, "65"),
        (2, "33"),
        (3, "22"),
        (4, "17"),
        (1, "100000"),
        (4, "18446744073709551615"),
    ] {
        let e = on_rustc_stack(move || error(&format!("order = {k}"), &jet(k, n)));
        assert!(
            e.contains("dimension too large") && e.contains("n k = 64"),
            "k = {k}, n = {n}: {e}"
        );
    }
    // at the limit, no such error (n = 16 at order 4: 64 unknowns)
    let within = expand("order = 4", &jet(4, "16"));
    assert!(
        within
            .as_ref()
            .err()
            .is_none_or(|e| !e.contains("dimension")),
        "{within:?}"
    );
    // array lengths of parameters and of list elements: at most u32::MAX, whose indices fit
    for ty in ["[f64; 4294967296]", "&[[f64; 4294967296]]"] {
        let e = error("order = 1", &scalar(&format!(", c: {ty}"), "", "q"));
        assert!(
            e.contains("exceeds the supported maximum of 4294967295"),
            "{e}"
        );
    }
    let longest = expand(
        "order = 1",
        &scalar(", c: [f64; 4294967295]", "", "c[4294967294] * q"),
    );
    assert!(longest.is_ok(), "{longest:?}");
    // unrolled counts: a documented maximum of statements; beyond, an error, also where the
    // count overflows usize
    for loops in [
        "for i in 0..1000000000 { acc += q; }",
        "for i in 0..4000000000 { for j in 0..4000000000 { for k in 0..4000000000 { acc += q; } } }",
        "for i in 0..1000 { for j in 0..1000 { acc += q; } }",
    ] {
        let item = scalar("", &format!("let mut acc = 0.0; {loops}"), "acc");
        let e = on_rustc_stack(move || error("order = 1", &item));
        assert!(e.contains("loop too long to unroll"), "{e}");
    }
}

#[test]
fn an_expansion_past_the_node_limit_is_one_error_at_the_name() {
    // 2000 distinct unrolled terms, each a chain of 20 calls in q and dq on R^4 at order 2:
    // the function is about 40 000 nodes, its Hessian in 12 variables tens of millions
    let chain = ".sin().atan2(q[1]).cos().atan2(dq[2]).tanh()".repeat(4);
    let item = format!(
        "fn big(q: [f64; 4], dq: [f64; 4], ddq: [f64; 4]) -> f64 {{ let mut acc = 0.0; \
         for i in 0..2000 {{ acc += (q[0] * (i as f64) + dq[3]){chain}; }} \
         0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1] + ddq[2] * ddq[2] + ddq[3] * ddq[3]) + acc }}"
    );
    let start = Instant::now();
    let (result, stats) = on_rustc_stack(move || {
        let (result, stats) =
            retract_codegen::expansion_stats("order = 2".parse().unwrap(), item.parse().unwrap());
        (
            result
                .map(|_| ())
                .map_err(|e| e.into_iter().collect::<Vec<_>>()),
            stats,
        )
    });
    let elapsed = start.elapsed();
    let errors = result.expect_err("expanded past the limit");
    assert_eq!(errors.len(), 1, "one error: {errors:?}");
    let message = errors[0].to_string();
    assert!(
        message.contains("needs more than 1000000 expression nodes") && message.contains("`big`"),
        "{message}"
    );
    assert!(stats.graph_nodes <= 1_000_000, "{stats:?}");
    // the graph stops at the limit: seconds, where the full expansion took minutes
    assert!(elapsed < Duration::from_secs(60), "{elapsed:?}");
}

/// The work of expanding an order-1 Lagrangian on R^2 ending in `+ tail`, on rustc's stack:
/// graph nodes and the length of the code, or the error messages.
fn work(tail: String) -> Result<(usize, usize), String> {
    on_rustc_stack(move || {
        let item = format!(
            "fn l(q: [f64; 2], dq: [f64; 2]) -> f64 {{ 0.5 * (dq[0] * dq[0] + dq[1] * dq[1]) + {tail} }}"
        );
        let (attr, item) = ("order = 1".parse().unwrap(), item.parse().unwrap());
        let (result, stats) = retract_codegen::expansion_stats(attr, item);
        match result {
            Ok(tokens) => Ok((stats.graph_nodes, tokens.to_string().len())),
            Err(e) => Err(e.into_iter().map(|e| e.to_string()).collect()),
        }
    })
}

/// Asserts that `make(4 m)` costs at most 4.5 times `make(m)` in graph nodes and in code:
/// linear work in the depth or length (quadratic would be 16 times).
fn linear(what: &str, m: usize, make: impl Fn(usize) -> String) {
    let small = work(make(m)).unwrap_or_else(|e| panic!("{what} {m}: {e}"));
    let large = work(make(4 * m)).unwrap_or_else(|e| panic!("{what} {}: {e}", 4 * m));
    let ratio = |a: usize, b: usize| b as f64 / a as f64;
    assert!(
        ratio(small.0, large.0) < 4.5 && ratio(small.1, large.1) < 4.5,
        "{what}: {m} -> {small:?}, {} -> {large:?} (nodes, bytes)",
        4 * m
    );
}

#[test]
fn deep_chains_long_sums_and_products_expand_in_linear_work() {
    // a chain of calls is lowered without recursion (5000 `.sin()` took more than a minute,
    // then were refused past 512 levels); guarded calls quote their argument in constant
    // space (nested `atan2` quoted each argument in full: quadratic code)
    linear("sin chain", 1250, |m| format!("q[0]{}", ".sin()".repeat(m)));
    linear("atan2 chain", 125, |m| {
        format!("q[0]{}", ".atan2(dq[1])".repeat(m))
    });
    linear("sqrt chain", 125, |m| {
        format!("q[0]{}", ".exp().sqrt()".repeat(m))
    });
    // nested in parentheses, within the bracket limit
    let nested = |m: usize| {
        let mut e = String::from("q[0]");
        for _ in 0..m {
            e = format!("({e}).sin().atan2(q[1])");
        }
        e
    };
    linear("nested atan2", 60, nested);
    // a sum is lowered without a level of nesting per term (1000 terms were refused)
    let sum = |m: usize| {
        let terms: Vec<String> = (0..m)
            .map(|i| format!("{}.5 * q[{}] * q[1]", i % 9, i % 2))
            .collect();
        terms.join(" + ")
    };
    linear("sum", 1250, sum);
    let product = |m: usize| {
        let factors: Vec<String> = (0..m).map(|i| format!("(q[{}] + {i}.5)", i % 2)).collect();
        factors.join(" * ")
    };
    linear("product", 250, product);
}

#[test]
fn brackets_nested_past_the_limit_are_one_error() {
    // syn parses nested brackets by recursion: 5000 levels overflowed the stack
    for (what, open, close) in [
        ("parentheses", "(", ").sin()"),
        ("atan2", "f64::atan2(", ", q[1])"),
        ("sums", "(1.0 + ", ")"),
    ] {
        for depth in [257, 5000] {
            let e =
                work(format!("{}q[0]{}", open.repeat(depth), close.repeat(depth))).expect_err(what);
            assert_eq!(
                e.matches("brackets nest deeper than 256 levels").count(),
                1,
                "{what} {depth}: {e}"
            );
        }
        // at the limit (the body's braces and the call's parentheses are two more)
        let e = work(format!("{}q[0]{}", open.repeat(250), close.repeat(250)));
        assert!(e.is_ok(), "{what} 250: {e:?}");
    }
}

#[test]
fn chains_of_five_thousand_operations_expand_with_bounded_nesting() {
    // the derivatives of a long product are sums and products nested in turn as deep as the
    // product is long; the emitter followed them by recursion before cutting the code at its
    // nesting limit, and 5000 factors overflowed rustc's stack
    let chain = |op: &str, m: usize| vec!["q[0]"; m].join(op);
    for op in [" * ", " / ", " + ", " - "] {
        linear(op, 1250, |m| chain(op, m));
        let item = format!(
            "fn l(q: [f64; 2], dq: [f64; 2]) -> f64 {{ 0.5 * (dq[0] * dq[0] + dq[1] * dq[1]) + {} }}",
            chain(op, 5000)
        );
        let depth =
            on_rustc_stack(move || paren_depth(expand("order = 1", &item).expect("expands")));
        assert!(depth <= 66, "{op}: nesting {depth}");
    }
    // the binary functions, chained as methods
    for call in [".hypot(q[1])", ".powf(2.5)", ".atan2(q[1])"] {
        linear(call, 250, |m| format!("q[0]{}", call.repeat(m)));
    }
}
