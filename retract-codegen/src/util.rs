//! Helpers shared by the stages that import nothing from them: error combining, the text
//! of tokens as the user wrote them and, for unit tests, an expansion formatted. This module uses no other module of the crate,
//! so that `signature`, `lower`, the emission and the entry points can all use it without
//! importing each other.

/// Combines several errors into one that reports all of them.
pub(crate) fn combine(errors: Vec<syn::Error>) -> Option<syn::Error> {
    let mut iter = errors.into_iter();
    let mut first = iter.next()?;
    for e in iter {
        first.combine(e);
    }
    Some(first)
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
    fn tidy_joins_calls_and_indexing() {
        assert_eq!(tidy("q [0] . powi (2) + (a * b)"), "q[0].powi(2) + (a * b)");
    }
}
