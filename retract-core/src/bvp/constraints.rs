//! Stage constraints of the optimizer: equalities $g(x_\theta, u) = 0$ at the evaluation
//! point of every step, and inequalities $\ell \le g \le u$ on a [`JetFunction`] written as
//! plain Rust (differentiated by `#[jet_function]`) or on one variable, imposed where their
//! [`Placement`] says: at the evaluation points $(x_{\theta,i}, u_i)$ of the steps, at the
//! nodes $x_i$, or both.

use nalgebra::{SMatrix, SVector};

use super::guess::Hermite;
use super::iterate::blocks;
use crate::{Gradient, Hessian, JetFunction, VectorJetFunction};

/// A variable of a step that a bound applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Variable {
    /// Entry `r` of the jet $x = (q, q', \dots, q^{(k-1)})$ (blocks of $n$: entry $j n + a$
    /// is $q_a^{(j)}$), at the nodes $x_i$ and the evaluation points $x_{\theta,i}$.
    Jet(usize),
    /// Component `a` of the top derivative $u = q^{(k)}$, which lives at the steps'
    /// evaluation points.
    Top(usize),
}

/// Where an inequality is imposed.
///
/// The jet $x = (q, \dots, q^{(k-1)})$ lives at the nodes $x_i$ (times $t_i = i h$) and at
/// the evaluation points $x_{\theta,i} = (1-\theta) x_i + \theta x_{i+1}$ of the steps; the
/// top derivative $u_i = q^{(k)}$ only at the evaluation points. A constraint of the jet
/// alone (a clearance, a joint limit) holds where the plan is: by default at both
/// ([`Placement::NodesAndMidpoints`]); one that involves $u$ at the evaluation points
/// ([`Placement::Midpoints`]). The plan reports its largest violation at each and along its
/// interpolant ([`super::Plan::violations`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Placement {
    /// At $(x_{\theta,i}, u_i)$ for every step $i < N$.
    Midpoints,
    /// At every node $x_i$, $i = 0, \dots, N$ (only for constraints of the jet alone, and
    /// with start and goal fixed: they are checked before iterating).
    Nodes,
    /// Both.
    NodesAndMidpoints,
}

impl Placement {
    /// Whether the constraint holds at the steps' evaluation points.
    pub fn at_midpoints(self) -> bool {
        matches!(self, Placement::Midpoints | Placement::NodesAndMidpoints)
    }
    /// Whether the constraint holds at the nodes.
    pub fn at_nodes(self) -> bool {
        matches!(self, Placement::Nodes | Placement::NodesAndMidpoints)
    }
}

/// The kind of a constraint a failure names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ConstraintKind {
    /// A stage equality ([`super::OptimalControlProblem::with_equality`]).
    Equality,
    /// An inequality on a function ([`super::OptimalControlProblem::with_inequality`],
    /// [`super::OptimalControlProblem::with_function_bounds`]).
    Inequality,
    /// The bounds of component `c` of a vector function
    /// ([`super::OptimalControlProblem::with_vector_bounds`]; indexed with the inequalities).
    Component(usize),
    /// A bound on a variable ([`super::OptimalControlProblem::with_bounds`] and the vector
    /// forms).
    Bound(Variable),
    /// The scheme's equations of a step, $x_{i+1} = \Phi_h(x_i, u_i)$, the [`ConstraintRef`]'s
    /// index their jet entry: named where a solve stalls with their defect
    /// $\Phi_h(x_i, u_i) - x_{i+1}$ the largest violation ([`super::Failure::StalledInfeasible`]).
    Dynamics,
    /// A fixed component of the start or goal (the [`ConstraintRef`]'s index its jet entry),
    /// missed by the first or last node: named where a solve stalls with that miss the
    /// largest violation.
    FixedEnd,
}

/// A constraint as the user added it: its kind, its index among the constraints of that
/// class (equalities, inequalities and bounds, counted separately in the order added), and the
/// generated type's name for a function ([`JetFunction::name`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ConstraintRef {
    /// Equality, inequality or bound.
    pub kind: ConstraintKind,
    /// The index among the constraints of its class, from 0 in the order they were added.
    pub index: usize,
    /// The function's type name (e.g. `CartForce`); `"bound"` for a bound, `"dynamics"` and
    /// `"end"` for [`ConstraintKind::Dynamics`] and [`ConstraintKind::FixedEnd`].
    pub name: &'static str,
}

