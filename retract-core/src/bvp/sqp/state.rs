//! One run of the SQP iteration ([`Sqp`]: the problem, its dynamics, the placed
//! inequalities, the workspace's pool, the options) and what its phases pass each other: the
//! models of an iterate ([`Models`]), a solved subproblem ([`Subproblem`]), the state carried
//! from one iterate to the next ([`State`]); the pool's take and give for them, and the clock.

use std::cell::{Cell, RefCell};
use std::time::Instant;

use nalgebra::SVector;

use super::acceptable::Kept;
use super::adaptive::Adaptive;
use super::filter::Filter;
use crate::bvp::barrier::Barrier;
use crate::bvp::constraints::{ConstraintKind, ConstraintRef, Inequality, Linearized};
use crate::bvp::dynamics::Dynamics;
use crate::bvp::iterate::Iterate;
use crate::bvp::kkt::model::{StageModel, Terminal};
use crate::bvp::kkt::riccati::{Direction, Riccati};
use crate::bvp::options::PlanOptions;
use crate::bvp::plan::violations::{Infeasibility, Location};
use crate::bvp::plan::{Certificate, Plan};
use crate::bvp::problem::OptimalControlProblem;
use crate::bvp::workspace::Pool;
use crate::{Lagrangian, LiftedSystem};

/// One run of the SQP iteration.
pub(in crate::bvp) struct Sqp<
    'p,
    'a,
    Sys: ?Sized,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
> {
    pub problem: &'p OptimalControlProblem<'a, Sys, N, K, X>,
    pub dynamics: Dynamics<N, X>,
    pub started: Instant,
    /// The inequalities placed at the steps' evaluation points.
    pub at_steps: &'p [Inequality<'a, N, K>],
    /// The inequalities placed at the nodes (imposed at the interior ones).
    pub at_nodes: &'p [Inequality<'a, N, K>],
    /// The weights of `at_steps` and `at_nodes` in the constraint violation
    /// ([`crate::bvp::constraints::violation_weights`]; 1 where missing).
    pub violation_weights: (&'p [f64], &'p [f64]),
    /// The vectors kept between iterations and solves.
    pub pool: &'p RefCell<Pool<N, X>>,
    /// The options of this run (the problem's, or those of a real-time iteration).
    pub options: PlanOptions,
    /// A real-time iteration: the iterate at the iteration limit is a result, not a failure.
    pub real_time: bool,
    /// The cost's scale $\sigma$: the iteration minimises $\sigma J$ (its multipliers,
    /// momenta, barrier parameter and curvature are those of $\sigma J$), and
    /// [`Self::plan`] reports them unscaled ([`super::PlanOptions::scaling_max_gradient`]).
    pub scale: f64,
    /// Whether each subproblem's solution is checked for a residual above rounding and then
    /// refined ([`needs_refinement`](crate::bvp::kkt::refine::needs_refinement)): set for
    /// the rest of the run once a full Newton step near a solution left the error no lower,
    /// or a line search made only rounding-level progress (the signs of a solve without the
    /// digits the step needs, e.g. a weakly controllable system's terminal pivot; the check
    /// costs a pass over the steps, 5-15 % of the swing-up suite's solve times, so it is
    /// not made before).
    pub check_refinement: Cell<bool>,
}

/// The models of all stages at one iterate.
pub(super) struct Models<const N: usize, const X: usize> {
    pub stages: Vec<StageModel<N, X>>,
    /// $J$.
    pub cost: f64,
    /// $J - h \mu \sum \ln g$.
    pub barrier_cost: f64,
    pub r0: SVector<f64, X>,
    pub r_end: SVector<f64, X>,
    /// The inequalities at every step (step-major).
    pub inequalities: Vec<Linearized<N, X>>,
    /// The gradient of $h L$ alone at every step (the models hold the barrier's too).
    pub cost_gradient: Vec<(SVector<f64, X>, SVector<f64, N>)>,
    /// $\sum |g - s|$ and $\max |g - s|$ over the inequalities.
    pub slack_violation: (f64, f64),
    /// The end: the terminal cost's Hessian and the fixed components of $x_N$.
    pub terminal: Terminal<X>,
    /// $\nabla\Phi(x_N)$ (zero without a terminal cost).
    pub terminal_gradient: SVector<f64, X>,
}

