//! The KKT solve of one SQP iteration: a Riccati recursion over the stages with the terminal
//! constraint as a parameter, and the inertia of the reduced Hessian.
//!
//! The quadratic subproblem is, with stage variables $(\delta x_i, \delta u_i)$,
//!
//! $$\min \sum_i \tfrac12 \delta y_i^T H_i \delta y_i + g_i^T \delta y_i, \qquad
//!   \delta y_i = (E\thinspace\delta x_i + \theta \bar B\thinspace\delta u_i + \theta c_i,\ \delta u_i),$$
//! $$\delta x_{i+1} = \bar A\thinspace\delta x_i + \bar B\thinspace\delta u_i + c_i, \quad
//!   \delta x_0 = r_0, \quad \delta x_N = r_N,$$
//!
//! where $\delta y_i$ is the change of the stage's evaluation point $(x_{\theta,i}, u_i)$,
//! $E = (1-\theta) I + \theta \bar A$, $H_i$ and $g_i$ the Hessian and gradient of
//! $h\thinspace L(x_{\theta,i}, u_i)$ and $c_i$ the dynamics defect. The terminal constraint enters
//! through its multiplier $\nu$: the cost-to-go is
//! $V_i(\delta x) = \tfrac12 \delta x^T P_i \delta x + \delta x^T (s_i + S_i \nu)$ with
//! $P_N = \nabla^2\Phi$, $s_N = \nabla\Phi$ (a terminal cost, else 0), $S_N = I$ (on the
//! components of $x_N$ the goal fixes), over the last steps only (the tail, from step $b$): with
//! $D = \partial \delta x_N / \partial \nu$ of the tail, $\nu = D^{-1}(r_N - S_b^T \delta
//! x_b - e)$ is eliminated at $x_b$ (constraint-to-go) and the steps before are plain Riccati
//! steps. $D$ is invertible from $k$ steps on (the controllability index of the chain of
//! integrators); the tail is the shortest of at least $k$ steps with $D$ well conditioned, the
//! whole horizon if none is.
//!
//! Inertia (Sylvester, Haynsworth): the Riccati recursion is a block $LDL^T$ factorisation
//! of the KKT matrix, eliminating $\delta u_{N-1}, \dots, \delta u_b$, then $\nu$ (pivot
//! $D$), then $\delta u_{b-1}, \dots, \delta u_0$; the pivots' negative eigenvalues add up
//! to those of the KKT matrix, which has $nk$ (one per row of the terminal constraint) more
//! than the reduced Hessian. So the reduced Hessian has
//! $\sum_i \mathrm{neg}(Q_{uu,i}) + \mathrm{neg}(D) - nk$ negative eigenvalues, and it is
//! positive definite exactly when that count is 0 and nothing is singular.

use std::time::Instant;

use nalgebra::{SMatrix, SVector};

use super::model::{StageLinear, StageModel, Terminal};
use super::pivots::invert_counting;
use crate::bvp::dynamics::Dynamics;
use crate::bvp::stack::Stack;

/// Where a factorisation, its solves and the eigenvalue of the certificate take their vectors
/// from and give them back: the solver's workspace, so that a warm re-solve allocates nothing.
/// One [`Stack`] per element type.
pub(crate) trait Vectors<const N: usize, const X: usize> {
    /// Jets: $\delta x$, costates.
    fn jets(&mut self) -> &mut Stack<SVector<f64, X>>;
    /// Top derivatives: $\delta u$, stage multipliers.
    fn tops(&mut self) -> &mut Stack<SVector<f64, N>>;
    /// The stages' factors.
    fn factors(&mut self) -> &mut Stack<StageFactor<N, X>>;
    /// The tail's factors.
    fn tails(&mut self) -> &mut Stack<TailFactor<N, X>>;
    /// The backward pass of a solve.
    fn backward(&mut self) -> &mut Stack<Backward<N, X>>;
    /// The Lanczos vectors of the certificate's eigenvalue (their own sizes).
    fn lanczos(&mut self) -> &mut Stack<f64>;
}

/// The stage constraints in the Riccati variables: with $\delta y = (E \delta x + \theta \bar B
/// \delta u + \theta c, \delta u)$ the linearisation is $C_x \delta x + C_u \delta u + c_0 = 0$,
/// $C_x = G_x E$, $C_u = G_x \theta \bar B + G_u$, $c_0 = g + \theta G_x c$. Returned: the
/// projector $\Pi = I - C_u^+ C_u$ onto the null space of $C_u$ and the pseudo-inverse
/// $C_u^+$ (Gram-Schmidt on the rows); `None` if $C_u$ is rank-deficient.
fn constraint_projection<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stage: &StageModel<N, X>,
) -> Option<(SMatrix<f64, N, N>, SMatrix<f64, N, N>, SMatrix<f64, N, X>)> {
    let m = stage.constraints;
    let cu = stage.cx * dynamics.b * dynamics.theta + stage.cu;
    let cx = stage.cx * dynamics.e;
    // rows of C_u = R Q with orthonormal rows q_j: R lower triangular (m x m)
    let mut q = SMatrix::<f64, N, N>::zeros();
    let mut r = SMatrix::<f64, N, N>::zeros();
    for j in 0..m {
        let mut row = cu.row(j).transpose();
        let norm0 = row.norm();
        for l in 0..j {
            let ql = q.row(l).transpose();
            let coefficient = ql.dot(&row);
            r[(j, l)] = coefficient;
            row -= ql * coefficient;
        }
        let norm = row.norm();
        if !(norm > 1e-10 * norm0.max(f64::MIN_POSITIVE) && norm.is_finite()) {
            return None;
        }
        r[(j, j)] = norm;
        q.set_row(j, &(row / norm).transpose());
    }
    // C_u^+ = Q^T R^{-1}: column j solves R^T-free forward substitution on unit vectors
    let mut r_inv = SMatrix::<f64, N, N>::zeros();
    for c in 0..m {
        for j in c..m {
            let mut v = if j == c { 1.0 } else { 0.0 };
            for l in c..j {
                v -= r[(j, l)] * r_inv[(l, c)];
            }
            r_inv[(j, c)] = v / r[(j, j)];
        }
    }
    let pinv = q.transpose() * r_inv;
    let projector = SMatrix::<f64, N, N>::identity() - q.transpose() * q;
    Some((projector, pinv, cx))
}

/// What the backward pass keeps of a stage.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StageFactor<const N: usize, const X: usize> {
    /// $\tilde Q^{-1} = (\Pi Q_{uu} \Pi + w (I - \Pi))^{-1}$ ($Q_{uu}^{-1}$ without constraints).
    quu_inv: SMatrix<f64, N, N>,
    quu: SMatrix<f64, N, N>,
    qux: SMatrix<f64, N, X>,
    /// The constraint projector $\Pi$ and $C_u^+$ (zero without constraints).
    projector: SMatrix<f64, N, N>,
    pinv: SMatrix<f64, N, N>,
    constrained: bool,
    /// $\delta u = K \delta x + k$ (plus $K_\nu \nu$ in the tail; $k$ depends on the linear
    /// terms).
    gain: SMatrix<f64, N, X>,
    /// $P_{i+1}$ of the next stage (for the costates).
    p_next: SMatrix<f64, X, X>,
}

