//! The expansion as a plain function, `TokenStream -> TokenStream`, testable without the
//! compiler's proc-macro bridge.

use proc_macro2::{Literal, TokenStream};
use quote::{ToTokens, format_ident, quote};
use syn::ItemFn;

use crate::codegen::emit;
use crate::emit::helpers::{
    Names, ParamTokens, allow_generated, callable, float_import, index, param_tokens, signed_sum,
    sum_tree, xu_leaf,
};
use crate::emit::scalar::{ScalarBodies, scalar_bodies};
use crate::graph::{Graph, Id};
use crate::lower::{Guard, GuardKind, Lower};
use crate::mechanics::{self, Degenerate, Mechanics};
use crate::signature::{self, Attribute, Signature};
use crate::util::{combine, tidy};

/// Expands `#[higher_order_lagrangian(attr)] item`; on error, the original item plus
/// `compile_error!`s, so the rest of the crate still type-checks. Never panics.
pub fn expand(attr: TokenStream, item: TokenStream) -> TokenStream {
    match try_expand(attr, item.clone()) {
        Ok(tokens) => tokens,
        Err(error) => {
            let errors = error.to_compile_error();
            quote!(#item #errors)
        }
    }
}

/// The expansion, or the errors of the input combined into one `syn::Error`.
pub fn try_expand(attr: TokenStream, item: TokenStream) -> syn::Result<TokenStream> {
    expand_counted(attr, item, &mut ExpansionStats::default())
}

/// The work of one expansion, counted in expression-graph nodes (deterministic, unlike wall
/// time): for tests that bound the work (the grammar fuzzer) and for benchmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExpansionStats {
    /// Nodes after lowering the body (the Lagrangian itself); 0 if the signature failed.
    pub lowered_nodes: usize,
    /// Nodes at the end (with the derivatives, the scheme and the guards at the step points).
    pub graph_nodes: usize,
    /// Guarded expressions (`check_domain`), factors included.
    pub guards: usize,
}

/// [`try_expand`] and the work it took (also when it failed).
pub fn expansion_stats(
    attr: TokenStream,
    item: TokenStream,
) -> (syn::Result<TokenStream>, ExpansionStats) {
    let mut stats = ExpansionStats::default();
    let result = expand_counted(attr, item, &mut stats);
    (result, stats)
}

fn expand_counted(
    attr: TokenStream,
    item: TokenStream,
    stats: &mut ExpansionStats,
) -> syn::Result<TokenStream> {
    let function: ItemFn = syn::parse2(item)?;
    let sig = signature::parse(attr, &function, Attribute::Lagrangian)?;
    let mut graph = Graph::default();
    let (root, guards) = {
        let mut lower = Lower::new(&mut graph, &sig);
        let root = lower.body(&function.block);
        stats.lowered_nodes = lower.g.len();
        stats.graph_nodes = lower.g.len();
        stats.guards = lower.guards.len();
        if let Some(e) = combine(std::mem::take(&mut lower.errors)) {
            return Err(e);
        }
        (root, std::mem::take(&mut lower.guards))
    };
    let mech = mechanics::build(&mut graph, root, sig.dim, sig.order);
    stats.graph_nodes = graph.len();
    let mech = mech.map_err(|reason| {
        let top = &sig.jet[sig.order];
        let msg = match reason {
            Degenerate::Independent => format!(
                "the Lagrangian does not depend on `{top}` = q^({}): its Legendre map is \
                 singular; lower the order or add a term in `{top}` (e.g. 0.5 * |{top}|^2)",
                sig.order
            ),
            Degenerate::Linear => format!(
                "the Lagrangian is linear in `{top}` = q^({}): d2L/d{top}2 = 0, so its Legendre \
                 map is singular; it must be (at least locally) strictly convex in `{top}`",
                sig.order
            ),
            Degenerate::Singular => format!(
                "d2L/d{top}2 is a singular constant matrix (or has a non-finite entry): the \
                 Legendre map is singular; every component of `{top}` must enter L \
                 quadratically with finite weights"
            ),
        };
        syn::Error::new(top.span(), msg)
    })?;
    let guards = if sig.guard {
        guards
            .into_iter()
            .map(|guard| {
                let points = mechanics::at_step_points(&mut graph, guard.node, sig.dim, sig.order);
                (guard, points)
            })
            .collect()
    } else {
        Vec::new()
    };
    let flat: Vec<Vec<Id>> = mech.hessian.clone();
    let reduced = mechanics::reduce(&mut graph, &mech.gradient, &flat, sig.dim, sig.order);
    stats.graph_nodes = graph.len();
    Ok(generate(
        &function,
        &sig,
        &graph,
        &mech,
        &guards,
        reduced.as_ref(),
    ))
}

