//! The compile-time conditions of a discretization map (`#[discretization_map]`):
//! R_d(q, 0) = (q, q) and d_v R2 - d_v R1 = I at v = 0.
//!
//! Each condition is an identity `lhs(q, params) = rhs(q)` for one component (or entry). It
//! holds when the graph's simplifier reduces `lhs - rhs` at v = 0 to the constant 0; it fails
//! when that is another constant; otherwise it is tested numerically at [`POINTS`]
//! pseudo-random points, q_a uniform in [-1, 1] and every parameter component uniform in
//! [0.25, 1.25], and fails if |lhs - rhs| > [`TOLERANCE`] (1 + |lhs| + |rhs|) at one of them.
//! Points where the map is not finite (a logarithm of a negative number, ...) are skipped;
//! if all are, or if the condition depends on a constant whose value the macro cannot see
//! (a user `const` named by path), the condition cannot be checked and that is an error
//! (`check = false` skips the checks). So a map that passes satisfies the conditions
//! identically, or numerically at the test points, where an identity that fails only on a
//! set of measure zero (or only for other parameter values) cannot be told apart.

use std::collections::HashMap;

use proc_macro2::Span;

use crate::front::signature::{Kind, Signature};
use crate::ir::diff::{Differentiator, substitute};
use crate::ir::graph::{Graph, Id, Node, Var};
use crate::util::ErrorContext;

/// Number of pseudo-random points of the numerical test.
pub const POINTS: usize = 4;

/// Relative tolerance of the numerical test.
pub const TOLERANCE: f64 = 1e-12;

/// A returned component with its span.
pub type Spanned = (Id, Span);

/// One condition: `lhs = rhs` at v = 0, reported at `span` with `what` naming it.
struct Condition {
    lhs: Id,
    rhs: Id,
    span: Span,
    what: String,
}

/// Checks the conditions on `r = [R1, R2]` (n components each): the errors, one per
/// component or entry that fails, combined.
pub fn check(g: &mut Graph, sig: &Signature, r: &[Vec<Spanned>; 2]) -> syn::Result<()> {
    let n = sig.dim;
    let mut memo = HashMap::new();
    let at_rest = |g: &mut Graph, v: Var| match v {
        Var::Jet { order: 0, index } if index as usize >= n => Some(g.constant(0.0)),
        _ => None,
    };
    let mut conditions = Vec::new();
    for (s, side) in r.iter().enumerate() {
        for (a, &(id, span)) in side.iter().enumerate() {
            let lhs = substitute(g, id, &at_rest, &mut memo);
            let rhs = g.var(Var::Jet {
                order: 0,
                index: a as u32,
            });
            let what = format!(
                "R_d(q, 0) = (q, q) requires R{}(q, 0) = q, but component {a} of R{} at v = 0 is \
                 not q[{a}]",
                s + 1,
                s + 1
            );
            conditions.push(Condition {
                lhs,
                rhs,
                span,
                what,
            });
        }
    }
    let mut d = Differentiator::default();
    for (a, (&(r1, _), &(r2, span))) in r[0].iter().zip(&r[1]).enumerate() {
        for b in 0..n {
            let v = Var::Jet {
                order: 0,
                index: (n + b) as u32,
            };
            let d1 = d.diff(g, r1, v);
            let d2 = d.diff(g, r2, v);
            let dv = g.sub(d2, d1);
            let lhs = substitute(g, dv, &at_rest, &mut memo);
            let rhs = g.constant(if a == b { 1.0 } else { 0.0 });
            let what = format!(
                "d_v R2 - d_v R1 must be the identity at v = 0, but d(R2[{a}] - R1[{a}])/dv[{b}] \
                 at v = 0 is not {}",
                if a == b { 1 } else { 0 }
            );
            conditions.push(Condition {
                lhs,
                rhs,
                span,
                what,
            });
        }
    }
    let mut errors = ErrorContext::new();
    for c in &conditions {
        if let Some(why) = verdict(g, sig, c) {
            errors.error(c.span, why);
        }
    }
    errors.check()
}

