//! Extreme inputs to the macro, tested on the expansion: each input ends in correct code or
//! in an error at its span, never in a panic, a hang or a silently wrong derivative. (The
//! compiled behaviour is checked in the workspace's `tests/integrators/macro_robustness.rs`,
//! `validation/tests/properties/derivatives.rs` and `ui/tests/ui`.)

use proc_macro2::TokenStream;
use retract_codegen::{try_expand, try_expand_jet_function};

/// The expansion as text, or the error messages joined.
fn expand(attr: &str, item: &str) -> Result<String, String> {
    let attr: TokenStream = attr.parse().expect("attribute tokens");
    let item: TokenStream = item.parse().expect("item tokens");
    try_expand(attr, item)
        .map(|tokens| tokens.to_string())
        .map_err(|e| {
            e.into_iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>()
                .join("\n")
        })
}

/// An order-1 Lagrangian on R with `body` before `0.5 * dq * dq + acc`.
fn scalar(body: &str) -> String {
    format!("fn l(q: f64, dq: f64) -> f64 {{ let mut acc = 0.0; {body} 0.5 * dq * dq + acc }}")
}

/// The body of the generated `fn lagrangian`, as token text.
fn lagrangian_body(expansion: &str) -> &str {
    let start = expansion.find("fn lagrangian").expect("fn lagrangian");
    let end = expansion[start..].find("fn gradient").expect("fn gradient");
    &expansion[start..start + end]
}

#[test]
fn dimension_seven_and_more_builds_the_closed_form_inverse_from_an_array() {
    // constant weights on the top derivative: the Legendre inverse is closed-form, and its
    // vector is built from an array (nalgebra's `SVector::new` exists only for n <= 6)
    for n in [6, 7, 12, 24] {
        let item = format!(
            "fn l(q: [f64; {n}], dq: [f64; {n}]) -> f64 {{
                let mut l = 0.0;
                for i in 0..{n} {{ l += 0.5 * (i as f64 + 1.0) * dq[i].powi(2) - q[i].cos(); }}
                l
            }}"
        );
        let out = expand("order = 1", &item).unwrap();
        let start = out
            .find("fn top_derivative")
            .expect("closed-form Legendre inverse");
        let body = &out[start + 2..];
        let body = &body[..body.find("fn ").unwrap_or(body.len())];
        assert!(
            !body.contains(":: new (") && body.contains(":: from ([0.0 +"),
            "n = {n}: {body}"
        );
    }
}

#[test]
fn a_function_name_that_makes_no_type_name_is_an_error_unless_named() {
    for name in ["_1", "_2d_arm", "self_", "_self", "__7"] {
        let item = format!("fn {name}(q: f64, dq: f64) -> f64 {{ 0.5 * dq * dq }}");
        let err = expand("order = 1", &item).unwrap_err();
        assert!(
            err.contains("is not a valid type name")
                && err.contains("(order = k, name = TypeName)"),
            "`{name}`: {err}"
        );
        // an explicit name is the way out
        let out = expand("order = 1, name = Named", &item).unwrap();
        assert!(out.contains("struct Named"), "`{name}`");
        // the same for #[jet_function]
        let jet = try_expand_jet_function("order = 1".parse().unwrap(), item.parse().unwrap())
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(
            jet.contains("#[jet_function(order = k, name = TypeName)]"),
            "{jet}"
        );
    }
    // names that camel-case to an identifier still work, keywords included
    for (name, ty) in [
        ("arm_2d", "Arm2d"),
        ("r#type", "Type"),
        ("self_test", "SelfTest"),
    ] {
        let item = format!("fn {name}(q: f64, dq: f64) -> f64 {{ 0.5 * dq * dq }}");
        let out = expand("order = 1", &item).unwrap();
        assert!(out.contains(&format!("struct {ty}")), "`{name}`");
    }
}

