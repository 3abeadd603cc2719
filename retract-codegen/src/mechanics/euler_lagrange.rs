//! The Euler-Lagrange operator of a mechanical Lagrangian l(q, q') (`#[mechanical_system]`),
//! with the non-conservative generalized forces Q_nc(q, q'), as graph nodes in the order-2
//! jet (q, q', q''):
//!
//! ```text
//! tau_i = D (dl/dq'_i) - dl/dq_i - Q_nc,i
//!       = sum_j M_ij q''_j + sum_j d2l/dq'_i dq_j q'_j - dl/dq_i - Q_nc,i,
//! M_ij  = d2l/dq'_i dq'_j
//! ```
//!
//! with D the total derivative (`ir::diff::total_derivatives`, q' and q'' the next jets, one
//! directional sweep over the momenta) and dl/dq, dl/dq' from one reverse sweep over l. The
//! motion is driven by inputs u in R^m through tau = B(q) u; the input the motion needs,
//! u(q, q', q''), and the passive equalities (what no input can supply) are:
//!
//! - actuated coordinates A (`actuated = [..]`, B the columns e_a of the identity):
//!   u = tau_A, and tau_c = 0 for every c not in A;
//! - an actuation matrix B(q), n x m, of full column rank m = n (square): u = B^{-1} tau, no
//!   equality; m = n - 1: u = (B^T B)^{-1} B^T tau, exact where tau is in the range of B,
//!   which is the one equality a(q)^T tau = 0 with the annihilator
//!   a_i = (-1)^i det B_(i) (B_(i): B without row i; a^T b_j = det[b_j | B] = 0, and a != 0
//!   iff B has rank n - 1). Then tau = B u exactly where the equality holds: tau - B u is the
//!   component of tau along a.
//!
//! More passive directions (m < n - 1) need a choice of annihilator that no formula of B
//! gives everywhere; they are refused (use `actuated` where B selects coordinates).
//!
//! The optimal-control Lagrangian of order 2 built from it is
//! L = R/2 |u|^2 + C(q, q', u), C the user's cost (zero without one).

use crate::ir::diff::{Differentiator, reverse_gradient, total_derivatives};
use crate::ir::graph::{Graph, Id, Var};
use crate::mechanics::{derivatives, invert, symbolic_solve};

/// tau and the mass matrix of l, with the derivatives of the components that no actuator
/// drives (the stage equalities tau_c = 0).
pub struct EulerLagrange {
    /// tau_i, i = 0..n.
    pub tau: Vec<Id>,
    /// M_ij at `i * n + j`, the entries on and above the diagonal mirrored (exactly
    /// symmetric).
    pub mass: Vec<Id>,
    /// Q_nc,i (zeros without forces).
    pub forces: Vec<Id>,
    /// u_j(q, q', q''), the input the motion needs (module docs), j = 0..m.
    pub input: Vec<Id>,
    /// B_ij at `i * m + j`, functions of q and the parameters.
    pub input_matrix: Vec<Id>,
    /// The passive equalities: with actuated coordinates, tau_c of each unactuated c
    /// (labelled c), ascending; with an actuation matrix, a^T tau (labelled 0) where m = n - 1.
    pub unactuated: Vec<Component>,
    /// The inputs u_j with their derivatives (labelled j), where asked for; else empty.
    pub input_functions: Vec<Component>,
}

/// How the inputs drive the coordinates.
pub enum Inputs<'a> {
    /// The actuated coordinates, ascending.
    Coordinates(&'a [usize]),
    /// The columns b_j of B(q), each of n entries.
    Matrix(Vec<Vec<Id>>),
}

/// A function of the jet (a passive equality tau_c, or an input u_j) with its gradient and
/// Hessian in (q, q', q'') (as `mechanics::derivatives` orders them).
pub struct Component {
    /// The label: the coordinate c, or the input j.
    pub index: usize,
    /// Its value.
    pub value: Id,
    /// Its gradient.
    pub gradient: Vec<Id>,
    /// Its Hessian.
    pub hessian: Vec<Vec<Id>>,
}

/// Why l makes no mechanical system.
pub enum NotMechanical {
    /// l does not depend on q'.
    NoVelocity,
    /// d2l/dq'2 vanishes identically (l linear in q').
    Linear,
    /// M is a constant singular matrix (or has a non-finite entry).
    Singular,
}

