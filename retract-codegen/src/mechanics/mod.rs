//! The mechanics of a Lagrangian, as graph nodes: gradient and Hessian in (x, u), the
//! Ostrogradsky momenta, the Legendre inversion when L is quadratic in u, and the residual
//! and Jacobians of the lifted theta-scheme (formulas in `retract_core::LiftedSystem`).
//!
//! Built in one of two ways ([`Derivation`]): by forward differentiation throughout, the
//! scheme's Jacobians differentiated symbolically (`#[higher_order_lagrangian]`); or
//! structurally, for a Lagrangian whose expression is large (the effort of a mechanical
//! system, a function of tau(q, q', q''), and the plant whose mass matrix varies): the
//! gradient by reverse accumulation (O(nodes)), the Hessian-vector product H d as the
//! derivative of that gradient along a symbolic direction d (O(nodes); the emitted Hessian,
//! momenta of order 2 and Legendre inverse evaluate it at run time, `emit::structural`:
//! forward over reverse, exact; the nodes it reads that d does not change are hoisted out of
//! the loop over the directions), the rows of u of the Hessian alone as nodes (for the
//! degeneracy checks and the Legendre inverse's conditions), the total time derivatives of
//! the momenta in one directional sweep, and no symbolic scheme: the emitted residual and
//! Jacobians call `retract_core::lifted`'s generic functions, which evaluate the same
//! formulas from the gradient and Hessian at the evaluation point.

pub(crate) mod euler_lagrange;
pub(crate) mod lift;
pub(crate) mod map_conditions;
pub(crate) mod separable;

use std::collections::HashMap;

use crate::front::lower::Guard;
use crate::front::signature::Signature;
use crate::ir::diff::{
    Differentiator, directional, reverse_gradient, substitute, total_derivative, total_derivatives,
};
use crate::ir::graph::{Graph, Id, Var};

/// u = A^{-1} (p_{k-1} - b(x)) where L is quadratic in u: A = d2L/du2 does not depend on u,
/// b = dL/du at u = 0.
pub struct LegendreInverse {
    /// A, row-major n x n.
    pub a: Vec<Id>,
    /// b(x), n entries.
    pub b: Vec<Id>,
    /// A^{-1} when every entry of A is a number (row-major), else the inversion is a
    /// run-time linear solve.
    pub a_inv: Option<Vec<f64>>,
}

/// Every quantity the emitted code needs.
pub struct Mechanics {
    pub lagrangian: Id,
    /// dL/dq^(j)_i at `j * n + i`, j = 0..=k.
    pub gradient: Vec<Id>,
    /// Hessian over the same index, full and symmetric (shared ids); where
    /// `hessian_vector` is given, only the rows and columns of u (the x-x block zeros).
    pub hessian: Vec<Vec<Id>>,
    /// H d for a direction d: the Hessian's columns at run time
    /// ([`Derivation::structural`]).
    pub hessian_vector: Option<HessianVector>,
    /// p_j component i at `j * n + i`, j = 0..k, as functions of q..q^(2k-1).
    pub momenta: Vec<Id>,
    pub legendre_inverse: Option<LegendreInverse>,
    /// The residual and Jacobians of the scheme as nodes; `None` where the emitted scheme
    /// calls the generic functions of `retract_core::lifted` ([`Derivation::structural`]).
    pub scheme: Option<Scheme>,
}

/// The Hessian-vector product H d (d: `Var::Direction`, entry `j * n + i`) split for a
/// run-time loop over the directions: `hoisted`, the nodes that H d reads and d does not
/// change (L's value and gradient below them), evaluated once; `column`, H d with each of
/// them as `Var::Hoisted(i)`.
pub struct HessianVector {
    /// The nodes evaluated before the loop.
    pub hoisted: Vec<Id>,
    /// H d, entry `j * n + i`, over `Var::Hoisted`, `Var::Direction` and the jet.
    pub column: Vec<Id>,
}