impl<const N: usize, const X: usize> StageFactor<N, X> {
    /// The map $v \mapsto \delta u$ of the stage's minimisation over $\delta u$ for the
    /// linear term $v$, up to sign: $Q_{uu}^{-1}$, with constraints
    /// $\Pi \tilde Q^{-1} \Pi$.
    fn solve_map(&self) -> SMatrix<f64, N, N> {
        if self.constrained {
            self.projector * self.quu_inv * self.projector
        } else {
            self.quu_inv
        }
    }
}

/// What the backward pass keeps of a step of the tail, the steps where the terminal
/// multiplier $\nu$ is still a parameter.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TailFactor<const N: usize, const X: usize> {
    /// $K_\nu$ of $\delta u = K \delta x + k + K_\nu \nu$.
    gain_nu: SMatrix<f64, N, X>,
    /// $S_{i+1}$ of the next stage.
    sens_next: SMatrix<f64, X, X>,
}

/// The factorised KKT system of one iteration. The terminal multiplier $\nu$ is a parameter
/// of the cost-to-go over the last steps only (the tail, at least $k$ steps: enough for
/// $D$ to be invertible); at the tail's first state $x_b$ it is eliminated,
/// $\nu = D^{-1}(r_N - S_b^T \delta x_b - e)$, and the steps before see the plain
/// cost-to-go $P_b - S_b D^{-1} S_b^T$ (constraint-to-go, as Laine and Tomlin 2019).
pub(crate) struct Riccati<const N: usize, const X: usize> {
    /// The stages' factors, last step first.
    stages: Vec<StageFactor<N, X>>,
    /// The tail's factors, last step first.
    tail: Vec<TailFactor<N, X>>,
    /// $S_b$ at the tail's first state.
    sens_boundary: SMatrix<f64, X, X>,
    /// $D^{-1}$ of the tail.
    d_inv: SMatrix<f64, X, X>,
    /// The fixed components of $x_N$ ([`Terminal::fixed`]): the terminal constraint's rows.
    fixed: SVector<f64, X>,
    /// 1 at the free components of $x_0$.
    start_free: SVector<f64, X>,
    /// The inverse of $P_0$ on the free start components (the identity elsewhere).
    start_inverse: SMatrix<f64, X, X>,
    /// $P_0$.
    p_start: SMatrix<f64, X, X>,
    /// Whether the terminal multiplier was eliminated at $x_0$ (free start components and a
    /// tail over the whole horizon).
    eliminated_at_start: bool,
    /// Negative eigenvalues of the reduced Hessian.
    pub negative: usize,
    /// The terminal pivot was singular and was shifted by $-\delta_c$ (the goal's fixed
    /// components and the stage equalities are dependent: [`regularized_inverse`]); the
    /// direction then meets the goal only in the least-squares sense along the dependent
    /// components.
    pub regularized: bool,
    /// A pivot was singular (or non-finite), or a stage constraint rank-deficient in $u$.
    pub singular: bool,
    /// The deadline of [`Self::factor_until`] passed before the factorisation was complete
    /// (then it is also `singular`, and not to be used).
    pub interrupted: bool,
}

/// The steps between two looks at the clock in [`Riccati::factor_until`].
pub(in crate::bvp) const STEPS_PER_CLOCK_CHECK: usize = 1024;

/// The solution of the quadratic subproblem.
pub(crate) struct Direction<const N: usize, const X: usize> {
    /// $\delta x_0, \dots, \delta x_N$.
    pub dx: Vec<SVector<f64, X>>,
    /// $\delta u_0, \dots, \delta u_{N-1}$.
    pub du: Vec<SVector<f64, N>>,
    /// $\lambda_{i+1} = \nabla V_{i+1}(\delta x_{i+1})$ for $i < N$: the cost-to-go gradients.
    pub costate: Vec<SVector<f64, X>>,
    /// The multipliers $y_i$ of the stage constraints (first `constraints` entries).
    pub multipliers: Vec<SVector<f64, N>>,
}

impl<const N: usize, const X: usize> Direction<N, X> {
    /// Gives the direction's vectors back to `pool`.
    pub fn recycle(self, pool: &mut impl Vectors<N, X>) {
        pool.jets().give(self.dx);
        pool.jets().give(self.costate);
        pool.tops().give(self.du);
        pool.tops().give(self.multipliers);
    }
}

/// One stage of the backward pass from $P_{i+1}$ and $S_{i+1}$:
/// $Q_{xx} = E^T H_{xx} E + \bar A^T P \bar A$, $Q_{ux} = (\theta \bar B^T H_{xx} + H_{ux}) E +
/// \bar B^T P \bar A$, $Q_{uu}$ likewise, and the gains. Without constraints
/// $K = -Q_{uu}^{-1} Q_{ux}$ and $K_\nu = -Q_{uu}^{-1} \bar B^T S$; with them
/// $\delta u = M \delta x + m_0 + \Pi v$ ($M = -C_u^+ C_x$) and $v$ minimises over the null
/// space: $K = M - \Pi \tilde Q^{-1} \Pi (Q_{ux} + Q_{uu} M)$, $K_\nu = -\Pi \tilde Q^{-1}
/// \Pi \bar B^T S$ with $\tilde Q = \Pi Q_{uu} \Pi + w (I - \Pi)$, $w = \max(1, \max_a
/// |(Q_{uu})_{aa}|)$ ($K_\nu$ by the caller, for the
/// tail). Returns the factor, $Q_{xx}$ and the negative eigenvalues of $\tilde Q$ on the null
/// space (`None`: singular).
#[inline(always)]
fn stage_factor<const N: usize, const X: usize>(
    dynamics: &Dynamics<N, X>,
    stage: &StageModel<N, X>,
    rho: f64,
    p: &SMatrix<f64, X, X>,
) -> (StageFactor<N, X>, SMatrix<f64, X, X>, Option<usize>) {
    let (a, b, e) = (&dynamics.poly_a, &dynamics.poly_b, &dynamics.poly_e);
    let theta = dynamics.theta;
    let (hxx, mut huu) = (stage.hxx, stage.huu);
    for a in 0..N {
        huu[(a, a)] += rho;
    }
    // fu = theta B: the evaluation point's dependence on the control; B^T H and B^T P are
    // shared by Q_ux and Q_uu
    let bth = b.left_t(&hxx) * theta;
    let btp = b.left_t(p);
    let mut qxx = e.left_t(&e.right(&hxx)) + a.left_t(&a.right(p));
    if let Some(node) = &stage.node {
        qxx += node.0;
    }
    for r in 0..X {
        qxx[(r, r)] += rho;
    }
    let qux = e.right(&(bth + stage.hux)) + a.right(&btp);
    let cross = b.right(&stage.hux) * theta;
    let quu = b.right(&bth) * theta + cross + cross.transpose() + huu + b.right(&btp);
    let quu = (quu + quu.transpose()) * 0.5;
    let mut factor = StageFactor {
        quu_inv: SMatrix::zeros(),
        quu,
        qux,
        projector: SMatrix::identity(),
        pinv: SMatrix::zeros(),
        constrained: stage.constraints > 0,
        gain: SMatrix::zeros(),
        p_next: *p,
    };
    if !factor.constrained {
        let Some((quu_inv, neg)) = invert_counting(quu) else {
            return (factor, qxx, None);
        };
        factor.quu_inv = quu_inv;
        factor.gain = -(quu_inv * qux);
        return (factor, qxx, Some(neg));
    }
    let Some((projector, pinv, cx)) = constraint_projection(dynamics, stage) else {
        return (factor, qxx, None);
    };
    // (the complement's weight drops out of Pi Qtilde^-1 Pi: the size of Q_uu's diagonal keeps
    // Qtilde as well conditioned as Q_uu on the null space, with a large inertia correction)
    let weight = (0..N).fold(1.0_f64, |w, a| w.max(quu[(a, a)].abs()));
    let complement = (SMatrix::<f64, N, N>::identity() - projector) * weight;
    let reduced = projector * quu * projector + complement;
    let Some((quu_inv, neg)) = invert_counting((reduced + reduced.transpose()) * 0.5) else {
        return (factor, qxx, None);
    };
    let m = -(pinv * cx);
    let solve = projector * quu_inv * projector;
    factor.gain = m - solve * (qux + quu * m);
    factor.quu_inv = quu_inv;
    factor.projector = projector;
    factor.pinv = pinv;
    (factor, qxx, Some(neg))
}

