//! The SQP iteration of [`super::OptimalControlProblem`]: stage models, the inertia-corrected
//! Riccati solve, the convergence test and the line search on the exact penalty.

use std::time::Instant;

use nalgebra::{SMatrix, SVector};

use super::certificate::{kkt_residuals, min_reduced_eigenvalue};
use super::optimize::{
    Certificate, Failure, Iterate, OptimalControlProblem, Plan, PlanError, blocks,
};
use super::riccati::{Direction, Dynamics, Riccati, StageModel};
use crate::{Hessian, Lagrangian, LiftedSystem};

/// One run of the SQP iteration.
pub(super) struct Sqp<
    'p,
    'a,
    Sys: ?Sized,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
> {
    pub problem: &'p OptimalControlProblem<'a, Sys, N, K, X>,
    pub dynamics: Dynamics<N, X>,
    pub started: Instant,
}

/// The models of all stages at one iterate.
struct Models<const N: usize, const X: usize> {
    stages: Vec<StageModel<N, X>>,
    cost: f64,
    r0: SVector<f64, X>,
    r_end: SVector<f64, X>,
}

impl<const N: usize, const X: usize> Models<N, X> {
    /// $\|c\|_1$ over defects, stage constraints and boundary data.
    fn violation_l1(&self) -> f64 {
        self.stages
            .iter()
            .map(|s| s.defect.lp_norm(1) + s.value.lp_norm(1))
            .sum::<f64>()
            + self.r0.lp_norm(1)
            + self.r_end.lp_norm(1)
    }
    /// $\|c\|_\infty$.
    fn violation_max(&self) -> f64 {
        self.stages
            .iter()
            .map(|s| s.defect.amax().max(s.value.amax()))
            .fold(self.r0.amax().max(self.r_end.amax()), f64::max)
    }
}

