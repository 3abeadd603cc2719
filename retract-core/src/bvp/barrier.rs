//! The primal-dual logarithmic barrier of the inequalities $g_j \ge 0$, with slacks: those at
//! the steps' evaluation points $(x_{\theta,i}, u_i)$ and those at the interior nodes $x_i$
//! ($0 < i < N$; the fixed ends are checked before iterating).
//!
//! Each inequality becomes $g - s = 0$, $s > 0$, and for a barrier parameter $\mu$ (per unit
//! time) the optimizer minimises $J - h \mu \sum \ln s$ (as IPOPT), so the first guess need not
//! satisfy the inequalities. With multipliers $z \approx \mu / s$ and the residual
//! $r = g - s$, eliminating $\delta s = \nabla g^T \delta y + r$ and $\delta z$ from the
//! primal-dual Newton system leaves, per constraint, the gradient
//! $-h \nabla g\thinspace(\mu/s - (z/s)\thinspace r)$ and the Hessian $h (z/s) \nabla g \nabla g^T - h y \nabla^2 g$
//! ($y$ the multipliers of $g - s = 0$, which follow $z$ with the primal step: IPOPT's
//! $y_d$)
//! added to the model of $h L$ of its step (in $(x_\theta, u)$) or of its node (in $x_i$);
//! then $\delta z = (\mu - z s - z\thinspace\delta s)/s$. The slacks
//! take the primal step length (at most the fraction to the boundary $\tau = \max(0.99, 1 - h\mu)$
//! of the way to 0, $\tau \le 1 - \sqrt{\varepsilon}$), the multipliers their own, clipped to $[\mu / (10^{10} s), 10^{10} \mu / s]$.
//! When the barrier problem is solved to $10 \mu$, $\mu \leftarrow \max(\mu_{\min},
//! \min(\mu / 5, \mu^{1.5}))$ in the transcribed problem's units (IPOPT's: its barrier term
//! is $h \mu \sum \ln s$, so its parameter is $h \mu$); with
//! [`BarrierUpdate::Adaptive`](super::BarrierUpdate::Adaptive), $\mu$ follows the LOQO rule
//! ([`Barrier::loqo`]) instead, safeguarded by that monotone update. The first slacks are
//! pushed into the interior as IPOPT's, the two sides of one interval sharing IPOPT's single slack
//! ([`super::constraints::slack_push`]); the inertia correction shifts the eliminated slacks'
//! Hessian too ([`Barrier::shift_slacks`]).

use nalgebra::{SMatrix, SVector};

use super::constraints::Linearized;
use super::kkt::model::StageModel;
use super::kkt::riccati::Direction;

/// The smallest slack of a warm start where the iterate has moved its inequality by more
/// than this ([`Barrier::warm_pair`]).
const WARM_SLACK_PUSH: f64 = 1e-3;

/// The largest ratio between a warm start's $z s$ and its $\mu$, either way, where the
/// iterate is the plan's point ([`Barrier::warm_pair`]).
const WARM_CENTRE: f64 = 1e2;

/// IPOPT's $\kappa_\Sigma$: the multipliers are kept in $[\mu / (\kappa_\Sigma s),
/// \kappa_\Sigma \mu / s]$.
const KAPPA_SIGMA: f64 = 1e10;

/// The largest multiplier $h z$ kept by [`Barrier::restart`] (IPOPT's
/// `bound_mult_reset_threshold`).
const MULTIPLIER_RESET: f64 = 1000.0;

/// The ratio $s / g$ below which a slack is reset to its inequality's value $g > 0$
/// ([`Barrier::reset_slacks`]).
const SLACK_RESET: f64 = 1e-3;

/// Barrier parameter, slacks and multipliers: `count` per step (step-major), then `nodes`
/// per interior node $x_1, \dots, x_{N-1}$ (node-major).
pub(super) struct Barrier {
    pub mu: f64,
    pub s: Vec<f64>,
    pub z: Vec<f64>,
    /// The multipliers $y$ of $g - s = 0$ (per unit time, as `z`), which weigh the
    /// constraints' curvature $-h y \nabla^2 g$ in the Hessian of the Lagrangian (IPOPT's
    /// $y_d$): they start at IPOPT's least-squares estimate and take the primal step towards
    /// the subproblem's $z + \delta z - w \rho \delta s$ ([`Self::update`]), while `z` takes
    /// its own (a violated constraint's $z$ grows as $\mu / s$ while its slack collapses; $y$
    /// stays with the step). Equal to $z$ at a solution.
    pub y: Vec<f64>,
    /// Inequalities per step.
    pub count: usize,
    /// Inequalities per interior node.
    pub nodes: usize,
    /// Steps $N$.
    pub steps: usize,
    /// The step length $h$ (the barrier parameter of the transcribed problem, IPOPT's, is
    /// $h \mu$).
    pub h: f64,
}

