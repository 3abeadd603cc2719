//! Why a solve returns no plan ([`Failure`]) and the message of each reason.

use super::violations::Infeasibility;
use crate::{DomainViolation, Error};

/// Why the optimizer stopped without a certified plan.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Failure {
    /// Invalid input (no iterate).
    Invalid(Error),
    /// The first guess leaves the domain of $L$ (e.g. passes through an obstacle) at step
    /// `step`.
    GuessOutsideDomain {
        /// The step.
        step: usize,
        /// What was violated.
        violation: DomainViolation,
    },
    /// A model value (cost, gradient, Hessian) was not finite.
    NonFinite,
    /// The iteration budget ran out.
    IterationLimit,
    /// The wall-time budget ran out.
    TimeLimit,
    /// No step along the (descent) direction was accepted, and the feasibility restoration
    /// phase, where it ran, found no point the filter accepts (an iterate that violates a
    /// constraint beyond the tolerance there is named [`Failure::StalledInfeasible`]).
    LineSearch,
    /// The inertia correction reached its cap without making the reduced Hessian definite.
    Regularization,
    /// A constraint the interior-point iteration cannot satisfy (refused before iterating):
    /// its own data contradict themselves or leave no interior (equal sides: write an
    /// equality), or the fixed start or goal violates it at the node.
    Infeasible(Infeasibility),
    /// The iteration stalled at a point that violates a constraint (the inertia correction or
    /// the line search failed there): the constraint violated most at the last iterate, where,
    /// and by how much, among the inequalities, the stage equalities, the scheme's equations
    /// of each step ([`crate::bvp::ConstraintKind::Dynamics`]) and the fixed ends
    /// ([`crate::bvp::ConstraintKind::FixedEnd`]). The constraints may contradict each other there (a point of local
    /// infeasibility), or the guess meets an obstacle head on, with no side to pass it
    /// preferred.
    StalledInfeasible(Infeasibility),
    /// The free-time search ([`crate::bvp::OptimalControlProblem::solve_free_time`]) ended
    /// without a certified horizon, with the best plan found attached: it made `solves`
    /// fixed-horizon solves (`iterations` SQP iterations in all) and either spent its budget of
    /// solves (`budget_spent`) or ran its rounds, each ended by a probe at $T \pm 10^{-3} T$
    /// that found a lower $\varphi(T) = w T + J^*(T)$ than the minimiser found ($\varphi$ is
    /// not unimodal or not smooth there: the fixed-horizon solves at nearby horizons end in
    /// different local minima, or the active set changes).
    FreeTimeSearch {
        /// Fixed-horizon solves made.
        solves: usize,
        /// SQP iterations of all of them.
        iterations: usize,
        /// Whether the budget of solves ran out (else the rounds did).
        budget_spent: bool,
    },
    /// The goal cannot be reached: its fixed component `component` depends on the stage
    /// equalities (linearised at the last iterate) and the dynamics alone (they leave it no
    /// control), and at the last iterate no step reduces its miss `miss` $= |x_N -
    /// \text{goal}|$ to first order, for several iterations or where the line search finds
    /// no step (a point of local infeasibility). Either the goal contradicts the equalities
    /// (free that component, [`crate::bvp::OptimalControlProblem::with_free_end`], or change
    /// the goal or the equalities), or only their linearisation at the iterate does (a car
    /// that cannot slip, started standing or sideways to a goal beside it): start from a
    /// guess along which the equalities allow motion towards the goal. Inequalities held at
    /// their bounds act as equalities here (e.g. bounds too narrow for the horizon).
    UnreachableGoal {
        /// The component of $x_N$.
        component: usize,
        /// Its miss at the last iterate.
        miss: f64,
    },
    /// The KKT conditions hold but the reduced Hessian has negative curvature: a saddle, not
    /// a minimum. (With 0 negative directions: the second-order check could not be made,
    /// the constraints' Jacobian losing rank at the point: its count of negative pivots
    /// stays under any shift of the Hessian, so it does not come from curvature. A reduced Hessian that is only
    /// singular, positive semidefinite, is a minimum flat along some direction: certified
    /// with [`Certificate::min_reduced_hessian_eig`](crate::bvp::Certificate::min_reduced_hessian_eig) 0.)
    NotAMinimum {
        /// Negative eigenvalues of the reduced Hessian.
        negative_directions: usize,
    },
    /// A plan's sensitivity was asked where an inequality is weakly active: its value and
    /// its multiplier both vanish (its slack $s$ and multiplier $z$, whose product is the
    /// barrier parameter $\mu$, within a factor 100 of each other: both near $\sqrt\mu$,
    /// where strict complementarity would keep one of order 1), so the active set changes
    /// with any perturbation and the plan is not differentiable there.
    WeaklyActive {
        /// The inequality.
        constraint: super::super::ConstraintRef,
        /// Where.
        location: super::violations::Location,
        /// Its slack $s$.
        slack: f64,
        /// Its multiplier $z$ (per unit time).
        multiplier: f64,
    },
}

