//! Moving charts: a rotation stored as a centre $c$ (a unit quaternion) and a Gibbs chart
//! state whose point $y$ gives the rotation $g = c\thinspace Q(y)$. After each step the chart is
//! moved to the step's end ([`recentre`]), so $y$ stays near 0, where the chart is best
//! conditioned, and a trajectory may turn through any angle.
//!
//! Moving the centre from $c$ to $c\thinspace Q(a)$ changes chart points by the left translation
//! $Q(\phi_a(y)) \propto Q(a)^{-1} Q(y)$:
//!
//! $$\phi_a(y) = \frac{y - a - a \times y}{1 + a \cdot y},$$
//!
//! defined where $1 + a \cdot y \ne 0$ (where the rotation is not a half-turn from the new
//! centre; the sign of $1 + a \cdot y$ is that of the quaternion representative). The jet
//! $(y, y', \dots, y^{(k-1)})$ changes by the derivatives of $\phi_a$ along the curve,
//! $y_{\rm new}^{(j)} = D^j \phi_a(y(t))$, and the momenta by the cotangent lift of that
//! point transformation, $p_{\rm new} = (\partial Y_{\rm new} / \partial Y)^{-T} p$: a
//! symplectic change of coordinates. The Jacobian is block lower triangular with blocks
//! $\partial y^{(j)}_{\rm new} / \partial y^{(i)} = \frac{j!}{i!} c_{j-i}[D\phi_a]$ (the
//! Taylor coefficients of $D\phi_a$ along the curve, as in [`crate::scheme::map::TaylorLift`]).
//! The Cayley midpoint map and a Lagrangian written in body coordinates are both invariant
//! under left translations, so a step commutes with the change of chart: stepping and
//! recentring give the same rotations as stepping in one chart, wherever that chart is
//! defined.

use nalgebra::{Matrix3, Quaternion, SVector, UnitQuaternion, Vector3};

use crate::Error;
use crate::manifold::MovingChart;
use crate::numeric::taylor::{Dual, Scalar, Taylor};
use crate::scheme::lifted::{Blocks, join, split};
use crate::scheme::map::taylor_lift::{curve, falling};

/// $\phi_a(y) = (y - a - a \times y) / (1 + a \cdot y)$: the chart point, in the chart
/// centred at $c\thinspace Q(a)$, of the point $y$ of the chart centred at $c$.
pub fn translate<T: Scalar>(a: &Vector3<f64>, y: [T; 3]) -> [T; 3] {
    let ay = [
        y[2] * a[1] - y[1] * a[2],
        y[0] * a[2] - y[2] * a[0],
        y[1] * a[0] - y[0] * a[1],
    ];
    let den = y[0] * a[0] + y[1] * a[1] + y[2] * a[2] + 1.0;
    core::array::from_fn(|i| (y[i] - ay[i] - a[i]) / den)
}

/// The unit quaternion $Q(y) = (1, y) / \sqrt{1 + |y|^2}$ of the chart point $y$.
pub fn chart_quaternion(y: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(Quaternion::new(1.0, y[0], y[1], y[2]))
}

/// The rotation $c\thinspace Q(y)$ of the chart state `z` (of order $k$) centred at `centre`.
pub fn orientation<const K: usize, const S: usize>(
    centre: &UnitQuaternion<f64>,
    z: &SVector<f64, S>,
) -> UnitQuaternion<f64> {
    const { assert!(K >= 1, "the order k is at least 1") };
    let (x, _) = split::<3, K, S>(z);
    So3::point(centre, &x[0])
}

/// The chart point of the rotation `g` in the chart centred at `centre`:
/// $y = \mathrm{vec}(c^{-1} g) / \mathrm{re}(c^{-1} g)$; `None` for a half-turn from the
/// centre (where no Gibbs chart centred there reaches).
pub fn chart_point(centre: &UnitQuaternion<f64>, g: &UnitQuaternion<f64>) -> Option<Vector3<f64>> {
    let relative = centre.inverse() * g;
    let w = relative.w;
    (w.abs() > 1e-12).then(|| relative.imag() / w)
}