impl core::fmt::Display for ConstraintRef {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.kind {
            ConstraintKind::Equality => write!(f, "equality #{} ({})", self.index, self.name),
            ConstraintKind::Inequality => {
                write!(f, "inequality #{} ({})", self.index, self.name)
            }
            ConstraintKind::Component(c) => {
                write!(
                    f,
                    "inequality #{} ({}, component {c})",
                    self.index, self.name
                )
            }
            ConstraintKind::Bound(Variable::Jet(r)) => {
                write!(f, "bound #{} on jet entry {r}", self.index)
            }
            ConstraintKind::Bound(Variable::Top(a)) => {
                write!(f, "bound #{} on top derivative {a}", self.index)
            }
            ConstraintKind::Dynamics => {
                write!(f, "the dynamics (the scheme's jet entry {})", self.index)
            }
            ConstraintKind::FixedEnd => write!(f, "the fixed jet entry {}", self.index),
        }
    }
}

/// What an inequality constrains.
#[derive(Clone, Copy)]
pub(super) enum Source<'a, const N: usize, const K: usize> {
    /// $g(x, u)$.
    Function(&'a (dyn JetFunction<N, K> + Sync)),
    /// Component `c` of $g(x, u) \in \mathbb{R}^m$ (valid for $c < m$).
    Component(&'a (dyn VectorJetFunction<N, K> + Sync), usize),
    /// One variable.
    Variable(Variable),
}

/// One scalar inequality $\sigma (v - c) \ge 0$ of a source value $v$: $v \ge c$ ($\sigma = 1$,
/// a lower bound) or $v \le c$ ($\sigma = -1$).
#[derive(Clone, Copy)]
pub(super) struct Inequality<'a, const N: usize, const K: usize> {
    pub source: Source<'a, N, K>,
    pub value: f64,
    pub sign: f64,
    pub placement: Placement,
    /// The index of the user's constraint (one `with_*_bounds` call may add two).
    pub index: usize,
    /// For a constraint of the jet alone imposed at an interior sample of each step
    /// ([`super::PlanOptions::interior_samples`]): the sample, a linear function of the
    /// step's $(x_\theta, u)$; `None` where it is imposed at $(x_\theta, u)$ or at a node.
    pub sample: Option<Sample>,
}

/// The most orders $k$ for which interior samples are formed.
pub(super) const SAMPLE_MAX_ORDER: usize = 4;

/// The jet $x(t_i + \tau h)$ of the plan's interpolant inside a step as a linear function of
/// the step's evaluation point $x_\theta$ and top derivative $u$: the nodes are
/// $x_i = x_\theta - \theta h (A x_\theta + B u)$ and $x_{i+1} = x_\theta + (1-\theta) h
/// (A x_\theta + B u)$ (the scheme's $x$-equations with no defect; $A$ the block shift, $B$ the
/// last block), and $x(t_i + \tau h)$ is the Hermite polynomial of degree $2k-1$ between them
/// ([`super::Plan::evaluate`]'s interpolant). Coordinates do not mix: block $j$ of the sample
/// is $\sum_{c<k} w_{jc} x_{\theta,c} + w_{jk} u$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Sample {
    /// The fraction $\tau \in (0, 1)$ of the step.
    pub fraction: f64,
    /// `weights[j][c]` $= w_{jc}$ ($j < k \le 4$, $c \le k$).
    weights: [[f64; SAMPLE_MAX_ORDER + 1]; SAMPLE_MAX_ORDER],
}

