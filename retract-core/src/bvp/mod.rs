//! Optimal control on the lifted scheme: an optimizer and a root finder.
//!
//! Given the jet $x = (q, \dots, q^{(k-1)})$ at both ends, $x(0) = a$ and $x(T) = b$, and
//! $N$ steps of $h = T/N$, the discrete necessary conditions of the lifted scheme are the
//! KKT system of the direct transcription
//!
//! $$\min \sum_{i<N} h\thinspace L(x_{\theta,i}, u_i) \quad \text{s.t.} \quad x_{i+1} - x_i = h A
//!   x_{\theta,i} + h B u_i, \quad x_0 = a, \quad x_N = b,$$
//!
//! whose multipliers are the momenta.
//!
//! - [`OptimalControlProblem`] minimises it (SQP with a Riccati KKT solve, inertia
//!   correction, IPOPT's filter line search, stage equalities and interior-point
//!   inequalities) and returns only certified local minima ([`Plan`], [`Certificate`]); every
//!   failure carries the last iterate ([`PlanError`]).
//! - [`root_finder`], the legacy root finder, kept as a cross-check of the optimizer and
//!   behind it: [`root_finder::BoundaryValueProblem`] solves the same conditions by Newton's
//!   method on their residual, blind to the cost (it can stop at a saddle). Everything a plan
//!   needs (guesses, options, results, warm starts, continuation in a parameter by warm
//!   starts) is the optimizer's; the root finder's types live in its module only.
//!
//! # Modules
//! In dependency order: a module imports only modules listed before it, so there is no
//! import cycle. Inside a folder, `mod.rs` and its files import in one direction only:
//! `problem/`'s files import the problem from its `mod.rs`; `plan/`'s and `sqp/`'s `mod.rs`
//! import from their files, which import only their siblings.
//!
//! 1. Leaves, importing nothing of the planner: `iterate` (an iterate's jets and top
//!    derivatives), `guess` (the Hermite spline), `stack` (a stack of kept vectors),
//!    `dynamics` (the transcription's linear step, with `dynamics/shift.rs`).
//! 2. `constraints` (the stage constraints: kinds, placement, values and derivatives),
//!    `curve` (guesses from a path $q(t)$, [`Curve`]), the root finder `root_finder` (with
//!    `root_finder/condense.rs`).
//! 3. `plan/`: the results: `mod.rs` ([`Plan`], [`RealTime`], [`PlanError`]),
//!    `certificate.rs` ([`Certificate`] and the advice of a failure), `failure.rs`
//!    ([`Failure`]), `duals.rs` ([`Duals`], for warm starts), `violations.rs`
//!    ([`Violations`], [`Infeasibility`]).
//! 4. `options` ([`PlanOptions`], [`PlanGuess`]).
//! 5. `problem/`: the problem ([`OptimalControlProblem`] and its builders in `mod.rs`;
//!    `constrain.rs` its constraints, `validate.rs` its checks, `measure.rs` an iterate's
//!    violations).
//! 6. `kkt/`: the subproblem's linear algebra (`model.rs` its data, `pivots.rs` the small
//!    dense inverses with their inertia, `riccati.rs` the factorisation, its inertia and
//!    solves; `refine.rs`; `residuals.rs` the KKT residuals and the reduced Hessian's smallest
//!    eigenvalue); it takes its vectors through a trait, not from the workspace.
//! 7. `barrier` (the interior-point terms of the inequalities), `workspace` (the vectors a
//!    solve keeps for the next: [`Workspace`], a warm re-solve that allocates nothing).
//! 8. `sqp/`: the iteration, one module per phase (`models`, `direction`, `line_search` with
//!    `filter`, `termination`, `second_order`) over `state`, and the loop in `mod.rs`.
//! 9. `solve` (the solve front: [`OptimalControlProblem::solve`] and its variants, the first
//!    iterate), `extrapolate` (Richardson extrapolation, [`Extrapolated`]), `free_time` (the
//!    horizon as a decision variable, [`FreeTime`], [`FreeTimePlan`]).
//! 10. `realtime` (real-time iterations in a preparation and a feedback phase,
//!     [`RealTimeIteration`]), `control` (a control period's safeguarded input and its
//!     status, [`OptimalControlProblem::control`]), `sensitivity` (a plan's derivatives with
//!     respect to its start and the Lagrangian's parameters from the factorisation at the
//!     solution).
//! 11. `batch` (many plans at once: [`solve_batch`], [`solve_stream`],
//!     [`OptimalControlProblem::solve_multistart`]; on rayon's thread pool with the
//!     `parallel` feature).
//!
//! # Example
//! The hand-written disc system of [`crate::models`] (with `retract`, a `#[higher_order_lagrangian]`
//! type is used the same way): from rest at $(2, 0)$ to rest at $(3, 1)$ in $T = 1$.
//! ```
//! use retract_core::bvp::{OptimalControlProblem, PlanGuess, PlanOptions};
//! use retract_core::models::PlanarBarrier;
//!
//! let system = PlanarBarrier { tau: 1e-12, radius: 1.0, mass: 1.0 };
//! let (start, goal) = ([2.0, 0.0, 0.0, 0.0], [3.0, 1.0, 0.0, 0.0]);
//! let plan = OptimalControlProblem::new(&system, &start, &goal, 1.0, 50)
//!     .with_options(PlanOptions::default().with_min_eigenvalue(true))
//!     .solve(PlanGuess::Spline)
//!     .expect("a certified minimum");
//! // without the (here negligible) barrier the optimum costs 6 |q(T) - q(0)|^2 / T^3 = 12
//! assert!((plan.cost - 12.0).abs() < 1e-2, "{}", plan.cost);
//! assert!(plan.certificate.min_reduced_hessian_eig > 0.0);
//! assert_eq!(plan.x.len(), 51);
//! ```
//!
//! # Receding horizon
//! Each control period the system moves one step along the plan, and the problem is solved
//! again from there, warm-started from [`Plan::shifted`] with a budget of SQP iterations
//! ([`OptimalControlProblem::solve_real_time`]); a loop that must not allocate re-solves one
//! problem ([`OptimalControlProblem::set_start`]) in a [`Workspace`]
//! ([`OptimalControlProblem::solve_with`]). Without the barrier ($\tau = 0$) the cost is
//! quadratic and the dynamics linear, so one SQP step from any guess reaches the minimum. By
//! the principle of optimality, the rest of an optimal plan is the optimal plan from its
//! second state over the remaining $N - 1$ steps:
//! ```
//! use retract_core::bvp::{OptimalControlProblem, PlanGuess};
//! use retract_core::models::PlanarBarrier;
//!
//! let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
//! let (goal, t_end, steps) = ([3.0, 1.0, 0.0, 0.0], 1.0, 50);
//! let problem = OptimalControlProblem::new(&system, &[2.0, 0.0, 0.0, 0.0], &goal, t_end, steps);
//! let mut plan = problem.solve(PlanGuess::Spline)?;
//! for _ in 0..3 {
//!     let start = plan.x[1].into(); // where the first step of the plan went
//!     let problem = OptimalControlProblem::new(&system, &start, &goal, t_end, steps);
//!     let next = problem.solve_real_time(PlanGuess::Plan(&plan.shifted()), 1)?;
//!     assert!(next.converged);
//!     plan = next.plan;
//! }
//! // shrinking horizon: the tail of the plan is optimal for the tail problem
//! let start = plan.x[1].into();
//! let tail = OptimalControlProblem::new(&system, &start, &goal, t_end - plan.h, steps - 1)
//!     .solve(PlanGuess::Path { x: &plan.x[1..], u: &plan.u[1..] })?;
//! for (a, b) in tail.x.iter().zip(&plan.x[1..]) {
//!     assert!((a - b).amax() < 1e-8);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod barrier;
mod batch;
mod constraints;
mod control;
mod curve;
mod dynamics;
mod extrapolate;
mod free_time;
mod guess;
mod iterate;
mod kkt;
mod options;
mod plan;
mod plan_sensitivity;
mod problem;
mod realtime;
mod sensitivity;
mod solve;
mod sqp;
mod stack;
mod workspace;

pub use batch::{Job, MultiStart, Outcome, Stream, solve_batch, solve_stream};
pub use constraints::{ConstraintKind, ConstraintRef, Placement, Variable};
pub use control::{Control, ControlOptions, ControlStatus, Fallback, InputSource};
pub use curve::Curve;
pub use extrapolate::Extrapolated;
pub use free_time::{FreeTime, FreeTimePlan};
pub use options::{BarrierUpdate, MAX_INTERIOR_SAMPLES, PlanGuess, PlanOptions};
pub use plan::duals::Duals;
pub use plan::violations::{INTERPOLANT_DIVISIONS, Infeasibility, Location, Violations};
pub use plan::{Certificate, Failure, Plan, PlanError, RealTime};
pub use plan_sensitivity::{Adjoint, PlanGradient, PlanSensitivities};
pub use problem::OptimalControlProblem;
pub use realtime::{Feedback, Preparation, RealTimeIteration};
pub use sensitivity::{Parameter, ParameterSensitivity, Sensitivity};
pub use workspace::Workspace;

pub mod root_finder;