/// Where entry `k` of a [`Barrier`] lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Slot {
    /// At the evaluation point of step `i`.
    Step(usize),
    /// At node `i`.
    Node(usize),
}

impl Barrier {
    /// Slacks $s = \min(\max(g, p_{\text{low}}), p_{\text{high}})$ with the clamps `push` of
    /// [`super::constraints::slack_push`] (IPOPT's `bound_push`), and multipliers $z = 1 / h$
    /// at the first iterate (IPOPT's `bound_mult_init_val` 1 in the transcribed problem's
    /// units, where the multiplier is $h z$), for `count` inequalities per step and `nodes` per
    /// interior node over `steps` steps of length `h`.
    /// (`vectors`: three empty vectors for $s$, $z$, $y$.)
    pub fn new(
        (mu, h): (f64, f64),
        (count, nodes, steps): (usize, usize, usize),
        values: &[f64],
        push: impl Fn(usize) -> (f64, f64),
        [mut s, mut z, mut y]: [Vec<f64>; 3],
    ) -> Self {
        s.extend(values.iter().enumerate().map(|(k, g)| {
            let (low, high) = push(k);
            g.max(low).min(high)
        }));
        z.resize(s.len(), 1.0 / h);
        y.resize(s.len(), 1.0 / h);
        Self {
            mu,
            s,
            z,
            y,
            count,
            nodes,
            steps,
            h,
        }
    }

    /// A copy in the three empty `vectors` (for $s$, $z$, $y$, from the workspace).
    pub fn copy_into(&self, [mut s, mut z, mut y]: [Vec<f64>; 3]) -> Self {
        s.extend_from_slice(&self.s);
        z.extend_from_slice(&self.z);
        y.extend_from_slice(&self.y);
        Self { s, z, y, ..*self }
    }

    /// Its vectors $s$, $z$, $y$ (to keep for a later [`Self::new`] or [`Self::warm`]).
    pub fn into_vectors(self) -> [Vec<f64>; 3] {
        [self.s, self.z, self.y]
    }

    /// The barrier of a primal-dual warm start from `duals` (which fit the layout `(count,
    /// nodes, steps)`) at an iterate where the inequalities take `values`, pair by pair
    /// ([`Self::warm_pair`]), and the plan's barrier parameter $\mu$ = `duals.barrier`, at
    /// least `floor`, its multipliers and $\mu$ times the cost's `scale` $\sigma$ (a plan's are
    /// unscaled, the iteration's those of $\sigma J$): a plan's is at its floor (or, certified at the acceptable level, a few
    /// times above it), so the barrier is not restarted from $\mu_0$
    /// (which would first undo the plan's complementarity), and an unfinished plan's (a
    /// real-time iteration's) goes on from where it was.
    pub fn warm<const N: usize>(
        duals: &super::plan::duals::Duals<N>,
        (count, nodes, steps): (usize, usize, usize),
        (floor, scale, values): (f64, f64, &[f64]),
        [mut s, mut z, mut y]: [Vec<f64>; 3],
        h: f64,
    ) -> Self {
        let mu = (duals.barrier * scale).max(floor);
        let slacks = duals.step_slacks.iter().chain(&duals.node_slacks);
        let multipliers = duals.step_multipliers.iter().chain(&duals.node_multipliers);
        for ((sk, zk), g) in slacks.zip(multipliers).zip(values) {
            let (sk, zk) = Self::warm_pair((*sk, *zk * scale), *g, mu);
            s.push(sk);
            z.push(zk);
        }
        y.extend_from_slice(&z);
        Self {
            mu,
            s,
            y,
            z,
            count,
            nodes,
            steps,
            h,
        }
    }