impl Sample {
    /// The sample at `fraction` of a step of length `h` with scheme parameter `theta`, for
    /// jets of order `k` (`None` for $k > 4$ or a degenerate step).
    pub fn new(fraction: f64, h: f64, theta: f64, k: usize) -> Option<Self> {
        if k == 0 || k > SAMPLE_MAX_ORDER {
            return None;
        }
        let mut weights = [[0.0; SAMPLE_MAX_ORDER + 1]; SAMPLE_MAX_ORDER];
        for c in 0..=k {
            // the scalar jets (x_theta, u) = e_c and the nodes they give
            let unit = |l: usize| if l == c { 1.0 } else { 0.0 };
            let rate = |l: usize| unit(l + 1);
            let start: Vec<f64> = (0..k).map(|l| unit(l) - theta * h * rate(l)).collect();
            let end: Vec<f64> = (0..k)
                .map(|l| unit(l) + (1.0 - theta) * h * rate(l))
                .collect();
            let piece = Hermite::new(&start, &end, h, 1, k).ok()?;
            for (j, row) in weights.iter_mut().enumerate().take(k) {
                row[c] = piece.jet_entry(j, fraction * h);
            }
        }
        Some(Self { fraction, weights })
    }

    /// The sample's jet from the step's $(x_\theta, u)$.
    fn point<const N: usize, const K: usize, const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
    ) -> SVector<f64, X> {
        let w = &self.weights;
        SVector::from_fn(|r, _| {
            let (j, a) = (r / N, r % N);
            (0..K).map(|c| w[j][c] * x[c * N + a]).sum::<f64>() + w[j][K] * u[a]
        })
    }

    /// The map $(x_\theta, u) \mapsto x$ as its two blocks $(T, U)$.
    fn blocks<const N: usize, const K: usize, const X: usize>(
        &self,
    ) -> (SMatrix<f64, X, X>, SMatrix<f64, X, N>) {
        let w = &self.weights;
        let t = SMatrix::from_fn(|r, s| if r % N == s % N { w[r / N][s / N] } else { 0.0 });
        let u = SMatrix::from_fn(|r, a| if r % N == a { w[r / N][K] } else { 0.0 });
        (t, u)
    }
}

/// Value, gradient $(\partial_x, \partial_u)$ of a stage constraint at $(x_\theta, u)$.
pub(super) struct Linearized<const N: usize, const X: usize> {
    pub value: f64,
    pub gx: SVector<f64, X>,
    pub gu: SVector<f64, N>,
}