/// `None` if the condition holds, else the message.
fn verdict(g: &mut Graph, sig: &Signature, c: &Condition) -> Option<String> {
    let difference = g.sub(c.lhs, c.rhs);
    if let Some(value) = g.as_const(difference) {
        return (value != 0.0).then(|| match g.as_const(c.lhs) {
            Some(lhs) => format!("{}: it is {lhs}", c.what),
            None => format!("{}: it differs from it by the constant {value}", c.what),
        });
    }
    let mut seed = 0x5eed_u64;
    let mut tested = 0;
    for point in 0..POINTS {
        let values = sample(sig, &mut seed);
        let leaf = |node: &Node| match node {
            Node::Var(Var::Jet { order: 0, index }) => values.q.get(*index as usize).copied(),
            Node::Var(Var::Param { param, index }) => values
                .params
                .get(*param as usize)
                .and_then(|p| p.get(*index as usize))
                .copied(),
            Node::Named(i) => std_constant(&g.named[*i as usize]),
            _ => None,
        };
        let root = c.lhs.max(c.rhs);
        let computed = g.evaluate(root, &leaf);
        let (Some(lhs), Some(rhs)) = (computed[c.lhs.0 as usize], computed[c.rhs.0 as usize])
        else {
            return Some(format!(
                "{}: cannot be checked at compile time, since it depends on a constant whose \
                 value the macro cannot see; write the value as a literal, or skip the checks \
                 with `check = false`",
                c.what
            ));
        };
        if !(lhs.is_finite() && rhs.is_finite()) {
            continue;
        }
        tested += 1;
        if (lhs - rhs).abs() > TOLERANCE * (1.0 + lhs.abs() + rhs.abs()) {
            return Some(format!(
                "{}: at the test point {point} (q = {:?}) it is {lhs}, not {rhs}",
                c.what, values.q
            ));
        }
    }
    (tested == 0).then(|| {
        format!(
            "{}: cannot be checked at compile time, since the map is not finite at any of the \
             {POINTS} test points; skip the checks with `check = false`",
            c.what
        )
    })
}

/// The values of q (n entries) and of the parameters at a test point.
struct Sample {
    q: Vec<f64>,
    params: Vec<Vec<f64>>,
}

/// A deterministic pseudo-random number in [0, 1).
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

fn sample(sig: &Signature, seed: &mut u64) -> Sample {
    let q = (0..sig.dim).map(|_| 2.0 * uniform(seed) - 1.0).collect();
    let params = sig
        .params
        .iter()
        .map(|p| {
            let len = match p.kind {
                Kind::Scalar => 1,
                Kind::Array(len) | Kind::Slice(len) => len,
            };
            (0..len).map(|_| 0.25 + uniform(seed)).collect()
        })
        .collect();
    Sample { q, params }
}

/// The value of a constant of `f64::consts` named by path (`std::f64::consts::PI`, ...).
fn std_constant(path: &str) -> Option<f64> {
    use std::f64::consts as c;
    let (module, name) = path.rsplit_once("::")?;
    if !module.ends_with("f64::consts") {
        return None;
    }
    Some(match name {
        "PI" => c::PI,
        "TAU" => c::TAU,
        "E" => c::E,
        "SQRT_2" => c::SQRT_2,
        "FRAC_1_SQRT_2" => c::FRAC_1_SQRT_2,
        "FRAC_PI_2" => c::FRAC_PI_2,
        "FRAC_PI_3" => c::FRAC_PI_3,
        "FRAC_PI_4" => c::FRAC_PI_4,
        "FRAC_PI_6" => c::FRAC_PI_6,
        "FRAC_PI_8" => c::FRAC_PI_8,
        "FRAC_1_PI" => c::FRAC_1_PI,
        "FRAC_2_PI" => c::FRAC_2_PI,
        "FRAC_2_SQRT_PI" => c::FRAC_2_SQRT_PI,
        "LN_2" => c::LN_2,
        "LN_10" => c::LN_10,
        "LOG2_E" => c::LOG2_E,
        "LOG10_E" => c::LOG10_E,
        "LOG2_10" => c::LOG2_10,
        "LOG10_2" => c::LOG10_2,
        _ => return None,
    })
}
