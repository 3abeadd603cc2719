//! Manifolds in moving charts. A state on a manifold is a chart and a state $z = (x, p)$ of
//! the system written in that chart; a step runs a scheme ([`crate::scheme`]) in the chart
//! centred at the current point, and the chart then moves to the step's end, so the chart
//! coordinates stay small. This layer imports the schemes and the numeric kernels.
//!
//! - [`sphere`]: the unit sphere $S^2$ in gnomonic charts;
//! - [`so3`]: the rotation group in Gibbs charts, and its Cayley and exponential midpoint
//!   maps;
//! - [`se3`]: the rigid motions in product charts (a Gibbs chart and the position).

pub mod se3;
pub mod so3;
pub mod sphere;
