//! What a plan is certified by: the KKT residuals with the momenta recovered from the
//! multipliers.

use nalgebra::SVector;

use super::model::StageModel;
use super::riccati::Direction;
use crate::bvp::dynamics::Dynamics;
use crate::newton::max_abs;

/// The multipliers $\mu_i$ of the scheme's $x$-equations
/// $x_{i+1} - x_i - h A x_{\theta,i} - h B u_i = 0$, the momenta and the stationarity residual.
///
/// With $\lambda_{i+1}$ the cost-to-go gradient of the subproblem after step $i$ and $g_i$ the
/// gradient of the stage's Lagrangian $h L - h z_i^T g^{\ge} + y_i^T g^{=}$ at step $i$
/// (`gradients` holds that of $h L - h z_i^T g^{\ge}$; $y_i$ are the multipliers of the stage
/// equalities): $\mu_i = -W^T(\lambda_{i+1} + \theta g_{x,i})$. The gradient
/// of the Lagrangian of the transcription is, in $u_i$, $r_{u,i} = g_{u,i} - h B^T \mu_i$ and,
/// in $x_i$ ($0 < i < N$), $r_{x,i} = (1-\theta) d_i + \theta d_{i-1} - (\mu_i - \mu_{i-1})$
/// with $d_i = g_{x,i} - h A^T \mu_i$; the momenta are $p_i = \mu_i - (1-\theta) d_i$ and
/// $p_N = \mu_{N-1} + \theta d_{N-1}$ (so that $\mu_i = \theta p_i + (1-\theta) p_{i+1}$ and
/// $p_{i+1} - p_i = d_i$, the scheme's $p$-equations). At the components of $x_N$ that are
/// free (`fixed` 0) the residual is $p_N + \nabla\Phi(x_N)$, at the free ones of $x_0$
/// (`start_fixed` 0) it is $p_0$. The node terms of the Lagrangian (`node_gradients`, its
/// gradient $n_i$ in $x_i$ from the inequalities at the nodes; empty without them) add to
/// $r_{x,i}$: where such a constraint is active the momentum jumps at the node, $p_{i+1} - p_i
/// = d_i + n_{i+1}$, and $p_{i+1}$ above is the value after the jump.
/// Where `carried` holds multipliers $\mu_i$ of their own (IPOPT's carried multipliers),
/// they replace those formed from the costates. Returns the momenta (in `momenta`, emptied
/// first), the relative stationarity $\max(|r_u|_\infty, |r_x|_\infty) / (h \sigma)$ (the
/// terminal residual without the $h$) and its scale $\sigma = \max(1, |\nabla L|_\infty)$.
pub(crate) fn kkt_residuals<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stages: &[StageModel<N, X>],
    gradients: &[(SVector<f64, X>, SVector<f64, N>)],
    (direction, carried): (&Direction<N, X>, Option<&[SVector<f64, X>]>),
    node_gradients: &[SVector<f64, X>],
    (terminal_gradient, fixed, start_fixed): (&SVector<f64, X>, &SVector<f64, X>, &SVector<f64, X>),
    mut momenta: Vec<SVector<f64, X>>,
) -> (Vec<SVector<f64, X>>, f64, f64) {
    let (h, theta) = (dynamics.h, dynamics.theta);
    let wt = &dynamics.poly_w;
    // (A^T mu)_j = mu_{j-1}; B^T mu = the last block
    let shift_t = |mu: &SVector<f64, X>| {
        SVector::<f64, X>::from_fn(|r, _| if r >= N { mu[r - N] } else { 0.0 })
    };
    let steps = stages.len();
    momenta.clear();
    let mut worst: f64 = 0.0;
    // max |grad (h L)|_inf over the steps (divided by h once, at the end)
    let mut largest: f64 = 0.0;
    let (mut mu_prev, mut d_prev) = (SVector::<f64, X>::zeros(), SVector::<f64, X>::zeros());
    for i in 0..steps {
        let (stage, (gx, gu)) = (&stages[i], &gradients[i]);
        largest = largest.max(max_abs(gx)).max(max_abs(gu));
        // the gradient of the stage's Lagrangian h L - h z^T g_ineq + y^T g_eq
        let (gx, gu) = if stage.constraints > 0 {
            let y = &direction.multipliers[i];
            (gx + stage.cx.transpose() * y, gu + stage.cu.transpose() * y)
        } else {
            (*gx, *gu)
        };
        let mu = match carried {
            Some(mu) => mu[i],
            None => -wt.left_t(&(direction.costate[i] + gx * theta)),
        };
        let d = gx - shift_t(&mu) * h;
        for a in 0..N {
            worst = worst.max((gu[a] - h * mu[X - N + a]).abs());
        }
        if i > 0 {
            let mut r = d * (1.0 - theta) + d_prev * theta - (mu - mu_prev);
            if let Some(node) = node_gradients.get(i) {
                r += node;
            }
            worst = worst.max(max_abs(&r));
        }
        momenta.push(mu - d * (1.0 - theta));
        (mu_prev, d_prev) = (mu, d);
    }
    // at the free components of x_N: p_N + grad Phi = 0 (a residual of size O(1), not O(h))
    let mut terminal: f64 = 0.0;
    if steps > 0 {
        let p_end = mu_prev + d_prev * theta;
        for r in 0..X {
            if fixed[r] == 0.0 {
                terminal = terminal.max((p_end[r] + terminal_gradient[r]).abs());
            }
        }
        momenta.push(p_end);
    }
    // at the free components of x_0: p_0 = 0
    if let Some(p_start) = momenta.first() {
        for r in 0..X {
            if start_fixed[r] == 0.0 {
                terminal = terminal.max(p_start[r].abs());
            }
        }
    }
    let scale = (largest / h).max(1.0);
    (momenta, (worst / (h * scale)).max(terminal / scale), scale)
}

/// The subproblem's own multipliers $\mu_i$ of the $x$-equations at its solution
/// `direction` (IPOPT's Newton multipliers $y_+$, which it carries from iterate to iterate),
/// into `out` (emptied first): $\mu_i = -W^T(\lambda_{i+1} + \theta G_{x,i})$ as in
/// [`kkt_residuals`], with $G$ the gradient of the stage's quadratic model at the step,
/// $G_{x,i} = g_{x,i} + H_{xx,i}\thinspace \delta x_{\theta,i} + H_{ux,i}^T \delta u_i +
/// c_{x,i}^T y_i$ ($g$ the model's gradient, the barrier's terms included; $\delta x_{\theta,i}
/// = (1-\theta) \delta x_i + \theta \delta x_{i+1}$; $y_i$ the step's stage-equality
/// multipliers). A direction without a step (the least-squares estimate) takes $\delta = 0$,
/// and `gradients` in place of the models' $g_x$ where given.
pub(crate) fn step_multipliers<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stages: &[StageModel<N, X>],
    direction: &Direction<N, X>,
    gradients: Option<&[(SVector<f64, X>, SVector<f64, N>)]>,
    out: &mut Vec<SVector<f64, X>>,
) {
    let theta = dynamics.theta;
    out.clear();
    let stepped = direction.dx.len() == stages.len() + 1 && direction.du.len() == stages.len();
    for (i, stage) in stages.iter().enumerate() {
        let mut gx = gradients.map_or(stage.gx, |g| g[i].0);
        if stepped {
            let dxt = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
            gx += stage.hxx * dxt + stage.hux.transpose() * direction.du[i];
        }
        if stage.constraints > 0 {
            gx += stage.cx.transpose() * direction.multipliers[i];
        }
        out.push(-dynamics.poly_w.left_t(&(direction.costate[i] + gx * theta)));
    }
}
