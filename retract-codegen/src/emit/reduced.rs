//! The `ReducedScheme` impl, emitted where the Hessian of L depends only on a few jet
//! components y (the core, r of them): the step F(z0, w) = A w + B z0 + n(y) = 0 is linear in
//! w at fixed y, with the forcing n nonzero in a few rows only, so Newton runs on the r
//! unknowns y instead of the m unknowns w (formulas in `retract_core::ReducedScheme`).
//!
//! With E the selection of the core rows, the factors of a step size are T = -A^{-1} B, the
//! forced columns of A^{-1}, K = theta E A^{-1} and G = (1 - theta) E + theta E T; the core
//! system is r(y) = y - G z0 + K n(y) with Jacobian I + K dn/dy, and the unknowns are
//! recovered as w = (T + T_lo) z0 - (A^{-1} + A^{-1}_lo) n(y), the corrections (the cached
//! factors' rounding errors, `retract_core::reduced`) added inside the one rounding of each
//! entry. Every product is emitted over the structural nonzeros of its factor; where T and
//! A^{-1} are known in closed form (a symbolic elimination of the blocks of A at compile time,
//! `closed_form_factors`), its zeros refine the patterns and its constants are written in
//! place of cached values (a constant +-1 is exact: no correction).

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::Emission;
use super::helpers::{index, signed_sum};
use crate::emit::codegen::{Emitted, constant, emit};
use crate::ir::graph::Id;
use crate::mechanics::{self, Reduced};

/// `impl ReducedScheme<s, m, r>`, where the step reduces.
pub(crate) fn reduced_scheme_impl(e: &Emission<'_>) -> Option<TokenStream> {
    let red = e.reduced?;
    Some(Reduction::new(e, red).scheme_impl())
}

/// The reduction of one Lagrangian with the structural patterns of its factors.
struct Reduction<'a> {
    e: &'a Emission<'a>,
    red: &'a Reduced,
    /// Number r of core unknowns.
    r: usize,
    /// r as a literal.
    r_lit: Literal,
    /// The type `SVector<f64, r>`.
    vec_r: TokenStream,
    /// The type of the cached factors, `ReducedFactors<s, m, r>`.
    factors_ty: TokenStream,
    /// Structural nonzeros of T = -A^{-1} B, m x s.
    t_pattern: Vec<Vec<bool>>,
    /// Structural nonzeros of A^{-1}, m x m (its forced columns are used).
    inverse_pattern: Vec<Vec<bool>>,
    /// Structural nonzeros of K = theta E A^{-1}, r x m.
    k_pattern: Vec<Vec<bool>>,
    /// Structural nonzeros of G = (1 - theta) E + theta E T, r x s.
    g_pattern: Vec<Vec<bool>>,
}

