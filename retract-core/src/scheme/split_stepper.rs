//! A stepper for splitting methods on $L = \tfrac{c}{2} |q^{(k)}|^2 + V(q)$ ([`crate::scheme::split`]):
//! one step of size $h$ of a [`SplittingMethod`],
//!
//! $$z_1 = e^{a_{s+1} h A}\thinspace K_{b_s h}\thinspace e^{a_s h A} \cdots K_{b_1 h}\thinspace
//!   e^{a_1 h A} z_0,$$
//!
//! with the free flow $e^{tA}$ and the kick $K_t: p_0 \mathrel{+}= t \nabla V(x_0)$.
//!
//! The step works in the jet variables $w = (q, \dots, q^{(2k-1)})$ of the free motion
//! ($w_j = x_j$ for $j < k$, $w_{k+i} = (-1)^i p_{k-1-i}/c$), where $A$ is the shift and
//! $e^{tA}$ the Taylor polynomial $w_m \mapsto \sum_i \tfrac{t^i}{i!} w_{m+i}$, and a kick adds
//! $(-1)^{k-1} t \nabla V / c$ to $w_{2k-1}$. Per step size it caches the powers
//! $(a_i h)^m / m!$ and the kick factors; per step it converts $z$ to $w$ and back once,
//! tests finiteness once at each end, and runs the singularity guard once, on the step from
//! $z_0$ to $z_1$ (not on the stages: a composed step's stages stay within a few $h$ of that
//! chord, and the guard samples it). A method that begins and ends with a kick evaluates the
//! last kick's gradient at the next step's first point: the stepper keeps it and reuses it
//! when the next step starts there (the position compared exactly).

use nalgebra::{SMatrix, SVector};

use crate::scheme::split::{
    MAX_K, Separable, flow_jet, free_flow, free_flow_matrix, jet_of, jet_of_state, state_of_jet,
    taylor_powers, weight_of,
};
use crate::scheme::split_methods::{MAX_KICKS, SplittingMethod};
use crate::scheme::step::{StepOptions, StepReport, check_step_domain};
use crate::{Error, LiftedSystem};

/// Steps a [`Separable`] system with a [`SplittingMethod`], caching per step size (module
/// docs).
///
/// # Example
/// The order-6 method of Blanes and Moan on a free spline ($V = 0$): exact, since the free
/// flow is.
/// ```
/// use nalgebra::SVector;
/// use retract_core::models::PlanarBarrier;
/// use retract_core::split_methods::SplittingMethod;
/// use retract_core::split_stepper::SplitStepper;
/// use retract_core::{LiftedSystem, StepOptions};
///
/// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
/// let jet = SVector::<f64, 8>::from_column_slice(&[2.0, 0.0, 1.0, 0.5, 0.2, 0.0, 0.6, -0.3]);
/// let mut stepper = SplitStepper::new(&system, SplittingMethod::blanes_moan_6())?;
/// let (z1, _) = stepper.step(&system.legendre(&jet), 0.5, &StepOptions::default())?;
/// let cubic = 2.0 + 0.5 * 1.0 + 0.125 * 0.2 + 0.5f64.powi(3) / 6.0 * 0.6;
/// assert!((z1[0] - cubic).abs() < 1e-14);
/// # Ok::<(), retract_core::Error>(())
/// ```
pub struct SplitStepper<'a, Sys: ?Sized, const N: usize, const K: usize, const S: usize> {
    system: &'a Sys,
    method: SplittingMethod,
    weight: f64,
    /// The step size the tables below are for (NaN before the first step).
    h: f64,
    /// `powers[i][m]` $= (a_i h)^m / m!$.
    powers: [[f64; 2 * MAX_K]; MAX_KICKS + 1],
    /// `kick_scale[i]` $= (-1)^{k-1} b_i h / c$.
    kick_scale: [f64; MAX_KICKS],
    /// The position of the last kick and $\nabla V$ there, for a method that ends with a kick.
    last_kick: Option<(SVector<f64, N>, SVector<f64, N>)>,
}

