//! Compile-time cost of `#[higher_order_lagrangian]`: the expansion (parse, derivatives,
//! emitted code, all methods including the domain check and the reduced step with its
//! closed-form factors) of a second-order Lagrangian on $\mathbb{R}^n$ with unrolled barrier
//! terms ([`retract_codegen::samples::obstacle_field`]), timed as the best of several
//! expansions, with the lines of the formatted expansion.

use std::io::Write;
use std::time::Instant;

use retract_codegen::samples::obstacle_field;
use retract_codegen::try_expand;

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

/// Every case of [`CASES`], each expanded `rounds` times (at least once).
///
/// # Errors
/// [`Error::Domain`] if a case does not expand or its expansion does not parse as a file.
pub fn expansions(rounds: usize) -> Result<Vec<Expansion>, Error> {
    CASES
        .iter()
        .map(|&(n, obstacles)| {
            let mut seconds = f64::INFINITY;
            let mut tokens = None;
            for _ in 0..rounds.max(1) {
                let (attr, item) = obstacle_field(n, obstacles);
                let start = Instant::now();
                let expanded = try_expand(attr, item);
                seconds = seconds.min(start.elapsed().as_secs_f64());
                tokens = Some(expanded);
            }
            let file = tokens
                .and_then(Result::ok)
                .and_then(|t| syn::parse2::<syn::File>(t).ok())
                .ok_or(Error::Domain("an obstacle field that does not expand"))?;
            let lines = prettyplease::unparse(&file).lines().count();
            Ok(Expansion {
                n,
                obstacles,
                lines,
                seconds,
            })
        })
        .collect()
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
