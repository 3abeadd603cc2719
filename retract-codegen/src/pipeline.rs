//! The pipeline every attribute runs, written once: parse the item, read the signature
//! (`front::signature`), lower the body to the expression graph (`front::lower`, every error
//! of the body reported at once), compose with the chart of the function's space (`charts`),
//! build what the attribute derives from it (`mechanics`) and emit the items (`emit`).
//!
//! The attributes differ only in their passes, as pest's optimizer chains its passes: each
//! implements [`Passes`] (what it lowers, how it composes with a chart, what it derives and
//! what it emits), and [`run`] chains them in that order.

use proc_macro2::TokenStream;
use quote::quote;
use syn::ItemFn;

use crate::front::lower::Lower;
use crate::front::signature::{self, Attribute, Signature};
use crate::ir::graph::{Graph, Id, MAX_NODES};

/// The passes of one attribute, chained by [`run`].
pub(crate) trait Passes {
    /// The attribute, for the options it accepts and its messages.
    const ATTRIBUTE: Attribute;
    /// What lowering the body yields: the roots in the graph and what travels with them.
    type Lowered;
    /// What the mechanics pass derives from the lowered function, for the emission.
    type Derived;

    /// Lowers the body of `function` through `lower`; errors go to `lower.errors`.
    fn lower(&mut self, lower: &mut Lower<'_>, function: &ItemFn, sig: &Signature)
    -> Self::Lowered;

    /// The lowered function composed with the chart of `sig`'s space, with the signature of
    /// the composed function.
    fn charts(
        &mut self,
        graph: &mut Graph,
        sig: Signature,
        lowered: Self::Lowered,
    ) -> (Signature, Self::Lowered);

    /// What the attribute derives (derivatives, momenta, scheme, lift), or the error that
    /// stops the expansion.
    fn mechanics(
        &mut self,
        graph: &mut Graph,
        sig: &Signature,
        lowered: Self::Lowered,
    ) -> syn::Result<Self::Derived>;

    /// The generated items.
    fn emit(
        &self,
        function: &ItemFn,
        sig: &Signature,
        graph: &Graph,
        derived: Self::Derived,
    ) -> TokenStream;
}

/// Runs the pipeline (module docs) with `passes` on `#[attribute(attr)] item`: the generated
/// items, or the errors of the first stage that failed, combined into one `syn::Error`.
pub(crate) fn run<P: Passes>(
    passes: &mut P,
    attr: TokenStream,
    item: TokenStream,
) -> syn::Result<TokenStream> {
    crate::util::check_group_nesting(&item)?;
    let function: ItemFn = syn::parse2(item)?;
    let sig = signature::parse(attr, &function, P::ATTRIBUTE)?;
    let mut graph = Graph::default();
    let lowered = {
        let mut lower = Lower::new(&mut graph, &sig);
        let lowered = passes.lower(&mut lower, &function, &sig);
        check_size(lower.g, &function)?;
        lower.errors.check()?;
        lowered
    };
    let (sig, lowered) = passes.charts(&mut graph, sig, lowered);
    let derived = passes.mechanics(&mut graph, &sig, lowered);
    check_size(&graph, &function)?;
    Ok(passes.emit(&function, &sig, &graph, derived?))
}

/// The error at `function`'s name when `graph` outgrew [`MAX_NODES`].
fn check_size(graph: &Graph, function: &ItemFn) -> syn::Result<()> {
    if !graph.overflowed() {
        return Ok(());
    }
    Err(syn::Error::new(
        function.sig.ident.span(),
        format!(
            "the expansion of `{}` needs more than {MAX_NODES} expression nodes (the \
             function, its derivatives and the scheme), more than rustc could compile in \
             reasonable time; make the function smaller: fewer unrolled loop iterations \
             (a `for` over a slice parameter is not unrolled) or shorter chains of nested \
             calls",
            function.sig.ident
        ),
    ))
}

/// `roots` (a function and its guarded expressions) composed with the chart of `sig`'s space
/// (`charts`), with the signature of the composed function (`Signature::in_chart`: the
/// chart's frame appended to the parameters); unchanged on R^n.
pub(crate) fn compose_with_chart(
    graph: &mut Graph,
    sig: Signature,
    roots: &[Id],
) -> (Signature, Vec<Id>) {
    let frame = sig.params.len() as u32;
    let roots = sig.space.chart().compose(graph, sig.order, frame, roots);
    (sig.in_chart(), roots)
}

/// The expansion of `item` where it succeeded; where it failed, the original item (its
/// `#[output]` marks removed) followed by the errors as `compile_error!`s, so that the rest of
/// the crate still type-checks and the errors do not cascade.
pub(crate) fn fail_softly(item: TokenStream, result: syn::Result<TokenStream>) -> TokenStream {
    match result {
        Ok(tokens) => tokens,
        Err(error) => {
            let errors = error.to_compile_error();
            let item = crate::front::lower::item_without_output_marks(item);
            quote!(#item #errors)
        }
    }
}
