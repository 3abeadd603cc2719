//! A system written by hand: a reference for the generated code and a template for
//! implementing [`Lagrangian`] without the macro.

use nalgebra::{SMatrix, SVector, Vector2};

use crate::{Gradient, Hessian, Lagrangian};

/// The paper's obstacle-avoidance Lagrangian on $\mathbb{R}^2$ (order 2):
/// $L = \tfrac{m}{2}|q''|^2 + V(q)$, $V(q) = \tau / (|q|^2 - r^2)$.
///
/// Derivatives, with $s = |q|^2 - r^2$:
/// $\nabla V = -2\tau q / s^2$,
/// $\nabla^2 V = -2\tau I / s^2 + 8 \tau q q^T / s^3$,
/// $\partial L/\partial u = m u$, $\partial^2 L/\partial u^2 = m I$;
/// momenta $p_1 = m q''$, $p_0 = -m q'''$.
///
/// ```
/// use retract_core::{models::PlanarBarrier, step, LiftedSystem, StepOptions};
/// use nalgebra::SVector;
///
/// let system = PlanarBarrier { tau: 1e-2, radius: 1.0, mass: 1.0 };
/// // derivative data (q, q', q'', q''') -> Hamiltonian state (x, p)
/// let jet = SVector::<f64, 8>::from_column_slice(&[-2.0, 1.2, 1.0, -0.1, 0.0, 0.0, 0.0, 0.0]);
/// let z0 = system.legendre(&jet);
/// let (z1, report) = step(&system, &z0, 0.01, &StepOptions::default())?;
/// assert!(report.iterations <= 4);
/// assert!((z1[0] - (-2.0 + 0.01)).abs() < 1e-4);
/// # Ok::<(), retract_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarBarrier {
    /// Barrier weight $\tau$.
    pub tau: f64,
    /// Obstacle radius $r$.
    pub radius: f64,
    /// Weight $m$ of the control effort.
    pub mass: f64,
}

impl PlanarBarrier {
    /// The potential $V(q) = \tau / (|q|^2 - r^2)$.
    pub fn potential(&self, q: &Vector2<f64>) -> f64 {
        self.tau / (q.norm_squared() - self.radius * self.radius)
    }
}

impl Lagrangian<2, 2> for PlanarBarrier {
    fn lagrangian(&self, x: &[SVector<f64, 2>; 2], u: &SVector<f64, 2>) -> f64 {
        0.5 * self.mass * u.norm_squared() + self.potential(&x[0])
    }

    fn gradient(&self, x: &[SVector<f64, 2>; 2], u: &SVector<f64, 2>) -> Gradient<2, 2> {
        let s = x[0].norm_squared() - self.radius * self.radius;
        Gradient {
            x: [x[0] * (-2.0 * self.tau / (s * s)), SVector::zeros()],
            u: u * self.mass,
        }
    }

    fn hessian(&self, x: &[SVector<f64, 2>; 2], _u: &SVector<f64, 2>) -> Hessian<2, 2> {
        let q = x[0];
        let s = q.norm_squared() - self.radius * self.radius;
        let mut hessian = Hessian::zeros();
        hessian.xx[0][0] = SMatrix::<f64, 2, 2>::identity() * (-2.0 * self.tau / (s * s))
            + q * q.transpose() * (8.0 * self.tau / (s * s * s));
        hessian.uu = SMatrix::<f64, 2, 2>::identity() * self.mass;
        hessian
    }

    fn momenta(
        &self,
        _lower: &[SVector<f64, 2>; 2],
        upper: &[SVector<f64, 2>; 2],
    ) -> [SVector<f64, 2>; 2] {
        [-upper[1] * self.mass, upper[0] * self.mass]
    }
}

crate::impl_lifted_system!(PlanarBarrier, n = 2, k = 2);

/// $L = \tfrac{m}{2} |q''|^2 + V(q)$: the weight $c = m$.
impl crate::scheme::split::Separable<2, 2> for PlanarBarrier {
    fn kinetic_weight(&self) -> f64 {
        self.mass
    }
}
