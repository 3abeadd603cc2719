//! Higher order by symmetric composition of the midpoint step.
//!
//! For a symmetric one-step map $\Psi_h$ of order $2m$, the triple jump
//! $\Psi_{\gamma_1 h} \circ \Psi_{\gamma_0 h} \circ \Psi_{\gamma_1 h}$ with
//! $\gamma_1 = 1/(2 - 2^{1/(2m+1)})$, $\gamma_0 = 1 - 2\gamma_1$ is symmetric of order $2m + 2$
//! (Yoshida 1990; Hairer, Lubich, Wanner, *Geometric Numerical Integration*, II.4).
//! Applied recursively to the midpoint rule (order 2): order 4 with 3 stages, order 6 with 9,
//! order 8 with 27. A composition of symplectic maps is symplectic.
//!
//! The base step must be symmetric: the theta-scheme with $\theta = 1/2$.

use nalgebra::SVector;

use crate::step::StepReport;
use crate::{Error, LiftedSystem, StepOptions};

/// Most stages of a supported composition (order 8).
pub const MAX_STAGES: usize = 27;

/// The step-size fractions $\gamma_i$ (summing to 1) of the recursive triple jump of
/// `order` (2, 4, 6 or 8), in the first `len` entries.
///
/// # Errors
/// [`Error::InvalidArgument`] for another order.
pub fn coefficients(order: u32) -> Result<([f64; MAX_STAGES], usize), Error> {
    if !matches!(order, 2 | 4 | 6 | 8) {
        return Err(Error::InvalidArgument {
            name: "order",
            requirement: "compositions of the midpoint rule have order 2, 4, 6 or 8",
        });
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
    mut base: impl FnMut(&SVector<f64, S>, f64) -> Result<(SVector<f64, S>, StepReport), Error>,
    z0: &SVector<f64, S>,
    h: f64,
    order: u32,
) -> Result<(SVector<f64, S>, StepReport), Error> {
    let (gamma, stages) = coefficients(order)?;
    let mut z = *z0;
    let mut report = StepReport::default();
    for &g in &gamma[..stages] {
        let (next, r) = base(&z, g * h)?;
        z = next;
        report.iterations += r.iterations;
        report.residual_norm = report.residual_norm.max(r.residual_norm);
    }
    Ok((z, report))
}

/// One step of the composition of `order` of the midpoint rule ([`crate::step()`]).
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
        for (order, stages) in [(2, 1), (4, 3), (6, 9), (8, 27)] {
            let (gamma, len) = coefficients(order).unwrap();
            assert_eq!(len, stages);
            let sum: f64 = gamma[..len].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "order {order}: sum {sum}");
            for i in 0..len {
                assert_eq!(gamma[i], gamma[len - 1 - i]);
            }
            // the order conditions of a symmetric method: sum gamma^3 = 0 for order >= 4
            if order >= 4 {
                let third: f64 = gamma[..len].iter().map(|g| g * g * g).sum();
                assert!(
                    third.abs() < 1e-13,
                    "order {order}: sum gamma^3 = {third:e}"
                );
            }
        }
        assert!(coefficients(3).is_err() && coefficients(10).is_err());
    }
}