/// `hv` split into the nodes that do not depend on `Var::Direction` and that a node which
/// does reads (the frontier, hoisted), and `hv` with each frontier node replaced by
/// `Var::Hoisted(i)`; nothing hoisted where `hv` has a sum over a slice (a node of its body
/// reads the loop's element).
fn hoist(g: &mut Graph, hv: &[Id]) -> HessianVector {
    let mut below: Vec<Id> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut stack: Vec<Id> = hv.to_vec();
    while let Some(id) = stack.pop() {
        if seen.insert(id) {
            below.push(id);
            stack.extend(crate::ir::graph::children(g.node(id)));
        }
    }
    below.sort_unstable();
    if below
        .iter()
        .any(|&id| matches!(g.node(id), crate::ir::graph::Node::Sum { .. }))
    {
        return HessianVector {
            hoisted: Vec::new(),
            column: hv.to_vec(),
        };
    }
    let mut varying = std::collections::HashSet::new();
    let mut hoisted = Vec::new();
    let mut memo = HashMap::new();
    for &id in &below {
        let node = g.node(id).clone();
        let kids = crate::ir::graph::children(&node);
        let on = match node {
            crate::ir::graph::Node::Var(v) => matches!(v, Var::Direction(_)),
            _ => kids.iter().any(|c| varying.contains(c)),
        };
        if !on {
            continue;
        }
        varying.insert(id);
        for c in kids {
            let leaf = crate::ir::graph::children(g.node(c)).is_empty();
            if !varying.contains(&c) && !leaf && !memo.contains_key(&c) {
                let placeholder = g.var(Var::Hoisted(hoisted.len() as u32));
                memo.insert(c, placeholder);
                hoisted.push(c);
            }
        }
    }
    let unchanged = |_: &mut Graph, _: Var| None;
    let column = hv
        .iter()
        .map(|&id| substitute(g, id, &unchanged, &mut memo))
        .collect();
    HessianVector { hoisted, column }
}

/// The lifted theta-scheme as graph nodes.
pub struct Scheme {
    /// F(z0, w), M = 2nk + n entries.
    pub residual: Vec<Id>,
    /// dF/dw, row-major M x M.
    pub jacobian: Vec<Id>,
    /// dF/dz0, row-major M x S.
    pub jacobian_initial: Vec<Id>,
}

/// How [`build_with`] derives the mechanics (module docs).
#[derive(Clone, Copy, Default)]
pub struct Derivation {
    /// Accept a constant singular A = d2L/du2 (no Legendre inverse then): an
    /// optimal-control cost whose singular directions the stage equalities fix, as the
    /// effort of an underactuated mechanical system.
    pub singular_allowed: bool,
    /// The structural build (module docs); else forward differentiation throughout.
    pub structural: bool,
}

/// Why the mechanics cannot be built.
pub enum Degenerate {
    /// L does not depend on u at all.
    Independent,
    /// L depends on u but d2L/du2 vanishes identically (e.g. linear in u).
    Linear,
    /// A = d2L/du2 is constant and singular.
    Singular,
}

fn jet(order: usize, index: usize) -> Var {
    Var::Jet {
        order: order as u8,
        index: index as u32,
    }
}

/// The gradient of `f` in the jet q, ..., q^(k) on R^n (entry `j * n + i` is df/dq^(j)_i) and
/// its Hessian over the same index, full and symmetric (shared ids), with the differentiator
/// that computed them (its memo serves later derivatives).
pub fn derivatives(
    g: &mut Graph,
    f: Id,
    n: usize,
    k: usize,
) -> (Differentiator, Vec<Id>, Vec<Vec<Id>>) {
    let built = derivatives_with(g, f, n, k, false);
    (built.d, built.gradient, built.hessian)
}

/// [`derivatives`]; where `reverse`, the gradient by reverse accumulation
/// (`ir::diff::reverse_gradient`; forward where f sums over a slice), only the rows and
/// columns of u of the Hessian, and the Hessian-vector product H d (`Var::Direction`) as the
/// derivative of the gradient along d.
fn derivatives_with(g: &mut Graph, f: Id, n: usize, k: usize, reverse: bool) -> Derivatives {
    let mut d = Differentiator::default();
    let vars: Vec<Var> = (0..=k)
        .flat_map(|j| (0..n).map(move |i| jet(j, i)))
        .collect();
    let gradient: Vec<Id> = match reverse.then(|| reverse_gradient(g, f, &vars)).flatten() {
        Some(gradient) => gradient,
        None => vars.iter().map(|&v| d.diff(g, f, v)).collect(),
    };
    let m = vars.len();
    let mut hessian = vec![vec![g.constant(0.0); m]; m];
    for a in 0..m {
        // (structural: the rows of u only, each entry the derivative of dL/du_b)
        let first = if reverse { a.max(k * n) } else { a };
        for b in first..m {
            let h = if reverse {
                d.diff(g, gradient[b], vars[a])
            } else {
                d.diff(g, gradient[a], vars[b])
            };
            hessian[a][b] = h;
            hessian[b][a] = h;
        }
    }
    let hessian_vector = reverse.then(|| {
        let along = |g: &mut Graph, v: Var| match v {
            Var::Jet { order, index } => {
                Some(g.var(Var::Direction(u32::from(order) * n as u32 + index)))
            }
            _ => None,
        };
        let hv = directional(g, &gradient, &along);
        hoist(g, &hv)
    });
    Derivatives {
        d,
        gradient,
        hessian,
        hessian_vector,
    }
}

