//! The `Separable` impl, where L = c/2 |u|^2 + V(q) (`crate::mechanics::separable`): the weight c, for
//! the explicit splitting of `retract_core::split`.

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use crate::emit::codegen::emit;
use crate::mechanics::separable;

/// `impl Separable<n, k>` with `kinetic_weight` = c, or nothing when L is not of the form.
pub(crate) fn separable_impl(e: &Emission<'_>) -> Option<TokenStream> {
    let c = separable::kinetic_weight(e.g, e.mech, e.n, e.k)?;
    let (n_lit, k_lit, float) = (&e.n_lit, &e.k_lit, &e.float);
    let header = e.impl_header(quote!(Separable<#n_lit, #k_lit>));
    let code = emit(e.g, &[c], &e.scheme());
    let (stmts, value) = (&code.stmts, &code.exprs[0]);
    Some(quote! {
        #header {
            /// The weight c of L = c/2 |u|^2 + V(q), read off d2L/du2 at compile time.
            fn kinetic_weight(&self) -> f64 {
                #float
                #stmts
                #value
            }
        }
    })
}
