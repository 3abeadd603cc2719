//! `#[higher_order_lagrangian]` as a plain function, `TokenStream -> TokenStream`, testable
//! without the compiler's proc-macro bridge: its passes of the pipeline (`crate::pipeline`):
//! the body lowered with its guards and named outputs, composed with its chart, the mechanics
//! (momenta, scheme, Jacobians, the guards at the step's points, the reduced scheme), and the
//! items emitted from an [`Emission`] context (module `emit`), concatenated.

use proc_macro2::TokenStream;
use syn::ItemFn;

use super::helper;
use crate::charts::Space;
use crate::emit::outputs::outputs_impl;
use crate::emit::{Emission, system_items};
use crate::front::lower::{Guard, Lower, Output, without_output_marks};
use crate::front::signature::{Attribute, Signature};
use crate::ir::graph::{Graph, Id};
use crate::mechanics::{self, Degenerate, Mechanics, Reduced};
use crate::pipeline::{self, Passes, compose_with_chart, fail_softly};

/// Expands `#[higher_order_lagrangian(attr)] item`; on error, the original item plus
/// `compile_error!`s, so the rest of the crate still type-checks. Never panics.
pub fn expand(attr: TokenStream, item: TokenStream) -> TokenStream {
    fail_softly(item.clone(), try_expand(attr, item))
}

/// The expansion, or the errors of the input combined into one `syn::Error`.
pub fn try_expand(attr: TokenStream, item: TokenStream) -> syn::Result<TokenStream> {
    expand_counted(attr, item, &mut ExpansionStats::default())
}

/// The work of one expansion, counted in expression-graph nodes (deterministic, unlike wall
/// time): for tests that bound the work (the grammar fuzzer) and for benchmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExpansionStats {
    /// Nodes after lowering the body (the Lagrangian itself); 0 if the signature failed.
    pub lowered_nodes: usize,
    /// Nodes at the end (with the derivatives, the scheme and the guards at the step points).
    pub graph_nodes: usize,
    /// Guarded expressions (`check_domain`), factors included.
    pub guards: usize,
}

/// [`try_expand`] and the work it took (also when it failed).
pub fn expansion_stats(
    attr: TokenStream,
    item: TokenStream,
) -> (syn::Result<TokenStream>, ExpansionStats) {
    let mut stats = ExpansionStats::default();
    let result = expand_counted(attr, item, &mut stats);
    (result, stats)
}

fn expand_counted(
    attr: TokenStream,
    item: TokenStream,
    stats: &mut ExpansionStats,
) -> syn::Result<TokenStream> {
    if let Some(chain) = helper::chain_if_named(&attr, "lagrangian", &item)? {
        return Ok(chain);
    }
    pipeline::run(&mut LagrangianPasses { stats }, attr, item)
}

/// The passes of `#[higher_order_lagrangian]`, counting their work in `stats`.
struct LagrangianPasses<'a> {
    stats: &'a mut ExpansionStats,
}

/// L, its guarded expressions and its named outputs, as lowered.
struct Lowered {
    root: Id,
    guards: Vec<Guard>,
    outputs: Vec<Output>,
}

/// The mechanics of L, its guards at the step's points, the reduced scheme where it applies,
/// and the named outputs.
struct Derived {
    mech: Mechanics,
    guards: Vec<(Guard, [Id; 3])>,
    reduced: Option<Reduced>,
    outputs: Vec<Output>,
}

impl Passes for LagrangianPasses<'_> {
    const ATTRIBUTE: Attribute = Attribute::Lagrangian;
    type Lowered = Lowered;
    type Derived = Derived;

    fn lower(&mut self, lower: &mut Lower<'_>, function: &ItemFn, sig: &Signature) -> Lowered {
        let root = lower.body(&function.block);
        self.stats.lowered_nodes = lower.g.len();
        self.stats.graph_nodes = lower.g.len();
        self.stats.guards = lower.guards.len();
        if let Some(output) = lower.outputs.first().filter(|_| sig.space != Space::Flat) {
            let span = output.name.span();
            lower.errors.error(
                span,
                format!(
                    "named outputs are not supported with {} (the generated system works in a \
                     chart)",
                    Space::option_list(", ", " or ")
                ),
            );
        }
        Lowered {
            root,
            guards: std::mem::take(&mut lower.guards),
            outputs: std::mem::take(&mut lower.outputs),
        }
    }

    fn charts(
        &mut self,
        graph: &mut Graph,
        sig: Signature,
        lowered: Lowered,
    ) -> (Signature, Lowered) {
        let (sig, root, guards) = in_chart(graph, sig, lowered.root, lowered.guards);
        let outputs = lowered.outputs;
        (
            sig,
            Lowered {
                root,
                guards,
                outputs,
            },
        )
    }

    fn mechanics(
        &mut self,
        graph: &mut Graph,
        sig: &Signature,
        lowered: Lowered,
    ) -> syn::Result<Derived> {
        let mech = mechanics::build(graph, lowered.root, sig.dim, sig.order);
        self.stats.graph_nodes = graph.len();
        let mech = mech.map_err(|reason| degenerate(sig, reason))?;
        let guards = mechanics::guards_at_step_points(graph, lowered.guards, sig);
        let flat: Vec<Vec<Id>> = mech.hessian.clone();
        let reduced = mechanics::reduce(graph, &mech.gradient, &flat, sig.dim, sig.order);
        self.stats.graph_nodes = graph.len();
        Ok(Derived {
            mech,
            guards,
            reduced,
            outputs: lowered.outputs,
        })
    }

    fn emit(&self, function: &ItemFn, sig: &Signature, graph: &Graph, d: Derived) -> TokenStream {
        let function = without_output_marks(function);
        let emission = Emission::new(
            &function,
            sig,
            graph,
            &d.mech,
            &d.guards,
            d.reduced.as_ref(),
        );
        let mut out = system_items(&emission);
        out.extend(outputs_impl(&emission, &d.outputs));
        out
    }
}

