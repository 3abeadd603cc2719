// the README with its figures embedded as data URIs (build.rs), so they show on docs.rs
#![doc = include_str!(concat!(env!("OUT_DIR"), "/README.md"))]
#![cfg_attr(not(feature = "std"), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub use retract_core::*;

// the generated items name `::retract`, also inside this crate (`sphere`)
extern crate self as retract;

#[cfg(feature = "plot")]
pub mod plot;
pub mod se3;
pub mod so3;
pub mod sphere;

// The long form of the README (`docs/`): its Rust code blocks are doctests like the README's.
// (`docs/benchmarks.md`, `docs/paper-notes.md` and `docs/architecture.md` have none.)
#[cfg(doctest)]
#[doc = include_str!("../docs/guide.md")]
pub struct GuideDoctests;

/// A runnable example: an obstacle course's Lagrangian, stepped once.
///
/// ```
/// use retract::nalgebra::SVector;
/// use retract::{LiftedSystem, StepOptions, higher_order_lagrangian, step};
///
/// #[higher_order_lagrangian(order = 2)]
/// fn obstacle(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
///     0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
/// }
///
/// let system = Obstacle::new(1e-3); // the type is named after the function
/// assert_eq!((Obstacle::DIMENSION, Obstacle::ORDER, Obstacle::STATE), (2, 2, 8));
/// // the function stays callable: L at q = (2, 0) at rest
/// assert!((obstacle([2.0, 0.0], [0.0; 2], [0.0; 2], 1e-3) - 1e-3 / 3.0).abs() < 1e-18);
/// let z0 = system.legendre(&SVector::from([2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0]));
/// let (z1, _) = step(&system, &z0, 0.01, &StepOptions::default())?;
/// assert!((z1[1] - 0.01).abs() < 1e-6); // moving up at unit speed
/// # Ok::<(), retract::Error>(())
/// ```
#[doc(inline)]
pub use retract_macros::higher_order_lagrangian;

/// A runnable example: the pole torque of a cart-pole as a stage constraint.
///
/// ```
/// use retract::nalgebra::SVector;
/// use retract::{JetFunction, jet_function};
///
/// #[jet_function(order = 2)]
/// fn pole_torque(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], mp: f64, l: f64, g: f64) -> f64 {
///     mp * l * q[1].cos() * ddq[0] + mp * l * l * ddq[1] + mp * g * l * q[1].sin()
/// }
///
/// let tau = PoleTorque::new(0.3, 0.5, 9.81);
/// let x = [SVector::from([0.0, 0.2]), SVector::zeros()];
/// let u = SVector::from([1.0, -2.0]);
/// // linear in q'': its gradient in u is (mp l cos q1, mp l^2)
/// let g = tau.gradient(&x, &u);
/// assert!((g.u[0] - 0.15 * 0.2f64.cos()).abs() < 1e-15 && (g.u[1] - 0.075).abs() < 1e-15);
/// ```
#[doc(inline)]
pub use retract_macros::jet_function;

/// A runnable example: one torque formula shared by a cost and a constraint.
/// ```
/// use retract::nalgebra::SVector;
/// use retract::{JetFunction, Lagrangian, helper, higher_order_lagrangian, jet_function};
///
/// /// The torques of a point mass on two joints (a toy M(q) q'' + G(q)).
/// #[helper]
/// fn torque(q: [f64; 2], ddq: [f64; 2]) -> [f64; 2] {
///     [2.0 * ddq[0] + q[1].cos() * ddq[1] + q[0].sin(), ddq[1] + q[1].sin()]
/// }
///
/// /// The effort: L = 1/2 |tau|^2.
/// #[higher_order_lagrangian(order = 2, helpers = [torque])]
/// fn effort(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
///     let tau = torque(q, ddq);
///     0.5 * (tau[0] * tau[0] + tau[1] * tau[1])
/// }
///
/// /// The first joint passive.
/// #[jet_function(order = 2, helpers = [torque])]
/// fn shoulder(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
///     torque(q, ddq)[0]
/// }
///
/// let (x, u) = ([SVector::from([0.3, 0.1]), SVector::zeros()], SVector::from([1.0, 2.0]));
/// let t = torque([0.3, 0.1], [1.0, 2.0]); // still a plain function
/// assert!((Effort.lagrangian(&x, &u) - 0.5 * (t[0] * t[0] + t[1] * t[1])).abs() < 1e-14);
/// assert!((Shoulder.value(&x, &u) - t[0]).abs() < 1e-15);
/// ```
#[doc(inline)]
pub use retract_macros::helper;

