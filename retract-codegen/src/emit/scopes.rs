//! Bounded scope depth for long straight-line code.
//!
//! Every `let` opens a scope nested in the previous one, and rustc's debug information
//! describes each as a lexical block inside the last: LLVM builds those recursively, and a
//! function of about 3000 `let`s in a debug build (`-g`, no optimisation: cargo's default
//! `dev` profile) overflows its stack. [`bounded_scopes`] leaves code of at most [`FLAT`]
//! statements alone and groups longer code into blocks of [`CHUNK`] statements, each
//! returning the names it binds as a tuple,
//!
//! `let (a, b, ...) = { let a = ...; let b = ...; ...; (a, b, ...) };`
//!
//! so the nesting is about n / CHUNK + CHUNK deep instead of n. No operation changes.

use proc_macro2::{Ident, TokenStream, TokenTree};
use quote::quote;

/// Statement counts up to this are emitted as they are.
pub const FLAT: usize = 256;

/// Statements per block beyond [`FLAT`].
pub const CHUNK: usize = 64;

/// The statements of `stmts` (each `let ...;`, a `for` loop joined to the statement before
/// it, which declares its accumulator), grouped into blocks when there are more than
/// [`FLAT`].
pub fn bounded_scopes(stmts: TokenStream) -> TokenStream {
    let units = statements(stmts);
    if units.len() <= FLAT {
        return units.into_iter().collect();
    }
    let mut out = TokenStream::new();
    for chunk in units.chunks(CHUNK) {
        let names: Vec<Ident> = chunk.iter().filter_map(bound_name).collect();
        let body: TokenStream = chunk.iter().cloned().collect();
        out.extend(quote!(let (#(#names,)*) = { #body (#(#names,)*) };));
    }
    out
}

/// Splits at the top-level `;`s; a statement that starts with `for` ends at its block and
/// is joined to the statement before it.
fn statements(stmts: TokenStream) -> Vec<TokenStream> {
    let mut units: Vec<TokenStream> = Vec::new();
    let mut current: Vec<TokenTree> = Vec::new();
    let mut is_loop = false;
    for tt in stmts {
        if current.is_empty() {
            is_loop = matches!(&tt, TokenTree::Ident(i) if i == "for");
        }
        let ends = match &tt {
            TokenTree::Punct(p) => p.as_char() == ';' && !is_loop,
            TokenTree::Group(g) => is_loop && g.delimiter() == proc_macro2::Delimiter::Brace,
            _ => false,
        };
        current.push(tt);
        if ends {
            let unit: TokenStream = std::mem::take(&mut current).into_iter().collect();
            match units.last_mut() {
                Some(last) if is_loop => last.extend(unit),
                _ => units.push(unit),
            }
        }
    }
    if !current.is_empty() {
        units.push(current.into_iter().collect());
    }
    units
}

/// The name a statement `let [mut] name ...` binds.
fn bound_name(unit: &TokenStream) -> Option<Ident> {
    let mut tokens = unit.clone().into_iter();
    match tokens.next() {
        Some(TokenTree::Ident(l)) if l == "let" => {}
        _ => return None,
    }
    match tokens.next()? {
        TokenTree::Ident(m) if m == "mut" => match tokens.next()? {
            TokenTree::Ident(name) => Some(name),
            _ => None,
        },
        TokenTree::Ident(name) => Some(name),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lets(n: usize) -> TokenStream {
        let mut out = quote!(let mut acc: f64 = 0.0; for e in s.iter() { acc += e; });
        for i in 0..n {
            let name = quote::format_ident!("t{}", i);
            out.extend(quote!(let #name: f64 = acc + 1.0;));
        }
        out
    }

    #[test]
    fn short_code_is_unchanged_and_long_code_is_grouped() {
        let short = lets(10);
        assert_eq!(bounded_scopes(short.clone()).to_string(), short.to_string());
        let long = bounded_scopes(lets(1000));
        let text = long.to_string();
        // 1001 statements (the loop joined to its accumulator) in blocks of 64
        let blocks = long
            .into_iter()
            .filter(|t| matches!(t, TokenTree::Group(g) if g.delimiter() == proc_macro2::Delimiter::Brace))
            .count();
        assert_eq!(blocks, 1001_usize.div_ceil(CHUNK));
        assert!(text.starts_with("let (acc , t0 ,"), "{}", &text[..40]);
        assert!(text.contains("(acc , t0 ,"));
    }
}
