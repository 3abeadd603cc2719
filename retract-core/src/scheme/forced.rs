//! Plant simulation: a step under an external generalized force (discrete
//! Lagrange-d'Alembert).
//!
//! With a force $f \in \mathbb{R}^n$ on the configuration, held over the step, the
//! theta-scheme's momentum equation of $q$ gains the impulse $h f$:
//!
//! $$p_{0,1} - p_{0,0} = h\thinspace\big(\partial L/\partial q(x_\theta, u) + f\big),$$
//!
//! the other equations unchanged. For a mechanical Lagrangian $L(q, q')$ ($k = 1$) and
//! $\theta = 1/2$ this is the forced midpoint rule, the discrete Lagrange-d'Alembert
//! principle with the force at the midpoint: a plan's torques replayed on the plant, or a
//! controller closed around it. For quadratic $H$ its energy balance is exact,
//! $H(z_1) - H(z_0) = f \cdot (q_1 - q_0)$ (the work of the force).

use nalgebra::SVector;

use crate::scheme::step::{StepOptions, StepReport, check_energy, name_parameter, solve_offset};
use crate::{Error, LiftedSystem};

/// One step $z_0 \mapsto z_1$ of the theta-scheme under the force `force` $= f$ (module
/// docs), from the explicit predictor, with the options of [`crate::step()`] (domain check
/// included). `N` is the dimension $n$; `M` $= S + N$ is checked at compile time.
///
/// # Example
/// For $L = \tfrac12|q''|^2$ ($\partial L/\partial q = 0$) the force is the only change of
/// $p_0$: $p_{0,1} = p_{0,0} + h f$.
/// ```
/// use nalgebra::SVector;
/// use retract_core::models::PlanarBarrier;
/// use retract_core::{LiftedSystem, StepOptions, forced::forced_step};
///
/// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
/// let jet = SVector::<f64, 8>::from_column_slice(&[2.0, 0.0, 1.0, 0.5, 0.2, 0.0, 0.1, -0.3]);
/// let z0 = system.legendre(&jet);
/// let (f, h) = (SVector::from([0.5, -2.0]), 0.1);
/// let (z1, _) = forced_step(&system, &z0, &f, h, &StepOptions::default())?;
/// // z = (q, q', p0, p1), blocks of 2: p0 at rows 4, 5
/// for i in 0..2 {
///     assert!((z1[4 + i] - (z0[4 + i] + h * f[i])).abs() < 1e-14);
/// }
/// # Ok::<(), retract_core::Error>(())
/// ```
///
/// The energy check of [`StepOptions::energy_tolerance`] (off by default) counts the work of
/// the force,
/// $W = f \cdot (q_1 - q_0)$.
///
/// # Errors
/// [`Error::InvalidArgument`] for a force that is not finite, and those of
/// [`crate::step()`].
pub fn forced_step<Sys, const N: usize, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    force: &SVector<f64, N>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, S>, StepReport), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    const {
        assert!(
            M == S + N && S.is_multiple_of(2 * N),
            "M must equal S + N, S = 2 N K"
        )
    };
    options.validate(h)?;
    if !force.iter().all(|f| f.is_finite()) {
        return Err(Error::InvalidArgument {
            name: "force",
            requirement: "finite",
        });
    }
    // the momentum equation of q: rows S/2 .. S/2 + N of the residual
    let mut offset = SVector::<f64, M>::zeros();
    offset.fixed_rows_mut::<N>(S / 2).copy_from(&(force * h));
    let solved = system.predictor(z0, h, options.theta).and_then(|guess| {
        let (w, report) = solve_offset(system, z0, guess, h, options, Some(&offset))?;
        check_energy(system, z0, &guess, &w, h, options, Some(&offset))?;
        Ok((w, report))
    });
    let (w, report) = solved.map_err(|e| name_parameter(system, e))?;
    Ok((system.state(&w), report))
}
