//! The rigid motions SE(3) in moving product charts: a pose $g = (R, p)$ stored as a centre
//! $(C, c)$ (an [`Isometry3`]) and a chart state of dimension 6 whose point $(y, x)$ gives
//! the pose by left translation of the chart at the identity,
//!
//! $$g = (C, c)\thinspace(Q(y), x) = (C\thinspace Q(y),\thickspace c + C x),$$
//!
//! with $Q$ the Gibbs chart of [`crate::manifold::so3`]. The body velocity is
//! $\xi = (\Omega, v)$ with $\Omega = 2 (y' - y \times y') / (1 + |y|^2)$ and
//! $v = R^T p' = Q(y)^T x'$, the same in every chart.
//!
//! `#[higher_order_lagrangian(order = k, se3)]` takes L(g, xi, ..., xi^(k-1)) and composes it
//! with this chart, centred at a parameter of the generated type ([`Se3System`]). Moving the
//! centre from $(C, c)$ to $(C, c)(Q(a), b)$ changes chart points by
//! $(y, x) \mapsto (\phi_a(y), Q(a)^T (x - b))$: the Gibbs chart's transition
//! ([`crate::manifold::so3::translate`]) and a rigid motion of the position, so the jet and the momenta
//! change block by block ([`transition`]), and a step of a left-invariant discretization map
//! (the Cayley map on $y$ with the midpoint rule on $x$) commutes with the change.

use nalgebra::{Isometry3, Matrix3, SVector, Translation3, UnitQuaternion, Vector3};

use crate::Error;
use crate::manifold::so3::{chart_momentum, chart_quaternion, transition_blocks};
use crate::manifold::{CentredSystem, MovingChart};
use crate::scheme::lifted::{Blocks, join, split};

/// A generated Lagrangian or jet function on SE(3) (`se3`): a system on $\mathbb{R}^6$, the
/// product chart, whose centre $(C, c)$ is a parameter.
pub trait Se3System: Copy {
    /// The centre: $C$ row major ($g_{3i + j} = C_{ij}$), then $c$ ($g_{9 + i} = c_i$).
    fn centre(&self) -> [f64; 12];
    /// The same system with its chart centred at the pose `centre` (laid out as
    /// [`Se3System::centre`]).
    fn with_centre(&self, centre: [f64; 12]) -> Self;
}

/// The pose `centre` laid out as the parameter of [`Se3System`]: its rotation matrix row
/// major, then its translation.
pub fn centre_pose(centre: &Isometry3<f64>) -> [f64; 12] {
    let r = centre.rotation.to_rotation_matrix().into_inner();
    let c = centre.translation.vector;
    core::array::from_fn(|e| if e < 9 { r[(e / 3, e % 3)] } else { c[e - 9] })
}

/// `system` with its chart centred at `centre` ([`CentredSystem::centred`]).
pub fn centred<Sys: Se3System>(system: &Sys, centre: &Isometry3<f64>) -> Sys {
    CentredSystem::<Se3, 6>::centred(system, centre)
}

/// A system on SE(3) is written in the chart centred at any pose: its centre parameter is
/// the pose laid out by [`centre_pose`].
impl<Sys: Se3System> CentredSystem<Se3, 6> for Sys {
    fn centred(&self, chart: &Isometry3<f64>) -> Self {
        self.with_centre(centre_pose(chart))
    }
}

/// The rigid motions in moving product charts: a chart is its centre $(C, c)$ (an
/// [`Isometry3`]), the point of the chart coordinates $(y, x)$ is the pose
/// $(C, c)(Q(y), x)$, and the transition to the chart centred at $(C, c)(Q(a), b)$ is
/// [`transition`] (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Se3;

impl MovingChart<6> for Se3 {
    type Chart = Isometry3<f64>;
    type Point = Isometry3<f64>;

    /// The pose $(C, c)(Q(y), x)$.
    fn point(chart: &Isometry3<f64>, point: &SVector<f64, 6>) -> Isometry3<f64> {
        let (y, position) = halves(point);
        chart * chart_pose(&y, &position)
    }

    /// [`chart_point`]: `None` for a rotation a half-turn from the centre's.
    fn chart_point(chart: &Isometry3<f64>, g: &Isometry3<f64>) -> Option<SVector<f64, 6>> {
        chart_point(chart, g)
    }

