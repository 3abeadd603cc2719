//! How far a plan is from its constraints ([`Violations`]: the largest violation at the
//! nodes, at the steps' evaluation points and along the plan's interpolant between the
//! nodes), the constraint a failure names ([`Infeasibility`]), and the weights of the
//! interpolant's check points. The measurement itself is the problem's
//! (`OptimalControlProblem::violations`).

use crate::bvp::constraints::{ConstraintKind, ConstraintRef};
use crate::bvp::guess::Hermite;

/// The parts each step is cut into to check the interpolant ([`Violations::interpolant`]):
/// at the 15 points $t_i + j h / 16$, $j = 1, \dots, 15$, inside it.
pub const INTERPOLANT_DIVISIONS: usize = 16;

/// The largest constraint violation of a plan: $\max(0, -g)$ of the inequalities $g \ge 0$
/// (bounds on either side alike) and $|g|$ of the equalities, where each is imposed and along
/// the plan's interpolant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Violations {
    /// At the nodes $x_i$, over the constraints placed there ([`crate::bvp::Placement`]).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub nodes: f64,
    /// At the steps' evaluation points $(x_{\theta,i}, u_i)$, over the constraints placed
    /// there.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub midpoints: f64,
    /// Along the interpolant of [`super::Plan::evaluate`] at the
    /// [`INTERPOLANT_DIVISIONS`] $- 1$ points inside every step, over the inequalities placed at
    /// the nodes (constraints of the jet alone; between the nodes nothing holds them, so a
    /// plan may cut a corner here by $O(h^2)$).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub interpolant: f64,
}

impl Violations {
    /// The larger of the node and midpoint violations: what certification bounds (NaN if
    /// either is).
    pub fn imposed(&self) -> f64 {
        if self.nodes.is_nan() || self.midpoints.is_nan() {
            return f64::NAN;
        }
        self.nodes.max(self.midpoints)
    }
}

/// Where a constraint is violated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Location {
    /// In its own data: a lower side above an upper side, equal sides, or sides of two bounds
    /// of one variable that exclude each other.
    Definition,
    /// At the fixed start $x_0$.
    Start,
    /// At the fixed goal $x_N$.
    Goal,
    /// At node $x_i$.
    Node(usize),
    /// At the evaluation point of step $i$.
    Step(usize),
    /// On the interpolant inside step $i$.
    Between(usize),
}

/// A constraint that cannot be, or was not, satisfied: which one, where, and by how much.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Infeasibility {
    /// The constraint.
    pub constraint: ConstraintRef,
    /// Where.
    pub location: Location,
    /// By how much: $\max(0, -g)$ of an inequality, $|g|$ of an equality; for
    /// [`Location::Definition`] the lower side less the upper side.
    pub violation: f64,
}

impl core::fmt::Display for Infeasibility {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (c, v) = (&self.constraint, self.violation);
        match self.location {
            Location::Definition if v.is_infinite() => {
                write!(f, "{c} has an infinite side facing the wrong way")
            }
            Location::Definition if v == 0.0 => write!(
                f,
                "{c} has equal lower and upper sides: an inequality needs an interior (write \
                 an equality)"
            ),
            Location::Definition => write!(
                f,
                "{c} has a lower side {v:e} above an upper side (of itself or of another bound \
                 of the same variable): no point satisfies it"
            ),
            Location::Start | Location::Goal if c.kind == ConstraintKind::FixedEnd => {
                let (node, end) = match self.location {
                    Location::Start => ("first", "start"),
                    _ => ("last", "goal"),
                };
                write!(
                    f,
                    "the {node} node misses the {end}'s jet entry {} by {v:e}",
                    c.index
                )
            }
            Location::Start => write!(f, "the start violates {c} by {v:e}"),
            Location::Goal => write!(f, "the goal violates {c} by {v:e}"),
            Location::Node(i) => write!(f, "{c} is violated by {v:e} at node {i}"),
            Location::Step(i) => write!(f, "{c} is violated by {v:e} at step {i}"),
            Location::Between(i) => {
                write!(
                    f,
                    "{c} is violated by {v:e} on the interpolant inside step {i}"
                )
            }
        }
    }
}

/// The weights of the Hermite interpolant inside a step of length `h` between jets of order
/// `k`: at the point $t_p = p h / D$ ($p = 1, \dots, D - 1$, $D$ =
/// [`INTERPOLANT_DIVISIONS`]), $q^{(j)}(t_p) = \sum_{m < k} (a_{pjm} q^{(m)}(0) + b_{pjm}
/// q^{(m)}(h))$ coordinate by coordinate, with $a_{pjm}$ at index $((p - 1) k + j) 2k + m$
/// and $b_{pjm}$ $k$ after it. `None` where the interpolation is singular.
pub(in crate::bvp) fn interpolant_weights(h: f64, k: usize) -> Option<Vec<f64>> {
    // the polynomials of the unit jets: q^(m)(0) = 1 (side 0) or q^(m)(h) = 1 (side 1)
    let unit = |side: usize, m: usize| {
        let mut ends = vec![0.0; 2 * k];
        ends[side * k + m] = 1.0;
        Hermite::new(&ends[..k], &ends[k..], h, 1, k).ok()
    };
    let basis: Option<Vec<Hermite>> = (0..2 * k).map(|b| unit(b / k, b % k)).collect();
    let basis = basis?;
    let mut weights = Vec::with_capacity((INTERPOLANT_DIVISIONS - 1) * 2 * k * k);
    for p in 1..INTERPOLANT_DIVISIONS {
        let t = h * p as f64 / INTERPOLANT_DIVISIONS as f64;
        for j in 0..k {
            weights.extend(basis.iter().map(|b| b.derivative(0, j, t)));
        }
    }
    Some(weights)
}