/// $D^{-1}$ (by LU with partial pivoting: nalgebra's closed-form 4x4 inverse loses digits
/// here) and the negative eigenvalues of the symmetric part $(D + D^T)/2$ (for the inertia);
/// `None` if either is singular.
fn terminal_inverse<const X: usize>(d: &SMatrix<f64, X, X>) -> Option<(SMatrix<f64, X, X>, usize)> {
    let (_, negative) = invert_counting((d + d.transpose()) * 0.5)?;
    let inv = crate::linalg::solve(d, &SMatrix::identity())?;
    Some((inv, negative))
}

/// The relative size of the regularisation $\delta_c$ of a singular terminal pivot
/// ([`regularized_inverse`]).
const DELTA_C: f64 = 1e-8;

/// The inverse and negative eigenvalues of the whole horizon's terminal pivot, and whether it
/// was shifted: $\tilde D = D + I_{\rm free}$, or where
/// that is singular (fixed components of $x_N$ the stages cannot move independently: the
/// goal and the stage equalities are dependent), $\tilde D - \delta_c I_{\rm fixed}$ with
/// $\delta_c = $ [`DELTA_C`] $\max(\Vert D \Vert_{\max}, 1)$: IPOPT's $-\delta_c I$ block
/// on the constraints' multipliers. $D$ is negative definite on the fixed block where the
/// reduced Hessian is positive definite, so the shift keeps the inertia and makes the pivot
/// invertible; the terminal condition then holds in the least-squares sense along the
/// dependent directions (exactly where the data are consistent).
fn regularized_inverse<const X: usize>(
    d: &SMatrix<f64, X, X>,
    free: &SMatrix<f64, X, X>,
    fixed: &SVector<f64, X>,
) -> Option<(SMatrix<f64, X, X>, usize, bool)> {
    let pivot = d + free;
    if let Some((inverse, negative)) = terminal_inverse(&pivot) {
        return Some((inverse, negative, false));
    }
    let delta_c = DELTA_C * d.amax().max(1.0);
    let shifted = pivot - SMatrix::<f64, X, X>::from_diagonal(fixed) * delta_c;
    terminal_inverse(&shifted).map(|(inverse, negative)| (inverse, negative, true))
}

/// The largest condition number $\Vert D\Vert_{\max} \Vert D^{-1}\Vert_{\max}$ at which a tail's terminal
/// system is eliminated before the first step (a longer tail is better conditioned).
const TAIL_CONDITION: f64 = 1e6;

impl<const N: usize, const X: usize> Riccati<N, X> {
    /// The backward pass over `stages` with $\rho$ added to the diagonal of the Hessian in
    /// every node $\delta x_i$ and every top $\delta u_i$ (the inertia correction: IPOPT's
    /// $\delta_w I$ in the transcribed variables). Over the tail the cost-to-go carries $\nu$:
    /// $V_i(\delta x) = \tfrac12 \delta x^T P_i \delta x + \delta x^T (s_i + S_i \nu)$,
    /// $S_N = I$ (on the fixed components), $S_i = (\bar A + \bar B K_i)^T S_{i+1}$, and
    /// $D = \partial \delta x_N / \partial \nu = \sum_i (\bar B^T S_{i+1})^T K_{\nu,i}$. The tail
    /// ends at the first $b \le N - k$ where $D$ is well conditioned (else at 0); there
    /// $P_b \leftarrow P_b - S_b D^{-1} S_b^T$ (the maximum over $\nu$ of the parametric
    /// cost-to-go), and the steps before are plain Riccati steps.
    ///
    /// The end is `terminal`: $P_N$ its Hessian (plus $\rho$ on the diagonal), $S_N$ the
    /// identity on the fixed components only, so that $D$ has zero rows and columns at the
    /// free ones; there the pivot is $\tilde D = D + I_{\rm free}$, whose extra eigenvalues
    /// are positive, and the inertia subtracts one per fixed component.
    pub fn factor_with(
        dynamics: &Dynamics<N, X>,
        stages: &[StageModel<N, X>],
        rho: f64,
        terminal: &Terminal<X>,
        pool: &mut impl Vectors<N, X>,
    ) -> Self {
        Self::factor_until(dynamics, stages, rho, terminal, (None, false, pool))
    }