    /// A plan's slack and multiplier $(s, z)$ for a warm start at an iterate where their
    /// inequality takes the value `g`, under the barrier parameter `mu`:
    /// - where the iterate is the plan's point for this inequality, $|g - s| \le p$ =
    ///   [`WARM_SLACK_PUSH`] (the plan of a nearby problem, or the plan itself), the pair as
    ///   it is, complementary at the plan's $\mu$, except that a slack below [`SLACK_RESET`]
    ///   times $g > 0$ is $s = g$ (as [`Self::reset_slacks`]) and a multiplier whose product
    ///   $z s$ is more than $c$ = [`WARM_CENTRE`] from $\mu$ either way is moved to that
    ///   bound, $z \in [\mu / (c s), c \mu / s]$ (IPOPT's recentring towards its
    ///   `warm_start_target_mu`). An active slack is not pushed away from 0: pushed to $p$,
    ///   its pair starts at $z p \gg \mu$, the first steps collapse the slack again, $z / s$
    ///   reaches $10^{12}$ and more, and the residuals stall at the rounding of the barrier
    ///   Hessian above a tight tolerance;
    /// - where the iterate has moved the inequality by more than $p$ (a plan stretched to
    ///   another horizon), the plan's slack says little of it: $(\max(s, p), z)$ (IPOPT's
    ///   `warm_start_bound_push`), so that a step that moves it is not capped at the
    ///   fraction to the boundary of a slack at the rounding of an active constraint.
    fn warm_pair((s, z): (f64, f64), g: f64, mu: f64) -> (f64, f64) {
        if (g - s).abs() > WARM_SLACK_PUSH {
            return (s.max(WARM_SLACK_PUSH), z);
        }
        let s = if s < SLACK_RESET * g { g } else { s };
        (s, z.clamp(mu / (WARM_CENTRE * s), WARM_CENTRE * mu / s))
    }

    /// The barrier of a plan as it ended, for its sensitivities: the plan's `duals` (which
    /// fit the layout `(count, nodes, steps)`), slacks and multipliers exactly as they are
    /// (unlike [`Self::warm`]), $y = z$ and the final barrier parameter.
    pub fn at_solution<const N: usize>(
        duals: &super::plan::duals::Duals<N>,
        (count, nodes, steps): (usize, usize, usize),
        [mut s, mut z, mut y]: [Vec<f64>; 3],
        h: f64,
    ) -> Self {
        s.extend(duals.step_slacks.iter().chain(&duals.node_slacks));
        z.extend(duals.step_multipliers.iter().chain(&duals.node_multipliers));
        y.extend_from_slice(&z);
        Self {
            mu: duals.barrier,
            s,
            z,
            y,
            count,
            nodes,
            steps,
            h,
        }
    }

    /// The number of entries at the steps' evaluation points (those at the nodes follow).
    pub fn at_steps(&self) -> usize {
        self.count * self.steps
    }

    /// The index of inequality `j` of interior node `i`.
    pub fn node_index(&self, i: usize, j: usize) -> usize {
        self.at_steps() + (i - 1) * self.nodes + j
    }

    /// Where entry `k` lives.
    pub fn slot(&self, k: usize) -> Slot {
        let at_steps = self.at_steps();
        if k < at_steps {
            Slot::Step(k / self.count)
        } else {
            Slot::Node(1 + (k - at_steps) / self.nodes)
        }
    }

    /// Adds the barrier's gradient and primal-dual Hessian (without the constraints' own
    /// curvature) of the inequalities `lin` of interior node `i` to the node terms of its
    /// stage ([`StageModel::node`]).
    pub fn add_to_node<const N: usize, const X: usize>(
        &self,
        stage: &mut StageModel<N, X>,
        i: usize,
        lin: &[Linearized<N, X>],
        h: f64,
    ) {
        let node = stage
            .node
            .get_or_insert_with(|| (SMatrix::zeros(), SVector::zeros()));
        let (hessian, gradient) = node;
        for (j, c) in lin.iter().enumerate() {
            let k = self.node_index(i, j);
            let (s, z) = (self.s[k], self.z[k]);
            *gradient -= c.gx * (h * (self.mu / s - z / s * (c.value - s)));
            *hessian += c.gx * c.gx.transpose() * (h * z / s);
        }
    }

