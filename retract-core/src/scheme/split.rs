//! An explicit symplectic splitting for Lagrangians $L = \tfrac{c}{2} |q^{(k)}|^2 + V(q)$.
//!
//! Their Ostrogradsky Hamiltonian splits as $H = H_0 + H_V$ with
//!
//! $$H_0 = \sum_{j < k-1} p_j \cdot x_{j+1} + \tfrac{1}{2c} |p_{k-1}|^2, \qquad
//!   H_V = -V(x_0).$$
//!
//! The flow of $H_0$ is linear with a nilpotent generator $A$ ($x_j' = x_{j+1}$,
//! $x_{k-1}' = p_{k-1}/c$, $p_0' = 0$, $p_j' = -p_{j-1}$; $A^{2k} = 0$), so
//! $e^{tA} = \sum_{m < 2k} t^m A^m / m!$ is exact; the flow of $H_V$ is the kick
//! $p_0 \mathrel{+}= t\thinspace \nabla V(x_0)$. [`split_step`] is Strang's splitting
//! $e^{hA/2} \circ \mathrm{kick}_h \circ e^{hA/2}$: explicit (one gradient of $V$ per step, no
//! Newton solve), symplectic and symmetric, of order 2; compose it with
//! [`crate::scheme::compose::compose`] for orders 4, 6 and 8.
//!
//! `#[higher_order_lagrangian]` implements [`Separable`] when it finds this form in $L$.
//! Where it does not apply ($L$ not separable, such as $\tfrac12 |M(q) q'' + c|^2$), the
//! implicit midpoint scheme ([`crate::step()`]) is needed; near a stiff barrier an explicit
//! step also needs a step size that resolves the barrier, where the implicit one adapts by
//! halving.

use nalgebra::{SMatrix, SVector};

use crate::scheme::lifted::split;
use crate::scheme::step::{StepOptions, StepReport, check_step_domain};
use crate::{Error, Lagrangian, LiftedSystem};

/// The largest order the free flow supports (that of the macro).
pub(crate) const MAX_K: usize = 4;

/// A Lagrangian $L(x, u) = \tfrac{c}{2} |u|^2 + V(x_0)$: quadratic in the top derivative
/// $u = q^{(k)}$ with the constant weight $c > 0$, free of $q', \dots, q^{(k-1)}$, and no
/// term coupling $u$ and $q$. Then $\partial L / \partial x_0 = \nabla V(x_0)$.
pub trait Separable<const N: usize, const K: usize>: Lagrangian<N, K> {
    /// The weight $c$ of $\tfrac{c}{2} |u|^2$.
    fn kinetic_weight(&self) -> f64;
}

/// The exact free flow $e^{tA} z$ for the weight $c$ = `weight` (finite and positive: the
/// caller's to check, as [`split_step`] does; otherwise the result is not finite). In the variables $w = (x_0, \dots, x_{k-1}, p_{k-1}/c,
/// -p_{k-2}/c, \dots, (-1)^{k-1} p_0 / c)$, the derivatives $(q, \dots, q^{(2k-1)})$ of the
/// free motion $q^{(2k)} = 0$, $A$ is the shift $w_m \mapsto w_{m+1}$, so the flow is the
/// Taylor polynomial $w_m(t) = \sum_i t^i w_{m+i} / i!$.
pub fn free_flow<const N: usize, const K: usize, const S: usize>(
    z: &SVector<f64, S>,
    t: f64,
    weight: f64,
) -> SVector<f64, S> {
    let mut w = jet_of_state::<N, K, S>(z, weight);
    flow_jet::<N, K, S>(&mut w, &taylor_powers::<K>(t));
    state_of_jet::<N, K, S>(&w, weight)
}

/// The coefficients $t^m / m!$ for $m < 2k$ of the free flow $e^{tA}$ (the rest zero).
pub(crate) fn taylor_powers<const K: usize>(t: f64) -> [f64; 2 * MAX_K] {
    const { assert!(K <= MAX_K, "K at most 4") };
    let mut c = [0.0; 2 * MAX_K];
    c[0] = 1.0;
    for m in 1..2 * K {
        c[m] = c[m - 1] * t / m as f64;
    }
    c
}

