//! The `check_domain` method of the `LiftedSystem` impl: the singularity guard of a step.
//!
//! Each guarded expression of L (a denominator, each factor of a guarded expression, a
//! `sqrt`, `ln` or `powf` argument) is evaluated at x_0, x_1 and x_theta of a step, one loop
//! over the elements per guard that reads a slice parameter. A denominator (and each factor)
//! must be finite, non-zero and of one sign at the three points, a `sqrt` argument `>= 0`,
//! `ln` and `powf` arguments `> 0`; and every irreducible factor must stay clear of zero
//! between them: the quadratic through the three samples may not come within
//! `VANISH_TOLERANCE` of the largest sample of zero inside the step (`clear_of_zero_fn`).
//! Where every guard is a polynomial of degree at most 2 in the jet, that quadratic is the
//! guard along the chord, and the impl also says `guards_quadratic` (the step's check then
//! skips the chord's pieces).
//! The first violation is returned as a `DomainViolation` naming the expression as written.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::Emission;
use crate::emit::codegen::emit;
use crate::front::lower::{Guard, GuardKind};
use crate::ir::graph::Id;

/// The method `check_domain`, where L has guarded expressions.
pub(crate) fn check_domain(e: &Emission<'_>) -> Option<TokenStream> {
    let Emission {
        guards,
        core,
        vec_s,
        vec_m,
        ..
    } = e;
    if guards.is_empty() {
        return None;
    }
    let body = domain_check(e);
    let mut list: Vec<String> = Vec::new();
    for (guard, _) in guards.iter() {
        let item = format!("`{}`", guard.text);
        if !list.contains(&item) {
            list.push(item);
        }
    }
    let doc = format!(
        "Domain check at x_0, x_1 and x_theta of a step (and between them, by the quadratic through \
         the three values). Denominators that must keep their \
         sign, and arguments of sqrt (>= 0), ln and powf (> 0): {}.",
        list.join(", ")
    );
    // every guard quadratic (or linear) in the jet: the three samples decide the chord
    let quadratic = guards
        .iter()
        .all(|(guard, _)| e.g.jet_degree(guard.node, 2).is_some());
    let guards_quadratic = quadratic.then(|| {
        quote! {
            /// Every guarded expression is a polynomial of degree at most 2 in the jet: the
            /// three samples of `check_domain` decide the chord.
            fn guards_quadratic(&self) -> bool {
                true
            }
        }
    });
    Some(quote! {
        #guards_quadratic
        #[doc = #doc]
        fn check_domain(
            &self,
            z0: &#vec_s,
            w: &#vec_m,
            theta: f64,
        ) -> ::core::result::Result<(), #core::DomainViolation> {
            #[allow(unused_imports)]
            use ::retract::__private::Float as _;
            #body
            ::core::result::Result::Ok(())
        }
    })
}

/// The relative distance from zero below which a guarded factor counts as vanished.
const VANISH_TOLERANCE: f64 = 1e-9;
/// The rounding error of the fitted minimum, relative to the largest sample, over
/// `min(theta, 1 - theta)`: below it the fit cannot resolve anything.
const FIT_NOISE: f64 = 1e-13;

/// The "vanishes" rule of `check_domain`, emitted once as a local function: where the
/// quadratic through the samples `(0, a)`, `(theta, c)`, `(1, b)` (of one sign, by the sign
/// rule) has its extremum towards zero inside the step, it must stay more than
/// `VANISH_TOLERANCE` times the largest sample away from zero. The fit is exact for a factor
/// quadratic along the step (`x^2 + y^2 - r^2`, `|q'|^2`, `x^2 + y^2` of `atan2` and
/// `hypot`), so a step that passes through such a zero between the samples is caught. When
/// the smallest sample is below the fit's rounding error `margin` (a step starting on the
/// boundary, or a factor growing by 13 orders of magnitude within one step), the fit cannot
/// tell a touch from rounding: then only a minimum below `-margin` (a clear dip through zero)
/// is rejected. It is skipped (only the sign rule applies) for `theta` within `1e-3` of an
/// end.
fn clear_of_zero_fn() -> TokenStream {
    let tol = Literal::f64_suffixed(VANISH_TOLERANCE);
    let noise = Literal::f64_suffixed(FIT_NOISE);
    quote! {
        #[inline(always)]
        #[allow(dead_code)]
        fn __clear_of_zero(a: f64, b: f64, c: f64, theta: f64) -> bool {
            if !(theta > 1e-3 && theta < 1.0 - 1e-3) {
                return true;
            }
            let sign = if a < 0.0 { -1.0 } else { 1.0 };
            let (a, b, c) = (sign * a, sign * b, sign * c);
            let scale = a.max(b).max(c);
            let margin = #noise * scale / theta.min(1.0 - theta);
            // p(s) = a + beta s + alpha s^2 through the three samples
            let alpha = ((c - a) - theta * (b - a)) / (theta * theta - theta);
            let beta = (b - a) - alpha;
            let vertex = -beta / (2.0 * alpha);
            if !(alpha > 0.0 && vertex > 0.0 && vertex < 1.0) {
                return true;
            }
            let minimum = a + 0.5 * beta * vertex;
            if a.min(b).min(c) <= margin {
                minimum > -margin
            } else {
                minimum > #tol * scale
            }
        }
    }
}

