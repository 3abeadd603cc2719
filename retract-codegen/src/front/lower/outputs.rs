//! Named outputs: `#[output] let tau = ...;` at the top level of a Lagrangian's body binds a
//! number or an array that `emit::outputs` emits as a method of the generated type. The mark
//! is removed from the function emitted again as written (rustc does not know it).

use syn::spanned::Spanned;
use syn::{Expr, Pat, Stmt};

use super::{Binding, Lower, Output};
use crate::front::signature::Attribute;

/// The methods a generated Lagrangian's type already has, which an output of the same name
/// would shadow (an inherent method wins over a trait's at a call `sys.name(..)`) or clash
/// with: its constructor, those of the traits it implements (`Lagrangian`, `LiftedSystem`,
/// `ReducedScheme`, `Separable`, the manifolds' `SphereSystem`, `So3System`, `Se3System`) and
/// of its derives (`Clone`, `Debug`, `PartialEq`). Kept complete by a test that reads the
/// traits' definitions.
pub(crate) const RESERVED: &[&str] = &[
    "new",
    "clone",
    "clone_from",
    "fmt",
    "eq",
    "ne",
    "gradient",
    "hessian",
    "derivatives",
    "lagrangian",
    "momenta",
    "top_derivative",
    "check_domain",
    "check_parameters",
    "guards_quadratic",
    "hamiltonian",
    "jacobian",
    "jacobian_initial",
    "legendre",
    "predictor",
    "residual",
    "state",
    "step_cost",
    "vector_field",
    "closed_form_factors",
    "core_offset",
    "core_residual",
    "core_forcing",
    "core_system",
    "forcing",
    "forcing_jacobian",
    "initial_part",
    "linear_part",
    "recover",
    "recover_plain",
    "kinetic_weight",
    "chart",
    "with_chart",
    "centre",
    "with_centre",
    "centred",
];

/// Whether a `let` is marked `#[output]`.
pub(super) fn is_output(local: &syn::Local) -> bool {
    local.attrs.iter().any(|a| a.path().is_ident("output"))
}

/// `function` without the `#[output]` marks of its `let`s (rustc does not know the
/// attribute: the function is emitted again as written, without them), in its body, its
/// loops, blocks and helpers.
pub fn without_output_marks(function: &syn::ItemFn) -> syn::ItemFn {
    let mut out = function.clone();
    strip_block(&mut out.block);
    out
}

/// `item` without the `#[output]` marks if it is a function (else as it is): the original
/// item emitted beside the errors of a failed expansion. An item nested too deeply to parse
/// (`util::MAX_GROUP_NESTING`) is returned as it is.
pub fn item_without_output_marks(item: proc_macro2::TokenStream) -> proc_macro2::TokenStream {
    if crate::util::check_group_nesting(&item).is_err() {
        return item;
    }
    match syn::parse2::<syn::ItemFn>(item.clone()) {
        Ok(function) => quote::ToTokens::into_token_stream(without_output_marks(&function)),
        Err(_) => item,
    }
}

fn strip_block(block: &mut syn::Block) {
    for stmt in &mut block.stmts {
        match stmt {
            Stmt::Local(local) => local.attrs.retain(|a| !a.path().is_ident("output")),
            Stmt::Item(syn::Item::Fn(f)) => strip_block(&mut f.block),
            Stmt::Expr(Expr::ForLoop(l), _) => strip_block(&mut l.body),
            Stmt::Expr(Expr::Block(b), _) => strip_block(&mut b.block),
            _ => {}
        }
    }
}

impl Lower<'_> {
    /// Records the named output bound by the top-level `let` `local` (just lowered).
    pub(super) fn record_output(&mut self, local: &syn::Local) {
        if self.sig.attribute != Attribute::Lagrangian {
            self.error(
                local.span(),
                "named outputs are for `#[higher_order_lagrangian]`",
            );
            return;
        }
        let pat = match &local.pat {
            Pat::Type(t) => &*t.pat,
            other => other,
        };
        let Pat::Ident(p) = pat else {
            self.error(
                pat.span(),
                "a named output binds one name: `#[output] let tau = ...;`",
            );
            return;
        };
        if p.mutability.is_some() {
            self.error(
                p.ident.span(),
                "a named output is its value at the `let`: bind it without `mut`",
            );
            return;
        }
        let (ids, array) = match self.lookup(&p.ident.to_string()) {
            Some((_, Binding::Value { id, .. })) => (vec![id], false),
            Some((_, Binding::Array { slot })) => (self.arrays[slot as usize].clone(), true),
            // an error was reported where it was bound
            _ => return,
        };
        if let Some(attr) = local.attrs.iter().find(|a| a.path().is_ident("output"))
            && !matches!(attr.meta, syn::Meta::Path(_))
        {
            self.error(
                attr.span(),
                "`#[output]` takes no arguments: the method is named after the binding",
            );
            return;
        }
        let name = p.ident.to_string();
        if RESERVED.contains(&name.as_str()) {
            self.error(
                p.ident.span(),
                format!(
                    "the output `{name}` would shadow the generated type's method `{name}`: \
                     name it otherwise (reserved: {})",
                    RESERVED.join(", ")
                ),
            );
            return;
        }
        if self.outputs.iter().any(|o| o.name == p.ident) {
            self.error(
                p.ident.span(),
                format!("the output `{}` is named twice", p.ident),
            );
            return;
        }
        self.outputs.push(Output {
            name: p.ident.clone(),
            ids,
            array,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::RESERVED;

    /// Every method of the traits a generated Lagrangian's type implements, read from their
    /// definitions in retract-core, is reserved.
    #[test]
    fn every_trait_method_of_a_generated_type_is_reserved() {
        let traits = [
            ("system.rs", "Lagrangian"),
            ("system.rs", "LiftedSystem"),
            ("scheme/reduced.rs", "ReducedScheme"),
            ("scheme/split.rs", "Separable"),
            ("manifold/sphere.rs", "SphereSystem"),
            ("manifold/so3/body.rs", "So3System"),
            ("manifold/se3.rs", "Se3System"),
            ("manifold/mod.rs", "CentredSystem"),
        ];
        let mut checked = 0;
        for (file, name) in traits {
            let path = format!("{}/../retract-core/src/{file}", env!("CARGO_MANIFEST_DIR"));
            let text = std::fs::read_to_string(&path).expect("retract-core's source");
            let parsed = syn::parse_file(&text).expect("parses");
            let item = parsed.items.iter().find_map(|item| match item {
                syn::Item::Trait(t) if t.ident == name => Some(t),
                _ => None,
            });
            let item = item.unwrap_or_else(|| panic!("trait {name} in {file}"));
            for member in &item.items {
                if let syn::TraitItem::Fn(f) = member {
                    let method = f.sig.ident.to_string();
                    assert!(RESERVED.contains(&method.as_str()), "{name}::{method}");
                    checked += 1;
                }
            }
        }
        assert!(checked >= 30, "{checked} methods");
    }
}
