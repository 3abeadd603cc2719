//! The rotation group SO(3) in Gibbs (Rodrigues) charts, and its Cayley and exponential
//! midpoint maps.
//!
//! The chart centred at the identity writes a rotation as the unit quaternion
//! $Q(y) = (1, y)/\sqrt{1 + |y|^2}$, $y \in \mathbb{R}^3$ (a rotation by $2 \arctan |y|$ about
//! $y$); it covers every rotation by less than $\pi$. The body angular velocity of a curve
//! $y(t)$ is $\Omega = 2 Q^{-1} \dot Q = 2 (y' - y \times y') / (1 + |y|^2)$, so a Lagrangian
//! written in body coordinates becomes a Lagrangian of $y$ by substituting $\Omega$ (and its
//! total derivatives): rational functions, which the macro differentiates as usual.
//!
//! [`CayleyMidpoint`] is the group's discretization map $R_d(g, \xi) = (g\thinspace
//! \mathrm{cay}(-\xi/2), g\thinspace \mathrm{cay}(\xi/2))$ with $\xi = 2 Q^{-1} \delta Q$ the body
//! vector of the tangent vector $v$ at $y$ and $\mathrm{cay}(\omega) \propto (1, \omega/2)$
//! (the Cayley map, equal to $\exp$ to second order). In the chart, with
//! $w = \xi/4 = (v - y \times v) / (2 (1 + |y|^2))$ and the product
//! $(1, y)(1, \pm w) = (1 \mp y \cdot w, y \pm w \pm y \times w)$:
//!
//! $$R_{1,2}(y, v) = \frac{y \mp w \mp y \times w}{1 \pm y \cdot w}.$$
//!
//! It is symmetric ($R_d(y, -v) = (R_2, R_1)(y, v)$), so of order 2, and equivariant under
//! left multiplication, so a left-invariant Lagrangian's spatial momentum
//! ([`spatial_momentum`]) is conserved by its cotangent lift; [`crate::scheme::map::TaylorLift`]
//! lifts it to every order (and [`ExpMidpoint`], through [`Scalar::stumpff`], to order 16).
//!
//! [`ExpMidpoint`] is the map with the group's exponential, $R_d(g, \xi) = (g \exp(-\xi/2),
//! g \exp(\xi/2))$: the same products with $w = \tan(\theta/2)\thinspace \phi/\theta$, $\phi = \xi/2$,
//! $\theta = |\phi|$, written as $c_2(\theta^2)/c_1(\theta^2)\thinspace \phi$ in Stumpff functions
//! ([`crate::numeric::special`]) so that it is smooth through $\xi = 0$. It follows a one-parameter
//! subgroup (a spherical body's motion) exactly.
//!
//! One chart ends at a turn by $\pi$ from its centre. Moving charts ([`recentre`] after each
//! step, a centre quaternion $c$ and the rotation $c\thinspace Q(y)$) follow a body through any
//! number of turns; the change of chart is symplectic and commutes with the step (module
//! `moving`).
//!
//! A Lagrangian written in body coordinates, L(R, Omega, ..., Omega^(k-1)), is composed
//! with the chart by `#[higher_order_lagrangian(order = k, so3)]`, with the chart's centre as
//! a parameter ([`So3System`], module `body`): [`body_state`] starts it from body rates and
//! [`recentre_system`] moves chart and centre together.

use nalgebra::{SVector, Vector3};

mod body;
mod moving;
pub use body::{So3System, body_state, centre_matrix, centred, chart_derivatives, recentre_system};
pub use moving::{
    So3, chart_point, chart_quaternion, orientation, recentre, transition, translate,
    world_momentum,
};
pub(crate) use moving::{chart_momentum, transition_blocks};

use crate::numeric::taylor::Scalar;
use crate::scheme::map::BaseMap;

/// The Cayley midpoint map of SO(3) in the Gibbs chart (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CayleyMidpoint;