/// What [`derivatives_with`] builds.
struct Derivatives {
    /// The differentiator, its memo for later derivatives.
    d: Differentiator,
    gradient: Vec<Id>,
    hessian: Vec<Vec<Id>>,
    hessian_vector: Option<HessianVector>,
}

/// Builds the mechanics of L = `lagrangian` of order k on R^n.
pub fn build(g: &mut Graph, lagrangian: Id, n: usize, k: usize) -> Result<Mechanics, Degenerate> {
    build_with(g, lagrangian, n, k, Derivation::default())
}

/// [`build`], derived as `how` says.
pub fn build_with(
    g: &mut Graph,
    lagrangian: Id,
    n: usize,
    k: usize,
    how: Derivation,
) -> Result<Mechanics, Degenerate> {
    let Derivatives {
        mut d,
        gradient,
        hessian,
        hessian_vector,
    } = derivatives_with(g, lagrangian, n, k, how.structural);

    // Degeneracy in the top derivative.
    let top = k * n;
    let a: Vec<Id> = (0..n * n)
        .map(|r| hessian[top + r / n][top + r % n])
        .collect();
    if a.iter().all(|&e| g.is_const(e, 0.0)) {
        return Err(if gradient[top..].iter().all(|&e| g.is_const(e, 0.0)) {
            Degenerate::Independent
        } else {
            Degenerate::Linear
        });
    }

    // Momenta: p_{k-1} = dL/dq^(k); p_{j-1} = dL/dq^(j) - D p_j.
    let mut momenta = vec![g.constant(0.0); n * k];
    momenta[(k - 1) * n..].copy_from_slice(&gradient[top..top + n]);
    for j in (1..k).rev() {
        let block = j * n..(j + 1) * n;
        let dp: Vec<Id> = if how.structural {
            total_derivatives(g, &momenta[block], n, 2 * k - 1)
        } else {
            block
                .map(|a| total_derivative(g, &mut d, momenta[a], n, 2 * k - 1))
                .collect()
        };
        for (i, dp) in dp.into_iter().enumerate() {
            momenta[(j - 1) * n + i] = g.sub(gradient[j * n + i], dp);
        }
    }

    let legendre_inverse = match legendre_inverse(g, &mut d, &a, &gradient[top..], n, k) {
        Err(Degenerate::Singular) if how.singular_allowed => None,
        other => other?,
    };
    let scheme = (!how.structural).then(|| scheme(g, &mut d, &gradient, n, k));
    Ok(Mechanics {
        lagrangian,
        gradient,
        hessian,
        hessian_vector,
        momenta,
        legendre_inverse,
        scheme,
    })
}

fn legendre_inverse(
    g: &mut Graph,
    d: &mut Differentiator,
    a: &[Id],
    grad_u: &[Id],
    n: usize,
    k: usize,
) -> Result<Option<LegendreInverse>, Degenerate> {
    let depends_on_u = a.iter().any(|&e| {
        (0..n).any(|i| {
            let de = d.diff(g, e, jet(k, i));
            !g.is_const(de, 0.0)
        })
    });
    if depends_on_u {
        return Ok(None);
    }
    let mut memo = HashMap::new();
    let zero_u = move |g: &mut Graph, v: Var| match v {
        Var::Jet { order, .. } if order as usize == k => Some(g.constant(0.0)),
        _ => None,
    };
    let b = grad_u
        .iter()
        .map(|&e| substitute(g, e, &zero_u, &mut memo))
        .collect();
    let numbers: Option<Vec<f64>> = a.iter().map(|&e| g.as_const(e)).collect();
    let a_inv = match numbers {
        Some(values) => Some(invert(&values, n).ok_or(Degenerate::Singular)?),
        None => None,
    };
    Ok(Some(LegendreInverse {
        a: a.to_vec(),
        b,
        a_inv,
    }))
}

