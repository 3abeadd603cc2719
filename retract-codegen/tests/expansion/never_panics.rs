//! The expansion never panics: random token streams and mutated valid Lagrangians all end
//! in an expansion or a `syn::Error` (a `compile_error!` in the output).

use std::panic::{AssertUnwindSafe, catch_unwind};

use proc_macro2::TokenStream;
use proptest::prelude::*;
use retract_codegen::{expand, try_expand};

const ALPHABET: &[&str] = &[
    "q",
    "dq",
    "ddq",
    "tau",
    "o",
    "obstacles",
    "x",
    "i",
    "N",
    "f64",
    "usize",
    "fn",
    "let",
    "mut",
    "for",
    "in",
    "if",
    "else",
    "while",
    "loop",
    "match",
    "return",
    "const",
    "powi",
    "powf",
    "sqrt",
    "ln",
    "exp",
    "atan2",
    "hypot",
    "recip",
    "abs",
    "norm",
    "iter",
    "as",
    "+",
    "-",
    "*",
    "/",
    "=",
    "+=",
    "-=",
    "*=",
    "/=",
    "==",
    ";",
    ",",
    ".",
    ":",
    "::",
    "&",
    "->",
    "..",
    "..=",
    "|",
    "!",
    "[",
    "]",
    "(",
    ")",
    "{",
    "}",
    "0",
    "1",
    "2",
    "3",
    "0.5",
    "2.0",
    "1e-3",
    "-1",
    "99999999999999999999",
    "1e400",
    "'a",
    "\"s\"",
    "true",
];

const VALID: &[(&str, &str)] = &[
    (
        "order = 2",
        "fn barrier(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 { 0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0) }",
    ),
    (
        "order = 2",
        "fn scene(q: [f64; 3], dq: [f64; 3], ddq: [f64; 3], tau: f64, obstacles: &[[f64; 3]]) -> f64 { let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2)); for o in obstacles { l += tau / ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]); } l }",
    ),
    (
        "order = 1",
        "fn osc(q: f64, dq: f64, w: f64) -> f64 { const K: usize = 2; let mut e = 0.5 * dq * dq; for i in 0..K { e -= 0.25 * w * q.powi(2) * (i as f64 + 1.0) / 1.5; } e + q.sin().atan2(q.cos().exp()) + q.hypot(dq).sqrt() }",
    ),
    (
        "order = 3",
        "fn jerk(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], dddq: [f64; 2], c: [f64; 2]) -> f64 { 0.5 * (dddq[0].powi(2) + dddq[1].powi(2)) + c[0] * q[0].ln() + c[1] * q[1].powf(1.5) }",
    ),
];

/// Expands and checks that nothing panicked; returns whether the expansion succeeded.
fn expands(attr: &str, item: &str) -> Option<bool> {
    let (Ok(attr_tokens), Ok(item_tokens)) =
        (attr.parse::<TokenStream>(), item.parse::<TokenStream>())
    else {
        return None; // not a token stream (unbalanced delimiters): nothing to expand
    };
    let result = catch_unwind(AssertUnwindSafe(|| {
        let tokens = expand(attr_tokens.clone(), item_tokens.clone());
        let ok = try_expand(attr_tokens, item_tokens).is_ok();
        let text = tokens.to_string();
        assert!(
            ok || text.contains("compile_error"),
            "an error must surface: {text}"
        );
        ok
    }));
    match result {
        Ok(ok) => Some(ok),
        Err(_) => panic!("the expansion panicked on #[higher_order_lagrangian({attr})] {item}"),
    }
}

fn tokens(max: usize) -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(ALPHABET), 0..max).prop_map(|t| t.join(" "))
}

/// A valid Lagrangian with one token deleted, duplicated or replaced.
fn mutated() -> impl Strategy<Value = (String, String)> {
    (
        0..VALID.len(),
        any::<prop::sample::Index>(),
        0..3u8,
        prop::sample::select(ALPHABET),
    )
        .prop_map(|(which, at, how, replacement)| {
            let (attr, item) = VALID[which];
            let mut parts: Vec<String> = item
                .replace('(', " ( ")
                .replace(')', " ) ")
                .replace('[', " [ ")
                .replace(']', " ] ")
                .replace(';', " ; ")
                .replace(',', " , ")
                .split_whitespace()
                .map(String::from)
                .collect();
            let i = at.index(parts.len());
            match how {
                0 => {
                    parts.remove(i);
                }
                1 => {
                    let t = parts[i].clone();
                    parts.insert(i, t);
                }
                _ => parts[i] = replacement.to_string(),
            }
            (attr.to_string(), parts.join(" "))
        })
}

#[test]
fn valid_inputs_expand() {
    for (attr, item) in VALID {
        assert_eq!(expands(attr, item), Some(true), "{item}");
    }
}

#[test]
fn non_finite_constants_never_panic() {
    // found by `mutated_lagrangians`: an infinite weight on |q''|^2 made the compile-time
    // Legendre inverse NaN, whose literal panicked
    let j = "q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]";
    for body in [
        "1e400 * (ddq[0].powi(2) + ddq[1].powi(2))",
        "(0.0 * 1e400) * ddq[0].powi(2) + ddq[1].powi(2)",
        "ddq[0].powi(2) + ddq[1].powi(2) + 1e400 * q[0]",
        "ddq[0].powi(2) + ddq[1].powi(2) + (-1.0f64).sqrt() * q[0] + 1e-400 / 0.0",
        "(1e300 * 1e300) * ddq[0] * ddq[0] + ddq[1].powi(2)",
    ] {
        assert!(expands("order = 2", &format!("fn l({j}) -> f64 {{ {body} }}")).is_some());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn random_token_streams(attr in tokens(6), item in tokens(40)) {
        expands(&attr, &item);
        expands("order = 2", &format!("fn l(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {{ {item} }}"));
    }

    #[test]
    fn mutated_lagrangians((attr, item) in mutated()) {
        expands(&attr, &item);
    }
}
