//! The control period of a real-time iteration with its safeguards
//! ([`OptimalControlProblem::control`]): a re-plan that failed, or whose Newton step is
//! larger than the caller trusts, is not applied (the input of the plan shifted at the last
//! preparation is); the applied input is clamped to the problem's bounds on the top
//! derivative; and the status says which of these happened ([`ControlStatus`]). No
//! allocation.

use nalgebra::SVector;

use super::constraints::{Source, Variable};
use super::problem::OptimalControlProblem;
use super::realtime::RealTimeIteration;
use crate::{Lagrangian, LiftedSystem};

/// How a control period re-plans and when it applies the re-plan
/// ([`OptimalControlProblem::control`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlOptions {
    /// Feedback steps a period, at least 1: the first from the preparation made during the
    /// last period, each further one after a preparation at the new iterate with the same
    /// start. Default 1 (acados' RTI).
    pub iterations: usize,
    /// The re-plan counts as converged when its last Newton step $\max_i
    /// \max(\Vert\delta x_i\Vert_\infty, \Vert\delta u_i\Vert_\infty)$ is at most this: the
    /// iterate the step started from then solved the problem for the measured start to that
    /// size. Default $10^{-6}$.
    pub converged_step: f64,
    /// A re-plan any of whose Newton steps is larger than this is not applied (the shifted
    /// plan's input is, [`Fallback::StepLimit`]): a trust bound on the tangential predictor
    /// far from the linearisation point. Default $\infty$ (every finite re-plan is applied,
    /// and reported as unconverged when it is).
    pub max_step: f64,
}

impl Default for ControlOptions {
    fn default() -> Self {
        Self {
            iterations: 1,
            converged_step: 1e-6,
            max_step: f64::INFINITY,
        }
    }
}

impl ControlOptions {
    /// With `iterations` feedback steps a period (0 counts as 1).
    pub fn with_iterations(mut self, iterations: usize) -> Self {
        self.iterations = iterations;
        self
    }

    /// With the step below which a re-plan counts as converged.
    pub fn with_converged_step(mut self, step: f64) -> Self {
        self.converged_step = step;
        self
    }

    /// With the largest Newton step whose re-plan is applied.
    pub fn with_max_step(mut self, step: f64) -> Self {
        self.max_step = step;
        self
    }
}

/// Why a period applies the shifted plan's input instead of its re-plan's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fallback {
    /// The first feedback step failed (not prepared, or a step that is not finite).
    Failed,
    /// A Newton step was larger than [`ControlOptions::max_step`].
    StepLimit,
    /// The re-plan's first input is not finite.
    NotFinite,
}

/// Which plan a period's input was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputSource {
    /// The re-plan, converged ([`ControlOptions::converged_step`]).
    Converged,
    /// The re-plan, not converged: applied, as the tangential predictor of the solution
    /// (Newton steps finite and at most [`ControlOptions::max_step`]).
    Unconverged,
    /// The re-plan was not applied: the first input of the plan shifted at the last
    /// preparation (the iterate before this period's feedback), for the reason given.
    Shifted(Fallback),
}

/// How a period's input was chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlStatus {
    /// The plan the input was read from.
    pub source: InputSource,
    /// Whether the input was clamped to the problem's bounds on the top derivative (it was
    /// outside them, or not finite).
    pub clamped: bool,
    /// The feedback steps taken (0 if the first failed).
    pub iterations: usize,
    /// The largest Newton step taken (0 with none).
    pub step: f64,
}

impl ControlStatus {
    /// Whether the input is the converged re-plan's ([`InputSource::Converged`]).
    pub fn converged(&self) -> bool {
        self.source == InputSource::Converged
    }

    /// Whether the re-plan was applied (converged or not).
    pub fn replanned(&self) -> bool {
        !matches!(self.source, InputSource::Shifted(_))
    }
}

/// What a control period gives: the input to apply, $u_0$ of the chosen plan clamped to the
/// problem's bounds on the top derivative; that plan's first step (the jets $x_0$, $x_1$ and
/// $u_0$ before clamping, from which a caller reads what it applies: a torque $\tau(x_{\theta,0},
/// u_0)$); and how it was chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Control<const N: usize, const X: usize> {
    /// The input to apply: `planned` clamped to the bounds (finite; within them when the
    /// problem has them).
    pub input: SVector<f64, N>,
    /// $u_0$ of the chosen plan.
    pub planned: SVector<f64, N>,
    /// $x_0$ and $x_1$ of the chosen plan.
    pub x: [SVector<f64, X>; 2],
    /// How the input was chosen.
    pub status: ControlStatus,
}