#[test]
fn integers_at_the_ends_of_i32_and_i64_are_exact_or_errors_never_wrapped() {
    // the derivative of x^i32::MIN is i32::MIN x^(i32::MIN - 1): no overflow, and no
    // wrapped exponent (powi(2147483647)) in the gradient
    let out = expand("order = 1", &scalar("acc += q.powi(-2147483648);")).unwrap();
    assert!(!out.contains("2147483647i32"), "{out}");
    let out = expand("order = 1", &scalar("acc += q.powi(-2147483647 - 1);")).unwrap();
    assert!(!out.contains("2147483647i32"), "{out}");
    // exponents outside i32 and integers outside i64 are errors
    let err = expand("order = 1", &scalar("acc += q.powi(2147483648);")).unwrap_err();
    assert!(err.contains("exponent out of range"), "{err}");
    let err = expand(
        "order = 1",
        &scalar("acc += q.powi(9223372036854775807 + 1);"),
    )
    .unwrap_err();
    assert!(err.contains("integer overflow"), "{err}");
    let err = expand(
        "order = 1",
        &scalar("acc += q[-(-9223372036854775807 - 1)];"),
    )
    .unwrap_err();
    assert!(err.contains("integer overflow"), "{err}");
    // loops whose bounds reach the ends of i64: the right number of iterations, or "too long"
    // (neither a dropped loop nor one that runs for 2^64 iterations)
    let near_max = "for i in 9223372036854775805..=9223372036854775807 { acc += 1.0; }";
    let body = expand("order = 1", &scalar(near_max)).unwrap();
    assert!(lagrangian_body(&body).contains("3f64"), "{body}");
    let near_min = "for i in -9223372036854775808..-9223372036854775806 { acc += 1.0; }";
    let body = expand("order = 1", &scalar(near_min)).unwrap();
    assert!(lagrangian_body(&body).contains("2f64"), "{body}");
    for range in [
        "0..=9223372036854775807",
        "-9223372036854775808..9223372036854775807",
        "(-9223372036854775807 - 1)..=9223372036854775807",
        "-9223372036854775808..0",
    ] {
        let err = expand(
            "order = 1",
            &scalar(&format!("for i in {range} {{ acc += q; }}")),
        )
        .unwrap_err();
        assert!(err.contains("loop too long to unroll"), "{range}: {err}");
    }
    // unrolled work multiplied past usize, and nested loops: one error, not one per iteration
    let err = expand(
        "order = 1",
        &scalar("for i in 0..9223372036854775807 { acc += q; acc += q; acc += q; }"),
    )
    .unwrap_err();
    assert!(err.contains("loop too long to unroll"), "{err}");
    let err = expand(
        "order = 1",
        &scalar("for i in 0..1000 { for j in 0..1000 { acc += q; } }"),
    )
    .unwrap_err();
    assert_eq!(err.matches("loop too long").count(), 1, "{err}");
}

#[test]
fn indices_and_parameter_numbers_above_u16_are_not_truncated() {
    // a parameter array longer than 65 536
    let item = "fn l(q: f64, dq: f64, c: [f64; 70000]) -> f64 {
        0.5 * dq * dq + c[69999] * q + c[65536] * q.powi(2)
    }";
    let out = expand("order = 1", item).unwrap();
    let body = lagrangian_body(&out);
    assert!(
        body.contains("self . c [69999]") && body.contains("self . c [65536]"),
        "{body}"
    );
    assert!(!out.contains("65535"), "{out}");
    // slice elements
    let item = "fn l(q: f64, dq: f64, obs: &[[f64; 70000]]) -> f64 {
        let mut acc = 0.0;
        for o in obs { acc += o[69999] * q; }
        0.5 * dq * dq + acc
    }";
    let out = expand("order = 1", item).unwrap();
    assert!(
        out.contains("__e [69999]") && !out.contains("65535"),
        "{out}"
    );
    // the parameter numbered 65 536 (and beyond) is not parameter 65 535
    let params: Vec<String> = (0..65_540).map(|i| format!("p{i}: f64")).collect();
    let item = format!(
        "fn l(q: f64, dq: f64, {}) -> f64 {{ 0.5 * dq * dq + p65537 * q + p65535 * q.powi(2) }}",
        params.join(", ")
    );
    let out = expand("order = 1", &item).unwrap();
    let body = lagrangian_body(&out);
    assert!(
        body.contains("self . p65537") && body.contains("self . p65535"),
        "{body}"
    );
    assert!(!body.contains("self . p1 "), "{body}");
}