/// Gauss-Jordan inverse with partial pivoting; `None` if singular or not finite.
pub(crate) fn invert(a: &[f64], n: usize) -> Option<Vec<f64>> {
    if a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let mut m = a.to_vec();
    let mut inv: Vec<f64> = (0..n * n)
        .map(|r| if r / n == r % n { 1.0 } else { 0.0 })
        .collect();
    let scale = a.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&x, &y| m[x * n + col].abs().total_cmp(&m[y * n + col].abs()))?;
        if m[pivot * n + col].abs() <= 1e-14 * scale {
            return None;
        }
        for c in 0..n {
            m.swap(col * n + c, pivot * n + c);
            inv.swap(col * n + c, pivot * n + c);
        }
        let p = m[col * n + col];
        for c in 0..n {
            m[col * n + c] /= p;
            inv[col * n + c] /= p;
        }
        for r in 0..n {
            if r != col {
                let f = m[r * n + col];
                for c in 0..n {
                    m[r * n + c] -= f * m[col * n + c];
                    inv[r * n + c] -= f * inv[col * n + c];
                }
            }
        }
    }
    inv.iter().all(|v| v.is_finite()).then_some(inv)
}

/// The evaluation point of a step: x_theta = (1 - theta) x_0 + theta x_1 and
/// p_theta = theta p_0 + (1 - theta) p_1, componentwise, as graph nodes.
fn evaluation_point(g: &mut Graph, n: usize, k: usize) -> (Vec<Id>, Vec<Id>) {
    let theta = g.var(Var::Theta);
    let one = g.constant(1.0);
    let one_minus_theta = g.sub(one, theta);
    let mut x_th = Vec::with_capacity(n * k);
    let mut p_th = Vec::with_capacity(n * k);
    for j in 0..k {
        for i in 0..n {
            let (x0, x1) = (
                g.var(Var::Z0((j * n + i) as u32)),
                g.var(Var::W((j * n + i) as u32)),
            );
            let (ta, tb) = (g.mul(one_minus_theta, x0), g.mul(theta, x1));
            x_th.push(g.add_op(ta, tb));
            let c = ((k + j) * n + i) as u32;
            let (p0, p1) = (g.var(Var::Z0(c)), g.var(Var::W(c)));
            let (ta, tb) = (g.mul(theta, p0), g.mul(one_minus_theta, p1));
            p_th.push(g.add_op(ta, tb));
        }
    }
    (x_th, p_th)
}

/// The residual F(z0, w) of the theta-scheme, given the gradient of L already evaluated at
/// the evaluation point (`g_at[j * n + i]` = dL/dq^(j)_i, j = 0..=k).
fn residual_from(
    g: &mut Graph,
    g_at: &[Id],
    p_th: &[Id],
    x_th: &[Id],
    n: usize,
    k: usize,
) -> Vec<Id> {
    let s = 2 * n * k;
    let h = g.var(Var::Step);
    let mut f = vec![g.constant(0.0); s + n];
    for j in 0..k {
        for i in 0..n {
            let rate = if j + 1 < k {
                x_th[(j + 1) * n + i]
            } else {
                g.var(Var::W((s + i) as u32))
            };
            let (a, b) = (
                g.var(Var::W((j * n + i) as u32)),
                g.var(Var::Z0((j * n + i) as u32)),
            );
            let diff = g.sub(a, b);
            let hr = g.mul(h, rate);
            f[j * n + i] = g.sub(diff, hr);

            let mut force = g_at[j * n + i];
            if j > 0 {
                force = g.sub(force, p_th[(j - 1) * n + i]);
            }
            let c = ((k + j) * n + i) as u32;
            let (a, b) = (g.var(Var::W(c)), g.var(Var::Z0(c)));
            let diff = g.sub(a, b);
            let hf = g.mul(h, force);
            f[(k + j) * n + i] = g.sub(diff, hf);
        }
    }
    for i in 0..n {
        f[s + i] = g.sub(p_th[(k - 1) * n + i], g_at[k * n + i]);
    }
    f
}

/// The gradient with jet component (j, i) replaced by `at(j, i)`.
fn gradient_at(
    g: &mut Graph,
    gradient: &[Id],
    at: &dyn Fn(&mut Graph, usize, usize) -> Option<Id>,
) -> Vec<Id> {
    let map = |g: &mut Graph, v: Var| match v {
        Var::Jet { order, index } => at(g, order as usize, index as usize),
        _ => None,
    };
    let mut memo = HashMap::new();
    gradient
        .iter()
        .map(|&e| substitute(g, e, &map, &mut memo))
        .collect()
}

/// dF/dw (row-major M x M) and dF/dz0 (row-major M x S) of residual rows `f`.
fn jacobians(
    g: &mut Graph,
    d: &mut Differentiator,
    f: &[Id],
    m: usize,
    s: usize,
) -> (Vec<Id>, Vec<Id>) {
    let mut by_w = Vec::with_capacity(m * m);
    let mut by_z0 = Vec::with_capacity(m * s);
    for &row in f {
        for c in 0..m {
            by_w.push(d.diff(g, row, Var::W(c as u32)));
        }
        for c in 0..s {
            by_z0.push(d.diff(g, row, Var::Z0(c as u32)));
        }
    }
    (by_w, by_z0)
}

