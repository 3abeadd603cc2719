//! The named outputs of a Lagrangian (`#[output] let tau = ...;`): one method of the generated
//! type per output, evaluating it at `(x, u)` as straight-line code, so that a plan, a plant
//! or a controller reads the same formula as the Lagrangian.

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use super::helpers::{Names, ParamTokens, xu_leaf};
use crate::emit::codegen::emit;
use crate::front::lower::Output;

/// `impl Type { pub fn name(&self, x, u) -> f64 | [f64; len] }` for the outputs (nothing
/// without any).
pub(crate) fn outputs_impl(e: &Emission<'_>, outputs: &[Output]) -> TokenStream {
    if outputs.is_empty() {
        return TokenStream::new();
    }
    let (sig, g, k) = (e.sig, e.g, e.k);
    let (jet_blocks, vec_n, float, allow) = (&e.jet_blocks, &e.vec_n, &e.float, &e.allow);
    let in_xu = |order: u8, i: u32| xu_leaf(k, order, i);
    let xu = Names { sig, jet: &in_xu };
    let function = &e.function.sig.ident;
    let methods = outputs.iter().map(|output| {
        let code = emit(g, &output.ids, &xu);
        let (stmts, exprs) = (code.stmts, code.exprs);
        let name = &output.name;
        let doc = format!(
            " `{name}` of `{function}` at the jet x = (q, ..., q^(k-1)) and u = q^(k): \
             straight-line code of its `#[output] let`."
        );
        let (ty, value) = if output.array {
            let len = proc_macro2::Literal::usize_unsuffixed(exprs.len());
            (quote!([f64; #len]), quote!([#(#exprs),*]))
        } else {
            (quote!(f64), quote!(#(#exprs)*))
        };
        quote! {
            #[doc = #doc]
            #[must_use]
            pub fn #name(&self, x: &#jet_blocks, u: &#vec_n) -> #ty {
                #float
                #stmts
                #value
            }
        }
    });
    let ParamTokens {
        generics, ty_full, ..
    } = &e.params;
    quote! {
        #allow
        impl #generics #ty_full {
            #(#methods)*
        }
    }
}
