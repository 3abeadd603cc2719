//! Damped Newton's method on statically sized systems.
//!
//! Solves $F(w) = 0$, $F: \mathbb{R}^M \to \mathbb{R}^M$, by
//! $w \leftarrow w + \alpha \Delta$ with $J(w) \Delta = -F(w)$, where the step length
//! $\alpha \in \lbrace 1, 1/2, 1/4, \dots\rbrace$ is the first that satisfies the Armijo
//! condition on $\phi = \tfrac12 |F|^2$:
//! $\phi(w + \alpha\Delta) \le (1 - 2 c \alpha)\thinspace \phi(w)$.
//! A trial point whose residual is not finite is treated as a failed decrease, so the line
//! search backs away from singularities of the Lagrangian.
//!
//! Convergence, in max-norms $\Vert\cdot\Vert_\infty$, with the tolerances $r_a$, $r_r$, $s_a$,
//! $s_r$ of [`NewtonOptions`] (`residual_abs`, `residual_rel`, `step_abs`, `step_rel`):
//! - residual: $\Vert F(w)\Vert_\infty \le r_a + r_r \Vert F(w_0)\Vert_\infty$, or
//! - step: $\Vert\Delta\Vert_\infty \le s_a + s_r \Vert w\Vert_\infty$ (the step is
//!   then applied, so the returned iterate carries the quadratic-convergence gain), and the
//!   residual there small row by row against the Jacobian's scale of the unknowns,
//!   $|F_i| \le r_a + r_r \Vert F(w_0)\Vert_\infty + \sum_j |J_{ij}| (s_a + s_r |w_j|)$
//!   (what a step within the tolerance could leave). A small step alone is not convergence:
//!   with one unknown of $10^{154}$, every step is small against $\Vert w\Vert_\infty$, while
//!   a row of positions of order 1 may still be off by 1. Such an iterate is not returned;
//!   Newton goes on from it.
//!
//! Nothing here allocates or panics.

use nalgebra::{SMatrix, SVector};

use crate::Error;

/// A square nonlinear system $F(w) = 0$ with its Jacobian $J = \partial F / \partial w$.
pub trait Problem<const M: usize> {
    /// The residual $F(w)$.
    fn residual(&self, w: &SVector<f64, M>) -> SVector<f64, M>;
    /// The Jacobian $J(w) = \partial F / \partial w$.
    fn jacobian(&self, w: &SVector<f64, M>) -> SMatrix<f64, M, M>;
}

/// Options of [`solve`]. Build with [`NewtonOptions::default`] and the `with_*` methods.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NewtonOptions {
    /// Absolute tolerance on $\Vert F\Vert_\infty$.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub residual_abs: f64,
    /// Tolerance on $\Vert F\Vert_\infty$ relative to the initial residual.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub residual_rel: f64,
    /// Absolute tolerance on the Newton step $\Vert\Delta\Vert_\infty$.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub step_abs: f64,
    /// Tolerance on $\Vert\Delta\Vert_\infty$ relative to $\Vert w\Vert_\infty$.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub step_rel: f64,
    /// Maximum number of Newton iterations (Jacobian factorisations).
    pub max_iterations: usize,
    /// Armijo constant $c$ of the sufficient-decrease test.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub armijo: f64,
    /// Maximum number of step halvings per iteration.
    pub max_backtracks: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            residual_abs: 1e-14,
            residual_rel: 0.0,
            step_abs: 1e-15,
            step_rel: 1e-10,
            max_iterations: 50,
            armijo: 1e-4,
            max_backtracks: 30,
        }
    }
}

impl NewtonOptions {
    /// Sets the absolute and relative residual tolerances.
    pub fn with_residual_tolerance(mut self, abs: f64, rel: f64) -> Self {
        self.residual_abs = abs;
        self.residual_rel = rel;
        self
    }

