//! The items of a mechanical system (`#[mechanical_system]`) beyond those of its order-2
//! optimal-control Lagrangian: the inherent methods `tau` (inverse dynamics), `mass_matrix`,
//! `nonconservative_force`, `input` (the u a motion needs), `unactuated_torques` and, where
//! asked for, `input_functions` with the constants `INPUTS`, `PASSIVE` (and `ACTUATED`,
//! `UNACTUATED` where the actuation names coordinates), `plant` and `input_force`, and the
//! impl of `retract_core::MechanicalSystem` (each passive equality and each input function
//! with its gradient and Hessian in (x, u), for the optimizer's stage constraints).

use proc_macro2::TokenStream;
use quote::quote;

use super::Emission;
use super::helpers::{Names, index};
use super::scalar::{ScalarBodies, scalar_bodies};
use crate::emit::codegen::emit;
use crate::mechanics::euler_lagrange::{Component, EulerLagrange};

/// The inherent impl and the `MechanicalSystem` impl of the system `e` with the
/// Euler-Lagrange operator `el` and the actuated coordinates `actuated`.
pub(crate) fn mechanical_impl(
    e: &Emission<'_>,
    plant: &Emission<'_>,
    el: &EulerLagrange,
    actuated: Option<&[usize]>,
) -> TokenStream {
    let mut out = inherent(e, el, actuated);
    out.extend(plant_methods(e, plant, el));
    out.extend(mechanical_system_impl(e, el, actuated.unwrap_or(&[])));
    out
}

