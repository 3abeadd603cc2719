//! A grammar-based fuzzer. It generates Lagrangians from the documented
//! syntax (docs/guide.md, "What a Lagrangian may contain": jets of order 1 to 3, scalar and array
//! jets, `f64`, array and slice parameters, nesting, long sums, `const`s, `let` and `let mut`
//! with every compound assignment, unrolled and run-time loops, every supported method in
//! both call forms, extreme literals, odd names) plus a share of unsupported constructs, and
//! asserts that every one ends in an expansion or a `compile_error!`, never a panic, with
//! the work bounded in expression-graph nodes (`expansion_stats`), not wall time.
//!
//! Each run takes `CASES` cases from a fixed seed and `CASES` from a random one (printed; set
//! `RETRACT_FUZZ_SEED` to replay it, `RETRACT_FUZZ_CASES` for more cases per seed,
//! `RETRACT_FUZZ_SHOW=<case>` to print one case's source). The
//! generated bodies include helper fns (some recursive: an error) and deep nesting. A sample of well-behaved Lagrangians from the fixed
//! seed is compiled in the workspace's `tests/integrators/fuzz_corpus.rs`, whose derivatives are checked
//! against finite differences there; `the_compiled_corpus_is_the_fixed_seed_sample`
//! keeps that file equal to what the generator makes (`RETRACT_BLESS_CORPUS=1` rewrites it).

use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};

use proc_macro2::TokenStream;
use retract_codegen::{ExpansionStats, expand, expansion_stats};

/// Cases per seed (two seeds per run: 2000 cases); `RETRACT_FUZZ_CASES` sets another count
/// per seed (the long run: `RETRACT_FUZZ_CASES=5000 cargo test -p retract-codegen --test
/// expansion grammar_fuzz`, 10 000 cases).
const CASES: usize = 1000;

/// The cases per seed of this run.
fn cases() -> usize {
    std::env::var("RETRACT_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(CASES)
}
/// The case that `RETRACT_FUZZ_SHOW` names, if any: its source is printed.
fn show_case() -> Option<usize> {
    std::env::var("RETRACT_FUZZ_SHOW").ok()?.parse().ok()
}
const FIXED_SEED: u64 = 0x5eed_0014_0010;
/// Compiled sample size.
const CORPUS: usize = 20;

/// Work bound per case: graph nodes at most this many times the lowered nodes times the
/// number of Hessian entries (the derivatives of one node cost a bounded number of nodes per
/// entry), plus a constant.
const NODES_PER_LOWERED_ENTRY: usize = 12;
const NODES_SLACK: usize = 20_000;
/// Work bound of a whole run of `CASES` cases, in graph nodes.
const NODES_PER_RUN: usize = 5_000_000;

/// splitmix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64 <= p
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
    /// A moderate literal in [lo, hi), two decimals.
    fn moderate(&mut self, lo: f64, hi: f64) -> String {
        let v = lo + (hi - lo) * self.below(1000) as f64 / 1000.0;
        format!("{v:.2}")
    }
}

const EXTREME: &[&str] = &[
    "0.0",
    "1.0",
    "2",
    "0.5",
    "3.25",
    "1e-300",
    "5e-324",
    "1e300",
    "1.7976931348623157e308",
    "1e400",
    "123456789012345678901234567890.0",
    "0.1e1",
    "1_000.0",
    "2.0f64",
];

const ODD_JET: &[&[&str]] = &[
    &["q", "dq", "ddq", "dddq"],
    &["x", "v", "a", "j"],
    &["_q", "_dq", "_ddq", "_dddq"],
    &["ψ", "ψ1", "ψ2", "ψ3"],
    &["q_", "dq_", "ddq_", "dddq_"],
    &["r#in", "r#fn", "r#do", "r#as"],
    &["q", "q", "ddq", "dddq"],
];

const UNARY: &[&str] = &[
    "sqrt", "exp", "ln", "sin", "cos", "tan", "tanh", "recip", "abs",
];
const BINARY: &[&str] = &["powi", "powf", "atan2", "hypot"];