impl<'a> Reduction<'a> {
    fn new(e: &'a Emission<'a>, red: &'a Reduced) -> Self {
        let (s, m) = (e.s, e.m);
        let r = red.core.len();
        let r_lit = index(r);
        let Emission {
            core,
            na,
            s_lit,
            m_lit,
            ..
        } = e;
        let mut reduction = Reduction {
            e,
            red,
            r,
            vec_r: quote!(#na::SVector<f64, #r_lit>),
            factors_ty: quote!(#core::ReducedFactors<#s_lit, #m_lit, #r_lit>),
            r_lit,
            t_pattern: Vec::new(),
            inverse_pattern: Vec::new(),
            k_pattern: Vec::new(),
            g_pattern: Vec::new(),
        };
        // structural nonzeros of T = -A^{-1} B, of A^{-1} (its forced columns are used), of
        // K = theta E A^{-1} and of G = (1 - theta) E + theta E T; where the closed form is
        // known, its zeros refine them and its constants are written in place of cached values
        let known_zero = |id: Option<Id>| id.is_some_and(|id| e.g.is_const(id, 0.0));
        let structural_t = mechanics::product_pattern(&red.inverse_pattern, &red.initial_pattern);
        let t_pattern: Vec<Vec<bool>> = (0..m)
            .map(|row| {
                (0..s)
                    .map(|c| structural_t[row][c] && !known_zero(reduction.closed_t(row, c)))
                    .collect()
            })
            .collect();
        let inverse_pattern: Vec<Vec<bool>> = (0..m)
            .map(|row| {
                (0..m)
                    .map(|q| {
                        red.inverse_pattern[row][q] && !known_zero(reduction.closed_a_inv(row, q))
                    })
                    .collect()
            })
            .collect();
        reduction.k_pattern = red
            .core
            .iter()
            .map(|&c| inverse_pattern[c].clone())
            .collect();
        reduction.g_pattern = red
            .core
            .iter()
            .map(|&core| (0..s).map(|c| c == core || t_pattern[core][c]).collect())
            .collect();
        reduction.t_pattern = t_pattern;
        reduction.inverse_pattern = inverse_pattern;
        reduction
    }

    /// T[(row, c)] in closed form, if known.
    fn closed_t(&self, row: usize, c: usize) -> Option<Id> {
        let s = self.e.s;
        self.red
            .closed_form
            .as_ref()
            .map(|(t, _, _)| t[row * s + c])
    }

    /// A^{-1}[(row, q)] in closed form, if known (q a forced row).
    fn closed_a_inv(&self, row: usize, q: usize) -> Option<Id> {
        let red = self.red;
        let forced_count = red.rows.len();
        let f = red.rows.iter().position(|&r| r == q)?;
        red.closed_form
            .as_ref()
            .map(|(_, a_inv, _)| a_inv[row * forced_count + f])
    }

    /// The impl: the core, forced rows and blocks as constants, then its methods.
    fn scheme_impl(&self) -> TokenStream {
        let Emission {
            s_lit, m_lit, m, ..
        } = self.e;
        let (red, r, r_lit) = (self.red, self.r, &self.r_lit);
        let core_list = red.core.iter().map(|&c| index(c));
        let forced_list = red.rows.iter().map(|&q| index(q));
        let block_list = red.blocks.iter().map(|(rows, cols)| {
            let (rows, cols) = (
                rows.iter().map(|&i| index(i)),
                cols.iter().map(|&i| index(i)),
            );
            quote!((&[#(#rows),*], &[#(#cols),*]))
        });
        let doc = format!(
            "The reduced step: the Hessian of L depends only on the jet components {:?} (flat \
             indices j n + i), so Newton runs on {r} unknowns instead of {m}; forces act in rows \
             {:?} of the residual.",
            red.core, red.rows
        );
        let forced_entries = self.forced_entries();
        let residual_entries = Self::residual_entries(&forced_entries);
        let forcing_lets = self.forcing_lets();
        let header = self
            .e
            .impl_header(quote!(ReducedScheme<#s_lit, #m_lit, #r_lit>));
        let linear_parts = self.linear_parts();
        let core_offset = self.core_offset();
        let core_system = self.core_system(&residual_entries);
        let closed_form = self.closed_form();
        let forcing_jacobian = self.forcing_jacobian();
        let core_residual = self.core_residual(&forcing_lets, &residual_entries);
        let core_forcing = self.core_forcing();
        let forcing = self.forcing();
        let recover = self.recover(&forcing_lets);
        quote! {
            #[doc = #doc]
            #header {
                const CORE: [usize; #r_lit] = [#(#core_list),*];
                const FORCED: &'static [usize] = &[#(#forced_list),*];
                const BLOCKS: &'static [(&'static [usize], &'static [usize])] = &[#(#block_list),*];

                #linear_parts

                #core_offset

                #core_system

                #closed_form

                #forcing_jacobian

                #core_residual

                #core_forcing

                #forcing

                #recover
            }
        }
    }

    /// The methods `linear_part` (A) and `initial_part` (B).
    fn linear_parts(&self) -> TokenStream {
        let Emission {
            na,
            s,
            m,
            s_lit,
            m_lit,
            ..
        } = self.e;
        let linear = self.e.matrix_body(&self.red.linear, *m);
        let initial = self.e.matrix_body(&self.red.initial, *s);
        quote! {
            /// A = dF/dw at fixed y.
            fn linear_part(&self, h: f64, theta: f64) -> #na::SMatrix<f64, #m_lit, #m_lit> {
                #linear
            }

            /// B = dF/dz0 at fixed y.
            fn initial_part(&self, h: f64, theta: f64) -> #na::SMatrix<f64, #m_lit, #s_lit> {
                #initial
            }
        }
    }

    /// The method `core_offset`: G z0 over the structural nonzeros of G.
    fn core_offset(&self) -> TokenStream {
        let Emission { na, s, vec_s, .. } = self.e;
        let (r_lit, vec_r, factors_ty) = (&self.r_lit, &self.vec_r, &self.factors_ty);
        let offset_sets = self.g_pattern.iter().enumerate().map(|(row, pattern)| {
            let cols: Vec<(usize, TokenStream)> = (0..*s)
                .filter(|&c| pattern[c])
                .map(|c| (c, z0_entry(c)))
                .collect();
            dot(quote!(factors.g), row, &cols)
        });
        quote! {
            /// G z0 over the structural nonzeros of G.
            #[inline]
            fn core_offset(&self, factors: &#factors_ty, z0: &#vec_s) -> #vec_r {
                #na::SVector::<f64, #r_lit>::from([#(#offset_sets),*])
            }
        }
    }

    /// The rows of K n over the structural nonzeros of K, with n_q under the names `__n<q>`.
    fn forced_entries(&self) -> Vec<TokenStream> {
        self.k_pattern
            .iter()
            .enumerate()
            .map(|(mi, pattern)| {
                let cols: Vec<(usize, TokenStream)> = self
                    .red
                    .rows
                    .iter()
                    .filter(|&&q| pattern[q])
                    .map(|&q| {
                        let name = n_name(q);
                        (q, quote!(#name))
                    })
                    .collect();
                dot(quote!(factors.k), mi, &cols)
            })
            .collect()
    }

    /// The rows of r(y) = y - offset + K n(y), from the rows of K n ([`Self::forced_entries`]).
    fn residual_entries(forced_entries: &[TokenStream]) -> Vec<TokenStream> {
        forced_entries
            .iter()
            .enumerate()
            .map(|(mi, sum)| {
                let mi_lit = index(mi);
                quote!(y[#mi_lit] - offset[#mi_lit] + #sum)
            })
            .collect()
    }

    /// The columns of I + K dn/dy, from `with_jacobian`: the code of n(y) followed by dn/dy.
    fn jacobian_entries(&self, with_jacobian: &Emitted) -> Vec<Vec<TokenStream>> {
        let (g, red, r) = (self.e.g, self.red, self.r);
        let dn = |q_pos: usize, l: usize| {
            let id = red.nonlinear_jacobian[q_pos * r + l];
            (!g.is_const(id, 0.0))
                .then(|| with_jacobian.exprs[red.rows.len() + q_pos * r + l].clone())
        };
        let mut jacobian_entries = vec![Vec::new(); r];
        for (mi, pattern) in self.k_pattern.iter().enumerate() {
            for (l, column) in jacobian_entries.iter_mut().enumerate() {
                let cols: Vec<(usize, TokenStream)> = red
                    .rows
                    .iter()
                    .enumerate()
                    .filter(|&(_, &q)| pattern[q])
                    .filter_map(|(pos, &q)| dn(pos, l).map(|e| (q, quote!((#e)))))
                    .collect();
                let sum = dot(quote!(factors.k), mi, &cols);
                let one = if l == mi { quote!(1.0 + ) } else { quote!() };
                column.push(quote!(#one #sum));
            }
        }
        jacobian_entries
    }

    /// The method `core_system`: r(y) and I + K dn/dy over the structural nonzeros.
    fn core_system(&self, residual_entries: &[TokenStream]) -> TokenStream {
        let Emission { na, float, .. } = self.e;
        let (red, r_lit, vec_r, factors_ty) =
            (self.red, &self.r_lit, &self.vec_r, &self.factors_ty);
        let mut roots = red.nonlinear.clone();
        roots.extend(&red.nonlinear_jacobian);
        let with_jacobian = emit(self.e.g, &roots, &self.e.scheme());
        let wj_stmts = &with_jacobian.stmts;
        let wj_lets = red.rows.iter().zip(&with_jacobian.exprs).map(|(&q, e)| {
            let name = n_name(q);
            quote!(let #name: f64 = #e;)
        });
        let jacobian_entries = self.jacobian_entries(&with_jacobian);
        quote! {
            /// r(y) = y - offset + K n(y) and I + K dn/dy over the structural nonzeros.
            #[inline]
            fn core_system(
                &self,
                factors: &#factors_ty,
                offset: &#vec_r,
                y: &#vec_r,
                h: f64,
                theta: f64,
            ) -> (#vec_r, #na::SMatrix<f64, #r_lit, #r_lit>) {
                #float
                #wj_stmts
                #(#wj_lets)*
                (
                    #na::SVector::<f64, #r_lit>::from([#(#residual_entries),*]),
                    #na::SMatrix::<f64, #r_lit, #r_lit>::from([#([#(#jacobian_entries),*]),*]),
                )
            }
        }
    }

    /// The method `closed_form_factors`, where T and A^{-1} are known in closed form.
    fn closed_form(&self) -> Option<TokenStream> {
        let Emission {
            g,
            core,
            na,
            s,
            m,
            s_lit,
            m_lit,
            float,
            ..
        } = self.e;
        let (s, m, red) = (*s, *m, self.red);
        let (t, a_inv, polynomial) = red.closed_form.as_ref()?;
        let kind = if *polynomial {
            quote!(Polynomial)
        } else {
            quote!(Rational)
        };
        let mut roots = t.clone();
        roots.extend(a_inv);
        let code = emit(g, &roots, &self.e.scheme());
        let stmts = &code.stmts;
        let forced = red.rows.len();
        let sets = roots
            .iter()
            .enumerate()
            .filter(|(_, id)| !g.is_const(**id, 0.0))
            .map(|(e, _)| {
                let value = &code.exprs[e];
                if e < m * s {
                    let (row, col) = (index(e / s), index(e % s));
                    quote!(t[(#row, #col)] = #value;)
                } else {
                    let e = e - m * s;
                    let (row, col) = (index(e / forced), index(red.rows[e % forced]));
                    quote!(a_inv[(#row, #col)] = #value;)
                }
            });
        Some(quote! {
            /// T = -A^{-1} B and the forced columns of A^{-1}, from a symbolic elimination
            /// of the blocks of A at compile time.
            fn closed_form_factors(
                &self,
                h: f64,
                theta: f64,
                t: &mut #na::SMatrix<f64, #m_lit, #s_lit>,
                a_inv: &mut #na::SMatrix<f64, #m_lit, #m_lit>,
            ) -> #core::ClosedForm {
                #float
                #stmts
                #(#sets)*
                #core::ClosedForm::#kind
            }
        })
    }

    /// The method `forcing_jacobian`: dn/dy, nonzero in the forced rows only.
    fn forcing_jacobian(&self) -> TokenStream {
        let Emission { g, na, m_lit, .. } = self.e;
        let (red, r, r_lit, vec_r) = (self.red, self.r, &self.r_lit, &self.vec_r);
        let forcing = emit(g, &red.nonlinear_jacobian, &self.e.scheme());
        let dn_stmts = forcing.stmts;
        let dn_sets: Vec<TokenStream> = red
            .nonlinear_jacobian
            .iter()
            .enumerate()
            .filter(|(_, id)| !g.is_const(**id, 0.0))
            .map(|(e, _)| {
                let value = &forcing.exprs[e];
                let (q, l) = (index(red.rows[e / r]), index(e % r));
                quote!(__out[(#q, #l)] = #value;)
            })
            .collect();
        let body = self.e.matrix_out(&dn_stmts, &dn_sets, m_lit, r_lit);
        quote! {
            /// dn/dy, nonzero in the forced rows only.
            fn forcing_jacobian(
                &self,
                y: &#vec_r,
                h: f64,
                theta: f64,
            ) -> #na::SMatrix<f64, #m_lit, #r_lit> {
                #body
            }
        }
    }

    /// The forcing given as a vector: its forced rows under the names `__n<q>`.
    fn forcing_lets(&self) -> Vec<TokenStream> {
        self.red
            .rows
            .iter()
            .map(|&q| {
                let (name, q) = (n_name(q), index(q));
                quote!(let #name: f64 = forcing[#q];)
            })
            .collect()
    }

    /// The method `core_residual`: r(y) for a given forcing n = n(y).
    fn core_residual(
        &self,
        forcing_lets: &[TokenStream],
        residual_entries: &[TokenStream],
    ) -> TokenStream {
        let Emission { na, vec_m, .. } = self.e;
        let (r_lit, vec_r, factors_ty) = (&self.r_lit, &self.vec_r, &self.factors_ty);
        quote! {
            /// r(y) = y - offset + K n for the given forcing n = n(y).
            #[inline]
            fn core_residual(
                &self,
                factors: &#factors_ty,
                offset: &#vec_r,
                y: &#vec_r,
                forcing: &#vec_m,
            ) -> #vec_r {
                #(#forcing_lets)*
                #na::SVector::<f64, #r_lit>::from([#(#residual_entries),*])
            }
        }
    }

    /// The method `core_forcing`: K n(y) at y, each entry of K a leaf of the product chains of
    /// n (bound first as `__h`), so that it is multiplied in with their early operands: the
    /// fixed-point step y0 - K n(y0) waits on no multiplication by K after n.
    fn core_forcing(&self) -> TokenStream {
        let Emission { na, float, .. } = self.e;
        let (red, r_lit, vec_r, factors_ty) =
            (self.red, &self.r_lit, &self.vec_r, &self.factors_ty);
        let code = emit(self.e.g, &red.scaled, &self.e.scheme());
        let (stmts, exprs) = (&code.stmts, &code.exprs);
        let count = index(red.scale_entries.len());
        let entries = red.scale_entries.iter().map(|&(m, q)| {
            let (m, q) = (index(m), index(q));
            quote!(factors.k[(#m, #q)])
        });
        quote! {
            /// K n(y) over the structural nonzeros of K, the entries of K inside the products
            /// of n.
            #[inline]
            fn core_forcing(
                &self,
                factors: &#factors_ty,
                y: &#vec_r,
                h: f64,
                theta: f64,
            ) -> #vec_r {
                #float
                let __h: [f64; #count] = [#(#entries),*];
                #stmts
                #na::SVector::<f64, #r_lit>::from([#(#exprs),*])
            }
        }
    }

    /// The method `forcing`: n(y), nonzero in the forced rows only.
    fn forcing(&self) -> TokenStream {
        let Emission {
            g,
            vec_m,
            vec_m_path,
            float,
            ..
        } = self.e;
        let (red, vec_r) = (self.red, &self.vec_r);
        let forces = emit(g, &red.nonlinear, &self.e.scheme());
        let force_stmts = &forces.stmts;
        let force_lets: Vec<TokenStream> = red
            .rows
            .iter()
            .zip(&forces.exprs)
            .map(|(&q, e)| {
                let name = n_name(q);
                quote!(let #name: f64 = #e;)
            })
            .collect();
        let forcing_sets: Vec<TokenStream> = red
            .rows
            .iter()
            .map(|&q| {
                let (name, q) = (n_name(q), index(q));
                quote!(__out[#q] = #name;)
            })
            .collect();
        quote! {
            /// n(y), nonzero in the forced rows only.
            #[inline]
            fn forcing(&self, y: &#vec_r, h: f64, theta: f64) -> #vec_m {
                #float
                #force_stmts
                #(#force_lets)*
                let mut __out = #vec_m_path::zeros();
                #(#forcing_sets)*
                __out
            }
        }
    }

    /// A term `factor * value` of a row of w: the cached factor entry, or its constant where
    /// the closed form knows one (times `sign`).
    fn term(&self, cached: TokenStream, known: Option<Id>, value: TokenStream, sign: f64) -> Term {
        match known.and_then(|id| self.e.g.as_const(id)).map(|v| sign * v) {
            Some(1.0) => Term::Exact(value),
            Some(-1.0) => Term::Exact(quote!(-#value)),
            Some(v) => {
                let v = constant(v);
                Term::Product(quote!(#v), value)
            }
            None if sign < 0.0 => Term::Product(quote!(-#cached), value),
            None => Term::Product(cached, value),
        }
    }

    /// Row `row` of w = (T + T_lo) z0 - (A^{-1} + A^{-1}_lo) n(y): the terms of T and A^{-1}
    /// summed as balanced trees in two halves, the terms of n (known last, summed apart: one
    /// addition after n, not the depth of the tree) or the two halves of the terms, and the
    /// corrections (T_lo z0 and A^{-1}_lo n, of the size of the rounding errors; those of n's
    /// terms summed apart and added last) added to the half without a term of factor +-1
    /// first, the late one where both qualify (`sum_folded`: that half is the small one, so
    /// that they enter the one rounding of the result instead of being lost below the last
    /// bit); with unit terms in both halves, the last addition exact (`sum_corrected`:
    /// `two_sum` with the corrections added to its error). A row of exact terms (factors +-1)
    /// has no correction and is a plain sum. With `compensated` false, the row is the plain sum of
    /// the terms of T and A^{-1} (no corrections, no exact addition), the terms of n again
    /// added last.
    fn recover_row(&self, row: usize, compensated: bool) -> TokenStream {
        let (core, s, red) = (&self.e.core, self.e.s, self.red);
        let rl = index(row);
        let mut terms: Vec<Term> = Vec::new();
        let mut corrections: Vec<(bool, TokenStream)> = Vec::new();
        for c in (0..s).filter(|&c| self.t_pattern[row][c]) {
            let (cl, z) = (index(c), z0_entry(c));
            let term = self.term(
                quote!(factors.t[(#rl, #cl)]),
                self.closed_t(row, c),
                z.clone(),
                1.0,
            );
            // T_lo is the rounding error of the T the step multiplies (the cached one, which
            // holds the closed form's values): none where that is +-1, exact
            if matches!(term, Term::Product(..)) {
                corrections.push((false, quote!(factors.t_lo[(#rl, #cl)] * #z)));
            }
            terms.push(term);
        }
        // the forcing is known last: its terms join the sum of the others at the end
        let (forced_start, early_corrections) = (terms.len(), corrections.len());
        for &q in red.rows.iter().filter(|&&q| self.inverse_pattern[row][q]) {
            let (ql, name) = (index(q), n_name(q));
            let term = self.term(
                quote!(factors.a_inv[(#rl, #ql)]),
                self.closed_a_inv(row, q),
                quote!(#name),
                -1.0,
            );
            if matches!(term, Term::Product(..)) {
                corrections.push((true, quote!(factors.a_inv_lo[(#rl, #ql)] * #name)));
            }
            terms.push(term);
        }
        let signed: Vec<(bool, TokenStream)> = terms
            .iter()
            .map(|term| match term {
                Term::Exact(v) => (false, v.clone()),
                Term::Product(a, b) => (false, quote!(#a * #b)),
            })
            .collect();
        // the forcing's terms, known last, are summed apart and join the sum of the others in
        // its last addition: one addition after them, not the depth of a balanced tree
        let mixed = forced_start > 0 && forced_start < terms.len();
        if corrections.is_empty() || !compensated {
            if mixed {
                let (left, right) = signed.split_at(forced_start);
                let (left, right) = (signed_sum(left), signed_sum(right));
                return quote!((#left + #right));
            }
            return signed_sum(&signed);
        }
        // the corrections of the forcing's terms (known last) are summed apart, as theirs
        let (early, late) = corrections.split_at(early_corrections);
        let small = match (early.is_empty(), late.is_empty()) {
            (false, false) => {
                let (early, late) = (signed_sum(early), signed_sum(late));
                quote!((#early + #late))
            }
            (true, _) => signed_sum(late),
            (false, true) => signed_sum(early),
        };
        if let [Term::Product(a, b)] = terms.as_slice() {
            // one product: its own rounding error, exact, carries the correction
            return quote!({
                let (__p, __e) = #core::two_product(#a, #b);
                __p + (__e + #small)
            });
        }
        let split = if mixed { forced_start } else { terms.len() / 2 };
        let exact = |terms: &[Term]| terms.iter().any(|t| matches!(t, Term::Exact(_)));
        let (exact_left, exact_right) = (exact(&terms[..split]), exact(&terms[split..]));
        let (left, right) = signed.split_at(split);
        let (left, right) = (signed_sum(left), signed_sum(right));
        // the corrections join the half without a term of factor +-1 (a unit term carries the
        // state: the other half, of the terms of n or of factors scaled by powers of h, is the
        // small one), the late half where both qualify; with a unit term in each, the exact sum
        match (exact_left, exact_right) {
            (_, false) => quote!(#core::sum_folded(#left, #right, #small)),
            (false, true) => quote!(#core::sum_folded(#right, #left, #small)),
            (true, true) => quote!(#core::sum_corrected(#left, #right, #small)),
        }
    }

    /// The methods `recover`, w = (T + T_lo) z0 - (A^{-1} + A^{-1}_lo) n(y) over the
    /// structural nonzeros, each row with its corrections inside its one rounding
    /// ([`Self::recover_row`]), and `recover_plain`, w = T z0 - A^{-1} n(y), each row one plain
    /// sum.
    fn recover(&self, forcing_lets: &[TokenStream]) -> TokenStream {
        let Emission {
            m,
            vec_s,
            vec_m,
            vec_m_path,
            ..
        } = self.e;
        let factors_ty = &self.factors_ty;
        let method = |name: Ident, doc: &str, compensated: bool| {
            let sets = (0..*m).map(|row| self.recover_row(row, compensated));
            quote! {
                #[doc = #doc]
                #[inline(always)]
                fn #name(
                    &self,
                    factors: &#factors_ty,
                    z0: &#vec_s,
                    forcing: &#vec_m,
                ) -> #vec_m {
                    #(#forcing_lets)*
                    #vec_m_path::from([#(#sets),*])
                }
            }
        };
        let compensated = method(
            format_ident!("recover"),
            " w = (T + T_lo) z0 - (A^{-1} + A^{-1}_lo) n(y) over the structural nonzeros, the \
             corrections inside each row's one rounding.",
            true,
        );
        let plain = method(
            format_ident!("recover_plain"),
            " w = T z0 - A^{-1} n(y) over the structural nonzeros, each row one plain sum.",
            false,
        );
        quote!(#compensated #plain)
    }
}

/// A term of a row of w.
enum Term {
    /// An exact value (a value times +-1).
    Exact(TokenStream),
    /// A product `a * b`.
    Product(TokenStream, TokenStream),
}

/// The name `__n<q>` of n_q(y) in the generated code.
fn n_name(q: usize) -> Ident {
    format_ident!("__n{}", q)
}

/// `z0[c]`.
fn z0_entry(c: usize) -> TokenStream {
    let c = index(c);
    quote!(z0[#c])
}

/// The sum of `factor[(row, c)] * value(c)` over the pattern `cols` of one row.
fn dot(factor: TokenStream, row: usize, cols: &[(usize, TokenStream)]) -> TokenStream {
    let terms: Vec<(bool, TokenStream)> = cols
        .iter()
        .map(|(c, value)| {
            let (r, c) = (index(row), index(*c));
            (false, quote!(#factor[(#r, #c)] * #value))
        })
        .collect();
    signed_sum(&terms)
}