    /// $-h z \nabla g$ summed over the inequalities of every node ($i = 0, \dots, N$; zero at
    /// the ends and where there are none), with the multipliers `z`: the node terms of the
    /// gradient of the Lagrangian (in `out`, emptied first).
    pub fn node_gradients<const N: usize, const X: usize>(
        &self,
        lin: &[Linearized<N, X>],
        z: &[f64],
        h: f64,
        out: &mut Vec<SVector<f64, X>>,
    ) {
        out.clear();
        out.resize(
            if self.nodes > 0 { self.steps + 1 } else { 0 },
            SVector::zeros(),
        );
        for (k, c) in lin.iter().enumerate().skip(self.at_steps()) {
            if let Slot::Node(i) = self.slot(k) {
                out[i] -= c.gx * (h * z[k]);
            }
        }
    }

    /// The barrier's share $\sum_k h (z_k / s_k) (\nabla g_k^T \delta y)^2$ of the model's
    /// curvature along a direction with slack steps `ds` ($\nabla g^T \delta y = \delta s -
    /// (g - s)$).
    pub fn curvature<const N: usize, const X: usize>(
        &self,
        lin: &[Linearized<N, X>],
        ds: &[f64],
        h: f64,
    ) -> f64 {
        lin.iter()
            .zip(ds)
            .zip(self.s.iter().zip(&self.z))
            .map(|((c, d), (s, z))| {
                let along = d - (c.value - s);
                h * z / s * along * along
            })
            .sum()
    }

    /// The multipliers after a primal-dual step with slack steps `ds`:
    /// $z + \alpha_z \delta z$, $\delta z = (\mu - z s - z\thinspace\delta s) / s$ and
    /// $\alpha_z$ the dual fraction-to-the-boundary step of [`Self::update`] (1 near a
    /// solution, where this is $(\mu - z\thinspace\delta s) / s$), in `out` (emptied first).
    pub fn predicted(&self, ds: &[f64], out: &mut Vec<f64>) {
        let alpha_z = self.dual_step_length(ds);
        out.clear();
        out.extend((0..self.z.len()).map(|k| self.z[k] + alpha_z * self.dual_step(k, ds)));
    }

    /// $\delta z_k = (\mu - z_k s_k - z_k\thinspace\delta s_k) / s_k$.
    fn dual_step(&self, k: usize, ds: &[f64]) -> f64 {
        let (z, s) = (self.z[k], self.s[k]);
        (self.mu - z * s - z * ds[k]) / s
    }

    /// The largest step in $(0, 1]$ along $\delta z$ ([`Self::dual_step`]) that keeps every
    /// multiplier above $(1 - \tau)$ times its value.
    pub fn dual_step_length(&self, ds: &[f64]) -> f64 {
        let tau = self.tau();
        (0..self.z.len())
            .map(|k| (self.z[k], self.dual_step(k, ds)))
            .filter(|(_, d)| *d < 0.0)
            .fold(1.0_f64, |a, (z, d)| a.min(-tau * z / d))
    }

    /// The fraction-to-the-boundary parameter $\tau = \min(\max(0.99, 1 - h\mu), 1 -
    /// \sqrt{\varepsilon})$: IPOPT's, with its barrier parameter $h \mu$, but a step keeps at
    /// least $\sqrt{\varepsilon} \approx 1.5 \cdot 10^{-8}$ of each slack. At the barrier's floor
    /// IPOPT's $1 - h\mu$ lets a slack fall by $10^{11}$ in one step, and the weight $h z / s$
    /// then leaves the digits of the condensed Riccati recursion: the failure hunt's
    /// minimum-time cart-poles (`examples/hunt.rs mintime`), whose free-time search compares
    /// warm-started solves at horizons 0.1 % apart, certified 123 of 135 without the cap and
    /// all 135 with it.
    pub fn tau(&self) -> f64 {
        (1.0 - self.h * self.mu)
            .max(0.99)
            .min(1.0 - f64::EPSILON.sqrt())
    }

    /// Adds the barrier's gradient and primal-dual Hessian (without the constraints' own
    /// curvature) of the inequalities `lin` of step `i` to its model.
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