/// A solved subproblem: the factorisation used (`stale` if it is the previous iterate's),
/// its inertia correction, the direction, the momenta and residuals, and the error
/// $\max$(stationarity, feasibility).
pub(super) struct Subproblem<const N: usize, const X: usize> {
    pub riccati: Riccati<N, X>,
    pub rho: f64,
    pub stale: bool,
    pub direction: Direction<N, X>,
    pub momenta: Vec<SVector<f64, X>>,
    pub certificate: Certificate,
    pub error: f64,
    /// The error of the barrier problem, IPOPT's $E_\mu$ per unit time: the absolute
    /// stationarity $\sigma \times$ the relative one over $s_d$, the feasibility and $\max |z s
    /// - \mu|$ over $s_c$ ([`Barrier::error_scales`]); see [`Sqp::barrier_error`].
    pub barrier_error: f64,
}

/// What the iteration carries from one iterate to the next.
pub(super) struct State<const N: usize, const X: usize> {
    pub iterate: Iterate<N, X>,
    /// The stage equalities' multipliers.
    pub y: Vec<SVector<f64, N>>,
    /// The multipliers $\mu_i$ of the $x$-equations carried from iterate to iterate as IPOPT
    /// carries its multipliers (from the least-squares estimate, each step a fraction
    /// $\alpha$ of the way to the subproblem's own,
    /// [`step_multipliers`](crate::bvp::kkt::residuals::step_multipliers)), for IPOPT's
    /// barrier test at the current multipliers; `None` where they are not carried (a warm
    /// start, after the restoration phase).
    pub mu: Option<Vec<SVector<f64, X>>>,
    pub barrier: Barrier,
    pub filter: Option<Filter>,
    /// The last direction, after a full step (its multipliers are the Newton estimates at the
    /// new iterate).
    pub full_step: Option<Direction<N, X>>,
    /// A factorisation kept for a simplified Newton step, with the error where it was made.
    pub kept: Option<(Riccati<N, X>, f64)>,
    /// The last point where the barrier problem was solved with the error below the
    /// tolerance and the complementarity below the acceptable level, kept for the
    /// acceptable-level exit ([`super::acceptable`]).
    pub acceptable: Option<Kept<N, X>>,
    /// The adaptive barrier update's state ([`crate::bvp::BarrierUpdate::Adaptive`] with
    /// inequalities; `None` for the monotone update).
    pub adaptive: Option<Adaptive>,
}

impl<const N: usize, const X: usize> State<N, X> {
    /// The carried multipliers $\mu$ a fraction `alpha` of the way to the subproblem's
    /// `target` (IPOPT's $\alpha_y = \alpha$), or dropped after a point of the restoration
    /// phase (`restored`).
    pub(super) fn carry_multipliers(
        &mut self,
        target: &[SVector<f64, X>],
        (alpha, restored): (f64, bool),
        pool: &mut Pool<N, X>,
    ) {
        if restored {
            if let Some(carried) = self.mu.take() {
                pool.jets.give(carried);
            }
            return;
        }
        if let Some(carried) = &mut self.mu {
            for (c, target) in carried.iter_mut().zip(target) {
                *c += (target - *c) * alpha;
            }
        }
    }

    /// In the adaptive update's free mode, $\mu$ chosen afresh ([`Adaptive::choose`]) and
    /// the filter emptied with it (the barrier cost changes with $\mu$, as in IPOPT).
    pub(super) fn choose_barrier(&mut self, floor: f64) {
        if let Some(adaptive) = &mut self.adaptive
            && adaptive.choose(&mut self.barrier, floor)
            && let Some(filter) = &mut self.filter
        {
            filter.reset();
        }
    }

    /// $\mu$ set to `mu`, the filter emptied with it.
    pub(super) fn set_barrier(&mut self, mu: f64) {
        self.barrier.mu = mu;
        if let Some(filter) = &mut self.filter {
            filter.reset();
        }
    }
}