/// Residual F(z0, w) of the theta-scheme and its Jacobians.
fn scheme(g: &mut Graph, d: &mut Differentiator, gradient: &[Id], n: usize, k: usize) -> Scheme {
    let s = 2 * n * k;
    let m = s + n;
    let (x_th, p_th) = evaluation_point(g, n, k);
    let at = |g: &mut Graph, j: usize, i: usize| {
        Some(if j < k {
            x_th[j * n + i]
        } else {
            g.var(Var::W((s + i) as u32))
        })
    };
    let g_at = gradient_at(g, gradient, &at);
    let f = residual_from(g, &g_at, &p_th, &x_th, n, k);
    let (jacobian, jacobian_initial) = jacobians(g, d, &f, m, s);
    Scheme {
        residual: f,
        jacobian,
        jacobian_initial,
    }
}

/// The reduced step: F(z0, w) = A w + B z0 + n(y), with y the values at the evaluation point
/// of the jet components on which the Hessian of L depends (the nonlinear core) and A, B
/// depending on h, theta and parameters only.
pub struct Reduced {
    /// Jet index j * n + i (j < k) of each core variable.
    pub core: Vec<usize>,
    /// A = dF/dw at fixed y, row-major M x M.
    pub linear: Vec<Id>,
    /// B = dF/dz0 at fixed y, row-major M x S.
    pub initial: Vec<Id>,
    /// The rows q of F where n(y) is not identically zero, ascending.
    pub rows: Vec<usize>,
    /// n_q(y) for each q in `rows`.
    pub nonlinear: Vec<Id>,
    /// dn_q/dy, row-major |rows| x R.
    pub nonlinear_jacobian: Vec<Id>,
    /// K n(y), row m the sum of `k_mq n_q(y)` over the entries (m, q) of `scale_entries`,
    /// `k_mq` the leaf `Var::Hoisted(i)` of the i-th entry: the factor enters the product
    /// chain of n_q with its other early operands, not after its last one.
    pub scaled: Vec<Id>,
    /// The entries (m, q) of K that `scaled` multiplies, in the order of their leaves: the
    /// structural nonzeros of the core rows of A^{-1} at the forced columns, less the zeros
    /// of the closed form.
    pub scale_entries: Vec<(usize, usize)>,
    /// The irreducible blocks of A: (rows, columns), ascending.
    pub blocks: Vec<(Vec<usize>, Vec<usize>)>,
    /// Structural nonzeros of A^{-1}, M x M (a superset: entries in one irreducible block).
    pub inverse_pattern: Vec<Vec<bool>>,
    /// Structural nonzeros of B, M x S.
    pub initial_pattern: Vec<Vec<bool>>,
    /// T = -A^{-1} B (row-major M x S) and the columns of A^{-1} at the forced rows
    /// (row-major M x |rows|) as expressions in h, theta and the parameters, from a symbolic
    /// elimination of each block, and whether every pivot was a nonzero constant (then the
    /// expressions are polynomials: no division); `None` when an elimination grows too large.
    pub closed_form: Option<(Vec<Id>, Vec<Id>, bool)>,
}

/// Nodes a symbolic block elimination may add before the closed form is given up.
const CLOSED_FORM_BUDGET: usize = 20_000;

/// X with A X = Y for a small square A of graph nodes, by Gauss-Jordan elimination with
/// structural pivoting: in each column the pivot is the nonzero constant of largest magnitude
/// among the remaining rows if there is one, else the first structurally nonzero entry (whose
/// value the run-time check of the factors guards). `None` if a column has no structurally
/// nonzero candidate or the graph grows past `budget` nodes. The flag says whether every
/// pivot was a nonzero constant.
pub(crate) fn symbolic_solve(
    g: &mut Graph,
    mut a: Vec<Vec<Id>>,
    mut y: Vec<Vec<Id>>,
    budget: usize,
) -> Option<(Vec<Vec<Id>>, bool)> {
    let n = a.len();
    let start = g.len();
    let mut constant_pivots = true;
    for col in 0..n {
        let candidates = (col..n).filter(|&r| !g.is_const(a[r][col], 0.0));
        let constant = candidates
            .clone()
            .filter_map(|r| g.as_const(a[r][col]).map(|v| (r, v.abs())))
            .max_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(r, _)| r);
        constant_pivots &= constant.is_some();
        let pivot_row = constant.or_else(|| candidates.clone().next())?;
        a.swap(col, pivot_row);
        y.swap(col, pivot_row);
        let pivot = a[col][col];
        for entry in a[col][col..].iter_mut().chain(y[col].iter_mut()) {
            *entry = g.div(*entry, pivot);
        }
        let (pivot_a, pivot_y) = (a[col].clone(), y[col].clone());
        for (r, (row_a, row_y)) in a.iter_mut().zip(y.iter_mut()).enumerate() {
            let factor = row_a[col];
            if r == col || g.is_const(factor, 0.0) {
                continue;
            }
            for (entry, &p) in row_a[col..]
                .iter_mut()
                .chain(row_y.iter_mut())
                .zip(pivot_a[col..].iter().chain(&pivot_y))
            {
                let update = g.mul(factor, p);
                *entry = g.sub(*entry, update);
            }
        }
        if g.len() - start > budget {
            return None;
        }
    }
    Some((y, constant_pivots))
}

