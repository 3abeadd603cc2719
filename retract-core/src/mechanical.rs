//! A mechanical system written as its energy, $l(q, q') = T - V$, seen by the optimizer:
//! the trait [`MechanicalSystem`] that `#[mechanical_system]` implements, and
//! [`TorqueComponent`], one component of its Euler-Lagrange operator as a stage equality.
//!
//! The Euler-Lagrange operator of $l$, with the non-conservative forces $Q_{nc}$,
//!
//! $$\tau(q, q', q'') = \frac{d}{dt}\frac{\partial l}{\partial q'} - \frac{\partial l}{\partial q} - Q_{nc}
//!   = M(q, q')\thinspace q'' + \frac{\partial^2 l}{\partial q'\partial q}\thinspace q' - \frac{\partial l}{\partial q} - Q_{nc},
//! \qquad M = \frac{\partial^2 l}{\partial q'^2},$$
//!
//! is the generalized force the actuators must supply for the motion $q(t)$. On the jet of
//! order 2 ($x = (q, q')$, $u = q''$) each component $\tau_c$ is a function of $(x, u)$; the
//! components no actuator supplies must vanish along a plan, which
//! [`TorqueComponent`] poses as an equality of [`crate::bvp::OptimalControlProblem`].

use nalgebra::SVector;

use crate::{Gradient, Hessian, JetFunction};

/// A mechanical system on $\mathbb{R}^N$ with its Euler-Lagrange operator $\tau$ (module
/// docs) as a function of the order-2 jet: $x = (q, q')$, $u = q''$. Implemented by
/// `#[mechanical_system]`, whose type is also the optimal-control [`crate::Lagrangian`] of
/// order 2, $\tfrac{R}{2}\sum_{a\ \mathrm{actuated}} \tau_a^2$.
pub trait MechanicalSystem<const N: usize> {
    /// The actuated coordinates, ascending.
    fn actuated(&self) -> &'static [usize];

    /// The coordinates no actuator drives, ascending (the complement of
    /// [`Self::actuated`]): their $\tau_c$ must vanish.
    fn unactuated(&self) -> &'static [usize];

    /// $\tau_c(x, u)$ (NaN for $c \ge N$).
    fn torque_value(&self, c: usize, x: &[SVector<f64, N>; 2], u: &SVector<f64, N>) -> f64;

    /// The gradient of $\tau_c$ in $(x, u)$ (zero for $c \ge N$).
    fn torque_gradient(
        &self,
        c: usize,
        x: &[SVector<f64, N>; 2],
        u: &SVector<f64, N>,
    ) -> Gradient<N, 2>;

    /// The Hessian of $\tau_c$ in $(x, u)$ (zero for $c \ge N$).
    fn torque_hessian(
        &self,
        c: usize,
        x: &[SVector<f64, N>; 2],
        u: &SVector<f64, N>,
    ) -> Hessian<N, 2>;

    /// The system's type name, for messages.
    fn system_name(&self) -> &'static str {
        "mechanical system"
    }
}

/// Component `index` of the Euler-Lagrange operator of `system`,
/// $g(x, u) = \tau_{\mathrm{index}}(x, u)$, as a [`JetFunction`]: the equality
/// $\tau_c = 0$ of a coordinate no actuator drives, for
/// [`crate::bvp::OptimalControlProblem::with_equalities`]. The generated method
/// `unactuated_torques()` returns one per unactuated coordinate.
#[derive(Clone, Copy, Debug)]
pub struct TorqueComponent<'a, S: ?Sized> {
    /// The system.
    pub system: &'a S,
    /// The coordinate $c$.
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
