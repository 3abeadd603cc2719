//! The primal-dual logarithmic barrier of the inequalities $g_j(x_{\theta,i}, u_i) \ge 0$, with
//! slacks.
//!
//! Each inequality becomes $g - s = 0$, $s > 0$, and for a barrier parameter $\mu$ (per unit
//! time) the optimizer minimises $J - h \mu \sum \ln s$ (as IPOPT), so the first guess need not
//! satisfy the inequalities. With multipliers $z \approx \mu / s$ and the residual
//! $r = g - s$, eliminating $\delta s = \nabla g^T \delta y + r$ and $\delta z$ from the
//! primal-dual Newton system leaves, per step, the gradient
//! $-h \nabla g\thinspace(\mu/s - (z/s)\thinspace r)$ and the Hessian $h (z/s) \nabla g \nabla g^T - h z \nabla^2 g$
//! added to the model of $h L$; then $\delta z = (\mu - z s - z\thinspace\delta s)/s$. The slacks
//! take the primal step length (at most the fraction to the boundary $\tau = \max(0.99, 1 - \mu)$
//! of the way to 0), the multipliers their own, clipped to $[\mu / (10^{10} s), 10^{10} \mu / s]$.
//! When the barrier problem is solved to $10 \mu$, $\mu \leftarrow \max(\mu_{\min},
//! \min(\mu / 5, \mu^{1.5}))$.

use super::constraints::Linearized;
use super::riccati::{Direction, StageModel};

/// Barrier parameter, slacks and multipliers, `count` per step, step-major.
pub(super) struct Barrier {
    pub mu: f64,
    pub s: Vec<f64>,
    pub z: Vec<f64>,
    pub count: usize,
}

impl Barrier {
    /// Slacks $s = \max(g, 0.1 \max(1, |g|))$ and $z = \mu / s$ at the first iterate.
    pub fn new(mu: f64, count: usize, values: &[f64]) -> Self {
        let s: Vec<f64> = values
            .iter()
            .map(|g| g.max(0.1 * g.abs().max(1.0)))
            .collect();
        Self {
            mu,
            z: s.iter().map(|s| mu / s).collect(),
            s,
            count,
        }
    }

    /// The fraction-to-the-boundary parameter $\tau$.
    pub fn tau(&self) -> f64 {
        (1.0 - self.mu).max(0.99)
    }

    /// Adds the barrier's gradient and primal-dual Hessian (without the constraints' own
    /// curvature) of step `i` to its model.
    pub fn add_to_stage<const N: usize, const X: usize>(
        &self,
        stage: &mut StageModel<N, X>,
        i: usize,
        lin: &[Linearized<N, X>],
        h: f64,
    ) {
        for (j, c) in lin.iter().enumerate() {
            let k = i * self.count + j;
            let (s, z) = (self.s[k], self.z[k]);
            let pull = h * (self.mu / s - z / s * (c.value - s));
            stage.gx -= c.gx * pull;
            stage.gu -= c.gu * pull;
            let weight = h * z / s;
            stage.hxx += c.gx * c.gx.transpose() * weight;
            stage.hux += c.gu * c.gx.transpose() * weight;
            stage.huu += c.gu * c.gu.transpose() * weight;
        }
    }

    /// Subtracts $h z \nabla g$ of every inequality from the cost gradients: the gradient of
    /// the Lagrangian $h L - h z^T g$ per step.
    pub fn lagrangian_gradients<const N: usize, const X: usize>(
        &self,
        gradients: &mut [(nalgebra::SVector<f64, X>, nalgebra::SVector<f64, N>)],
        lin: &[Linearized<N, X>],
        h: f64,
    ) {
        let count = self.count.max(1);
        for (k, c) in lin.iter().enumerate() {
            let (gx, gu) = &mut gradients[k / count];
            *gx -= c.gx * (h * self.z[k]);
            *gu -= c.gu * (h * self.z[k]);
        }
    }