const UNSUPPORTED: &[&str] = &[
    "if q0 > 0.0 { 1.0 } else { 2.0 }",
    "q0.norm()",
    "helper(q0)",
    "q0.max(1.0)",
    "(|t: f64| t)(q0)",
    "match 1 { _ => 1.0 }",
    "1u8",
    "q0 % 2.0",
    "!q0",
    "q0.powi(2147483647).powi(2)",
    "q0.powi(-2147483648)",
    "q0.powi(99999999999)",
    "q0.powf(q0)",
    "JET[3]",
    "\"s\"",
    "q0.sqrt(1.0)",
    "f64::consts::PI",
    "core::f64::consts::PI * q0",
    "std::f64::consts::E",
];

/// What a generated Lagrangian may refer to.
struct Scope {
    /// n = 0: a scalar jet (`q: f64`).
    n: usize,
    k: usize,
    jet: Vec<String>,
    scalars: Vec<String>,
    arrays: Vec<(String, usize)>,
    slices: Vec<(String, usize)>,
    consts: Vec<String>,
    lets: Vec<String>,
    /// Loop variable of an unrolled loop (as `i as f64`) and slice element in scope.
    index: Option<String>,
    element: Option<(String, usize)>,
    /// Corpus mode: only expressions that are smooth everywhere and of moderate size.
    smooth: bool,
}

impl Scope {
    fn jet_component(&self, rng: &mut Rng, order: usize) -> String {
        let name = &self.jet[order];
        if self.n == 0 {
            name.clone()
        } else {
            // mostly in range, sometimes past the end (an error)
            let i = if !self.smooth && rng.chance(0.01) {
                self.n + rng.below(3)
            } else {
                rng.below(self.n)
            };
            format!("{name}[{i}]")
        }
    }

    fn literal(&self, rng: &mut Rng) -> String {
        if self.smooth || rng.chance(0.6) {
            rng.moderate(-2.0, 2.0).replace('-', "")
        } else {
            rng.pick(EXTREME).to_string()
        }
    }

    fn leaf(&self, rng: &mut Rng) -> String {
        let order = rng.below(self.k);
        match rng.below(10) {
            0..=3 => self.jet_component(rng, order),
            4 if !self.scalars.is_empty() => rng.pick(&self.scalars).clone(),
            5 if !self.arrays.is_empty() => {
                let (name, len) = rng.pick(&self.arrays);
                format!("{name}[{}]", rng.below(*len))
            }
            6 if !self.lets.is_empty() => rng.pick(&self.lets).clone(),
            7 if self.index.is_some() => format!("({} as f64)", self.index.as_ref().unwrap()),
            8 if self.element.is_some() => {
                let (name, len) = self.element.as_ref().unwrap();
                format!("{name}[{}]", rng.below(*len))
            }
            9 if !self.consts.is_empty() => rng.pick(&self.consts).clone(),
            _ => self.literal(rng),
        }
    }

    /// An expression of nesting depth at most `depth`.
    fn expr(&self, rng: &mut Rng, depth: usize) -> String {
        if depth == 0 || rng.chance(0.25) {
            return self.leaf(rng);
        }
        if self.smooth {
            return self.smooth_expr(rng, depth);
        }
        let d = depth - 1;
        match rng.below(12) {
            0 => format!("{} + {}", self.expr(rng, d), self.expr(rng, d)),
            1 => format!("{} - ({})", self.expr(rng, d), self.expr(rng, d)),
            2 => format!("({}) * ({})", self.expr(rng, d), self.expr(rng, d)),
            3 => format!("({}) / ({})", self.expr(rng, d), self.expr(rng, d)),
            4 => format!("-({})", self.expr(rng, d)),
            5 | 6 => {
                let m = rng.pick(UNARY);
                if rng.chance(0.3) {
                    format!("f64::{m}({})", self.expr(rng, d))
                } else {
                    format!("({}).{m}()", self.expr(rng, d))
                }
            }
            7 | 8 => self.binary_method(rng, d),
            9 if rng.chance(0.3) => self.long_sum(rng),
            9 if rng.chance(0.05) => self.deep(rng),
            9 if rng.chance(0.1) && !self.smooth => format!("h0({})", self.expr(rng, d)),
            10 if rng.chance(0.1) => rng.pick(UNSUPPORTED).replace("q0", &self.leaf(rng)),
            _ => format!("(({}))", self.expr(rng, d)),
        }
    }

