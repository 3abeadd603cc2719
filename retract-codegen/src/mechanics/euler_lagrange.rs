//! The Euler-Lagrange operator of a mechanical Lagrangian l(q, q') (`#[mechanical_system]`),
//! as graph nodes in the order-2 jet (q, q', q''):
//!
//! ```text
//! tau_i = D (dl/dq'_i) - dl/dq_i = sum_j M_ij q''_j + sum_j d2l/dq'_i dq_j q'_j - dl/dq_i,
//! M_ij  = d2l/dq'_i dq'_j
//! ```
//!
//! with D the total derivative (`ir::diff::total_derivative`, q' and q'' the next jets), and
//! the optimal-control Lagrangian of order 2 built from it, L = R/2 sum_a tau_a^2 over the
//! actuated coordinates a.

use crate::ir::diff::{Differentiator, total_derivative};
use crate::ir::graph::{Graph, Id, Var};
use crate::mechanics::{derivatives, invert};

/// tau and the mass matrix of l, with the derivatives of the components that no actuator
/// drives (the stage equalities tau_c = 0).
pub struct EulerLagrange {
    /// tau_i, i = 0..n.
    pub tau: Vec<Id>,
    /// M_ij at `i * n + j`.
    pub mass: Vec<Id>,
    /// The components of the coordinates no actuator drives, ascending.
    pub unactuated: Vec<Component>,
}

/// A component tau_c with its gradient and Hessian in (q, q', q'') (as
/// `mechanics::derivatives` orders them).
pub struct Component {
    /// The coordinate c.
    pub index: usize,
    /// tau_c.
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

/// The Euler-Lagrange operator of `l` on R^n with the coordinates `actuated` driven (module
/// docs), or why M cannot be a mass matrix.
pub fn build(
    g: &mut Graph,
    l: Id,
    n: usize,
    actuated: &[usize],
) -> Result<EulerLagrange, NotMechanical> {
    let mut d = Differentiator::default();
    let jet = |order: u8, i: usize| Var::Jet {
        order,
        index: i as u32,
    };
    let momenta: Vec<Id> = (0..n).map(|i| d.diff(g, l, jet(1, i))).collect();
    let mass: Vec<Id> = (0..n * n)
        .map(|r| d.diff(g, momenta[r / n], jet(1, r % n)))
        .collect();
    if mass.iter().all(|&m| g.is_const(m, 0.0)) {
        return Err(if momenta.iter().all(|&p| g.is_const(p, 0.0)) {
            NotMechanical::NoVelocity
        } else {
            NotMechanical::Linear
        });
    }
    let numbers: Option<Vec<f64>> = mass.iter().map(|&m| g.as_const(m)).collect();
    if numbers.is_some_and(|values| invert(&values, n).is_none()) {
        return Err(NotMechanical::Singular);
    }
    let tau: Vec<Id> = (0..n)
        .map(|i| {
            let dp = total_derivative(g, &mut d, momenta[i], n, 2);
            let dl = d.diff(g, l, jet(0, i));
            g.sub(dp, dl)
        })
        .collect();
    let unactuated = (0..n)
        .filter(|c| !actuated.contains(c))
        .map(|index| {
            let (_, gradient, hessian) = derivatives(g, tau[index], n, 2);
            Component {
                index,
                value: tau[index],
                gradient,
                hessian,
            }
        })
        .collect();
    Ok(EulerLagrange {
        tau,
        mass,
        unactuated,
    })
}

/// The optimal-control Lagrangian of order 2: L = `weight`/2 sum_a tau_a^2 over `actuated`.
pub fn effort(g: &mut Graph, tau: &[Id], actuated: &[usize], weight: f64) -> Id {
    let mut sum = g.constant(0.0);
    for &a in actuated {
        let square = g.powi(tau[a], 2);
        sum = g.add_op(sum, square);
    }
    let half_weight = g.constant(0.5 * weight);
    g.mul(half_weight, sum)
}
