//! The value, gradient and Hessian of a scalar function of the jet as straight-line method
//! bodies in `(x, u)`: the `lagrangian`, `gradient` and `hessian` of the `Lagrangian` impl and
//! the `value`, `gradient` and `hessian` of a `JetFunction`, and the three in one body (the
//! `Lagrangian`'s `derivatives`).

use proc_macro2::TokenStream;
use quote::quote;

use super::helpers::{Names, float_import, index, xu_leaf};
use crate::emit::codegen::emit;
use crate::front::signature::Signature;
use crate::ir::graph::{Graph, Id};
use crate::util::core_path;

/// The bodies of the value, gradient and Hessian methods of a scalar function of the jet,
/// in `(x, u)`: shared by `Lagrangian` and `JetFunction`.
pub(crate) struct ScalarBodies {
    /// The value (`lagrangian` / `value`).
    pub value: TokenStream,
    /// The gradient, as a `Gradient`.
    pub gradient: TokenStream,
    /// The Hessian, as a `Hessian`; structural zeros are not computed.
    pub hessian: TokenStream,
}

/// Straight-line bodies for `value`, its `gradient` (entry `j * n + i` is d/dq^(j)_i) and its
/// symmetric `hessian` over the same index, as built by `mechanics::derivatives` (the
/// Hessian from a Hessian-vector product is `structural`'s).
pub(crate) fn scalar_bodies(
    g: &Graph,
    sig: &Signature,
    value: Id,
    gradient: &[Id],
    hessian: &[Vec<Id>],
) -> ScalarBodies {
    let core = core_path();
    let float = float_import();
    let in_xu = |order: u8, i: u32| xu_leaf(sig.order, order, i);
    let xu = Names { sig, jet: &in_xu };

    let value_code = emit(g, &[value], &xu);
    let (l_stmts, l_expr) = (value_code.stmts, &value_code.exprs[0]);

    let gradient_code = emit(g, gradient, &xu);
    let g_stmts = gradient_code.stmts;
    let g_sets = gradient_sets(g, sig, gradient, &gradient_code.exprs, &quote!(__out));

    let flat_h: Vec<_> = hessian.iter().flatten().copied().collect();
    let hessian_code = emit(g, &flat_h, &xu);
    let h_stmts = hessian_code.stmts;
    let h_sets = hessian_sets(g, sig, &flat_h, &hessian_code.exprs, &quote!(__out));

    ScalarBodies {
        value: quote! {
            #float
            #l_stmts
            #l_expr
        },
        gradient: quote! {
            #float
            #g_stmts
            let mut __out = #core::Gradient::zeros();
            #(#g_sets)*
            __out
        },
        hessian: quote! {
            #float
            #h_stmts
            let mut __out = #core::Hessian::zeros();
            #(#h_sets)*
            __out
        },
    }
}

/// The body of `derivatives`: the value, the gradient and the Hessian of [`scalar_bodies`]
/// as one straight-line code (one `emit` of all their roots, so that every subexpression
/// they share is computed once), returning a `Derivatives`.
pub(crate) fn derivatives_body(
    g: &Graph,
    sig: &Signature,
    value: Id,
    gradient: &[Id],
    hessian: &[Vec<Id>],
) -> TokenStream {
    let core = core_path();
    let float = float_import();
    let in_xu = |order: u8, i: u32| xu_leaf(sig.order, order, i);
    let xu = Names { sig, jet: &in_xu };
    let mut roots = vec![value];
    roots.extend_from_slice(gradient);
    let flat_h: Vec<_> = hessian.iter().flatten().copied().collect();
    roots.extend_from_slice(&flat_h);
    let code = emit(g, &roots, &xu);
    let stmts = code.stmts;
    let value_expr = &code.exprs[0];
    let gradient_exprs = &code.exprs[1..1 + gradient.len()];
    let hessian_exprs = &code.exprs[1 + gradient.len()..];
    let g_sets = gradient_sets(g, sig, gradient, gradient_exprs, &quote!(__out.gradient));
    let h_sets = hessian_sets(g, sig, &flat_h, hessian_exprs, &quote!(__out.hessian));
    quote! {
        #float
        #stmts
        let mut __out = #core::Derivatives {
            value: #value_expr,
            gradient: #core::Gradient::zeros(),
            hessian: #core::Hessian::zeros(),
        };
        #(#g_sets)*
        #(#h_sets)*
        __out
    }
}

/// The assignments `out.x[j][i] = e;` (`out.u[i]` for the top derivative) of the nonzero
/// gradient entries `gradient` (entry `j * n + i`), whose expressions are `exprs`.
fn gradient_sets(
    g: &Graph,
    sig: &Signature,
    gradient: &[Id],
    exprs: &[TokenStream],
    out: &TokenStream,
) -> Vec<TokenStream> {
    let (n, k) = (sig.dim, sig.order);
    let entries = gradient.iter().zip(exprs).enumerate();
    entries
        .filter(|(_, (id, _))| !g.is_const(**id, 0.0))
        .map(|(a, (_, e))| {
            let (j, i) = (a / n, index(a % n));
            if j < k {
                let j = index(j);
                quote!(#out.x[#j][#i] = #e;)
            } else {
                quote!(#out.u[#i] = #e;)
            }
        })
        .collect()
}

/// The assignments of the nonzero entries of the flattened symmetric Hessian `flat_h`
/// (row-major over the gradient's index) into `out.xx`, `out.xu` and `out.uu`, whose
/// expressions are `exprs`; the (u, x) block is the transpose of `xu` and is not assigned.
fn hessian_sets(
    g: &Graph,
    sig: &Signature,
    flat_h: &[Id],
    exprs: &[TokenStream],
    out: &TokenStream,
) -> Vec<TokenStream> {
    let (n, k) = (sig.dim, sig.order);
    let dim = n * (k + 1);
    let entries = flat_h.iter().zip(exprs).enumerate();
    entries
        .filter(|(_, (id, _))| !g.is_const(**id, 0.0))
        .filter_map(|(r, (_, e))| {
            let (a, b) = (r / dim, r % dim);
            let (ja, ia, jb, ib) = (a / n, index(a % n), b / n, index(b % n));
            Some(match (ja < k, jb < k) {
                (true, true) => {
                    let (ja, jb) = (index(ja), index(jb));
                    quote!(#out.xx[#ja][#jb][(#ia, #ib)] = #e;)
                }
                (true, false) => {
                    let ja = index(ja);
                    quote!(#out.xu[#ja][(#ia, #ib)] = #e;)
                }
                (false, true) => return None, // the transpose, stored in xu
                (false, false) => quote!(#out.uu[(#ia, #ib)] = #e;),
            })
        })
        .collect()
}
