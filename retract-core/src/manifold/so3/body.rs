//! Systems written in body coordinates: `#[higher_order_lagrangian(order = k, so3)]` takes
//! L(R, Omega, ..., Omega^(k-1)) (the rotation and the body angular velocity with its
//! derivatives) and composes it with the Gibbs chart centred at a rotation $C$, a parameter
//! of the generated type ([`So3System`]): $R = C\thinspace Q(y)$ and
//! $\Omega = 2 (y' - y \times y') / (1 + |y|^2)$.
//!
//! Moving the centre with the chart keeps the composed Lagrangian: for the centre
//! $C\thinspace Q(a)$ and the translated jet $\phi_a(y)$ ([`super::transition`]), $C\thinspace Q(a)\thinspace
//! Q(\phi_a(y)) = C\thinspace Q(y)$ and the body velocity is unchanged, so [`recentre_system`] moves
//! the state and the system's centre together, and a step in the new chart continues the
//! step of the old one, also when L depends on R (a potential, a pointing constraint).

use nalgebra::{SVector, UnitQuaternion, Vector3};

use super::moving::So3;
use crate::manifold::CentredSystem;
use crate::scheme::lifted::join;
use crate::{Error, Lagrangian};

/// A generated Lagrangian or jet function on SO(3) (`so3`): a system on $\mathbb{R}^3$,
/// the Gibbs chart, whose centre $C$ is a parameter.
pub trait So3System: Copy {
    /// The centre $C$: a rotation matrix, row major ($c_{3i + j} = C_{ij}$).
    fn centre(&self) -> [f64; 9];
    /// The same system with its chart centred at the rotation matrix `centre` (row major).
    fn with_centre(&self, centre: [f64; 9]) -> Self;
}

/// The rotation matrix of `rotation`, row major ($c_{3i + j} = R_{ij}$): the centre
/// parameter of [`So3System`].
pub fn centre_matrix(rotation: &UnitQuaternion<f64>) -> [f64; 9] {
    let r = rotation.to_rotation_matrix().into_inner();
    core::array::from_fn(|e| r[(e / 3, e % 3)])
}

/// `system` with its chart centred at `centre` ([`CentredSystem::centred`]).
pub fn centred<Sys: So3System>(system: &Sys, centre: &UnitQuaternion<f64>) -> Sys {
    CentredSystem::<So3, 3>::centred(system, centre)
}

/// A system on SO(3) is written in the chart centred at any rotation: its centre parameter
/// is the rotation matrix of the chart's centre ([`centre_matrix`]).
impl<Sys: So3System> CentredSystem<So3, 3> for Sys {
    fn centred(&self, chart: &UnitQuaternion<f64>) -> Self {
        self.with_centre(centre_matrix(chart))
    }
}

/// Moves the chart of the state `z` (order $k$) to its own point, as
/// [`recentre`](super::recentre), and the
/// centre of `system` with it: afterwards $y = 0$, `centre` is the state's rotation and
/// `system` is centred there ([`crate::manifold::recentre_system`]). An error (nothing
/// changed) as for [`recentre`](super::recentre).
pub fn recentre_system<Sys: So3System, const K: usize, const S: usize>(
    system: &mut Sys,
    centre: &mut UnitQuaternion<f64>,
    z: &mut SVector<f64, S>,
) -> Result<(), Error> {
    crate::manifold::recentre_system::<So3, Sys, 3, K, S>(system, centre, z)
}

/// The derivatives $(y', \dots, y^{(J)})$ of the chart curve through the chart point `y`
/// whose body velocity has the derivatives `rates` $= (\Omega, \Omega', \dots,
/// \Omega^{(J-1)})$: the Taylor coefficients $c_m = y^{(m)}/m!$ of
/// $y' = \tfrac12 (\Omega + y \times \Omega + (y \cdot \Omega)\thinspace y)$ (the inverse of
/// $\Omega = 2 (y' - y \times y') / (1 + |y|^2)$), solved order by order:
/// $c_{m+1} = \tfrac{1}{2(m+1)} \big(w_m + \sum_{i+j=m} c_i \times w_j
/// + \sum_{i+j+l=m} (c_i \cdot w_j)\thinspace c_l\big)$ with $w_j = \Omega^{(j)}/j!$.
pub fn chart_derivatives<const J: usize>(
    y: &Vector3<f64>,
    rates: &[Vector3<f64>; J],
) -> [Vector3<f64>; J] {
    const { assert!(J <= 8, "at most 8 derivatives (k <= 4)") };
    let mut factorial = 1.0;
    let w: [Vector3<f64>; J] = core::array::from_fn(|j| {
        factorial *= if j == 0 { 1.0 } else { j as f64 };
        rates[j] / factorial
    });
    // c[m], m = 0..=J, filled in order
    let mut c = [Vector3::zeros(); 9];
    c[0] = *y;
    for m in 0..J {
        let mut f = w[m];
        for i in 0..=m {
            f += c[i].cross(&w[m - i]);
            for j in 0..=m - i {
                f += c[i].dot(&w[j]) * c[m - i - j];
            }
        }
        c[m + 1] = f / (2.0 * (m + 1) as f64);
    }
    let mut factorial = 1.0;
    core::array::from_fn(|j| {
        factorial *= (j + 1) as f64;
        c[j + 1] * factorial
    })
}

/// The state $z = (x, p)$ of order $k$ at the centre of `system` ($y = 0$, the rotation
/// $C$) with the body velocity's derivatives `rates` $= (\Omega, \dots,
/// \Omega^{(2k-2)})$: the chart jet $(0, y', \dots, y^{(2k-1)})$ by [`chart_derivatives`],
/// the momenta by the Legendre map. An error if a momentum is not finite.
pub fn body_state<Sys, const K: usize, const S: usize, const J: usize>(
    system: &Sys,
    rates: &[Vector3<f64>; J],
) -> Result<SVector<f64, S>, Error>
where
    Sys: Lagrangian<3, K>,
{
    const {
        assert!(
            J + 1 == 2 * K && S == 6 * K && K <= 4,
            "rates holds Omega, ..., Omega^(2k-2): J = 2k - 1; S = 6k; k <= 4"
        )
    };
    let derivatives = chart_derivatives(&Vector3::zeros(), rates);
    let jet: [Vector3<f64>; 8] = core::array::from_fn(|j| {
        if j == 0 || j > J {
            Vector3::zeros()
        } else {
            derivatives[j - 1]
        }
    });
    let lower: [Vector3<f64>; K] = core::array::from_fn(|j| jet[j]);
    let upper: [Vector3<f64>; K] = core::array::from_fn(|j| jet[K + j]);
    let p = system.momenta(&lower, &upper);
    let z = join::<3, K, S>(&lower, &p);
    if z.iter().all(|v| v.is_finite()) {
        Ok(z)
    } else {
        Err(Error::NonFinite {
            iteration: 0,
            location: "momenta of the Legendre map",
        })
    }
}