#[test]
fn non_finite_constants_are_folded_as_f64_does() {
    // each constant term is NaN or infinite when f64 evaluates it; folding keeps that value
    for (term, want) in [
        ("(0.0 / 0.0) * q", "NAN"),
        ("(1e308 * 10.0 - 1e308 * 10.0) * q", "NAN"),
        ("(1e308 * 10.0 - 1e308 * 10.0)", "NAN"),
        ("0.0 * (1.0 / 0.0)", "NAN"),
        ("(1.0 / 0.0) * q", "INFINITY"),
        ("(1.0 / -0.0) * q", "NEG_INFINITY"),
        ("(1e308 * 10.0) / (1e308 * 10.0) * q", "NAN"),
        ("((1e308 * 10.0 - q) + 1e308 * 10.0) * 0.5", "INFINITY"),
        ("(-1.0f64).sqrt() * q", "NAN"),
        ("(-1.0f64).powf(0.5) * q", "NAN"),
        ("(-1.0f64 / 0.0).powf(0.5) * q", "INFINITY"),
    ] {
        let out = expand("order = 1", &scalar(&format!("acc += {term};"))).unwrap();
        let body = lagrangian_body(&out);
        assert!(
            body.contains(&format!(":: f64 :: {want}")),
            "`{term}` should keep {want}: {body}"
        );
    }
}

/// A recurrence unrolled to the documented limit (10 000 iterations, each a few nodes
/// deeper) is differentiated and substituted without deep recursion, so the expansion fits a
/// 1 MiB stack even unoptimised (the compiler's own stack overflowed on it before). The
/// emitted code of this case compiles too (about 80 s and 0.8 GB in a release build, so it is
/// not compiled here; `tests/integrators/long_recurrence.rs` compiles the 1000-iteration case).
#[test]
fn a_recurrence_unrolled_to_the_limit_expands_on_a_small_stack() {
    let run = std::thread::Builder::new()
        .stack_size(1 << 20)
        .spawn(|| {
            expand(
                "order = 1",
                "fn recurrence(q: f64, dq: f64) -> f64 {
                    let mut x = q;
                    for _ in 0..10000 {
                        x = x * 0.999 + 0.001 * q.sin();
                    }
                    0.5 * dq * dq - x * x
                }",
            )
            .map(|e| e.len())
        })
        .expect("a thread");
    let length = run.join().expect("no stack overflow").expect("expands");
    assert!(length > 1_000_000, "{length} bytes");
}

#[test]
fn a_variable_powf_exponent_is_reported_once_per_expansion() {
    // a chain of 1250 calls whose exponent depends on the jet: one error, at the first call
    let chain = ".powf(q)".repeat(1250);
    let err = expand("order = 1", &scalar(&format!("acc += (q + 2.0){chain};"))).unwrap_err();
    assert_eq!(err.lines().count(), 1, "{}", &err[..err.len().min(400)]);
    assert!(
        err.contains("the exponent of `powf` must not depend on the jet"),
        "{err}"
    );
    // separate calls in one body, and a variable exponent through a let: still once
    let err = expand(
        "order = 1",
        &scalar("let e = dq * 2.0; acc += q.powf(dq); acc += (q + 1.0).powf(e);"),
    )
    .unwrap_err();
    assert_eq!(err.matches("the exponent of `powf`").count(), 1, "{err}");
    // a constant exponent still expands
    assert!(expand("order = 1", &scalar("acc += (q * q + 1.0).powf(2.5);")).is_ok());
}