/// T = -A^{-1} B and the columns of A^{-1} at the forced rows, block by block.
fn closed_form(
    g: &mut Graph,
    linear: &[Id],
    initial: &[Id],
    forced: &[usize],
    blocks: &[(Vec<usize>, Vec<usize>)],
    m: usize,
    s: usize,
) -> Option<(Vec<Id>, Vec<Id>, bool)> {
    let zero = g.constant(0.0);
    let mut polynomial = true;
    let one = g.constant(1.0);
    let mut t = vec![zero; m * s];
    let mut a_inv = vec![zero; m * forced.len()];
    let budget_start = g.len();
    for (rows, cols) in blocks {
        let a: Vec<Vec<Id>> = rows
            .iter()
            .map(|&r| cols.iter().map(|&c| linear[r * m + c]).collect())
            .collect();
        let y: Vec<Vec<Id>> = rows
            .iter()
            .map(|&r| {
                let mut row: Vec<Id> = initial[r * s..(r + 1) * s].to_vec();
                row.extend(forced.iter().map(|&q| if q == r { one } else { zero }));
                row
            })
            .collect();
        let used = g.len() - budget_start;
        let (x, constant_pivots) = symbolic_solve(g, a, y, CLOSED_FORM_BUDGET.checked_sub(used)?)?;
        polynomial &= constant_pivots;
        for (j, &c) in cols.iter().enumerate() {
            for col in 0..s {
                t[c * s + col] = g.neg(x[j][col]);
            }
            for f in 0..forced.len() {
                a_inv[c * forced.len() + f] = x[j][s + f];
            }
        }
    }
    Some((t, a_inv, polynomial))
}

/// The reduced step of L, if its Hessian depends on some jet components but on no component
/// of the top derivative u (else the general scheme is kept).
pub fn reduce(
    g: &mut Graph,
    gradient: &[Id],
    hessian: &[Vec<Id>],
    n: usize,
    k: usize,
) -> Option<Reduced> {
    let (s, m) = (2 * n * k, 2 * n * k + n);
    let vars = n * (k + 1);
    let varying = |g: &Graph, id: Id| depends_on(g, id, &|v| matches!(v, Var::Jet { .. }));
    // (the rows of u first: one that varies rules the reduction out before the others are
    // searched)
    if (k * n..vars).any(|a| (0..vars).any(|b| varying(g, hessian[a][b]))) {
        return None;
    }
    let core: Vec<usize> = (0..vars)
        .filter(|&a| (0..vars).any(|b| varying(g, hessian[a][b])))
        .collect();
    if core.is_empty() || core.iter().any(|&a| a >= k * n) {
        return None;
    }
    let (x_th, p_th) = evaluation_point(g, n, k);
    let at = |g: &mut Graph, j: usize, i: usize| {
        let a = j * n + i;
        Some(match core.iter().position(|&c| c == a) {
            Some(pos) => g.var(Var::Core(pos as u32)),
            None if j < k => x_th[a],
            None => g.var(Var::W((s + i) as u32)),
        })
    };
    let g_at = gradient_at(g, gradient, &at);
    let f = residual_from(g, &g_at, &p_th, &x_th, n, k);
    let mut d = Differentiator::default();
    let (linear, initial) = jacobians(g, &mut d, &f, m, s);
    // A and B must not depend on the state or the core (else the split is not affine)
    let on_state = |v: &Var| matches!(v, Var::W(_) | Var::Core(_) | Var::Z0(_));
    if linear
        .iter()
        .chain(&initial)
        .any(|&e| depends_on(g, e, &on_state))
    {
        return None;
    }
    // n(y) = F at w = 0, z0 = 0
    let zero_state =
        |g: &mut Graph, v: Var| matches!(v, Var::W(_) | Var::Z0(_)).then(|| g.constant(0.0));
    let mut memo = HashMap::new();
    let mut rows = Vec::new();
    let mut nonlinear = Vec::new();
    for (q, &e) in f.iter().enumerate() {
        let value = substitute(g, e, &zero_state, &mut memo);
        if !g.is_const(value, 0.0) {
            rows.push(q);
            nonlinear.push(value);
        }
    }
    let mut nonlinear_jacobian = Vec::with_capacity(rows.len() * core.len());
    for &e in &nonlinear {
        for c in 0..core.len() {
            nonlinear_jacobian.push(d.diff(g, e, Var::Core(c as u32)));
        }
    }
    let pattern = |entries: &[Id], cols: usize| -> Vec<Vec<bool>> {
        entries
            .chunks(cols)
            .map(|row| row.iter().map(|&e| !g.is_const(e, 0.0)).collect())
            .collect()
    };
    let linear_pattern = pattern(&linear, m);
    let blocks = blocks(&linear_pattern);
    // a block with more rows than columns (or fewer) makes A singular for every h
    if blocks.iter().any(|(rows, cols)| rows.len() != cols.len()) {
        return None;
    }
    let inverse_pattern = inverse_pattern(&linear_pattern);
    let initial_pattern = pattern(&initial, s);
    let closed_form = closed_form(g, &linear, &initial, &rows, &blocks, m, s);
    let (scaled, scale_entries) =
        scaled_forcing(g, &core, &rows, &nonlinear, &inverse_pattern, &closed_form);
    Some(Reduced {
        core,
        linear,
        initial,
        rows,
        nonlinear,
        nonlinear_jacobian,
        scaled,
        scale_entries,
        blocks,
        inverse_pattern,
        initial_pattern,
        closed_form,
    })
}

