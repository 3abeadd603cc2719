//! A mechanical system written as its energy, $l(q, q') = T - V$, seen by the optimizer:
//! the trait [`MechanicalSystem`] that `#[mechanical_system]` implements, and
//! [`TorqueComponent`], one component of its Euler-Lagrange operator as a stage equality, and
//! [`InputComponent`], one component of the input it needs, for bounds on the inputs.
//!
//! The Euler-Lagrange operator of $l$, with the non-conservative forces $Q_{nc}$,
//!
//! $$\tau(q, q', q'') = \frac{d}{dt}\frac{\partial l}{\partial q'} - \frac{\partial l}{\partial q} - Q_{nc}
//!   = M(q, q')\thinspace q'' + \frac{\partial^2 l}{\partial q'\partial q}\thinspace q' - \frac{\partial l}{\partial q} - Q_{nc},
//! \qquad M = \frac{\partial^2 l}{\partial q'^2},$$
//!
//! is the generalized force the inputs must supply for the motion $q(t)$, through the
//! actuation matrix $B(q)$: $\tau = B(q)\thinspace u$. On the jet of order 2 ($x = (q, q')$,
//! $u = q''$) each component $\tau_c$ is a function of $(x, u)$; what no input can supply
//! must vanish along a plan, which [`TorqueComponent`] poses as an equality of
//! [`crate::bvp::OptimalControlProblem`]: with actuated coordinates, $\tau_c = 0$ for each
//! coordinate $c$ no actuator drives; with an actuation matrix of $n - 1$ columns of full
//! rank, the one equality $a(q)^T \tau = 0$ with $a_i = (-1)^i \det B_{(i)}$ ($B$ without
//! row $i$), which spans the vectors $B^T$ annihilates, so that $\tau = B u$ exactly where
//! it holds.

use nalgebra::SVector;

use crate::{Gradient, Hessian, JetFunction};

/// A mechanical system on $\mathbb{R}^N$ with its Euler-Lagrange operator $\tau$ (module
/// docs) as a function of the order-2 jet: $x = (q, q')$, $u = q''$. Implemented by
/// `#[mechanical_system]`, whose type is also the optimal-control [`crate::Lagrangian`] of
/// order 2, $\tfrac{R}{2}|u|^2 + C(q, q', u)$ with the input $u(q, q', q'')$ the motion needs
/// (on the actuated coordinates $u = \tau$; through an actuation matrix $B$, the solution of
/// $B u = \tau$ or of $B^T B u = B^T \tau$) and $C$ the user's cost.
pub trait MechanicalSystem<const N: usize> {
    /// The actuated coordinates, ascending (none where an actuation matrix drives the
    /// system).
    fn actuated(&self) -> &'static [usize];

    /// The labels $c$ of the passive equalities, ascending: the coordinates no actuator
    /// drives (the complement of [`Self::actuated`]), whose $\tau_c$ must vanish; or, with
    /// an actuation matrix of $n - 1$ columns, the label 0 of $a(q)^T \tau = 0$ (module
    /// docs).
    fn unactuated(&self) -> &'static [usize];

    /// The passive equality labelled $c$ at $(x, u)$: $\tau_c(x, u)$, or $a^T \tau$ (NaN for
    /// another $c$).
    fn torque_value(&self, c: usize, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> f64;

    /// The gradient of $\tau_c$ in $(x, u)$ (zero for another $c$).
    fn torque_gradient(
        &self,
        c: usize,
        x: &[SVector<f64, N>; 2],
        u: &SVector<f64, N>,
    ) -> Gradient<N, 2>;

    /// The Hessian of $\tau_c$ in $(x, u)$ (zero for another $c$).
    fn torque_hessian(
        &self,
        c: usize,
        x: &[SVector<f64, N>; 2],
        u: &SVector<f64, N>,
    ) -> Hessian<N, 2>;

    /// The input $u_j(x, u)$ the motion needs (the type's `input`), where the system was
    /// generated with `input_functions = true`; NaN otherwise or for $j \ge m$.
    fn input_value(&self, j: usize, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> f64 {
        let _ = (j, x, u);
        f64::NAN
    }

    /// The gradient of $u_j$ in $(x, u)$ (`input_functions = true`; zero otherwise).
    fn input_gradient(
        &self,
        j: usize,
        x: &[SVector<f64, N>; 2],
        u: &SVector<f64, N>,
    ) -> Gradient<N, 2> {
        let _ = (j, x, u);
        Gradient::zeros()
    }

    /// The Hessian of $u_j$ in $(x, u)$ (`input_functions = true`; zero otherwise).
    fn input_hessian(
        &self,
        j: usize,
        x: &[SVector<f64, N>; 2],
        u: &SVector<f64, N>,
    ) -> Hessian<N, 2> {
        let _ = (j, x, u);
        Hessian::zeros()
    }

    /// The system's type name, for messages.
    fn system_name(&self) -> &'static str {
        "mechanical system"
    }
}

/// The passive equality labelled `index` of `system` (a component
/// $g(x, u) = \tau_{\mathrm{index}}(x, u)$ of its Euler-Lagrange operator, or $a^T \tau$ for
/// an actuation matrix; [`MechanicalSystem::unactuated`]) as a [`JetFunction`]: the equality
/// $g = 0$ of what no input supplies, for
/// [`crate::bvp::OptimalControlProblem::with_equalities`]. The generated method
/// `unactuated_torques()` returns one per unactuated coordinate.
#[derive(Clone, Copy, Debug)]
pub struct TorqueComponent<'a, S: ?Sized> {
    /// The system.
    pub system: &'a S,
    /// The label $c$ ([`MechanicalSystem::unactuated`]).
    pub index: usize,
}

impl<S: MechanicalSystem<N> + ?Sized, const N: usize> JetFunction<N, 2> for TorqueComponent<'_, S> {
    fn value(&self, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> f64 {
        self.system.torque_value(self.index, x, u)
    }

    fn gradient(&self, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> Gradient<N, 2> {
        self.system.torque_gradient(self.index, x, u)
    }

    fn hessian(&self, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> Hessian<N, 2> {
        self.system.torque_hessian(self.index, x, u)
    }

    fn name(&self) -> &'static str {
        self.system.system_name()
    }
}

/// The input component $u_j$ of `system` ([`MechanicalSystem::input_value`]: the $j$-th
/// input the motion needs, $\tau_{a_j}$ on the $j$-th actuated coordinate or the $j$-th
/// component of the solution of $B u = \tau$) as a [`JetFunction`] $g(x, q'') = u_j$, for
/// bounds on the inputs: `with_function_bounds(&inputs[j], lower, upper)` keeps
/// lower $\le u_j \le$ upper at every step. The generated method `input_functions()` (with
/// `#[mechanical_system(input_functions = true)]`) returns one per input.
#[derive(Clone, Copy, Debug)]
pub struct InputComponent<'a, S: ?Sized> {
    /// The system.
    pub system: &'a S,
    /// The input's index $j$, below the number of inputs $m$.
    pub index: usize,
}

impl<S: MechanicalSystem<N> + ?Sized, const N: usize> JetFunction<N, 2> for InputComponent<'_, S> {
    fn value(&self, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> f64 {
        self.system.input_value(self.index, x, u)
    }

    fn gradient(&self, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> Gradient<N, 2> {
        self.system.input_gradient(self.index, x, u)
    }

    fn hessian(&self, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> Hessian<N, 2> {
        self.system.input_hessian(self.index, x, u)
    }

    fn name(&self) -> &'static str {
        self.system.system_name()
    }
}