    /// [`Self::factor_with`], stopped (`interrupted`) once `deadline` has passed (the clock is
    /// read every [`STEPS_PER_CLOCK_CHECK`] steps), and, with `stop_indefinite`, as soon as the
    /// negative pivots outnumber the terminal constraint's rows: the reduced Hessian is then
    /// indefinite, and its factor (not [`Self::positive_definite`], its count of negative
    /// eigenvalues a lower bound) serves no solve (an inertia correction's trial).
    pub fn factor_until(
        dynamics: &Dynamics<N, X>,
        stages: &[StageModel<N, X>],
        rho: f64,
        terminal: &Terminal<X>,
        (deadline, stop_indefinite, pool): (Option<Instant>, bool, &mut impl Vectors<N, X>),
    ) -> Self {
        let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
        let steps = stages.len();
        let mut p = (terminal.hessian + terminal.hessian.transpose()) * 0.5;
        for r in 0..X {
            p[(r, r)] += rho;
        }
        let mut sens = SMatrix::<f64, X, X>::from_diagonal(&terminal.fixed);
        let free = SMatrix::<f64, X, X>::from_diagonal(&terminal.fixed.map(|f| 1.0 - f));
        let mut factors = pool.factors().take(steps);
        let mut tail = pool.tails().take(steps);
        let mut negative = 0;
        let mut singular = false;
        let mut d = SMatrix::<f64, X, X>::zeros();
        let mut eliminated: Option<SMatrix<f64, X, X>> = None;
        let mut interrupted = false;
        for (j, stage) in stages.iter().rev().enumerate() {
            if j % STEPS_PER_CLOCK_CHECK == STEPS_PER_CLOCK_CHECK - 1
                && deadline.is_some_and(|d| Instant::now() >= d)
            {
                interrupted = true;
                break;
            }
            let (factor, qxx, neg) = stage_factor(dynamics, stage, rho, &p);
            singular |= neg.is_none();
            negative += neg.unwrap_or(0);
            if stop_indefinite && negative > terminal.rows() {
                // (the count only grows: the reduced Hessian is indefinite whatever follows)
                break;
            }
            // V_i(dx) = Q(dx, K dx + k + K_nu nu): the general form (K need not minimise Q
            // over all du when the stage is constrained)
            let (k, qux) = (&factor.gain, &factor.qux);
            let p_new = if factor.constrained {
                let quu_k = factor.quu * k;
                qxx + k.transpose() * qux + qux.transpose() * k + k.transpose() * quu_k
            } else {
                qxx + qux.transpose() * k
            };
            p = (p_new + p_new.transpose()) * 0.5;
            if eliminated.is_none() {
                let bts = b.left_t(&sens);
                let gain_nu = -(factor.solve_map() * bts);
                // D accumulates Phi(N, i+1) B K_nu,i with Phi(N, i+1) = S_{i+1}^T: symmetric
                // (K_nu,i = -Qtilde^-1 B^T S_{i+1}) up to rounding
                d += bts.transpose() * gain_nu;
                tail.push(TailFactor {
                    gain_nu,
                    sens_next: sens,
                });
                // S_i = (A + B K)^T S_{i+1} (with constraints the term (Q_ux + Q_uu K)^T K_nu
                // vanishes: Pi (Q_ux + Q_uu K) = 0)
                sens = a.left_t(&sens) + k.transpose() * bts;
                if j + 1 >= X / N && j + 1 < steps {
                    let pivot = d + free;
                    let conditioned = terminal_inverse(&pivot)
                        .filter(|(inv, _)| pivot.amax() * inv.amax() <= TAIL_CONDITION);
                    if let Some((d_inv, neg_d)) = conditioned {
                        negative += neg_d;
                        let p_new = p - sens * d_inv * sens.transpose();
                        p = (p_new + p_new.transpose()) * 0.5;
                        eliminated = Some(d_inv);
                    }
                }
            }
            factors.push(factor);
        }
        let start_free = terminal.start_fixed.map(|f| 1.0 - f);
        let free_start = start_free.iter().any(|f| *f != 0.0);
        // with free start components the tail spanning the horizon is eliminated at x_0 too
        let eliminated_at_start = eliminated.is_none() && free_start;
        let mut regularized = false;
        let d_inv =
            eliminated.unwrap_or_else(|| match regularized_inverse(&d, &free, &terminal.fixed) {
                Some((d_inv, neg_d, shifted)) => {
                    regularized = shifted;
                    negative += neg_d;
                    if free_start {
                        let p_new = p - sens * d_inv * sens.transpose();
                        p = (p_new + p_new.transpose()) * 0.5;
                    }
                    d_inv
                }
                None => {
                    singular = true;
                    SMatrix::zeros()
                }
            });
        // the free start components minimise V_0: the pivot P_0 on them (I elsewhere)
        let start_inverse = if free_start {
            let fixed_part = SMatrix::<f64, X, X>::from_diagonal(&terminal.start_fixed);
            let masked = SMatrix::<f64, X, X>::from_diagonal(&start_free);
            let pivot = masked * p * masked + fixed_part;
            match invert_counting(pivot) {
                Some((inverse, neg)) => {
                    negative += neg;
                    inverse
                }
                None => {
                    singular = true;
                    SMatrix::zeros()
                }
            }
        } else {
            SMatrix::zeros()
        };
        Self {
            stages: factors,
            tail,
            sens_boundary: sens,
            d_inv,
            fixed: terminal.fixed,
            start_free,
            start_inverse,
            p_start: p,
            eliminated_at_start,
            negative: negative.saturating_sub(terminal.rows()),
            regularized,
            singular: singular || interrupted,
            interrupted,
        }
    }

    /// The number of steps $N$ factorised.
    pub fn steps(&self) -> usize {
        self.stages.len()
    }

    /// Gives the factorisation's vectors back to `pool`.
    pub fn recycle(self, pool: &mut impl Vectors<N, X>) {
        pool.factors().give(self.stages);
        pool.tails().give(self.tail);
    }

    /// The factor of step `i`.
    fn step_factor(&self, i: usize) -> &StageFactor<N, X> {
        &self.stages[self.stages.len() - 1 - i]
    }

    /// The first step of the tail, $b$.
    fn boundary(&self) -> usize {
        self.stages.len() - self.tail.len()
    }

    /// The tail factor of step `i` $\ge b$.
    fn tail_factor(&self, i: usize) -> &TailFactor<N, X> {
        &self.tail[self.stages.len() - 1 - i]
    }

    /// True when the reduced Hessian is positive definite.
    /// The bytes a factorisation holds per step (its stage factors).
    pub fn bytes_per_step() -> usize {
        core::mem::size_of::<StageFactor<N, X>>()
    }

    pub fn positive_definite(&self) -> bool {
        !self.singular && self.negative == 0
    }

    /// Solves the subproblem for the model `stages` (the same Hessians as in
    /// [`Self::factor_with`]), with $\delta x_0 = $ `r0`, $\delta x_N = $ `r_end` on the fixed
    /// components and the terminal cost's gradient `s_end` $= \nabla\Phi(x_N)$.
    pub fn solve(
        &self,
        dynamics: &Dynamics<N, X>,
        stages: &[StageModel<N, X>],
        r0: &SVector<f64, X>,
        (r_end, s_end): (&SVector<f64, X>, &SVector<f64, X>),
        pool: &mut impl Vectors<N, X>,
    ) -> Direction<N, X> {
        let prepared = self.prepare(dynamics, stages, (r_end, s_end), pool);
        let direction = self.forward(dynamics, &prepared, r0, r_end, pool);
        prepared.recycle(pool);
        direction
    }

    /// The part of [`Self::solve`] that does not depend on $\delta x_0$: the backward pass
    /// for the stage linear terms of `stages` (the feed-forward terms and the cost-to-go's
    /// linear term at $x_0$). [`Self::forward`] then gives the direction for any
    /// $\delta x_0$ (the feedback phase of a real-time iteration).
    pub fn prepare(
        &self,
        dynamics: &Dynamics<N, X>,
        stages: &[StageModel<N, X>],
        (r_end, s_end): (&SVector<f64, X>, &SVector<f64, X>),
        pool: &mut impl Vectors<N, X>,
    ) -> Prepared<N, X> {
        let theta = dynamics.theta;
        let linear = |i: usize| {
            let stage = &stages[i];
            let offset = stage.defect * theta;
            let gx = stage.gx + stage.hxx * offset;
            let gu = stage.gu + stage.hux * offset;
            let mut lx = dynamics.poly_e.left_t(&gx);
            if let Some(node) = &stage.node {
                lx += node.1;
            }
            StageLinear {
                lx,
                lu: dynamics.poly_b.left_t(&gx) * theta + gu,
                defect: stage.defect,
                constraint: stage.value + stage.cx * offset,
            }
        };
        self.prepare_linear(dynamics, &linear, (r_end, s_end), pool)
    }