/// K n(y) over the structural nonzeros of K (the core rows of A^{-1} at the forced columns,
/// less the closed form's zeros), each entry of K a leaf `Var::Hoisted(i)`; with the entries
/// (m, q), in the order of i ([`Reduced::scaled`]).
fn scaled_forcing(
    g: &mut Graph,
    core: &[usize],
    rows: &[usize],
    nonlinear: &[Id],
    inverse_pattern: &[Vec<bool>],
    closed_form: &Option<(Vec<Id>, Vec<Id>, bool)>,
) -> (Vec<Id>, Vec<(usize, usize)>) {
    let mut entries = Vec::new();
    let mut scaled = Vec::with_capacity(core.len());
    for (mi, &c) in core.iter().enumerate() {
        let mut sum = None;
        for (f, (&q, &n_q)) in rows.iter().zip(nonlinear).enumerate() {
            let known_zero = closed_form
                .as_ref()
                .is_some_and(|(_, a_inv, _)| g.is_const(a_inv[c * rows.len() + f], 0.0));
            if !inverse_pattern[c][q] || known_zero {
                continue;
            }
            let k = g.var(Var::Hoisted(entries.len() as u32));
            entries.push((mi, q));
            let term = g.mul(k, n_q);
            sum = Some(match sum {
                Some(s) => g.add_op(s, term),
                None => term,
            });
        }
        scaled.push(sum.unwrap_or_else(|| g.constant(0.0)));
    }
    (scaled, entries)
}

/// The irreducible blocks of a square pattern: rows and columns (ascending) connected through
/// nonzeros, in the order of their first row. A is block diagonal after permuting rows and
/// columns by them.
pub fn blocks(a: &[Vec<bool>]) -> Vec<(Vec<usize>, Vec<usize>)> {
    let m = a.len();
    // union-find over rows 0..m and columns m..2m
    let mut parent: Vec<usize> = (0..2 * m).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for (r, row) in a.iter().enumerate() {
        for (c, &nonzero) in row.iter().enumerate() {
            if nonzero {
                let (x, y) = (find(&mut parent, r), find(&mut parent, m + c));
                parent[x] = y;
            }
        }
    }
    let mut out: Vec<(usize, Vec<usize>, Vec<usize>)> = Vec::new();
    for node in 0..2 * m {
        let root = find(&mut parent, node);
        let slot = match out.iter().position(|(r, _, _)| *r == root) {
            Some(slot) => slot,
            None => {
                out.push((root, Vec::new(), Vec::new()));
                out.len() - 1
            }
        };
        if node < m {
            out[slot].1.push(node);
        } else {
            out[slot].2.push(node - m);
        }
    }
    out.into_iter()
        .map(|(_, rows, cols)| (rows, cols))
        .collect()
}

