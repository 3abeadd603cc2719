//! Higher order by symmetric composition of the midpoint step.
//!
//! A symmetric composition $\Psi_{\gamma_s h} \circ \dots \circ \Psi_{\gamma_1 h}$ of a symmetric
//! one-step map $\Psi_h$ of order 2, with $\gamma_i = \gamma_{s+1-i}$ and $\sum \gamma_i = 1$,
//! is symmetric, and symplectic when $\Psi$ is; its order depends on the $\gamma_i$
//! (Hairer, Lubich, Wanner, *Geometric Numerical Integration*, II.4 and V.3).
//!
//! - [`triple_jump`]: the recursive triple jump $\Psi_{\gamma_1 h} \circ \Psi_{\gamma_0 h} \circ
//!   \Psi_{\gamma_1 h}$ with $\gamma_1 = 1/(2 - 2^{1/(2m+1)})$, $\gamma_0 = 1 - 2\gamma_1$, which
//!   raises order $2m$ to $2m + 2$ (Yoshida 1990): orders 4, 6, 8 with 3, 9, 27 stages.
//! - [`coefficients`]: the cheapest known set per order: the triple jump for order 4, and the
//!   Kahan-Li methods s9odr6a (order 6, 9 stages) and s15odr8 (order 8, 15 stages), whose
//!   error constants are far smaller than the recursive triple jump's (Kahan and Li 1997;
//!   GNI V.3.2, (3.12) and (3.13)).
//!
//! The base step must be symmetric: the theta-scheme with $\theta = 1/2$.

use nalgebra::SVector;

use crate::scheme::step::StepReport;
use crate::{Error, LiftedSystem, StepOptions};

/// Most stages of a supported composition (the order-8 triple jump).
pub const MAX_STAGES: usize = 27;

/// Kahan-Li s9odr6a: $\gamma_1, \dots, \gamma_5$ ($\gamma_{10-i} = \gamma_i$), with the
/// published digits.
#[allow(clippy::excessive_precision)]
const KAHAN_LI_6: [f64; 5] = [
    0.392_161_444_007_314_139_279_250_56,
    0.332_599_136_789_359_438_599_748_64,
    -0.706_246_172_557_639_359_809_964_82,
    0.082_213_596_293_550_800_231_490_45,
    0.798_543_990_934_829_963_398_950_35,
];

/// Kahan-Li s15odr8: $\gamma_1, \dots, \gamma_8$ ($\gamma_{16-i} = \gamma_i$), with the
/// published digits.
#[allow(clippy::excessive_precision)]
const KAHAN_LI_8: [f64; 8] = [
    0.741_670_364_350_612_953_448_227_80,
    -0.409_100_825_800_031_593_997_300_10,
    0.190_754_710_296_238_379_953_876_26,
    -0.573_862_471_116_082_266_656_387_73,
    0.299_064_181_303_655_923_844_463_54,
    0.334_624_918_245_298_183_784_957_98,
    0.315_293_092_396_766_596_632_056_66,
    -0.796_887_939_352_916_354_019_788_84,
];

fn invalid_order() -> Error {
    Error::InvalidArgument {
        name: "order",
        requirement: "compositions of the midpoint rule have order 2, 4, 6 or 8",
    }
}

/// The step-size fractions $\gamma_i$ (summing to 1) of the cheapest supported composition
/// of `order` (2, 4, 6 or 8), in the first `len` entries: the midpoint rule itself, the triple
/// jump (3 stages), Kahan-Li s9odr6a (9 stages) and s15odr8 (15 stages).
///
/// # Errors
/// [`Error::InvalidArgument`] for another order.
pub fn coefficients(order: u32) -> Result<([f64; MAX_STAGES], usize), Error> {
    let half: &[f64] = match order {
        2 | 4 => return triple_jump(order),
        6 => &KAHAN_LI_6,
        8 => &KAHAN_LI_8,
        _ => return Err(invalid_order()),
    };
    // palindrome: gamma_1 .. gamma_c .. gamma_1
    let len = 2 * half.len() - 1;
    let mut gamma = [0.0; MAX_STAGES];
    for (i, &g) in half.iter().enumerate() {
        gamma[i] = g;
        gamma[len - 1 - i] = g;
    }
    Ok((gamma, len))
}

/// The step-size fractions $\gamma_i$ (summing to 1) of the recursive triple jump of
/// `order` (2, 4, 6 or 8: 1, 3, 9 or 27 stages), in the first `len` entries.
///
/// # Errors
/// [`Error::InvalidArgument`] for another order.
pub fn triple_jump(order: u32) -> Result<([f64; MAX_STAGES], usize), Error> {
    if !matches!(order, 2 | 4 | 6 | 8) {
        return Err(invalid_order());
    }
    let mut gamma = [0.0; MAX_STAGES];
    gamma[0] = 1.0;
    let mut len = 1;
    let mut reached = 2;
    while reached < order {
        let root = libm_pow2(1.0 / f64::from(reached + 1));
        let outer = 1.0 / (2.0 - root);
        let inner = 1.0 - 2.0 * outer;
        let mut next = [0.0; MAX_STAGES];
        for (block, factor) in [outer, inner, outer].into_iter().enumerate() {
            for i in 0..len {
                next[block * len + i] = factor * gamma[i];
            }
        }
        gamma = next;
        len *= 3;
        reached += 2;
    }
    Ok((gamma, len))
}

/// $2^x$ without std.
fn libm_pow2(x: f64) -> f64 {
    num_traits::Float::powf(2.0, x)
}

