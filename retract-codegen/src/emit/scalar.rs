//! The value, gradient and Hessian of a scalar function of the jet as straight-line method
//! bodies in `(x, u)`: the `lagrangian`, `gradient` and `hessian` of the `Lagrangian` impl and
//! the `value`, `gradient` and `hessian` of a `JetFunction`.

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
    let (n, k) = (sig.dim, sig.order);
    let core = core_path();
    let float = float_import();
    let in_xu = |order: u8, i: u32| xu_leaf(k, order, i);
    let xu = Names { sig, jet: &in_xu };

    let value_code = emit(g, &[value], &xu);
    let (l_stmts, l_expr) = (value_code.stmts, &value_code.exprs[0]);

    let gradient_code = emit(g, gradient, &xu);
    let g_stmts = gradient_code.stmts;
    let g_sets = gradient.iter().enumerate().filter_map(|(a, &id)| {
        if g.is_const(id, 0.0) {
            return None;
        }
        let e = &gradient_code.exprs[a];
        let (j, i) = (a / n, index(a % n));
        Some(if j < k {
            let j = index(j);
            quote!(__out.x[#j][#i] = #e;)
        } else {
            quote!(__out.u[#i] = #e;)
        })
    });

    let flat_h: Vec<_> = hessian.iter().flatten().copied().collect();
    let hessian_code = emit(g, &flat_h, &xu);
    let h_stmts = hessian_code.stmts;
    let dim = n * (k + 1);
    let h_sets = flat_h.iter().enumerate().filter_map(|(r, &id)| {
        if g.is_const(id, 0.0) {
            return None;
        }
        let e = &hessian_code.exprs[r];
        let (a, b) = (r / dim, r % dim);
        let (ja, ia, jb, ib) = (a / n, index(a % n), b / n, index(b % n));
        Some(match (ja < k, jb < k) {
            (true, true) => {
                let (ja, jb) = (index(ja), index(jb));
                quote!(__out.xx[#ja][#jb][(#ia, #ib)] = #e;)
            }
            (true, false) => {
                let ja = index(ja);
                quote!(__out.xu[#ja][(#ia, #ib)] = #e;)
            }
            (false, true) => return None, // the transpose, stored in xu
            (false, false) => quote!(__out.uu[(#ia, #ib)] = #e;),
        })
    });

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