impl<const N: usize, const K: usize> Inequality<'_, N, K> {
    /// The constraint as the user added it.
    pub fn reference(&self) -> ConstraintRef {
        match self.source {
            Source::Function(g) => ConstraintRef {
                kind: ConstraintKind::Inequality,
                index: self.index,
                name: g.name(),
            },
            Source::Component(g, c) => ConstraintRef {
                kind: ConstraintKind::Component(c),
                index: self.index,
                name: g.name(),
            },
            Source::Variable(v) => ConstraintRef {
                kind: ConstraintKind::Bound(v),
                index: self.index,
                name: "bound",
            },
        }
    }

    /// Whether the source involves the top derivative $u$ (then it lives at the midpoints).
    pub fn involves_top(&self) -> bool {
        match self.source {
            Source::Function(g) => g.involves_top(),
            Source::Component(g, c) => g.component_involves_top(c),
            Source::Variable(v) => matches!(v, Variable::Top(_)),
        }
    }

    /// $\sigma (v(x, u) - c)$, at the sample of `(x, u)` for an interior sample.
    pub fn value<const X: usize>(&self, x: &SVector<f64, X>, u: &SVector<f64, N>) -> f64 {
        if let Some(sample) = &self.sample {
            return self.at_point(&sample.point::<N, K, X>(x, u), u);
        }
        self.at_point(x, u)
    }

    /// $\sigma (v(x, u) - c)$ at `(x, u)` itself.
    fn at_point<const X: usize>(&self, x: &SVector<f64, X>, u: &SVector<f64, N>) -> f64 {
        let v = match self.source {
            Source::Function(g) => g.value(&blocks::<N, K, X>(x), u),
            Source::Component(g, c) => g.component_value(c, &blocks::<N, K, X>(x), u),
            Source::Variable(variable) => read(variable, x, u),
        };
        self.sign * (v - self.value)
    }

    /// Value and gradient (in the step's $(x_\theta, u)$ for an interior sample: $T^T \nabla
    /// g$, $U^T \nabla g$ with the sample's blocks, [`Sample`]).
    pub fn linearize<const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
    ) -> Linearized<N, X> {
        let Some(sample) = &self.sample else {
            return self.linearize_at_point(x, u);
        };
        let at = self.linearize_at_point(&sample.point::<N, K, X>(x, u), u);
        let (t, tu) = sample.blocks::<N, K, X>();
        Linearized {
            value: at.value,
            gx: t.transpose() * at.gx,
            gu: tu.transpose() * at.gx + at.gu,
        }
    }

    /// Value and gradient at `(x, u)` itself.
    fn linearize_at_point<const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
    ) -> Linearized<N, X> {
        let sign = self.sign;
        let of_gradient = |value: f64, grad: Gradient<N, K>| Linearized {
            value: sign * (value - self.value),
            gx: SVector::from_fn(|r, _| sign * grad.x[r / N][r % N]),
            gu: grad.u * sign,
        };
        match self.source {
            Source::Function(g) => {
                let xb = blocks::<N, K, X>(x);
                of_gradient(g.value(&xb, u), g.gradient(&xb, u))
            }
            Source::Component(g, c) => {
                let xb = blocks::<N, K, X>(x);
                of_gradient(
                    g.component_value(c, &xb, u),
                    g.component_gradient(c, &xb, u),
                )
            }
            Source::Variable(variable) => {
                let (mut gx, mut gu) = (SVector::zeros(), SVector::zeros());
                match variable {
                    Variable::Jet(r) => gx[r] = sign,
                    Variable::Top(a) => gu[a] = sign,
                }
                Linearized {
                    value: sign * (read(variable, x, u) - self.value),
                    gx,
                    gu,
                }
            }
        }
    }

    /// `weight` times the Hessian blocks $(H_{xx}, H_{ux}, H_{uu})$ of $\sigma v$ (none for a
    /// bound); for an interior sample of a function of the jet alone $(T^T H T, U^T H T,
    /// U^T H U)$ with the sample's blocks.
    pub fn weighted_hessian<const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
        weight: f64,
    ) -> Option<(SMatrix<f64, X, X>, SMatrix<f64, N, X>, SMatrix<f64, N, N>)> {
        let Some(sample) = &self.sample else {
            return self.hessian_at_point(x, u, weight);
        };
        let (hxx, _, _) = self.hessian_at_point(&sample.point::<N, K, X>(x, u), u, weight)?;
        let (t, tu) = sample.blocks::<N, K, X>();
        let ht = hxx * t;
        Some((
            t.transpose() * ht,
            tu.transpose() * ht,
            tu.transpose() * hxx * tu,
        ))
    }

    /// `weight` times the Hessian blocks at `(x, u)` itself.
    fn hessian_at_point<const X: usize>(
        &self,
        x: &SVector<f64, X>,
        u: &SVector<f64, N>,
        weight: f64,
    ) -> Option<(SMatrix<f64, X, X>, SMatrix<f64, N, X>, SMatrix<f64, N, N>)> {
        match self.source {
            Source::Function(g) if weight != 0.0 => Some(flat_hessian::<N, K, X>(
                &g.hessian(&blocks::<N, K, X>(x), u),
                weight * self.sign,
            )),
            Source::Component(g, c) if weight != 0.0 => Some(flat_hessian::<N, K, X>(
                &g.component_hessian(c, &blocks::<N, K, X>(x), u),
                weight * self.sign,
            )),
            _ => None,
        }
    }

    /// Whether `self` and `other` bound the same value at a common place: the two sides of
    /// one constraint, or bounds of one variable.
    pub fn same_source(&self, other: &Self) -> bool {
        let overlap = (self.placement.at_nodes() && other.placement.at_nodes())
            || (self.placement.at_midpoints() && other.placement.at_midpoints());
        overlap
            && self.sample.map(|s| s.fraction) == other.sample.map(|s| s.fraction)
            && match (self.source, other.source) {
                (Source::Variable(a), Source::Variable(b)) => a == b,
                (Source::Function(f), Source::Function(g)) => {
                    self.index == other.index && core::ptr::addr_eq(f, g)
                }
                (Source::Component(f, a), Source::Component(g, b)) => {
                    self.index == other.index && a == b && core::ptr::addr_eq(f, g)
                }
                _ => false,
            }
    }

    /// Whether the constraint is well formed for jets of length `X`: a value that is not NaN
    /// (an infinite one is refused as a contradiction), a variable or component in range, and no node
    /// placement for what involves $u$.
    pub fn valid<const X: usize>(&self) -> bool {
        let inside = match self.source {
            Source::Function(_) => true,
            Source::Component(g, c) => c < g.components(),
            Source::Variable(Variable::Jet(r)) => r < X,
            Source::Variable(Variable::Top(a)) => a < N,
        };
        inside && !self.value.is_nan() && !(self.placement.at_nodes() && self.involves_top())
    }
}

