//! Iterative refinement of a subproblem's solution (as IPOPT refines its KKT solves).
//!
//! Near the end of an interior-point solve the barrier Hessian $h (z/s) \nabla g \nabla g^T$
//! of an active inequality reaches $10^{10}$ times the rest of the stage Hessian, and the
//! Riccati solution carries errors of that times the rounding unit: enough to keep the
//! stationarity residual at $10^{-5}$ while the iterate has converged. One refinement step
//! computes the residual $F$ of the subproblem's optimality conditions at the computed solution
//! with the same model and solves the same factorised system for the correction, $K \Delta =
//! -F$: the subproblem with $F$ as its linear terms, defects and constraint offsets.
//!
//! The same loss comes from a long tail's terminal pivot on a weakly controllable system; there
//! [`needs_refinement`] measures $F$ against IPOPT's residual ratio first.

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

/// The residual of the subproblem's optimality conditions at stage $i$ of its solution `d`
/// (`rho` as in [`Riccati::factor_with`]): the stationarity in $\delta x_i$ (with the
/// costates $\bar A^T \lambda_{i+1} - \lambda_i$) and in $\delta u_i$, the dynamics' defect
/// and the stage constraints' residual.
fn stage_residual<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stage: &StageModel<N, X>,
    rho: f64,
    d: &Direction<N, X>,
    i: usize,
) -> StageLinear<N, X> {
    let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
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
}

/// The residuals of the ends of the subproblem's solution `d`: the fixed start components'
/// miss of `r0`, the fixed end components' miss of `r_end`, and at the free components of
/// $x_N$ the stationarity $(P_N + \rho) \delta x_N + s_{\rm end} - \lambda_N$.
fn end_residuals<const N: usize, const X: usize>(
    terminal: &Terminal<X>,
    rho: f64,
    r0: &SVector<f64, X>,
    (r_end, s_end): (&SVector<f64, X>, &SVector<f64, X>),
    d: &Direction<N, X>,
) -> [SVector<f64, X>; 3] {
    let steps = d.du.len();
    let start = (r0 - d.dx[0]).component_mul(&terminal.start_fixed);
    let end = (r_end - d.dx[steps]).component_mul(&terminal.fixed);
    let last = &d.dx[steps];
    let free = terminal.fixed.map(|f| 1.0 - f);
    let stationarity =
        (terminal.hessian * last + last * rho + s_end - d.costate[steps - 1]).component_mul(&free);
    [start, end, stationarity]
}

/// The largest residual ratio above which [`needs_refinement`] asks for a refinement step:
/// IPOPT's `residual_ratio_max`.
const RESIDUAL_RATIO_MAX: f64 = 1e-10;

/// Whether the solution `d` of the subproblem of `stages` misses its optimality conditions by
/// more than rounding: IPOPT's test of a KKT solve, $\Vert F \Vert_\infty / (\min(\Vert d
/// \Vert_\infty, 10^6 \Vert b \Vert_\infty) + \Vert b \Vert_\infty) > 10^{-10}$, with $F$ the
/// residuals of [`refine`] and $b$ the subproblem's data (the stages' gradients, defects and
/// constraint values, the ends' offsets and the terminal gradient). One pass over the steps
/// without a solve: it finds the digits a long tail's terminal pivot (a weakly controllable
/// system, whose constraint-to-go $S D^{-1} S^T$ cancels most of the cost-to-go) costs the
/// costates, which no other sign shows.
pub(crate) fn needs_refinement<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    (stages, terminal): (&[StageModel<N, X>], &Terminal<X>),
    rho: f64,
    r0: &SVector<f64, X>,
    end: (&SVector<f64, X>, &SVector<f64, X>),
    d: &Direction<N, X>,
) -> bool {
    if stages.is_empty() {
        return false;
    }
    let (mut residual, mut data, mut size) = (0.0_f64, 0.0_f64, 0.0_f64);
    // (at x_0 the fixed components' stationarity is the start condition's multiplier)
    let start_free = terminal.start_fixed.map(|f| 1.0 - f);
    for (i, stage) in stages.iter().enumerate() {
        let mut r = stage_residual(dynamics, stage, rho, d, i);
        if i == 0 {
            r.lx.component_mul_assign(&start_free);
        }
        residual = residual
            .max(r.lx.amax())
            .max(r.lu.amax())
            .max(r.defect.amax())
            .max(r.constraint.amax());
        data = data
            .max(stage.gx.amax())
            .max(stage.gu.amax())
            .max(stage.defect.amax())
            .max(stage.value.amax());
        size = size
            .max(d.dx[i].amax())
            .max(d.du[i].amax())
            .max(d.costate[i].amax())
            .max(d.multipliers[i].amax());
    }
    for r in end_residuals(terminal, rho, r0, end, d) {
        residual = residual.max(r.amax());
    }
    data = data.max(r0.amax()).max(end.0.amax()).max(end.1.amax());
    size = size.max(d.dx[stages.len()].amax());
    residual > RESIDUAL_RATIO_MAX * (size.min(1e6 * data) + data)
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
    end: (&SVector<f64, X>, &SVector<f64, X>),
    (d, pool): (&mut Direction<N, X>, &mut impl Vectors<N, X>),
) {
    let residual = |i: usize| stage_residual(dynamics, &stages[i], rho, d, i);
    let [start, end, stationarity] = end_residuals(terminal, rho, r0, end, d);
    let ends = (&end, &stationarity);
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
