//! The checks of a problem before its solve ([`OptimalControlProblem::validate`]: sizes,
//! options, constraint data, boundary data), of the first iterate (the boundary jets against
//! the domain of the Lagrangian, the terminal cost), and of an iterate's steps against the
//! system's singularity guard ([`OptimalControlProblem::guard`]).

use nalgebra::SVector;

use super::OptimalControlProblem;
use crate::bvp::constraints::SAMPLE_MAX_ORDER;
use crate::bvp::iterate::{Iterate, blocks};
use crate::{DomainViolation, Error, LiftedSystem};

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'_, Sys, N, K, X>
{
    pub(in crate::bvp) fn validate(&self, n: usize, k: usize) -> Result<(), Error> {
        let invalid = |name, requirement| Err(Error::InvalidArgument { name, requirement });
        let o = &self.options;
        if n * k != X || N != n {
            return invalid("system", "the jet length X must be n k");
        }
        if !self.inequalities.iter().all(|c| c.valid::<X>()) {
            return invalid(
                "bounds",
                "bounds need values that are not NaN, a jet index < n k (a block j < k) or a \
                 top index < n, one lower and one upper value per component of a vector \
                 function, and no node placement for what involves the top derivative",
            );
        }
        let free_end = self
            .fixed_start
            .iter()
            .chain(self.fixed_end.iter())
            .any(|f| *f == 0.0);
        if free_end && self.inequalities.iter().any(|c| c.placement.at_nodes()) {
            return invalid(
                "placement",
                "constraints at the nodes need a start and a goal that fix every component (with \
                 a free end, place them at the midpoints: Placement::Midpoints)",
            );
        }
        if self.equalities.len() > n {
            return invalid(
                "equalities",
                "at most n equality constraints per step (each must fix a direction of u)",
            );
        }
        if o.theta == 0.0 && self.equalities.iter().any(|g| !g.involves_top()) {
            return invalid(
                "equalities",
                "at theta = 0 an equality is imposed at x_i, which u_i does not move: it must \
                 involve the top derivative (write it on q^(k), or use theta > 0)",
            );
        }
        if !self
            .start
            .iter()
            .chain(self.goal.iter())
            .all(|v| v.is_finite())
        {
            return invalid("start/goal", "boundary data must be finite");
        }
        if self.steps < k || self.steps > 1 << 24 {
            return invalid("steps", "need k <= steps <= 2^24");
        }
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return invalid("t_end", "the horizon must be finite and positive");
        }
        o.validate()?;
        if o.interior_samples > 0 && k > SAMPLE_MAX_ORDER {
            return invalid(
                "options",
                "at most 63 interior samples per step, for orders k <= 4",
            );
        }
        // (mu = mu_0 / h per unit time: finite for the barrier to be)
        if !(o.initial_barrier / self.h()).is_finite() {
            return invalid(
                "options",
                "the initial barrier parameter per unit time, mu_0 / h, must be finite",
            );
        }
        Ok(())
    }

    /// The boundary jets against the domain of the Lagrangian
    /// ([`crate::bvp::root_finder::check_boundary`], momenta zero as in [`Self::guard`], the
    /// guess's top derivatives of the first and last steps).
    pub(in crate::bvp) fn check_ends<const S: usize, const M: usize>(
        &self,
        iterate: &Iterate<N, X>,
    ) -> Result<(), Error>
    where
        Sys: LiftedSystem<S, M>,
    {
        let state =
            |x: &SVector<f64, X>| SVector::<f64, S>::from_fn(|r, _| if r < X { x[r] } else { 0.0 });
        let (Some(first), Some(last)) = (iterate.u.first(), iterate.u.last()) else {
            return Ok(());
        };
        crate::bvp::root_finder::check_boundary::<Sys, S, M>(
            self.system,
            &state(&self.start),
            &state(&self.goal),
            first.as_slice(),
            last.as_slice(),
        )
    }

    /// A terminal cost must not depend on $q^{(k)}$: its derivatives in it vanish (checked at
    /// the guess's last jet) and its value is finite there.
    pub(in crate::bvp) fn check_terminal_cost(&self, iterate: &Iterate<N, X>) -> Result<(), Error> {
        let (Some(phi), Some(last)) = (self.terminal_cost, iterate.x.last()) else {
            return Ok(());
        };
        let x = blocks::<N, K, X>(last);
        let u = SVector::<f64, N>::zeros();
        let (gradient, hessian) = (phi.gradient(&x, &u), phi.hessian(&x, &u));
        let on_u = gradient.u.amax()
            + hessian.uu.amax()
            + hessian.xu.iter().map(|m| m.amax()).fold(0.0, f64::max);
        if on_u != 0.0 || !phi.value(&x, &u).is_finite() {
            return Err(Error::InvalidArgument {
                name: "terminal cost",
                requirement: "a finite function of x_N = (q, ..., q^(k-1)) only, not of q^(k)",
            });
        }
        Ok(())
    }

    /// The singularity guard on every step ([`crate::step::check_step_domain`]): at its ends,
    /// its evaluation point and, for a chord longer than `chord_spacing`, on its pieces (none
    /// where the guards are quadratic: the three points decide the chord).
    pub(in crate::bvp) fn guard<const S: usize, const M: usize>(
        &self,
        iterate: &Iterate<N, X>,
    ) -> Result<(), (usize, DomainViolation)>
    where
        Sys: LiftedSystem<S, M>,
    {
        let options = crate::StepOptions::default()
            .with_theta(self.options.theta)
            .with_chord_check(self.options.chord_spacing, self.options.max_chord_pieces);
        // (the momenta are not read by the guard: zero, set once)
        let (mut z0, mut w) = (SVector::<f64, S>::zeros(), SVector::<f64, M>::zeros());
        for i in 0..self.steps {
            z0.fixed_rows_mut::<X>(0).copy_from(&iterate.x[i]);
            w.fixed_rows_mut::<X>(0).copy_from(&iterate.x[i + 1]);
            w.fixed_rows_mut::<N>(S).copy_from(&iterate.u[i]);
            crate::step::check_step_domain(self.system_at(i), &z0, &w, &options)
                .map_err(|v| (i, v))?;
        }
        Ok(())
    }
}