impl<'a, Sys, const N: usize, const K: usize, const S: usize> SplitStepper<'a, Sys, N, K, S>
where
    Sys: Separable<N, K> + ?Sized,
{
    /// A stepper for `system` with `method`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a weight $c$ that is not finite and positive.
    pub fn new(system: &'a Sys, method: SplittingMethod) -> Result<Self, Error> {
        const {
            assert!(
                S == 2 * N * K && K <= MAX_K,
                "S must equal 2 N K, K at most 4"
            )
        };
        Ok(Self {
            system,
            method,
            weight: weight_of(system)?,
            h: f64::NAN,
            powers: [[0.0; 2 * MAX_K]; MAX_KICKS + 1],
            kick_scale: [0.0; MAX_KICKS],
            last_kick: None,
        })
    }

    /// The method this stepper applies.
    pub fn method(&self) -> &SplittingMethod {
        &self.method
    }

    /// One step of size `h` from `z0` (module docs), with the singularity guard of
    /// [`check_step_domain`] from `z0` to the result (`u` the top derivative $p_{k-1}/c$ at
    /// the end) unless `options.check_domain` is false.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a step size or options that [`crate::step()`] rejects;
    /// [`Error::NonFinite`] if `z0`, a gradient of $V$ or the result is not finite;
    /// [`Error::Domain`] if the step leaves the domain of $L$.
    pub fn step<const M: usize>(
        &mut self,
        z0: &SVector<f64, S>,
        h: f64,
        options: &StepOptions,
    ) -> Result<(SVector<f64, S>, StepReport), Error>
    where
        Sys: LiftedSystem<S, M>,
    {
        const { assert!(M == S + N, "M must equal S + N") };
        options.validate(h)?;
        if h.to_bits() != self.h.to_bits() {
            self.prepare(h);
        }
        if !z0.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite {
                iteration: 0,
                location: "initial state of the splitting step",
            });
        }
        let w = self.advance(z0);
        let z1 = state_of_jet::<N, K, S>(&w, self.weight);
        if !z1.iter().all(|v| v.is_finite()) {
            self.last_kick = None;
            return Err(Error::NonFinite {
                iteration: 0,
                location: "splitting step (gradient of the potential)",
            });
        }
        if options.check_domain {
            let guard =
                SVector::<f64, M>::from_fn(|r, _| if r < S { z1[r] } else { w[K * N + r - S] });
            check_step_domain(self.system, z0, &guard, options).map_err(Error::Domain)?;
        }
        Ok((z1, StepReport::default()))
    }

    /// The tables for step size `h`.
    fn prepare(&mut self, h: f64) {
        // (the zips stop at the shorter side: no table is written past its length)
        for (row, &a) in self.powers.iter_mut().zip(self.method.flows()) {
            *row = taylor_powers::<K>(a * h);
        }
        let sign = if !K.is_multiple_of(2) { 1.0 } else { -1.0 };
        for (scale, &b) in self.kick_scale.iter_mut().zip(self.method.kicks()) {
            *scale = sign * b * h / self.weight;
        }
        self.h = h;
    }

    /// The method's map in the jet variables, from `z0`.
    fn advance(&mut self, z0: &SVector<f64, S>) -> SVector<f64, S> {
        let mut w = jet_of_state::<N, K, S>(z0, self.weight);
        let flows = self.method.flows();
        let s = flows.len() - 1;
        let reuse = self.method.starts_with_kick();
        let top = (2 * K - 1) * N;
        for (i, &a) in flows[..s].iter().enumerate() {
            if a != 0.0 {
                flow_jet::<N, K, S>(&mut w, &self.powers[i]);
            }
            let q = w.fixed_rows::<N>(0).into_owned();
            let g = match self.last_kick {
                Some((at, g)) if i == 0 && reuse && at == q => g,
                _ => self.gradient(&w),
            };
            let scale = self.kick_scale[i];
            for a in 0..N {
                w[top + a] += scale * g[a];
            }
            if i + 1 == s && reuse {
                self.last_kick = Some((q, g));
            }
        }
        if flows[s] != 0.0 {
            flow_jet::<N, K, S>(&mut w, &self.powers[s]);
        }
        w
    }

    /// $\nabla V(x_0) = \partial L / \partial x_0$ at the jet `w`.
    fn gradient(&self, w: &SVector<f64, S>) -> SVector<f64, N> {
        let x = core::array::from_fn(|j| w.fixed_rows::<N>(j * N).into_owned());
        let u = w.fixed_rows::<N>(K * N).into_owned();
        self.system.gradient(&x, &u).x[0]
    }

    /// The derivative $\partial z_1 / \partial z_0$ of [`Self::step`]: the product of the
    /// free flows $e^{a_i h A}$ and the kicks' derivatives $I + b_i h\thinspace \nabla^2 V$ (in
    /// the block $\partial p_0 / \partial x_0$), each at its stage (for the symplecticity
    /// check $D^T J D = J$). Uses no cache.
    ///
    /// # Errors
    /// [`Error::NonFinite`] for a derivative that is not finite.
    pub fn step_derivative(
        &self,
        z0: &SVector<f64, S>,
        h: f64,
    ) -> Result<SMatrix<f64, S, S>, Error> {
        let (c, flows, kicks) = (self.weight, self.method.flows(), self.method.kicks());
        let mut z = *z0;
        let mut d = SMatrix::<f64, S, S>::identity();
        for (i, &a) in flows.iter().enumerate() {
            if a != 0.0 {
                z = free_flow::<N, K, S>(&z, a * h, c);
                d = free_flow_matrix::<N, K, S>(a * h, c) * d;
            }
            let Some(&b) = kicks.get(i) else { break };
            let (x, u) = jet_of::<N, K, S>(&z, c);
            let hessian = self.system.hessian(&x, &u).xx[0][0] * (b * h);
            let grad = self.system.gradient(&x, &u).x[0] * (b * h);
            let dx0 = d.fixed_rows::<N>(0).into_owned();
            let mut dp0 = d.fixed_rows_mut::<N>(K * N);
            dp0 += hessian * dx0;
            let mut p0 = z.fixed_rows_mut::<N>(K * N);
            p0 += grad;
        }
        if d.iter().all(|v| v.is_finite()) {
            Ok(d)
        } else {
            Err(Error::NonFinite {
                iteration: 0,
                location: "derivative of the splitting step",
            })
        }
    }
}
