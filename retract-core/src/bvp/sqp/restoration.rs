//! The feasibility restoration phase (Wächter and Biegler, Math. Program. 106, 2006, sec.
//! 3.3): where neither the filter line search nor the penalty search makes progress, the
//! iteration leaves the barrier problem for one that only reduces the constraint violation,
//! and comes back at a point the filter accepts.
//!
//! At the point $w_R = (x_R, u_R)$ where the filter failed, with violation $\theta_R$ and
//! barrier cost $\varphi_R$, the restoration problem (in the transcribed problem's units)
//! is
//!
//! $$\min_{x, u, n \ge 0}\ \sum_k \bigl(\rho\thinspace n_k - \mu_R \ln(g_k + n_k) - \mu_R
//!   \ln n_k\bigr) + \frac{\zeta}{2} \Vert D_R (w - w_R)\Vert^2 \quad \text{s.t. the
//!   dynamics, the stage equalities and the boundary data},$$
//!
//! with an elastic variable $n_k$ on every inequality row $g_k \ge 0$ (its slack is $g_k +
//! n_k > 0$, so the problem is feasible wherever the equalities are), $\rho = 1000$, $\mu_R
//! = \max(h \mu, \Vert c\Vert_\infty)$, $\zeta = \sqrt{\mu_R}$ and $D_R = \mathrm{diag}
//! (\min(1, 1 / |w_{R,k}|))$, as IPOPT's. The dynamics and the boundary data are linear in
//! the unknowns and stay hard; the stage equalities are linearised as in the main
//! iteration. Each $n_k$ is eliminated in closed form ([`elastic`]): the row's term becomes
//! a smooth convex function $\phi(g_k)$, condensed into the stage models as the barrier's
//! terms are, so every step is one inertia-corrected Riccati solve, $O(N)$. The steps are
//! Newton steps on that problem with backtracking on $F + \pi \Vert c\Vert_1$ ($F$ its
//! objective, $c$ the equalities); $\mu_R$ falls by IPOPT's monotone rule, $\mu_R \leftarrow
//! \min(\mu_R / 5, \mu_R^{1.5})$, whenever the Newton step (relative to the iterate) and
//! $\Vert c\Vert_1$ are below $\kappa_\varepsilon \mu_R$.
//!
//! The phase returns at the first iterate whose violation, with the slacks $s_k = g_k +
//! n_k$, is at most $\kappa_R \theta_R$ ($\kappa_R = 0.9$) and which the filter, augmented
//! by the point where it failed, accepts; the multipliers $z$ are reset under IPOPT's
//! threshold ([`Barrier::restart`]), those of the stage equalities kept as they were (IPOPT
//! recomputes them by least squares). Where the barrier problem is solved at the smallest
//! $\mu_R$ with the violation still above the tolerance, the point is locally infeasible.
//! The phase gives up (and the penalty search's step is taken) after [`MAX_RESTORATION`]
//! passes, or [`STALL`] passes without progress. Its Newton steps count as iterations of the
//! solve, whatever its outcome.

use nalgebra::{SMatrix, SVector};

use super::filter::Filter;
use super::state::{Models, Sqp};
use crate::bvp::barrier::Barrier;
use crate::bvp::iterate::{Iterate, blocks};
use crate::bvp::kkt::model::{StageModel, Terminal};
use crate::bvp::kkt::riccati::Direction;
use crate::{Lagrangian, LiftedSystem};

/// IPOPT's penalty $\rho$ of the elastic variables.
const RHO: f64 = 1000.0;
/// The fraction $\kappa_R$ of the violation at which the phase returns.
const KAPPA_R: f64 = 0.9;
/// The most restoration steps in one phase.
pub(super) const MAX_RESTORATION: usize = 60;
/// The smallest $\mu_R$ relative to $\max(1, \theta_R)$.
const MU_R_FLOOR: f64 = 1e-10;
/// The phase gives up after `STALL` steps without lowering the least violation so far by
/// the fraction `PROGRESS` ([`Restoration::Unfinished`], or [`Restoration::Infeasible`]
/// without progress at all, [`NO_PROGRESS`]).
const STALL: usize = 10;
const PROGRESS: f64 = 1e-3;
/// A phase that gives up without ever lowering the violation it started from by this
/// fraction ends at a point of local infeasibility.
const NO_PROGRESS: f64 = 1e-2;
/// IPOPT's $\kappa_\varepsilon$: $\mu_R$ decreases once the Newton step (relative to the
/// iterate) and $\Vert c\Vert_1$ are below $\kappa_\varepsilon \mu_R$.
const KAPPA_EPSILON: f64 = 10.0;
/// Armijo's constant of the restoration's backtracking, and its most halvings.
const ARMIJO: f64 = 1e-4;
const BACKTRACKS: usize = 40;