impl<const N: usize, const X: usize> Models<N, X> {
    /// The largest entry of the scheme's defects $\Phi_h(x_i, u_i) - x_{i+1}$ and of the
    /// fixed ends' misses $|x_0 - \text{start}|$, $|x_N - \text{goal}|$ (the equality rows the
    /// problem's own [`OptimalControlProblem::violations`] leaves out), as the constraint a
    /// stalled solve names; `None` without steps.
    pub(super) fn worst_defect(&self) -> Option<Infeasibility> {
        let named = |(kind, name), index, location, violation: f64| Infeasibility {
            constraint: ConstraintRef { kind, index, name },
            location,
            violation: violation.abs(),
        };
        let dynamics = (ConstraintKind::Dynamics, "dynamics");
        let steps = self.stages.iter().enumerate().map(|(i, stage)| {
            let r = stage.defect.iamax();
            named(dynamics, r, Location::Step(i), stage.defect[r])
        });
        let end = (ConstraintKind::FixedEnd, "end");
        let ends = [(&self.r0, Location::Start), (&self.r_end, Location::Goal)]
            .map(|(miss, at)| named(end, miss.iamax(), at, miss.amax()));
        steps
            .chain(ends)
            .max_by(|a, b| a.violation.total_cmp(&b.violation))
    }

    /// $\Vert c\Vert_1$ over defects, stage constraints and boundary data.
    pub(super) fn violation_l1(&self) -> f64 {
        self.slack_violation.0
            + self
                .stages
                .iter()
                .map(|s| s.defect.lp_norm(1) + s.value.lp_norm(1))
                .sum::<f64>()
            + self.r0.lp_norm(1)
            + self.r_end.lp_norm(1)
    }
    /// $\Vert c\Vert_\infty$.
    pub(super) fn violation_max(&self) -> f64 {
        self.stages
            .iter()
            .map(|s| s.defect.amax().max(s.value.amax()))
            .fold(self.r0.amax().max(self.r_end.amax()), f64::max)
            .max(self.slack_violation.1)
    }
}

impl<Sys, const N: usize, const K: usize, const X: usize, const S: usize, const M: usize>
    Sqp<'_, '_, Sys, N, K, X, S, M>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
{
    /// An empty iterate of `steps` steps, from the pool.
    pub(super) fn take_iterate(&self, steps: usize) -> Iterate<N, X> {
        let mut pool = self.pool.borrow_mut();
        Iterate {
            x: pool.jets.take(steps + 1),
            u: pool.tops.take(steps),
        }
    }

    /// Gives an iterate's vectors back to the pool.
    pub(super) fn give_iterate(&self, iterate: Iterate<N, X>) {
        let mut pool = self.pool.borrow_mut();
        pool.jets.give(iterate.x);
        pool.tops.give(iterate.u);
    }

    /// Gives a plan's vectors back to the pool.
    pub(super) fn give_plan(&self, plan: Plan<N, X>) {
        self.pool.borrow_mut().give_plan(plan);
    }

    /// Gives the models' vectors back to the pool.
    pub(super) fn give_models(&self, models: Models<N, X>) {
        let mut pool = self.pool.borrow_mut();
        pool.stages.give(models.stages);
        pool.linearized.give(models.inequalities);
        pool.gradients.give(models.cost_gradient);
    }

    /// Gives a subproblem's vectors back to the pool.
    pub(super) fn give_subproblem(&self, sub: Subproblem<N, X>) {
        let mut pool = self.pool.borrow_mut();
        sub.riccati.recycle(&mut *pool);
        sub.direction.recycle(&mut *pool);
        pool.jets.give(sub.momenta);
    }

    /// Gives the models' and the subproblem's vectors back to the pool at a failure, keeping
    /// what its last iterate reports: the models' cost, the subproblem's certificate and its
    /// momenta.
    pub(super) fn hand_back(
        &self,
        models: Models<N, X>,
        mut sub: Subproblem<N, X>,
    ) -> (f64, Certificate, Vec<SVector<f64, X>>) {
        let kept = (
            models.cost,
            sub.certificate,
            core::mem::take(&mut sub.momenta),
        );
        self.give_models(models);
        self.give_subproblem(sub);
        kept
    }

    pub(super) fn x_theta(&self, iterate: &Iterate<N, X>, i: usize) -> SVector<f64, X> {
        let theta = self.dynamics.theta;
        iterate.x[i] * (1.0 - theta) + iterate.x[i + 1] * theta
    }

    /// When the wall-time budget runs out: the start of the solve plus
    /// [`super::PlanOptions::max_time`].
    pub(super) fn deadline(&self) -> Option<Instant> {
        let budget = self.options.max_time?;
        self.started.checked_add(budget)
    }

    /// Whether the wall-time budget ([`Self::deadline`]) has run out.
    pub(super) fn out_of_time(&self) -> bool {
        self.deadline().is_some_and(|d| Instant::now() >= d)
    }
}
