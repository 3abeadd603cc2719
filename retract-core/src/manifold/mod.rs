//! Manifolds in moving charts. A state on a manifold is a chart and a state $z = (x, p)$ of
//! the system written in that chart; a step runs a scheme ([`crate::scheme`]) in the chart
//! centred at the current point, and the chart then moves to the step's end, so the chart
//! coordinates stay small. This layer imports the schemes and the numeric kernels.
//!
//! What the manifolds share is [`MovingChart`]: a chart ([`MovingChart::Chart`]), the point
//! of chart coordinates $y$ and back ([`MovingChart::point`], [`MovingChart::chart_point`]),
//! the transition of a state to the chart centred at a point $a$ of the current one
//! ([`MovingChart::transition`]: the jet by the lift of the change of coordinates, the
//! momenta by its inverse transpose, a cotangent lift and so symplectic), and recentring
//! ([`MovingChart::recentre`], the transition to the state's own point). A generated system
//! whose chart is a parameter is a [`CentredSystem`]; [`recentre_system`] moves the state
//! and the system's chart together.
//!
//! - [`sphere`]: the unit sphere $S^2$ in gnomonic charts ([`sphere::Sphere`]);
//! - [`so3`]: the rotation group in Gibbs charts ([`so3::So3`]), and its Cayley and
//!   exponential midpoint maps;
//! - [`se3`]: the rigid motions in product charts, a Gibbs chart and the position
//!   ([`se3::Se3`]).
//!
//! A new manifold implements [`MovingChart`] (and [`CentredSystem`] for the systems the
//! macro generates on it).

use nalgebra::SVector;

use crate::Error;

pub mod se3;
pub mod so3;
pub mod sphere;

/// A manifold of dimension `D` in moving charts: the charts, the map between a chart's
/// coordinates $y \in \mathbb{R}^D$ and the manifold, and the change of chart of a state
/// $z = (x, p)$ of order $k$ ($x = (y, y', \dots, y^{(k-1)})$, $z \in \mathbb{R}^{2Dk}$).
pub trait MovingChart<const D: usize> {
    /// A chart: where it is centred on the manifold (and, for the sphere, its frame).
    type Chart: Copy;
    /// A point of the manifold.
    type Point;

    /// The point with coordinates `y` in `chart`.
    fn point(chart: &Self::Chart, y: &SVector<f64, D>) -> Self::Point;

    /// The coordinates of `point` in `chart`, the inverse of [`MovingChart::point`]; `None`
    /// where the chart does not reach the point.
    fn chart_point(chart: &Self::Chart, point: &Self::Point) -> Option<SVector<f64, D>>;

    /// The chart centred at the point with coordinates `a` in `chart`, and the state `z` of
    /// order $k$ (`S` $= 2Dk$) written in it: the jet by the derivatives of the change of
    /// coordinates along the curve, the momenta by the inverse transpose of its Jacobian.
    ///
    /// # Errors
    /// When the new chart does not reach the state's point, the change of coordinates is
    /// singular there, or the result is not finite (each manifold's transition says which
    /// [`Error`]).
    fn transition<const K: usize, const S: usize>(
        chart: &Self::Chart,
        a: &SVector<f64, D>,
        z: &SVector<f64, S>,
    ) -> Result<(Self::Chart, SVector<f64, S>), Error>;

    /// Moves the chart of `z` to the state's own point: [`MovingChart::transition`] with
    /// $a = y$, after which $y = 0$ (to rounding). An error (with nothing changed) as for the
    /// transition.
    fn recentre<const K: usize, const S: usize>(
        chart: &mut Self::Chart,
        z: &mut SVector<f64, S>,
    ) -> Result<(), Error> {
        let a = z.fixed_rows::<D>(0).into_owned();
        let (next, moved) = Self::transition::<K, S>(chart, &a, z)?;
        *chart = next;
        *z = moved;
        Ok(())
    }
}

/// A system written in the charts of the manifold `M`, whose chart is a parameter (what
/// `#[higher_order_lagrangian]` generates with `sphere`, `so3` or `se3`).
pub trait CentredSystem<M: MovingChart<D>, const D: usize>: Copy {
    /// The same system written in `chart`.
    fn centred(&self, chart: &M::Chart) -> Self;
}

/// Moves the chart of the state `z` (order $k$) to its own point ([`MovingChart::recentre`])
/// and the chart of `system` with it, so that a step continues in the new chart. An error
/// (nothing changed) as for [`MovingChart::transition`].
pub fn recentre_system<M, Sys, const D: usize, const K: usize, const S: usize>(
    system: &mut Sys,
    chart: &mut M::Chart,
    z: &mut SVector<f64, S>,
) -> Result<(), Error>
where
    M: MovingChart<D>,
    Sys: CentredSystem<M, D>,
{
    M::recentre::<K, S>(chart, z)?;
    *system = system.centred(chart);
    Ok(())
}

/// What the tests of the three manifolds share: seeded numbers and the round trip of a
/// transition.
#[cfg(test)]
mod testing {
    use super::{MovingChart, SVector};

    /// A number in $[-1, 1)$ from a linear congruential generator (Knuth's MMIX constants).
    pub(super) fn uniform(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// A vector with entries `scale` times [`uniform`].
    pub(super) fn vector<const R: usize>(state: &mut u64, scale: f64) -> SVector<f64, R> {
        SVector::from_fn(|_, _| scale * uniform(state))
    }

    /// The transition of `z` from `chart` to the chart centred at `a`, then back to the chart
    /// centred at the old chart's centre: the chart and the state reached.
    pub(super) fn there_and_back<
        M: MovingChart<D>,
        const D: usize,
        const K: usize,
        const S: usize,
    >(
        chart: &M::Chart,
        a: &SVector<f64, D>,
        z: &SVector<f64, S>,
    ) -> (M::Chart, SVector<f64, S>) {
        let (there, moved) = M::transition::<K, S>(chart, a, z).expect("the way there");
        let origin = M::point(chart, &SVector::zeros());
        let back = M::chart_point(&there, &origin).expect("the old centre in the new chart");
        M::transition::<K, S>(&there, &back, &moved).expect("the way back")
    }
}
