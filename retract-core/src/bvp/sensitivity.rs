//! Sensitivities of a plan from the KKT factorisation at the solution: the derivative of the
//! plan with respect to its start ([`OptimalControlProblem::start_sensitivity`]) and to a
//! parameter of the Lagrangian ([`OptimalControlProblem::parameter_sensitivity`]).
//!
//! At a solution $z^*(p)$ of the KKT conditions $F(z, p) = 0$ whose matrix $\partial F /
//! \partial z$ is regular, $\partial F / \partial z\thinspace dz/dp = -\partial F / \partial
//! p$ (the implicit function theorem). The quadratic subproblem prepared at the solution has
//! that matrix, so its solution for the linear terms $\partial F / \partial p$ in place of the
//! residuals is the derivative: one backward and one forward pass of its Riccati
//! factorisation.

use nalgebra::SVector;

use super::dynamics::Dynamics;
use super::iterate::blocks;
use super::kkt::model::StageLinear;
use super::plan::Failure;
use super::problem::OptimalControlProblem;
use super::realtime::RealTimeIteration;
use crate::{Error, JetFunction, Lagrangian, LiftedSystem};

/// A plan's derivative along a direction of its start:
/// $(\partial x_i / \partial a\thinspace d)_{i \le N}$ and $(\partial u_i / \partial
/// a\thinspace d)_{i < N}$ ([`OptimalControlProblem::start_sensitivity`]).
pub type Sensitivity<const N: usize, const X: usize> = (Vec<SVector<f64, X>>, Vec<SVector<f64, N>>);

/// A plan's derivative with respect to a parameter $p$ of its Lagrangian
/// ([`OptimalControlProblem::parameter_sensitivity`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterSensitivity<const N: usize, const X: usize> {
    /// $\partial x_i / \partial p$, $i = 0, \dots, N$.
    pub x: Vec<SVector<f64, X>>,
    /// $\partial u_i / \partial p$, $i < N$.
    pub u: Vec<SVector<f64, N>>,
    /// $dJ/dp$ (the envelope theorem: the derivative of the Lagrangian $J + \sum_i y_i^T g_i$
    /// in $p$ at the solution).
    pub cost: f64,
}