/// `h` times the Hessian blocks of a function of $(x, u)$ as $(H_{xx}, H_{ux}, H_{uu})$ over the
/// flat jet.
fn flat_hessian<const N: usize, const K: usize, const X: usize>(
    hs: &Hessian<N, K>,
    scale: f64,
) -> (SMatrix<f64, X, X>, SMatrix<f64, N, X>, SMatrix<f64, N, N>) {
    (
        SMatrix::from_fn(|r, c| scale * hs.xx[r / N][c / N][(r % N, c % N)]),
        SMatrix::from_fn(|b, c| scale * hs.xu[c / N][(c % N, b)]),
        hs.uu * scale,
    )
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    fn x_theta(&self, iterate: &Iterate<N, X>, i: usize) -> SVector<f64, X> {
        let theta = self.dynamics.theta;
        iterate.x[i] * (1.0 - theta) + iterate.x[i + 1] * theta
    }

    /// $J$ and $\|c\|_1$ (line search); `None` if not finite.
    fn merit_parts(&self, iterate: &Iterate<N, X>) -> Option<(f64, f64)> {
        let (h, system) = (self.dynamics.h, self.problem.system);
        let (mut cost, mut violation) = (0.0, 0.0);
        for (i, u) in iterate.u.iter().enumerate() {
            let xb = blocks::<N, K, X>(&self.x_theta(iterate, i));
            cost += h * system.lagrangian(&xb, u);
            violation += (self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1]).lp_norm(1);
            for g in &self.problem.equalities {
                violation += g.value(&xb, u).abs();
            }
        }
        violation += (self.problem.start - iterate.x[0]).lp_norm(1)
            + (self.problem.goal - iterate.x[iterate.x.len() - 1]).lp_norm(1);
        (cost.is_finite() && violation.is_finite()).then_some((cost, violation))
    }

    /// The model of stage `i`: the Hessian of $h L + y^T g$, the gradient of $h L$, the
    /// defect and the constraints with their Jacobians.
    fn stage(&self, iterate: &Iterate<N, X>, i: usize, y: &SVector<f64, N>) -> StageModel<N, X> {
        let (h, system) = (self.dynamics.h, self.problem.system);
        let u = &iterate.u[i];
        let xb = blocks::<N, K, X>(&self.x_theta(iterate, i));
        let g = system.gradient(&xb, u);
        let (mut hxx, mut hux, mut huu) = flat_hessian::<N, K, X>(&system.hessian(&xb, u), h);
        let mut stage = StageModel {
            hxx,
            hux,
            huu,
            gx: SVector::from_fn(|r, _| h * g.x[r / N][r % N]),
            gu: g.u * h,
            defect: self.dynamics.next(&iterate.x[i], u) - iterate.x[i + 1],
            constraints: self.problem.equalities.len(),
            cx: SMatrix::zeros(),
            cu: SMatrix::zeros(),
            value: SVector::zeros(),
        };
        for (j, c) in self.problem.equalities.iter().enumerate() {
            let grad = c.gradient(&xb, u);
            stage.value[j] = c.value(&xb, u);
            for r in 0..X {
                stage.cx[(j, r)] = grad.x[r / N][r % N];
            }
            for a in 0..N {
                stage.cu[(j, a)] = grad.u[a];
            }
            if y[j] != 0.0 {
                let (cxx, cux, cuu) = flat_hessian::<N, K, X>(&c.hessian(&xb, u), y[j]);
                hxx += cxx;
                hux += cux;
                huu += cuu;
            }
        }
        (stage.hxx, stage.hux, stage.huu) = (hxx, hux, huu);
        stage
    }

    /// The models of every stage with the constraint multipliers `y`; `None` if anything is
    /// not finite.
    fn models(&self, iterate: &Iterate<N, X>, y: &[SVector<f64, N>]) -> Option<Models<N, X>> {
        let (h, system) = (self.dynamics.h, self.problem.system);
        let mut stages = Vec::with_capacity(iterate.u.len());
        let mut cost = 0.0;
        for (i, u) in iterate.u.iter().enumerate() {
            cost += h * system.lagrangian(&blocks::<N, K, X>(&self.x_theta(iterate, i)), u);
            let stage = self.stage(iterate, i, &y[i]);
            let finite = stage
                .hxx
                .iter()
                .chain(stage.hux.iter())
                .chain(stage.huu.iter())
                .chain(stage.gx.iter())
                .chain(stage.gu.iter())
                .chain(stage.cx.iter())
                .chain(stage.cu.iter())
                .chain(stage.value.iter())
                .all(|v| v.is_finite());
            if !finite {
                return None;
            }
            stages.push(stage);
        }
        let r0 = self.problem.start - iterate.x[0];
        let r_end = self.problem.goal - iterate.x[iterate.x.len() - 1];
        cost.is_finite().then_some(Models {
            stages,
            cost,
            r0,
            r_end,
        })
    }

    /// The Riccati factorisation with an inertia correction $\rho$ (scaled by $h$) that makes
    /// the reduced Hessian positive definite: none if the last iteration needed none (or
    /// little), else from a third of the `last` one (the correction decays geometrically
    /// instead of dropping to 0 at a point where the Hessian is barely definite), growing by 8
    /// (100 from scratch) until the inertia is right.
    fn factor_corrected(&self, models: &Models<N, X>, last: f64) -> Option<(Riccati<N, X>, f64)> {
        let h = self.dynamics.h;
        if last < 1e-8 {
            let riccati = Riccati::factor(&self.dynamics, &models.stages, 0.0);
            if riccati.positive_definite() {
                return Some((riccati, 0.0));
            }
        }
        let mut rho = if last > 0.0 { last / 3.0 } else { 1e-4 };
        while rho < 1e40 {
            let riccati = Riccati::factor(&self.dynamics, &models.stages, h * rho);
            if riccati.positive_definite() {
                return Some((riccati, rho));
            }
            rho *= if last > 0.0 { 8.0 } else { 100.0 };
        }
        None
    }

    fn plan(
        &self,
        iterate: &Iterate<N, X>,
        cost: f64,
        iterations: usize,
        momenta: Vec<SVector<f64, X>>,
        certificate: Certificate,
    ) -> Plan<N, X> {
        Plan {
            h: self.dynamics.h,
            theta: self.dynamics.theta,
            x: iterate.x.clone(),
            u: iterate.u.clone(),
            momenta,
            cost,
            iterations,
            certificate,
        }
    }

    /// Iterates from `iterate` until the KKT residuals are below the tolerance with a positive
    /// definite reduced Hessian, or a budget or the line search fails.
    pub fn run(&self, mut iterate: Iterate<N, X>) -> Result<Plan<N, X>, PlanError<N, X>> {
        let options = &self.problem.options;
        let h = self.dynamics.h;
        let mut rho_last = 0.0;
        let mut penalty = 0.0;
        let mut iterations = 0;
        let mut y = vec![SVector::<f64, N>::zeros(); iterate.u.len()];
        loop {
            let done = iterations;
            let fail = |failure, iterate: &Iterate<N, X>, cost, certificate, momenta| PlanError {
                failure,
                last: Some(Box::new(self.plan(
                    iterate,
                    cost,
                    done,
                    momenta,
                    certificate,
                ))),
            };
            let Some(models) = self.models(&iterate, &y) else {
                return Err(PlanError {
                    failure: Failure::NonFinite,
                    last: None,
                });
            };
            let Some((riccati, rho)) = self.factor_corrected(&models, rho_last) else {
                let unknown = super::optimize::unknown_certificate();
                return Err(fail(
                    Failure::Regularization,
                    &iterate,
                    models.cost,
                    unknown,
                    vec![],
                ));
            };
            rho_last = rho;
            let direction = riccati.solve(
                &self.dynamics,
                &models.stages,
                h * rho,
                &models.r0,
                &models.r_end,
            );
            let (momenta, stationarity) = kkt_residuals(&self.dynamics, &models.stages, &direction);
            let mut certificate = Certificate {
                stationarity,
                feasibility: models.violation_max(),
                negative_directions: riccati.negative,
                min_reduced_hessian_eig: f64::NAN,
            };
            if stationarity <= options.tolerance && certificate.feasibility <= options.tolerance {
                // the certificate is the factorisation without correction
                let exact = if rho > 0.0 {
                    Riccati::factor(&self.dynamics, &models.stages, 0.0)
                } else {
                    riccati
                };
                certificate.negative_directions = exact.negative;
                if !exact.positive_definite() {
                    let failure = Failure::NotAMinimum {
                        negative_directions: exact.negative,
                    };
                    return Err(fail(failure, &iterate, models.cost, certificate, momenta));
                }
                certificate.min_reduced_hessian_eig =
                    min_reduced_eigenvalue(&exact, &self.dynamics, self.problem.steps);
                return Ok(self.plan(&iterate, models.cost, iterations, momenta, certificate));
            }
            let out_of_time = options
                .max_time
                .is_some_and(|budget| self.started.elapsed() >= budget);
            if iterations == options.max_iterations || out_of_time {
                let failure = if out_of_time {
                    Failure::TimeLimit
                } else {
                    Failure::IterationLimit
                };
                return Err(fail(failure, &iterate, models.cost, certificate, momenta));
            }
            iterations += 1;
            let Some((next, alpha)) = self.line_search(&iterate, &models, &direction, &mut penalty)
            else {
                let failure = Failure::LineSearch;
                return Err(fail(failure, &iterate, models.cost, certificate, momenta));
            };
            iterate = next;
            // the constraint multipliers move with the primal step
            for (yi, target) in y.iter_mut().zip(&direction.multipliers) {
                *yi += (target - *yi) * alpha;
            }
        }
    }

    /// Backtracking on $J + \pi \|c\|_1$ along the direction: the accepted point and step
    /// length, `None` if no step is accepted.
    fn line_search(
        &self,
        iterate: &Iterate<N, X>,
        models: &Models<N, X>,
        direction: &Direction<N, X>,
        penalty: &mut f64,
    ) -> Option<(Iterate<N, X>, f64)> {
        let options = &self.problem.options;
        let theta = self.dynamics.theta;
        // directional derivative of J and the curvature of the model along the direction
        let (mut slope, mut curvature) = (0.0, 0.0);
        for (i, stage) in models.stages.iter().enumerate() {
            let dxt = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
            let du = &direction.du[i];
            slope += stage.gx.dot(&dxt) + stage.gu.dot(du);
            curvature += dxt.dot(&(stage.hxx * dxt))
                + 2.0 * du.dot(&(stage.hux * dxt))
                + du.dot(&(stage.huu * du));
        }
        let violation = models.violation_l1();
        if violation > 0.0 {
            let needed = (slope + 0.5 * curvature.max(0.0)) / (0.9 * violation);
            if needed > *penalty {
                *penalty = needed * 1.1;
            }
        }
        let descent = slope - *penalty * violation;
        let merit0 = models.cost + *penalty * violation;
        if !descent.is_finite() {
            return None;
        }
        // rounding of the merit function: of J and of the defects (about eps |x| each)
        let size: f64 = iterate.x.iter().map(|x| x.lp_norm(1)).sum();
        let noise = 1e-14 * (models.cost.abs() + 2.0 * *penalty * size);
        // a non-negative slope: the direction is at rounding level; take it as it is
        let descent = descent.min(0.0);
        let mut alpha = 1.0;
        for _ in 0..=options.max_backtracks {
            let trial = Iterate {
                x: iterate
                    .x
                    .iter()
                    .zip(&direction.dx)
                    .map(|(x, d)| x + d * alpha)
                    .collect(),
                u: iterate
                    .u
                    .iter()
                    .zip(&direction.du)
                    .map(|(u, d)| u + d * alpha)
                    .collect(),
            };
            let merit = self
                .problem
                .guard::<S, M>(&trial)
                .ok()
                .and_then(|()| self.merit_parts(&trial))
                .map(|(cost, violation)| cost + *penalty * violation);
            if merit.is_some_and(|m| m <= merit0 + options.armijo * alpha * descent + noise) {
                return Some((trial, alpha));
            }
            alpha *= 0.5;
        }
        None
    }
}
