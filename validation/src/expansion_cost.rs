//! Compile-time cost of `#[higher_order_lagrangian]`: the expansion (parse, derivatives,
//! emitted code, all methods including the domain check and the reduced step with its
//! closed-form factors) of a second-order Lagrangian on $\mathbb{R}^n$ with unrolled barrier
//! terms ([`retract_codegen::samples::obstacle_field`]), timed as the best of several
//! expansions, with the lines of the formatted expansion; and the same of
//! `#[mechanical_system]` on the n-link chain written as T - V
//! ([`retract_codegen::samples::energy_chain`]), one line each,
//! `chain n=<n> expand_ms=<t> lines=<l>`.

use std::io::Write;
use std::time::Instant;

use proc_macro2::TokenStream;
use retract_codegen::samples::{energy_chain, obstacle_field};
use retract_codegen::{try_expand, try_expand_mechanical_system};

use crate::Error;

/// The cases `(n, obstacles)`: the dimension with one barrier term, then unrolled terms on
/// $\mathbb{R}^2$, then n = 6 with five terms.
pub const CASES: [(usize, usize); 9] = [
    (1, 1),
    (2, 1),
    (3, 1),
    (6, 1),
    (12, 1),
    (2, 10),
    (2, 20),
    (2, 50),
    (6, 5),
];

/// One expansion's cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Expansion {
    /// The dimension of q.
    pub n: usize,
    /// The unrolled barrier terms.
    pub obstacles: usize,
    /// Lines of the expansion formatted by prettyplease.
    pub lines: usize,
    /// The best time of an expansion, in seconds.
    pub seconds: f64,
}

/// The chain lengths of [`chain_expansions`].
pub const CHAIN_LINKS: [usize; 5] = [3, 5, 7, 9, 12];

/// The best time of `rounds` (at least one) expansions of the sample `sample()` by `expand`
/// and the lines of its formatted expansion, or `None` if it does not expand or parse.
fn best_expansion(
    rounds: usize,
    sample: impl Fn() -> (TokenStream, TokenStream),
    expand: fn(TokenStream, TokenStream) -> syn::Result<TokenStream>,
) -> Option<(f64, usize)> {
    let mut seconds = f64::INFINITY;
    let mut tokens = None;
    for _ in 0..rounds.max(1) {
        let (attr, item) = sample();
        let start = Instant::now();
        let expanded = expand(attr, item);
        seconds = seconds.min(start.elapsed().as_secs_f64());
        tokens = Some(expanded);
    }
    let file = syn::parse2::<syn::File>(tokens?.ok()?).ok()?;
    Some((seconds, prettyplease::unparse(&file).lines().count()))
}

/// Every case of [`CASES`], each expanded `rounds` times (at least once).
///
/// # Errors
/// [`Error::Domain`] if a case does not expand or its expansion does not parse as a file.
pub fn expansions(rounds: usize) -> Result<Vec<Expansion>, Error> {
    CASES
        .iter()
        .map(|&(n, obstacles)| {
            let (seconds, lines) =
                best_expansion(rounds, || obstacle_field(n, obstacles), try_expand)
                    .ok_or(Error::Domain("an obstacle field that does not expand"))?;
            Ok(Expansion {
                n,
                obstacles,
                lines,
                seconds,
            })
        })
        .collect()
}

/// The chain from T - V for each length of [`CHAIN_LINKS`], each expanded `rounds` times (at
/// least once); `obstacles` is 0.
///
/// # Errors
/// [`Error::Domain`] if a chain does not expand or its expansion does not parse as a file.
pub fn chain_expansions(rounds: usize) -> Result<Vec<Expansion>, Error> {
    CHAIN_LINKS
        .iter()
        .map(|&n| {
            let (seconds, lines) =
                best_expansion(rounds, || energy_chain(n), try_expand_mechanical_system)
                    .ok_or(Error::Domain("a chain from T - V that does not expand"))?;
            Ok(Expansion {
                n,
                obstacles: 0,
                lines,
                seconds,
            })
        })
        .collect()
}

/// Writes the chain's expansions, one line each: `chain n=<n> expand_ms=<t> lines=<l>`.
///
/// # Errors
/// [`Error::Io`].
pub fn write_chain_expansions(out: &mut dyn Write, rows: &[Expansion]) -> Result<(), Error> {
    writeln!(
        out,
        "
Compile-time cost: `#[mechanical_system]` on the n-link chain written as T - V:\n"
    )?;
    for row in rows {
        writeln!(
            out,
            "chain n={} expand_ms={:.1} lines={}",
            row.n,
            row.seconds * 1e3,
            row.lines
        )?;
    }
    Ok(())
}

/// Writes the expansions as a markdown table.
///
/// # Errors
/// [`Error::Io`].
pub fn write_expansions(
    out: &mut dyn Write,
    rows: &[Expansion],
    rounds: usize,
) -> Result<(), Error> {
    writeln!(
        out,
        "\nCompile-time cost: `#[higher_order_lagrangian(order = 2)]` on R^n with unrolled \
         barrier terms (best of {} expansions; lines of the formatted expansion):\n",
        rounds.max(1)
    )?;
    writeln!(out, "| n | barrier terms | lines | expansion |")?;
    writeln!(out, "|---|---|---|---|")?;
    for row in rows {
        writeln!(
            out,
            "| {} | {} | {} | {:.1} ms |",
            row.n,
            row.obstacles,
            row.lines,
            row.seconds * 1e3
        )?;
    }
    Ok(())
}
