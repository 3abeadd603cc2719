//! The expansion behind `#[discretization_map]`: a map R_d(q, v) = (R1(q, v), R2(q, v)) on a
//! chart of Q = R^n, written as plain Rust, lifted to T^(k-1)Q and differentiated
//! symbolically into a `retract_core::map::DiscretizationMap<n, k>`.
//!
//! The stages: `signature` (order, dimension, parameters; (q, v) instead of a jet) ->
//! `lower` (the `let`s of the body, then the points, here: the body must end with the pair
//! of array literals) -> `mechanics::map_conditions` (R_d(q, 0) = (q, q), d_v R2 - d_v R1 = I at v = 0) ->
//! `mechanics::lift` (the lift by total derivatives, its Jacobians and the covector Hessian) ->
//! `emit::map` (the items).

use proc_macro2::TokenStream;
use syn::spanned::Spanned as _;
use syn::{Block, Expr, ItemFn, Stmt};

use crate::emit::map::map_items;
use crate::front::lower::Lower;
use crate::front::signature::{Attribute, Signature};
use crate::ir::graph::Graph;
use crate::mechanics::lift::{Lift, lift};
use crate::mechanics::map_conditions::{self, Spanned};
use crate::pipeline::{self, Passes, fail_softly};

/// Expands `#[discretization_map(attr)] item`; on error, the original item plus
/// `compile_error!`s, so the rest of the crate still type-checks. Never panics.
pub fn expand_discretization_map(attr: TokenStream, item: TokenStream) -> TokenStream {
    fail_softly(item.clone(), try_expand_discretization_map(attr, item))
}

/// The expansion of `#[discretization_map(attr)] item`, or the errors of the input combined
/// into one `syn::Error`.
pub fn try_expand_discretization_map(
    attr: TokenStream,
    item: TokenStream,
) -> syn::Result<TokenStream> {
    pipeline::run(&mut MapPasses, attr, item)
}

/// The passes of `#[discretization_map]`: the pair of points, no chart, the conditions
/// checked and the lift, the items.
struct MapPasses;

impl Passes for MapPasses {
    const ATTRIBUTE: Attribute = Attribute::Map;
    type Lowered = [Vec<Spanned>; 2];
    type Derived = Lift;

    fn lower(
        &mut self,
        lower: &mut Lower<'_>,
        function: &ItemFn,
        sig: &Signature,
    ) -> [Vec<Spanned>; 2] {
        points(lower, &function.block, sig)
    }

    /// A map is written on a chart of R^n (it takes no space option): unchanged.
    fn charts(
        &mut self,
        _: &mut Graph,
        sig: Signature,
        points: [Vec<Spanned>; 2],
    ) -> (Signature, [Vec<Spanned>; 2]) {
        (sig, points)
    }

    fn mechanics(
        &mut self,
        graph: &mut Graph,
        sig: &Signature,
        points: [Vec<Spanned>; 2],
    ) -> syn::Result<Lift> {
        if sig.check {
            map_conditions::check(graph, sig, &points)?;
        }
        let r = points.map(|side| side.iter().map(|&(id, _)| id).collect());
        Ok(lift(graph, &r, sig.dim, sig.order))
    }

    fn emit(&self, function: &ItemFn, sig: &Signature, graph: &Graph, lifted: Lift) -> TokenStream {
        map_items(function, sig, graph, &lifted)
    }
}

/// The supported form of the body, for messages.
fn supported_form(n: usize) -> String {
    let components = |side: usize| match n {
        0..=3 => (0..n)
            .map(|a| format!("R{side}_{a}"))
            .collect::<Vec<_>>()
            .join(", "),
        _ => format!("R{side}_0, ..., R{side}_{}", n - 1),
    };
    format!(
        "a discretization map must end with its pair of points as array literals, \
         `([{}], [{}])` (or `(R1, R2)` for q: f64), after `let` bindings of scalars",
        components(1),
        components(2)
    )
}

