//! The `LiftedSystem` impl: the lifted theta-scheme of the Lagrangian on the Hamiltonian
//! state z = (x, p) of size s = 2nk with the Newton unknowns w = (z_1, u) of size
//! m = 2nk + n (formulas in `retract_core::LiftedSystem`). Its residual F(z0, w) and the
//! Jacobians dF/dw and dF/dz0 are straight-line code over their structural nonzeros (where
//! the mechanics were built structurally, `mechanics::Derivation`, calls to the generic
//! `retract_core::lifted::{residual, jacobian, jacobian_initial}`, which evaluate the same
//! formulas from the `Lagrangian` impl's gradient and Hessian at the evaluation point); the
//! Hamiltonian, the vector field, the Legendre map, the step cost and the predictor call the
//! generic implementations in `retract_core::lifted`; `check_domain` is emitted by `domain`.

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use super::domain::check_domain;
use super::helpers::index;
use crate::emit::codegen::emit;
use crate::front::signature::Kind;

/// `impl LiftedSystem<s, m>`.
pub(crate) fn lifted_system_impl(e: &Emission<'_>) -> TokenStream {
    let Emission {
        g,
        mech,
        s,
        m,
        n_lit,
        k_lit,
        s_lit,
        m_lit,
        core,
        na,
        vec_s,
        vec_m,
        vec_m_path,
        float,
        ..
    } = e;
    let header = e.impl_header(quote!(LiftedSystem<#s_lit, #m_lit>));
    let generic = |f: TokenStream| quote!(#core::#f::<Self, #n_lit, #k_lit, #s_lit, #m_lit>(self, z0, w, h, theta));
    let (residual, jacobian, jacobian_initial) = match &mech.scheme {
        Some(scheme) => {
            let residual = emit(g, &scheme.residual, &e.scheme());
            let r_stmts = residual.stmts;
            let r_sets = scheme.residual.iter().enumerate().filter_map(|(r, &id)| {
                if g.is_const(id, 0.0) {
                    return None;
                }
                let v = &residual.exprs[r];
                let r = index(r);
                Some(quote!(__out[#r] = #v;))
            });
            let residual = quote! {
                #float
                #r_stmts
                let mut __out = #vec_m_path::zeros();
                #(#r_sets)*
                __out
            };
            (
                residual,
                e.matrix_body(&scheme.jacobian, *m),
                e.matrix_body(&scheme.jacobian_initial, *s),
            )
        }
        None => (
            generic(quote!(residual)),
            generic(quote!(jacobian)),
            generic(quote!(jacobian_initial)),
        ),
    };
    let check_domain = check_domain(e);
    let check_parameters = check_parameters(e);

    quote! {
        #header {
            const DIMENSION: usize = #n_lit;
            const ORDER: usize = #k_lit;

            /// The Ostrogradsky Hamiltonian H(x, p).
            fn hamiltonian(&self, z: &#vec_s) -> ::core::result::Result<f64, #core::Error> {
                #core::hamiltonian::<Self, #n_lit, #k_lit, #s_lit>(self, z)
            }

            /// Hamilton's equations.
            fn vector_field(&self, z: &#vec_s) -> ::core::result::Result<#vec_s, #core::Error> {
                #core::vector_field::<Self, #n_lit, #k_lit, #s_lit>(self, z)
            }

            /// The Legendre map (q, ..., q^(2k-1)) -> (x, p).
            fn legendre(&self, jet: &#vec_s) -> #vec_s {
                #core::legendre::<Self, #n_lit, #k_lit, #s_lit>(self, jet)
            }

            /// F(z0, w) of the lifted theta-scheme.
            fn residual(&self, z0: &#vec_s, w: &#vec_m, h: f64, theta: f64) -> #vec_m {
                #residual
            }

            /// dF/dw of the lifted theta-scheme; structural zeros are not computed.
            fn jacobian(
                &self,
                z0: &#vec_s,
                w: &#vec_m,
                h: f64,
                theta: f64,
            ) -> #na::SMatrix<f64, #m_lit, #m_lit> {
                #jacobian
            }

            /// dF/dz0 of the lifted theta-scheme; structural zeros are not computed.
            fn jacobian_initial(
                &self,
                z0: &#vec_s,
                w: &#vec_m,
                h: f64,
                theta: f64,
            ) -> #na::SMatrix<f64, #m_lit, #s_lit> {
                #jacobian_initial
            }

            /// h L(x_theta, u), the cost of one step.
            fn step_cost(&self, z0: &#vec_s, w: &#vec_m, h: f64, theta: f64) -> f64 {
                #core::step_cost::<Self, #n_lit, #k_lit, #s_lit, #m_lit>(self, z0, w, h, theta)
            }

            #check_domain

            #check_parameters

            /// Explicit Euler guess of w.
            fn predictor(
                &self,
                z0: &#vec_s,
                h: f64,
                _theta: f64,
            ) -> ::core::result::Result<#vec_m, #core::Error> {
                #core::predictor::<Self, #n_lit, #k_lit, #s_lit, #m_lit>(self, z0, h)
            }
        }
    }
}

/// `check_parameters`: every scalar, array component and list element component of the
/// parameters is finite, else `Error::NonFiniteParameter` naming the first that is not
/// (nothing emitted without parameters: the trait's default is `Ok`).
fn check_parameters(e: &Emission<'_>) -> TokenStream {
    let core = &e.core;
    if e.sig.params.is_empty() {
        return quote!();
    }
    let saturate = quote!(|i: usize| u32::try_from(i).unwrap_or(u32::MAX));
    let checks = e.sig.params.iter().map(|p| {
        let field = &p.name;
        let name = p.name.to_string();
        let fail = |element: TokenStream, index: TokenStream| {
            quote! {
                return ::core::result::Result::Err(#core::Error::NonFiniteParameter {
                    name: #name,
                    element: #element,
                    index: #index,
                });
            }
        };
        match p.kind {
            Kind::Scalar => {
                let fail = fail(quote!(None), quote!(None));
                quote!(if !self.#field.is_finite() { #fail })
            }
            Kind::Array(_) => {
                let fail = fail(quote!(None), quote!(Some(__u32(__i))));
                quote! {
                    for (__i, __v) in self.#field.iter().enumerate() {
                        if !__v.is_finite() { #fail }
                    }
                }
            }
            Kind::Slice(_) => {
                let fail = fail(quote!(Some(__u32(__k))), quote!(Some(__u32(__i))));
                quote! {
                    for (__k, __e) in self.#field.iter().enumerate() {
                        for (__i, __v) in __e.iter().enumerate() {
                            if !__v.is_finite() { #fail }
                        }
                    }
                }
            }
        }
    });
    quote! {
        /// Whether every parameter is finite; the first that is not, by name.
        #[allow(clippy::redundant_closure_call, unused_variables)]
        fn check_parameters(&self) -> ::core::result::Result<(), #core::Error> {
            let __u32 = #saturate;
            #(#checks)*
            ::core::result::Result::Ok(())
        }
    }
}