/// $z \mapsto w$: the jet variables of the free motion (see [`free_flow`]), $w_j = x_j$ for
/// $j < k$ and $w_{k+i} = (-1)^i p_{k-1-i}/c$.
pub(crate) fn jet_of_state<const N: usize, const K: usize, const S: usize>(
    z: &SVector<f64, S>,
    weight: f64,
) -> SVector<f64, S> {
    const {
        assert!(
            S == 2 * N * K && K <= MAX_K,
            "S must equal 2 N K, K at most 4"
        )
    };
    let inverse = 1.0 / weight;
    SVector::from_fn(|r, _| {
        let (m, a) = (r / N, r % N);
        if m < K {
            z[r]
        } else {
            let i = m - K;
            let sign = if i.is_multiple_of(2) {
                inverse
            } else {
                -inverse
            };
            z[(2 * K - 1 - i) * N + a] * sign
        }
    })
}

/// $w \mapsto z$, the inverse of [`jet_of_state`].
pub(crate) fn state_of_jet<const N: usize, const K: usize, const S: usize>(
    w: &SVector<f64, S>,
    weight: f64,
) -> SVector<f64, S> {
    SVector::from_fn(|r, _| {
        let (m, a) = (r / N, r % N);
        if m < K {
            w[r]
        } else {
            // z block m = K + j holds p_j = (-1)^i c w_{K+i} with i = K - 1 - j
            let i = 2 * K - 1 - m;
            let sign = if i.is_multiple_of(2) { weight } else { -weight };
            w[(K + i) * N + a] * sign
        }
    })
}

/// $w \mapsto e^{tA} w$ in place, with `c[m]` $= t^m / m!$ ([`taylor_powers`]):
/// $w_m \mathrel{+}= \sum_{i \ge 1} c_i w_{m+i}$ in increasing $m$ (each $w_m$ reads only
/// blocks not yet updated).
#[inline(always)]
pub(crate) fn flow_jet<const N: usize, const K: usize, const S: usize>(
    w: &mut SVector<f64, S>,
    c: &[f64; 2 * MAX_K],
) {
    for m in 0..2 * K {
        for i in 1..2 * K - m {
            for a in 0..N {
                w[m * N + a] += c[i] * w[(m + i) * N + a];
            }
        }
    }
}

/// $e^{tA}$ as a matrix (the free flow's derivative).
pub(crate) fn free_flow_matrix<const N: usize, const K: usize, const S: usize>(
    t: f64,
    weight: f64,
) -> SMatrix<f64, S, S> {
    let mut m = SMatrix::<f64, S, S>::zeros();
    for c in 0..S {
        let mut unit = SVector::<f64, S>::zeros();
        unit[c] = 1.0;
        m.set_column(c, &free_flow::<N, K, S>(&unit, t, weight));
    }
    m
}

/// $(x, u)$ at state `z` with $u = p_{k-1}/c$ (the top derivative of the free flow).
pub(crate) fn jet_of<const N: usize, const K: usize, const S: usize>(
    z: &SVector<f64, S>,
    weight: f64,
) -> ([SVector<f64, N>; K], SVector<f64, N>) {
    let (x, p) = split::<N, K, S>(z);
    (x, p[K - 1] / weight)
}

/// The weight $c$ of `system`, checked: finite and positive.
pub(crate) fn weight_of<Sys, const N: usize, const K: usize>(system: &Sys) -> Result<f64, Error>
where
    Sys: Separable<N, K> + ?Sized,
{
    let c = system.kinetic_weight();
    if c.is_finite() && c > 0.0 {
        Ok(c)
    } else {
        Err(Error::InvalidArgument {
            name: "kinetic_weight",
            requirement: "finite and positive (L = c/2 |u|^2 + V(q) with c > 0)",
        })
    }
}