/// The state `z` (of order $k$: jet and momenta of $y$) in the chart centred at
/// $c\thinspace Q(a)$ instead of $c$ (module docs): the jet by $D^j \phi_a$, the momenta by the
/// inverse transpose of its Jacobian. An error if the rotation is a half-turn from the new
/// centre ($|1 + a \cdot y| \le 10^{-12} (1 + |a| |y|)$, where no Gibbs chart centred there
/// reaches) or the result is not finite.
pub fn transition<const K: usize, const S: usize>(
    a: &Vector3<f64>,
    z: &SVector<f64, S>,
) -> Result<SVector<f64, S>, Error> {
    const { assert!(K >= 1, "the order k is at least 1") };
    let (x, p) = split::<3, K, S>(z);
    let (jet, momenta) = transition_blocks(a, &x, &p)?;
    let out = join::<3, K, S>(&jet, &momenta);
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(Error::NonFinite {
            iteration: 0,
            location: "chart transition",
        })
    }
}

/// [`transition`] of the jet `x` and the momenta `p` (blocks of order 0..k-1), without the
/// finiteness test of the result.
pub(crate) fn transition_blocks<const K: usize>(
    a: &Vector3<f64>,
    x: &Blocks<3, K>,
    p: &Blocks<3, K>,
) -> Result<(Blocks<3, K>, Blocks<3, K>), Error> {
    let den = 1.0 + a.dot(&x[0]);
    if den.is_nan() || den.abs() <= 1e-12 * (1.0 + a.norm() * x[0].norm()) {
        return Err(Error::InvalidArgument {
            name: "z",
            requirement: "a rotation that is not a half-turn from the new centre \
                          (1 + a . y != 0)",
        });
    }
    let series: [Taylor<Dual<3>, K>; 3] =
        translate(a, curve::<Dual<3>, 3, K>(x, 0, Dual::variable));
    // the new jet, and the diagonal block (D phi at y) and those below it
    let jet: Blocks<3, K> =
        core::array::from_fn(|j| Vector3::from_fn(|c, _| series[c].c[j].f * falling(j, 0)));
    let block = |j: usize, i: usize| -> Matrix3<f64> {
        let scale = falling(j, i);
        Matrix3::from_fn(|c, b| scale * series[c].c[j - i].g[b])
    };
    let Some(inverse_t) = block(0, 0).transpose().try_inverse() else {
        return Err(Error::SingularJacobian { iteration: 0 });
    };
    // J^T p_new = p, J block lower triangular: back substitution from the top derivative
    let mut momenta: Blocks<3, K> = [Vector3::zeros(); K];
    for i in (0..K).rev() {
        let mut rhs = p[i];
        for (j, pj) in momenta.iter().enumerate().skip(i + 1) {
            rhs -= block(j, i).transpose() * pj;
        }
        momenta[i] = inverse_t * rhs;
    }
    Ok((jet, momenta))
}

/// Moves the chart of `z` to its own point: `centre` becomes $c\thinspace Q(y)$ (renormalised) and
/// `z` the same state in that chart ([`transition`] with $a = y$), whose point is 0
/// ([`So3`]'s [`MovingChart::recentre`]). An error (with nothing changed) if `z` is not
/// finite.
pub fn recentre<const K: usize, const S: usize>(
    centre: &mut UnitQuaternion<f64>,
    z: &mut SVector<f64, S>,
) -> Result<(), Error> {
    So3::recentre::<K, S>(centre, z)
}

/// The rotation group in moving Gibbs charts: a chart is its centre $c$ (a unit
/// quaternion), the point of the chart coordinates $y$ is the rotation $c\thinspace Q(y)$, and
/// the transition to the chart centred at $c\thinspace Q(a)$ is [`transition`] (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct So3;

impl MovingChart<3> for So3 {
    type Chart = UnitQuaternion<f64>;
    type Point = UnitQuaternion<f64>;

    /// The rotation $c\thinspace Q(y)$.
    fn point(chart: &UnitQuaternion<f64>, y: &Vector3<f64>) -> UnitQuaternion<f64> {
        chart * chart_quaternion(y)
    }

    /// [`chart_point`]: `None` for a half-turn from the centre.
    fn chart_point(chart: &UnitQuaternion<f64>, g: &UnitQuaternion<f64>) -> Option<Vector3<f64>> {
        chart_point(chart, g)
    }

    /// The centre $c\thinspace Q(a)$ (renormalised) and [`transition`] of `z`.
    fn transition<const K: usize, const S: usize>(
        chart: &UnitQuaternion<f64>,
        a: &Vector3<f64>,
        z: &SVector<f64, S>,
    ) -> Result<(UnitQuaternion<f64>, SVector<f64, S>), Error> {
        let moved = transition::<K, S>(a, z)?;
        let next =
            UnitQuaternion::new_normalize(chart.into_inner() * chart_quaternion(a).into_inner());
        Ok((next, moved))
    }
}