    /// The centre $(C, c)(Q(a), b)$ (its quaternion renormalised) and [`transition`] of `z`,
    /// with `a` $= (a, b)$.
    fn transition<const K: usize, const S: usize>(
        chart: &Isometry3<f64>,
        a: &SVector<f64, 6>,
        z: &SVector<f64, S>,
    ) -> Result<(Isometry3<f64>, SVector<f64, S>), Error> {
        let (a, b) = halves(a);
        let moved = transition::<K, S>(&a, &b, z)?;
        let mut next = chart * chart_pose(&a, &b);
        next.rotation = UnitQuaternion::new_normalize(next.rotation.into_inner());
        Ok((next, moved))
    }
}

/// The chart point $(y, x)$ of the pose $(Q(y), x)$ relative to the chart's centre.
fn chart_pose(y: &Vector3<f64>, x: &Vector3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(*x), chart_quaternion(y))
}

/// The pose $(C, c)(Q(y), x)$ of the chart state `z` (of order $k$, dimension 6: $y$ then
/// $x$) centred at `centre`.
pub fn pose<const K: usize, const S: usize>(
    centre: &Isometry3<f64>,
    z: &SVector<f64, S>,
) -> Isometry3<f64> {
    const { assert!(K >= 1, "the order k is at least 1") };
    let (x, _) = split::<6, K, S>(z);
    Se3::point(centre, &x[0])
}

/// The chart point $(y, x)$ of the pose `g` in the chart centred at `centre`:
/// $y$ of [`crate::manifold::so3::chart_point`] and $x = C^T (p - c)$; `None` for a rotation a
/// half-turn from the centre's.
pub fn chart_point(centre: &Isometry3<f64>, g: &Isometry3<f64>) -> Option<SVector<f64, 6>> {
    let relative = centre.inverse() * g;
    let w = relative.rotation.w;
    (w.abs() > 1e-12).then(|| {
        let (y, x) = (relative.rotation.imag() / w, relative.translation.vector);
        SVector::<f64, 6>::from_iterator(y.iter().chain(x.iter()).copied())
    })
}

/// The rotation and position parts $(y, x)$ of a chart vector.
fn halves(v: &SVector<f64, 6>) -> (Vector3<f64>, Vector3<f64>) {
    (
        v.fixed_rows::<3>(0).into_owned(),
        v.fixed_rows::<3>(3).into_owned(),
    )
}

/// The blocks of `v` split into their rotation and position parts.
fn split_blocks<const K: usize>(v: &Blocks<6, K>) -> (Blocks<3, K>, Blocks<3, K>) {
    (
        core::array::from_fn(|j| halves(&v[j]).0),
        core::array::from_fn(|j| halves(&v[j]).1),
    )
}

/// The blocks of dimension 6 with rotation parts `y` and position parts `x`.
fn join_blocks<const K: usize>(y: &Blocks<3, K>, x: &Blocks<3, K>) -> Blocks<6, K> {
    core::array::from_fn(|j| {
        SVector::<f64, 6>::from_iterator(y[j].iter().chain(x[j].iter()).copied())
    })
}

/// The state `z` (of order $k$) in the chart centred at $(C, c)(Q(a), b)$ instead of
/// $(C, c)$ (module docs): the rotation part by [`crate::manifold::so3::transition`], the position's
/// jet $x \mapsto Q(a)^T (x - b)$ and $x^{(j)} \mapsto Q(a)^T x^{(j)}$, its momenta
/// $p \mapsto Q(a)^T p$ (the inverse transpose of an orthogonal map). An error if the
/// rotation is a half-turn from the new centre's or the result is not finite.
pub fn transition<const K: usize, const S: usize>(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    z: &SVector<f64, S>,
) -> Result<SVector<f64, S>, Error> {
    const { assert!(K >= 1, "the order k is at least 1") };
    let (x, p) = split::<6, K, S>(z);
    let ((y, mut position), (py, mut px)) = (split_blocks(&x), split_blocks(&p));
    let (y, py) = transition_blocks(a, &y, &py)?;
    let back: Matrix3<f64> = chart_quaternion(a)
        .to_rotation_matrix()
        .into_inner()
        .transpose();
    position[0] -= b;
    for j in 0..K {
        position[j] = back * position[j];
        px[j] = back * px[j];
    }
    let out = join::<6, K, S>(&join_blocks(&y, &position), &join_blocks(&py, &px));
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(Error::NonFinite {
            iteration: 0,
            location: "chart transition",
        })
    }
}