/// The relative distance from zero below which a guarded factor counts as vanished.
const VANISH_TOLERANCE: f64 = 1e-9;
/// The rounding error of the fitted minimum, relative to the largest sample, over
/// `min(theta, 1 - theta)`: below it the fit cannot resolve anything.
const FIT_NOISE: f64 = 1e-13;

/// The "vanishes" rule of `check_domain`, emitted once as a local function: where the
/// quadratic through the samples `(0, a)`, `(theta, c)`, `(1, b)` (of one sign, by the sign
/// rule) has its extremum towards zero inside the step, it must stay more than
/// `VANISH_TOLERANCE` times the largest sample away from zero. The fit is exact for a factor
/// quadratic along the step (`x^2 + y^2 - r^2`, `|q'|^2`, `x^2 + y^2` of `atan2` and
/// `hypot`), so a step that passes through such a zero between the samples is caught. It is
/// skipped (only the sign rule applies) for `theta` within `1e-3` of an end and when the
/// smallest sample is below the fit's rounding error (a factor growing by 13 orders of
/// magnitude within one step), where it cannot resolve a zero.
fn clear_of_zero_fn() -> TokenStream {
    let tol = Literal::f64_suffixed(VANISH_TOLERANCE);
    let noise = Literal::f64_suffixed(FIT_NOISE);
    quote! {
        #[inline(always)]
        #[allow(dead_code)]
        fn __clear_of_zero(a: f64, b: f64, c: f64, theta: f64) -> bool {
            if !(theta > 1e-3 && theta < 1.0 - 1e-3) {
                return true;
            }
            let sign = if a < 0.0 { -1.0 } else { 1.0 };
            let (a, b, c) = (sign * a, sign * b, sign * c);
            let scale = a.max(b).max(c);
            if a.min(b).min(c) <= #noise * scale / theta.min(1.0 - theta) {
                return true;
            }
            // p(s) = a + beta s + alpha s^2 through the three samples
            let alpha = ((c - a) - theta * (b - a)) / (theta * theta - theta);
            let beta = (b - a) - alpha;
            let vertex = -beta / (2.0 * alpha);
            !(alpha > 0.0 && vertex > 0.0 && vertex < 1.0)
                || a + 0.5 * beta * vertex > #tol * scale
        }
    }
}

