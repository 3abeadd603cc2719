//! Helpers and Lagrangians shared by the integration tests.
#![allow(dead_code)] // each test file uses a subset

use retract::diagnostics::rk4_step;
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, trajectory};

/// The state after `steps` steps of size `t_end / steps` of the theta-scheme.
pub fn theta_final<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    t_end: f64,
    steps: usize,
    theta: f64,
) -> SVector<f64, S>
where
    Sys: LiftedSystem<S, M>,
{
    let options = StepOptions::default().with_theta(theta);
    let run = trajectory(system, z0, t_end / steps as f64, steps, &options).expect("regular run");
    run.states[steps]
}

/// The state at `t_end` by classical RK4 with `steps` steps.
pub fn rk4_final<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    t_end: f64,
    steps: usize,
) -> SVector<f64, S>
where
    Sys: LiftedSystem<S, M>,
{
    let h = t_end / steps as f64;
    let mut z = *z0;
    for _ in 0..steps {
        z = rk4_step(system, &z, h).expect("regular RK4 step");
    }
    z
}

/// Observed orders log2(e(h) / e(h/2)) at `t_end` for the step counts `sweep` (each the
/// double of the previous), errors max-norm against `reference`.
pub fn observed_orders<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    reference: &SVector<f64, S>,
    t_end: f64,
    theta: f64,
    sweep: &[usize],
) -> Vec<f64>
where
    Sys: LiftedSystem<S, M>,
{
    let errors: Vec<f64> = sweep
        .iter()
        .map(|&steps| (theta_final(system, z0, t_end, steps, theta) - reference).amax())
        .collect();
    errors.windows(2).map(|e| (e[0] / e[1]).log2()).collect()
}

/// Asserts every observed order lies in `range`, with the sweep in the message.
pub fn assert_orders(orders: &[f64], range: std::ops::Range<f64>, what: &str) {
    for (i, p) in orders.iter().enumerate() {
        assert!(
            range.contains(p),
            "{what}: refinement {i} has order {p:.3} ({orders:?})"
        );
    }
}

pub mod models;

/// $\max_k |a_k - b_k|_\infty$ over two runs' states, paired in order.
pub fn largest_gap<const S: usize>(a: &[SVector<f64, S>], b: &[SVector<f64, S>]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).amax())
        .fold(0.0, f64::max)
}

/// Component `c` of the gradient blocks over the flat (x, u).
pub fn grad_entry<const N: usize, const K: usize>(g: &retract::Gradient<N, K>, c: usize) -> f64 {
    if c < N * K {
        g.x[c / N][c % N]
    } else {
        g.u[c - N * K]
    }
}

/// Entry (a, b) of the Hessian blocks over the flat (x, u); the (u, x) block is the transpose
/// of `xu`.
pub fn hess_entry<const N: usize, const K: usize>(
    h: &retract::Hessian<N, K>,
    a: usize,
    b: usize,
) -> f64 {
    let (ja, ia, jb, ib) = (a / N, a % N, b / N, b % N);
    match (ja < K, jb < K) {
        (true, true) => h.xx[ja][jb][(ia, ib)],
        (true, false) => h.xu[ja][(ia, ib)],
        (false, true) => h.xu[jb][(ib, ia)],
        (false, false) => h.uu[(ia, ib)],
    }
}

/// f'(0) of a scalar function of one variable, fourth-order central stencil (error
/// O(eps^4)).
pub fn fd(f: impl Fn(f64) -> f64, eps: f64) -> f64 {
    (-f(2.0 * eps) + 8.0 * f(eps) - 8.0 * f(-eps) + f(-2.0 * eps)) / (12.0 * eps)
}

/// Asserts |got - want| <= 1e-8 (1 + scale), naming `what` (a generated derivative against
/// its finite differences).
pub fn close(what: &str, got: f64, want: f64, scale: f64) {
    let tol = 1e-8 * (1.0 + scale);
    assert!(
        (got - want).abs() <= tol,
        "{what}: generated {got:e}, finite differences {want:e} (|diff| {:e} > {tol:e})",
        (got - want).abs()
    );
}

/// (x, u) with component `c` of the flat (x, u) moved by `t`.
pub fn shifted<const N: usize, const K: usize>(
    x: &[SVector<f64, N>; K],
    u: &SVector<f64, N>,
    c: usize,
    t: f64,
) -> ([SVector<f64, N>; K], SVector<f64, N>) {
    let (mut x, mut u) = (*x, *u);
    if c < N * K {
        x[c / N][c % N] += t;
    } else {
        u[c - N * K] += t;
    }
    (x, u)
}

/// Deterministic pseudo-random numbers in [-1, 1] (xorshift64), for tests at "random" points.
pub struct Noise(u64);

impl Noise {
    /// The sequence from `seed` (not 0).
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }

    /// The next number, uniform on a grid of step 1e-6 in [-1, 1].
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % 2_000_001) as f64 / 1e6 - 1.0
    }
}

/// Asserts that `plan` is certified as a strict local minimum at the default tolerance: no
/// negative direction, a positive smallest reduced-Hessian eigenvalue, stationarity and
/// feasibility at most $10^{-9}$.
pub fn assert_strict_minimum<const N: usize, const X: usize>(
    plan: &retract::bvp::Plan<N, X>,
    case: &str,
) {
    let c = &plan.certificate;
    assert!(
        c.negative_directions == 0 && c.min_reduced_hessian_eig > 0.0,
        "{case}: {c:?}"
    );
    assert!(
        c.stationarity <= 1e-9 && c.feasibility <= 1e-9,
        "{case}: {c:?}"
    );
}