    /// [`Self::prepare`] for the stage linear terms, defects and constraint offsets given by
    /// `linear(i)`.
    pub fn prepare_linear(
        &self,
        dynamics: &Dynamics<N, X>,
        linear: &impl Fn(usize) -> StageLinear<N, X>,
        ends: (&SVector<f64, X>, &SVector<f64, X>),
        pool: &mut impl Vectors<N, X>,
    ) -> Prepared<N, X> {
        let mut backward = pool.backward().take(self.stages.len());
        let s_start = self.backward(dynamics, linear, ends, &mut backward);
        Prepared { backward, s_start }
    }

    /// The subproblem's solution for the stage linear terms, defects and constraint offsets
    /// given by `linear(i)`: a backward pass for the feed-forward terms, then one forward pass
    /// for the direction ([`Self::forward`]).
    pub fn solve_linear(
        &self,
        dynamics: &Dynamics<N, X>,
        linear: &impl Fn(usize) -> StageLinear<N, X>,
        r0: &SVector<f64, X>,
        (r_end, s_end): (&SVector<f64, X>, &SVector<f64, X>),
        pool: &mut impl Vectors<N, X>,
    ) -> Direction<N, X> {
        let prepared = self.prepare_linear(dynamics, linear, (r_end, s_end), pool);
        let direction = self.forward(dynamics, &prepared, r0, r_end, pool);
        prepared.recycle(pool);
        direction
    }

    /// The forward pass of a solve from $\delta x_0 = $ `r0` (on the fixed start components)
    /// over the backward pass `prepared`: $\delta u_i = K_i \delta x_i + k_i$ (plus $K_\nu
    /// \nu$ in the tail), $\delta x_{i+1} = \bar A \delta x_i + \bar B \delta u_i + c_i$; at
    /// the tail's first state $\delta x_b$ it sets the terminal multiplier from $D \nu = r_N -
    /// \delta x_N(\nu = 0)$ (with one refinement when the terminal condition is missed by more
    /// than rounding; both by the cheap forward pass of [`Self::terminal`] over the tail).
    pub fn forward(
        &self,
        dynamics: &Dynamics<N, X>,
        prepared: &Prepared<N, X>,
        r0: &SVector<f64, X>,
        r_end: &SVector<f64, X>,
        pool: &mut impl Vectors<N, X>,
    ) -> Direction<N, X> {
        let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
        let steps = self.stages.len();
        let boundary = self.boundary();
        let (backward, s_start) = (&prepared.backward, prepared.s_start);
        let mut d = Direction {
            dx: pool.jets().take(steps + 1),
            du: pool.tops().take(steps),
            costate: pool.jets().take(steps),
            multipliers: pool.tops().take(steps),
        };
        // fixed start components from r0, free ones minimise V_0
        let mut x = r0.component_mul(&self.start_free.map(|f| 1.0 - f));
        if self.start_free.iter().any(|f| *f != 0.0) {
            let step = self.start_inverse * (s_start + self.p_start * x);
            x -= step.component_mul(&self.start_free);
        }
        let mut nu = SVector::<f64, X>::zeros();
        d.dx.push(x);
        for (i, (f, l)) in self
            .stages
            .iter()
            .rev()
            .zip(backward.iter().rev())
            .enumerate()
        {
            let tail = (i >= boundary).then(|| self.tail_factor(i));
            if i == boundary {
                let gap = r_end - self.terminal(dynamics, backward, &x, None);
                nu = self.d_inv * gap.component_mul(&self.fixed);
                let x_end = self.terminal(dynamics, backward, &x, Some(&nu));
                let miss = (r_end - x_end).component_mul(&self.fixed);
                if miss.amax() > 1e-12 * (1.0 + r_end.amax() + x_end.amax()) {
                    nu += self.d_inv * miss;
                }
            }
            let mut u = f.gain * x + l.feedforward;
            if let Some(t) = tail {
                u += t.gain_nu * nu;
            }
            if f.constrained {
                let mut dq = f.qux * x + f.quu * u + l.qu;
                if let Some(t) = tail {
                    dq += b.left_t(&(t.sens_next * nu));
                }
                d.multipliers.push(-(f.pinv.transpose() * dq));
            } else {
                d.multipliers.push(SVector::zeros());
            }
            x = a.left(&x) + b.left(&u) + l.defect;
            let mut costate = f.p_next * x + l.s_next;
            if let Some(t) = tail {
                costate += t.sens_next * nu;
            }
            d.costate.push(costate);
            d.du.push(u);
            d.dx.push(x);
        }
        d
    }

    /// The backward pass of a solve into `out`: per step (last step first) the feed-forward term, $q_u$,
    /// $s_{i+1}$ and the defect for the linear terms `linear(i)`. At the tail's first state
    /// (if not step 0) $\nu$ is eliminated: $s_b \leftarrow s_b + S_b D^{-1} (r_N - e)$ with
    /// $e = \delta x_N$ of the tail from $\delta x_b = 0$, $\nu = 0$.
    fn backward(
        &self,
        dynamics: &Dynamics<N, X>,
        linear: &impl Fn(usize) -> StageLinear<N, X>,
        (r_end, s_end): (&SVector<f64, X>, &SVector<f64, X>),
        out: &mut Vec<Backward<N, X>>,
    ) -> SVector<f64, X> {
        let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
        let steps = self.stages.len();
        let boundary = self.boundary();
        let mut s = *s_end;
        for i in (0..steps).rev() {
            let f = self.step_factor(i);
            let l = linear(i);
            let pcs = f.p_next * l.defect + s;
            let qx = l.lx + a.left_t(&pcs);
            let qu = l.lu + b.left_t(&pcs);
            let s_next = s;
            let k = if f.constrained {
                let m0 = -(f.pinv * l.constraint);
                let k = m0 - f.projector * (f.quu_inv * (f.projector * (qu + f.quu * m0)));
                s = qx + f.gain.transpose() * (qu + f.quu * k) + f.qux.transpose() * k;
                k
            } else {
                let k = -(f.quu_inv * qu);
                s = qx + f.qux.transpose() * k;
                k
            };
            out.push(Backward {
                feedforward: k,
                qu,
                s_next,
                defect: l.defect,
            });
            if i == boundary && (i > 0 || self.eliminated_at_start) {
                // the tail's entries are the ones pushed so far, last step first
                let x_end = self.tail_terminal(dynamics, out.iter().rev(), i);
                let gap = (r_end - x_end).component_mul(&self.fixed);
                s += self.sens_boundary * (self.d_inv * gap);
            }
        }
        s
    }