/// One step of size `h` of the composition of `order` built from `base` (a symmetric
/// one-step map `base(z, h)`, e.g. a closure around [`crate::step()`] or
/// [`crate::ReducedStepper::step`]). Reports are summed over stages.
///
/// # Errors
/// An invalid order, or the first failing stage's error.
pub fn compose<const S: usize>(
    base: impl FnMut(&SVector<f64, S>, f64) -> Result<(SVector<f64, S>, StepReport), Error>,
    z0: &SVector<f64, S>,
    h: f64,
    order: u32,
) -> Result<(SVector<f64, S>, StepReport), Error> {
    let (gamma, stages) = coefficients(order)?;
    compose_with(base, z0, h, &gamma[..stages])
}

/// One step of size `h` of the composition with step-size fractions `gamma` (e.g. from
/// [`triple_jump`]): $\Psi_{\gamma_s h} \circ \dots \circ \Psi_{\gamma_1 h}$. Reports are summed
/// over stages.
///
/// # Errors
/// The first failing stage's error.
pub fn compose_with<const S: usize>(
    mut base: impl FnMut(&SVector<f64, S>, f64) -> Result<(SVector<f64, S>, StepReport), Error>,
    z0: &SVector<f64, S>,
    h: f64,
    gamma: &[f64],
) -> Result<(SVector<f64, S>, StepReport), Error> {
    let mut z = *z0;
    let mut report = StepReport::default();
    for &g in gamma {
        let (next, r) = base(&z, g * h)?;
        z = next;
        report.iterations += r.iterations;
        report.residual_norm = report.residual_norm.max(r.residual_norm);
    }
    Ok((z, report))
}

/// One step of the composition of `order` of the midpoint rule ([`crate::step()`]).
///
/// # Example
/// Without a potential ($L = \tfrac12|q''|^2$) the flow is the cubic
/// $q(t) = q_0 + t q_0' + \tfrac{t^2}{2} q_0'' + \tfrac{t^3}{6} q_0'''$. The midpoint step
/// applies the Cayley transform of the nilpotent generator $A$ ($A^4 = 0$),
/// $\exp(hA + h^3A^3/12)$, so it misses $q(h)$ by $h^3 q_0'''/12$; a composition with
/// $\sum_i \gamma_i^3 = 0$ (every order $\ge 4$) applies $\exp(hA)$ and is exact:
/// ```
/// use nalgebra::SVector;
/// use retract_core::models::PlanarBarrier;
/// use retract_core::{LiftedSystem, StepOptions, composed_step, step};
///
/// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
/// let (q, dq, ddq, dddq) = ([2.0, 0.0], [1.0, 0.5], [0.2, 0.0], [0.6, -0.3]);
/// let jet = SVector::<f64, 8>::from_column_slice(&[q, dq, ddq, dddq].concat());
/// let (z0, h, options) = (system.legendre(&jet), 0.5, StepOptions::default());
/// let cubic = |i: usize| q[i] + h * dq[i] + h * h / 2.0 * ddq[i] + h * h * h / 6.0 * dddq[i];
/// let (midpoint, _) = step(&system, &z0, h, &options)?;
/// for order in [4, 6, 8] {
///     let (composed, _) = composed_step(&system, &z0, h, order, &options)?;
///     for i in 0..2 {
///         assert!((composed[i] - cubic(i)).abs() < 1e-13);
///         let miss = midpoint[i] - cubic(i);
///         assert!((miss - h * h * h / 12.0 * dddq[i]).abs() < 1e-13);
///     }
/// }
/// # Ok::<(), retract_core::Error>(())
/// ```
///
/// # Errors
/// `options.theta` other than 1/2 (the base must be symmetric), an invalid order, or a
/// failing stage.
pub fn composed_step<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    order: u32,
    options: &StepOptions,
) -> Result<(SVector<f64, S>, StepReport), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    if options.theta != 0.5 {
        return Err(Error::InvalidArgument {
            name: "theta",
            requirement: "compositions need the symmetric midpoint base (theta = 1/2)",
        });
    }
    compose(
        |z, step| crate::step(system, z, step, options),
        z0,
        h,
        order,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_sum_to_one_and_are_symmetric() {
        let sets = [
            (
                coefficients as fn(u32) -> _,
                [(2, 1), (4, 3), (6, 9), (8, 15)],
            ),
            (triple_jump, [(2, 1), (4, 3), (6, 9), (8, 27)]),
        ];
        for (set, orders) in sets {
            for (order, stages) in orders {
                let (gamma, len) = set(order).unwrap();
                assert_eq!(len, stages);
                let sum: f64 = gamma[..len].iter().sum();
                assert!((sum - 1.0).abs() < 1e-14, "order {order}: sum {sum}");
                for i in 0..len {
                    assert_eq!(gamma[i], gamma[len - 1 - i]);
                }
                // the order conditions of a symmetric method: sum gamma^3 = 0 for order >= 4,
                // sum gamma^5 = 0 for order >= 6
                for (power, from) in [(3, 4), (5, 6)] {
                    if order >= from {
                        let moment: f64 = gamma[..len].iter().map(|g| g.powi(power)).sum();
                        let scale: f64 = gamma[..len].iter().map(|g| g.abs().powi(power)).sum();
                        assert!(
                            moment.abs() < 1e-14 * scale,
                            "order {order}: sum gamma^{power} = {moment:e} (scale {scale:e})"
                        );
                    }
                }
            }
            assert!(set(3).is_err() && set(10).is_err());
        }
    }
}