/// `check_domain`: each guard at the three points of a step, one loop per slice guard. A
/// denominator (and each factor of a guarded expression) must be finite, non-zero and of one
/// sign at the three points, a `sqrt` argument `>= 0`, `ln` and `powf` arguments `> 0`; and
/// every guarded expression must stay clear of zero between them (`clear_of_zero_fn`).
fn domain_check(
    g: &Graph,
    sig: &Signature,
    guards: &[(Guard, [Id; 3])],
    scheme: &Names<'_>,
) -> TokenStream {
    let core = quote!(::retract::__private::retract_core);
    let check = |guard: &Guard, values: &[TokenStream], element: TokenStream| {
        let (a, b, c) = (&values[0], &values[1], &values[2]);
        let text = &guard.text;
        let sign = if guard.factor {
            GuardKind::Denominator
        } else {
            guard.kind
        };
        let condition = match sign {
            // finite, non-zero and of one sign (NaN fails every comparison)
            GuardKind::Denominator => quote!((#a > 0.0 && #b > 0.0 && #c > 0.0
                    && #a < ::core::f64::INFINITY && #b < ::core::f64::INFINITY
                    && #c < ::core::f64::INFINITY)
                || (#a < 0.0 && #b < 0.0 && #c < 0.0 && #a > ::core::f64::NEG_INFINITY
                    && #b > ::core::f64::NEG_INFINITY && #c > ::core::f64::NEG_INFINITY)),
            GuardKind::SqrtArgument => quote!(#a >= 0.0 && #b >= 0.0 && #c >= 0.0),
            GuardKind::LnArgument | GuardKind::PowfBase => {
                quote!(#a > 0.0 && #b > 0.0 && #c > 0.0)
            }
        };
        let kind = match guard.kind {
            GuardKind::Denominator => quote!(Denominator),
            GuardKind::SqrtArgument => quote!(SqrtArgument),
            GuardKind::LnArgument => quote!(LnArgument),
            GuardKind::PowfBase => quote!(PowfBase),
        };
        let condition = if guard.touch {
            quote!((#condition) && __clear_of_zero(#a, #b, #c, theta))
        } else {
            condition
        };
        quote! {
            if !(#condition) {
                return ::core::result::Result::Err(#core::DomainViolation {
                    expression: #text,
                    kind: #core::DomainKind::#kind,
                    element: #element,
                });
            }
        }
    };
    let mut out = clear_of_zero_fn();
    let plain: Vec<&(Guard, [Id; 3])> = guards
        .iter()
        .filter(|(guard, _)| guard.slice.is_none())
        .collect();
    if !plain.is_empty() {
        let roots: Vec<Id> = plain.iter().flat_map(|(_, p)| p.iter().copied()).collect();
        let code = emit(g, &roots, scheme);
        let stmts = code.stmts;
        out.extend(quote!(#stmts));
        for (i, (guard, _)) in plain.iter().enumerate() {
            out.extend(check(
                guard,
                &code.exprs[3 * i..3 * i + 3],
                quote!(::core::option::Option::None),
            ));
        }
    }
    for (guard, points) in guards.iter().filter(|(guard, _)| guard.slice.is_some()) {
        let Some(param) = guard.slice else { continue };
        let code = emit(g, points, scheme);
        let stmts = code.stmts;
        let name = &sig.params[param as usize].name;
        let test = check(
            guard,
            &code.exprs,
            quote!(::core::option::Option::Some(__k)),
        );
        out.extend(quote! {
            for (__k, __e) in self.#name.iter().enumerate() {
                #stmts
                #test
            }
        });
    }
    out
}

fn generate(
    function: &ItemFn,
    sig: &Signature,
    g: &Graph,
    mech: &Mechanics,
    guards: &[(Guard, [Id; 3])],
    reduced: Option<&mechanics::Reduced>,
) -> TokenStream {
    let (n, k) = (sig.dim, sig.order);
    let (s, m) = (2 * n * k, 2 * n * k + n);
    let (n_lit, k_lit, s_lit, m_lit) = (index(n), index(k), index(s), index(m));
    let core = quote!(::retract::__private::retract_core);
    let na = quote!(::retract::__private::nalgebra);
    let vec_n = quote!(#na::SVector<f64, #n_lit>);
    let vec_n_path = quote!(#na::SVector::<f64, #n_lit>);
    let ty = &sig.type_name;
    let vis = &function.vis;
    let fn_name = &function.sig.ident;
    let ParamTokens {
        generics,
        ty_full,
        fields,
        ctor_args,
        field_names,
    } = param_tokens(sig, "L");
    let body_text = tidy(&function.block.to_token_stream().to_string());
    let struct_doc = format!(
        "The order-{k} Lagrangian [`{fn_name}`] on R^{n} with its parameters, as a system for \
         the `retract` runtime (generated by `#[higher_order_lagrangian]`).\n\n\
         L(q, ..., q^({k})) = `{body_text}`\n\n\
         State z = (x, p) of size {s} = 2nk; Newton unknowns w = (z_1, u) of size {m}."
    );

    // q^(order)[index] in each method
    let in_xu = |order: u8, i: u32| xu_leaf(k, order, i);
    let in_jet = |order: u8, i: u32| {
        let i = index(i as usize);
        if (order as usize) < k {
            let o = index(order as usize);
            quote!(lower[#o][#i])
        } else {
            let o = index(order as usize - k);
            quote!(upper[#o][#i])
        }
    };
    let none = |_: u8, _: u32| quote!(::core::f64::NAN);
    let xu = Names { sig, jet: &in_xu };
    let jet = Names { sig, jet: &in_jet };
    let scheme = Names { sig, jet: &none };

    let ScalarBodies {
        value: l_body,
        gradient: g_body,
        hessian: h_body,
    } = scalar_bodies(g, sig, mech.lagrangian, &mech.gradient, &mech.hessian);

    let momenta = emit(g, &mech.momenta, &jet);
    let p_stmts = momenta.stmts;
    let p_sets = mech.momenta.iter().enumerate().filter_map(|(a, &id)| {
        if g.is_const(id, 0.0) {
            return None;
        }
        let e = &momenta.exprs[a];
        let (j, i) = (index(a / n), index(a % n));
        Some(quote!(__out[#j][#i] = #e;))
    });

    let top_derivative = mech.legendre_inverse.as_ref().map(|inv| {
        let mut roots = inv.b.clone();
        roots.extend(inv.a.iter().copied());
        let code = emit(g, &roots, &xu);
        let stmts = code.stmts;
        let b = &code.exprs[..n];
        let rhs = (0..n).map(|i| {
            let bi = &b[i];
            let ii = index(i);
            quote!(p_top[#ii] - #bi)
        });
        let solve = match &inv.a_inv {
            Some(a_inv) => {
                let rows = (0..n).map(|r| {
                    let terms = (0..n).filter(|c| a_inv[r * n + c] != 0.0).map(|c| {
                        let v = crate::codegen::constant(a_inv[r * n + c]);
                        let c = index(c);
                        quote!(+ #v * __rhs[#c])
                    });
                    quote!(0.0 #(#terms)*)
                });
                quote! {
                    let __rhs: [f64; #n_lit] = [#(#rhs),*];
                    // `from` an array: nalgebra's `new` takes the entries only for n <= 6
                    ::core::result::Result::Ok(#vec_n_path::from([#(#rows),*]))
                }
            }
            None => {
                let a = &code.exprs[n..];
                let entries = (0..n * n).map(|e| {
                    let (r, c) = (index(e / n), index(e % n));
                    let v = &a[e];
                    quote!(__a[(#r, #c)] = #v;)
                });
                quote! {
                    let mut __a = #na::SMatrix::<f64, #n_lit, #n_lit>::zeros();
                    #(#entries)*
                    let __rhs = #vec_n_path::from([#(#rhs),*]);
                    #core::linalg::solve(&__a, &__rhs)
                        .ok_or(#core::Error::SingularJacobian { iteration: 0 })
                }
            }
        };
        let doc = if inv.a_inv.is_some() {
            "Closed-form Legendre inverse: L is quadratic in u with a constant Hessian A, so \
             u = A^{-1} (p_{k-1} - dL/du(x, 0)), with A^{-1} computed at compile time."
        } else {
            "Legendre inverse for L quadratic in u: solves A(x) u = p_{k-1} - dL/du(x, 0) with \
             A = d2L/du2 (independent of u), by LU."
        };
        quote! {
            #[doc = #doc]
            fn top_derivative(
                &self,
                x: &[#vec_n; #k_lit],
                p_top: &#vec_n,
                _guess: &#vec_n,
            ) -> ::core::result::Result<#vec_n, #core::Error> {
                #[allow(unused_imports)]
                use ::retract::__private::Float as _;
                #stmts
                #solve
            }
        }
    });

    let residual = emit(g, &mech.residual, &scheme);
    let r_stmts = residual.stmts;
    let r_sets = mech.residual.iter().enumerate().filter_map(|(r, &id)| {
        if g.is_const(id, 0.0) {
            return None;
        }
        let e = &residual.exprs[r];
        let r = index(r);
        Some(quote!(__out[#r] = #e;))
    });
    let matrix_sets = |entries: &[crate::graph::Id], cols: usize| {
        let code = emit(g, entries, &scheme);
        let sets: Vec<TokenStream> = entries
            .iter()
            .enumerate()
            .filter(|(_, id)| !g.is_const(**id, 0.0))
            .map(|(e, _)| {
                let v = &code.exprs[e];
                let (r, c) = (index(e / cols), index(e % cols));
                quote!(__out[(#r, #c)] = #v;)
            })
            .collect();
        (code.stmts, sets)
    };
    let (j_stmts, j_sets) = matrix_sets(&mech.jacobian, m);
    let (ji_stmts, ji_sets) = matrix_sets(&mech.jacobian_initial, s);

    let vec_s = quote!(#na::SVector<f64, #s_lit>);
    let vec_m = quote!(#na::SVector<f64, #m_lit>);
    let vec_m_path = quote!(#na::SVector::<f64, #m_lit>);
    let check_domain = (!guards.is_empty()).then(|| {
        let body = domain_check(g, sig, guards, &scheme);
        let mut list: Vec<String> = Vec::new();
        for (guard, _) in guards {
            let item = format!("`{}`", guard.text);
            if !list.contains(&item) {
                list.push(item);
            }
        }
        let doc = format!(
            "Domain check at x_0, x_1 and x_theta of a step (and between them, by the quadratic through \
             the three values). Denominators that must keep their \
             sign, and arguments of sqrt (>= 0), ln and powf (> 0): {}.",
            list.join(", ")
        );
        quote! {
            #[doc = #doc]
            fn check_domain(
                &self,
                z0: &#vec_s,
                w: &#vec_m,
                theta: f64,
            ) -> ::core::result::Result<(), #core::DomainViolation> {
                #[allow(unused_imports)]
                use ::retract::__private::Float as _;
                #body
                ::core::result::Result::Ok(())
            }
        }
    });

    let float = float_import();
    let allow = allow_generated();
    let reduced_unknowns = index(reduced.map_or(0, |r| r.core.len()));
    let reduced_impl = reduced.map(|red| {
        let r = red.core.len();
        let r_lit = index(r);
        let core_list = red.core.iter().map(|&c| index(c));
        let forced_list = red.rows.iter().map(|&q| index(q));
        let block_list = red.blocks.iter().map(|(rows, cols)| {
            let (rows, cols) = (
                rows.iter().map(|&i| index(i)),
                cols.iter().map(|&i| index(i)),
            );
            quote!((&[#(#rows),*], &[#(#cols),*]))
        });
        let (a_stmts, a_sets) = matrix_sets(&red.linear, m);
        let (b_stmts, b_sets) = matrix_sets(&red.initial, s);
        // structural nonzeros of T = -A^{-1} B, of A^{-1} (its forced columns are used), of
        // K = theta E A^{-1} and of G = (1 - theta) E + theta E T; where the closed form is
        // known, its zeros refine them and its constants are written in place of cached values
        let forced_count = red.rows.len();
        let closed_t =
            |row: usize, c: usize| red.closed_form.as_ref().map(|(t, _, _)| t[row * s + c]);
        let closed_a_inv = |row: usize, q: usize| {
            let f = red.rows.iter().position(|&r| r == q)?;
            red.closed_form
                .as_ref()
                .map(|(_, a_inv, _)| a_inv[row * forced_count + f])
        };
        let known_zero = |id: Option<crate::graph::Id>| id.is_some_and(|id| g.is_const(id, 0.0));
        let structural_t = mechanics::product_pattern(&red.inverse_pattern, &red.initial_pattern);
        let t_pattern: Vec<Vec<bool>> = (0..m)
            .map(|row| {
                (0..s)
                    .map(|c| structural_t[row][c] && !known_zero(closed_t(row, c)))
                    .collect()
            })
            .collect();
        let inverse_pattern: Vec<Vec<bool>> = (0..m)
            .map(|row| {
                (0..m)
                    .map(|q| red.inverse_pattern[row][q] && !known_zero(closed_a_inv(row, q)))
                    .collect()
            })
            .collect();
        let k_pattern: Vec<Vec<bool>> = red
            .core
            .iter()
            .map(|&c| inverse_pattern[c].clone())
            .collect();
        let g_pattern: Vec<Vec<bool>> = red
            .core
            .iter()
            .map(|&core| (0..s).map(|c| c == core || t_pattern[core][c]).collect())
            .collect();
        // a cached factor entry times a value, or the known constant times it
        let coefficient =
            |cached: TokenStream, known: Option<crate::graph::Id>, value: TokenStream| match known
                .and_then(|id| g.as_const(id))
            {
                Some(1.0) => (false, value),
                Some(-1.0) => (true, value),
                Some(v) => {
                    let v = crate::codegen::constant(v);
                    (false, quote!(#v * #value))
                }
                None => (false, quote!(#cached * #value)),
            };
        // sum of factor[(row, c)] * value(c) over the pattern of one row
        let dot = |factor: TokenStream, row: usize, cols: &[(usize, TokenStream)]| {
            let terms: Vec<(bool, TokenStream)> = cols
                .iter()
                .map(|(c, value)| {
                    let (r, c) = (index(row), index(*c));
                    (false, quote!(#factor[(#r, #c)] * #value))
                })
                .collect();
            signed_sum(&terms)
        };
        let z0_entry = |c: usize| {
            let c = index(c);
            quote!(z0[#c])
        };
        let offset_sets = g_pattern.iter().enumerate().map(|(row, pattern)| {
            let cols: Vec<(usize, TokenStream)> = (0..s)
                .filter(|&c| pattern[c])
                .map(|c| (c, z0_entry(c)))
                .collect();
            dot(quote!(factors.g), row, &cols)
        });

        // n_q(y) as __n<q>, and dn_q/dy
        let n_name = |q: usize| format_ident!("__n{}", q);
        let forces = emit(g, &red.nonlinear, &scheme);
        let force_stmts = &forces.stmts;
        // the forcing given as a vector: its forced rows under the names __n<q>
        let forcing_lets: Vec<TokenStream> = red
            .rows
            .iter()
            .map(|&q| {
                let (name, q) = (n_name(q), index(q));
                quote!(let #name: f64 = forcing[#q];)
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
        let force_lets: Vec<TokenStream> = red
            .rows
            .iter()
            .zip(&forces.exprs)
            .map(|(&q, e)| {
                let name = n_name(q);
                quote!(let #name: f64 = #e;)
            })
            .collect();
        let mut roots = red.nonlinear.clone();
        roots.extend(&red.nonlinear_jacobian);
        let with_jacobian = emit(g, &roots, &scheme);
        let wj_stmts = &with_jacobian.stmts;
        let wj_lets = red.rows.iter().zip(&with_jacobian.exprs).map(|(&q, e)| {
            let name = n_name(q);
            quote!(let #name: f64 = #e;)
        });
        let dn = |q_pos: usize, l: usize| {
            let id = red.nonlinear_jacobian[q_pos * r + l];
            (!g.is_const(id, 0.0))
                .then(|| with_jacobian.exprs[red.rows.len() + q_pos * r + l].clone())
        };
        let mut residual_entries = Vec::new();
        let mut jacobian_entries = vec![Vec::new(); r];
        for (mi, pattern) in k_pattern.iter().enumerate() {
            let cols: Vec<(usize, TokenStream)> = red
                .rows
                .iter()
                .filter(|&&q| pattern[q])
                .map(|&q| {
                    let name = n_name(q);
                    (q, quote!(#name))
                })
                .collect();
            let sum = dot(quote!(factors.k), mi, &cols);
            let mi_lit = index(mi);
            residual_entries.push(quote!(y[#mi_lit] - offset[#mi_lit] + #sum));
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
        let recover_sets = (0..m).map(|row| {
            let terms: Vec<(bool, TokenStream)> = (0..s)
                .filter(|&c| t_pattern[row][c])
                .map(|c| {
                    let (rl, cl, z) = (index(row), index(c), z0_entry(c));
                    coefficient(quote!(factors.t[(#rl, #cl)]), closed_t(row, c), z)
                })
                .collect();
            let forced: Vec<(bool, TokenStream)> = red
                .rows
                .iter()
                .filter(|&&q| inverse_pattern[row][q])
                .map(|&q| {
                    let (rl, ql, name) = (index(row), index(q), n_name(q));
                    let (negative, term) = coefficient(
                        quote!(factors.a_inv[(#rl, #ql)]),
                        closed_a_inv(row, q),
                        quote!(#name),
                    );
                    (!negative, term)
                })
                .collect();
            // the forcing is known last: its terms join the sum of the others at the end
            let parts: Vec<(bool, TokenStream)> = [sum_tree(&terms), sum_tree(&forced)]
                .into_iter()
                .flatten()
                .collect();
            signed_sum(&parts)
        });
        let forcing = emit(g, &red.nonlinear_jacobian, &scheme);
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
        let closed_form = red.closed_form.as_ref().map(|(t, a_inv, polynomial)| {
            let kind = if *polynomial {
                quote!(Polynomial)
            } else {
                quote!(Rational)
            };
            let mut roots = t.clone();
            roots.extend(a_inv);
            let code = emit(g, &roots, &scheme);
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
            quote! {
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
            }
        });
        let vec_r = quote!(#na::SVector<f64, #r_lit>);
        let factors_ty = quote!(#core::ReducedFactors<#s_lit, #m_lit, #r_lit>);
        let doc = format!(
            "The reduced step: the Hessian of L depends only on the jet components {:?} (flat \
             indices j n + i), so Newton runs on {r} unknowns instead of {m}; forces act in rows \
             {:?} of the residual.",
            red.core, red.rows
        );
        quote! {
            #[doc = #doc]
            #[automatically_derived]
            #allow
            impl #generics #core::ReducedScheme<#s_lit, #m_lit, #r_lit> for #ty_full {
                const CORE: [usize; #r_lit] = [#(#core_list),*];
                const FORCED: &'static [usize] = &[#(#forced_list),*];
                const BLOCKS: &'static [(&'static [usize], &'static [usize])] = &[#(#block_list),*];

                /// A = dF/dw at fixed y.
                fn linear_part(&self, h: f64, theta: f64) -> #na::SMatrix<f64, #m_lit, #m_lit> {
                    #float
                    #a_stmts
                    let mut __out = #na::SMatrix::<f64, #m_lit, #m_lit>::zeros();
                    #(#a_sets)*
                    __out
                }

                /// B = dF/dz0 at fixed y.
                fn initial_part(&self, h: f64, theta: f64) -> #na::SMatrix<f64, #m_lit, #s_lit> {
                    #float
                    #b_stmts
                    let mut __out = #na::SMatrix::<f64, #m_lit, #s_lit>::zeros();
                    #(#b_sets)*
                    __out
                }

                /// G z0 over the structural nonzeros of G.
                #[inline]
                fn core_offset(&self, factors: &#factors_ty, z0: &#vec_s) -> #vec_r {
                    #na::SVector::<f64, #r_lit>::from([#(#offset_sets),*])
                }

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

                #closed_form

                /// dn/dy, nonzero in the forced rows only.
                fn forcing_jacobian(
                    &self,
                    y: &#vec_r,
                    h: f64,
                    theta: f64,
                ) -> #na::SMatrix<f64, #m_lit, #r_lit> {
                    #float
                    #dn_stmts
                    let mut __out = #na::SMatrix::<f64, #m_lit, #r_lit>::zeros();
                    #(#dn_sets)*
                    __out
                }

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

                /// w = T z0 - A^{-1} n(y) over the structural nonzeros.
                #[inline]
                fn recover(
                    &self,
                    factors: &#factors_ty,
                    z0: &#vec_s,
                    forcing: &#vec_m,
                ) -> #vec_m {
                    #(#forcing_lets)*
                    #vec_m_path::from([#(#recover_sets),*])
                }
            }
        }
    });

    let jet_blocks = quote!([#vec_n; #k_lit]);

    let function = callable(function);

    quote! {
        #function

        #[doc = #struct_doc]
        #[derive(Clone, Copy, Debug, PartialEq)]
        #vis struct #ty #generics {
            #(#fields,)*
        }

        #[automatically_derived]
        impl #generics #ty_full {
            /// Dimension n of the configuration space.
            pub const DIMENSION: usize = #n_lit;
            /// Order k of the Lagrangian.
            pub const ORDER: usize = #k_lit;
            /// Size 2nk of the Hamiltonian state z = (x, p).
            pub const STATE: usize = #s_lit;
            /// Number 2nk + n of Newton unknowns w = (z_1, u) of one step.
            pub const UNKNOWNS: usize = #m_lit;
            /// Unknowns of the reduced step (`retract::ReducedScheme`), or 0 where the
            /// general step is kept.
            pub const REDUCED_UNKNOWNS: usize = #reduced_unknowns;

            /// The system with these parameters.
            #[allow(clippy::too_many_arguments)]
            pub fn new(#(#ctor_args),*) -> Self {
                Self { #(#field_names),* }
            }
        }

        #[automatically_derived]
        #allow
        impl #generics #core::Lagrangian<#n_lit, #k_lit> for #ty_full {
            /// L(x, u), straight-line code of the annotated function.
            fn lagrangian(&self, x: &#jet_blocks, u: &#vec_n) -> f64 {
                #l_body
            }

            /// (dL/dx_0, ..., dL/dx_{k-1}, dL/du), differentiated at compile time.
            fn gradient(&self, x: &#jet_blocks, u: &#vec_n) -> #core::Gradient<#n_lit, #k_lit> {
                #g_body
            }

            /// The Hessian of L in (x, u); structural zeros are not computed.
            fn hessian(&self, x: &#jet_blocks, u: &#vec_n) -> #core::Hessian<#n_lit, #k_lit> {
                #h_body
            }

            /// Ostrogradsky momenta p_{k-1} = dL/dq^(k), p_{j-1} = dL/dq^(j) - D p_j.
            fn momenta(&self, lower: &#jet_blocks, upper: &#jet_blocks) -> #jet_blocks {
                #float
                #p_stmts
                let mut __out = [#na::SVector::<f64, #n_lit>::zeros(); #k_lit];
                #(#p_sets)*
                __out
            }

            #top_derivative
        }

        #[automatically_derived]
        #allow
        impl #generics #core::LiftedSystem<#s_lit, #m_lit> for #ty_full {
            const DIMENSION: usize = #n_lit;
            const ORDER: usize = #k_lit;

            /// The Ostrogradsky Hamiltonian H(x, p).
            fn hamiltonian(&self, z: &#vec_s) -> ::core::result::Result<f64, #core::Error> {
                #core::lifted::hamiltonian::<Self, #n_lit, #k_lit, #s_lit>(self, z)
            }

            /// Hamilton's equations.
            fn vector_field(&self, z: &#vec_s) -> ::core::result::Result<#vec_s, #core::Error> {
                #core::lifted::vector_field::<Self, #n_lit, #k_lit, #s_lit>(self, z)
            }

            /// The Legendre map (q, ..., q^(2k-1)) -> (x, p).
            fn legendre(&self, jet: &#vec_s) -> #vec_s {
                #core::lifted::legendre::<Self, #n_lit, #k_lit, #s_lit>(self, jet)
            }

            /// F(z0, w) of the lifted theta-scheme, straight-line.
            fn residual(&self, z0: &#vec_s, w: &#vec_m, h: f64, theta: f64) -> #vec_m {
                #float
                #r_stmts
                let mut __out = #vec_m_path::zeros();
                #(#r_sets)*
                __out
            }

            /// dF/dw of the lifted theta-scheme; structural zeros are not computed.
            fn jacobian(
                &self,
                z0: &#vec_s,
                w: &#vec_m,
                h: f64,
                theta: f64,
            ) -> #na::SMatrix<f64, #m_lit, #m_lit> {
                #float
                #j_stmts
                let mut __out = #na::SMatrix::<f64, #m_lit, #m_lit>::zeros();
                #(#j_sets)*
                __out
            }

            /// dF/dz0 of the lifted theta-scheme; structural zeros are not computed.
            fn jacobian_initial(
                &self,
                z0: &#vec_s,
                w: &#vec_m,
                h: f64,
                theta: f64,
            ) -> #na::SMatrix<f64, #m_lit, #s_lit> {
                #float
                #ji_stmts
                let mut __out = #na::SMatrix::<f64, #m_lit, #s_lit>::zeros();
                #(#ji_sets)*
                __out
            }

            /// h L(x_theta, u), the cost of one step.
            fn step_cost(&self, z0: &#vec_s, w: &#vec_m, h: f64, theta: f64) -> f64 {
                #core::lifted::step_cost::<Self, #n_lit, #k_lit, #s_lit, #m_lit>(self, z0, w, h, theta)
            }

            #check_domain

            /// Explicit Euler guess of w.
            fn predictor(
                &self,
                z0: &#vec_s,
                h: f64,
                _theta: f64,
            ) -> ::core::result::Result<#vec_m, #core::Error> {
                #core::lifted::predictor::<Self, #n_lit, #k_lit, #s_lit, #m_lit>(self, z0, h)
            }
        }

        #reduced_impl
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The expansion, formatted, or the error messages.
    fn pretty(attr: &str, item: &str) -> Result<String, String> {
        let attr: TokenStream = attr.parse().map_err(|e| format!("{e}"))?;
        let item: TokenStream = item.parse().map_err(|e| format!("{e}"))?;
        let tokens = try_expand(attr, item).map_err(|e| {
            e.into_iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>()
                .join("\n")
        })?;
        let file: syn::File = syn::parse2(tokens).map_err(|e| e.to_string())?;
        Ok(prettyplease::unparse(&file))
    }

    #[test]
    fn every_supported_construct_expands() {
        let out = pretty(
            "order = 2, name = Everything",
            "pub fn all(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], a: f64, c: [f64; 2],
                        obs: &[[f64; 3]]) -> f64 {
                const N: usize = 2;
                const W: f64 = 0.5;
                let mut acc = 0.0;
                for i in 0..N { acc += W * ddq[i].powi(2); }
                for i in 0..=1 { acc -= (-dq[i]) * 0.0; }
                let mut m = 1.0;
                m *= 2.0;
                m /= 2.0;
                m = m + 0.0;
                for o in obs {
                    let d2 = (q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2];
                    acc += a / d2;
                }
                for o in obs.iter() { acc -= 0.0 * o[0]; }
                let t = q[0].sin() + q[1].cos() + q[0].tan().tanh() + q[1].exp().ln()
                    + q[0].hypot(q[1]) + q[1].atan2(q[0]) + q[0].abs().sqrt() + q[1].recip()
                    + q[0].powf(1.5) + c[1] * std::f64::consts::PI + f64::sqrt(q[0])
                    + (2 as f64) * q[1];
                m * acc + t
            }",
        )
        .unwrap();
        assert!(out.contains("pub struct Everything<'a>"), "{out}");
        assert!(out.contains("for __e in self.obs.iter()"), "{out}");
        assert!(out.contains("pub fn all("), "{out}");
    }

    #[test]
    fn errors_name_what_is_supported() {
        let err = |body: &str| {
            pretty(
                "order = 2",
                &format!("fn l(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {{ {body} }}"),
            )
            .unwrap_err()
        };
        assert!(
            err("ddq[0].powi(2) + q[0].norm()")
                .contains("unsupported method `norm`; supported: powi")
        );
        assert!(err("ddq[0].powi(2) + foo(q[0])").contains("unknown function `foo`"));
        assert!(err("if q[0] > 0.0 { ddq[0] } else { ddq[1] }").contains("`if` is not supported"));
        assert!(err("ddq[0].powi(2) + q[2]").contains("index 2 out of range"));
        assert!(err("q[0] + q[1]").contains("does not depend on `ddq`"));
        assert!(err("ddq[0] + q[1]").contains("linear in `ddq`"));
        assert!(err("ddq[0].powi(2) + q[1]").contains("singular constant matrix"));
        // all errors of one compile at once
        let both = err("let a = q[0].norm(); ddq[0].powi(2) + bar(a)");
        assert!(both.contains("norm") && both.contains("bar"), "{both}");
    }

    #[test]
    fn malformed_input_never_panics() {
        let cases = [
            ("", ""),
            ("order = 2", ""),
            ("order = 2", "struct S;"),
            ("order = 0", "fn l(q: f64) -> f64 { q }"),
            ("order = 9", "fn l(q: f64) -> f64 { q }"),
            ("order = x", "fn l(q: f64) -> f64 { q }"),
            (
                "order = 1, bogus",
                "fn l(q: f64, dq: f64) -> f64 { dq * dq }",
            ),
            ("order = 1", "fn l() -> f64 { 1.0 }"),
            ("order = 1", "fn l(q: f64, dq: f64) {}"),
            ("order = 1", "fn l(q: f64, dq: f64) -> f64 { }"),
            ("order = 1", "fn l(q: f64, dq: f64) -> f64 { return; }"),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { for i in 0.. { } dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { for i in 0..100000000 { } dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { let x; dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { dq.powi(99999999999) }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64) -> f64 { dq * dq / 0.0 + (-1.0f64).ln() }",
            ),
            (
                "order = 1",
                "fn l(q: [f64; 0], dq: [f64; 0]) -> f64 { 0.0 }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64, s: &[[f64; 2]]) -> f64 { for a in s { for b in s { } } dq * dq }",
            ),
            (
                "order = 1",
                "fn l(q: f64, dq: f64, s: &[[f64; 2]]) -> f64 { let mut x = 0.0; for a in s { x += a[0]; x += x; } dq * dq }",
            ),
        ];
        for (attr, item) in cases {
            let attr: TokenStream = attr.parse().unwrap();
            let item: TokenStream = item.parse().unwrap();
            let _ = expand(attr, item);
        }
    }

    #[test]
    fn expression_growth_is_bounded() {
        // n = 6, k = 2, 5 obstacles in an unrolled loop
        let (attr, item) = crate::samples::obstacle_field(6, 5);
        let tokens = try_expand(attr, item).unwrap();
        let file: syn::File = syn::parse2(tokens).unwrap();
        let lines = prettyplease::unparse(&file).lines().count();
        println!("expansion: {lines} lines");
        assert!(lines < 2000, "{lines} lines");
    }
}