    /// Adds the inertia correction `rho_h` of the eliminated slacks, $w_k \rho_h \nabla g_k
    /// \nabla g_k^T$ per inequality, to the stage and node Hessians and $w_k \rho_h (g_k -
    /// s_k) \nabla g_k$ to their gradients (IPOPT corrects the slacks' Hessian $\Sigma$ as
    /// every other variable's: eliminated, $\Sigma + \rho_h$ weighs $\nabla g \nabla g^T$ and
    /// the residual $g - s$), with the `weights` of [`Self::weights`]: $\frac12$ for
    /// each side of an interval, whose two sides share IPOPT's one slack.
    pub fn shift_slacks<const N: usize, const X: usize>(
        &self,
        stages: &mut [StageModel<N, X>],
        lin: &[Linearized<N, X>],
        rho_h: f64,
        weights: (&[f64], &[f64]),
    ) {
        if rho_h == 0.0 {
            return;
        }
        for ((k, c), w) in lin.iter().enumerate().zip(self.weights(weights)) {
            let weight = w * rho_h;
            self.add_outer(stages, k, c, weight);
            // (the slack's Hessian also weighs its residual g - s in the eliminated gradient)
            let pull = weight * (c.value - self.s[k]);
            match self.slot(k) {
                Slot::Step(i) => {
                    stages[i].gx += c.gx * pull;
                    stages[i].gu += c.gu * pull;
                }
                Slot::Node(i) => {
                    if let Some(node) = &mut stages[i].node {
                        node.1 += c.gx * pull;
                    }
                }
            }
        }
    }

    /// Adds `weight` $\nabla g \nabla g^T$ of inequality `k` (linearised as `c`) to the
    /// Hessian of its step's model, or of its node's terms.
    pub fn add_outer<const N: usize, const X: usize>(
        &self,
        stages: &mut [StageModel<N, X>],
        k: usize,
        c: &Linearized<N, X>,
        weight: f64,
    ) {
        match self.slot(k) {
            Slot::Step(i) => {
                let stage = &mut stages[i];
                stage.hxx += c.gx * c.gx.transpose() * weight;
                stage.hux += c.gu * c.gx.transpose() * weight;
                stage.huu += c.gu * c.gu.transpose() * weight;
            }
            Slot::Node(i) => {
                let node = stages[i]
                    .node
                    .get_or_insert_with(|| (SMatrix::zeros(), SVector::zeros()));
                node.0 += c.gx * c.gx.transpose() * weight;
            }
        }
    }

    /// Subtracts $h z \nabla g$ of every inequality at the steps, with the multipliers `z`,
    /// from the cost gradients: the gradient of the Lagrangian $h L - h z^T g$ per step.
    pub fn lagrangian_gradients<const N: usize, const X: usize>(
        &self,
        gradients: &mut [(nalgebra::SVector<f64, X>, nalgebra::SVector<f64, N>)],
        lin: &[Linearized<N, X>],
        z: &[f64],
        h: f64,
    ) {
        for (k, c) in lin.iter().enumerate().take(self.at_steps()) {
            let (gx, gu) = &mut gradients[k / self.count];
            *gx -= c.gx * (h * z[k]);
            *gu -= c.gu * (h * z[k]);
        }
    }