/// The statements of the body, then its points `[R1, R2]` with the span of each component
/// (placeholders where they are in error: the errors are in `lower.errors`).
fn points(lower: &mut Lower<'_>, block: &Block, sig: &Signature) -> [Vec<Spanned>; 2] {
    let n = sig.dim;
    let zero = lower.g.constant(0.0);
    let placeholder = |span| [vec![(zero, span); n], vec![(zero, span); n]];
    let Some((last, init)) = block.stmts.split_last() else {
        let msg = format!("the body is empty: {}", supported_form(n));
        lower.errors.push(syn::Error::new(block.span(), msg));
        return placeholder(block.span());
    };
    lower.statements(init);
    let tail = match last {
        Stmt::Expr(Expr::Return(r), _) => r.expr.as_deref(),
        Stmt::Expr(e, None) => Some(e),
        _ => None,
    };
    let Some(Expr::Tuple(pair)) = tail.map(strip) else {
        let span = tail.map_or(last.span(), |e| e.span());
        let msg = format!("unsupported body: {}", supported_form(n));
        lower.errors.push(syn::Error::new(span, msg));
        return placeholder(span);
    };
    if pair.elems.len() != 2 {
        let msg = format!(
            "the pair of points has {} elements: {}",
            pair.elems.len(),
            supported_form(n)
        );
        lower.errors.push(syn::Error::new(pair.span(), msg));
        return placeholder(pair.span());
    }
    let mut sides = pair.elems.iter().map(|e| side(lower, e, sig));
    let (r1, r2) = (sides.next(), sides.next());
    [r1.unwrap_or_default(), r2.unwrap_or_default()]
}

/// The n components of one point with their spans (placeholders where in error).
fn side(lower: &mut Lower<'_>, e: &Expr, sig: &Signature) -> Vec<Spanned> {
    let n = sig.dim;
    if sig.scalar_jet {
        return vec![(lower.expr(e), e.span())];
    }
    let zero = lower.g.constant(0.0);
    match strip(e) {
        Expr::Array(array) if array.elems.len() == n => array
            .elems
            .iter()
            .map(|c| (lower.expr(c), c.span()))
            .collect(),
        Expr::Array(array) => {
            let msg = format!(
                "this point has {} components, but q has {n}: {}",
                array.elems.len(),
                supported_form(n)
            );
            lower.errors.push(syn::Error::new(array.span(), msg));
            vec![(zero, array.span()); n]
        }
        other => {
            let msg = format!(
                "unsupported point: write it as an array literal; {}",
                supported_form(n)
            );
            lower.errors.push(syn::Error::new(other.span(), msg));
            vec![(zero, other.span()); n]
        }
    }
}