/// An inequality row's elastic variable eliminated at $g$ under $\mu$: the minimiser $n$ of
/// $\rho n - \mu \ln(g + n) - \mu \ln n$, the slack $s = g + n$, the minimum $\phi(g)$ and
/// its first two derivatives in $g$.
#[derive(Clone, Copy, Debug)]
pub(super) struct Elastic {
    pub n: f64,
    pub s: f64,
    pub value: f64,
    pub slope: f64,
    pub curvature: f64,
}

/// [`Elastic`] at $g$: the stationarity $\rho - \mu / s - \mu / n = 0$ is the quadratic
/// $\rho n^2 + (\rho g - 2 \mu) n - \mu g = 0$, whose positive root is $n = (2\mu - \rho g +
/// r) / (2\rho)$ with $r = \sqrt{\rho^2 g^2 + 4 \mu^2}$, and $s = (2\mu + \rho g + r) /
/// (2\rho)$ (each formed without cancellation: $r - \rho |g| = 4\mu^2 / (r + \rho |g|)$);
/// $\phi'(g) = -\mu / s$ (the envelope theorem) and $\phi''(g) = \mu (1 + n'(g)) / s^2$
/// with $1 + n' = (1 + \rho g / r) / 2 \in (0, 1)$.
pub(super) fn elastic(g: f64, mu: f64) -> Elastic {
    let root = (RHO * RHO * g * g + 4.0 * mu * mu).sqrt();
    let small = 4.0 * mu * mu / (root + RHO * g.abs());
    let big = (2.0 * mu + RHO * g.abs() + root) / (2.0 * RHO);
    let little = (2.0 * mu + small) / (2.0 * RHO);
    let (n, s, factor) = if g >= 0.0 {
        (little, big, (root + RHO * g) / (2.0 * root))
    } else {
        (big, little, small / (2.0 * root))
    };
    Elastic {
        n,
        s,
        value: RHO * n - mu * (s.ln() + n.ln()),
        slope: -mu / s,
        curvature: mu * factor / (s * s),
    }
}

/// The squared scaling $D_R^2$ of the proximity term at a reference vector:
/// $\min(1, 1 / |v_k|)^2$ per component.
fn scaling<const D: usize>(reference: &SVector<f64, D>) -> SVector<f64, D> {
    reference.map(|v| {
        let d = (1.0 / v.abs()).min(1.0);
        d * d
    })
}

/// The restoration problem's data: the reference point $w_R$, $\mu_R$ and $\zeta$.
struct Reference<'r, const N: usize, const X: usize> {
    point: &'r Iterate<N, X>,
    mu: f64,
    zeta: f64,
}

/// The quantities of one point of the restoration: its objective $F$, $\Vert c\Vert_1$ over
/// the equalities (dynamics, stage equalities, boundary data), the main problem's cost $J +
/// \Phi$, $\sum_k n_k$ and $\sum_k \ln s_k$.
#[derive(Clone, Copy, Debug, Default)]
struct Evaluation {
    objective: f64,
    constraints: f64,
    cost: f64,
    elastic: f64,
    log: f64,
}

