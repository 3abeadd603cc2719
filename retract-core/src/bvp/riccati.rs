//! The KKT solve of one SQP iteration: a Riccati recursion over the stages with the terminal
//! constraint as a parameter, and the inertia of the reduced Hessian.
//!
//! The quadratic subproblem is, with stage variables $(\delta x_i, \delta u_i)$,
//!
//! $$\min \sum_i \tfrac12 \delta y_i^T H_i \delta y_i + g_i^T \delta y_i, \qquad
//!   \delta y_i = (E\,\delta x_i + \theta \bar B\,\delta u_i + \theta c_i,\ \delta u_i),$$
//! $$\delta x_{i+1} = \bar A\,\delta x_i + \bar B\,\delta u_i + c_i, \quad
//!   \delta x_0 = r_0, \quad \delta x_N = r_N,$$
//!
//! where $\delta y_i$ is the change of the stage's evaluation point $(x_{\theta,i}, u_i)$,
//! $E = (1-\theta) I + \theta \bar A$, $H_i$ and $g_i$ the Hessian and gradient of
//! $h\,L(x_{\theta,i}, u_i)$ and $c_i$ the dynamics defect. The terminal constraint enters
//! through its multiplier $\nu$: the cost-to-go is
//! $V_i(\delta x) = \tfrac12 \delta x^T P_i \delta x + \delta x^T (s_i + S_i \nu)$ with
//! $P_N = 0$, $s_N = 0$, $S_N = I$, and a forward sweep of $\partial \delta x_i/\partial \nu$
//! gives the $nk \times nk$ system $D_N \nu = r_N - e_N$.
//!
//! Inertia (Sylvester, Haynsworth): the Riccati recursion is a block $LDL^T$ factorisation
//! of the Hessian $W$ reduced by the dynamics alone, so $W$ has
//! $\sum_i \mathrm{neg}(Q_{uu,i})$ negative eigenvalues, and with the terminal constraint the
//! reduced Hessian has $\mathrm{neg}(W) + \mathrm{neg}(D_N) - nk$ of them ($D_N = -G W^{-1}
//! G^T$ for the terminal map $G$). It is positive definite exactly when that count is 0 and
//! nothing is singular.

use nalgebra::{DMatrix, SMatrix, SVector, SymmetricEigen};

/// The constant linear dynamics of the lifted scheme's $x$-equations for one $(h, \theta)$:
/// $x_{i+1} = \bar A x_i + \bar B u_i$ with $\bar A = W (I + h(1-\theta) A)$, $\bar B = W h B$,
/// $W = (I - h\theta A)^{-1} = \sum_m (h \theta A)^m$, $A$ the block shift
/// ($x_j' = x_{j+1}$) and $B$ the last block ($x_{k-1}' = u$).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Dynamics<const N: usize, const X: usize> {
    pub h: f64,
    pub theta: f64,
    /// $\bar A$.
    pub a: SMatrix<f64, X, X>,
    /// $\bar B$.
    pub b: SMatrix<f64, X, N>,
    /// $E = (1 - \theta) I + \theta \bar A$: $x_\theta$ as a function of $x_i$ (given $u$).
    pub e: SMatrix<f64, X, X>,
    /// $W = (I - h\theta A)^{-1}$.
    pub w: SMatrix<f64, X, X>,
}

impl<const N: usize, const X: usize> Dynamics<N, X> {
    pub fn new(h: f64, theta: f64) -> Self {
        let k = X / N;
        let shift = SMatrix::<f64, X, X>::from_fn(|r, c| if c == r + N { 1.0 } else { 0.0 });
        let last =
            SMatrix::<f64, X, N>::from_fn(|r, c| if r == (k - 1) * N + c { 1.0 } else { 0.0 });
        let mut w = SMatrix::<f64, X, X>::identity();
        let mut power = SMatrix::<f64, X, X>::identity();
        for _ in 1..k {
            power = power * shift * (h * theta);
            w += power;
        }
        let a = w * (SMatrix::<f64, X, X>::identity() + shift * (h * (1.0 - theta)));
        let b = w * last * h;
        let e = SMatrix::<f64, X, X>::identity() * (1.0 - theta) + a * theta;
        Self {
            h,
            theta,
            a,
            b,
            e,
            w,
        }
    }

    /// $x_{i+1} = \bar A x_i + \bar B u_i$.
    pub fn next(&self, x: &SVector<f64, X>, u: &SVector<f64, N>) -> SVector<f64, X> {
        self.a * x + self.b * u
    }
}

