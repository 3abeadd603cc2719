//! The `check_domain` method of the `LiftedSystem` impl: the singularity guard of a step.
//!
//! Each guarded expression of L (a denominator, each factor of a guarded expression, a
//! `sqrt`, `ln` or `powf` argument) is evaluated at x_0, x_1 and x_theta of a step, one loop
//! over the elements per guard that reads a slice parameter. A denominator (and each factor)
//! must be finite, non-zero and of one sign at the three points, a `sqrt` argument `>= 0`,
//! `ln` and `powf` arguments `> 0`; and every irreducible factor must stay clear of zero
//! between them: the quadratic through the three samples may not come within
//! 10^-9 of the largest sample of zero inside the step
//! (`retract_core::scheme::guard_fit::clear_of_zero`, called by the emitted code).
//! Where every guard is a polynomial of degree at most 2 in the jet, that quadratic is the
//! guard along the chord, and the impl also says `guards_quadratic` (the step's check then
//! skips the chord's pieces).
//! The first violation is returned as a `DomainViolation` naming the expression as written.

use proc_macro2::TokenStream;
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
        #[inline(always)]
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

/// `check_domain`: each guard at the three points of a step, one loop per slice guard. A
/// denominator (and each factor of a guarded expression) must be finite, non-zero and of one
/// sign at the three points, a `sqrt` argument `>= 0`, `ln` and `powf` arguments `> 0`; and
/// every guarded expression must stay clear of zero between them
/// (`retract_core::scheme::guard_fit::clear_of_zero`).
fn domain_check(e: &Emission<'_>) -> TokenStream {
    let Emission { g, sig, guards, .. } = e;
    let scheme = e.scheme();
    let mut out = TokenStream::new();
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
        quote!((#condition) && #core::clear_of_zero(#a, #b, #c, theta))
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
