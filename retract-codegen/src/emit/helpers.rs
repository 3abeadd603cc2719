//! Token helpers shared by the emitted items (and by `#[jet_function]`): literals, the
//! names of the leaves inside the generated methods, the parameter struct, the lints and
//! imports of generated impls, and balanced signed sums. They use the earlier stages
//! (`front::signature`, `ir::graph`, `emit::codegen`) and nothing of the items that use them.

use proc_macro2::{Literal, TokenStream};
use quote::quote;
use syn::ItemFn;

use crate::charts::Space;
use crate::emit::codegen::{Leaves, signed_add};
use crate::front::signature::{Kind, Signature};
use crate::ir::graph::Var;
use crate::util::core_path;

/// `i` as an unsuffixed literal (an index or a length in the generated code).
pub(crate) fn index(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

/// Names the leaves inside the generated methods.
pub(crate) struct Names<'a> {
    pub sig: &'a Signature,
    /// q^(order)[index] as an expression.
    pub jet: &'a dyn Fn(u8, u32) -> TokenStream,
}

impl Leaves for Names<'_> {
    fn var(&self, var: Var) -> TokenStream {
        match var {
            Var::Jet { order, index } => (self.jet)(order, index),
            Var::Param { param, index } => {
                let p = &self.sig.params[param as usize];
                let name = &p.name;
                match p.kind {
                    Kind::Scalar => quote!(self.#name),
                    _ => {
                        let i = self::index(index as usize);
                        quote!(self.#name[#i])
                    }
                }
            }
            Var::Elem { index, .. } => {
                let i = self::index(index as usize);
                quote!(__e[#i])
            }
            Var::Z0(c) => {
                let c = self::index(c as usize);
                quote!(z0[#c])
            }
            Var::W(c) => {
                let c = self::index(c as usize);
                quote!(w[#c])
            }
            Var::Core(m) => {
                let m = self::index(m as usize);
                quote!(y[#m])
            }
            Var::Covector { side, block, index } => {
                let w = if side == 0 { quote!(w1) } else { quote!(w2) };
                let (b, i) = (self::index(block as usize), self::index(index as usize));
                quote!(#w[#b][#i])
            }
            Var::Step => quote!(h),
            Var::Theta => quote!(theta),
            Var::Direction(a) => {
                let a = self::index(a as usize);
                quote!(__d[#a])
            }
            Var::Hoisted(i) => {
                let i = self::index(i as usize);
                quote!(__h[#i])
            }
        }
    }

    fn slice(&self, param: u32) -> TokenStream {
        let name = &self.sig.params[param as usize].name;
        quote!(self.#name)
    }
}

/// `q^(order)[i]` inside a method taking `(x, u)`: `x[order][i]` below the top order k,
/// `u[i]` at it.
pub(crate) fn xu_leaf(k: usize, order: u8, i: u32) -> TokenStream {
    let i = index(i as usize);
    if (order as usize) < k {
        let o = index(order as usize);
        quote!(x[#o][#i])
    } else {
        quote!(u[#i])
    }
}

/// The math methods for no_std (with std the inherent f64 methods take precedence).
pub(crate) fn float_import() -> TokenStream {
    quote!(
        #[allow(unused_imports)]
        use ::retract::__private::Float as _;
    )
}

/// The lints allowed on generated impls.
pub(crate) fn allow_generated() -> TokenStream {
    quote!(#[allow(
        unused_imports,
        unused_variables,
        unused_mut,
        unused_parens,
        clippy::all,
        clippy::pedantic,
        clippy::nursery
    )])
}

/// The annotated function as it is re-emitted: the generated code does not call it; it
/// stays for users to call.
pub(crate) fn callable(function: &ItemFn) -> ItemFn {
    let mut function = function.clone();
    function.block.stmts.insert(
        0,
        syn::parse_quote!(
            #[allow(unused_imports)]
            use ::retract::__private::Float as _;
        ),
    );
    function
        .attrs
        .push(syn::parse_quote!(#[allow(dead_code, clippy::too_many_arguments)]));
    function
}

/// The annotated function, re-emitted (`callable`), then [`type_items`]. Shared by the
/// Lagrangian (`emit::ty`), `#[jet_function]` and `#[discretization_map]`.
pub(crate) fn function_and_type(
    function: &ItemFn,
    sig: &Signature,
    params: &ParamTokens,
    doc: &str,
    consts: TokenStream,
    new_doc: TokenStream,
) -> TokenStream {
    let callable = callable(function);
    let items = type_items(&function.vis, sig, params, doc, consts, new_doc);
    quote! {
        #callable

        #items
    }
}

/// The parameter struct of `sig` with visibility `vis`, documented by `doc`, and its
/// inherent impl: the constants `consts`, then the constructor `new` documented by `new_doc`
/// (a doc comment).
pub(crate) fn type_items(
    vis: &syn::Visibility,
    sig: &Signature,
    params: &ParamTokens,
    doc: &str,
    consts: TokenStream,
    new_doc: TokenStream,
) -> TokenStream {
    let ParamTokens {
        generics,
        ty_full,
        fields,
        ctor_args,
        field_names,
    } = params;
    let ty = &sig.type_name;
    // without parameters a unit struct, usable as a value by its name alone
    let body = if fields.is_empty() {
        quote!(;)
    } else {
        quote!({ #(#fields,)* })
    };
    quote! {
        #[doc = #doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        #vis struct #ty #generics #body

        #[automatically_derived]
        impl #generics #ty_full {
            #consts

            #new_doc
            #[allow(clippy::too_many_arguments)]
            pub fn new(#(#ctor_args),*) -> Self {
                Self { #(#field_names),* }
            }
        }
    }
}

/// Where a generated system lives, for its docs: "R^n", or the space and its chart.
pub(crate) fn space_description(sig: &Signature) -> String {
    sig.space.chart().description(sig.dim)
}

/// For a function on the sphere (`sphere`), `SphereSystem`; on SO(3) (`so3`), `So3System`;
/// on SE(3) (`se3`), `Se3System` (`charts::Frame::runtime`): the chart parameter, read and
/// replaced. Nothing on R^n.
pub(crate) fn chart_system_impl(space: Space, params: &ParamTokens) -> TokenStream {
    let (generics, ty) = (&params.generics, &params.ty_full);
    let allow = allow_generated();
    let Some(frame) = space.chart().frame() else {
        return TokenStream::new();
    };
    let field = syn::Ident::new(frame.name, proc_macro2::Span::call_site());
    let len = index(frame.len);
    let core = core_path();
    let [tr, read, replace] = frame
        .runtime
        .map(|name| syn::Ident::new(name, proc_macro2::Span::call_site()));
    quote! {
        #[automatically_derived]
        #allow
        impl #generics #core::#tr for #ty {
            fn #read(&self) -> [f64; #len] {
                self.#field
            }

            fn #replace(&self, frame: [f64; #len]) -> Self {
                Self { #field: frame, ..*self }
            }
        }
    }
}

/// The pieces of the generated parameter struct.
pub(crate) struct ParamTokens {
    /// `<'a>` when a parameter is a slice, else nothing.
    pub generics: TokenStream,
    /// The type with its generics.
    pub ty_full: TokenStream,
    /// The public fields, documented.
    pub fields: Vec<TokenStream>,
    /// The arguments of `new`.
    pub ctor_args: Vec<TokenStream>,
    /// The field initialisers of `new`, in order: the arguments by name, and for a system on
    /// the sphere the chart at the north pole.
    pub field_names: Vec<TokenStream>,
}

/// The parameter struct of `sig`; `symbol` names the function in the docs (`L`, `g`).
pub(crate) fn param_tokens(sig: &Signature, symbol: &str) -> ParamTokens {
    let ty = &sig.type_name;
    let has_slice = sig.params.iter().any(|p| matches!(p.kind, Kind::Slice(_)));
    let (generics, ty_full) = if has_slice {
        (quote!(<'a>), quote!(#ty<'a>))
    } else {
        (quote!(), quote!(#ty))
    };
    // the chart of a system on a manifold is set by the stepper, not by the user
    let frame = sig.space.chart().frame();
    let fields = sig
        .params
        .iter()
        .map(|p| {
            let name = &p.name;
            let (t, doc) = match p.kind {
                Kind::Scalar => (quote!(f64), format!("Parameter `{name}`.")),
                Kind::Array(len) => {
                    let l = index(len);
                    (quote!([f64; #l]), format!("Parameter `{name}`."))
                }
                Kind::Slice(len) => {
                    let l = index(len);
                    (
                        quote!(&'a [[f64; #l]]),
                        format!("Parameter list `{name}` (any length; {symbol} sums over it)."),
                    )
                }
            };
            let doc = match &frame {
                Some(frame) if name == frame.name => frame.doc.to_string(),
                _ => doc,
            };
            quote!(#[doc = #doc] pub #name: #t)
        })
        .collect();
    let user_params = &sig.params[..sig.params.len() - usize::from(frame.is_some())];
    let ctor_args = user_params
        .iter()
        .map(|p| {
            let name = &p.name;
            match p.kind {
                Kind::Scalar => quote!(#name: f64),
                Kind::Array(len) => {
                    let l = index(len);
                    quote!(#name: [f64; #l])
                }
                Kind::Slice(len) => {
                    let l = index(len);
                    quote!(#name: &'a [[f64; #l]])
                }
            }
        })
        .collect();
    let mut field_names: Vec<TokenStream> = user_params
        .iter()
        .map(|p| {
            let name = &p.name;
            quote!(#name)
        })
        .collect();
    if let Some(frame) = frame {
        let field = syn::Ident::new(frame.name, proc_macro2::Span::call_site());
        let initial = (frame.initial)();
        field_names.push(quote!(#field: #initial));
    }
    ParamTokens {
        generics,
        ty_full,
        fields,
        ctor_args,
        field_names,
    }
}

/// `t_0 +- t_1 +- ...` for terms `(negative, t)` as a balanced tree (adjacent terms paired,
/// so the additions of a long row run in parallel); `0.0` for none.
pub(crate) fn signed_sum(terms: &[(bool, TokenStream)]) -> TokenStream {
    match sum_tree(terms) {
        None => quote!(0.0),
        Some((false, sum)) => sum,
        Some((true, sum)) => quote!(-#sum),
    }
}

/// The balanced sum of `terms` as `(negative, tokens)`: the value is the tokens, negated if
/// `negative`.
pub(crate) fn sum_tree(terms: &[(bool, TokenStream)]) -> Option<(bool, TokenStream)> {
    if terms.len() <= 1 {
        return terms.first().cloned();
    }
    let (left, right) = terms.split_at(terms.len() / 2);
    Some(signed_add(sum_tree(left)?, sum_tree(right)?))
}
