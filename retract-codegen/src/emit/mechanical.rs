//! The items of a mechanical system (`#[mechanical_system]`) beyond those of its order-2
//! optimal-control Lagrangian: the inherent methods `tau` (inverse dynamics), `mass_matrix`
//! and `unactuated_torques` with the constants `ACTUATED` and `UNACTUATED`, and the impl of
//! `retract_core::MechanicalSystem` (each unactuated component of tau with its gradient and
//! Hessian in (x, u), for the optimizer's stage equalities).

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use super::helpers::{Names, ParamTokens, index};
use super::scalar::{ScalarBodies, scalar_bodies};
use crate::emit::codegen::emit;
use crate::mechanics::euler_lagrange::EulerLagrange;

/// The inherent impl and the `MechanicalSystem` impl of the system `e` with the
/// Euler-Lagrange operator `el` and the actuated coordinates `actuated`.
pub(crate) fn mechanical_impl(
    e: &Emission<'_>,
    plant: &Emission<'_>,
    el: &EulerLagrange,
    actuated: &[usize],
) -> TokenStream {
    let mut out = inherent(e, el, actuated);
    out.extend(plant_methods(e, plant, actuated));
    out.extend(mechanical_system_impl(e, el, actuated));
    out
}

/// `impl Type { ACTUATED, UNACTUATED, tau, mass_matrix, unactuated_torques }`.
fn inherent(e: &Emission<'_>, el: &EulerLagrange, actuated: &[usize]) -> TokenStream {
    let (g, n) = (e.g, e.n);
    let (na, core, vec_n, vec_n_path, n_lit) = (&e.na, &e.core, &e.vec_n, &e.vec_n_path, &e.n_lit);
    let (float, allow) = (&e.float, &e.allow);
    let in_qdq = |order: u8, i: u32| {
        let i = index(i as usize);
        match order {
            0 => quote!(q[#i]),
            1 => quote!(dq[#i]),
            _ => quote!(ddq[#i]),
        }
    };
    let names = Names {
        sig: e.sig,
        jet: &in_qdq,
    };
    let tau = emit(g, &el.tau, &names);
    let (tau_stmts, tau_exprs) = (&tau.stmts, &tau.exprs);
    let mass = emit(g, &el.mass, &names);
    let mass_sets = el.mass.iter().enumerate().filter_map(|(r, &id)| {
        let v = &mass.exprs[r];
        let (i, j) = (index(r / n), index(r % n));
        (!g.is_const(id, 0.0)).then(|| quote!(__out[(#i, #j)] = #v;))
    });
    let mass_stmts = &mass.stmts;
    let unactuated: Vec<usize> = el.unactuated.iter().map(|u| u.index).collect();
    let (a_len, u_len) = (index(actuated.len()), index(unactuated.len()));
    let (a_list, u_list) = (
        actuated.iter().map(|&i| index(i)),
        unactuated.iter().map(|&i| index(i)),
    );
    let components = unactuated.iter().map(|&c| {
        let c = index(c);
        quote!(#core::TorqueComponent { system: self, index: #c })
    });
    let ParamTokens {
        generics, ty_full, ..
    } = &e.params;
    quote! {
        #[automatically_derived]
        #allow
        impl #generics #ty_full {
            /// The actuated coordinates, ascending.
            pub const ACTUATED: [usize; #a_len] = [#(#a_list),*];
            /// The coordinates no actuator drives, ascending: their tau must vanish.
            pub const UNACTUATED: [usize; #u_len] = [#(#u_list),*];

            /// The inverse dynamics tau(q, q', q'') = d/dt dl/dq' - dl/dq, the generalized
            /// force the motion needs: straight-line code differentiated at compile time.
            #[must_use]
            pub fn tau(&self, q: &#vec_n, dq: &#vec_n, ddq: &#vec_n) -> #vec_n {
                #float
                #tau_stmts
                #vec_n_path::from([#(#tau_exprs),*])
            }

            /// The mass matrix M(q, q') = d2l/dq'2 (for l = T - V with T quadratic in q', a
            /// function of q alone).
            #[must_use]
            pub fn mass_matrix(&self, q: &#vec_n, dq: &#vec_n) -> #na::SMatrix<f64, #n_lit, #n_lit> {
                #float
                #mass_stmts
                let mut __out = #na::SMatrix::<f64, #n_lit, #n_lit>::zeros();
                #(#mass_sets)*
                __out
            }

            /// The equalities tau_c = 0 of the unactuated coordinates (`UNACTUATED`), for
            /// `OptimalControlProblem::with_equalities`.
            #[must_use]
            pub fn unactuated_torques(&self) -> [#core::TorqueComponent<'_, Self>; #u_len] {
                [#(#components),*]
            }
        }
    }
}

/// `impl Type { plant, input_force }`: the plant with the same parameters, and the
/// generalized force B u of an input u on the actuated coordinates.
fn plant_methods(e: &Emission<'_>, plant: &Emission<'_>, actuated: &[usize]) -> TokenStream {
    let (na, vec_n, vec_n_path, allow) = (&e.na, &e.vec_n, &e.vec_n_path, &e.allow);
    let ParamTokens {
        generics, ty_full, ..
    } = &e.params;
    let (plant_ty, plant_name) = (&plant.params.ty_full, &plant.sig.type_name);
    let fields = e.sig.params.iter().map(|p| {
        let name = &p.name;
        quote!(#name: self.#name)
    });
    let a_len = index(actuated.len());
    let sets = actuated.iter().enumerate().map(|(i, &a)| {
        let (i, a) = (index(i), index(a));
        quote!(__out[#a] = u[#i];)
    });
    quote! {
        #[automatically_derived]
        #allow
        impl #generics #ty_full {
            /// The plant: the Lagrangian l(q, q') of order 1 with these parameters, for plant
            /// simulation under an input u by the forced midpoint rule (discrete
            /// Lagrange-d'Alembert), `retract::forced::forced_step(&system.plant(), &z0,
            /// &system.input_force(&u), h, &options)`.
            #[must_use]
            pub fn plant(&self) -> #plant_ty {
                #plant_name { #(#fields),* }
            }

            /// The generalized force B u of the input u: u_i on the i-th actuated coordinate
            /// (`ACTUATED`), zero on the others.
            #[must_use]
            pub fn input_force(&self, u: &#na::SVector<f64, #a_len>) -> #vec_n {
                let mut __out = #vec_n_path::zeros();
                #(#sets)*
                __out
            }
        }
    }
}

/// `impl MechanicalSystem<n>`: the unactuated components of tau in (x, u).
fn mechanical_system_impl(e: &Emission<'_>, el: &EulerLagrange, actuated: &[usize]) -> TokenStream {
    let (core, n_lit, vec_n, jet_blocks) = (&e.core, &e.n_lit, &e.vec_n, &e.jet_blocks);
    let header = e.impl_header(quote!(MechanicalSystem<#n_lit>));
    let mut values = Vec::new();
    let mut gradients = Vec::new();
    let mut hessians = Vec::new();
    for component in &el.unactuated {
        let ScalarBodies {
            value,
            gradient,
            hessian,
        } = scalar_bodies(
            e.g,
            e.sig,
            component.value,
            &component.gradient,
            &component.hessian,
        );
        let c = index(component.index);
        values.push(quote!(#c => { #value }));
        gradients.push(quote!(#c => { #gradient }));
        hessians.push(quote!(#c => { #hessian }));
    }
    let a_list = actuated.iter().map(|&i| index(i));
    let u_list = el.unactuated.iter().map(|u| index(u.index));
    let name = e.sig.type_name.to_string();
    quote! {
        #header {
            fn actuated(&self) -> &'static [usize] {
                &[#(#a_list),*]
            }

            fn unactuated(&self) -> &'static [usize] {
                &[#(#u_list),*]
            }

            /// tau_c(x, u) of an unactuated c, straight-line code (NaN for another c).
            fn torque_value(&self, c: usize, x: &#jet_blocks, u: &#vec_n) -> f64 {
                match c {
                    #(#values)*
                    _ => f64::NAN,
                }
            }

            /// The gradient of tau_c of an unactuated c (zero for another c).
            fn torque_gradient(&self, c: usize, x: &#jet_blocks, u: &#vec_n) -> #core::Gradient<#n_lit, 2> {
                match c {
                    #(#gradients)*
                    _ => #core::Gradient::zeros(),
                }
            }

            /// The Hessian of tau_c of an unactuated c (zero for another c).
            fn torque_hessian(&self, c: usize, x: &#jet_blocks, u: &#vec_n) -> #core::Hessian<#n_lit, 2> {
                match c {
                    #(#hessians)*
                    _ => #core::Hessian::zeros(),
                }
            }

            fn system_name(&self) -> &'static str {
                #name
            }
        }
    }
}