/// `e` without parentheses and invisible groups.
fn strip(mut e: &Expr) -> &Expr {
    loop {
        match e {
            Expr::Paren(p) => e = &p.expr,
            Expr::Group(g) => e = &g.expr,
            _ => return e,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The expansion, formatted, or the error messages joined.
    fn expand_str(attr: &str, item: &str) -> Result<String, String> {
        crate::util::pretty_expansion(try_expand_discretization_map, attr, item)
    }

    /// A map on R^2 with the components `r1`, `r2` (text, in q, v and the parameter c).
    fn map(attr: &str, r1: [&str; 2], r2: [&str; 2]) -> Result<String, String> {
        expand_str(
            attr,
            &format!(
                "fn m(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {{
                    let s = c * q[0].sin();
                    ([{}, {}], [{}, {}])
                }}",
                r1[0], r1[1], r2[0], r2[1]
            ),
        )
    }

    #[test]
    fn a_map_expands_to_its_type_and_impl() {
        let out = map(
            "order = 2",
            ["q[0] - 0.5 * v[0] + s * v[0] * v[0]", "q[1] - 0.5 * v[1]"],
            ["q[0] + 0.5 * v[0] + s * v[0] * v[0]", "q[1] + 0.5 * v[1]"],
        )
        .unwrap();
        assert!(
            out.contains("struct M") && out.contains("pub c: f64"),
            "{out}"
        );
        assert!(out.contains("DiscretizationMap<2, 2> for M"), "{out}");
        assert!(out.contains("pub fn new(c: f64)"), "{out}");
        assert!(
            out.contains("w2[0][0]") && out.contains("w1[1][0]"),
            "{out}"
        );
        assert!(out.contains("fn m("), "{out}");
    }

    /// `v * sqrt(q0 - 5) / sqrt(q0 - 5)` is not `v` (it is NaN for q0 < 5): the points are
    /// computed as written (before, the quotient was folded to 1 and the map was defined
    /// everywhere); the conditions hold where it is defined.
    #[test]
    fn a_quotient_of_equal_factors_is_not_folded_out_of_the_map() {
        let guarded = "q[0] + v[0] * (q[0] - 5.0).sqrt() / (q[0] - 5.0).sqrt()";
        let out = map("order = 1", ["q[0]", "q[1]"], [guarded, "q[1] + v[1]"]).unwrap();
        let points = &out[out.find("fn points(").unwrap()..out.find("fn jacobians(").unwrap()];
        assert!(
            points.contains(".sqrt()") && points.contains(" / "),
            "{points}"
        );
    }

    #[test]
    fn the_conditions_are_checked_at_compile_time() {
        let ok = |r1: [&str; 2], r2: [&str; 2]| map("order = 1", r1, r2);
        let err = |r1, r2| ok(r1, r2).unwrap_err();
        // symbolically
        let e = err(["q[0] + 1.0", "q[1]"], ["q[0] + v[0]", "q[1] + v[1]"]);
        assert!(
            e.contains("requires R1(q, 0) = q") && e.contains("component 0"),
            "{e}"
        );
        assert!(!e.contains("component 1"), "{e}");
        let e = err(
            ["q[0]", "q[1]"],
            ["q[0] + 0.5 * v[0]", "q[1] + v[1] + v[0]"],
        );
        assert!(e.contains("dv[0] at v = 0 is not 1: it is 0.5"), "{e}");
        assert!(
            e.contains("d(R2[1] - R1[1])/dv[0] at v = 0 is not 0: it is 1"),
            "{e}"
        );
        // numerically, where the simplifier cannot decide
        ok(
            [
                "q[0] * (q[1].sin().powi(2) + q[1].cos().powi(2))",
                "q[1] - c * v[1]",
            ],
            ["q[0] + v[0]", "q[1] + (1.0 - c) * v[1] * (c * v[0]).exp()"],
        )
        .unwrap();
        let e = err(
            ["q[0] + 1e-9 * (q[0] * q[1]).sin()", "q[1]"],
            ["q[0] + v[0]", "q[1] + v[1]"],
        );
        assert!(e.contains("at the test point 0"), "{e}");
        // a constant of the user's crate cannot be evaluated; those of f64::consts can
        let e = err(["q[0] * SCALE", "q[1]"], ["q[0] + v[0]", "q[1] + v[1]"]);
        assert!(e.contains("cannot be checked at compile time"), "{e}");
        ok(
            [
                "q[0] * std::f64::consts::FRAC_PI_4 * 4.0 / std::f64::consts::PI",
                "q[1]",
            ],
            ["q[0] + v[0]", "q[1] + v[1]"],
        )
        .unwrap();
    }

    #[test]
    fn check_false_admits_the_sphere_projection() {
        let item = "fn sphere(q: [f64; 3], xi: [f64; 3]) -> ([f64; 3], [f64; 3]) {
            let r = ((q[0] + xi[0]).powi(2) + (q[1] + xi[1]).powi(2) + (q[2] + xi[2]).powi(2)).sqrt();
            ([q[0], q[1], q[2]], [(q[0] + xi[0]) / r, (q[1] + xi[1]) / r, (q[2] + xi[2]) / r])
        }";
        let e = expand_str("order = 2", item).unwrap_err();
        assert!(e.contains("requires R2(q, 0) = q"), "{e}");
        assert!(e.contains("must be the identity"), "{e}");
        expand_str("order = 2, check = false", item).unwrap();
    }

    #[test]
    fn unsupported_forms_are_errors_naming_the_supported_one() {
        let e = expand_str(
            "order = 1",
            "fn m(q: [f64; 2], v: [f64; 2]) -> ([f64; 2], [f64; 2]) { let a = q[0]; (q, v) }",
        )
        .unwrap_err();
        assert!(
            e.contains("unsupported point: write it as an array literal"),
            "{e}"
        );
        let e = expand_str(
            "order = 1",
            "fn m(q: [f64; 2], v: [f64; 2]) -> ([f64; 2], [f64; 2]) { q[0] }",
        )
        .unwrap_err();
        assert!(e.contains("unsupported body"), "{e}");
        let e = expand_str(
            "order = 1",
            "fn m(q: [f64; 2], v: [f64; 2]) -> ([f64; 2], [f64; 2]) { ([q[0]], [q[0], q[1]]) }",
        )
        .unwrap_err();
        assert!(
            e.contains("this point has 1 components, but q has 2"),
            "{e}"
        );
        let e =
            expand_str("order = 1", "fn m(q: [f64; 2], v: [f64; 2]) -> f64 { 0.0 }").unwrap_err();
        assert!(
            e.contains("the return type must be `([f64; 2], [f64; 2])`"),
            "{e}"
        );
        let e = expand_str(
            "order = 1",
            "fn m(q: f64, v: [f64; 2], s: &[[f64; 2]]) -> (f64, f64) { (q, q) }",
        )
        .unwrap_err();
        assert!(
            e.contains("tangent vector v") && e.contains("parameter type"),
            "{e}"
        );
        let e = expand_str(
            "order = 5",
            "fn m(q: f64, v: f64) -> (f64, f64) { (q, q + v) }",
        )
        .unwrap_err();
        assert!(e.contains("unsupported order 5"), "{e}");
        let e = expand_str(
            "order = 1, guard = false",
            "fn m(q: f64, v: f64) -> (f64, f64) { (q, q + v) }",
        )
        .unwrap_err();
        assert!(e.contains("`check = false`"), "{e}");
        // a scalar map
        expand_str(
            "order = 3",
            "fn m(q: f64, v: f64) -> (f64, f64) { (q - v * v, q + v) }",
        )
        .unwrap();
    }

    #[test]
    fn malformed_input_never_panics() {
        for (attr, item) in [
            ("", ""),
            ("order = 1", "struct S;"),
            ("order = 1", "fn m() -> (f64, f64) { (0.0, 0.0) }"),
            ("order = 1", "fn m(q: f64) -> (f64, f64) { (q, q) }"),
            ("order = 1", "fn m(q: f64, v: f64) -> (f64, f64) { }"),
            (
                "order = 1",
                "fn m(q: f64, v: f64) -> (f64, f64) { return; }",
            ),
            (
                "order = 1",
                "fn m(q: f64, v: f64) -> (f64, f64) { (q, q, v) }",
            ),
            (
                "order = 1",
                "fn m(q: f64, v: f64) -> (f64, f64) { (q / 0.0, q + v) }",
            ),
            (
                "order = 1",
                "fn m(q: f64, v: f64) -> (f64, f64) { (q, (q + v).ln()) }",
            ),
            (
                "order = 1",
                "fn m(q: [f64; 0], v: [f64; 0]) -> ([f64; 0], [f64; 0]) { ([], []) }",
            ),
        ] {
            let _ = expand_discretization_map(attr.parse().unwrap(), item.parse().unwrap());
        }
    }
}