/// Why an actuation matrix B (n x m) is refused.
pub enum BadInputMatrix {
    /// A column has not n entries.
    Rows(usize),
    /// m > n.
    TooManyInputs(usize),
    /// m < n - 1 (module docs).
    TooManyPassive(usize),
    /// B is constant without full column rank, or its inversion is structurally singular.
    RankDeficient,
}

/// The Euler-Lagrange operator of `l` on R^n with the forces `forces` (Q_nc, n entries) and
/// the inputs `inputs` (module docs), with the derivatives of the inputs where
/// `input_functions`, or why M cannot be a mass matrix (`Err(Ok(_))`) or B cannot be an
/// actuation matrix (`Err(Err(_))`).
pub fn build(
    g: &mut Graph,
    l: Id,
    n: usize,
    forces: Option<&[Id]>,
    inputs: Inputs<'_>,
    input_functions: bool,
) -> Result<EulerLagrange, Result<NotMechanical, BadInputMatrix>> {
    let mut d = Differentiator::default();
    let jet = |order: u8, i: usize| Var::Jet {
        order,
        index: i as u32,
    };
    // dl/dq and the momenta dl/dq' in one reverse sweep (O(nodes of l): for a chain whose
    // velocities accumulate link by link, O(n), where one forward derivative per coordinate
    // is O(n^2)); forward where l sums over a slice
    let vars: Vec<Var> = (0..2)
        .flat_map(|o| (0..n).map(move |i| jet(o, i)))
        .collect();
    let mut dl = match reverse_gradient(g, l, &vars) {
        Some(gradient) => gradient,
        None => vars.iter().map(|&v| d.diff(g, l, v)).collect(),
    };
    let momenta = dl.split_off(n);
    // (the entries on and above the diagonal, mirrored: M is exactly symmetric)
    let mass: Vec<Id> = (0..n * n)
        .map(|r| {
            let (i, j) = (r / n, r % n);
            d.diff(g, momenta[i.min(j)], jet(1, i.max(j)))
        })
        .collect();
    if mass.iter().all(|&m| g.is_const(m, 0.0)) {
        return Err(Ok(if momenta.iter().all(|&p| g.is_const(p, 0.0)) {
            NotMechanical::NoVelocity
        } else {
            NotMechanical::Linear
        }));
    }
    let numbers: Option<Vec<f64>> = mass.iter().map(|&m| g.as_const(m)).collect();
    if numbers.is_some_and(|values| invert(&values, n).is_none()) {
        return Err(Ok(NotMechanical::Singular));
    }
    let zero = g.constant(0.0);
    let forces = forces.map_or_else(|| vec![zero; n], <[Id]>::to_vec);
    // D p in one directional sweep: q moves at the rate q', q' at the rate q''
    let dp = total_derivatives(g, &momenta, n, 2);
    let tau: Vec<Id> = (0..n)
        .map(|i| {
            let conservative = g.sub(dp[i], dl[i]);
            g.sub(conservative, forces[i])
        })
        .collect();
    let (input, input_matrix, passive) = match inputs {
        Inputs::Coordinates(actuated) => {
            let one = g.constant(1.0);
            let matrix = (0..n * actuated.len())
                .map(|r| {
                    let (i, j) = (r / actuated.len(), r % actuated.len());
                    if actuated[j] == i { one } else { zero }
                })
                .collect();
            let passive: Vec<(usize, Id)> = (0..n)
                .filter(|c| !actuated.contains(c))
                .map(|c| (c, tau[c]))
                .collect();
            (actuated.iter().map(|&a| tau[a]).collect(), matrix, passive)
        }
        Inputs::Matrix(columns) => {
            let (input, passive) = through_matrix(g, &tau, &columns).map_err(Err)?;
            let m = columns.len();
            let matrix = (0..n * m).map(|r| columns[r % m][r / m]).collect();
            (
                input,
                matrix,
                passive.map(|a| (0, a)).into_iter().collect::<Vec<_>>(),
            )
        }
    };
    let mut component = |(index, value): (usize, Id)| {
        let (_, gradient, hessian) = derivatives(g, value, n, 2);
        Component {
            index,
            value,
            gradient,
            hessian,
        }
    };
    let unactuated = passive.into_iter().map(&mut component).collect();
    let input_functions = if input_functions {
        input.iter().copied().enumerate().map(component).collect()
    } else {
        Vec::new()
    };
    Ok(EulerLagrange {
        tau,
        mass,
        forces,
        input,
        input_matrix,
        unactuated,
        input_functions,
    })
}