impl core::fmt::Display for Failure {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Failure::Invalid(e) => write!(f, "{e}"),
            Failure::GuessOutsideDomain { step, violation } => write!(
                f,
                "the first guess leaves the domain of the Lagrangian at step {step} \
                 ({violation}): pass a guess that stays inside it, e.g. around the obstacle"
            ),
            Failure::NonFinite => write!(
                f,
                "a non-finite cost, gradient or Hessian at an iterate: check the parameters"
            ),
            Failure::IterationLimit => write!(
                f,
                "no certified minimum within the iteration budget; the last iterate is attached"
            ),
            Failure::TimeLimit => write!(
                f,
                "the wall-time budget ran out; the best iterate is attached"
            ),
            Failure::LineSearch => write!(
                f,
                "the line search found no acceptable step (the direction descends, but every \
                 trial point left the domain or did not decrease the merit function); the \
                 last iterate is attached"
            ),
            Failure::Regularization => write!(
                f,
                "the inertia correction could not make the reduced Hessian positive definite"
            ),
            Failure::Infeasible(infeasibility) => write!(f, "infeasible: {infeasibility}"),
            Failure::StalledInfeasible(infeasibility) => write!(
                f,
                "stalled at an infeasible point: {infeasibility}; check that the constraints, \
                 the dynamics and the fixed ends can hold together there (bounds wide enough \
                 for the horizon), or start from a guess that satisfies them (around an \
                 obstacle, not through it)"
            ),
            Failure::UnreachableGoal { component, miss } => write!(
                f,
                "the goal cannot be reached from the last iterate: its component {component} \
                 is left without control by the stage equalities or the inequalities at \
                 their bounds (linearised there) and the dynamics, and no step reduces its \
                 miss {miss:e}; start from a guess along which the constraints allow motion \
                 towards the goal (a path already heading there), free that component \
                 (with_free_end), or make the goal consistent with the constraints (bounds \
                 wide enough for the horizon)"
            ),
            Failure::FreeTimeSearch {
                solves,
                iterations,
                budget_spent,
            } => {
                write!(
                    f,
                    "the free-time search certified no horizon in {solves} fixed-horizon \
                     solves ({iterations} iterations in all): "
                )?;
                if *budget_spent {
                    write!(f, "its budget of solves ran out")?;
                } else {
                    write!(
                        f,
                        "each of its rounds ended with a probe at 0.1 % from the minimiser \
                         found finding a lower w T + J (not unimodal or not smooth in T there: \
                         e.g. the fixed-horizon solves at nearby horizons end in different \
                         local minima, or an active bound changes)"
                    )?;
                }
                write!(
                    f,
                    "; the best plan found is attached: solve at its horizon (h N) with it as \
                     the guess, or narrow [T_min, T_max] about that horizon"
                )
            }
            Failure::NotAMinimum {
                negative_directions: 0,
            } => write!(
                f,
                "the second-order check could not be made at the KKT point found: the \
                 constraints' Jacobian loses rank there (dependent stage constraints, or an \
                 active inequality whose gradient vanishes); remove the redundant ones or \
                 start from another guess"
            ),
            Failure::WeaklyActive {
                constraint,
                location,
                slack,
                multiplier,
            } => {
                match location {
                    super::violations::Location::Node(i) => write!(f, "at node {i}, ")?,
                    super::violations::Location::Step(i) => write!(f, "at step {i}, ")?,
                    other => write!(f, "at {other:?}, ")?,
                }
                write!(
                    f,
                    "{constraint} is weakly active (slack {slack:e}, multiplier \
                     {multiplier:e}: both near zero), so the plan is not differentiable there; \
                     move the constraint off the unconstrained plan or make it strictly active"
                )
            }
            Failure::NotAMinimum {
                negative_directions,
            } => write!(
                f,
                "the KKT point found is not a minimum: its reduced Hessian has \
                 {negative_directions} negative eigenvalue(s); start from another guess (or \
                 allow more new starts from below a saddle: PlanOptions::saddle_escapes)"
            ),
        }
    }
}

impl std::error::Error for Failure {}