    /// $\delta x_N$ of the closed tail loop from $\delta x_b = 0$ with $\nu = 0$, for the
    /// backward pass entries `tail` of steps $b, \dots, N-1$.
    fn tail_terminal<'b>(
        &self,
        dynamics: &Dynamics<N, X>,
        tail: impl Iterator<Item = &'b Backward<N, X>>,
        boundary: usize,
    ) -> SVector<f64, X>
    where
        Backward<N, X>: 'b,
    {
        let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
        let mut x = SVector::<f64, X>::zeros();
        for (i, l) in (boundary..).zip(tail) {
            let du = self.step_factor(i).gain * x + l.feedforward;
            x = a.left(&x) + b.left(&du) + l.defect;
        }
        x
    }

    /// $\delta x_N$ of the closed loop over the tail from its first state $\delta x_b = $ `xb`
    /// with the terminal multiplier `nu` (none: 0), for the backward pass entries `backward`
    /// (last step first).
    fn terminal(
        &self,
        dynamics: &Dynamics<N, X>,
        backward: &[Backward<N, X>],
        xb: &SVector<f64, X>,
        nu: Option<&SVector<f64, X>>,
    ) -> SVector<f64, X> {
        let (a, b) = (&dynamics.poly_a, &dynamics.poly_b);
        let boundary = self.boundary();
        let mut x = *xb;
        for (i, l) in (boundary..).zip(backward[..backward.len() - boundary].iter().rev()) {
            let mut du = self.step_factor(i).gain * x + l.feedforward;
            if let Some(nu) = nu {
                du += self.tail_factor(i).gain_nu * nu;
            }
            x = a.left(&x) + b.left(&du) + l.defect;
        }
        x
    }
}

/// The backward pass of a solve ([`Riccati::prepare`]): per step, last step first, what the
/// forward pass needs, and the linear term $s_0$ of the cost-to-go at $x_0$.
pub(crate) struct Prepared<const N: usize, const X: usize> {
    backward: Vec<Backward<N, X>>,
    s_start: SVector<f64, X>,
}

impl<const N: usize, const X: usize> Prepared<N, X> {
    /// Gives the pass's vectors back to `pool`.
    pub fn recycle(self, pool: &mut impl Vectors<N, X>) {
        pool.backward().give(self.backward);
    }
}

/// What the backward pass of a solve keeps of a step.
pub(crate) struct Backward<const N: usize, const X: usize> {
    feedforward: SVector<f64, N>,
    qu: SVector<f64, N>,
    s_next: SVector<f64, X>,
    defect: SVector<f64, X>,
}

#[cfg(test)]
mod tests {
    use super::super::pivots::{invert_by_eigen, jacobi_eigen};
    use super::*;
    use crate::bvp::workspace::Pool;
    use nalgebra::{DMatrix, SymmetricEigen};

    /// The Jacobi eigendecomposition of an indefinite symmetric matrix rebuilds it, with
    /// orthonormal vectors, and the fallback inverse counts its negative eigenvalues.
    #[test]
    fn jacobi_rebuilds_an_indefinite_matrix_and_counts_its_negative_eigenvalues() {
        let mut seed = 11;
        let b = SMatrix::<f64, 5, 5>::from_fn(|_, _| noise(&mut seed));
        let m = b + b.transpose() - SMatrix::<f64, 5, 5>::identity() * 0.7;
        let (values, vectors) = jacobi_eigen(&m);
        let rebuilt = vectors * SMatrix::from_diagonal(&values) * vectors.transpose();
        assert!((rebuilt - m).amax() < 1e-13, "{}", (rebuilt - m).amax());
        let gram = vectors.transpose() * vectors - SMatrix::<f64, 5, 5>::identity();
        assert!(gram.amax() < 1e-14);
        let reference = SymmetricEigen::new(DMatrix::from_column_slice(5, 5, m.as_slice()));
        let negative = reference.eigenvalues.iter().filter(|l| **l < 0.0).count();
        let (inverse, counted) = invert_by_eigen(&m).expect("regular");
        assert!(negative > 0 && negative < 5 && counted == negative);
        assert!((inverse * m - SMatrix::<f64, 5, 5>::identity()).amax() < 1e-10);
    }

