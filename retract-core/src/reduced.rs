//! The reduced step: Newton on the nonlinear core only.
//!
//! When the Hessian of $L$ depends on a few jet components $y$ (the core, e.g. the position
//! of a body in a barrier potential) and on no component of the top derivative, the
//! theta-scheme residual splits as
//!
//! $$F(z_0, w) = A(h, \theta)\, w + c(z_0, y), \qquad y = P w + y_0(z_0),$$
//!
//! with $y$ the core values at the evaluation point ($P$ picks $\theta x_1$, $y_0 = (1-\theta) x_0$)
//! and $A$ independent of the state. Then $w = -A^{-1} c(z_0, y)$ and $y$ solves the small
//! system
//!
//! $$r(y) = y - y_0 + K c(z_0, y) = 0, \qquad K = P A^{-1}, \qquad
//!   \partial r/\partial y = I + K\, \partial c/\partial y,$$
//!
//! $R$ unknowns instead of $M$. $A^{-1}$ and $K$ depend on $(h, \theta)$ only and are cached by
//! [`ReducedStepper`]; $A$ itself is not generated but formed from the Jacobian of the general
//! scheme, $A = \partial F/\partial w - (\partial c/\partial y) P$, at the first state stepped
//! with that $(h, \theta)$ (the macro has checked that it does not depend on the state). The
//! result is the same $z_1$ as the general step, to rounding.

use nalgebra::{SMatrix, SVector};

use crate::newton::{self, Problem};
use crate::step::StepReport;
use crate::{Error, LiftedSystem, StepOptions};

/// A system whose step reduces to its nonlinear core of `R` variables.
pub trait ReducedScheme<const S: usize, const M: usize, const R: usize>:
    LiftedSystem<S, M>
{
    /// Flat index $j n + i$ (into $z$ and $w$) of the jet component of each core variable.
    const CORE: [usize; R];

    /// $c(z_0, y) = F(z_0, w) - A w$ with the core values $y$ at the evaluation point.
    fn affine_part(
        &self,
        z0: &SVector<f64, S>,
        y: &SVector<f64, R>,
        h: f64,
        theta: f64,
    ) -> SVector<f64, M>;

    /// $\partial c / \partial y$.
    fn affine_jacobian(
        &self,
        z0: &SVector<f64, S>,
        y: &SVector<f64, R>,
        h: f64,
        theta: f64,
    ) -> SMatrix<f64, M, R>;
}

/// Cached factors for one $(h, \theta)$.
#[derive(Clone, Debug)]
struct Factors<const M: usize, const R: usize> {
    h: f64,
    theta: f64,
    a_inv: SMatrix<f64, M, M>,
    k: SMatrix<f64, R, M>,
}

/// How many $(h, \theta)$ factorisations a [`ReducedStepper`] keeps (a composition of
/// order 4 or more alternates between two or three step sizes).
const CACHED: usize = 4;

/// Steps a [`ReducedScheme`] with Newton on its core; caches $A^{-1}$ for the last
/// few step sizes. No heap.
#[derive(Clone, Debug)]
pub struct ReducedStepper<'a, Sys: ?Sized, const S: usize, const M: usize, const R: usize> {
    system: &'a Sys,
    factors: [Option<Factors<M, R>>; CACHED],
    next_slot: usize,
}

/// $r(y)$ of the module docs as a Newton problem.
struct CoreProblem<'a, Sys: ?Sized, const S: usize, const M: usize, const R: usize> {
    system: &'a Sys,
    z0: &'a SVector<f64, S>,
    y0: SVector<f64, R>,
    k: &'a SMatrix<f64, R, M>,
    h: f64,
    theta: f64,
}

impl<Sys, const S: usize, const M: usize, const R: usize> Problem<R>
    for CoreProblem<'_, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    fn residual(&self, y: &SVector<f64, R>) -> SVector<f64, R> {
        y - self.y0 + self.k * self.system.affine_part(self.z0, y, self.h, self.theta)
    }

    fn jacobian(&self, y: &SVector<f64, R>) -> SMatrix<f64, R, R> {
        SMatrix::identity() + self.k * self.system.affine_jacobian(self.z0, y, self.h, self.theta)
    }
}

