//! Helper functions shared by several Lagrangians and stage constraints of a crate:
//! `#[helper] fn torque(...) -> [f64; 2] { ... }` next to them, and
//! `#[higher_order_lagrangian(order = 2, helpers = [torque])]` (or `#[jet_function(...)]`) on
//! each user.
//!
//! A proc macro sees only its own item, so the body travels by macro: `#[helper]` emits the
//! function unchanged and a `macro_rules!` of the same name (macros and functions live in
//! different namespaces) that appends the function's tokens to a list and passes the list on.
//! An attribute with `helpers = [a, b]` expands to `a! { @retract_helpers [] [b] ... }`; each
//! helper's macro adds itself and calls the next, the last calls
//! `expand_with_helpers` (the re-entry, in `attribute`), which puts the functions into the
//! body as nested helper `fn`s ([`with_helpers_inlined`]; inlined by the lowering,
//! `front::lower`) and expands the attribute without the option. This module imports none
//! of the attributes, so that they can all start the chain ([`chain_if_named`]).
//! The macros follow `macro_rules!` scoping: a helper is visible to the items after it in
//! its module (and in modules declared after it).

use proc_macro2::TokenStream;
use quote::{ToTokens, quote};
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{Ident, ItemFn, Meta, Token};

use crate::front::lower::helper_signature_problem;