    fn binary_method(&self, rng: &mut Rng, d: usize) -> String {
        let m = rng.pick(BINARY);
        let x = self.expr(rng, d);
        let arg = match *m {
            "powi" => {
                let e: i64 = *rng.pick(&[-3, -2, -1, 0, 1, 2, 3, 4, 7, 64, i32::MAX as i64]);
                if rng.chance(0.2) && !self.consts.is_empty() {
                    "N_I".to_string()
                } else {
                    e.to_string()
                }
            }
            "powf" => {
                if rng.chance(0.5) {
                    rng.pick(&["0.5", "1.5", "-0.5", "-2.0", "2.0", "3.0", "0.0", "1e400"])
                        .to_string()
                } else {
                    self.non_jet(rng)
                }
            }
            _ => self.expr(rng, d),
        };
        if rng.chance(0.3) {
            format!("f64::{m}({x}, {arg})")
        } else {
            format!("({x}).{m}({arg})")
        }
    }

    /// An expression without the jet (a `powf` exponent).
    fn non_jet(&self, rng: &mut Rng) -> String {
        match rng.below(3) {
            0 if !self.scalars.is_empty() => rng.pick(&self.scalars).clone(),
            1 if !self.arrays.is_empty() => format!("{}[0]", rng.pick(&self.arrays).0),
            _ => rng.moderate(0.5, 3.0),
        }
    }

    fn long_sum(&self, rng: &mut Rng) -> String {
        let terms = 20 + rng.below(280);
        let mut out = String::from("(0.0");
        for t in 0..terms {
            let _ = write!(out, " + {}.{t} * {}", t % 7, self.leaf(rng));
        }
        out.push(')');
        out
    }

    /// Deep nesting: a chain of up to 300 calls, brackets nested up to 150 levels, or a
    /// product of up to 300 factors (deeper cases, and brackets past the limit, are tested in
    /// `expansion_limits`).
    fn deep(&self, rng: &mut Rng) -> String {
        let m = 1 + rng.below(300);
        let x = self.leaf(rng);
        match rng.below(3) {
            0 => {
                let calls: Vec<String> = (0..m)
                    .map(|_| match rng.below(3) {
                        0 => format!(".atan2({})", self.leaf(rng)),
                        _ => format!(".{}()", rng.pick(&["sin", "cos", "tanh"])),
                    })
                    .collect();
                format!("{x}{}", calls.concat())
            }
            1 => {
                let m = m / 2;
                format!("{}{x}{}", "(".repeat(m), ").sin()".repeat(m))
            }
            _ => {
                let factors: Vec<String> = (0..m)
                    .map(|_| format!("(1.0 + 0.01 * {})", self.leaf(rng)))
                    .collect();
                factors.join(" * ")
            }
        }
    }

    /// Smooth everywhere: every singular operation gets an argument bounded away from its
    /// singular set.
    fn smooth_expr(&self, rng: &mut Rng, depth: usize) -> String {
        let d = depth - 1;
        let a = self.expr(rng, d);
        let b = self.expr(rng, d);
        let c = rng.moderate(0.2, 1.5);
        match rng.below(16) {
            0 => format!("{a} + {b}"),
            1 => format!("{a} - ({b})"),
            2 => format!("({a}) * ({b})"),
            3 => format!("({a}) / (1.5 + ({b}).cos())"),
            4 => format!("-({a})"),
            5 => format!("(1.0 + ({a}).powi(2)).sqrt()"),
            6 => format!("(0.5 * ({a}).sin()).exp()"),
            7 => format!("f64::ln(2.0 + ({a}).sin())"),
            8 => format!("({a}).sin() * {c}"),
            9 => format!("(0.5 * ({a}).tanh()).tan() + ({b}).cos()"),
            10 => format!("(2.0 + ({a}).tanh()).recip()"),
            11 => format!("({a}).powi({})", rng.pick(&[1, 2, 3])),
            12 => format!("(1.0 + ({a}) * ({a})).powf({c})"),
            13 => format!("({a}).atan2(2.0 + ({b}).cos())"),
            14 => format!("f64::hypot({a}, 1.0 + ({b}).powi(2))"),
            _ => format!("(1.0 + 0.5 * ({a}).sin()).abs() * ({b})"),
        }
    }
}

/// A generated Lagrangian: attribute, item, and (corpus mode) the parameter values.
struct Case {
    attr: String,
    item: String,
    n: usize,
    k: usize,
    /// `Name { field: value, .. }` initialiser fields.
    fields: Vec<String>,
}