/// The error of a Lagrangian whose Legendre map is singular, at its top argument.
fn degenerate(sig: &Signature, reason: Degenerate) -> syn::Error {
    let top = &sig.jet[sig.order];
    let what = sig.space.chart().top(sig.order);
    let msg = match reason {
        Degenerate::Independent => format!(
            "the Lagrangian does not depend on `{top}` = {what}: its Legendre map is \
             singular; lower the order or add a term in `{top}` (e.g. 0.5 * |{top}|^2)"
        ),
        Degenerate::Linear => format!(
            "the Lagrangian is linear in `{top}` = {what}: d2L/d{top}2 = 0, so its Legendre \
             map is singular; it must be (at least locally) strictly convex in `{top}`"
        ),
        Degenerate::Singular => format!(
            "d2L/d{top}2 is a singular constant matrix (or has a non-finite entry): the \
             Legendre map is singular; every component of `{top}` must enter L \
             quadratically with finite weights"
        ),
    };
    syn::Error::new(top.span(), msg)
}

/// L and its guards composed with the chart of their space (`charts`), with the signature
/// of the composed Lagrangian.
fn in_chart(
    graph: &mut Graph,
    sig: Signature,
    root: Id,
    guards: Vec<Guard>,
) -> (Signature, Id, Vec<Guard>) {
    let roots: Vec<Id> = core::iter::once(root)
        .chain(guards.iter().map(|g| g.node))
        .collect();
    let (sig, composed) = compose_with_chart(graph, sig, &roots);
    let guards = guards
        .into_iter()
        .zip(&composed[1..])
        .map(|(guard, &node)| Guard { node, ..guard })
        .collect();
    (sig, composed[0], guards)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The expansion, formatted, or the error messages.
    fn pretty(attr: &str, item: &str) -> Result<String, String> {
        crate::util::pretty_expansion(try_expand, attr, item)
    }

    #[test]
    fn every_supported_construct_expands() {
        let out = pretty(
            "order = 2, name = Everything",
            "pub fn all(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], a: f64, c: [f64; 2],
                        obs: &[[f64; 3]]) -> f64 {
                const N: usize = 2;
                const W: f64 = 0.5;
                let mut acc = 0.0;
                for i in 0..N { acc += W * ddq[i].powi(2); }
                for i in 0..=1 { acc -= (-dq[i]) * 0.0; }
                let mut m = 1.0;
                m *= 2.0;
                m /= 2.0;
                m = m + 0.0;
                for o in obs {
                    let d2 = (q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2];
                    acc += a / d2;
                }
                for o in obs.iter() { acc -= 0.0 * o[0]; }
                let t = q[0].sin() + q[1].cos() + q[0].tan().tanh() + q[1].exp().ln()
                    + q[0].hypot(q[1]) + q[1].atan2(q[0]) + q[0].abs().sqrt() + q[1].recip()
                    + q[0].powf(1.5) + c[1] * std::f64::consts::PI + f64::sqrt(q[0])
                    + (2 as f64) * q[1];
                m * acc + t
            }",
        )
        .unwrap();
        assert!(out.contains("pub struct Everything<'a>"), "{out}");
        assert!(out.contains("for __e in self.obs.iter()"), "{out}");
        assert!(out.contains("pub fn all("), "{out}");
    }

    /// `derivatives` is one straight-line code for the value, the gradient and the Hessian:
    /// each trigonometric function of an angle is evaluated once in it (the separate
    /// `gradient` and `hessian` evaluate it once each).
    #[test]
    fn derivatives_evaluate_each_shared_subexpression_once() {
        let out = pretty(
            "order = 2",
            "fn l(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
                let t = (2.0 + q[1].cos()) * ddq[0] + q[1].sin() * dq[0] * dq[1]
                    + 9.81 * (q[0] + q[1]).sin();
                0.5 * t * t + ddq[1] * ddq[1]
            }",
        )
        .unwrap();
        let body = |name: &str| {
            let from = out.find(&format!("fn {name}(")).unwrap_or(0);
            let to = out[from..]
                .find("\n    fn ")
                .map_or(out.len(), |n| from + n);
            out[from..to].to_string()
        };
        let derivatives = body("derivatives");
        assert!(derivatives.contains("Derivatives"), "{out}");
        for call in [".sin()", ".cos()"] {
            // sin q1, sin(q0 + q1) / cos q1, cos(q0 + q1) (each maybe with its argument bound)
            assert_eq!(derivatives.matches(call).count(), 2, "{derivatives}");
            assert_eq!(body("gradient").matches(call).count(), 2, "{out}");
            assert_eq!(body("hessian").matches(call).count(), 2, "{out}");
        }
    }

    #[test]
    fn errors_name_what_is_supported() {
        let err = |body: &str| {
            pretty(
                "order = 2",
                &format!("fn l(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {{ {body} }}"),
            )
            .unwrap_err()
        };
        assert!(
            err("ddq[0].powi(2) + q[0].norm()")
                .contains("unsupported method `norm`; supported: powi")
        );
        assert!(err("ddq[0].powi(2) + foo(q[0])").contains("unknown function `foo`"));
        assert!(err("if q[0] > 0.0 { ddq[0] } else { ddq[1] }").contains("`if` is not supported"));
        assert!(err("ddq[0].powi(2) + q[2]").contains("index 2 out of range"));
        assert!(err("q[0] + q[1]").contains("does not depend on `ddq`"));
        assert!(err("ddq[0] + q[1]").contains("linear in `ddq`"));
        assert!(err("ddq[0].powi(2) + q[1]").contains("singular constant matrix"));
        // all errors of one compile at once
        let both = err("let a = q[0].norm(); ddq[0].powi(2) + bar(a)");
        assert!(both.contains("norm") && both.contains("bar"), "{both}");
    }

    /// A chain of 2000 calls and a sum of 2000 terms expand (they are lowered without
    /// recursion); brackets nested past the limit are one error (not a deeper recursion).
    #[test]
    fn deep_nesting_is_an_error_and_long_chains_and_sums_expand() {
        let expand = |body: String| {
            pretty(
                "order = 2",
                &format!("fn l(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1]) -> f64 {{ {body} }}"),
            )
        };
        let chain = format!("ddq[0].powi(2) + q[0]{}", ".sin()".repeat(2000));
        assert!(expand(chain).is_ok());
        let nested = format!(
            "ddq[0].powi(2) + {}q[0]{}",
            "(".repeat(300),
            ").sin()".repeat(300)
        );
        let message = expand(nested).unwrap_err();
        assert_eq!(
            message.matches("brackets nest deeper than 256").count(),
            1,
            "{message}"
        );
        let sum = (0..2000)
            .map(|i| format!("{i}.0 * q[0].sin()"))
            .collect::<Vec<_>>();
        assert!(expand(format!("ddq[0].powi(2) + {}", sum.join(" + "))).is_ok());
    }

    #[test]
    fn malformed_input_never_panics() {
        let cases = [
            ("", ""),
            ("order = 2", ""),
            ("order = 2", "struct S;"),
            ("order = 0", "fn l(q: f64) -> f64 { q }"),
            ("order = 9", "fn l(q: f64) -> f64 { q }"),
            ("order = x", "fn l(q: f64) -> f64 { q }"),
            (
                "order = 1, bogus",
                "fn l(q: f64, dq: f64) -> f64 { dq * dq }",
            ),
            ("order = 1", "fn l() -> f64 { 1.0 }"),
            ("order = 1", "fn l(q: f64, dq: f64) {}"),
            ("order = 1", "fn l(q: f64, dq: f64) -> f64 { }"),
            ("order = 1", "fn l(q: f64, dq: f64) -> f64 { return; }"),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { for i in 0.. { } dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { for i in 0..100000000 { } dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { let x; dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { dq.powi(99999999999) }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { dq * dq / 0.0 + (-1.0f64).ln() }",
            ),
            (
                "order = 1",
                "fn l(q: [f64; 0], dq: [f64; 0]) -> f64 { 0.0 }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64, s: &[[f64; 2]]) -> f64 { for a in s { for b in s { } } dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64, s: &[[f64; 2]]) -> f64 { let mut x = 0.0; for a in s { x += a[0]; x += x; } dq * dq }",
            ),
        ];
        for (attr, item) in cases {
            let attr: TokenStream = attr.parse().unwrap();
            let item: TokenStream = item.parse().unwrap();
            let _ = expand(attr, item);
        }
    }

    #[test]
    fn expression_growth_is_bounded() {
        // n = 6, k = 2, 5 obstacles in an unrolled loop: 2002 lines (1946 before the plain
        // recovery `recover_plain`, linear in M); the bound catches a blow-up, not a line
        let (attr, item) = crate::samples::obstacle_field(6, 5);
        let tokens = try_expand(attr, item).unwrap();
        let file: syn::File = syn::parse2(tokens).unwrap();
        let lines = prettyplease::unparse(&file).lines().count();
        println!("expansion: {lines} lines");
        assert!(lines < 2200, "{lines} lines");
    }
}