/// How a restoration phase ended.
pub(super) enum Restoration<const N: usize, const X: usize> {
    /// At an iterate the filter accepts: it and its slacks.
    Restored(Iterate<N, X>, Vec<f64>),
    /// At a point of local infeasibility: the phase's barrier problem solved at its floor
    /// with the violation above the tolerance, or the phase given up without any step
    /// lowering the violation it started from by [`NO_PROGRESS`].
    Infeasible,
    /// Without either (its budget or a factorisation ran out).
    Unfinished,
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// The restoration phase from `iterate` (its `models` and `barrier`), the `filter`
    /// augmented by the point first (IPOPT's rule: the iteration cannot come back to it):
    /// how it ended and the Newton steps it took.
    pub(super) fn restore(
        &self,
        (iterate, models): (&Iterate<N, X>, &Models<N, X>),
        barrier: &Barrier,
        filter: &mut Filter,
    ) -> (Restoration<N, X>, usize) {
        let (theta_r, phi_r) = (models.violation_l1(), models.barrier_cost);
        filter.augment((1.0 - 1e-5) * theta_r, phi_r - 1e-8 * theta_r);
        let h = self.dynamics.h;
        let mu = (h * barrier.mu).max(models.violation_max());
        let mut reference = Reference {
            point: iterate,
            mu,
            zeta: mu.sqrt(),
        };
        let floor = MU_R_FLOOR * theta_r.max(1.0);
        let mut w = self.copy_iterate(iterate);
        let (mut penalty, mut rho_last) = (0.0, 0.0);
        // the least violation so far and the step where it was reached
        let mut best = (theta_r, 0);
        let mut slacks = self.pool.borrow_mut().reals.take(barrier.s.len());
        // the Newton steps taken (the passes that only lower mu_R take none)
        let mut newton = 0;
        // (how the phase ends if it leaves the loop)
        let mut end = Restoration::Unfinished;
        for step in 1..=MAX_RESTORATION {
            if self.out_of_time() {
                break;
            }
            let Some(at) = self.evaluate(&w, &reference, None) else {
                break;
            };
            let Some((d, rho)) = self.restoration_direction(&w, &reference, rho_last) else {
                break;
            };
            if rho > 0.0 {
                rho_last = rho;
            }
            let size = w.x.iter().map(|x| x.amax()).fold(1.0, f64::max);
            let length = (d.dx.iter().map(|v| v.amax()))
                .chain(d.du.iter().map(|v| v.amax()))
                .fold(0.0, f64::max);
            // the restoration's barrier problem solved to about mu_R: mu_R decreased (IPOPT's
            // monotone rule), or at its floor, the violation is as small as it gets here
            if length <= KAPPA_EPSILON * reference.mu * size
                && at.constraints <= KAPPA_EPSILON * reference.mu
            {
                self.recycle_direction(d);
                if reference.mu <= floor {
                    let theta = at.constraints + at.elastic;
                    self.finish_restoration(w, slacks);
                    let end = if theta > self.options.tolerance {
                        Restoration::Infeasible
                    } else {
                        Restoration::Unfinished
                    };
                    return (end, newton);
                }
                reference.mu = (reference.mu / 5.0).min(reference.mu.powf(1.5)).max(floor);
                reference.zeta = reference.mu.sqrt();
                continue;
            }
            let searched = (&w, &d, at, &reference);
            let next = self.restoration_step(searched, &mut penalty, &mut slacks);
            self.recycle_direction(d);
            let Some((next, evaluation)) = next else {
                break;
            };
            newton += 1;
            self.give_iterate(core::mem::replace(&mut w, next));
            let theta = evaluation.constraints + evaluation.elastic;
            let phi = evaluation.cost - h * barrier.mu * evaluation.log;
            if theta <= KAPPA_R * theta_r && !filter.rejects(theta, phi) {
                return (Restoration::Restored(w, slacks), newton);
            }
            if theta < (1.0 - PROGRESS) * best.0 {
                best = (theta, step);
            } else if step - best.1 >= STALL {
                // (no step of the phase lowered the violation by NO_PROGRESS: the iterate is
                // where the violation is stationary, a point of local infeasibility)
                if best.0 > (1.0 - NO_PROGRESS) * theta_r {
                    end = Restoration::Infeasible;
                }
                break;
            }
        }
        self.finish_restoration(w, slacks);
        (end, newton)
    }

    /// Gives the phase's iterate and slacks back to the pool.
    fn finish_restoration(&self, w: Iterate<N, X>, slacks: Vec<f64>) {
        self.give_iterate(w);
        self.pool.borrow_mut().reals.give(slacks);
    }

    /// A copy of `iterate` from the pool.
    fn copy_iterate(&self, iterate: &Iterate<N, X>) -> Iterate<N, X> {
        let mut w = self.take_iterate(iterate.u.len());
        w.x.extend_from_slice(&iterate.x);
        w.u.extend_from_slice(&iterate.u);
        w
    }

    /// Gives a direction's vectors back to the pool.
    fn recycle_direction(&self, d: Direction<N, X>) {
        d.recycle(&mut *self.pool.borrow_mut());
    }