fn signature(rng: &mut Rng, smooth: bool, name: &str) -> (Scope, String, Vec<String>) {
    let k = 1 + rng.below(if smooth { 2 } else { 3 });
    let n = if smooth { rng.below(3) } else { rng.below(5) };
    let names: &[&str] = if smooth {
        ODD_JET[0]
    } else {
        ODD_JET[rng.below(ODD_JET.len())]
    };
    let jet: Vec<String> = names[..=k].iter().map(|s| s.to_string()).collect();
    let ty = if n == 0 {
        "f64".to_string()
    } else {
        format!("[f64; {n}]")
    };
    let mut args: Vec<String> = jet.iter().map(|j| format!("{j}: {ty}")).collect();
    let mut scope = Scope {
        n,
        k,
        jet,
        scalars: Vec::new(),
        arrays: Vec::new(),
        slices: Vec::new(),
        consts: Vec::new(),
        lets: Vec::new(),
        index: None,
        element: None,
        smooth,
    };
    let mut fields = Vec::new();
    for p in 0..rng.below(4) {
        match rng.below(3) {
            0 => {
                let name = format!("a{p}");
                args.push(format!("{name}: f64"));
                fields.push(format!("{name}: {}", rng.moderate(0.3, 1.3)));
                scope.scalars.push(name);
            }
            1 => {
                let len = 1 + rng.below(3);
                let name = format!("c{p}");
                args.push(format!("{name}: [f64; {len}]"));
                let values: Vec<String> = (0..len).map(|_| rng.moderate(-1.0, 1.0)).collect();
                fields.push(format!("{name}: [{}]", values.join(", ")));
                scope.arrays.push((name, len));
            }
            _ => {
                let len = 1 + rng.below(3);
                let name = format!("obs{p}");
                args.push(format!("{name}: &[[f64; {len}]]"));
                let row = |rng: &mut Rng| {
                    let v: Vec<String> = (0..len).map(|_| rng.moderate(-1.0, 1.0)).collect();
                    format!("[{}]", v.join(", "))
                };
                let rows = [row(rng), row(rng)];
                fields.push(format!("{name}: &[{}]", rows.join(", ")));
                scope.slices.push((name, len));
            }
        }
    }
    let head = format!("fn {name}({}) -> f64", args.join(", "));
    (scope, head, fields)
}

/// `0.5 * sum_i w_i (q^(k)_i)^2`: the Lagrangian's convex part in the top derivative.
fn kinetic(scope: &Scope, rng: &mut Rng) -> String {
    let top = &scope.jet[scope.k];
    let terms: Vec<String> = if scope.n == 0 {
        vec![format!("{top} * {top}")]
    } else {
        (0..scope.n)
            .map(|i| format!("{} * {top}[{i}].powi(2)", rng.moderate(0.5, 2.0)))
            .collect()
    };
    format!("0.5 * ({})", terms.join(" + "))
}

/// The body: consts, lets, compound assignments, loops, and the returned expression.
fn body(scope: &mut Scope, rng: &mut Rng) -> String {
    let depth = if scope.smooth { 3 } else { 5 };
    let mut out = String::new();
    if !scope.smooth {
        // a helper fn, called by `h0(..)` (and calling another, or itself: an error)
        let inner = *rng.pick(&["x.sin() * 0.5 + x", "h1(x) * x", "h0(x) + 1.0", "x * x"]);
        let _ = write!(
            out,
            "fn h1(y: f64) -> f64 {{ y.cos() + y }} fn h0(x: f64) -> f64 {{ {inner} }} "
        );
    }
    if rng.chance(0.3) {
        out.push_str("const N_I: i32 = 2; const C_0: f64 = 1.25; ");
        scope.consts.push("C_0".into());
    }
    for l in 0..rng.below(4) {
        let name = format!("t{l}");
        let _ = write!(out, "let {name} = {}; ", scope.expr(rng, depth));
        scope.lets.push(name);
    }
    out.push_str("let mut acc = 0.0; ");
    for _ in 0..rng.below(4) {
        let op = if scope.smooth {
            *rng.pick(&["+=", "-=", "*="])
        } else {
            *rng.pick(&["+=", "-=", "*=", "/=", "="])
        };
        let _ = write!(out, "acc {op} {}; ", scope.expr(rng, depth - 1));
    }
    if rng.chance(0.5) {
        let count = if scope.smooth {
            1 + rng.below(4)
        } else {
            *rng.pick(&[0, 1, 3, 8, 40])
        };
        let nested = !scope.smooth && rng.chance(0.2);
        scope.index = Some("i".into());
        let inner = scope.expr(rng, depth - 2);
        let inner = if nested {
            format!("for j in 0..2 {{ acc += ({inner}) * (j as f64); }}")
        } else {
            format!("acc += {inner};")
        };
        let _ = write!(out, "for i in 0..{count} {{ {inner} }} ");
        scope.index = None;
    }
    if let Some((name, len)) = scope.slices.first().cloned() {
        scope.element = Some(("o".into(), len));
        let op = *rng.pick(&["+=", "-="]);
        let _ = write!(
            out,
            "for o in {name} {{ acc {op} {}; }} ",
            scope.expr(rng, depth - 2)
        );
        scope.element = None;
    }
    let kin = kinetic(scope, rng);
    let tail = scope.expr(rng, depth);
    let _ = write!(out, "{kin} + acc + {tail}");
    out
}