/// Expands `#[helper] item`: the function, and its macro (module docs).
pub fn expand_helper(attr: TokenStream, item: TokenStream) -> TokenStream {
    match try_expand_helper(attr, item.clone()) {
        Ok(tokens) => tokens,
        Err(error) => {
            let errors = error.to_compile_error();
            quote!(#item #errors)
        }
    }
}

fn try_expand_helper(attr: TokenStream, item: TokenStream) -> syn::Result<TokenStream> {
    if !attr.is_empty() {
        return Err(syn::Error::new_spanned(
            attr,
            "`#[helper]` takes no options",
        ));
    }
    crate::util::check_group_nesting(&item)?;
    let function: ItemFn = syn::parse2(item)?;
    if let Some((span, message)) = helper_signature_problem(&function.sig) {
        return Err(syn::Error::new(span, message));
    }
    let name = &function.sig.ident;
    let tokens = function.to_token_stream();
    // the function as a Lagrangian is emitted again: callable, its lints allowed
    let callable = crate::emit::helpers::callable(&function);
    Ok(quote! {
        #callable

        #[doc(hidden)]
        #[allow(unused_macros)]
        macro_rules! #name {
            (@retract_helpers [$($done:tt)*] [$next:ident $(, $rest:ident)*] $($tail:tt)*) => {
                $next! { @retract_helpers [$($done)* #tokens] [$($rest),*] $($tail)* }
            };
            (@retract_helpers [$($done:tt)*] [] $($tail:tt)*) => {
                ::retract::__private::expand_with_helpers! { [$($done)* #tokens] $($tail)* }
            };
        }
    })
}

/// Where the attribute's options `attr` name helpers, the start of the chain for the attribute
/// `which` (module docs); `None` without them.
pub(crate) fn chain_if_named(
    attr: &TokenStream,
    which: &str,
    item: &TokenStream,
) -> syn::Result<Option<TokenStream>> {
    let helpers = helper_names(attr)?;
    Ok((!helpers.is_empty()).then(|| chain(&helpers, which, attr, item)))
}

/// [`chain_if_named`] where the attribute's options also name the functions `named` (as
/// `#[mechanical_system(forces = damping)]`): those not defined in the item's body join the
/// helpers of the chain, so that a `#[helper]` need not be listed twice.
pub(crate) fn chain_if_named_or_used(
    attr: &TokenStream,
    which: &str,
    item: &TokenStream,
    named: &[Ident],
) -> syn::Result<Option<TokenStream>> {
    let mut helpers = helper_names(attr)?;
    let nested: Vec<String> = syn::parse2::<ItemFn>(item.clone())
        .map(|f| {
            f.block
                .stmts
                .iter()
                .filter_map(|s| match s {
                    syn::Stmt::Item(syn::Item::Fn(f)) => Some(f.sig.ident.to_string()),
                    _ => None,
                })
                .collect()
        })
        .unwrap_or_default();
    for name in named {
        if !nested.contains(&name.to_string()) && !helpers.contains(name) {
            helpers.push(name.clone());
        }
    }
    Ok((!helpers.is_empty()).then(|| chain(&helpers, which, attr, item)))
}

/// The names of `helpers = [a, b]` in an attribute's options (none without it).
fn helper_names(attr: &TokenStream) -> syn::Result<Vec<Ident>> {
    let metas = syn::parse::Parser::parse2(
        Punctuated::<Meta, Token![,]>::parse_terminated,
        attr.clone(),
    )?;
    for meta in metas {
        if let Meta::NameValue(nv) = meta
            && nv.path.is_ident("helpers")
        {
            let syn::Expr::Array(list) = nv.value else {
                return Err(syn::Error::new_spanned(
                    nv.value,
                    "`helpers` lists the helper functions by name: `helpers = [torque, mass]`",
                ));
            };
            return list
                .elems
                .iter()
                .map(|e| {
                    let name = match e {
                        syn::Expr::Path(p) => p.path.get_ident().cloned(),
                        _ => None,
                    };
                    name.ok_or_else(|| {
                        syn::Error::new_spanned(
                            e,
                            "a helper is named by its function's name, as `torque`",
                        )
                    })
                })
                .collect();
        }
    }
    Ok(Vec::new())
}

/// The start of the chain for an attribute `which` with helpers `names` (module docs).
fn chain(names: &[Ident], which: &str, attr: &TokenStream, item: &TokenStream) -> TokenStream {
    let which = Ident::new(which, proc_macro2::Span::call_site());
    let (first, rest) = (&names[0], &names[1..]);
    quote!(#first! { @retract_helpers [] [#(#rest),*] #which [#attr] #item })
}

/// The input of the end of the chain (`attribute::expand_with_helpers`): `[fns] which [attr]
/// item`.
struct WithHelpers {
    helpers: Vec<ItemFn>,
    which: Ident,
    attr: TokenStream,
    item: ItemFn,
}

impl Parse for WithHelpers {
    fn parse(input: ParseStream<'_>) -> syn::Result<Self> {
        let content;
        syn::bracketed!(content in input);
        let mut helpers = Vec::new();
        while !content.is_empty() {
            helpers.push(content.parse()?);
        }
        let which = input.parse()?;
        let attr;
        syn::bracketed!(attr in input);
        let attr = attr.parse()?;
        let item = input.parse()?;
        Ok(Self {
            helpers,
            which,
            attr,
            item,
        })
    }
}

/// The end of the chain, `[fns] which [attr] item`: the attribute's name `which`, its options
/// without `helpers`, and `item` with the helper functions put first in its body.
pub(crate) fn with_helpers_inlined(
    input: TokenStream,
) -> syn::Result<(Ident, TokenStream, TokenStream)> {
    let WithHelpers {
        helpers,
        which,
        attr,
        mut item,
    } = {
        crate::util::check_group_nesting(&input)?;
        syn::parse2(input)?
    };
    let metas = syn::parse::Parser::parse2(Punctuated::<Meta, Token![,]>::parse_terminated, attr)
        .unwrap_or_default();
    let kept: Punctuated<Meta, Token![,]> = metas
        .into_iter()
        .filter(|m| !matches!(m, Meta::NameValue(nv) if nv.path.is_ident("helpers")))
        .collect();
    let stmts = helpers
        .into_iter()
        .map(|f| syn::Stmt::Item(syn::Item::Fn(f)));
    item.block.stmts.splice(0..0, stmts);
    Ok((which, kept.to_token_stream(), item.to_token_stream()))
}