    /// The Newton direction of the restoration problem at `w`: its models
    /// ([`Self::restoration_models`]) factored with the inertia correction (from `rho_last`)
    /// and solved; with the correction found. `None` if a model is not finite or the
    /// correction fails.
    fn restoration_direction(
        &self,
        w: &Iterate<N, X>,
        reference: &Reference<'_, N, X>,
        rho_last: f64,
    ) -> Option<(Direction<N, X>, f64)> {
        let mut models = self.restoration_models(w, reference)?;
        let none = Barrier {
            mu: 0.0,
            s: Vec::new(),
            z: Vec::new(),
            y: Vec::new(),
            count: 0,
            nodes: 0,
            steps: w.u.len(),
            h: self.dynamics.h,
        };
        let factored = self.factor_corrected(&mut models, &none, rho_last);
        let result = factored.ok().map(|(riccati, rho)| {
            let mut pool = self.pool.borrow_mut();
            let end = (&models.r_end, &models.terminal_gradient);
            let (stages, r0) = (&models.stages, &models.r0);
            let d = riccati.solve(&self.dynamics, stages, r0, end, &mut *pool);
            riccati.recycle(&mut *pool);
            (d, rho)
        });
        self.give_models(models);
        result
    }

    /// The restoration problem's models at `w`: per step the proximity term's Hessian
    /// $\zeta D_R^2$ and gradient $\zeta D_R^2 (w - w_R)$ (on $u_i$ in the stage, on $x_i$ in
    /// its node terms, on $x_N$ at the end), each inequality row's $\phi''(g) \nabla g \nabla
    /// g^T + \phi'(g) \nabla^2 g$ and $\phi'(g) \nabla g$ ([`elastic`]), the defect and the
    /// stage equalities; `None` if anything is not finite.
    fn restoration_models(
        &self,
        w: &Iterate<N, X>,
        reference: &Reference<'_, N, X>,
    ) -> Option<Models<N, X>> {
        let (zeta, mu, wr) = (reference.zeta, reference.mu, reference.point);
        let steps = w.u.len();
        let mut stages = self.pool.borrow_mut().stages.take(steps);
        let zero = SVector::<f64, N>::zeros();
        let mut finite = true;
        for (i, u) in w.u.iter().enumerate() {
            let (dx, du) = (scaling(&wr.x[i]) * zeta, scaling(&wr.u[i]) * zeta);
            let xt = self.x_theta(w, i);
            let (cx, cu, value) = self.equality_rows(&blocks::<N, K, X>(&xt), u);
            let mut stage = StageModel {
                hxx: SMatrix::zeros(),
                hux: SMatrix::zeros(),
                huu: SMatrix::from_diagonal(&du),
                gx: SVector::zeros(),
                gu: du.component_mul(&(u - wr.u[i])),
                defect: self.dynamics.next(&w.x[i], u) - w.x[i + 1],
                constraints: self.problem.equalities.len(),
                cx,
                cu,
                value,
                node: None,
            };
            for c in self.at_steps {
                let lin = c.linearize(&xt, u);
                let e = elastic(lin.value, mu);
                stage.gx += lin.gx * e.slope;
                stage.gu += lin.gu * e.slope;
                stage.hxx += lin.gx * lin.gx.transpose() * e.curvature;
                stage.hux += lin.gu * lin.gx.transpose() * e.curvature;
                stage.huu += lin.gu * lin.gu.transpose() * e.curvature;
                if let Some((cxx, cux, cuu)) = c.weighted_hessian(&xt, u, e.slope) {
                    stage.hxx += cxx;
                    stage.hux += cux;
                    stage.huu += cuu;
                }
            }
            let mut node = (
                SMatrix::from_diagonal(&dx),
                dx.component_mul(&(w.x[i] - wr.x[i])),
            );
            for c in self.at_nodes.iter().filter(|_| i > 0) {
                let lin = c.linearize(&w.x[i], &zero);
                let e = elastic(lin.value, mu);
                node.0 += lin.gx * lin.gx.transpose() * e.curvature;
                node.1 += lin.gx * e.slope;
                if let Some((cxx, _, _)) = c.weighted_hessian(&w.x[i], &zero, e.slope) {
                    node.0 += cxx;
                }
            }
            stage.node = Some(node);
            finite &= stage.is_finite();
            stages.push(stage);
        }
        let last = &w.x[steps];
        let end = scaling(&wr.x[steps]) * zeta;
        let (inequalities, cost_gradient) = {
            let mut pool = self.pool.borrow_mut();
            (pool.linearized.take(0), pool.gradients.take(0))
        };
        let models = Models {
            stages,
            cost: 0.0,
            barrier_cost: 0.0,
            r0: (self.problem.start - w.x[0]).component_mul(&self.problem.fixed_start),
            r_end: (self.problem.goal - last).component_mul(&self.problem.fixed_end),
            inequalities,
            cost_gradient,
            slack_violation: (0.0, 0.0),
            terminal: Terminal {
                hessian: SMatrix::from_diagonal(&end),
                fixed: self.problem.fixed_end,
                start_fixed: self.problem.fixed_start,
            },
            terminal_gradient: end.component_mul(&(last - wr.x[steps])),
        };
        if finite {
            Some(models)
        } else {
            self.give_models(models);
            None
        }
    }

