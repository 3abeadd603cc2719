//! The violations of an iterate: how far it is from the problem's constraints at the nodes,
//! the steps' evaluation points and along the interpolant
//! ([`crate::bvp::Violations`]), and the constraint violated most.

use nalgebra::SVector;

use super::OptimalControlProblem;
use crate::bvp::constraints::{ConstraintKind, ConstraintRef};
use crate::bvp::iterate::{Iterate, blocks};
use crate::bvp::plan::violations::{INTERPOLANT_DIVISIONS, Infeasibility, Location, Violations};

/// The running maximum of violations with the constraint that attains it.
#[derive(Default)]
struct Worst {
    value: f64,
    at: Option<Infeasibility>,
}

impl Worst {
    fn see(&mut self, violation: f64, constraint: ConstraintRef, location: Location) {
        // (a NaN violation is the worst of all)
        if violation > self.value || (violation.is_nan() && !self.value.is_nan()) {
            self.value = violation;
            self.at = Some(Infeasibility {
                constraint,
                location,
                violation,
            });
        }
    }
}

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'_, Sys, N, K, X>
{
    /// The violations of `iterate` (jets and top derivatives, the problem's steps) with
    /// `theta`, and the worst constraint at a node or evaluation point.
    pub(in crate::bvp) fn violations(
        &self,
        iterate: &Iterate<N, X>,
        theta: f64,
    ) -> (Violations, Option<Infeasibility>) {
        let zero = SVector::<f64, N>::zeros();
        let (mut nodes, mut midpoints, mut between) =
            (Worst::default(), Worst::default(), Worst::default());
        for (i, x) in iterate.x.iter().enumerate() {
            for c in self.inequalities.iter().filter(|c| c.placement.at_nodes()) {
                nodes.see(-c.value(x, &zero), c.reference(), Location::Node(i));
            }
        }
        for (i, u) in iterate.u.iter().enumerate() {
            let xt = iterate.x[i] * (1.0 - theta) + iterate.x[i + 1] * theta;
            for c in self
                .inequalities
                .iter()
                .filter(|c| c.placement.at_midpoints())
            {
                midpoints.see(-c.value(&xt, u), c.reference(), Location::Step(i));
            }
            let xb = blocks::<N, K, X>(&xt);
            for (index, g) in self.equalities.iter().enumerate() {
                let constraint = ConstraintRef {
                    kind: ConstraintKind::Equality,
                    index,
                    name: g.name(),
                };
                midpoints.see(g.value(&xb, u).abs(), constraint, Location::Step(i));
            }
            self.between(iterate, i, &mut between);
        }
        let worst = [nodes.at, midpoints.at]
            .into_iter()
            .flatten()
            .max_by(|a, b| a.violation.total_cmp(&b.violation));
        let report = Violations {
            nodes: nodes.value,
            midpoints: midpoints.value,
            interpolant: between.value,
        };
        (report, worst)
    }

    /// The node inequalities on the interpolant inside step `i` (the Hermite polynomial
    /// between its end jets, [`interpolant_weights`]).
    fn between(&self, iterate: &Iterate<N, X>, i: usize, worst: &mut Worst) {
        let mut at_nodes = self
            .inequalities
            .iter()
            .filter(|c| c.placement.at_nodes())
            .peekable();
        if at_nodes.peek().is_none() {
            return;
        }
        let Some(weights) = &self.placed().interpolant else {
            return;
        };
        let (x0, x1) = (&iterate.x[i], &iterate.x[i + 1]);
        let zero = SVector::<f64, N>::zeros();
        let mut points = [SVector::<f64, X>::zeros(); INTERPOLANT_DIVISIONS - 1];
        for (p, point) in points.iter_mut().enumerate() {
            let w = &weights[p * 2 * K * K..(p + 1) * 2 * K * K];
            *point = SVector::from_fn(|r, _| {
                let (j, a) = (r / N, r % N);
                let row = &w[j * 2 * K..(j + 1) * 2 * K];
                (0..K)
                    .map(|m| row[m] * x0[m * N + a] + row[K + m] * x1[m * N + a])
                    .sum()
            });
        }
        for c in at_nodes {
            for x in &points {
                worst.see(-c.value(x, &zero), c.reference(), Location::Between(i));
            }
        }
    }
}