/// IPOPT's push of the first slacks into the interior (`bound_push` = `bound_frac` =
/// $\kappa = 10^{-2}$), per inequality of `list`: a side $\sigma(v - c) \ge 0$ alone starts
/// at $s = \max(g, p)$ with $p = \kappa \max(1, |c|)$; the two sides of one interval
/// $\ell \le v \le u$ share IPOPT's single slack $v_s \in [\ell + p_\ell, u - p_u]$,
/// $p_\ell = \min(\kappa \max(1, |\ell|), \kappa (u - \ell))$ (and $p_u$ alike), so that each
/// side's slack is $\min(\max(g, p_{\text{own}}), (u - \ell) - p_{\text{other}})$ and the two
/// slacks sum to $u - \ell$ (a sum every Newton step keeps). Returned as the pair
/// (lower clamp, upper clamp) of each entry.
pub(super) fn slack_push<const N: usize, const K: usize>(
    list: &[Inequality<'_, N, K>],
) -> Vec<(f64, f64)> {
    const KAPPA: f64 = 1e-2;
    let alone = |c: &Inequality<'_, N, K>| KAPPA * c.value.abs().max(1.0);
    list.iter()
        .enumerate()
        .map(|(j, c)| match partner(list, j) {
            Some(d) => {
                let width = c.sign * (d.value - c.value);
                let own = alone(c).min(KAPPA * width);
                let other = alone(d).min(KAPPA * width);
                (own, width - other)
            }
            None => (alone(c), f64::INFINITY),
        })
        .collect()
}

/// The other side of the interval of `list[j]`, if it is one side of an interval
/// $\ell \le v \le u$ (the same source and user's constraint, the opposite sign).
fn partner<'l, 'a, const N: usize, const K: usize>(
    list: &'l [Inequality<'a, N, K>],
    j: usize,
) -> Option<&'l Inequality<'a, N, K>> {
    partner_index(list, j).map(|k| &list[k])
}