/// A runnable example: the symmetric "bent midpoint" map lifted to order 2, stepping the
/// Pais-Uhlenbeck oscillator with [`map::step`].
///
/// ```
/// use retract::nalgebra::SVector;
/// use retract::map::{self, DiscretizationMap};
/// use retract::{LiftedSystem, NewtonOptions, discretization_map, higher_order_lagrangian};
///
/// #[discretization_map(order = 2)]
/// fn bent_midpoint(q: [f64; 2], v: [f64; 2], c: f64) -> ([f64; 2], [f64; 2]) {
///     let s = c * q[0].sin();
///     (
///         [q[0] - 0.5 * v[0] + s * v[0] * v[0], q[1] - 0.5 * v[1] + s * v[1] * v[1]],
///         [q[0] + 0.5 * v[0] + s * v[0] * v[0], q[1] + 0.5 * v[1] + s * v[1] * v[1]],
///     )
/// }
///
/// #[higher_order_lagrangian(order = 2)]
/// fn pais_uhlenbeck(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 {
///     0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) - 0.5 * (dq[0].powi(2) + dq[1].powi(2))
///         + 0.5 * (q[0].powi(2) + q[1].powi(2))
/// }
///
/// let map = BentMidpoint::new(0.3);
/// // block 1 of the lifted R2 is D R2 = q' + v'/2 + ...
/// let x = [SVector::from([0.1, 0.2]), SVector::from([0.3, -0.1])];
/// let xi = [SVector::zeros(), SVector::from([0.5, 0.4])];
/// let (_, r2) = map.points(&x, &xi);
/// assert!((r2[1] - (x[1] + xi[1] * 0.5)).amax() < 1e-15);
///
/// let system = PaisUhlenbeck {};
/// let z0 = system.legendre(&SVector::<f64, 8>::from_fn(|r, _| 0.1 * (r as f64 + 1.0).sin()));
/// let (z1, report) = map::step(&system, &map, &z0, 0.01, &NewtonOptions::default())?;
/// assert!((z1 - z0).amax() < 0.1 && report.iterations <= 6);
/// # Ok::<(), retract::Error>(())
/// ```
#[doc(inline)]
pub use retract_macros::discretization_map;

/// A runnable example: the cart-pole written as its energy, its inverse dynamics, and the
/// swing-up posed with the pole unactuated.
///
/// ```
/// use retract::nalgebra::SVector;
/// use retract::{Lagrangian, OptimalControlProblem, mechanical_system};
///
/// /// Cart x, pole angle th from the downward vertical: l = T - V.
/// #[mechanical_system(actuated = [0])]
/// fn cart_pole(q: [f64; 2], dq: [f64; 2], mc: f64, mp: f64, l: f64, g: f64) -> f64 {
///     let kinetic = 0.5 * (mc + mp) * dq[0] * dq[0]
///         + mp * l * q[1].cos() * dq[0] * dq[1]
///         + 0.5 * mp * l * l * dq[1] * dq[1];
///     kinetic + mp * g * l * q[1].cos()
/// }
///
/// let system = CartPole::new(1.0, 0.3, 0.5, 9.81);
/// let (q, dq, ddq) = (SVector::from([0.0, 0.4]), SVector::from([0.1, -0.2]), SVector::from([1.0, 2.0]));
/// // the pole's torque: mp l cos(th) x'' + mp l^2 th'' + mp g l sin(th)
/// let pole = 0.15 * 0.4f64.cos() + 0.075 * 2.0 + 0.15 * 9.81 * 0.4f64.sin();
/// assert!((system.tau(&q, &dq, &ddq)[1] - pole).abs() < 1e-14);
/// assert!((system.mass_matrix(&q, &dq)[(1, 1)] - 0.075).abs() < 1e-15);
/// // the cost is 1/2 tau_0^2, the pole's torque an equality
/// let cart = system.tau(&q, &dq, &ddq)[0];
/// assert!((system.lagrangian(&[q, dq], &ddq) - 0.5 * cart * cart).abs() < 1e-14);
/// let passive = system.unactuated_torques();
/// let problem = OptimalControlProblem::new(&system, &[0.0; 4], &[0.0, 0.5, 0.0, 0.0], 1.0, 50)
///     .with_equalities(&passive);
/// # let _ = problem;
/// // the plant: one forced midpoint step under the cart force u = 2
/// let plant = system.plant();
/// let z0 = retract::LiftedSystem::legendre(&plant, &SVector::from([0.0, 0.4, 0.0, 0.0]));
/// let force = system.input_force(&SVector::from([0.0, 0.4]), &SVector::from([2.0]));
/// let (z1, _) = retract::forced::forced_step(&plant, &z0, &force, 0.01, &Default::default())?;
/// assert!(z1[0] > 0.0); // the cart moves forward
/// # Ok::<(), retract::Error>(())
/// ```
#[doc(inline)]
pub use retract_macros::mechanical_system;

#[doc(hidden)]
pub mod __private {
    pub use retract_core;
    pub use retract_core::Float;
    pub use retract_core::nalgebra;
    pub use retract_macros::expand_with_helpers;
}