impl<Sys: ?Sized, const N: usize, const K: usize, const X: usize>
    OptimalControlProblem<'_, Sys, N, K, X>
{
    /// `u` clamped to the problem's bounds on the top derivative
    /// ([`Self::with_input_bounds`], [`Self::with_bounds`] on [`Variable::Top`]):
    /// $\min(\max(u_a, \ell_a), \bar u_a)$ componentwise over all such bounds; a component that
    /// is not finite becomes $\min(\max(0, \ell_a), \bar u_a)$. Without bounds, `u` (with its
    /// non-finite components zero).
    pub fn clamp_input(&self, u: &SVector<f64, N>) -> SVector<f64, N> {
        let mut out = u.map(|v| if v.is_finite() { v } else { 0.0 });
        for c in &self.inequalities {
            if let Source::Variable(Variable::Top(a)) = c.source
                && let Some(v) = out.get_mut(a)
            {
                *v = if c.sign > 0.0 {
                    v.max(c.value)
                } else {
                    v.min(c.value)
                };
            }
        }
        out
    }

    /// One control period of `rti` from the measured `start`: the feedback step
    /// ([`Self::feedback`]; with [`ControlOptions::iterations`] $> 1$, preparation and
    /// feedback again), then the input to apply. The re-plan's first input $u_0$ is applied
    /// if every Newton step was finite and at most [`ControlOptions::max_step`] and $u_0$ is
    /// finite ([`InputSource::Converged`] if the last step was at most
    /// [`ControlOptions::converged_step`], else [`InputSource::Unconverged`]); otherwise the
    /// first input of the iterate as it was before the period (the plan shifted at the last
    /// preparation, [`InputSource::Shifted`]). The iterate keeps the re-plan's steps either
    /// way (unchanged if the first failed): the next period linearises there, so that the
    /// iteration goes on converging towards the moved solution, while the input applied meanwhile
    /// is the last one trusted (returning to the shifted plan instead would keep feeding back
    /// from a plan the system has left). The input is clamped to the bounds on the top
    /// derivative ([`Self::clamp_input`]), so it always satisfies them. No allocation; a
    /// failure is in the status, never an error.
    pub fn control<const S: usize, const M: usize>(
        &self,
        rti: &mut RealTimeIteration<N, X>,
        start: &[f64; X],
        options: &ControlOptions,
    ) -> Control<N, X>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M>,
    {
        let shifted = first_step(rti);
        let (mut iterations, mut largest, mut last) = (0, 0.0_f64, f64::INFINITY);
        for i in 0..options.iterations.max(1) {
            if i > 0 && self.prepare::<S, M>(rti).is_err() {
                break;
            }
            let Ok(fed) = self.feedback::<S, M>(rti, start) else {
                break;
            };
            iterations += 1;
            largest = largest.max(fed.step);
            last = fed.step;
        }
        let replan = first_step(rti);
        let source = if iterations == 0 {
            InputSource::Shifted(Fallback::Failed)
        } else if largest > options.max_step || largest.is_nan() {
            InputSource::Shifted(Fallback::StepLimit)
        } else if !replan.1.iter().all(|v| v.is_finite()) {
            InputSource::Shifted(Fallback::NotFinite)
        } else if last <= options.converged_step {
            InputSource::Converged
        } else {
            InputSource::Unconverged
        };
        let first = match source {
            InputSource::Shifted(_) => shifted,
            _ => replan,
        };
        self.clamped_control(first, source, (iterations, largest))
    }

    /// The [`Control`] of a period whose plan's first step is `first` $= ((x_0, x_1), u_0)$,
    /// read from the plan `source` says, after `work` $=$ (iterations, largest Newton step):
    /// its input $u_0$ clamped ([`Self::clamp_input`]) and the status saying whether it was.
    /// For a caller's own re-plan (a full solve from the shifted plan) as for
    /// [`Self::control`].
    pub fn clamped_control(
        &self,
        (x, planned): ([SVector<f64, X>; 2], SVector<f64, N>),
        source: InputSource,
        (iterations, step): (usize, f64),
    ) -> Control<N, X> {
        let input = self.clamp_input(&planned);
        Control {
            input,
            planned,
            x,
            status: ControlStatus {
                source,
                clamped: input != planned,
                iterations,
                step,
            },
        }
    }
}

/// The first step of the iterate of `rti`: $(x_0, x_1)$ and $u_0$.
fn first_step<const N: usize, const X: usize>(
    rti: &RealTimeIteration<N, X>,
) -> ([SVector<f64, X>; 2], SVector<f64, N>) {
    let (x, u) = (rti.x(), rti.u());
    match (x.first(), x.get(1), u.first()) {
        (Some(&x0), Some(&x1), Some(&u0)) => ([x0, x1], u0),
        _ => ([SVector::repeat(f64::NAN); 2], SVector::repeat(f64::NAN)),
    }
}