/// The index in `list` of the other side of the interval of `list[j]` ([`partner`]).
pub(super) fn partner_index<const N: usize, const K: usize>(
    list: &[Inequality<'_, N, K>],
    j: usize,
) -> Option<usize> {
    let c = list.get(j)?;
    (list.iter().enumerate())
        .find(|(k, d)| *k != j && d.sign == -c.sign && d.index == c.index && c.same_source(d))
        .map(|(k, _)| k)
}

/// The weight of each inequality of `list` in the constraint violation $\theta$ of the line
/// search, $\sum_j w_j |g_j - s_j|$: $\tfrac12$ for a side of an interval, 1 for a side
/// alone. The two sides of $\ell \le v \le u$ have two slacks where IPOPT has one ($v - s
/// = 0$, $s \in [\ell, u]$), and along a Newton step their residuals are equal and opposite
/// (the nonlinearity of $v$ in each): with the halves, $\theta$ is IPOPT's. (The restoration
/// phase counts each side's elastic violation whole: it returns only where that larger
/// measure has fallen.)
pub(super) fn violation_weights<const N: usize, const K: usize>(
    list: &[Inequality<'_, N, K>],
) -> Vec<f64> {
    (0..list.len())
        .map(|j| if partner(list, j).is_some() { 0.5 } else { 1.0 })
        .collect()
}

fn read<const N: usize, const X: usize>(
    variable: Variable,
    x: &SVector<f64, X>,
    u: &SVector<f64, N>,
) -> f64 {
    match variable {
        Variable::Jet(r) => x[r],
        Variable::Top(a) => u[a],
    }
}

/// `scale` times the Hessian blocks of a function of $(x, u)$ as $(H_{xx}, H_{ux}, H_{uu})$
/// over the flat jet.
#[inline(always)]
pub(super) fn flat_hessian<const N: usize, const K: usize, const X: usize>(
    hs: &Hessian<N, K>,
    scale: f64,
) -> (SMatrix<f64, X, X>, SMatrix<f64, N, X>, SMatrix<f64, N, N>) {
    let mut hxx = SMatrix::<f64, X, X>::zeros();
    let mut hux = SMatrix::<f64, N, X>::zeros();
    // block by block with constant bounds (the compiler unrolls the copies)
    for (i, row) in hs.xx.iter().enumerate() {
        for (j, block) in row.iter().enumerate() {
            for b in 0..N {
                for a in 0..N {
                    hxx[(i * N + a, j * N + b)] = scale * block[(a, b)];
                }
            }
        }
    }
    for (j, block) in hs.xu.iter().enumerate() {
        for b in 0..N {
            for a in 0..N {
                hux[(b, j * N + a)] = scale * block[(a, b)];
            }
        }
    }
    (hxx, hux, hs.uu * scale)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Gradient, Hessian};

    fn side(value: f64, sign: f64, index: usize) -> Inequality<'static, 1, 2> {
        Inequality {
            source: Source::Variable(Variable::Top(0)),
            value,
            sign,
            placement: Placement::Midpoints,
            index,
            sample: None,
        }
    }

    /// The two sides of an interval weigh a half each in the constraint violation, a side
    /// alone (or a side of another constraint of the same variable) the whole.
    #[test]
    fn the_sides_of_an_interval_share_one_weight() {
        let list = [side(-1.0, 1.0, 0), side(2.0, -1.0, 0), side(0.5, 1.0, 1)];
        assert_eq!(violation_weights(&list), vec![0.5, 0.5, 1.0]);
    }

    /// $g = q_0^2 q_1' + q_1 \sin q_0'$ on $\mathbb{R}^2$, $k = 2$ (a function of the jet alone).
    struct Curved;

    impl JetFunction<2, 2> for Curved {
        fn value(&self, x: &[SVector<f64, 2>; 2], _u: &SVector<f64, 2>) -> f64 {
            x[0][0] * x[0][0] * x[1][1] + x[0][1] * x[1][0].sin()
        }
        fn gradient(&self, x: &[SVector<f64, 2>; 2], _u: &SVector<f64, 2>) -> Gradient<2, 2> {
            let mut g = Gradient::zeros();
            g.x[0] = SVector::from([2.0 * x[0][0] * x[1][1], x[1][0].sin()]);
            g.x[1] = SVector::from([x[0][1] * x[1][0].cos(), x[0][0] * x[0][0]]);
            g
        }
        fn hessian(&self, x: &[SVector<f64, 2>; 2], _u: &SVector<f64, 2>) -> Hessian<2, 2> {
            let mut h = Hessian::zeros();
            h.xx[0][0] = SMatrix::from([[2.0 * x[1][1], 0.0], [0.0, 0.0]]);
            // rows: entries of x_0, columns: entries of x_1 (column-major literals)
            h.xx[0][1] = SMatrix::from([[0.0, x[1][0].cos()], [2.0 * x[0][0], 0.0]]);
            h.xx[1][0] = h.xx[0][1].transpose();
            h.xx[1][1] = SMatrix::from([[-x[0][1] * x[1][0].sin(), 0.0], [0.0, 0.0]]);
            h
        }
        fn involves_top(&self) -> bool {
            false
        }
    }

    /// The sample at tau of (x_theta, u) is the Hermite polynomial between the nodes that the
    /// scheme's equations give (at tau = 0 and 1 the nodes themselves), for k = 3; and the
    /// chain rule through it (gradient and Hessian in (x_theta, u)) agrees with central
    /// differences of the sampled constraint for k = 2.
    #[test]
    fn a_sample_is_the_interpolant_and_its_derivatives_follow_the_chain_rule() {
        let (h, theta) = (0.3, 0.4);
        // k = 3, n = 1: x_theta = (q, q', q''), u = q'''
        let (xt, u) = (
            SVector::<f64, 3>::new(0.2, -1.1, 0.7),
            SVector::<f64, 1>::new(2.5),
        );
        let rate = SVector::<f64, 3>::new(xt[1], xt[2], u[0]);
        let (start, end) = (xt - rate * (theta * h), xt + rate * ((1.0 - theta) * h));
        let piece = Hermite::new(start.as_slice(), end.as_slice(), h, 1, 3).unwrap();
        for tau in [0.0, 0.25, 0.7, 1.0] {
            let point = Sample::new(tau, h, theta, 3)
                .unwrap()
                .point::<1, 3, 3>(&xt, &u);
            for r in 0..3 {
                assert!(
                    (point[r] - piece.jet_entry(r, tau * h)).abs() < 1e-13,
                    "{tau} {r}"
                );
            }
        }
        // k = 2, n = 2: the chain rule against differences in (x_theta, u)
        let c = Inequality {
            source: Source::Function(&Curved),
            value: 0.1,
            sign: -1.0,
            placement: Placement::NodesAndMidpoints,
            index: 0,
            sample: Sample::new(0.3, h, theta, 2),
        };
        let (x, u) = (
            SVector::<f64, 4>::new(0.4, -0.3, 1.2, 0.8),
            SVector::<f64, 2>::new(-0.6, 1.5),
        );
        let lin = c.linearize(&x, &u);
        let (hxx, hux, huu) = c.weighted_hessian(&x, &u, 1.0).unwrap();
        let pick = |l: &Linearized<2, 4>, s: usize| if s < 4 { l.gx[s] } else { l.gu[s - 4] };
        let e = 1e-6;
        for r in 0..6 {
            let moved = |d: f64| {
                let (mut x, mut u) = (x, u);
                if r < 4 {
                    x[r] += d;
                } else {
                    u[r - 4] += d;
                }
                (x, u)
            };
            let ((xp, up), (xm, um)) = (moved(e), moved(-e));
            let slope = (c.value(&xp, &up) - c.value(&xm, &um)) / (2.0 * e);
            assert!(
                (slope - pick(&lin, r)).abs() < 1e-8,
                "gradient {r}: {slope}"
            );
            let (gp, gm) = (c.linearize(&xp, &up), c.linearize(&xm, &um));
            for s in 0..6 {
                let fd = (pick(&gp, s) - pick(&gm, s)) / (2.0 * e);
                let exact = match (r < 4, s < 4) {
                    (true, true) => hxx[(s, r)],
                    (true, false) => hux[(s - 4, r)],
                    (false, true) => hux[(r - 4, s)],
                    (false, false) => huu[(s - 4, r - 4)],
                };
                assert!(
                    (fd - exact).abs() < 1e-7,
                    "hessian ({r}, {s}): {fd} vs {exact}"
                );
            }
        }
    }

    /// The two sides of $-6 \le u \le 6$ share one slack: clamps $p = \min(0.06, 0.12)$ from
    /// each end, so that the pushed slacks of any value sum to the width 12; a lone side
    /// $u \ge 2$ is pushed to $0.02$ with no upper clamp.
    #[test]
    fn the_sides_of_an_interval_share_one_pushed_slack() {
        let list = [side(-6.0, 1.0, 0), side(6.0, -1.0, 0), side(2.0, 1.0, 1)];
        let push = slack_push(&list);
        assert_eq!(push[0], (0.06, 12.0 - 0.06));
        assert_eq!(push[1], (0.06, 12.0 - 0.06));
        assert_eq!(push[2], (0.02, f64::INFINITY));
        for u in [-9.0, -6.0, -5.99, 0.0, 5.97, 7.5] {
            let lower = (u + 6.0_f64).max(push[0].0).min(push[0].1);
            let upper = (6.0 - u).max(push[1].0).min(push[1].1);
            assert!((lower + upper - 12.0).abs() < 1e-12, "u = {u}");
            assert!(lower >= 0.06 && upper >= 0.06, "u = {u}");
        }
    }
}