impl<'a, Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'a, Sys, N, K, X>
{
    /// The derivative of the iterate of `rti` with respect to the start, along `direction`:
    /// $(\partial x_i / \partial a, \partial u_i / \partial a)\thinspace d$ for $d = $
    /// `direction` (its free start components ignored), from the subproblem prepared at the
    /// iterate, which must be a solution ([`Self::prepare`] at a converged plan): the
    /// subproblem's solution is affine in $\delta x_0$, and its linear part is the KKT
    /// system's derivative, so the sensitivity is the forward pass from $\delta x_0 = d$
    /// less the one from $\delta x_0 = 0$. The preparation is kept (for more directions or a
    /// feedback).
    ///
    /// # Errors
    /// [`Failure::Invalid`] if `rti` is not prepared.
    pub fn start_sensitivity<const S: usize, const M: usize>(
        &self,
        rti: &RealTimeIteration<N, X>,
        direction: &[f64; X],
    ) -> Result<Sensitivity<N, X>, Failure>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let Some(lin) = rti.linearization.as_ref() else {
            return Err(not_prepared());
        };
        let sqp = self.sqp::<S, M>(&rti.workspace);
        let d = SVector::<f64, X>::from_column_slice(direction).component_mul(&self.fixed_start);
        let mut pool = rti.workspace.pool.borrow_mut();
        let (riccati, dynamics) = (&lin.riccati, &sqp.dynamics);
        let moved = riccati.forward(dynamics, &lin.prepared, &d, &lin.r_end, &mut *pool);
        let base = (riccati).forward(
            dynamics,
            &lin.prepared,
            &SVector::zeros(),
            &lin.r_end,
            &mut *pool,
        );
        let dx = (moved.dx.iter().zip(&base.dx))
            .map(|(a, b)| a - b)
            .collect();
        let du = (moved.du.iter().zip(&base.du))
            .map(|(a, b)| a - b)
            .collect();
        moved.recycle(&mut *pool);
        base.recycle(&mut *pool);
        Ok((dx, du))
    }

    /// The derivative of the iterate of `rti`, a solution ([`Self::prepare`] at a converged
    /// plan), with respect to a parameter $p$ of the Lagrangian and of the stage equalities,
    /// given their derivatives: `derivative` $= \partial L / \partial p\thinspace(x, u)$ (of
    /// every stage's Lagrangian) and `equalities` $= (\partial g_j / \partial p)_j$ in the
    /// order the equalities were added (empty: they do not depend on $p$), written under
    /// `#[jet_function]`. The subproblem prepared at the solution is solved with, at each
    /// step's $(x_{\theta,i}, u_i)$, the stage gradient $h \nabla_{(x_\theta, u)} \partial L
    /// / \partial p + \sum_j y_{ij} \nabla \partial g_j / \partial p$ ($y_i$: the equalities'
    /// multipliers) in place of the Lagrangian's and the constraint values $\partial g_j /
    /// \partial p$, no defects or boundary residuals (the dynamics and the ends do not depend
    /// on $p$), from $\delta x_0 = 0$: $(\partial x_i / \partial p, \partial u_i / \partial
    /// p)$; and $dJ/dp = \sum_i (h\thinspace \partial L / \partial p + y_i^T \partial g /
    /// \partial p)$ (the envelope theorem). The preparation is kept.
    ///
    /// # Errors
    /// [`Failure::Invalid`] if `rti` is not prepared, or was prepared with an inertia
    /// correction (the reduced Hessian is not positive definite there: not a strict local
    /// minimum, or not a solution), or `equalities` is neither empty nor one per equality;
    /// [`Failure::NonFinite`] if the result is not finite.
    pub fn parameter_sensitivity<const S: usize, const M: usize>(
        &self,
        rti: &RealTimeIteration<N, X>,
        derivative: &(dyn JetFunction<N, K> + Sync),
        equalities: &[&(dyn JetFunction<N, K> + Sync)],
    ) -> Result<ParameterSensitivity<N, X>, Failure>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let Some(lin) = rti.linearization.as_ref() else {
            return Err(not_prepared());
        };
        self.check_parameter(equalities)?;
        if lin.rho != 0.0 {
            return Err(Failure::Invalid(Error::InvalidArgument {
                name: "real-time iteration",
                requirement: "prepared at a solution without inertia correction (a positive \
                              definite reduced Hessian) for a parameter sensitivity",
            }));
        }
        let sqp = self.sqp::<S, M>(&rti.workspace);
        let dynamics = &sqp.dynamics;
        let (h, theta) = (dynamics.h, dynamics.theta);
        let (x, u) = (rti.x(), rti.u());
        let parameter = Parameter {
            lagrangian: derivative,
            equalities,
        };
        let terms = |i: usize| {
            let xt = x[i] * (1.0 - theta) + x[i + 1] * theta;
            ParameterTerms::new::<K>(&xt, &u[i], &rti.y[i], h, &parameter)
        };
        let linear = |i: usize| terms(i).linear(dynamics);
        let stage_cost = |i: usize| terms(i).cost;
        let zero = SVector::<f64, X>::zeros();
        let mut pool = rti.workspace.pool.borrow_mut();
        let solved =
            (lin.riccati).solve_linear(dynamics, &linear, &zero, (&zero, &zero), &mut *pool);
        let sensitivity = ParameterSensitivity {
            x: solved.dx.clone(),
            u: solved.du.clone(),
            cost: (0..u.len()).map(stage_cost).sum(),
        };
        solved.recycle(&mut *pool);
        sensitivity.checked()
    }

    /// [`Failure::Invalid`] unless `equalities` (the derivatives of the stage equalities in
    /// a parameter) is empty or holds one per stage equality.
    pub(super) fn check_parameter(
        &self,
        equalities: &[&(dyn JetFunction<N, K> + Sync)],
    ) -> Result<(), Failure> {
        if !equalities.is_empty() && equalities.len() != self.equalities.len() {
            return Err(Failure::Invalid(Error::InvalidArgument {
                name: "equalities",
                requirement: "one derivative per stage equality, or none",
            }));
        }
        Ok(())
    }
}

/// The refusal of a sensitivity before a preparation.
fn not_prepared() -> Failure {
    Failure::Invalid(Error::InvalidArgument {
        name: "real-time iteration",
        requirement: "prepared (OptimalControlProblem::prepare) before a sensitivity",
    })
}

