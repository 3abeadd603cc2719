//! Adding constraints to an [`OptimalControlProblem`], and the checks that refuse a problem
//! with no feasible point before any iteration: a bound whose lower value exceeds its upper
//! one, bounds of one variable that exclude each other, equal bounds (an empty interior: an
//! equality), and fixed boundary data outside a node constraint.

use super::OptimalControlProblem;
use crate::bvp::constraints::{ConstraintRef, Inequality, Placement, Source, Variable};
use crate::bvp::plan::violations::{Infeasibility, Location};
use crate::{JetFunction, VectorJetFunction};

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// Adds the equality constraint $g(x_{\theta,i}, u_i) = 0$ at every step (e.g. a passive
    /// joint's torque, written under `#[jet_function]`). At most $n$ constraints, jointly of
    /// full rank in the top derivative $u$ (so that each step can satisfy them).
    ///
    /// A constraint on lower derivatives only reaches $u$ through the evaluation point
    /// $x_{\theta,i}$, by a factor $\theta h^{k-j}$ for the highest derivative $q^{(j)}$ it
    /// involves: one on $q'$ at order 2 (a car's no-slip condition) is solved at any $N$, one
    /// on $q$ alone loses digits as $h^2$ (the linear $q_1 = 2 q_0$ at $T = 1$ stalls from
    /// $N = 200$). Write such a constraint on the top derivative instead (differentiated
    /// $k - j$ times, with ends that satisfy it and its derivatives). At $\theta = 0$, where
    /// $x_{\theta,i} = x_i$ does not depend on $u_i$ at all, it is refused
    /// ([`Failure::Invalid`](crate::bvp::Failure::Invalid)).
    pub fn with_equality(mut self, constraint: &'a (dyn JetFunction<N, K> + Sync)) -> Self {
        self.equalities.push(constraint);
        self
    }

    /// Adds each of `constraints` as an equality ([`Self::with_equality`]): e.g. the
    /// unactuated components of a mechanical system's Euler-Lagrange operator
    /// (`unactuated_torques()` of a `#[mechanical_system]` type).
    pub fn with_equalities<C: JetFunction<N, K> + Sync>(mut self, constraints: &'a [C]) -> Self {
        for constraint in constraints {
            self.equalities.push(constraint);
        }
        self
    }

    /// Adds the inequality $g \ge 0$ (obstacle clearance, a keep-out cone, a torque limit
    /// $\tau_{\max} - \tau \ge 0$) where it belongs: a $g$ of the jet alone at every node and
    /// every step's evaluation point, one that involves $u$ at the evaluation points
    /// ([`Placement`], [`JetFunction::involves_top`]). Handled by the interior-point iteration
    /// with slacks (see the module docs): the first guess need not satisfy it.
    pub fn with_inequality(self, constraint: &'a (dyn JetFunction<N, K> + Sync)) -> Self {
        let placement = default_placement(constraint.involves_top());
        self.with_inequality_at(constraint, placement)
    }

    /// [`Self::with_inequality`] placed explicitly. [`Self::solve`] refuses a node placement
    /// for a $g$ that involves $u$ (which lives at the evaluation points only).
    pub fn with_inequality_at(
        self,
        constraint: &'a (dyn JetFunction<N, K> + Sync),
        placement: Placement,
    ) -> Self {
        self.with_function_bounds_at(constraint, 0.0, f64::INFINITY, placement)
    }

    /// Bounds `lower` $\le g \le$ `upper` on a function (either side may be infinite: no bound
    /// there), placed as [`Self::with_inequality`]: one constraint with two sides, each handled
    /// by the barrier (a force limit $|F| \le F_{\max}$ is one call, not two functions).
    pub fn with_function_bounds(
        self,
        constraint: &'a (dyn JetFunction<N, K> + Sync),
        lower: f64,
        upper: f64,
    ) -> Self {
        let placement = default_placement(constraint.involves_top());
        self.with_function_bounds_at(constraint, lower, upper, placement)
    }

    /// [`Self::with_function_bounds`] placed explicitly.
    pub fn with_function_bounds_at(
        mut self,
        constraint: &'a (dyn JetFunction<N, K> + Sync),
        lower: f64,
        upper: f64,
        placement: Placement,
    ) -> Self {
        let index = self.function_inequalities;
        self.function_inequalities += 1;
        self.push_interval(Source::Function(constraint), lower, upper, placement, index);
        self
    }

    /// Bounds `lower[c]` $\le g_c \le$ `upper[c]` on each component of a vector function
    /// $g(x, u) \in \mathbb{R}^m$ (`#[jet_function]` returning `[f64; m]`; infinite entries: no
    /// bound on that side), each component placed as [`Self::with_inequality`] from its own
    /// dependence on $u$. One constraint (one index in messages, which name the component),
    /// $m$ scalar intervals for the barrier: two thrusts in $[0, f_{\max}]$ are one call.
    /// [`Self::solve`] refuses `lower` or `upper` of a length other than $m$.
    pub fn with_vector_bounds(
        self,
        constraint: &'a (dyn VectorJetFunction<N, K> + Sync),
        lower: &[f64],
        upper: &[f64],
    ) -> Self {
        self.with_vector_bounds_placed(constraint, lower, upper, None)
    }

    /// [`Self::with_vector_bounds`] with every component placed at `placement`.
    pub fn with_vector_bounds_at(
        self,
        constraint: &'a (dyn VectorJetFunction<N, K> + Sync),
        lower: &[f64],
        upper: &[f64],
        placement: Placement,
    ) -> Self {
        self.with_vector_bounds_placed(constraint, lower, upper, Some(placement))
    }

    fn with_vector_bounds_placed(
        mut self,
        constraint: &'a (dyn VectorJetFunction<N, K> + Sync),
        lower: &[f64],
        upper: &[f64],
        placement: Option<Placement>,
    ) -> Self {
        let index = self.function_inequalities;
        self.function_inequalities += 1;
        let m = constraint.components();
        if lower.len() != m || upper.len() != m {
            // (a NaN side: refused by `validate` with the other malformed bounds)
            let source = Source::Component(constraint, 0);
            let placement = Placement::Midpoints;
            self.push_interval(source, f64::NAN, f64::INFINITY, placement, index);
            return self;
        }
        for (c, (&lower, &upper)) in lower.iter().zip(upper).enumerate() {
            let placement = placement
                .unwrap_or_else(|| default_placement(constraint.component_involves_top(c)));
            let source = Source::Component(constraint, c);
            self.push_interval(source, lower, upper, placement, index);
        }
        self
    }

    /// Bounds `lower` $\le v \le$ `upper` on one variable (either may be infinite: no bound
    /// on that side): a jet entry at every node and evaluation point, a top derivative at the
    /// evaluation points.
    pub fn with_bounds(mut self, variable: Variable, lower: f64, upper: f64) -> Self {
        let placement = default_placement(matches!(variable, Variable::Top(_)));
        let index = self.bounds;
        self.bounds += 1;
        self.push_interval(Source::Variable(variable), lower, upper, placement, index);
        self
    }

    /// Bounds `lower[a]` $\le u_a \le$ `upper[a]` on the top derivative $u = q^{(k)}$ at every
    /// step (infinite entries: no bound there), one bound per component
    /// ([`Self::with_bounds`] with [`Variable::Top`]).
    pub fn with_input_bounds(mut self, lower: [f64; N], upper: [f64; N]) -> Self {
        for a in 0..N {
            if lower[a] != f64::NEG_INFINITY || upper[a] != f64::INFINITY {
                self = self.with_bounds(Variable::Top(a), lower[a], upper[a]);
            }
        }
        self
    }

    /// Bounds `lower[a]` $\le q^{(j)}_a \le$ `upper[a]` on block `j` of the jet (0: $q$,
    /// 1: $q'$, ...) at every node and evaluation point (infinite entries: no bound there);
    /// [`Self::solve`] refuses $j \ge k$.
    pub fn with_state_bounds(mut self, j: usize, lower: [f64; N], upper: [f64; N]) -> Self {
        for a in 0..N {
            if lower[a] != f64::NEG_INFINITY || upper[a] != f64::INFINITY {
                let entry = if j < K { j * N + a } else { X };
                self = self.with_bounds(Variable::Jet(entry), lower[a], upper[a]);
            }
        }
        self
    }

    /// The two sides of `lower` $\le v \le$ `upper` as scalar inequalities (a side that is
    /// infinite in its own direction is left out; NaN is kept, to be refused by `validate`,
    /// and an infinity facing the wrong way, to be refused as a contradiction).
    fn push_interval(
        &mut self,
        source: Source<'a, N, K>,
        lower: f64,
        upper: f64,
        placement: Placement,
        index: usize,
    ) {
        self.placed = std::sync::OnceLock::new();
        for (value, sign, absent) in [
            (lower, 1.0, f64::NEG_INFINITY),
            (upper, -1.0, f64::INFINITY),
        ] {
            if value != absent {
                self.inequalities.push(Inequality {
                    source,
                    value,
                    sign,
                    placement,
                    index,
                    sample: None,
                });
            }
        }
    }

    /// The first constraint that no point satisfies: a side infinite the wrong way, a lower
    /// side above the upper side of the same constraint or of another bound of the same
    /// variable, or equal sides (no interior: write an equality).
    pub(in crate::bvp) fn contradiction(&self) -> Option<Infeasibility> {
        let list = &self.inequalities;
        for lower in list {
            if lower.value.is_infinite() {
                return Some(definition(lower.reference(), f64::INFINITY));
            }
            if lower.sign < 0.0 {
                continue;
            }
            for upper in list.iter().filter(|c| c.sign < 0.0) {
                if !lower.same_source(upper) {
                    continue;
                }
                if lower.value >= upper.value {
                    let reference = if lower.index >= upper.index {
                        lower
                    } else {
                        upper
                    };
                    return Some(definition(reference.reference(), lower.value - upper.value));
                }
            }
        }
        None
    }

    /// The first node constraint that the fixed components of the start or the goal violate
    /// (every component fixed: a node constraint there cannot be repaired).
    pub(in crate::bvp) fn ends_violation(&self) -> Option<Infeasibility> {
        let zero = nalgebra::SVector::<f64, N>::zeros();
        let ends = [
            (Location::Start, &self.start, &self.fixed_start),
            (Location::Goal, &self.goal, &self.fixed_end),
        ];
        for (location, x, fixed) in ends {
            if fixed.iter().any(|f| *f == 0.0) {
                continue;
            }
            for c in self.inequalities.iter().filter(|c| c.placement.at_nodes()) {
                let value = c.value(x, &zero);
                // (NaN counts as violated; rounding of a value on the bound does not)
                if value.is_nan() || -value > self.options.tolerance {
                    return Some(Infeasibility {
                        constraint: c.reference(),
                        location,
                        violation: -value,
                    });
                }
            }
        }
        None
    }
}

/// Nodes and midpoints for a constraint of the jet alone, midpoints for one involving $u$.
fn default_placement(involves_top: bool) -> Placement {
    if involves_top {
        Placement::Midpoints
    } else {
        Placement::NodesAndMidpoints
    }
}

/// A constraint whose own data admit no point.
fn definition(constraint: ConstraintRef, violation: f64) -> Infeasibility {
    Infeasibility {
        constraint,
        location: Location::Definition,
        violation,
    }
}