fn generate(rng: &mut Rng, smooth: bool, name: &str) -> Case {
    let (mut scope, head, fields) = signature(rng, smooth, name);
    let body = body(&mut scope, rng);
    let mut attr = format!("order = {}", scope.k);
    if !smooth && rng.chance(0.05) {
        attr = rng
            .pick(&[
                "order = 0",
                "order = 9",
                "order = 2, guard = false",
                "",
                "order",
            ])
            .to_string();
    }
    Case {
        attr,
        item: format!("{head} {{ {body} }}"),
        n: scope.n,
        k: scope.k,
        fields,
    }
}

/// Expands `case`, asserting no panic, an error surfacing as `compile_error!`, and the work
/// bound; returns whether it expanded and its statistics.
fn check_case(case: &Case, seed: u64, index: usize) -> (bool, ExpansionStats) {
    let (Ok(attr), Ok(item)) = (
        case.attr.parse::<TokenStream>(),
        case.item.parse::<TokenStream>(),
    ) else {
        return (false, ExpansionStats::default());
    };
    let run = catch_unwind(AssertUnwindSafe(|| {
        let (result, stats) = expansion_stats(attr.clone(), item.clone());
        let ok = result.is_ok();
        if !ok {
            let text = expand(attr, item).to_string();
            assert!(text.contains("compile_error"), "no error surfaced");
        }
        (ok, stats)
    }));
    let Ok((ok, stats)) = run else {
        panic!(
            "seed {seed:#x}, case {index}: the expansion panicked on \
             #[higher_order_lagrangian({})] {}",
            case.attr, case.item
        );
    };
    let m = case.n.max(1) * (case.k + 1);
    let bound = NODES_PER_LOWERED_ENTRY * stats.lowered_nodes * (m * m + 1) + NODES_SLACK;
    assert!(
        stats.graph_nodes <= bound,
        "seed {seed:#x}, case {index}: {} graph nodes > bound {bound} ({stats:?}): {}",
        stats.graph_nodes,
        case.item
    );
    (ok, stats)
}

/// Runs `CASES` cases from `seed`; returns (expanded, total graph nodes).
fn run(seed: u64) -> (usize, usize) {
    let cases = cases();
    let mut rng = Rng(seed);
    let (mut slowest, mut slowest_case, mut over_10s) = (std::time::Duration::ZERO, 0, 0);
    let (mut expanded, mut nodes, mut largest, mut ratio) = (0, 0, 0, 0.0_f64);
    for i in 0..cases {
        let smooth = rng.chance(0.2);
        let case = generate(&mut rng, smooth, &format!("l{i}"));
        if show_case() == Some(i) {
            println!(
                "case {i}: #[higher_order_lagrangian({})] {}",
                case.attr, case.item
            );
        }
        let start = std::time::Instant::now();
        let (ok, stats) = check_case(&case, seed, i);
        let elapsed = start.elapsed();
        if elapsed > slowest {
            (slowest, slowest_case) = (elapsed, i);
        }
        if elapsed.as_secs() >= 5 {
            println!(
                "seed {seed:#x}, case {i}: {elapsed:?} ({} graph nodes)",
                stats.graph_nodes
            );
        }
        over_10s += usize::from(elapsed.as_secs() >= 10);
        expanded += usize::from(ok);
        nodes += stats.graph_nodes;
        largest = largest.max(stats.graph_nodes);
        let m = case.n.max(1) * (case.k + 1);
        let per = stats.graph_nodes as f64 / ((stats.lowered_nodes * (m * m + 1)).max(1)) as f64;
        ratio = ratio.max(per);
    }
    println!(
        "seed {seed:#x}: {cases} cases, {expanded} expanded, {nodes} graph nodes in all, \
         largest {largest}, at most {ratio:.2} nodes per lowered node and Hessian entry, \
         slowest case {slowest:?} (case {slowest_case}), {over_10s} cases over 10 s"
    );
    assert!(
        nodes <= NODES_PER_RUN * cases / CASES,
        "seed {seed:#x}: {nodes} graph nodes > {NODES_PER_RUN}"
    );
    (expanded, nodes)
}