/// One stage's quadratic model: the Hessian blocks and gradient of $h\,L$ in
/// $y = (x_\theta, u)$, and the defect $c_i$.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StageModel<const N: usize, const X: usize> {
    pub hxx: SMatrix<f64, X, X>,
    /// $\partial^2 / \partial u \partial x_\theta$ ($N \times X$).
    pub hux: SMatrix<f64, N, X>,
    pub huu: SMatrix<f64, N, N>,
    pub gx: SVector<f64, X>,
    pub gu: SVector<f64, N>,
    pub defect: SVector<f64, X>,
}

/// What the backward pass keeps of a stage.
#[derive(Clone, Copy, Debug)]
struct StageFactor<const N: usize, const X: usize> {
    quu_inv: SMatrix<f64, N, N>,
    qux: SMatrix<f64, N, X>,
    /// $\delta u = K \delta x + k + K_\nu \nu$ ($k$ depends on the linear terms).
    gain: SMatrix<f64, N, X>,
    gain_nu: SMatrix<f64, N, X>,
    /// $P_{i+1}$ and $S_{i+1}$ of the next stage (for the costates).
    p_next: SMatrix<f64, X, X>,
    sens_next: SMatrix<f64, X, X>,
}

/// The factorised KKT system of one iteration.
pub(crate) struct Riccati<const N: usize, const X: usize> {
    stages: Vec<StageFactor<N, X>>,
    /// $D_N$ and its inverse.
    d_end_inv: SMatrix<f64, X, X>,
    /// Negative eigenvalues of the reduced Hessian.
    pub negative: usize,
    /// A pivot was singular (or non-finite).
    pub singular: bool,
}

/// The solution of the quadratic subproblem.
pub(crate) struct Direction<const N: usize, const X: usize> {
    /// $\delta x_0, \dots, \delta x_N$.
    pub dx: Vec<SVector<f64, X>>,
    /// $\delta u_0, \dots, \delta u_{N-1}$.
    pub du: Vec<SVector<f64, N>>,
    /// $\lambda_{i+1} = \nabla V_{i+1}(\delta x_{i+1})$ for $i < N$: the cost-to-go gradients.
    pub costate: Vec<SVector<f64, X>>,
}

/// Inverts a symmetric matrix and counts its negative eigenvalues; `None` if (nearly)
/// singular or not finite. Cholesky first, the eigendecomposition when that fails.
fn invert_counting<const D: usize>(m: SMatrix<f64, D, D>) -> Option<(SMatrix<f64, D, D>, usize)> {
    if let Some(chol) = m.cholesky() {
        let inv = chol.inverse();
        return inv.iter().all(|v| v.is_finite()).then_some((inv, 0));
    }
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    // the indefinite case is rare: a dynamic eigendecomposition
    let eig = SymmetricEigen::new(DMatrix::from_column_slice(D, D, m.as_slice()));
    let scale = eig.eigenvalues.amax().max(f64::MIN_POSITIVE);
    if eig.eigenvalues.iter().any(|l| l.abs() <= 1e-13 * scale) {
        return None;
    }
    let negative = eig.eigenvalues.iter().filter(|l| **l < 0.0).count();
    let inv_diag = DMatrix::from_diagonal(&eig.eigenvalues.map(|l| 1.0 / l));
    let inv = &eig.eigenvectors * inv_diag * eig.eigenvectors.transpose();
    Some((SMatrix::from_column_slice(inv.as_slice()), negative))
}

impl<const N: usize, const X: usize> Riccati<N, X> {
    /// The backward pass over `stages` with $\rho$ added to the diagonal of every $H_i$
    /// (inertia correction), then the terminal system.
    pub fn factor(dynamics: &Dynamics<N, X>, stages: &[StageModel<N, X>], rho: f64) -> Self {
        let (a, b, e, theta) = (&dynamics.a, &dynamics.b, &dynamics.e, dynamics.theta);
        let fu = b * theta;
        let mut p = SMatrix::<f64, X, X>::zeros();
        let mut sens = SMatrix::<f64, X, X>::identity();
        let mut factors = Vec::with_capacity(stages.len());
        let mut negative = 0;
        let mut singular = false;
        for stage in stages.iter().rev() {
            let hxx = stage.hxx + SMatrix::<f64, X, X>::identity() * rho;
            let huu = stage.huu + SMatrix::<f64, N, N>::identity() * rho;
            let hxx_e = hxx * e;
            let hxx_fu = hxx * fu;
            let pa = p * a;
            let pb = p * b;
            let qxx = e.transpose() * hxx_e + a.transpose() * pa;
            let qux = fu.transpose() * hxx_e + stage.hux * e + b.transpose() * pa;
            let cross = stage.hux * fu;
            let quu =
                fu.transpose() * hxx_fu + cross + cross.transpose() + huu + b.transpose() * pb;
            let quu = (quu + quu.transpose()) * 0.5;
            let (quu_inv, neg) = match invert_counting(quu) {
                Some(pair) => pair,
                None => {
                    singular = true;
                    (SMatrix::zeros(), 0)
                }
            };
            negative += neg;
            let gain = -(quu_inv * qux);
            let gain_nu = -(quu_inv * (b.transpose() * sens));
            factors.push(StageFactor {
                quu_inv,
                qux,
                gain,
                gain_nu,
                p_next: p,
                sens_next: sens,
            });
            let p_new = qxx + qux.transpose() * gain;
            p = (p_new + p_new.transpose()) * 0.5;
            sens = a.transpose() * sens + qux.transpose() * gain_nu;
        }
        factors.reverse();
        // D_N = d delta x_N / d nu: forward sweep of the closed-loop sensitivity
        let mut d = SMatrix::<f64, X, X>::zeros();
        for f in &factors {
            d = (a + b * f.gain) * d + b * f.gain_nu;
        }
        let d_sym = (d + d.transpose()) * 0.5;
        let (d_end_inv, neg_d) = invert_counting(d_sym).unwrap_or_else(|| {
            singular = true;
            (SMatrix::zeros(), 0)
        });
        Self {
            stages: factors,
            d_end_inv,
            negative: (negative + neg_d).saturating_sub(X),
            singular,
        }
    }

