//! The `Lagrangian` impl: L(x, u), its gradient (dL/dx_0, ..., dL/dx_{k-1}, dL/du) and
//! Hessian in (x, u), and the three in one body (`scalar`), the Ostrogradsky momenta
//! p_{k-1} = dL/dq^(k), p_{j-1} = dL/dq^(j) - D p_j, and, where L is quadratic in u = q^(k),
//! the Legendre inverse u = A^{-1} (p_{k-1} - dL/du(x, 0)) with A = d2L/du2: A^{-1} computed
//! at compile time when A is constant, else an LU solve at run time.

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use super::helpers::{Names, index, xu_leaf};
use super::scalar::{ScalarBodies, derivatives_body, scalar_bodies};
use super::structural;
use crate::emit::codegen::{constant, emit};
use crate::ir::graph::Id;
use crate::mechanics::LegendreInverse;

/// `impl Lagrangian<n, k>`.
pub(crate) fn lagrangian_impl(e: &Emission<'_>) -> TokenStream {
    let Emission {
        sig,
        g,
        mech,
        n_lit,
        k_lit,
        core,
        na,
        vec_n,
        jet_blocks,
        float,
        ..
    } = e;
    let header = e.impl_header(quote!(Lagrangian<#n_lit, #k_lit>));
    // (with a Hessian-vector product, the Hessian's nodes are the rows of u alone: not emitted)
    let entries: &[Vec<Id>] = match mech.hessian_vector {
        Some(_) => &[],
        None => &mech.hessian,
    };
    let ScalarBodies {
        value: l_body,
        gradient: g_body,
        hessian: h_body,
    } = scalar_bodies(g, sig, mech.lagrangian, &mech.gradient, entries);
    // (the three in one body, sharing their subexpressions; with a Hessian-vector product
    // the trait's default, which calls the three)
    let derivatives = mech.hessian_vector.is_none().then(|| {
        let body = derivatives_body(g, sig, mech.lagrangian, &mech.gradient, entries);
        quote! {
            /// L, its gradient and its Hessian in (x, u) as one straight-line code: the
            /// subexpressions they share are computed once.
            fn derivatives(&self, x: &#jet_blocks, u: &#vec_n) -> #core::Derivatives<#n_lit, #k_lit> {
                #body
            }
        }
    });
    let (h_body, h_doc, hessian_vectors) = match &mech.hessian_vector {
        Some(hv) => (
            {
                let body = structural::hessian_body(e);
                quote!(#float #body)
            },
            "The Hessian of L in (x, u), column by column: the Hessian-vector product (the \
             derivative of the gradient along a direction) at each unit vector.",
            Some(structural::hessian_vectors_method(e, hv)),
        ),
        None => (
            h_body,
            "The Hessian of L in (x, u); structural zeros are not computed.",
            None,
        ),
    };
    let momenta_body = match mech
        .hessian_vector
        .as_ref()
        .and(structural::momenta_body(e))
    {
        Some(body) => quote!(#float #body),
        None => {
            let (p_stmts, p_sets) = momenta(e);
            quote! {
                #float
                #p_stmts
                let mut __out = [#na::SVector::<f64, #n_lit>::zeros(); #k_lit];
                #(#p_sets)*
                __out
            }
        }
    };
    let top_derivative = mech
        .legendre_inverse
        .as_ref()
        .map(|inv| top_derivative(e, inv));

    quote! {
        #header {
            /// L(x, u), straight-line code of the annotated function.
            fn lagrangian(&self, x: &#jet_blocks, u: &#vec_n) -> f64 {
                #l_body
            }

            /// (dL/dx_0, ..., dL/dx_{k-1}, dL/du), differentiated at compile time.
            fn gradient(&self, x: &#jet_blocks, u: &#vec_n) -> #core::Gradient<#n_lit, #k_lit> {
                #g_body
            }

            #[doc = #h_doc]
            fn hessian(&self, x: &#jet_blocks, u: &#vec_n) -> #core::Hessian<#n_lit, #k_lit> {
                #h_body
            }

            #derivatives

            /// Ostrogradsky momenta p_{k-1} = dL/dq^(k), p_{j-1} = dL/dq^(j) - D p_j.
            fn momenta(&self, lower: &#jet_blocks, upper: &#jet_blocks) -> #jet_blocks {
                #momenta_body
            }

            #top_derivative
        }

        #hessian_vectors
    }
}

/// The statements and the `__out[j][i] = ...;` assignments of the momenta, as functions of
/// `lower` = (q, ..., q^(k-1)) and `upper` = (q^(k), ..., q^(2k-1)).
fn momenta(e: &Emission<'_>) -> (TokenStream, Vec<TokenStream>) {
    let (g, n, k) = (e.g, e.n, e.k);
    let in_jet = |order: u8, i: u32| {
        let i = index(i as usize);
        if (order as usize) < k {
            let o = index(order as usize);
            quote!(lower[#o][#i])
        } else {
            let o = index(order as usize - k);
            quote!(upper[#o][#i])
        }
    };
    let jet = Names {
        sig: e.sig,
        jet: &in_jet,
    };
    let momenta = emit(g, &e.mech.momenta, &jet);
    let sets = e
        .mech
        .momenta
        .iter()
        .enumerate()
        .filter_map(|(a, &id)| {
            if g.is_const(id, 0.0) {
                return None;
            }
            let v = &momenta.exprs[a];
            let (j, i) = (index(a / n), index(a % n));
            Some(quote!(__out[#j][#i] = #v;))
        })
        .collect();
    (momenta.stmts, sets)
}

/// The method `top_derivative`: the Legendre inverse u(x, p_{k-1}) for L quadratic in u.
fn top_derivative(e: &Emission<'_>, inv: &LegendreInverse) -> TokenStream {
    let Emission {
        sig,
        g,
        n,
        k,
        k_lit,
        core,
        vec_n,
        ..
    } = e;
    // (structural: b from the gradient at u = 0 and A from the Hessian-vector product)
    let (stmts, a, b) = if e.mech.hessian_vector.is_some() {
        structural::legendre_inputs(e, inv.a_inv.is_some())
    } else {
        let in_xu = |order: u8, i: u32| xu_leaf(*k, order, i);
        let xu = Names { sig, jet: &in_xu };
        let mut roots = inv.b.clone();
        roots.extend(inv.a.iter().copied());
        let mut code = emit(g, &roots, &xu);
        let a = code.exprs.split_off(*n);
        (code.stmts, a, code.exprs)
    };
    let rhs: Vec<TokenStream> = b
        .iter()
        .enumerate()
        .map(|(i, bi)| {
            let ii = index(i);
            quote!(p_top[#ii] - #bi)
        })
        .collect();
    let solve = legendre_solve(e, inv, &a, &rhs);
    let doc = if inv.a_inv.is_some() {
        "Closed-form Legendre inverse: L is quadratic in u with a constant Hessian A, so \
         u = A^{-1} (p_{k-1} - dL/du(x, 0)), with A^{-1} computed at compile time."
    } else {
        "Legendre inverse for L quadratic in u: solves A(x) u = p_{k-1} - dL/du(x, 0) with \
         A = d2L/du2 (independent of u), by LU."
    };
    quote! {
        #[doc = #doc]
        fn top_derivative(
            &self,
            x: &[#vec_n; #k_lit],
            p_top: &#vec_n,
            _guess: &#vec_n,
        ) -> ::core::result::Result<#vec_n, #core::Error> {
            #[allow(unused_imports)]
            use ::retract::__private::Float as _;
            #stmts
            #solve
        }
    }
}

/// u = A^{-1} rhs, rhs = p_{k-1} - b(x): a product with the constant A^{-1} when it is
/// known, else an LU solve of A(x) u = rhs with `a` the entries of A (row-major).
fn legendre_solve(
    e: &Emission<'_>,
    inv: &LegendreInverse,
    a: &[TokenStream],
    rhs: &[TokenStream],
) -> TokenStream {
    let Emission {
        n,
        n_lit,
        core,
        na,
        vec_n_path,
        ..
    } = e;
    let n = *n;
    match &inv.a_inv {
        Some(a_inv) => {
            let rows = (0..n).map(|r| {
                let terms = (0..n).filter(|c| a_inv[r * n + c] != 0.0).map(|c| {
                    let v = constant(a_inv[r * n + c]);
                    let c = index(c);
                    quote!(+ #v * __rhs[#c])
                });
                quote!(0.0 #(#terms)*)
            });
            quote! {
                let __rhs: [f64; #n_lit] = [#(#rhs),*];
                // `from` an array: nalgebra's `new` takes the entries only for n <= 6
                ::core::result::Result::Ok(#vec_n_path::from([#(#rows),*]))
            }
        }
        None => {
            let entries = (0..n * n).map(|entry| {
                let (r, c) = (index(entry / n), index(entry % n));
                let v = &a[entry];
                quote!(__a[(#r, #c)] = #v;)
            });
            quote! {
                let mut __a = #na::SMatrix::<f64, #n_lit, #n_lit>::zeros();
                #(#entries)*
                let __rhs = #vec_n_path::from([#(#rhs),*]);
                #core::solve(&__a, &__rhs)
                    .ok_or(#core::Error::SingularJacobian { iteration: 0 })
            }
        }
    }
}