    /// The slack steps $\delta s = \nabla g^T \delta y + r$ along `direction`.
    pub fn slack_steps<const N: usize, const X: usize>(
        &self,
        lin: &[Linearized<N, X>],
        direction: &Direction<N, X>,
        theta: f64,
    ) -> Vec<f64> {
        let count = self.count.max(1);
        lin.iter()
            .enumerate()
            .map(|(k, c)| {
                let i = k / count;
                let dx = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
                c.gx.dot(&dx) + c.gu.dot(&direction.du[i]) + c.value - self.s[k]
            })
            .collect()
    }

    /// The largest step length in $(0, 1]$ that keeps every slack above $(1 - \tau)$ times
    /// its value.
    pub fn max_step(&self, ds: &[f64]) -> f64 {
        let tau = self.tau();
        self.s
            .iter()
            .zip(ds)
            .filter(|(_, d)| **d < 0.0)
            .fold(1.0_f64, |a, (s, d)| a.min(-tau * s / d))
    }

    /// $-h \mu \sum \ln(s + \alpha \delta s)$ and $\sum |g - s - \alpha \delta s|$ at a trial
    /// point where the constraints take `values`.
    pub fn trial_terms(&self, values: &[f64], ds: &[f64], alpha: f64, h: f64) -> (f64, f64) {
        let mut log = 0.0;
        let mut violation = 0.0;
        for ((s, d), g) in self.s.iter().zip(ds).zip(values) {
            let next = s + alpha * d;
            log += next.ln();
            violation += (g - next).abs();
        }
        (-h * self.mu * log, violation)
    }

    /// The barrier term and $\sum |g - s|$ at the current iterate.
    pub fn current_terms<const N: usize, const X: usize>(
        &self,
        lin: &[Linearized<N, X>],
        h: f64,
    ) -> (f64, f64) {
        let log: f64 = self.s.iter().map(|s| s.ln()).sum();
        let violation = lin
            .iter()
            .zip(&self.s)
            .map(|(c, s)| (c.value - s).abs())
            .sum();
        (-h * self.mu * log, violation)
    }

    /// The derivative of $-h \mu \sum \ln s$ along the slack steps.
    pub fn slope(&self, ds: &[f64], h: f64) -> f64 {
        -h * self.mu * self.s.iter().zip(ds).map(|(s, d)| d / s).sum::<f64>()
    }

    /// $\max z s$ and $\max |z s - \mu|$.
    pub fn complementarity(&self) -> (f64, f64) {
        self.z
            .iter()
            .zip(&self.s)
            .fold((0.0_f64, 0.0_f64), |(m, e), (z, s)| {
                (m.max(z * s), e.max((z * s - self.mu).abs()))
            })
    }

    /// $\max |g - s|$.
    pub fn residual<const N: usize, const X: usize>(&self, lin: &[Linearized<N, X>]) -> f64 {
        lin.iter()
            .zip(&self.s)
            .fold(0.0, |m, (c, s)| m.max((c.value - s).abs()))
    }

    /// Takes the step: slacks by `alpha` along `ds`, multipliers by their own length.
    pub fn update(&mut self, ds: &[f64], alpha: f64) {
        let tau = self.tau();
        let dz: Vec<f64> = self
            .z
            .iter()
            .zip(&self.s)
            .zip(ds)
            .map(|((z, s), d)| (self.mu - z * s - z * d) / s)
            .collect();
        let alpha_z = self
            .z
            .iter()
            .zip(&dz)
            .filter(|(_, d)| **d < 0.0)
            .fold(1.0_f64, |a, (z, d)| a.min(-tau * z / d));
        for (((z, s), d), dzk) in self.z.iter_mut().zip(self.s.iter_mut()).zip(ds).zip(&dz) {
            *s += alpha * d;
            *z = (*z + alpha_z * dzk).clamp(self.mu / (1e10 * *s), 1e10 * self.mu / *s);
        }
    }

    /// Lowers $\mu$ towards `floor` (IPOPT's monotone rule).
    pub fn decrease(&mut self, floor: f64) {
        self.mu = (self.mu / 5.0).min(self.mu.powf(1.5)).max(floor);
    }
}