    /// One backtracking step of the restoration from `w` along `d` (at `w` the evaluation
    /// `at`) on the merit $F + \pi \Vert c\Vert_1$, $\pi$ raised to $2 \nabla F^T d / \Vert
    /// c\Vert_1$ where that is larger (then the merit's derivative $\nabla F^T d - \pi \Vert
    /// c\Vert_1$ is negative: the direction satisfies the linearised equalities): the new
    /// point and its evaluation, with its slacks in `slacks`; `None` if no step is accepted.
    fn restoration_step(
        &self,
        (w, d, at, reference): (
            &Iterate<N, X>,
            &Direction<N, X>,
            Evaluation,
            &Reference<'_, N, X>,
        ),
        penalty: &mut f64,
        slacks: &mut Vec<f64>,
    ) -> Option<(Iterate<N, X>, Evaluation)> {
        let slope = self.restoration_slope(w, d, reference);
        if at.constraints > 0.0 && slope > 0.0 {
            *penalty = penalty.max(2.0 * slope / at.constraints);
        }
        let descent = (slope - *penalty * at.constraints).min(0.0);
        let merit0 = at.objective + *penalty * at.constraints;
        let noise = 1e-14 * merit0.abs().max(1.0);
        let mut alpha = 1.0;
        for _ in 0..=BACKTRACKS {
            let mut trial = self.take_iterate(w.u.len());
            (trial.x).extend(w.x.iter().zip(&d.dx).map(|(x, dx)| x + dx * alpha));
            (trial.u).extend(w.u.iter().zip(&d.du).map(|(u, du)| u + du * alpha));
            let evaluation = (self.problem.guard::<S, M>(&trial).ok())
                .and_then(|()| self.evaluate(&trial, reference, Some(&mut *slacks)));
            if let Some(e) = evaluation
                && e.objective + *penalty * e.constraints
                    <= merit0 + ARMIJO * alpha * descent + noise
            {
                return Some((trial, e));
            }
            self.give_iterate(trial);
            alpha *= 0.5;
        }
        None
    }

    /// $\nabla F^T d$ of the restoration objective at `w` along `d`: the proximity term's and
    /// every inequality row's $\phi'(g) \nabla g^T d$.
    fn restoration_slope(
        &self,
        w: &Iterate<N, X>,
        d: &Direction<N, X>,
        reference: &Reference<'_, N, X>,
    ) -> f64 {
        let (zeta, mu, wr) = (reference.zeta, reference.mu, reference.point);
        let theta = self.dynamics.theta;
        let zero = SVector::<f64, N>::zeros();
        let mut slope = 0.0;
        for (i, x) in w.x.iter().enumerate() {
            let dx = scaling(&wr.x[i]) * zeta;
            slope += dx.component_mul(&(x - wr.x[i])).dot(&d.dx[i]);
            if i > 0 && i < w.u.len() {
                for c in self.at_nodes {
                    let lin = c.linearize(x, &zero);
                    slope += elastic(lin.value, mu).slope * lin.gx.dot(&d.dx[i]);
                }
            }
        }
        for (i, u) in w.u.iter().enumerate() {
            let du = scaling(&wr.u[i]) * zeta;
            slope += du.component_mul(&(u - wr.u[i])).dot(&d.du[i]);
            let xt = self.x_theta(w, i);
            let dxt = d.dx[i] * (1.0 - theta) + d.dx[i + 1] * theta;
            for c in self.at_steps {
                let lin = c.linearize(&xt, u);
                let change = lin.gx.dot(&dxt) + lin.gu.dot(&d.du[i]);
                slope += elastic(lin.value, mu).slope * change;
            }
        }
        slope
    }

