//! The emission of the generated code, one module per emitted item over a shared
//! [`Emission`] context:
//!
//! - `ty`: the re-emitted function, the parameter struct and its constructor and constants;
//! - `lagrangian`: the `Lagrangian` impl (L, its gradient and Hessian, the Ostrogradsky
//!   momenta and, for L quadratic in the top derivative, the Legendre inverse), with
//!   `structural` where the mechanics were built structurally: the Hessian-vector product as
//!   one private method that the Hessian, the momenta and the Legendre inverse evaluate;
//! - `lifted`: the `LiftedSystem` impl (residual and Jacobians of the lifted theta-scheme);
//! - `domain`: its `check_domain` method (the singularity guard);
//! - `reduced`: the `ReducedScheme` impl, where the Hessian of L depends on a few jet
//!   components only;
//! - `separable`: the `Separable` impl, where L = c/2 |u|^2 + V(q) (explicit splitting);
//! - `outputs`: a method per named output (`#[output] let`) of the Lagrangian;
//! - `mechanical`: for `#[mechanical_system]`, the inverse dynamics, the mass matrix and the
//!   unactuated components of tau (`retract_core::MechanicalSystem`).
//!
//! `map` emits the items of `#[discretization_map]` (its own type and `DiscretizationMap`
//! impl, from the stages `mechanics::lift` and `mechanics::map_conditions`).
//!
//! Shared by them (and by `#[jet_function]`): the token helpers (`helpers`) and the
//! straight-line bodies of a scalar function of the jet (`scalar`). The items are
//! concatenated by `attribute::lagrangian`, in the order above; their code is written by
//! `codegen` (one `let` per shared node), its nesting bounded by `scopes`.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use syn::ItemFn;

use crate::emit::codegen::emit;
use crate::front::lower::Guard;
use crate::front::signature::Signature;
use crate::ir::graph::{Graph, Id};
use crate::mechanics::{Mechanics, Reduced};
use crate::util::core_path;
use helpers::{Names, ParamTokens, allow_generated, float_import, index, param_tokens};

pub(crate) mod codegen;
pub(crate) mod domain;
pub(crate) mod helpers;
pub(crate) mod lagrangian;
pub(crate) mod lifted;
pub(crate) mod map;
pub(crate) mod mechanical;
pub(crate) mod outputs;
pub(crate) mod reduced;
pub(crate) mod scalar;
pub(crate) mod scopes;
pub(crate) mod separable;
pub(crate) mod structural;
pub(crate) mod ty;

/// What the items generated for one Lagrangian share: the input, its mechanics, and the
/// sizes, paths and types that every item names.
pub(crate) struct Emission<'a> {
    /// The annotated function.
    pub function: &'a ItemFn,
    /// Its attribute and signature.
    pub sig: &'a Signature,
    /// The expression graph holding every node below.
    pub g: &'a Graph,
    /// L, its derivatives, the momenta and the scheme.
    pub mech: &'a Mechanics,
    /// The guarded expressions at the three points of a step (none without the guard).
    pub guards: &'a [(Guard, [Id; 3])],
    /// The reduced step, where it applies.
    pub reduced: Option<&'a Reduced>,
    /// Dimension n.
    pub n: usize,
    /// Order k.
    pub k: usize,
    /// Size s = 2nk of the state z = (x, p).
    pub s: usize,
    /// Number m = 2nk + n of Newton unknowns w = (z_1, u).
    pub m: usize,
    /// n as a literal.
    pub n_lit: Literal,
    /// k as a literal.
    pub k_lit: Literal,
    /// s as a literal.
    pub s_lit: Literal,
    /// m as a literal.
    pub m_lit: Literal,
    /// The path of `retract_core` through the facade.
    pub core: TokenStream,
    /// The path of `nalgebra` through the facade.
    pub na: TokenStream,
    /// The type `SVector<f64, n>`.
    pub vec_n: TokenStream,
    /// `SVector::<f64, n>`, for calls.
    pub vec_n_path: TokenStream,
    /// The type `SVector<f64, s>` of a state.
    pub vec_s: TokenStream,
    /// The type `SVector<f64, m>` of the unknowns.
    pub vec_m: TokenStream,
    /// `SVector::<f64, m>`, for calls.
    pub vec_m_path: TokenStream,
    /// The type `[SVector<f64, n>; k]` of the lower jet x (and of the momenta).
    pub jet_blocks: TokenStream,
    /// The parameter struct.
    pub params: ParamTokens,
    /// The math methods for no_std (`float_import`).
    pub float: TokenStream,
    /// The lints allowed on generated impls (`allow_generated`).
    pub allow: TokenStream,
}