impl<'a, Sys, const S: usize, const M: usize, const R: usize> ReducedStepper<'a, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    /// A stepper for `system` (factors are computed at the first step).
    pub fn new(system: &'a Sys) -> Self {
        Self {
            system,
            factors: [const { None }; CACHED],
            next_slot: 0,
        }
    }

    /// The cached factors for $(h, \theta)$, formed at `z0` with the first guess `y` if new.
    fn factors(
        &mut self,
        z0: &SVector<f64, S>,
        y: &SVector<f64, R>,
        h: f64,
        theta: f64,
    ) -> Result<&Factors<M, R>, Error> {
        let slot = match self
            .factors
            .iter()
            .position(|f| matches!(f, Some(f) if f.h == h && f.theta == theta))
        {
            Some(slot) => slot,
            None => {
                // A = dF/dw - (dc/dy) P at any state: here z0 and w with w[CORE] = x_1 from y
                let mut w = SVector::<f64, M>::zeros();
                for (m, &c) in Sys::CORE.iter().enumerate() {
                    if theta != 0.0 {
                        w[c] = (y[m] - (1.0 - theta) * z0[c]) / theta;
                    }
                }
                let dc = self.system.affine_jacobian(z0, y, h, theta);
                let mut a = self.system.jacobian(z0, &w, h, theta);
                for (m, &c) in Sys::CORE.iter().enumerate() {
                    for r in 0..M {
                        a[(r, c)] -= dc[(r, m)] * theta;
                    }
                }
                let a_inv = crate::linalg::solve(&a, &SMatrix::<f64, M, M>::identity())
                    .ok_or(Error::SingularJacobian { iteration: 0 })?;
                let k = SMatrix::<f64, R, M>::from_fn(|m, c| theta * a_inv[(Sys::CORE[m], c)]);
                let slot = self.next_slot;
                self.factors[slot] = Some(Factors { h, theta, a_inv, k });
                self.next_slot = (slot + 1) % CACHED;
                slot
            }
        };
        self.factors[slot]
            .as_ref()
            .ok_or(Error::SingularJacobian { iteration: 0 })
    }

    /// One step $z_1 = \Psi_h(z_0)$, the same map as [`crate::step()`].
    ///
    /// # Errors
    /// As [`crate::step()`]; a singular $A$ (only for degenerate $\theta$ and $h$) is
    /// [`Error::SingularJacobian`] at iteration 0.
    pub fn step(
        &mut self,
        z0: &SVector<f64, S>,
        h: f64,
        options: &StepOptions,
    ) -> Result<(SVector<f64, S>, StepReport), Error> {
        options.validate(h)?;
        if !z0.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite {
                iteration: 0,
                location: "state",
            });
        }
        let theta = options.theta;
        let system = self.system;
        let y0 = SVector::<f64, R>::from_fn(|m, _| (1.0 - theta) * z0[Sys::CORE[m]]);
        // first guess: x_theta ~ x_0 + theta h x_0' (the next jet block), x_0 for the last block
        let n = Sys::DIMENSION;
        let y_guess = SVector::<f64, R>::from_fn(|m, _| {
            let c = Sys::CORE[m];
            let rate = if c + n < S / 2 { z0[c + n] } else { 0.0 };
            z0[c] + theta * h * rate
        });
        let factors = self.factors(z0, &y_guess, h, theta)?;
        let problem = CoreProblem {
            system,
            z0,
            y0,
            k: &factors.k,
            h,
            theta,
        };
        let solution = newton::solve_validated(&problem, y_guess, &options.newton)?;
        let c = system.affine_part(z0, &solution.w, h, theta);
        let z1: SVector<f64, S> = -(factors.a_inv.fixed_rows::<S>(0) * c);
        if !z1.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite {
                iteration: solution.iterations,
                location: "reduced step",
            });
        }
        if options.check_domain {
            // the domain check reads x_1 from w and u from its tail
            let mut w = SVector::<f64, M>::zeros();
            w.fixed_rows_mut::<S>(0).copy_from(&z1);
            for r in S..M {
                w[r] = -(0..M).map(|k| factors.a_inv[(r, k)] * c[k]).sum::<f64>();
            }
            system.check_domain(z0, &w, theta).map_err(Error::Domain)?;
        }
        Ok((
            z1,
            StepReport {
                iterations: solution.iterations,
                residual_norm: solution.residual_norm,
                halvings: 0,
            },
        ))
    }
}

#[cfg(feature = "std")]
impl<Sys, const S: usize, const M: usize, const R: usize> ReducedStepper<'_, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    /// `steps` reduced steps of size `h` from `z0`, with the driver of [`crate::trajectory`]
    /// (step halving, domain crossing location).
    ///
    /// # Errors
    /// [`crate::Interrupted`] with the states before the failed step.
    pub fn trajectory(
        &mut self,
        z0: &SVector<f64, S>,
        h: f64,
        steps: usize,
        options: &StepOptions,
    ) -> Result<crate::Trajectory<S>, crate::Interrupted<S>> {
        crate::step::drive(
            |z: &SVector<f64, S>, h, o: &StepOptions| self.step(z, h, o),
            z0,
            h,
            steps,
            options,
        )
    }
}