    /// True when the reduced Hessian is positive definite.
    pub fn positive_definite(&self) -> bool {
        !self.singular && self.negative == 0
    }

    /// Solves the subproblem for the model `stages` (the same Hessians as in
    /// [`Self::factor`]), with $\delta x_0 = $ `r0`, $\delta x_N = $ `r_end`.
    pub fn solve(
        &self,
        dynamics: &Dynamics<N, X>,
        stages: &[StageModel<N, X>],
        rho: f64,
        r0: &SVector<f64, X>,
        r_end: &SVector<f64, X>,
    ) -> Direction<N, X> {
        let fu = dynamics.b * dynamics.theta;
        let linear = |i: usize| {
            let stage = &stages[i];
            let offset = stage.defect * dynamics.theta;
            let gx = stage.gx + (stage.hxx + SMatrix::<f64, X, X>::identity() * rho) * offset;
            let gu = stage.gu + stage.hux * offset;
            let lx = dynamics.e.transpose() * gx;
            let lu = fu.transpose() * gx + gu;
            (lx, lu, stage.defect)
        };
        self.solve_linear(dynamics, &linear, r0, r_end)
    }

    /// The subproblem's solution for the stage linear terms $(l_x, l_u)$ in
    /// $(\delta x_i, \delta u_i)$ and the defects $c_i$ given by `linear(i)`.
    pub fn solve_linear(
        &self,
        dynamics: &Dynamics<N, X>,
        linear: &dyn Fn(usize) -> (SVector<f64, X>, SVector<f64, N>, SVector<f64, X>),
        r0: &SVector<f64, X>,
        r_end: &SVector<f64, X>,
    ) -> Direction<N, X> {
        let (a, b) = (&dynamics.a, &dynamics.b);
        let steps = self.stages.len();
        // backward: the feed-forward terms and s_{i+1} for these linear terms
        let mut feedforward = vec![SVector::<f64, N>::zeros(); steps];
        let mut s_next = vec![SVector::<f64, X>::zeros(); steps];
        let mut defects = vec![SVector::<f64, X>::zeros(); steps];
        let mut s = SVector::<f64, X>::zeros();
        for i in (0..steps).rev() {
            let f = &self.stages[i];
            let (lx, lu, defect) = linear(i);
            let pcs = f.p_next * defect + s;
            let qx = lx + a.transpose() * pcs;
            let qu = lu + b.transpose() * pcs;
            let k = -(f.quu_inv * qu);
            s_next[i] = s;
            feedforward[i] = k;
            defects[i] = defect;
            s = qx + f.qux.transpose() * k;
        }
        // forward without nu, then nu from the terminal condition
        let mut x = *r0;
        for (i, f) in self.stages.iter().enumerate() {
            let du = f.gain * x + feedforward[i];
            x = a * x + b * du + defects[i];
        }
        let nu = self.d_end_inv * (r_end - x);
        let mut dx = Vec::with_capacity(steps + 1);
        let mut du = Vec::with_capacity(steps);
        let mut costate = Vec::with_capacity(steps);
        let mut x = *r0;
        dx.push(x);
        for (i, f) in self.stages.iter().enumerate() {
            let u = f.gain * x + feedforward[i] + f.gain_nu * nu;
            x = a * x + b * u + defects[i];
            costate.push(f.p_next * x + s_next[i] + f.sens_next * nu);
            du.push(u);
            dx.push(x);
        }
        Direction { dx, du, costate }
    }
}
