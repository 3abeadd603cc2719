//! Iterative refinement of a subproblem's solution (as IPOPT refines its KKT solves).
//!
//! Near the end of an interior-point solve the barrier Hessian $h (z/s) \nabla g \nabla g^T$
//! of an active inequality reaches $10^{10}$ times the rest of the stage Hessian, and the
//! Riccati solution carries errors of that times the rounding unit: enough to keep the
//! stationarity residual at $10^{-5}$ while the iterate has converged. One refinement step
//! computes the residual $F$ of the subproblem's optimality conditions at the computed solution
//! with the same model and solves the same factorised system for the correction, $K \Delta =
//! -F$: the subproblem with $F$ as its linear terms, defects and constraint offsets.

use nalgebra::SVector;

use super::model::{StageLinear, StageModel, Terminal};
use super::riccati::{Direction, Riccati, Vectors};
use crate::bvp::dynamics::Dynamics;

/// The gradient in $(\delta x_i, \delta u_i)$ of the Lagrangian of stage $i$'s model
/// $\ell_i + y^T (G_x \delta y_x + G_u \delta u + g)$ at `(dx, du)`, with $\rho$ on the
/// diagonal of its Hessian in $(\delta x_i, \delta u_i)$ as in [`Riccati::factor_with`] and
/// $\delta y_x = E \delta x + \theta \bar B \delta u + \theta c$; and the residual of its
/// constraints.
fn stage_gradient<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stage: &StageModel<N, X>,
    rho: f64,
    (dx, du, y): (&SVector<f64, X>, &SVector<f64, N>, &SVector<f64, N>),
) -> (SVector<f64, X>, SVector<f64, N>, SVector<f64, N>) {
    let theta = dynamics.theta;
    let yx = dynamics.poly_e.left(dx) + dynamics.poly_b.left(du) * theta + stage.defect * theta;
    let mut gx = stage.hxx * yx + stage.hux.transpose() * du + stage.gx;
    let mut gu = stage.hux * yx + stage.huu * du + du * rho + stage.gu;
    let mut constraint = SVector::<f64, N>::zeros();
    if stage.constraints > 0 {
        gx += stage.cx.transpose() * y;
        gu += stage.cu.transpose() * y;
        constraint = stage.cx * yx + stage.cu * du + stage.value;
        for r in stage.constraints..N {
            constraint[r] = 0.0;
        }
    }
    let mut lx = dynamics.poly_e.left_t(&gx);
    let lu = dynamics.poly_b.left_t(&gx) * theta + gu;
    if let Some(node) = &stage.node {
        lx += node.0 * dx + node.1;
    }
    lx += dx * rho;
    (lx, lu, constraint)
}

/// The multiplier $\mu$ of the start condition $\delta x_0 = r_0$ at the solution `d` of the
/// subproblem whose first stage is `stage` (no inertia correction): the gradient in
/// $\delta x_0$ of the Lagrangian of stage 0 at `d` plus $\bar A^T \lambda_0$ (the costate of
/// step 0), the residual of the stationarity at $x_0$ that the start condition takes up (zero
/// on the free start components).
pub(crate) fn start_multiplier<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stage: &StageModel<N, X>,
    d: &Direction<N, X>,
) -> SVector<f64, X> {
    let point = (&d.dx[0], &d.du[0], &d.multipliers[0]);
    let (lx, _, _) = stage_gradient(dynamics, stage, 0.0, point);
    lx + dynamics.poly_a.left_t(&d.costate[0])
}

/// One step of iterative refinement of `d`, the solution by `riccati` of the subproblem of
/// `stages` (with `rho`, the start `r0`, the end `r_end` and the terminal gradient `s_end`):
/// the residuals of stationarity in $\delta u_i$ and $\delta x_i$, of the dynamics, of the
/// stage constraints and of the ends, then their correction added to `d` (its vectors from
/// `pool`).
pub(crate) fn refine<const N: usize, const X: usize>(
    riccati: &Riccati<N, X>,
    dynamics: &Dynamics<N, X>,
    (stages, terminal): (&[StageModel<N, X>], &Terminal<X>),
    rho: f64,
    r0: &SVector<f64, X>,
    (r_end, s_end): (&SVector<f64, X>, &SVector<f64, X>),
    (d, pool): (&mut Direction<N, X>, &mut impl Vectors<N, X>),
) {
    let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
    let steps = stages.len();
    let residual = |i: usize| {
        let stage = &stages[i];
        let point = (&d.dx[i], &d.du[i], &d.multipliers[i]);
        let (mut lx, mut lu, constraint) = stage_gradient(dynamics, stage, rho, point);
        let next = &d.costate[i];
        lx += a.left_t(next);
        lu += b.left_t(next);
        if i > 0 {
            lx -= d.costate[i - 1];
        }
        let defect = a.left(&d.dx[i]) + b.left(&d.du[i]) + stage.defect - d.dx[i + 1];
        StageLinear {
            lx,
            lu,
            defect,
            constraint,
        }
    };
    let start = (r0 - d.dx[0]).component_mul(&terminal.start_fixed);
    let end = (r_end - d.dx[steps]).component_mul(&terminal.fixed);
    // at the free components of x_N: lambda_N = (P_N + rho) dx_N + s_end
    let last = &d.dx[steps];
    let free = terminal.fixed.map(|f| 1.0 - f);
    let terminal_residual =
        (terminal.hessian * last + last * rho + s_end - d.costate[steps - 1]).component_mul(&free);
    let ends = (&end, &terminal_residual);
    let correction = riccati.solve_linear(dynamics, &residual, &start, ends, pool);
    for (x, c) in d.dx.iter_mut().zip(&correction.dx) {
        *x += c;
    }
    for (u, c) in d.du.iter_mut().zip(&correction.du) {
        *u += c;
    }
    for (l, c) in d.costate.iter_mut().zip(&correction.costate) {
        *l += c;
    }
    for (y, c) in d.multipliers.iter_mut().zip(&correction.multipliers) {
        *y += c;
    }
    correction.recycle(pool);
}
