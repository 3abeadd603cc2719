//! Structure diagnostics: energy error, symplecticity of the step map, momentum drift,
//! and a classical RK4 step on the same Hamilton equations for comparison.

use nalgebra::{SMatrix, SVector};

use crate::scheme::step::{StepOptions, solve_step};
use crate::{Error, LiftedSystem};

/// $\max_i |H(z_i) - H(z_0)|$ over `states` (0 for an empty slice).
///
/// # Errors
/// When $H$ cannot be evaluated at some state.
pub fn energy_error<Sys, const S: usize, const M: usize>(
    system: &Sys,
    states: &[SVector<f64, S>],
) -> Result<f64, Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    let Some(first) = states.first() else {
        return Ok(0.0);
    };
    let h0 = system.hamiltonian(first)?;
    let mut worst: f64 = 0.0;
    for z in states {
        worst = worst.max((system.hamiltonian(z)? - h0).abs());
    }
    Ok(worst)
}

/// $\max_i |z_{i,c} - z_{0,c}|$: the drift of the state component `c` (e.g. a momentum
/// component $p_{0,a}$ at `c = K N + a`). 0 for an empty slice or an out-of-range `c`.
pub fn component_drift<const S: usize>(states: &[SVector<f64, S>], c: usize) -> f64 {
    let Some(first) = states.first() else {
        return 0.0;
    };
    let Some(&start) = first.as_slice().get(c) else {
        return 0.0;
    };
    states
        .iter()
        .filter_map(|z| z.as_slice().get(c))
        .map(|v| (v - start).abs())
        .fold(0.0, f64::max)
}

/// The canonical structure matrix $J = \begin{pmatrix} 0 & I \cr -I & 0 \end{pmatrix}$ on
/// $z = (x, p)$.
pub fn canonical_structure<const S: usize>() -> SMatrix<f64, S, S> {
    let half = S / 2;
    SMatrix::from_fn(|r, c| {
        if c == r + half {
            1.0
        } else if r == c + half {
            -1.0
        } else {
            0.0
        }
    })
}

/// The derivative $D\Psi$ of the one-step map at $z_0$ and the new state $z_1$, by the
/// implicit function theorem: $D\Psi = -[(\partial F/\partial w)^{-1}\thinspace\partial F/\partial z_0]_{1..S}$.
///
/// # Errors
/// A failed step, or a singular Newton matrix at the solution.
pub fn step_map_derivative<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, S>, SMatrix<f64, S, S>), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    let guess = system.predictor(z0, h, options.theta)?;
    let (w, report) = solve_step(system, z0, guess, h, options)?;
    let theta = options.theta;
    let dw = crate::numeric::linalg::solve(
        &system.jacobian(z0, &w, h, theta),
        &system.jacobian_initial(z0, &w, h, theta),
    )
    .ok_or(Error::SingularJacobian {
        iteration: report.iterations,
    })?;
    let d_psi: SMatrix<f64, S, S> = -dw.fixed_rows::<S>(0).into_owned();
    Ok((system.state(&w), d_psi))
}

/// $\max |D\Psi^T J D\Psi - J|$ for the step from $z_0$: zero to rounding for a symplectic
/// map.
///
/// # Errors
/// As [`step_map_derivative`].
pub fn symplecticity_error<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> Result<f64, Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    let (_, d_psi) = step_map_derivative(system, z0, h, options)?;
    let j = canonical_structure::<S>();
    Ok((d_psi.transpose() * j * d_psi - j).amax())
}

/// One classical fourth-order Runge-Kutta step on Hamilton's equations
/// $z' = f(z)$ ([`LiftedSystem::vector_field`]): $z_1 = z_0 + h(k_1 + 2k_2 + 2k_3 + k_4)/6$.
/// Not symplectic; for comparisons and references.
///
/// # Errors
/// When the vector field cannot be evaluated at a stage.
pub fn rk4_step<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z: &SVector<f64, S>,
    h: f64,
) -> Result<SVector<f64, S>, Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    let k1 = system.vector_field(z)?;
    let k2 = system.vector_field(&(z + k1 * (h / 2.0)))?;
    let k3 = system.vector_field(&(z + k2 * (h / 2.0)))?;
    let k4 = system.vector_field(&(z + k3 * h))?;
    Ok(z + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0))
}