/// `__out[(i, j)] = value;` (or `__out[i]` for a vector: `cols` = 0) for the entries of
/// `entries` (row-major, `cols` columns) that are not zero, with their statements.
fn sets(
    e: &Emission<'_>,
    entries: &[crate::ir::graph::Id],
    cols: usize,
    names: &Names<'_>,
) -> TokenStream {
    let code = emit(e.g, entries, names);
    let stmts = &code.stmts;
    let sets = entries.iter().enumerate().filter_map(|(r, &id)| {
        let v = &code.exprs[r];
        let at = match (r.checked_div(cols), r.checked_rem(cols)) {
            (Some(i), Some(j)) => {
                let (i, j) = (index(i), index(j));
                quote!([(#i, #j)])
            }
            _ => {
                let i = index(r);
                quote!([#i])
            }
        };
        (!e.g.is_const(id, 0.0)).then(|| quote!(__out #at = #v;))
    });
    quote!(#stmts #(#sets)*)
}

/// `impl Type { INPUTS, PASSIVE, (ACTUATED, UNACTUATED,) tau, mass_matrix,
/// nonconservative_force, input, unactuated_torques }`.
fn inherent(e: &Emission<'_>, el: &EulerLagrange, actuated: Option<&[usize]>) -> TokenStream {
    let (g, n) = (e.g, e.n);
    let (na, core, vec_n, vec_n_path, n_lit) = (&e.na, &e.core, &e.vec_n, &e.vec_n_path, &e.n_lit);
    let float = &e.float;
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
    let mass = sets(e, &el.mass, n, &names);
    let forces = sets(e, &el.forces, 0, &names);
    // (with actuated coordinates, u is tau there: read from `tau`, not emitted again)
    let input = match actuated {
        Some(actuated) => {
            let each = actuated.iter().enumerate().map(|(j, &a)| {
                let (j, a) = (index(j), index(a));
                quote!(__out[#j] = __tau[#a];)
            });
            quote! {
                let __tau = self.tau(q, dq, ddq);
                #(#each)*
            }
        }
        None => sets(e, &el.input, 0, &names),
    };
    let m_lit = index(el.input.len());
    let passive: Vec<usize> = el.unactuated.iter().map(|u| u.index).collect();
    let p_len = index(passive.len());
    let p_list = passive.iter().map(|&i| index(i));
    let components = passive.iter().map(|&c| {
        let c = index(c);
        quote!(#core::TorqueComponent { system: self, index: #c })
    });
    let input_functions = (!el.input_functions.is_empty()).then(|| {
        let each = (0..el.input.len()).map(|j| {
            let j = index(j);
            quote!(#core::InputComponent { system: self, index: #j })
        });
        quote! {
            /// The inputs u_j(q, q', q'') (`input`) as functions of the jet, each with its
            /// gradient and Hessian, for bounds on the inputs:
            /// `OptimalControlProblem::with_function_bounds(&inputs[j], lower, upper)`.
            #[must_use]
            pub fn input_functions(&self) -> [#core::InputComponent<'_, Self>; #m_lit] {
                [#(#each),*]
            }
        }
    });
    let coordinates = actuated.map(|actuated| {
        let a_len = index(actuated.len());
        let a_list = actuated.iter().map(|&i| index(i));
        let u_list = passive.iter().map(|&i| index(i));
        quote! {
            /// The actuated coordinates, ascending: the input u is tau there.
            pub const ACTUATED: [usize; #a_len] = [#(#a_list),*];
            /// The coordinates no actuator drives, ascending: their tau must vanish.
            pub const UNACTUATED: [usize; #p_len] = [#(#u_list),*];
        }
    });
    let header = e.inherent_header();
    quote! {
        #header {
            #coordinates
            /// The number m of inputs u.
            pub const INPUTS: usize = #m_lit;
            /// The labels of the passive equalities (`unactuated_torques`): the unactuated
            /// coordinates c (tau_c = 0), or 0 for a^T tau = 0 of an actuation matrix B of
            /// n - 1 columns (a spanning the vectors that B^T annihilates).
            pub const PASSIVE: [usize; #p_len] = [#(#p_list),*];

            /// The inverse dynamics tau(q, q', q'') = d/dt dl/dq' - dl/dq - Q_nc(q, q'), the
            /// generalized force the motion needs from the inputs: straight-line code
            /// differentiated at compile time.
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
                let mut __out = #na::SMatrix::<f64, #n_lit, #n_lit>::zeros();
                #mass
                __out
            }

            /// The non-conservative generalized forces Q_nc(q, q') (zero without `forces`).
            #[must_use]
            pub fn nonconservative_force(&self, q: &#vec_n, dq: &#vec_n) -> #vec_n {
                #float
                let mut __out = #vec_n_path::zeros();
                #forces
                __out
            }

            /// The input u(q, q', q'') the motion needs: tau on the actuated coordinates, or
            /// for an actuation matrix B(q) the solution of B u = tau (square B) or of the
            /// normal equations B^T B u = B^T tau (n - 1 columns; exact where the passive
            /// equality holds).
            #[must_use]
            pub fn input(&self, q: &#vec_n, dq: &#vec_n, ddq: &#vec_n) -> #na::SVector<f64, #m_lit> {
                #float
                let mut __out = #na::SVector::<f64, #m_lit>::zeros();
                #input
                __out
            }

            /// The passive equalities (`PASSIVE`), each a function of the jet that must
            /// vanish, for `OptimalControlProblem::with_equalities`.
            #[must_use]
            pub fn unactuated_torques(&self) -> [#core::TorqueComponent<'_, Self>; #p_len] {
                [#(#components),*]
            }

            #input_functions
        }
    }
}

/// `impl Type { plant, input_force }`: the plant with the same parameters, and the
/// generalized force B(q) u of an input u.
fn plant_methods(e: &Emission<'_>, plant: &Emission<'_>, el: &EulerLagrange) -> TokenStream {
    let (na, vec_n, float) = (&e.na, &e.vec_n, &e.float);
    let (plant_ty, plant_name) = (&plant.params.ty_full, &plant.sig.type_name);
    let fields = e.sig.params.iter().map(|p| {
        let name = &p.name;
        quote!(#name: self.#name)
    });
    let m = el.input.len();
    let in_q = |_: u8, i: u32| {
        let i = index(i as usize);
        quote!(q[#i])
    };
    let names = Names {
        sig: e.sig,
        jet: &in_q,
    };
    let matrix = sets(e, &el.input_matrix, m, &names);
    let m_lit = index(m);
    let n_lit = &e.n_lit;
    let header = e.inherent_header();
    quote! {
        #header {
            /// The plant: the Lagrangian l(q, q') of order 1 with these parameters, for plant
            /// simulation under an input u by the forced midpoint rule (discrete
            /// Lagrange-d'Alembert), `retract::forced::forced_step(&system.plant(), &z0,
            /// &system.input_force(&q, &u), h, &options)` (add `nonconservative_force` at the
            /// step's midpoint where the system has forces).
            #[must_use]
            pub fn plant(&self) -> #plant_ty {
                #plant_name { #(#fields),* }
            }

            /// The generalized force B(q) u of the input u (with actuated coordinates, u_j on
            /// the j-th of `ACTUATED`, zero on the others).
            #[must_use]
            pub fn input_force(&self, q: &#vec_n, u: &#na::SVector<f64, #m_lit>) -> #vec_n {
                #float
                let mut __out = #na::SMatrix::<f64, #n_lit, #m_lit>::zeros();
                #matrix
                __out * u
            }
        }
    }
}

/// The `match` arms of the value, the gradient and the Hessian of `components`, by label.
fn component_arms(
    e: &Emission<'_>,
    components: &[Component],
) -> (Vec<TokenStream>, Vec<TokenStream>, Vec<TokenStream>) {
    let mut values = Vec::new();
    let mut gradients = Vec::new();
    let mut hessians = Vec::new();
    for component in components {
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
    (values, gradients, hessians)
}

/// The `input_value`, `input_gradient` and `input_hessian` methods of the input functions
/// (none where they were not asked for: the trait's defaults, NaN and zeros).
fn input_methods(e: &Emission<'_>, el: &EulerLagrange) -> Option<TokenStream> {
    if el.input_functions.is_empty() {
        return None;
    }
    let (core, n_lit, vec_n, jet_blocks) = (&e.core, &e.n_lit, &e.vec_n, &e.jet_blocks);
    let (values, gradients, hessians) = component_arms(e, &el.input_functions);
    Some(quote! {
        /// u_j(x, u), straight-line code (NaN for j >= m).
        fn input_value(&self, j: usize, x: &#jet_blocks, u: &#vec_n) -> f64 {
            match j {
                #(#values)*
                _ => f64::NAN,
            }
        }

        /// The gradient of u_j (zero for j >= m).
        fn input_gradient(&self, j: usize, x: &#jet_blocks, u: &#vec_n) -> #core::Gradient<#n_lit, 2> {
            match j {
                #(#gradients)*
                _ => #core::Gradient::zeros(),
            }
        }

        /// The Hessian of u_j (zero for j >= m).
        fn input_hessian(&self, j: usize, x: &#jet_blocks, u: &#vec_n) -> #core::Hessian<#n_lit, 2> {
            match j {
                #(#hessians)*
                _ => #core::Hessian::zeros(),
            }
        }
    })
}

/// `impl MechanicalSystem<n>`: the unactuated components of tau and the input functions in
/// (x, u).
fn mechanical_system_impl(e: &Emission<'_>, el: &EulerLagrange, actuated: &[usize]) -> TokenStream {
    let (core, n_lit, vec_n, jet_blocks) = (&e.core, &e.n_lit, &e.vec_n, &e.jet_blocks);
    let header = e.impl_header(quote!(MechanicalSystem<#n_lit>));
    let (values, gradients, hessians) = component_arms(e, &el.unactuated);
    let inputs = input_methods(e, el);
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

            #inputs

            fn system_name(&self) -> &'static str {
                #name
            }
        }
    }
}