/// A parameter $p$ of a problem, given by its derivatives, written under `#[jet_function]`:
/// `lagrangian` $= \partial L / \partial p\thinspace(x, u)$ (of every stage's Lagrangian)
/// and `equalities` $= (\partial g_j / \partial p)_j$ in the order the stage equalities were
/// added (empty: they do not depend on $p$). The dynamics, the ends and the inequalities do
/// not depend on $p$.
#[derive(Clone, Copy)]
pub struct Parameter<'f, const N: usize, const K: usize> {
    /// $\partial L / \partial p$.
    pub lagrangian: &'f (dyn JetFunction<N, K> + Sync),
    /// $(\partial g_j / \partial p)_j$, one per stage equality, or none.
    pub equalities: &'f [&'f (dyn JetFunction<N, K> + Sync)],
}

impl<const N: usize, const K: usize> core::fmt::Debug for Parameter<'_, N, K> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Parameter")
            .field("lagrangian", &self.lagrangian.name())
            .field("equalities", &self.equalities.len())
            .finish()
    }
}

/// The terms of a parameter $p$ at one step's $(x_\theta, u)$ with the stage equalities'
/// multipliers $y$: the derivative in $p$ of the gradient of the Lagrangian, $h \nabla
/// \partial L / \partial p + \sum_j y_j \nabla \partial g_j / \partial p$ (in $x_\theta$ and
/// $u$), of the equalities, $\partial g_j / \partial p$, and of the step's Lagrangian, $h
/// \partial L / \partial p + y^T \partial g / \partial p$.
pub(super) struct ParameterTerms<const N: usize, const X: usize> {
    pub gx: SVector<f64, X>,
    pub gu: SVector<f64, N>,
    pub constraint: SVector<f64, N>,
    pub cost: f64,
}

impl<const N: usize, const X: usize> ParameterTerms<N, X> {
    /// The terms of `parameter` at `(x_theta, u)` with the multipliers `y`, step `h`.
    pub fn new<const K: usize>(
        x_theta: &SVector<f64, X>,
        u: &SVector<f64, N>,
        y: &SVector<f64, N>,
        h: f64,
        parameter: &Parameter<'_, N, K>,
    ) -> Self {
        let xb = blocks::<N, K, X>(x_theta);
        let (own, g) = (
            parameter.lagrangian.value(&xb, u),
            parameter.lagrangian.gradient(&xb, u),
        );
        let mut terms = Self {
            gx: SVector::from_fn(|r, _| h * g.x[r / N][r % N]),
            gu: g.u * h,
            constraint: SVector::zeros(),
            cost: h * own,
        };
        for (j, c) in parameter.equalities.iter().enumerate().take(N) {
            let (grad, value) = (c.gradient(&xb, u), c.value(&xb, u));
            terms.gx += SVector::<f64, X>::from_fn(|r, _| y[j] * grad.x[r / N][r % N]);
            terms.gu += grad.u * y[j];
            terms.constraint[j] = value;
            terms.cost += y[j] * value;
        }
        terms
    }

    /// The terms in the subproblem's variables $(\delta x_i, \delta u_i)$: $l_x = E^T g_x$,
    /// $l_u = \theta \bar B^T g_x + g_u$, no defect.
    pub fn linear(&self, dynamics: &Dynamics<N, X>) -> StageLinear<N, X> {
        StageLinear {
            lx: dynamics.poly_e.left_t(&self.gx),
            lu: dynamics.poly_b.left_t(&self.gx) * dynamics.theta + self.gu,
            defect: SVector::zeros(),
            constraint: self.constraint,
        }
    }
}

impl<const N: usize, const X: usize> ParameterSensitivity<N, X> {
    /// Itself if every entry is finite, else [`Failure::NonFinite`].
    pub(super) fn checked(self) -> Result<Self, Failure> {
        let finite = |v: &[f64]| v.iter().all(|e| e.is_finite());
        let all_finite = self.cost.is_finite()
            && self.x.iter().all(|v| finite(v.as_slice()))
            && self.u.iter().all(|v| finite(v.as_slice()));
        if all_finite {
            Ok(self)
        } else {
            Err(Failure::NonFinite)
        }
    }
}