    /// Sets the absolute and relative step tolerances.
    pub fn with_step_tolerance(mut self, abs: f64, rel: f64) -> Self {
        self.step_abs = abs;
        self.step_rel = rel;
        self
    }

    /// Sets the iteration cap.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Sets the number of step halvings per iteration (0: full Newton steps only).
    pub fn with_max_backtracks(mut self, max_backtracks: usize) -> Self {
        self.max_backtracks = max_backtracks;
        self
    }

    /// Checks every option is in its domain.
    #[inline]
    pub fn validate(&self) -> Result<(), Error> {
        // arithmetic rather than per-value class tests (which compile to a dozen integer
        // instructions each): sum of 0 * v is NaN iff some v is not finite
        let (a, b, c, d) = (
            self.residual_abs,
            self.residual_rel,
            self.step_abs,
            self.step_rel,
        );
        let finite = (a * 0.0 + b * 0.0) + (c * 0.0 + d * 0.0) == 0.0;
        // (comparisons, not `min`: its NaN handling costs a dozen instructions)
        if finite
            & (a >= 0.0)
            & (b >= 0.0)
            & (c >= 0.0)
            & (d >= 0.0)
            & (self.max_iterations > 0)
            & (self.armijo > 0.0)
            & (self.armijo < 0.5)
        {
            return Ok(());
        }
        self.invalid()
    }

    /// Whether a residual of max-norm `r_norm` meets the residual test, when the first
    /// iterate's was `r_start`.
    #[inline]
    pub(crate) fn converged(&self, r_norm: f64, r_start: f64) -> bool {
        r_norm <= self.residual_abs + self.residual_rel * r_start
    }

    /// The residual test of an iterate accepted on the step test: every row $i$ of the
    /// residual must be what a step within the step tolerance could leave,
    /// $|F_i| \le r_a + r_r \Vert F(w_0)\Vert_\infty + \sum_j |J_{ij}| (s_a + s_r |w_j|)$
    /// (the tolerances of the module docs); row by row, so that
    /// an iterate whose step is small against its largest entry (a momentum of 1e154) but not
    /// against the entries of a row (a position of order 1) is not taken for a root.
    /// `jacobian` is the last one factorised (a scale only).
    #[inline]
    pub(crate) fn small_residual<const M: usize>(
        &self,
        r: &SVector<f64, M>,
        jacobian: &SMatrix<f64, M, M>,
        w: &SVector<f64, M>,
        r_start: f64,
    ) -> bool {
        let floor = self.residual_abs + self.residual_rel * r_start;
        let allowed = w.abs() * self.step_rel + SVector::<f64, M>::repeat(self.step_abs);
        let bound = jacobian.abs() * allowed;
        r.iter()
            .zip(bound.iter())
            .all(|(ri, bi)| ri.abs() <= floor + bi)
    }

    /// The first option out of its domain, as an error (the slow path of `validate`).
    #[cold]
    fn invalid(&self) -> Result<(), Error> {
        let tolerances = [
            ("residual_abs", self.residual_abs),
            ("residual_rel", self.residual_rel),
            ("step_abs", self.step_abs),
            ("step_rel", self.step_rel),
        ];
        for (name, value) in tolerances {
            if !(value.is_finite() && value >= 0.0) {
                return Err(Error::InvalidArgument {
                    name,
                    requirement: "a tolerance must be finite and >= 0",
                });
            }
        }
        if self.max_iterations == 0 {
            return Err(Error::InvalidArgument {
                name: "max_iterations",
                requirement: "at least one Newton iteration is needed",
            });
        }
        if !(self.armijo > 0.0 && self.armijo < 0.5) {
            return Err(Error::InvalidArgument {
                name: "armijo",
                requirement: "the Armijo constant must lie in (0, 1/2)",
            });
        }
        Ok(())
    }
}

/// A converged Newton solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Solution<const M: usize> {
    /// The root $w$ with $F(w) \approx 0$.
    pub w: SVector<f64, M>,
    /// Newton iterations used (Jacobian factorisations).
    pub iterations: usize,
    /// $|F(w)|_\infty$ at the returned root.
    pub residual_norm: f64,
}