    /// The slack steps $\delta s = \nabla g^T \delta y + r$ along `direction`.
    pub fn slack_steps<const N: usize, const X: usize>(
        &self,
        lin: &[Linearized<N, X>],
        direction: &Direction<N, X>,
        theta: f64,
        mut out: Vec<f64>,
    ) -> Vec<f64> {
        out.clear();
        out.extend(lin.iter().enumerate().map(|(k, c)| {
            let change = match self.slot(k) {
                Slot::Step(i) => {
                    let dx = direction.dx[i] * (1.0 - theta) + direction.dx[i + 1] * theta;
                    c.gx.dot(&dx) + c.gu.dot(&direction.du[i])
                }
                Slot::Node(i) => c.gx.dot(&direction.dx[i]),
            };
            change + c.value - self.s[k]
        }));
        out
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

    /// The weight of every entry in the constraint violation, in order, from the `weights` of
    /// the inequalities at a step and at a node ([`super::constraints::violation_weights`]; 1
    /// where missing): the step pattern once per step, then the node pattern once per node.
    pub fn weights<'w>(
        &self,
        (steps, nodes): (&'w [f64], &'w [f64]),
    ) -> impl Iterator<Item = f64> + 'w {
        let pattern = |weights: &'w [f64], len: usize| {
            (0..len).map(move |j| weights.get(j).copied().unwrap_or(1.0))
        };
        let at_steps = pattern(steps, self.count).cycle().take(self.at_steps());
        let at_nodes = pattern(nodes, self.nodes).cycle();
        at_steps.chain(at_nodes).take(self.s.len())
    }

    /// $-h \mu \sum \ln(s + \alpha \delta s)$ and $\sum_k w_k |g_k - s_k - \alpha \delta s_k|$
    /// (the `weights` of [`Self::weights`]) at a trial point where the constraints take `values`.
    pub fn trial_terms(
        &self,
        values: &[f64],
        (ds, alpha): (&[f64], f64),
        h: f64,
        weights: (&[f64], &[f64]),
    ) -> (f64, f64) {
        let mut log = 0.0;
        let mut violation = 0.0;
        for (((s, d), g), w) in self.s.iter().zip(ds).zip(values).zip(self.weights(weights)) {
            let next = s + alpha * d;
            log += next.ln();
            violation += w * (g - next).abs();
        }
        (-h * self.mu * log, violation)
    }

    /// The barrier term and $\sum_k w_k |g_k - s_k|$ at the current iterate (the `weights` of
    /// [`Self::weights`]).
    pub fn current_terms<const N: usize, const X: usize>(
        &self,
        lin: &[Linearized<N, X>],
        h: f64,
        weights: (&[f64], &[f64]),
    ) -> (f64, f64) {
        let log: f64 = self.s.iter().map(|s| s.ln()).sum();
        let violation = (lin.iter().zip(&self.s).zip(self.weights(weights)))
            .map(|((c, s), w)| w * (c.value - s).abs())
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

    /// IPOPT's scales $(s_d, s_c)$ of the barrier problem's error, which keep large
    /// multipliers from holding $\mu$ up: $s_d = \max(1, \bar\lambda / 100)$ with
    /// $\bar\lambda$ the mean modulus of every multiplier in the transcribed problem's units
    /// ($h z$ and the others', whose $\ell_1$ norm and number are `others`), $s_c = \max(1,
    /// \overline{h z} / 100)$.
    pub fn error_scales(&self, z: &[f64], h: f64, (others, count): (f64, usize)) -> (f64, f64) {
        let sum: f64 = z.iter().map(|z| (h * z).abs()).sum();
        let s_d = (sum + others) / (z.len() + count).max(1) as f64;
        let s_c = sum / z.len().max(1) as f64;
        ((s_d / 100.0).max(1.0), (s_c / 100.0).max(1.0))
    }

    /// $\max |g - s|$.
    pub fn residual<const N: usize, const X: usize>(&self, lin: &[Linearized<N, X>]) -> f64 {
        lin.iter()
            .zip(&self.s)
            .fold(0.0, |m, (c, s)| m.max((c.value - s).abs()))
    }

    /// Takes the step: slacks by `alpha` along `ds`, the multipliers $z$ by `alpha_z`
    /// (their own length, [`Self::dual_step_length`], or `alpha` in a soft restoration step),
    /// the multipliers $y$ by `alpha` towards the step's $y^+ = z + \delta z - w_k \rho\,
    /// \delta s$ (the slack's stationarity with the inertia correction $\rho$ per unit time of
    /// the direction, shared as in [`Self::shift_slacks`] with the `weights`).
    pub fn update(
        &mut self,
        ds: &[f64],
        (alpha, alpha_z): (f64, f64),
        (rho, weights): (f64, (&[f64], &[f64])),
    ) {
        let mut shares = self.weights(weights);
        for k in 0..self.z.len() {
            let dzk = self.dual_step(k, ds);
            let share = shares.next().unwrap_or(1.0);
            let target = self.z[k] + dzk - share * rho * ds[k];
            self.y[k] += alpha * (target - self.y[k]);
            self.s[k] += alpha * ds[k];
            let s = self.s[k];
            self.z[k] = (self.z[k] + alpha_z * dzk)
                .clamp(self.mu / (KAPPA_SIGMA * s), KAPPA_SIGMA * self.mu / s);
        }
    }

    /// The slack reset after a step (as KNITRO's, Waltz, Morales, Nocedal and Orban, Math.
    /// Program. 107, 2006): where a slack has fallen below [`SLACK_RESET`] times its
    /// inequality's value $g_k > 0$ at the new iterate (`values`), $s_k \leftarrow g_k$ and
    /// $z_k$ is clipped to $[\mu / (\kappa_\Sigma s_k), \kappa_\Sigma \mu / s_k]$. That
    /// lowers both the violation $|g - s|$ and the barrier term $-h \mu \ln s$. Without it
    /// the slack of a degenerate inequality (its gradient vanishing where it is active, as
    /// $v^2 - \omega^2 \ge 0$ near rest) shrinks by the fraction to the boundary at every
    /// step while $g$ stays positive, and its weight $h (z/s) \nabla g \nabla g^T$ in the stage
    /// Hessians grows past $10^{16}$ times the rest: the Riccati pivots are then singular in
    /// floating point at every inertia correction below $10^{-13}$ of that weight. Returns
    /// the number of slacks reset.
    pub fn reset_slacks(&mut self, values: &[f64]) -> usize {
        let mut reset = 0;
        for (k, g) in values.iter().enumerate() {
            if self.s[k] < SLACK_RESET * g {
                let s = *g;
                self.s[k] = s;
                self.z[k] = self.z[k].clamp(self.mu / (KAPPA_SIGMA * s), KAPPA_SIGMA * self.mu / s);
                reset += 1;
            }
        }
        reset
    }

    /// Restarts at the slacks `s` (after the feasibility restoration phase), the multipliers
    /// reset under IPOPT's threshold (its `bound_mult_reset_threshold`): where the largest
    /// multiplier in the transcribed problem's units, $h z_k$, is above
    /// [`MULTIPLIER_RESET`], every $z_k = \mu / s_k$ (centred; IPOPT sets them to 1);
    /// otherwise each is kept within the safeguard of [`Self::update`], $z_k \in [\mu /
    /// (\kappa_\Sigma s_k), \kappa_\Sigma \mu / s_k]$ (IPOPT takes a step of them instead).
    /// The curvature multipliers follow, $y_k = z_k$.
    pub fn restart(&mut self, s: &[f64], h: f64) {
        for (own, s) in self.s.iter_mut().zip(s) {
            *own = *s;
        }
        let reset = self.z.iter().any(|z| h * z > MULTIPLIER_RESET);
        for ((z, y), s) in self.z.iter_mut().zip(&mut self.y).zip(s) {
            *z = if reset {
                self.mu / s
            } else {
                z.clamp(self.mu / (KAPPA_SIGMA * s), KAPPA_SIGMA * self.mu / s)
            };
            *y = *z;
        }
    }

    /// The average and the smallest $z_k s_k$ over the inequalities (per unit time, as
    /// $\mu$); `(0, 0)` without any.
    pub fn average_complementarity(&self) -> (f64, f64) {
        if self.s.is_empty() {
            return (0.0, 0.0);
        }
        let products = self.z.iter().zip(&self.s).map(|(z, s)| z * s);
        let (sum, min) = products.fold((0.0, f64::INFINITY), |(a, m), p| (a + p, m.min(p)));
        (sum / self.s.len() as f64, min)
    }

    /// The barrier parameter of the LOQO rule (Vanderbei and Shanno; IPOPT's `mu_oracle
    /// loqo`): $\sigma \bar c$ with the average complementarity $\bar c$ = mean $z_k s_k$,
    /// the centrality $\xi = \min_k z_k s_k / \bar c \in [0, 1]$ and $\sigma = 0.1
    /// \min(0.05 (1 - \xi) / \xi, 2)^3$: well centred ($\xi \to 1$) the parameter drops
    /// towards 0, off centre ($\xi \le 0.024$) it is $0.8 \bar c$. 0 without inequalities
    /// or with $\bar c$ not finite and positive.
    pub fn loqo(&self) -> f64 {
        let (average, min) = self.average_complementarity();
        if !(average.is_finite() && average > 0.0) {
            return 0.0;
        }
        let xi = (min / average).clamp(0.0, 1.0);
        // (xi = 0: the quotient is +infinity and the minimum 2)
        let sigma = 0.1 * (0.05 * (1.0 - xi) / xi).min(2.0).powi(3);
        sigma * average
    }

    /// Lowers $\mu$ towards `floor` by IPOPT's monotone rule on the transcribed problem's
    /// parameter $h \mu$: $\mu \leftarrow \max(\mu_{\min}, \min(\mu / 5, (h \mu)^{1.5} / h))$.
    pub fn decrease(&mut self, floor: f64, h: f64) {
        self.mu = (self.mu / 5.0).min((h * self.mu).powf(1.5) / h).max(floor);
    }
}