    /// A deterministic pseudo-random number in [-1, 1).
    fn noise(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// The Riccati solve equals a dense solve of the same equality-constrained quadratic
    /// program, with the terminal multiplier eliminated before the first step or not.
    /// The KKT matrix and right-hand side of the subproblem, dense: the variables
    /// (x_0..x_N, u_0..u_{N-1}), then the multipliers of x_0 = r0, of the dynamics and of
    /// x_N = r_end (a free component's row pins its multiplier to 0).
    fn dense_kkt(
        dynamics: &Dynamics<2, 4>,
        stages: &[StageModel<2, 4>],
        terminal: &Terminal<4>,
        (r0, r_end): (&SVector<f64, 4>, &SVector<f64, 4>),
        s_end: &SVector<f64, 4>,
    ) -> (DMatrix<f64>, nalgebra::DVector<f64>) {
        const N: usize = 2;
        const X: usize = 4;
        let steps = stages.len();
        let nv = (steps + 1) * X + steps * N;
        let nc = (steps + 2) * X;
        let xc = |i: usize| i * X;
        let uc = |i: usize| (steps + 1) * X + i * N;
        let mut kkt = DMatrix::<f64>::zeros(nv + nc, nv + nc);
        let mut rhs = nalgebra::DVector::<f64>::zeros(nv + nc);
        let theta = dynamics.theta;
        for (i, s) in stages.iter().enumerate() {
            let mut t = DMatrix::<f64>::zeros(6, nv);
            for r in 0..X {
                t[(r, xc(i) + r)] = 1.0 - theta;
                t[(r, xc(i + 1) + r)] = theta;
            }
            for a in 0..N {
                t[(4 + a, uc(i) + a)] = 1.0;
            }
            let mut h = DMatrix::<f64>::zeros(6, 6);
            h.view_mut((0, 0), (4, 4)).copy_from(&s.hxx);
            h.view_mut((4, 0), (2, 4)).copy_from(&s.hux);
            h.view_mut((0, 4), (4, 2)).copy_from(&s.hux.transpose());
            h.view_mut((4, 4), (2, 2)).copy_from(&s.huu);
            let g = nalgebra::DVector::from_iterator(6, s.gx.iter().chain(s.gu.iter()).copied());
            let block = t.transpose() * h * &t;
            let mut view = kkt.view_mut((0, 0), (nv, nv));
            view += block;
            let mut top = rhs.rows_mut(0, nv);
            top -= t.transpose() * g;
            // the node terms of x_i
            if let Some(node) = &s.node {
                let (hn, gn) = node;
                for r in 0..X {
                    for c in 0..X {
                        kkt[(xc(i) + r, xc(i) + c)] += hn[(r, c)];
                    }
                    rhs[xc(i) + r] -= gn[r];
                }
            }
            // x_{i+1} - A x_i - B u_i = c_i
            let row = nv + (i + 1) * X;
            for r in 0..X {
                kkt[(row + r, xc(i + 1) + r)] = 1.0;
                for c in 0..X {
                    kkt[(row + r, xc(i) + c)] = -dynamics.a[(r, c)];
                }
                for a in 0..N {
                    kkt[(row + r, uc(i) + a)] = -dynamics.b[(r, a)];
                }
                rhs[row + r] = s.defect[r];
            }
        }
        // the terminal cost on x_N; a free component's row pins its multiplier to 0
        for r in 0..X {
            for c in 0..X {
                kkt[(xc(steps) + r, xc(steps) + c)] += terminal.hessian[(r, c)];
            }
            rhs[xc(steps) + r] -= s_end[r];
        }
        for r in 0..X {
            if terminal.start_fixed[r] == 0.0 {
                kkt[(nv + r, nv + r)] = 1.0;
            } else {
                kkt[(nv + r, xc(0) + r)] = 1.0;
                rhs[nv + r] = r0[r];
            }
            let row = nv + (steps + 1) * X + r;
            if terminal.fixed[r] == 0.0 {
                kkt[(row, row)] = 1.0;
            } else {
                kkt[(row, xc(steps) + r)] = 1.0;
                rhs[row] = r_end[r];
            }
        }
        for r in nv..nv + nc {
            for c in 0..nv {
                kkt[(c, r)] = kkt[(r, c)];
            }
        }
        (kkt, rhs)
    }

    /// Iterative refinement leaves the Riccati solution of a subproblem with stage equality
    /// constraints, node terms, an inertia correction and a free end where it is (its
    /// residual is rounding), and takes a perturbed solution back to it; the residual check
    /// ([`needs_refinement`](crate::bvp::kkt::refine::needs_refinement)) passes the solution
    /// and the refined one and flags the perturbed one.
    #[test]
    fn refinement_keeps_a_constrained_solution() {
        const N: usize = 2;
        const X: usize = 4;
        let dynamics = Dynamics::<N, X>::new(0.3, 0.5);
        let mut seed = 11;
        let steps = 6;
        let stages: Vec<StageModel<N, X>> = (0..steps)
            .map(|i| {
                let m = SMatrix::<f64, 6, 6>::from_fn(|_, _| noise(&mut seed));
                let h = m * m.transpose() + SMatrix::<f64, 6, 6>::identity() * 0.5;
                let mut cx = SMatrix::<f64, N, X>::zeros();
                let mut cu = SMatrix::<f64, N, N>::zeros();
                let mut value = SVector::<f64, N>::zeros();
                let constraints = i % 2;
                if constraints == 1 {
                    cx.set_row(
                        0,
                        &SVector::<f64, X>::from_fn(|_, _| noise(&mut seed)).transpose(),
                    );
                    cu.set_row(
                        0,
                        &SVector::<f64, N>::from_fn(|_, _| noise(&mut seed)).transpose(),
                    );
                    value[0] = noise(&mut seed);
                }
                let node = (i > 0).then(|| {
                    let m = SMatrix::<f64, X, X>::from_fn(|_, _| noise(&mut seed));
                    (m * m.transpose(), SVector::from_fn(|_, _| noise(&mut seed)))
                });
                StageModel {
                    hxx: h.fixed_view::<4, 4>(0, 0).into_owned(),
                    hux: h.fixed_view::<2, 4>(4, 0).into_owned(),
                    huu: h.fixed_view::<2, 2>(4, 4).into_owned(),
                    gx: SVector::from_fn(|_, _| noise(&mut seed)),
                    gu: SVector::from_fn(|_, _| noise(&mut seed)),
                    defect: SVector::from_fn(|_, _| 0.1 * noise(&mut seed)),
                    constraints,
                    cx,
                    cu,
                    value,
                    node,
                }
            })
            .collect();
        let m = SMatrix::<f64, X, X>::from_fn(|_, _| noise(&mut seed));
        let terminal = Terminal {
            hessian: m * m.transpose(),
            fixed: SVector::from([1.0, 1.0, 0.0, 0.0]),
            start_fixed: SVector::repeat(1.0),
        };
        let r0 = SVector::<f64, X>::from_fn(|_, _| noise(&mut seed));
        let r_end = SVector::<f64, X>::from_fn(|_, _| noise(&mut seed));
        let s_end = SVector::<f64, X>::from_fn(|_, _| noise(&mut seed));
        let rho = 0.25;
        let riccati =
            Riccati::factor_with(&dynamics, &stages, rho, &terminal, &mut Pool::default());
        assert!(riccati.positive_definite());
        let solve = || {
            let pool = &mut Pool::default();
            riccati.solve(&dynamics, &stages, &r0, (&r_end, &s_end), pool)
        };
        let exact = solve();
        let model = (&stages[..], &terminal);
        let end = (&r_end, &s_end);
        let check = |d: &Direction<N, X>| {
            crate::bvp::kkt::refine::needs_refinement(&dynamics, model, rho, &r0, end, d)
        };
        for perturbation in [0.0, 0.1, 1e-7] {
            let mut d = solve();
            for v in d.dx.iter_mut().skip(1).chain(d.costate.iter_mut()) {
                *v += SVector::<f64, X>::from_fn(|_, _| perturbation * noise(&mut seed));
            }
            for v in d.du.iter_mut().chain(d.multipliers.iter_mut()) {
                *v += SVector::<f64, N>::from_fn(|_, _| perturbation * noise(&mut seed));
            }
            assert_eq!(check(&d), perturbation > 0.0, "perturbation {perturbation}");
            crate::bvp::kkt::refine::refine(
                &riccati,
                &dynamics,
                model,
                rho,
                &r0,
                (&r_end, &s_end),
                (&mut d, &mut Pool::default()),
            );
            assert!(!check(&d), "refined from {perturbation}");
            for (i, stage) in stages.iter().enumerate() {
                let off = (d.dx[i + 1] - exact.dx[i + 1])
                    .amax()
                    .max((d.du[i] - exact.du[i]).amax())
                    .max((d.costate[i] - exact.costate[i]).amax());
                assert!(off < 1e-9, "step {i}, perturbation {perturbation}: {off:e}");
                if stage.constraints > 0 {
                    let y = (d.multipliers[i] - exact.multipliers[i])[0];
                    assert!(y.abs() < 1e-9, "multiplier {i}: {y:e}");
                }
            }
        }
    }

    /// The x-equations' multipliers of the solution `d` ([`step_multipliers`]) against the
    /// dense KKT solution `sol` of [`dense_kkt`]: its rows are W times the scheme's, so its
    /// multipliers nu give mu = W^T nu.
    ///
    /// [`step_multipliers`]: crate::bvp::kkt::residuals::step_multipliers
    fn assert_step_multipliers(
        dynamics: &Dynamics<2, 4>,
        stages: &[StageModel<2, 4>],
        d: &Direction<2, 4>,
        sol: &nalgebra::DVector<f64>,
    ) {
        let mut mu = Vec::new();
        crate::bvp::kkt::residuals::step_multipliers(dynamics, stages, d, None, &mut mu);
        let nv = (stages.len() + 1) * 4 + stages.len() * 2;
        for (i, mu) in mu.iter().enumerate() {
            let nu = SVector::<f64, 4>::from_fn(|r, _| sol[nv + (i + 1) * 4 + r]);
            let expected = dynamics.w.transpose() * nu;
            let off = (mu - expected).amax();
            assert!(off < 1e-9 * (1.0 + expected.amax()), "mu[{i}]: {off:e}");
        }
    }

    #[test]
    fn riccati_equals_the_dense_kkt_solve() {
        const N: usize = 2;
        const X: usize = 4;
        // 2 steps: the tail is the whole horizon; 3 and 7: the terminal constraint is
        // eliminated after the tail of k = 2 steps. A shift of -1 makes stage Hessians
        // indefinite.
        for (steps, shift) in [
            (2, 0.5),
            (3, 0.5),
            (7, 0.5),
            (2, -1.0),
            (3, -1.0),
            (7, -1.0),
        ] {
            let dynamics = Dynamics::<N, X>::new(0.3, 0.5);
            let mut seed = 7;
            let stages: Vec<StageModel<N, X>> = (0..steps)
                .map(|i| {
                    let m = SMatrix::<f64, 6, 6>::from_fn(|_, _| noise(&mut seed));
                    let h = m * m.transpose() + SMatrix::<f64, 6, 6>::identity() * shift;
                    // node terms on the odd interior nodes (a node inequality's barrier)
                    let node = (i % 2 == 1).then(|| {
                        let m = SMatrix::<f64, X, X>::from_fn(|_, _| noise(&mut seed));
                        let g = SVector::<f64, X>::from_fn(|_, _| noise(&mut seed));
                        (m * m.transpose() * 0.5, g)
                    });
                    StageModel {
                        hxx: h.fixed_view::<4, 4>(0, 0).into_owned(),
                        hux: h.fixed_view::<2, 4>(4, 0).into_owned(),
                        huu: h.fixed_view::<2, 2>(4, 4).into_owned(),
                        gx: SVector::from_fn(|_, _| noise(&mut seed)),
                        gu: SVector::from_fn(|_, _| noise(&mut seed)),
                        defect: SVector::from_fn(|_, _| 0.1 * noise(&mut seed)),
                        constraints: 0,
                        cx: SMatrix::zeros(),
                        cu: SMatrix::zeros(),
                        value: SVector::zeros(),
                        node,
                    }
                })
                .collect();
            let r0 = SVector::<f64, X>::from_fn(|_, _| noise(&mut seed));
            let r_end = SVector::<f64, X>::from_fn(|_, _| noise(&mut seed));
            // the ends fixed; then q' free at the end with a terminal cost and q'_1 free at the
            // start; without and with an inertia correction rho, which the dense system has on
            // the diagonal of every node's Hessian (x_i), every top's (u_i) and the terminal's
            for (free_end, rho) in [(false, 0.0), (true, 0.0), (false, 0.7), (true, 0.7)] {
                let (terminal, s_end) = if free_end {
                    let m = SMatrix::<f64, X, X>::from_fn(|_, _| noise(&mut seed));
                    let terminal = Terminal {
                        hessian: m * m.transpose() + SMatrix::<f64, X, X>::identity() * shift,
                        fixed: SVector::from([1.0, 1.0, 0.0, 0.0]),
                        start_fixed: SVector::from([1.0, 0.0, 1.0, 1.0]),
                    };
                    (
                        terminal,
                        SVector::<f64, X>::from_fn(|_, _| noise(&mut seed)),
                    )
                } else {
                    (Terminal::fixed_end(), SVector::zeros())
                };
                let free = X - terminal.rows();
                let free_start = terminal.start_fixed.iter().filter(|f| **f == 0.0).count();
                let riccati =
                    Riccati::factor_with(&dynamics, &stages, rho, &terminal, &mut Pool::default());
                assert!(!riccati.singular);
                assert_eq!(riccati.boundary() > 0, steps > 2);
                let solve = || {
                    let pool = &mut Pool::default();
                    riccati.solve(&dynamics, &stages, &r0, (&r_end, &s_end), pool)
                };
                let d = solve();
                let shifted: Vec<StageModel<N, X>> = (stages.iter())
                    .map(|stage| {
                        let mut stage = stage.clone();
                        let node = stage
                            .node
                            .get_or_insert((SMatrix::zeros(), SVector::zeros()));
                        node.0 += SMatrix::<f64, X, X>::identity() * rho;
                        stage.huu += SMatrix::<f64, N, N>::identity() * rho;
                        stage
                    })
                    .collect();
                let mut dense_end = terminal;
                dense_end.hessian += SMatrix::<f64, X, X>::identity() * rho;
                let ends = (&r0, &r_end);
                let (kkt, rhs) = dense_kkt(&dynamics, &shifted, &dense_end, ends, &s_end);
                let nc = (steps + 2) * X;
                let xc = |i: usize| i * X;
                let uc = |i: usize| (steps + 1) * X + i * N;
                // the KKT matrix has nc + neg(Z^T H Z) negative eigenvalues
                let eigenvalues = SymmetricEigen::new(kkt.clone()).eigenvalues;
                let negative = eigenvalues.iter().filter(|l| **l < 0.0).count();
                assert_eq!(
                    riccati.negative,
                    negative - (nc - free - free_start),
                    "{steps} steps, shift {shift}, free end {free_end}, rho {rho}"
                );
                if shift > 0.0 {
                    assert!(riccati.positive_definite());
                }
                let sol = kkt.lu().solve(&rhs).unwrap();
                for i in 0..=steps {
                    for r in 0..X {
                        assert!((d.dx[i][r] - sol[xc(i) + r]).abs() < 1e-9, "dx[{i}][{r}]");
                    }
                }
                for i in 0..steps {
                    for a in 0..N {
                        assert!((d.du[i][a] - sol[uc(i) + a]).abs() < 1e-9, "du[{i}][{a}]");
                    }
                }
                assert_step_multipliers(&dynamics, &stages, &d, &sol);
                // one step of iterative refinement from a wrong solution gives the right one
                // (the system is linear), costates included
                let mut wrong = solve();
                for v in wrong.dx.iter_mut().chain(wrong.costate.iter_mut()) {
                    *v += SVector::<f64, X>::from_fn(|_, _| 0.1 * noise(&mut seed));
                }
                for v in &mut wrong.du {
                    *v += SVector::<f64, N>::from_fn(|_, _| 0.1 * noise(&mut seed));
                }
                let model = (&stages[..], &terminal);
                let end = (&r_end, &s_end);
                let pool = &mut Pool::default();
                crate::bvp::kkt::refine::refine(
                    &riccati,
                    &dynamics,
                    model,
                    rho,
                    &r0,
                    end,
                    (&mut wrong, pool),
                );
                for i in 0..=steps {
                    assert!((wrong.dx[i] - d.dx[i]).amax() < 1e-9, "refined dx[{i}]");
                }
                for i in 0..steps {
                    assert!((wrong.du[i] - d.du[i]).amax() < 1e-9, "refined du[{i}]");
                    let scale = 1.0 + d.costate[i].amax();
                    let off = (wrong.costate[i] - d.costate[i]).amax();
                    assert!(off < 1e-9 * scale, "refined costate[{i}]: {off:e}");
                }
            }
        }
    }
}
