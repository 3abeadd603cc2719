//! The attributes, one module each: `#[higher_order_lagrangian]` (`lagrangian`),
//! `#[jet_function]` (`jet_function`), `#[discretization_map]` (`map`), `#[mechanical_system]` (`mechanical`), each a set of passes
//! of the one pipeline (`crate::pipeline`) that returns the generated items, or the item
//! unchanged with its errors; and `#[helper]` (`helper`: the helper's macro and the chain
//! that collects the helpers an attribute names). The chain ends here, in
//! [`expand_with_helpers`], which re-enters the attribute: this module is the only one that
//! imports the attributes, so that none of them imports another.

use proc_macro2::TokenStream;

pub(crate) mod helper;
pub(crate) mod jet_function;
pub(crate) mod lagrangian;
pub(crate) mod map;
pub(crate) mod mechanical;

/// The end of the chain of helpers (module `helper`): the attribute `which` expanded on
/// `item` with the helper functions put first in its body and the `helpers` option removed.
pub fn expand_with_helpers(input: TokenStream) -> TokenStream {
    let (which, attr, item) = match helper::with_helpers_inlined(input) {
        Ok(parts) => parts,
        Err(error) => return error.to_compile_error(),
    };
    if which == "jet_function" {
        jet_function::expand_jet_function(attr, item)
    } else if which == "mechanical_system" {
        mechanical::expand_mechanical_system(attr, item)
    } else {
        lagrangian::expand(attr, item)
    }
}