/// A barrier of one step ($h = 1$, $\mu = 0.1$) whose inequalities take the `values`
/// (slacks pushed at least 0.01 inside), for the tests here and in the SQP's.
#[cfg(test)]
pub(crate) fn one_step(values: &[f64]) -> Barrier {
    let empty = [Vec::new(), Vec::new(), Vec::new()];
    let push = |_| (0.01, f64::INFINITY);
    Barrier::new((0.1, 1.0), (values.len(), 0, 1), values, push, empty)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fraction to the boundary is IPOPT's $\max(0.99, 1 - \mu_{\text{IPOPT}})$ with its
    /// barrier parameter $h \mu$, not the per-unit-time $\mu$: at $h = 0.01$, $\mu = 0.283$
    /// (the 7-link chain's second value) it is $0.99717$, not 0.99; a step towards 0 keeps
    /// $1 - \tau$ of the slack, and at least $\sqrt{\varepsilon}$ of it at a tiny $\mu$.
    #[test]
    fn the_fraction_to_the_boundary_uses_ipopts_barrier_parameter() {
        let push = |_| (0.01, f64::INFINITY);
        let empty = [Vec::new(), Vec::new(), Vec::new()];
        let barrier = Barrier::new((0.283, 0.01), (1, 0, 1), &[1.0], push, empty);
        assert!((barrier.tau() - (1.0 - 0.00283)).abs() < 1e-15);
        assert!((barrier.max_step(&[-2.0]) - 0.5 * (1.0 - 0.00283)).abs() < 1e-15);
        let coarse = one_step(&[1.0]);
        assert_eq!(coarse.tau(), 0.99);
        let empty = [Vec::new(), Vec::new(), Vec::new()];
        let floor = Barrier::new((5e-10, 0.01), (1, 0, 1), &[1.0], push, empty);
        assert_eq!(floor.tau(), 1.0 - f64::EPSILON.sqrt());
    }

    /// The LOQO rule at hand-computed points: complementarities (1, 2, 3) have the average
    /// 2 and the centrality 1/2, so sigma = 0.1 (0.05)^3; (1e-3, 1, 1) are off centre
    /// (xi below 0.024), so sigma = 0.8; equal products give 0.
    #[test]
    fn the_loqo_rule_follows_the_centrality() {
        let mut barrier = one_step(&[1.0, 1.0, 1.0]);
        barrier.z = vec![1.0, 2.0, 3.0];
        let expected = 0.1 * 0.05f64.powi(3) * 2.0;
        assert!((barrier.loqo() - expected).abs() <= 1e-15 * expected);
        barrier.z = vec![1e-3, 1.0, 1.0];
        let average = (1e-3 + 2.0) / 3.0;
        assert!((barrier.loqo() - 0.8 * average).abs() <= 1e-14 * average);
        barrier.z = vec![0.5, 0.5, 0.5];
        assert_eq!(barrier.loqo(), 0.0);
        assert_eq!(barrier.average_complementarity(), (0.5, 0.5));
    }

    /// A half step ($\alpha = 1/2$): the slack moves by half its step, $z$ by its own length
    /// (here the whole Newton step), and the curvature multiplier $y$ by half the way from
    /// its value to the Newton value $z + \delta z$.
    #[test]
    fn the_curvature_multiplier_follows_the_primal_step() {
        let mut barrier = one_step(&[0.5]);
        barrier.y = vec![3.0];
        let (s, z) = (barrier.s[0], barrier.z[0]);
        let ds = -0.45;
        let dz = (barrier.mu - z * s - z * ds) / s;
        let alpha = 0.5;
        let alpha_z = barrier.dual_step_length(&[ds]);
        barrier.update(&[ds], (alpha, alpha_z), (0.0, (&[], &[])));
        let expected_y = 3.0 + alpha * (z + dz - 3.0);
        assert!((barrier.y[0] - expected_y).abs() <= 1e-14 * expected_y.abs());
        assert!((barrier.s[0] - (s + alpha * ds)).abs() <= 1e-15);
        // z grows here (dz > 0): the full step, clipped only by the safeguard
        assert!(dz > 0.0 && (barrier.z[0] - (z + dz)).abs() <= 1e-14 * (z + dz));
    }
}
