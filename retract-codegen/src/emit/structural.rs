//! The methods of a Lagrangian whose mechanics were built structurally
//! (`mechanics::Derivation::structural`: the effort of `#[mechanical_system]` and the plant
//! whose mass matrix varies) that read the Hessian-vector product at run time instead of
//! emitting symbolic derivatives of their own. H d (`mechanics::HessianVector`) is emitted
//! once, as the private method `__hessian_vectors` of the type, which evaluates the nodes that
//! d does not change once and then H d for each direction of a list; with H the Hessian of L
//! in z = (x, u), index `j * n + i` for q^(j)_i:
//!
//! - `hessian`: H e_b for each unit vector e_b (column b), the entries on and above the
//!   diagonal kept and mirrored, so that the Hessian is exactly symmetric;
//! - `momenta` for k = 2: p_1 = dL/dq'' and p_0 = dL/dq' - D p_1, where
//!   D p_1 = sum_b (d p_1 / d z_b) z_b' is the rows of q'' of H d at d = (q', q'', q''');
//! - the Legendre inverse's A = d2L/du2 (the rows of u of H e_{u_c} at u = 0, mirrored as in
//!   `hessian`) and b = dL/du(x, 0) (the gradient at u = 0), for L quadratic in u.

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use super::helpers::{Names, index, xu_leaf};
use crate::emit::codegen::emit;
use crate::mechanics::HessianVector;

/// The inherent impl with `__hessian_vectors(x, u, directions, out)`: `out[c]` = H d_c for
/// each direction d_c of `directions` (module docs).
pub(crate) fn hessian_vectors_method(e: &Emission<'_>, hv: &HessianVector) -> TokenStream {
    let (sig, k) = (e.sig, e.k);
    let (jet_blocks, vec_n, float) = (&e.jet_blocks, &e.vec_n, &e.float);
    let in_xu = |order: u8, i: u32| xu_leaf(k, order, i);
    let xu = Names { sig, jet: &in_xu };
    let hoisted = emit(e.g, &hv.hoisted, &xu);
    let (h_stmts, h_exprs, h_len) = (&hoisted.stmts, &hoisted.exprs, index(hv.hoisted.len()));
    let code = emit(e.g, &hv.column, &xu);
    let (stmts, exprs) = (&code.stmts, &code.exprs);
    let dim = index(e.n * (k + 1));
    let header = e.inherent_header();
    quote! {
        #header {
            /// H d for each direction d of `directions`, into `out` in order (H the Hessian
            /// of L in (x, u), index j n + i for q^(j)_i): the derivative of the gradient
            /// along d, forward over reverse, exact; the nodes that d does not change are
            /// evaluated once.
            fn __hessian_vectors(
                &self,
                x: &#jet_blocks,
                u: &#vec_n,
                directions: &[[f64; #dim]],
                out: &mut [[f64; #dim]],
            ) {
                #float
                #h_stmts
                let __h: [f64; #h_len] = [#(#h_exprs),*];
                for (__d, __column) in directions.iter().zip(out.iter_mut()) {
                    #stmts
                    *__column = [#(#exprs),*];
                }
            }
        }
    }
}

/// The body of `hessian(x, u)`: the columns H e_b from `__hessian_vectors` (module docs).
pub(crate) fn hessian_body(e: &Emission<'_>) -> TokenStream {
    let (core, n_lit, k_lit) = (&e.core, &e.n_lit, &e.k_lit);
    let dim = index(e.n * (e.k + 1));
    quote! {
        let mut __directions = [[0.0f64; #dim]; #dim];
        for (__b, __d) in __directions.iter_mut().enumerate() {
            __d[__b] = 1.0;
        }
        let mut __columns = [[0.0f64; #dim]; #dim];
        self.__hessian_vectors(x, u, &__directions, &mut __columns);
        let mut __out = #core::Hessian::zeros();
        for (__b, __column) in __columns.iter().enumerate() {
            let (__jb, __ib) = (__b / #n_lit, __b % #n_lit);
            for (__a, &__v) in __column.iter().enumerate().take(__b + 1) {
                let (__ja, __ia) = (__a / #n_lit, __a % #n_lit);
                if __jb < #k_lit {
                    __out.xx[__ja][__jb][(__ia, __ib)] = __v;
                    __out.xx[__jb][__ja][(__ib, __ia)] = __v;
                } else if __ja < #k_lit {
                    __out.xu[__ja][(__ia, __ib)] = __v;
                } else {
                    __out.uu[(__ia, __ib)] = __v;
                    __out.uu[(__ib, __ia)] = __v;
                }
            }
        }
        __out
    }
}

/// The body of `momenta(lower, upper)` for k = 2 (module docs); `None` for another order.
pub(crate) fn momenta_body(e: &Emission<'_>) -> Option<TokenStream> {
    if e.k != 2 {
        return None;
    }
    let (core, na, n_lit, k_lit) = (&e.core, &e.na, &e.n_lit, &e.k_lit);
    let (dim, n2) = (index(3 * e.n), index(2 * e.n));
    Some(quote! {
        let __g = <Self as #core::Lagrangian<#n_lit, #k_lit>>::gradient(self, lower, &upper[0]);
        let mut __d = [[0.0f64; #dim]; 1];
        for __i in 0..#n_lit {
            __d[0][__i] = lower[1][__i];
            __d[0][#n_lit + __i] = upper[0][__i];
            __d[0][#n2 + __i] = upper[1][__i];
        }
        let mut __hd = [[0.0f64; #dim]; 1];
        self.__hessian_vectors(lower, &upper[0], &__d, &mut __hd);
        let mut __out = [#na::SVector::<f64, #n_lit>::zeros(); #k_lit];
        for __i in 0..#n_lit {
            __out[1][__i] = __g.u[__i];
            __out[0][__i] = __g.x[1][__i] - __hd[0][#n2 + __i];
        }
        __out
    })
}

/// The Legendre inverse's inputs at run time (module docs): the statements, then the
/// entries of A (row-major, n x n; none where `constant_a`, A^{-1} being known) and of b.
pub(crate) fn legendre_inputs(
    e: &Emission<'_>,
    constant_a: bool,
) -> (TokenStream, Vec<TokenStream>, Vec<TokenStream>) {
    let (core, n_lit, k_lit, vec_n_path) = (&e.core, &e.n_lit, &e.k_lit, &e.vec_n_path);
    let (n, k) = (e.n, e.k);
    let (top, dim) = (index(k * n), index(n * (k + 1)));
    let gradient = quote! {
        let __zero = #vec_n_path::zeros();
        let __g = <Self as #core::Lagrangian<#n_lit, #k_lit>>::gradient(self, x, &__zero);
    };
    let b = (0..n)
        .map(|i| {
            let i = index(i);
            quote!(__g.u[#i])
        })
        .collect();
    if constant_a {
        return (gradient, Vec::new(), b);
    }
    let a = (0..n * n)
        .map(|entry| {
            let (r, c) = (entry / n, entry % n);
            let (column, row) = (index(r.max(c)), index(k * n + r.min(c)));
            quote!(__columns[#column][#row])
        })
        .collect();
    let stmts = quote! {
        #gradient
        let mut __directions = [[0.0f64; #dim]; #n_lit];
        for (__c, __d) in __directions.iter_mut().enumerate() {
            __d[#top + __c] = 1.0;
        }
        let mut __columns = [[0.0f64; #dim]; #n_lit];
        self.__hessian_vectors(x, &__zero, &__directions, &mut __columns);
    };
    (stmts, a, b)
}
