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

/// `system` with its chart centred at `centre`.
pub fn centred<Sys: Se3System>(system: &Sys, centre: &Isometry3<f64>) -> Sys {
    system.with_centre(centre_pose(centre))
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
    let (y, position) = halves(&x[0]);
    centre * chart_pose(&y, &position)
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
/// $(a, b) = (y, x)$), whose point is 0. An error (with nothing changed) as for
/// [`transition`].
pub fn recentre<const K: usize, const S: usize>(
    centre: &mut Isometry3<f64>,
    z: &mut SVector<f64, S>,
) -> Result<(), Error> {
    let (x, _) = split::<6, K, S>(z);
    let (y, position) = halves(&x[0]);
    let moved = transition::<K, S>(&y, &position, z)?;
    let mut next = *centre * chart_pose(&y, &position);
    next.rotation = UnitQuaternion::new_normalize(next.rotation.into_inner());
    *centre = next;
    *z = moved;
    Ok(())
}

/// Moves the chart of `z` to its own point, as [`recentre`], and the centre of `system` with
/// it. An error (nothing changed) as for [`recentre`].
pub fn recentre_system<Sys: Se3System, const K: usize, const S: usize>(
    system: &mut Sys,
    centre: &mut Isometry3<f64>,
    z: &mut SVector<f64, S>,
) -> Result<(), Error> {
    recentre::<K, S>(centre, z)?;
    *system = centred(system, centre);
    Ok(())
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