/// $a \times b$.
fn cross<T: Scalar>(a: &[T; 3], b: &[T; 3]) -> [T; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// $a \cdot b$.
fn dot<T: Scalar>(a: &[T; 3], b: &[T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The chart points $y \mp w \mp y \times w$ over $1 \pm y \cdot w$ of the left
/// translations of $y$ by the Gibbs vectors $\mp w$, with $w = \rho(|\phi|^2)\thinspace \phi$,
/// $\phi = (v - y \times v) / (1 + |y|^2) = \Omega / 2$ (module docs).
fn gibbs_halves<T: Scalar>(y: [T; 3], v: [T; 3], rho: impl Fn(T) -> T) -> ([T; 3], [T; 3]) {
    let yv = cross(&y, &v);
    let scale = dot(&y, &y) + 1.0;
    let phi: [T; 3] = core::array::from_fn(|a| (v[a] - yv[a]) / scale);
    let ratio = rho(dot(&phi, &phi));
    let w: [T; 3] = core::array::from_fn(|a| phi[a] * ratio);
    let yw = cross(&y, &w);
    let d = dot(&y, &w);
    let (minus, plus) = (-d + 1.0, d + 1.0);
    (
        core::array::from_fn(|a| (y[a] - w[a] - yw[a]) / plus),
        core::array::from_fn(|a| (y[a] + w[a] + yw[a]) / minus),
    )
}

impl BaseMap<3> for CayleyMidpoint {
    /// The Gibbs products of the module docs with $\rho = 1/2$: $w = \Omega / 4$, the Gibbs vector of
    /// $\mathrm{cay}(\Omega / 2)$.
    fn base<T: Scalar>(&self, y: [T; 3], v: [T; 3]) -> ([T; 3], [T; 3]) {
        gibbs_halves(y, v, |_| T::constant(0.5))
    }
}

/// The exponential midpoint map of SO(3) in the Gibbs chart: $R_d(g, \xi) = (g
/// \exp(-\xi/2), g \exp(\xi/2))$, the exact flow of the constant body velocity $\xi$ over
/// half a step either way, where [`CayleyMidpoint`] takes the Cayley map. Its Gibbs vector is
/// $w = \tan(\theta/2)\thinspace \phi / \theta$ with $\phi = \xi/2$, $\theta = |\phi|$: the ratio
/// $\rho(s) = c_2(s) / c_1(s)$ of Stumpff functions ([`crate::numeric::special`]), entire near
/// $\xi = 0$, so the map and its derivatives need no branch there. It is symmetric and
/// left-equivariant as the Cayley map is, and a step costs a few more operations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExpMidpoint;

impl BaseMap<3> for ExpMidpoint {
    fn base<T: Scalar>(&self, y: [T; 3], v: [T; 3]) -> ([T; 3], [T; 3]) {
        gibbs_halves(y, v, |s: T| s.stumpff(2) / s.stumpff(1))
    }
}

/// The Noether momentum of left multiplication at the chart state $(y, p)$ of a
/// first-order system ($k = 1$): component $a$ is $p \cdot \delta_a y$ with
/// $\delta_a y = \tfrac12 (e_a + e_a \times y + (e_a \cdot y)\thinspace y)$, the chart velocity of
/// $Q \mapsto (1, \epsilon e_a / 2) Q$. For a Lagrangian written in body coordinates this is
/// the spatial angular momentum $R\thinspace \partial L / \partial \Omega$, conserved by the
/// cotangent lift of [`CayleyMidpoint`].
pub fn spatial_momentum(y: &Vector3<f64>, p: &Vector3<f64>) -> Vector3<f64> {
    let z = crate::scheme::lifted::join::<3, 1, 6>(&[*y], &[*p]);
    world_momentum::<1, 6>(&nalgebra::UnitQuaternion::identity(), &z)
}

/// The rotation matrix of the chart point $y$: $R = ((1 - |y|^2) I + 2 y y^T + 2 \hat y)
/// / (1 + |y|^2)$ with $\hat y v = y \times v$.
pub fn rotation(y: &Vector3<f64>) -> nalgebra::Matrix3<f64> {
    let n = y.norm_squared();
    ((1.0 - n) * nalgebra::Matrix3::identity() + 2.0 * y * y.transpose() + 2.0 * y.cross_matrix())
        / (1.0 + n)
}

/// The chart state $(y, p)$ of a first-order system as blocks of $z \in \mathbb{R}^6$.
pub fn parts(z: &SVector<f64, 6>) -> (Vector3<f64>, Vector3<f64>) {
    (
        z.fixed_rows::<3>(0).into_owned(),
        z.fixed_rows::<3>(3).into_owned(),
    )
}