/// u and the passive equality a^T tau (none where B is square) of the actuation matrix with
/// columns `columns` (module docs).
fn through_matrix(
    g: &mut Graph,
    tau: &[Id],
    columns: &[Vec<Id>],
) -> Result<(Vec<Id>, Option<Id>), BadInputMatrix> {
    let (n, m) = (tau.len(), columns.len());
    if let Some(column) = columns.iter().find(|c| c.len() != n) {
        return Err(BadInputMatrix::Rows(column.len()));
    }
    if m > n {
        return Err(BadInputMatrix::TooManyInputs(m));
    }
    if m + 1 < n {
        return Err(BadInputMatrix::TooManyPassive(m));
    }
    let dot = |g: &mut Graph, a: &[Id], b: &[Id]| {
        let mut sum = g.constant(0.0);
        for (&x, &y) in a.iter().zip(b) {
            let product = g.mul(x, y);
            sum = g.add_op(sum, product);
        }
        sum
    };
    // square: B u = tau; else the normal equations B^T B u = B^T tau
    let (system, rhs): (Vec<Vec<Id>>, Vec<Vec<Id>>) = if m == n {
        let rows = (0..n).map(|i| columns.iter().map(|c| c[i]).collect());
        (rows.collect(), tau.iter().map(|&t| vec![t]).collect())
    } else {
        let gram = columns
            .iter()
            .map(|a| columns.iter().map(|b| dot(g, a, b)).collect())
            .collect();
        (gram, columns.iter().map(|c| vec![dot(g, c, tau)]).collect())
    };
    let numbers: Option<Vec<f64>> = system.iter().flatten().map(|&e| g.as_const(e)).collect();
    if numbers.is_some_and(|values| invert(&values, m).is_none()) {
        return Err(BadInputMatrix::RankDeficient);
    }
    let (solution, _) =
        symbolic_solve(g, system, rhs, INVERSION_BUDGET).ok_or(BadInputMatrix::RankDeficient)?;
    let input = solution.into_iter().map(|row| row[0]).collect();
    if m == n {
        return Ok((input, None));
    }
    let annihilator: Vec<Id> = (0..n)
        .map(|i| {
            let minor: Vec<Vec<Id>> = (0..n)
                .filter(|&r| r != i)
                .map(|r| columns.iter().map(|c| c[r]).collect())
                .collect();
            let det = determinant(g, &minor);
            if i % 2 == 0 { det } else { g.neg(det) }
        })
        .collect();
    if annihilator.iter().all(|&a| g.is_const(a, 0.0)) {
        return Err(BadInputMatrix::RankDeficient);
    }
    let passive = dot(g, &annihilator, tau);
    Ok((input, Some(passive)))
}

/// Nodes the symbolic solve for u may add.
const INVERSION_BUDGET: usize = 20_000;

/// The determinant of a square matrix of nodes, by the Laplace expansion along the rows with
/// the minors memoized by their set of columns (m 2^m products for m x m).
fn determinant(g: &mut Graph, a: &[Vec<Id>]) -> Id {
    let m = a.len();
    // det[S] of the last |S| rows over the columns S, built up from the empty set
    let mut det: Vec<Option<Id>> = vec![None; 1 << m];
    det[0] = Some(g.constant(1.0));
    let mut masks: Vec<usize> = (1..1usize << m).collect();
    masks.sort_by_key(|s| s.count_ones());
    for mask in masks {
        let row = m - mask.count_ones() as usize;
        let mut sum = g.constant(0.0);
        for (position, j) in (0..m).filter(|j| mask & (1 << j) != 0).enumerate() {
            let Some(rest) = det[mask & !(1 << j)] else {
                continue;
            };
            let term = g.mul(a[row][j], rest);
            sum = if position % 2 == 0 {
                g.add_op(sum, term)
            } else {
                g.sub(sum, term)
            };
        }
        det[mask] = Some(sum);
    }
    det[(1 << m) - 1].unwrap_or_else(|| g.constant(0.0))
}

/// The optimal-control Lagrangian of order 2: L = `weight`/2 |u|^2 + `cost` (module docs).
pub fn effort(g: &mut Graph, input: &[Id], weight: f64, cost: Option<Id>) -> Id {
    let mut sum = g.constant(0.0);
    for &u in input {
        let square = g.powi(u, 2);
        sum = g.add_op(sum, square);
    }
    let half_weight = g.constant(0.5 * weight);
    let effort = g.mul(half_weight, sum);
    match cost {
        Some(c) => g.add_op(effort, c),
        None => effort,
    }
}
