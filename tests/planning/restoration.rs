//! The feasibility restoration phase: a guess from which the filter line search jams (the
//! slacks of the thrust bounds and the disc at their bounds, the steps cut to nothing) is
//! brought back to the feasible region and the plan certified.

use crate::quadrotor::{Clearance, Lateral, Quadrotor, Rotors};
use retract::bvp::{Curve, OptimalControlProblem, PlanGuess, PlanOptions};

/// The quadrotor of the constrained suite (thrusts in [0, 15], the disc, T = 2, N = 50) from
/// the zero guess: every thrust starts at its lower bound, far from the hover thrust; the
/// filter line search takes steps of 1e-3 and shorter and, without restoration, the solve
/// stalled infeasible after 735 iterations (as it still does with the phase off, the
/// default). With it, the plan is certified at IPOPT's
/// minimum on the same transcription from the same guess, J = 51.514725806 (IPOPT 3.14 with
/// MUMPS through CasADi, tol 1e-10, 51 iterations; the reference script `ip.py` with
/// `'{"prob":"quad","T":2.0,"N":50,"kind":"Zero","F":15.0,"goal":[2.0,1.0,0.0]}'`).
#[test]
fn the_quadrotor_from_the_zero_guess_is_restored_and_certified() {
    let (m, inertia, arm) = (1.0, 0.01, 0.1);
    let zero = Curve::from_derivatives(|_, _| [0.0; 3]);
    let plan = OptimalControlProblem::new(
        &Quadrotor::new(m, inertia, arm),
        &[0.0; 6],
        &[2.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        2.0,
        50,
    )
    .with_equality(&Lateral::new(m))
    .with_vector_bounds(&Rotors::new(m, inertia, arm), &[0.0; 2], &[15.0; 2])
    .with_inequality(&Clearance::new())
    .with_options(PlanOptions::default().with_restoration(true))
    .solve(PlanGuess::Curve(&zero))
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(plan.certificate.negative_directions, 0);
    assert!(plan.violations.imposed() <= 1e-8, "{:?}", plan.violations);
    let ipopt = 51.514_725_806_007_796;
    assert!(
        (plan.cost - ipopt).abs() <= 1e-7 * ipopt,
        "J = {}",
        plan.cost
    );
}