/// Whether every entry is finite (over the storage slice: nalgebra's element iterator is
/// slow for small matrices, and this runs every step).
///
/// $\sum_i 0 \cdot m_i$ is $\pm 0$ when every entry is finite and NaN otherwise.
#[inline]
pub(crate) fn all_finite<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> bool {
    lane_sum(m.as_slice(), |v| v * 0.0) == 0.0
}

/// $\sum_i |m_i|$: NaN if an entry is NaN, infinite if one is or the sum overflows.
#[inline]
pub(crate) fn sum_abs<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> f64 {
    lane_sum(m.as_slice(), f64::abs)
}

/// $\sum_i f(v_i)$, summed in four lanes so that it vectorises (a single running sum is a
/// chain of dependent additions that the compiler may not reorder). The lanes start at
/// $-0$, the identity of the addition ($-0 + x = x$ for every $x$, where $+0 + (-0) = +0$),
/// so the compiler drops the first addition of each lane and, for fewer than four entries,
/// the empty lanes.
#[inline]
pub(crate) fn lane_sum(entries: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut lanes = [-0.0f64; 4];
    let mut chunks = entries.chunks_exact(4);
    for chunk in &mut chunks {
        for (lane, &v) in lanes.iter_mut().zip(chunk) {
            *lane += f(v);
        }
    }
    for (lane, &v) in lanes.iter_mut().zip(chunks.remainder()) {
        *lane += f(v);
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
}

/// $\max_i |m_i|$ (NaN entries are skipped, as by nalgebra's `amax`), in four lanes as
/// [`lane_sum`] (a single running maximum is a chain of dependent comparisons).
#[inline]
pub(crate) fn max_abs<const R: usize, const C: usize>(m: &SMatrix<f64, R, C>) -> f64 {
    let mut lanes = [0.0f64; 4];
    let mut chunks = m.as_slice().chunks_exact(4);
    for chunk in &mut chunks {
        for (lane, &v) in lanes.iter_mut().zip(chunk) {
            *lane = lane.max(v.abs());
        }
    }
    for (lane, &v) in lanes.iter_mut().zip(chunks.remainder()) {
        *lane = lane.max(v.abs());
    }
    lanes[0].max(lanes[1]).max(lanes[2].max(lanes[3]))
}

/// Solves $F(w) = 0$ from the guess `w0` (module docs give the method).
///
/// # Errors
/// [`Error::NonFinite`] if the guess, a residual at an accepted iterate or a Jacobian is not
/// finite; [`Error::SingularJacobian`] if the LU factorisation has a zero pivot or its solve
/// overflows; [`Error::LineSearchFailed`] if no step length decreases $|F|^2$;
/// [`Error::NoConvergence`] after `max_iterations`; [`Error::InvalidArgument`] for bad
/// options.
pub fn solve<P, const M: usize>(
    problem: &P,
    w0: SVector<f64, M>,
    options: &NewtonOptions,
) -> Result<Solution<M>, Error>
where
    P: Problem<M> + ?Sized,
{
    options.validate()?;
    solve_validated(problem, w0, options)
}

/// [`solve`] for options already checked with [`NewtonOptions::validate`] (the step paths
/// validate once per step).
pub(crate) fn solve_validated<P, const M: usize>(
    problem: &P,
    w0: SVector<f64, M>,
    options: &NewtonOptions,
) -> Result<Solution<M>, Error>
where
    P: Problem<M> + ?Sized,
{
    if !all_finite(&w0) {
        return Err(Error::NonFinite {
            iteration: 0,
            location: "initial guess",
        });
    }
    let mut w = w0;
    let mut r = problem.residual(&w);
    if !all_finite(&r) {
        return Err(Error::NonFinite {
            iteration: 0,
            location: "residual",
        });
    }
    let mut r_norm = max_abs(&r);
    let r_start = r_norm;
    for iteration in 1..=options.max_iterations {
        if options.converged(r_norm, r_start) {
            return Ok(Solution {
                w,
                iterations: iteration - 1,
                residual_norm: r_norm,
            });
        }
        let jacobian = problem.jacobian(&w);
        if !all_finite(&jacobian) {
            return Err(Error::NonFinite {
                iteration,
                location: "Jacobian",
            });
        }
        let delta = match crate::numeric::linalg::solve(&jacobian, &(-r)) {
            Some(delta) if all_finite(&delta) => delta,
            _ => return Err(Error::SingularJacobian { iteration }),
        };
        if max_abs(&delta) <= options.step_abs + options.step_rel * max_abs(&w) {
            let next = w + delta;
            let r_next = problem.residual(&next);
            if !all_finite(&r_next) {
                return Err(Error::NonFinite {
                    iteration,
                    location: "residual",
                });
            }
            if options.small_residual(&r_next, &jacobian, &next, r_start) {
                return Ok(Solution {
                    w: next,
                    iterations: iteration,
                    residual_norm: max_abs(&r_next),
                });
            }
            // the step is small against the largest unknown only: keep iterating (the line
            // search below starts from this full step)
        }
        let phi = r.norm_squared();
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..=options.max_backtracks {
            let trial = w + delta * alpha;
            let r_trial = problem.residual(&trial);
            if all_finite(&r_trial)
                && r_trial.norm_squared() <= (1.0 - 2.0 * options.armijo * alpha) * phi
            {
                w = trial;
                r = r_trial;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            return Err(Error::LineSearchFailed {
                iteration,
                residual_norm: r_norm,
            });
        }
        r_norm = max_abs(&r);
    }
    if options.converged(r_norm, r_start) {
        return Ok(Solution {
            w,
            iterations: options.max_iterations,
            residual_norm: r_norm,
        });
    }
    Err(Error::NoConvergence {
        iterations: options.max_iterations,
        residual_norm: r_norm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Vector2};

    /// F(w) = (w0^2 + w1^2 - 4, w0 - w1): root (sqrt 2, sqrt 2) from a positive guess.
    struct Circle;

    impl Problem<2> for Circle {
        fn residual(&self, w: &Vector2<f64>) -> Vector2<f64> {
            Vector2::new(w[0] * w[0] + w[1] * w[1] - 4.0, w[0] - w[1])
        }
        fn jacobian(&self, w: &Vector2<f64>) -> Matrix2<f64> {
            Matrix2::new(2.0 * w[0], 2.0 * w[1], 1.0, -1.0)
        }
    }

    #[test]
    fn converges_quadratically_to_the_root() {
        let s = solve(&Circle, Vector2::new(3.0, 1.0), &NewtonOptions::default()).unwrap();
        let root = 2f64.sqrt();
        assert!((s.w[0] - root).abs() < 1e-15 && (s.w[1] - root).abs() < 1e-15);
        assert!(s.iterations <= 7, "iterations {}", s.iterations);
        assert!(s.residual_norm < 1e-14);
    }

    #[test]
    fn singular_start_is_reported() {
        // J(0, 0) = [[0, 0], [1, -1]] has a zero pivot.
        let e = solve(&Circle, Vector2::zeros(), &NewtonOptions::default()).unwrap_err();
        assert_eq!(e, Error::SingularJacobian { iteration: 1 });
    }

    #[test]
    fn invalid_options_are_rejected() {
        let o = NewtonOptions::default().with_max_iterations(0);
        assert!(matches!(
            solve(&Circle, Vector2::new(1.0, 1.0), &o),
            Err(Error::InvalidArgument {
                name: "max_iterations",
                ..
            })
        ));
        let o = NewtonOptions::default().with_residual_tolerance(f64::NAN, 0.0);
        assert!(solve(&Circle, Vector2::new(1.0, 1.0), &o).is_err());
    }
}