#[test]
fn fuzzed_lagrangians_of_the_fixed_seed_expand_or_error_without_panic() {
    let (expanded, _) = run(FIXED_SEED);
    // the generator must exercise the expansion, not only the error paths
    assert!(
        expanded >= cases() / 5,
        "only {expanded} of {} cases expanded",
        cases()
    );
}

#[test]
fn fuzzed_lagrangians_of_a_random_seed_expand_or_error_without_panic() {
    let seed = match std::env::var("RETRACT_FUZZ_SEED") {
        Ok(s) => u64::from_str_radix(s.trim_start_matches("0x"), 16).expect("a hex seed"),
        Err(_) => std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(1, |d| d.as_nanos() as u64),
    };
    println!("random seed {seed:#x} (replay with RETRACT_FUZZ_SEED={seed:x})");
    run(seed);
}

/// The corpus section of `tests/integrators/fuzz_corpus.rs`: the first `CORPUS` smooth Lagrangians of
/// the fixed seed that expand, and one derivative check per Lagrangian.
fn corpus() -> String {
    let mut rng = Rng(FIXED_SEED ^ 0xc0de);
    let (mut items, mut checks) = (String::new(), String::new());
    let mut found = 0;
    for i in 0.. {
        if found == CORPUS {
            break;
        }
        assert!(i < 100 * CORPUS, "too few smooth cases expand");
        let name = format!("fuzz_{found}");
        let case = generate(&mut rng, true, &name);
        let (attr, item) = (case.attr.parse().unwrap(), case.item.parse().unwrap());
        if expansion_stats(attr, item).0.is_err() {
            continue;
        }
        let _ = writeln!(
            items,
            "#[higher_order_lagrangian({})]\n{}\n",
            case.attr, case.item
        );
        let ty = format!("Fuzz{found}");
        let _ = writeln!(
            checks,
            "    check::<_, {}, {}>(\"{name}\", &{ty} {{ {} }});",
            case.n.max(1),
            case.k,
            case.fields.join(", ")
        );
        found += 1;
    }
    format!("{items}pub fn corpus_checks() {{\n{checks}}}\n")
}

const BEGIN: &str =
    "// ---- BEGIN GENERATED (retract-codegen/tests/expansion/grammar_fuzz.rs) ----\n";
const END: &str = "// ---- END GENERATED ----\n";

#[test]
fn the_compiled_corpus_is_the_fixed_seed_sample() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/integrators/fuzz_corpus.rs"
    );
    let text = std::fs::read_to_string(path).expect("tests/integrators/fuzz_corpus.rs");
    let (Some(start), Some(end)) = (text.find(BEGIN), text.find(END)) else {
        panic!("markers missing in {path}");
    };
    let want = corpus();
    let have = &text[start + BEGIN.len()..end];
    if have != want {
        if std::env::var_os("RETRACT_BLESS_CORPUS").is_some() {
            let new = format!("{}{BEGIN}{want}{}", &text[..start], &text[end..]);
            std::fs::write(path, new).expect("write the corpus");
        } else {
            panic!(
                "tests/integrators/fuzz_corpus.rs is not the fixed-seed sample; regenerate it with \
                 RETRACT_BLESS_CORPUS=1 cargo test -p retract-codegen --test expansion"
            );
        }
    }
}
