//! Helpers shared by the stages that import nothing from them: the error context, the text
//! of tokens as the user wrote them and, for unit tests, an expansion formatted. This module
//! uses no other module of the crate, so that `signature`, `lower`, the emission and the entry
//! points can all use it without importing each other.

/// The errors of an expansion, collected so that the user sees all of them at once, that
/// cannot be forgotten: they leave only through [`ErrorContext::check`], and a context
/// dropped with errors it was given and never checked panics in a debug build (a proc-macro
/// that forgot its errors would expand without them). A check leaves the context empty and
/// checked; an error recorded after it must be checked again.
pub(crate) struct ErrorContext {
    /// The errors since the last check; `None` once checked with nothing recorded after.
    list: Option<Vec<syn::Error>>,
}

impl ErrorContext {
    /// An empty context: nothing to report, but still to be checked.
    pub(crate) fn new() -> Self {
        Self {
            list: Some(Vec::new()),
        }
    }

    /// Records `error`.
    pub(crate) fn push(&mut self, error: syn::Error) {
        self.list.get_or_insert_with(Vec::new).push(error);
    }

    /// Records the error `message` at `span`.
    pub(crate) fn error(&mut self, span: proc_macro2::Span, message: impl std::fmt::Display) {
        self.push(syn::Error::new(span, message));
    }

    /// The number of errors recorded since the last check.
    pub(crate) fn len(&self) -> usize {
        self.list.as_ref().map_or(0, Vec::len)
    }

    /// Whether no error was recorded since the last check.
    pub(crate) fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Forgets the errors recorded after the first `len` (a tentative lowering that is
    /// retried another way).
    pub(crate) fn truncate(&mut self, len: usize) {
        if let Some(list) = &mut self.list {
            list.truncate(len);
        }
    }

    /// `Err` with every error recorded since the last check combined into one (each keeps
    /// its span), `Ok` if there were none; the context is left empty and checked.
    pub(crate) fn check(&mut self) -> syn::Result<()> {
        let mut iter = self.list.take().unwrap_or_default().into_iter();
        let Some(mut first) = iter.next() else {
            return Ok(());
        };
        for e in iter {
            first.combine(e);
        }
        Err(first)
    }
}

impl Drop for ErrorContext {
    /// Panics (debug builds, outside an unwinding panic) if errors were recorded and never
    /// checked, or the context was never checked at all.
    fn drop(&mut self) {
        if cfg!(debug_assertions) && self.list.is_some() && !std::thread::panicking() {
            panic!("an ErrorContext was dropped without `check`: its errors would be lost");
        }
    }
}

/// The path through which generated code names what it calls of `retract_core`: the
/// runtime's hidden `__private` module (one flat list of what only generated code needs),
/// reached through the facade's, so that the user's crate depends on `retract` alone.
pub(crate) fn core_path() -> proc_macro2::TokenStream {
    quote::quote!(::retract::__private::retract_core::__private)
}

/// The deepest nesting of delimited groups (`()`, `[]`, `{}`) an attribute parses. syn parses
/// a nested group by recursion, about 16 KiB of stack a level when unoptimised (as a
/// proc-macro's dependencies are built): 512 levels of `(1.0 + (...))` overflowed rustc's
/// 8 MiB stack, 384 did not. Past this the item is refused before it is parsed.
pub(crate) const MAX_GROUP_NESTING: usize = 256;

/// `Err` at the first group nested deeper than [`MAX_GROUP_NESTING`] in `tokens`, found
/// without recursion (the walk is iterative, linear in the tokens).
pub(crate) fn check_group_nesting(tokens: &proc_macro2::TokenStream) -> syn::Result<()> {
    let mut stack = vec![(tokens.clone(), 0)];
    while let Some((tokens, depth)) = stack.pop() {
        for tree in tokens {
            if let proc_macro2::TokenTree::Group(g) = tree {
                if depth + 1 > MAX_GROUP_NESTING {
                    return Err(syn::Error::new(
                        g.span_open(),
                        format!(
                            "brackets nest deeper than {MAX_GROUP_NESTING} levels here: bind \
                             intermediate values with `let`"
                        ),
                    ));
                }
                stack.push((g.stream(), depth + 1));
            }
        }
    }
    Ok(())
}

/// Token text with the spaces that `to_string` puts around `.`, `[` and calls removed.
pub(crate) fn tidy(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let chars: Vec<char> = text.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if c == ' ' {
            let prev = if i > 0 { chars[i - 1] } else { ' ' };
            let next = chars.get(i + 1).copied().unwrap_or(' ');
            let glue = next == '.'
                || prev == '.'
                || next == '['
                || (next == '(' && (prev.is_alphanumeric() || prev == '_'));
            if glue {
                continue;
            }
        }
        out.push(c);
    }
    out
}

/// For unit tests of an expansion: `expand(attr, item)` from text, formatted, or its error
/// messages joined by newlines.
#[cfg(test)]
pub(crate) fn pretty_expansion(
    expand: fn(
        proc_macro2::TokenStream,
        proc_macro2::TokenStream,
    ) -> syn::Result<proc_macro2::TokenStream>,
    attr: &str,
    item: &str,
) -> Result<String, String> {
    let attr: proc_macro2::TokenStream = attr.parse().map_err(|e| format!("{e}"))?;
    let item: proc_macro2::TokenStream = item.parse().map_err(|e| format!("{e}"))?;
    let tokens = expand(attr, item).map_err(|e| {
        e.into_iter()
            .map(|e| e.to_string())
            .collect::<Vec<_>>()
            .join("\n")
    })?;
    let file: syn::File = syn::parse2(tokens).map_err(|e| e.to_string())?;
    Ok(prettyplease::unparse(&file))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_check_gives_every_error_in_order_and_leaves_the_context_checked() {
        let mut errors = ErrorContext::new();
        errors.error(proc_macro2::Span::call_site(), "first");
        errors.push(syn::Error::new(proc_macro2::Span::call_site(), "second"));
        assert_eq!(errors.len(), 2);
        let messages: Vec<String> = match errors.check() {
            Err(e) => e.into_iter().map(|e| e.to_string()).collect(),
            Ok(()) => Vec::new(),
        };
        assert_eq!(messages, ["first", "second"]);
        assert!(errors.is_empty());
        assert!(errors.check().is_ok());
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "dropped without `check`")]
    fn a_context_dropped_unchecked_panics_in_a_debug_build() {
        let mut errors = ErrorContext::new();
        errors.error(proc_macro2::Span::call_site(), "lost");
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "dropped without `check`")]
    fn an_error_recorded_after_a_check_must_be_checked_again() {
        let mut errors = ErrorContext::new();
        assert!(errors.check().is_ok());
        errors.error(proc_macro2::Span::call_site(), "late");
    }

    #[test]
    fn tidy_joins_calls_and_indexing() {
        assert_eq!(tidy("q [0] . powi (2) + (a * b)"), "q[0].powi(2) + (a * b)");
    }
}