    /// [`Evaluation`] at `w`; with `slacks`, the rows' slacks $g_k + n_k$ into it (emptied
    /// first), in the barrier's order (steps, then interior nodes). `None` if not finite.
    fn evaluate(
        &self,
        w: &Iterate<N, X>,
        reference: &Reference<'_, N, X>,
        mut slacks: Option<&mut Vec<f64>>,
    ) -> Option<Evaluation> {
        let (h, zeta, mu, wr) = (
            self.dynamics.h,
            reference.zeta,
            reference.mu,
            reference.point,
        );
        let mut e = Evaluation::default();
        if let Some(s) = slacks.as_deref_mut() {
            s.clear();
        }
        let mut row = |g: f64, e: &mut Evaluation| {
            let r = elastic(g, mu);
            e.objective += r.value;
            e.elastic += r.n;
            e.log += r.s.ln();
            if let Some(s) = slacks.as_deref_mut() {
                s.push(r.s);
            }
        };
        let proximity = |v: f64, r: f64| {
            let d = (1.0 / r.abs()).min(1.0);
            0.5 * zeta * (d * (v - r)).powi(2)
        };
        for (i, u) in w.u.iter().enumerate() {
            let xt = self.x_theta(w, i);
            let xb = blocks::<N, K, X>(&xt);
            e.cost += h * self.scale * self.problem.system_at(i).lagrangian(&xb, u);
            e.constraints += (self.dynamics.next(&w.x[i], u) - w.x[i + 1]).lp_norm(1);
            for g in &self.problem.equalities {
                e.constraints += g.value(&xb, u).abs();
            }
            for c in self.at_steps {
                row(c.value(&xt, u), &mut e);
            }
            e.objective += u
                .iter()
                .zip(wr.u[i].iter())
                .map(|(v, r)| proximity(*v, *r))
                .sum::<f64>();
        }
        let zero = SVector::<f64, N>::zeros();
        for x in w.x.iter().take(w.u.len()).skip(1) {
            for c in self.at_nodes {
                row(c.value(x, &zero), &mut e);
            }
        }
        for (x, r) in w.x.iter().zip(&wr.x) {
            e.objective += x
                .iter()
                .zip(r.iter())
                .map(|(v, r)| proximity(*v, *r))
                .sum::<f64>();
        }
        let last = &w.x[w.u.len()];
        e.constraints += (self.problem.start - w.x[0])
            .component_mul(&self.problem.fixed_start)
            .lp_norm(1)
            + (self.problem.goal - last)
                .component_mul(&self.problem.fixed_end)
                .lp_norm(1);
        e.cost += self.terminal_value(last);
        let finite = [e.objective, e.constraints, e.cost, e.elastic, e.log];
        finite.iter().all(|v| v.is_finite()).then_some(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eliminated elastic variable: $n$ and $s$ satisfy the stationarity
    /// $\rho - \mu / s - \mu / n = 0$ with $s = g + n$, and $\phi'$, $\phi''$ agree with
    /// central differences of $\phi$, for violated, active and satisfied rows.
    #[test]
    fn the_elastic_term_is_the_minimum_over_the_elastic_variable() {
        let mu = 0.3;
        for g in [-5.0, -1e-3, 0.0, 1e-3, 2.0] {
            let e = elastic(g, mu);
            assert!((e.s - (g + e.n)).abs() <= 1e-12 * e.s.max(1.0));
            assert!((RHO - mu / e.s - mu / e.n).abs() <= 1e-9 * RHO);
            // (the scale on which phi varies: s, or |g| where the row is violated)
            let step = 1e-4 * e.s.max(g.abs()).min(1.0);
            let (plus, minus) = (elastic(g + step, mu), elastic(g - step, mu));
            let slope = (plus.value - minus.value) / (2.0 * step);
            assert!((slope - e.slope).abs() <= 1e-6 * e.slope.abs().max(1.0));
            let curvature = (plus.slope - minus.slope) / (2.0 * step);
            assert!((curvature - e.curvature).abs() <= 1e-5 * e.curvature.abs().max(1e-3));
            assert!(e.curvature > 0.0);
        }
    }
}