/// Moves the chart of `z` to its own point: `centre` becomes $(C, c)(Q(y), x)$ (its
/// quaternion renormalised) and `z` the same state in that chart ([`transition`] with
/// $(a, b) = (y, x)$), whose point is 0 ([`Se3`]'s [`MovingChart::recentre`]). An error
/// (with nothing changed) as for [`transition`].
pub fn recentre<const K: usize, const S: usize>(
    centre: &mut Isometry3<f64>,
    z: &mut SVector<f64, S>,
) -> Result<(), Error> {
    Se3::recentre::<K, S>(centre, z)
}

/// Moves the chart of `z` to its own point, as [`recentre`], and the centre of `system` with
/// it ([`crate::manifold::recentre_system`]). An error (nothing changed) as for
/// [`recentre`].
pub fn recentre_system<Sys: Se3System, const K: usize, const S: usize>(
    system: &mut Sys,
    centre: &mut Isometry3<f64>,
    z: &mut SVector<f64, S>,
) -> Result<(), Error> {
    crate::manifold::recentre_system::<Se3, Sys, 6, K, S>(system, centre, z)
}

/// The spatial momentum (the Noether momentum of left multiplication, in world axes) of the
/// chart state `z` of order $k$ centred at `centre` $= (C, c)$: the linear part
/// $P = C\thinspace p_{x,0}$ (translations move $x$ by a constant) and the angular part about the
/// world origin $L = C \big(M + \sum_j w_j \times p_{x,j}\big)$ with $M$ the Gibbs chart's
/// ([`crate::manifold::so3::world_momentum`] in the centre's axes), $w_0 = C^T c + x$ and
/// $w_j = x^{(j)}$ (a rotation $\omega$ moves $x$ by $C^T\omega \times (C^T c + x)$). A
/// Lagrangian written in body coordinates conserves both, and so do the steps of the
/// left-invariant map. Returns $(L, P)$.
pub fn spatial_momentum<const K: usize, const S: usize>(
    centre: &Isometry3<f64>,
    z: &SVector<f64, S>,
) -> (Vector3<f64>, Vector3<f64>) {
    let (x, p) = split::<6, K, S>(z);
    let ((y, position), (py, px)) = (split_blocks(&x), split_blocks(&p));
    let mut angular = chart_momentum(&y, &py);
    let origin = centre.rotation.inverse() * centre.translation.vector;
    for j in 0..K {
        let w = if j == 0 {
            origin + position[0]
        } else {
            position[j]
        };
        angular += w.cross(&px[j]);
    }
    (centre.rotation * angular, centre.rotation * px[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifold::testing::{there_and_back, vector};

    /// A pose from a seeded axis-angle vector and translation.
    fn pose_at(seed: &mut u64) -> Isometry3<f64> {
        let rotation = UnitQuaternion::from_scaled_axis(vector::<3>(seed, 1.8));
        Isometry3::from_parts(Translation3::from(vector::<3>(seed, 3.0)), rotation)
    }

    #[test]
    fn a_transition_there_and_back_is_the_identity() {
        let mut seed = 5;
        for _ in 0..50 {
            let centre = pose_at(&mut seed);
            let z: SVector<f64, 24> = vector(&mut seed, 1.0);
            let a: SVector<f64, 6> = vector(&mut seed, 0.5);
            let (back, z_back) = there_and_back::<Se3, 6, 2, 24>(&centre, &a, &z);
            assert!(back.rotation.angle_to(&centre.rotation) < 1e-12);
            assert!((back.translation.vector - centre.translation.vector).amax() < 1e-12);
            assert!((z_back - z).amax() < 1e-12, "{z_back} {z}");
        }
    }

    #[test]
    fn recentring_puts_the_point_at_the_origin_and_keeps_the_pose() {
        let mut seed = 13;
        for _ in 0..50 {
            let mut centre = pose_at(&mut seed);
            let mut z: SVector<f64, 24> = vector(&mut seed, 1.0);
            let before = pose::<2, 24>(&centre, &z);
            let (angular, linear) = spatial_momentum::<2, 24>(&centre, &z);
            Se3::recentre::<2, 24>(&mut centre, &mut z).unwrap();
            assert!(z.fixed_rows::<6>(0).amax() < 1e-15, "{z}");
            assert!(centre.rotation.angle_to(&before.rotation) < 1e-12);
            assert!((centre.translation.vector - before.translation.vector).amax() < 1e-12);
            let (angular_after, linear_after) = spatial_momentum::<2, 24>(&centre, &z);
            let scale = 1.0 + angular.amax() + linear.amax();
            assert!((angular_after - angular).amax() < 1e-12 * scale);
            assert!((linear_after - linear).amax() < 1e-12 * scale);
        }
    }
}