impl<'a> Emission<'a> {
    /// The context of the items of the Lagrangian `function`.
    pub fn new(
        function: &'a ItemFn,
        sig: &'a Signature,
        g: &'a Graph,
        mech: &'a Mechanics,
        guards: &'a [(Guard, [Id; 3])],
        reduced: Option<&'a Reduced>,
    ) -> Self {
        let (n, k) = (sig.dim, sig.order);
        let (s, m) = (2 * n * k, 2 * n * k + n);
        let (n_lit, k_lit, s_lit, m_lit) = (index(n), index(k), index(s), index(m));
        let core = core_path();
        let na = quote!(::retract::__private::nalgebra);
        let vec_n = quote!(#na::SVector<f64, #n_lit>);
        Emission {
            function,
            sig,
            g,
            mech,
            guards,
            reduced,
            n,
            k,
            s,
            m,
            vec_n_path: quote!(#na::SVector::<f64, #n_lit>),
            vec_s: quote!(#na::SVector<f64, #s_lit>),
            vec_m: quote!(#na::SVector<f64, #m_lit>),
            vec_m_path: quote!(#na::SVector::<f64, #m_lit>),
            jet_blocks: quote!([#vec_n; #k_lit]),
            vec_n,
            n_lit,
            k_lit,
            s_lit,
            m_lit,
            core,
            na,
            params: param_tokens(sig, "L"),
            float: float_import(),
            allow: allow_generated(),
        }
    }

    /// The head of the impl of `retract_core::#trait_` for the generated type:
    /// `#[automatically_derived]`, the allowed lints and `impl<'a> ... for Type<'a>`.
    pub fn impl_header(&self, trait_: TokenStream) -> TokenStream {
        let (core, allow) = (&self.core, &self.allow);
        let ParamTokens {
            generics, ty_full, ..
        } = &self.params;
        quote! {
            #[automatically_derived]
            #allow
            impl #generics #core::#trait_ for #ty_full
        }
    }

    /// The head of an inherent impl of the generated type: `#[automatically_derived]`, the
    /// allowed lints and `impl<'a> Type<'a>`.
    pub fn inherent_header(&self) -> TokenStream {
        let allow = &self.allow;
        let ParamTokens {
            generics, ty_full, ..
        } = &self.params;
        quote! {
            #[automatically_derived]
            #allow
            impl #generics #ty_full
        }
    }

    /// The leaves inside the methods of the scheme, which read z0, w, h, theta and the
    /// parameters (never the jet, named NaN).
    pub fn scheme(&self) -> Names<'a> {
        Names {
            sig: self.sig,
            jet: &no_jet,
        }
    }

    /// The body of a method returning the m x `cols` matrix with the row-major `entries`, in
    /// the scheme's leaves: straight-line code, then `__out[(r, c)] = ...;` for the structural
    /// nonzeros only.
    pub fn matrix_body(&self, entries: &[Id], cols: usize) -> TokenStream {
        let g = self.g;
        let code = emit(g, entries, &self.scheme());
        let sets: Vec<TokenStream> = entries
            .iter()
            .enumerate()
            .filter(|(_, id)| !g.is_const(**id, 0.0))
            .map(|(e, _)| {
                let v = &code.exprs[e];
                let (r, c) = (index(e / cols), index(e % cols));
                quote!(__out[(#r, #c)] = #v;)
            })
            .collect();
        self.matrix_out(&code.stmts, &sets, &self.m_lit, &index(cols))
    }

    /// A method body: `stmts`, then `__out`, a `rows` x `cols` matrix of zeros with `sets`
    /// assigned.
    pub fn matrix_out(
        &self,
        stmts: &TokenStream,
        sets: &[TokenStream],
        rows: &Literal,
        cols: &Literal,
    ) -> TokenStream {
        let (na, float) = (&self.na, &self.float);
        quote! {
            #float
            #stmts
            let mut __out = #na::SMatrix::<f64, #rows, #cols>::zeros();
            #(#sets)*
            __out
        }
    }
}

/// The jet inside the methods of the scheme: not read there.
fn no_jet(_: u8, _: u32) -> TokenStream {
    quote!(::core::f64::NAN)
}

/// The items of a system, in order: the function and its type (`ty`), the `Lagrangian` impl
/// (`lagrangian`), the `LiftedSystem` impl with its domain check (`lifted`, `domain`), where
/// the step reduces, the `ReducedScheme` impl (`reduced`) and, where L = c/2 |u|^2 + V(q),
/// the `Separable` impl (`separable`).
pub(crate) fn system_items(e: &Emission<'_>) -> TokenStream {
    let mut out = ty::type_and_constructor(e);
    out.extend(lagrangian::lagrangian_impl(e));
    out.extend(lifted::lifted_system_impl(e));
    out.extend(reduced::reduced_scheme_impl(e));
    out.extend(separable::separable_impl(e));
    out
}
