//! The options of `#[mechanical_system]` beyond the signature's: which coordinates the
//! actuators drive (`actuated = [i, ...]`, all of them by default) or the actuation matrix
//! B(q) (`input_matrix = f`, a helper returning its columns), the weight R of the effort
//! 1/2 R |u|^2 (`weight = R`, 1 by default), the non-conservative generalized forces
//! Q_nc(q, q') (`forces = f`), a cost C(q, q', u) added to the effort (`cost = f`) and
//! whether the inputs are emitted as functions of the jet with their derivatives, for bounds
//! on them (`input_functions = true`, false by default: each costs a symbolic Hessian), each
//! error at its span. The functions are helpers (`#[helper]` before the system, or `fn`s in
//! its body) whose arguments are taken by name (`front::lower`'s `call_by_name`).

use proc_macro2::{Span, TokenStream};
use syn::spanned::Spanned;

use crate::util::ErrorContext;

/// The options this module reads (`front::signature` skips them).
pub(crate) const OPTIONS: [&str; 6] = [
    "actuated",
    "weight",
    "forces",
    "input_matrix",
    "cost",
    "input_functions",
];

/// The actuation of a mechanical system, as written.
pub(crate) struct Actuation {
    /// The actuated coordinates with the span of each index; `None`: all of them.
    pub actuated: Option<Vec<(usize, Span)>>,
    /// R > 0.
    pub weight: f64,
    /// The helper returning Q_nc(q, q') as `[f64; n]`.
    pub forces: Option<syn::Ident>,
    /// The helper returning the columns of B(q): `[f64; n]` (one input) or a tuple of them.
    pub input_matrix: Option<syn::Ident>,
    /// The helper returning the cost C(q, q', u) as an `f64`.
    pub cost: Option<syn::Ident>,
    /// Whether u_j(q, q', q'') is emitted with its gradient and Hessian (`input_functions()`).
    pub input_functions: bool,
}

impl Actuation {
    /// The functions the options name (forces, actuation matrix, cost), in that order.
    pub fn functions(&self) -> impl Iterator<Item = &syn::Ident> {
        [&self.forces, &self.input_matrix, &self.cost]
            .into_iter()
            .flatten()
    }

    /// The actuated coordinates of a system of dimension `n`, ascending, or the errors at the
    /// indices out of range or repeated.
    pub fn coordinates(&self, n: usize) -> syn::Result<Vec<usize>> {
        let Some(list) = &self.actuated else {
            return Ok((0..n).collect());
        };
        let mut errors = ErrorContext::new();
        let mut seen = vec![false; n];
        for &(i, span) in list {
            if i >= n {
                errors.push(syn::Error::new(
                    span,
                    format!(
                        "actuated coordinate {i} out of range: q has {n} coordinates, \
                         0..={}",
                        n.saturating_sub(1)
                    ),
                ));
            } else if std::mem::replace(&mut seen[i], true) {
                errors.push(syn::Error::new(
                    span,
                    format!("coordinate {i} is listed twice in `actuated`"),
                ));
            }
        }
        errors.check()?;
        Ok((0..n).filter(|&i| seen[i]).collect())
    }
}

/// Reads the options of this module (`OPTIONS`) from the attribute's, skipping the others.
pub(crate) fn parse(attr: TokenStream) -> syn::Result<Actuation> {
    let mut out = Actuation {
        actuated: None,
        weight: 1.0,
        forces: None,
        input_matrix: None,
        cost: None,
        input_functions: false,
    };
    let parser = syn::meta::parser(|meta| {
        if meta.path.is_ident("actuated") {
            let list: syn::ExprArray = meta.value()?.parse()?;
            if list.elems.is_empty() {
                return Err(syn::Error::new(
                    list.span(),
                    "`actuated` lists at least one coordinate (an index of q)",
                ));
            }
            let indices = list.elems.iter().map(|e| match e {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(i),
                    ..
                }) => Ok((i.base10_parse::<usize>()?, i.span())),
                other => Err(syn::Error::new(
                    other.span(),
                    "`actuated` lists the indices of q as integer literals: `actuated = [0, 2]`",
                )),
            });
            out.actuated = Some(indices.collect::<syn::Result<_>>()?);
        } else if let Some(slot) = [
            ("forces", &mut out.forces),
            ("input_matrix", &mut out.input_matrix),
            ("cost", &mut out.cost),
        ]
        .into_iter()
        .find_map(|(name, slot)| meta.path.is_ident(name).then_some(slot))
        {
            let option = meta
                .path
                .get_ident()
                .map(ToString::to_string)
                .unwrap_or_default();
            let value: syn::Expr = meta.value()?.parse()?;
            let name = match &value {
                syn::Expr::Path(p) => p.path.get_ident().cloned(),
                _ => None,
            };
            *slot = Some(name.ok_or_else(|| {
                syn::Error::new(
                    value.span(),
                    format!(
                        "`{option}` names a helper function by its name, as `{option} = f` \
                         (`#[helper] fn f(...)` before the system, or a `fn` in its body)"
                    ),
                )
            })?);
        } else if meta.path.is_ident("input_functions") {
            let value: syn::Expr = meta.value()?.parse()?;
            out.input_functions = match &value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Bool(b),
                    ..
                }) => b.value,
                _ => {
                    return Err(syn::Error::new(
                        value.span(),
                        "`input_functions` is `true` or `false`: whether each input u_j is \
                         emitted as a function of the jet with its derivatives \
                         (`input_functions()`, for bounds on the inputs)",
                    ));
                }
            };
        } else if meta.path.is_ident("weight") {
            let value: syn::Expr = meta.value()?.parse()?;
            let weight = match &value {
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Float(f),
                    ..
                }) => f.base10_parse::<f64>().ok(),
                syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(i),
                    ..
                }) => i.base10_parse::<f64>().ok(),
                _ => None,
            };
            out.weight = weight
                .filter(|w| w.is_finite() && *w > 0.0)
                .ok_or_else(|| {
                    syn::Error::new(
                        value.span(),
                        "`weight` is the effort's weight R, a positive finite number literal: \
                     `weight = 0.5`",
                    )
                })?;
        } else {
            // (the signature's options, checked by `front::signature`)
            if meta.input.peek(syn::Token![=]) {
                let _: syn::Expr = meta.value()?.parse()?;
            }
        }
        Ok(())
    });
    syn::parse::Parser::parse2(parser, attr)?;
    if let (Some(_), Some(matrix)) = (&out.actuated, &out.input_matrix) {
        return Err(syn::Error::new(
            matrix.span(),
            "`input_matrix` and `actuated` exclude each other: the actuation is either the \
             actuated coordinates or the matrix B(q) of the inputs' generalized forces",
        ));
    }
    Ok(out)
}