/// A superset of the nonzeros of A^{-1} from those of a square A: entry (c, r) can be nonzero
/// only if column c and row r of A lie in one of its [`blocks`].
pub fn inverse_pattern(a: &[Vec<bool>]) -> Vec<Vec<bool>> {
    let m = a.len();
    let mut inverse = vec![vec![false; m]; m];
    for (rows, cols) in blocks(a) {
        for &c in &cols {
            for &r in &rows {
                inverse[c][r] = true;
            }
        }
    }
    inverse
}

/// The nonzeros of the product of two patterns.
pub fn product_pattern(a: &[Vec<bool>], b: &[Vec<bool>]) -> Vec<Vec<bool>> {
    let cols = b.first().map_or(0, Vec::len);
    a.iter()
        .map(|row| {
            (0..cols)
                .map(|c| row.iter().zip(b).any(|(&x, brow)| x && brow[c]))
                .collect()
        })
        .collect()
}

/// Whether a variable matching `target` is reachable from `id` (through sums too).
pub(crate) fn depends_on(g: &Graph, id: Id, target: &dyn Fn(&Var) -> bool) -> bool {
    let mut stack = vec![id];
    let mut seen = std::collections::HashSet::new();
    while let Some(node) = stack.pop() {
        if !seen.insert(node) {
            continue;
        }
        match g.node(node) {
            crate::ir::graph::Node::Var(v) if target(v) => return true,
            other => stack.extend(crate::ir::graph::children(other)),
        }
    }
    false
}

/// A guarded expression at the three points of a step: start x_0, end x_1 and evaluation
/// point x_theta (with the top derivative u = w[S..] at each).
pub fn at_step_points(g: &mut Graph, node: Id, n: usize, k: usize) -> [Id; 3] {
    let s = 2 * n * k;
    let theta = g.var(Var::Theta);
    let one = g.constant(1.0);
    let one_minus_theta = g.sub(one, theta);
    let point = |which: usize| {
        move |g: &mut Graph, v: Var| match v {
            Var::Jet { order, index } if (order as usize) < k => {
                let c = (order as usize * n + index as usize) as u32;
                Some(match which {
                    0 => g.var(Var::Z0(c)),
                    1 => g.var(Var::W(c)),
                    _ => {
                        let (a, b) = (g.var(Var::Z0(c)), g.var(Var::W(c)));
                        let (ta, tb) = (g.mul(one_minus_theta, a), g.mul(theta, b));
                        g.add_op(ta, tb)
                    }
                })
            }
            Var::Jet { order, index } if order as usize == k => {
                Some(g.var(Var::W((s + index as usize) as u32)))
            }
            _ => None,
        }
    };
    [0, 1, 2].map(|which| substitute(g, node, &point(which), &mut HashMap::new()))
}

/// Each of `guards` with its expression at the three points of a step ([`at_step_points`]),
/// for the system of signature `sig`; none where `sig` turns the guard off.
pub fn guards_at_step_points(
    g: &mut Graph,
    guards: Vec<Guard>,
    sig: &Signature,
) -> Vec<(Guard, [Id; 3])> {
    if !sig.guard {
        return Vec::new();
    }
    guards
        .into_iter()
        .map(|guard| {
            let points = at_step_points(g, guard.node, sig.dim, sig.order);
            (guard, points)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(rows: &[&str]) -> Vec<Vec<bool>> {
        rows.iter()
            .map(|r| r.chars().map(|c| c == 'x').collect())
            .collect()
    }

    #[test]
    fn inverse_pattern_is_the_blocks_of_a_permuted_block_diagonal_matrix() {
        // rows {0, 2} x columns {1, 2} and row 1 x column 0 are the two blocks
        let a = pattern(&[".xx", "x..", ".x."]);
        let inv = inverse_pattern(&a);
        // A^{-1}[c][r] may be nonzero only within a block
        assert_eq!(inv, pattern(&[".x.", "x.x", "x.x"]));
        // a triangular matrix has a full (lower) inverse: one block, all entries
        let lower = pattern(&["x..", "xx.", ".xx"]);
        assert!(inverse_pattern(&lower).iter().flatten().all(|&v| v));
        assert_eq!(
            blocks(&a),
            vec![(vec![0, 2], vec![1, 2]), (vec![1], vec![0])]
        );
    }

    #[test]
    fn product_pattern_is_the_boolean_product() {
        let a = pattern(&["x.", ".x", "xx"]);
        let b = pattern(&["x..", "..x"]);
        assert_eq!(product_pattern(&a, &b), pattern(&["x..", "..x", "x.x"]));
    }
}