/// `check_domain`: each guard at the three points of a step, one loop per slice guard. A
/// denominator (and each factor of a guarded expression) must be finite, non-zero and of one
/// sign at the three points, a `sqrt` argument `>= 0`, `ln` and `powf` arguments `> 0`; and
/// every guarded expression must stay clear of zero between them (`clear_of_zero_fn`).
fn domain_check(e: &Emission<'_>) -> TokenStream {
    let Emission { g, sig, guards, .. } = e;
    let scheme = e.scheme();
    let mut out = clear_of_zero_fn();
    let plain: Vec<&(Guard, [Id; 3])> = guards
        .iter()
        .filter(|(guard, _)| guard.slice.is_none())
        .collect();
    if !plain.is_empty() {
        let roots: Vec<Id> = plain.iter().flat_map(|(_, p)| p.iter().copied()).collect();
        let code = emit(g, &roots, &scheme);
        let stmts = code.stmts;
        out.extend(quote!(#stmts));
        for (i, (guard, _)) in plain.iter().enumerate() {
            out.extend(check(
                e,
                guard,
                &code.exprs[3 * i..3 * i + 3],
                quote!(::core::option::Option::None),
            ));
        }
    }
    for (guard, points) in guards.iter().filter(|(guard, _)| guard.slice.is_some()) {
        let Some(param) = guard.slice else { continue };
        let code = emit(g, points, &scheme);
        let stmts = code.stmts;
        let name = &sig.params[param as usize].name;
        let test = check(
            e,
            guard,
            &code.exprs,
            quote!(::core::option::Option::Some(__k)),
        );
        out.extend(quote! {
            for (__k, __e) in self.#name.iter().enumerate() {
                #stmts
                #test
            }
        });
    }
    out
}

/// The test of one guard on its `values` at the three points, returning the violation with
/// `element` (the index of the slice element, if any) when it fails.
fn check(
    e: &Emission<'_>,
    guard: &Guard,
    values: &[TokenStream],
    element: TokenStream,
) -> TokenStream {
    let core = &e.core;
    let (a, b, c) = (&values[0], &values[1], &values[2]);
    let text = &guard.text;
    let sign = if guard.factor {
        GuardKind::Denominator
    } else {
        guard.kind
    };
    let condition = match sign {
        // finite, non-zero and of one sign (NaN fails every comparison)
        GuardKind::Denominator => quote!((#a > 0.0 && #b > 0.0 && #c > 0.0
                && #a < ::core::f64::INFINITY && #b < ::core::f64::INFINITY
                && #c < ::core::f64::INFINITY)
            || (#a < 0.0 && #b < 0.0 && #c < 0.0 && #a > ::core::f64::NEG_INFINITY
                && #b > ::core::f64::NEG_INFINITY && #c > ::core::f64::NEG_INFINITY)),
        GuardKind::SqrtArgument => quote!(#a >= 0.0 && #b >= 0.0 && #c >= 0.0),
        GuardKind::LnArgument | GuardKind::PowfBase | GuardKind::AsinArgument => {
            quote!(#a > 0.0 && #b > 0.0 && #c > 0.0)
        }
    };
    let kind = match guard.kind {
        GuardKind::Denominator => quote!(Denominator),
        GuardKind::SqrtArgument => quote!(SqrtArgument),
        GuardKind::LnArgument => quote!(LnArgument),
        GuardKind::PowfBase => quote!(PowfBase),
        GuardKind::AsinArgument => quote!(AsinArgument),
    };
    let condition = if guard.touch {
        quote!((#condition) && __clear_of_zero(#a, #b, #c, theta))
    } else {
        condition
    };
    quote! {
        if !(#condition) {
            return ::core::result::Result::Err(#core::DomainViolation {
                expression: #text,
                kind: #core::DomainKind::#kind,
                element: #element,
            });
        }
    }
}