/// The spatial angular momentum (the Noether momentum of left multiplication, in the world
/// frame) of the chart state `z` of order $k$ centred at `centre`: $R(c)\thinspace M$ with
/// $M_a = \sum_j p_j \cdot D^j[\delta_a y]$, where $\delta_a y = \tfrac12 (e_a + e_a
/// \times y + (e_a \cdot y)\thinspace y)$ is the chart velocity of $Q \mapsto (1, \epsilon e_a / 2)
/// Q$. At $k = 1$ and $c = 1$ it is [`super::spatial_momentum`]. The lifted Cayley midpoint
/// map conserves it for a Lagrangian written in body coordinates.
pub fn world_momentum<const K: usize, const S: usize>(
    centre: &UnitQuaternion<f64>,
    z: &SVector<f64, S>,
) -> Vector3<f64> {
    let (x, p) = split::<3, K, S>(z);
    centre * chart_momentum(&x, &p)
}

/// The angular momentum of [`world_momentum`] in the centre's axes, of the jet `x` and the
/// momenta `p` of the Gibbs chart: $M_a = \sum_j p_j \cdot D^j[\delta_a y]$.
pub(crate) fn chart_momentum<const K: usize>(x: &Blocks<3, K>, p: &Blocks<3, K>) -> Vector3<f64> {
    let y: [Taylor<f64, K>; 3] =
        core::array::from_fn(|c| Taylor::from_derivatives(core::array::from_fn(|j| x[j][c])));
    Vector3::from_fn(|a, _| {
        // delta_a y = (e_a + e_a x y + y_a y) / 2
        let e_cross_y = [
            [Taylor::constant(0.0), -y[2], y[1]],
            [y[2], Taylor::constant(0.0), -y[0]],
            [-y[1], y[0], Taylor::constant(0.0)],
        ][a];
        let delta: [Taylor<f64, K>; 3] = core::array::from_fn(|c| {
            let unit = if c == a { 1.0 } else { 0.0 };
            (e_cross_y[c] + y[a] * y[c] + unit) * 0.5
        });
        let d = delta.map(|s| s.derivatives());
        (0..K)
            .map(|j| (0..3).map(|c| p[j][c] * d[c][j]).sum::<f64>())
            .sum::<f64>()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifold::testing::{there_and_back, vector};

    /// A rotation from a seeded axis-angle vector (angles up to $\pi$).
    fn rotation(seed: &mut u64) -> UnitQuaternion<f64> {
        UnitQuaternion::from_scaled_axis(vector::<3>(seed, 1.8))
    }

    #[test]
    fn a_transition_there_and_back_is_the_identity() {
        let mut seed = 7;
        for _ in 0..50 {
            let centre = rotation(&mut seed);
            let z: SVector<f64, 12> = vector(&mut seed, 1.0);
            let a: Vector3<f64> = vector(&mut seed, 0.5);
            let (back, z_back) = there_and_back::<So3, 3, 2, 12>(&centre, &a, &z);
            assert!(back.angle_to(&centre) < 1e-12, "{back} {centre}");
            assert!((z_back - z).amax() < 1e-12, "{z_back} {z}");
        }
    }

    #[test]
    fn recentring_puts_the_point_at_the_origin_and_keeps_the_rotation() {
        let mut seed = 11;
        for _ in 0..50 {
            let mut centre = rotation(&mut seed);
            let mut z: SVector<f64, 12> = vector(&mut seed, 1.0);
            let before = orientation::<2, 12>(&centre, &z);
            let momentum = world_momentum::<2, 12>(&centre, &z);
            So3::recentre::<2, 12>(&mut centre, &mut z).unwrap();
            assert_eq!(z.fixed_rows::<3>(0).into_owned(), Vector3::zeros());
            assert!(centre.angle_to(&before) < 1e-12);
            // the spatial momentum is a function on the cotangent bundle, whatever the chart
            let after = world_momentum::<2, 12>(&centre, &z);
            assert!((after - momentum).amax() < 1e-12 * (1.0 + momentum.amax()));
        }
    }

    #[test]
    fn chart_points_invert_points() {
        let mut seed = 3;
        let centre = rotation(&mut seed);
        let y: Vector3<f64> = vector(&mut seed, 2.0);
        let g = So3::point(&centre, &y);
        let back = So3::chart_point(&centre, &g).unwrap();
        assert!((back - y).amax() < 1e-12 * (1.0 + y.amax()), "{back} {y}");
    }
}