/// One step of Strang's splitting $e^{hA/2} \circ \mathrm{kick}_h \circ e^{hA/2}$ (module
/// docs), with the singularity guard of [`check_step_domain`] from `z0` to the result (its
/// `options.theta` and chord settings; `u` the top derivative $p_{k-1}/c$ at the end)
/// unless `options.check_domain` is false.
///
/// # Errors
/// [`Error::InvalidArgument`] for a weight that is not finite and positive, or a step size or
/// options that [`crate::step()`] rejects (`h` zero or not finite); [`Error::NonFinite`] if the state, $\nabla V$ or the result is not
/// finite;
/// [`Error::Domain`] if the step leaves the domain of $L$.
pub fn split_step<Sys, const N: usize, const K: usize, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, S>, StepReport), Error>
where
    Sys: Separable<N, K> + LiftedSystem<S, M> + ?Sized,
{
    const { assert!(M == S + N, "M must equal S + N") };
    let weight = weight_of(system)?;
    if !z0.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFinite {
            iteration: 0,
            location: "initial state of the explicit splitting step",
        });
    }
    // the step size and the guard's settings, checked as for the implicit step
    options.validate(h)?;
    let mut z = free_flow::<N, K, S>(z0, 0.5 * h, weight);
    let (x, u) = jet_of::<N, K, S>(&z, weight);
    let grad = system.gradient(&x, &u).x[0];
    for a in 0..N {
        z[K * N + a] += h * grad[a];
    }
    let z1 = free_flow::<N, K, S>(&z, 0.5 * h, weight);
    if !z1.iter().all(|v| v.is_finite()) {
        return Err(Error::NonFinite {
            iteration: 0,
            location: "explicit splitting step (gradient of the potential)",
        });
    }
    if options.check_domain {
        let (_, u1) = jet_of::<N, K, S>(&z1, weight);
        let w = SVector::<f64, M>::from_fn(|r, _| if r < S { z1[r] } else { u1[r - S] });
        check_step_domain(system, z0, &w, options).map_err(Error::Domain)?;
    }
    Ok((z1, StepReport::default()))
}

/// The derivative $\partial z_1 / \partial z_0$ of [`split_step`]: $e^{hA/2} (I + h\thinspace
/// \partial^2 V) e^{hA/2}$, the kick's block $\partial p_0 / \partial x_0 = h \nabla^2 V$
/// (for the symplecticity check $D^T J D = J$).
///
/// # Errors
/// As the weight check of [`split_step`]; [`Error::NonFinite`] for a Hessian of $V$ that is
/// not finite.
pub fn split_step_derivative<Sys, const N: usize, const K: usize, const S: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
) -> Result<SMatrix<f64, S, S>, Error>
where
    Sys: Separable<N, K> + ?Sized,
{
    let weight = weight_of(system)?;
    let half = free_flow_matrix::<N, K, S>(0.5 * h, weight);
    let (x, u) = jet_of::<N, K, S>(&free_flow::<N, K, S>(z0, 0.5 * h, weight), weight);
    let hessian = system.hessian(&x, &u).xx[0][0];
    let mut kick = SMatrix::<f64, S, S>::identity();
    for a in 0..N {
        for b in 0..N {
            kick[(K * N + a, b)] = h * hessian[(a, b)];
        }
    }
    let d = half * kick * half;
    if d.iter().all(|v| v.is_finite()) {
        Ok(d)
    } else {
        Err(Error::NonFinite {
            iteration: 0,
            location: "derivative of the explicit splitting step",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without a potential the flow of L = 1/2 |q'''|^2 (k = 3) is the quintic through the
    /// jet: the free flow reproduces it exactly.
    #[test]
    fn the_free_flow_is_the_polynomial_through_the_jet() {
        // k = 3, n = 1: q^(6) = 0, with p_2 = q''' (c = 1), p_1 = -q'''' , p_0 = q^(5)
        let d = [0.3, -1.2, 0.7, 2.0, -0.5, 1.5]; // q, q', ..., q^(5) at 0
        let z = SVector::<f64, 6>::from([d[0], d[1], d[2], d[5], -d[4], d[3]]);
        let t = 0.8;
        let q = (0..6).fold((0.0, 1.0), |(s, term), m| {
            (s + d[m] * term, term * t / (m + 1) as f64)
        });
        let flowed = free_flow::<1, 3, 6>(&z, t, 1.0);
        assert!((flowed[0] - q.0).abs() < 1e-15, "{} {}", flowed[0], q.0);
        // and it is a flow: e^{(s+t)A} = e^{sA} e^{tA}
        let twice = free_flow::<1, 3, 6>(&free_flow::<1, 3, 6>(&z, 0.3, 1.0), 0.5, 1.0);
        assert!((twice - flowed).amax() < 1e-15);
    }
}
