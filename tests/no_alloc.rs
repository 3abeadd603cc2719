//! The stepping path allocates nothing: a counting global allocator sees zero allocations
//! during steps (predictor, Newton, domain check), a Newton solve, the symplecticity
//! diagnostic and an RK4 step of a generated system; nor do the optimizer's warm re-solves in
//! a workspace and the receding horizon's control periods.

mod common;

use common::models::Scene;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use retract::diagnostics::{rk4_step, symplecticity_error};
use retract::nalgebra::SVector;
use retract::{LiftedSystem, ReducedStepper, StepOptions, step};

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

struct Counting;

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

#[test]
fn stepping_allocates_nothing() {
    let obstacles = [[0.0, 0.0, 1.0], [3.0, 2.0, 0.5]];
    let system = Scene {
        tau: 1e-2,
        obstacles: &obstacles,
    };
    let jet = SVector::<f64, 12>::from_column_slice(&[
        -2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ]);
    let z0 = system.legendre(&jet);
    let options = StepOptions::default();
    let mut stepper = ReducedStepper::new(&system);
    let before = allocations();
    let mut z = z0;
    let mut iterations = 0;
    for _ in 0..400 {
        let (next, report) = step(&system, &z, 0.01, &options).expect("regular step");
        z = next;
        iterations += report.iterations;
    }
    let sympl = symplecticity_error(&system, &z, 0.01, &options).expect("regular");
    let explicit = rk4_step(&system, &z, 0.01).expect("regular");
    // the reduced stepper with a new step size each step: new factors each step, in the
    // slots of its cache (more sizes than slots, so slots are overwritten)
    let sizes = 2 * retract::scheme::reduced::CACHE_SIZE;
    let mut reduced = z0;
    for i in 0..sizes {
        let h = 0.01 * (1.0 + 0.001 * i as f64);
        reduced = stepper.step(&reduced, h, &options).expect("regular step").0;
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations on the stepping path");
    // the work was real
    assert!(iterations > 400 && sympl < 1e-12 && explicit[0] > z0[0]);
    assert!(stepper.factorisations() == sizes && reduced[0] > z0[0]);
    // and the counter works: a Vec allocates
    let v: Vec<f64> = Vec::with_capacity(4);
    assert!(allocations() > after && v.capacity() >= 4);
}

/// A stage constraint with a run-time list: linear in q''.
#[retract::jet_function(order = 2)]
fn clearance_rate(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], discs: &[[f64; 3]]) -> f64 {
    let mut s = ddq[0] * dq[1] - ddq[1] * dq[0];
    for d in discs {
        s += (-((q[0] - d[0]).powi(2) + (q[1] - d[1]).powi(2)).sqrt()).exp() * d[2];
    }
    s
}

#[test]
fn jet_functions_allocate_nothing() {
    use retract::JetFunction;
    let discs = [[0.0, 0.0, 1.0], [3.0, 2.0, 0.5]];
    let g = ClearanceRate::new(&discs);
    let x = [SVector::from([1.0, 2.0]), SVector::from([0.5, -0.5])];
    let u = SVector::from([0.3, 0.1]);
    let before = allocations();
    let mut acc = 0.0;
    for _ in 0..100 {
        acc += g.value(&x, &u) + g.gradient(&x, &u).u[0] + g.hessian(&x, &u).xu[1][(0, 0)];
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in a jet function");
    assert!(acc.is_finite() && acc != 0.0);
}

// the cart-pole of the swing-up suite, shared with the examples
#[path = "../examples/common/cart_pole.rs"]
mod cart_pole;

/// A warm re-solve in a workspace that has seen a solve of the same size allocates nothing:
/// the bounded cart-pole (C1 of the constrained suite, T = 2, |F| <= 12, at a fifth of its
/// steps: an equality, a two-sided inequality, the barrier, the filter and the certificate's
/// smallest eigenvalue), re-solved from the plan of the previous start as the start moves,
/// with the replaced plans given back to the workspace.
#[test]
fn a_warm_re_solve_in_a_workspace_allocates_nothing() {
    use cart_pole::{CartForce, CartPole, PoleTorque};
    use retract::bvp::{OptimalControlProblem, PlanGuess, Workspace};
    let system = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, 9.81);
    let force = CartForce::new(1.0, 0.3, 0.5);
    let upright = [0.0, std::f64::consts::PI, 0.0, 0.0];
    let mut problem = OptimalControlProblem::new(&system, &[0.0; 4], &upright, 2.0, 40)
        .with_equality(&unactuated)
        .with_function_bounds(&force, -12.0, 12.0);
    let mut workspace = Workspace::new();
    let mut plan = problem
        .solve_with(PlanGuess::Spline, &mut workspace)
        .expect("cold");
    let mut counted = Vec::new();
    for (k, x0) in [0.01, 0.02, 0.03, 0.04].into_iter().enumerate() {
        problem.set_start(&[x0, 0.0, 0.0, 0.0]);
        let before = allocations();
        let next = problem
            .solve_with(PlanGuess::Plan(&plan), &mut workspace)
            .unwrap_or_else(|e| panic!("x0 = {x0}: {e}"));
        workspace.recycle(std::mem::replace(&mut plan, next));
        // (the first warm solve sizes what a warm solve needs beyond a cold one)
        if k > 0 {
            counted.push((x0, allocations() - before, plan.iterations));
        }
    }
    for (x0, count, iterations) in counted {
        assert_eq!(
            count, 0,
            "x0 = {x0}: {count} allocations in {iterations} iterations"
        );
        // the work was real: iterations, the bound held, a certified minimum
        assert!(iterations >= 1, "x0 = {x0}");
    }
    let eig = plan.certificate.min_reduced_hessian_eig;
    assert!(eig > 0.0 && eig.is_finite(), "{eig}");
    assert!(plan.violations.imposed() <= 1e-8 && (plan.x[0][0] - 0.04).abs() < 1e-12);
}

/// A failed solve gives the vectors it held back to the workspace: after a solve interrupted
/// by a zero budget while the models are built (the clock is read every 1024 steps of the
/// build, so the budget runs out at its last step) or one that ends at its iteration limit
/// after one iteration from the spline (the models' and the subproblem's vectors), both at
/// N = 1024, and the failed iterate recycled, a warm re-solve allocates nothing.
#[test]
fn a_failed_solve_keeps_the_workspace_whole() {
    use cart_pole::{CartForce, CartPole, PoleTorque};
    use retract::bvp::{Failure, OptimalControlProblem, PlanGuess, PlanOptions, Workspace};
    use std::time::Duration;
    let system = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, 9.81);
    let force = CartForce::new(1.0, 0.3, 0.5);
    let problem = OptimalControlProblem::new(&system, &[0.0; 4], &[0.5, 0.0, 0.0, 0.0], 2.0, 1024)
        .with_equality(&unactuated)
        .with_function_bounds(&force, -1.0, 1.0);
    let failures = [
        (
            PlanOptions::default().with_max_time(Duration::ZERO),
            Failure::TimeLimit,
        ),
        (
            PlanOptions::default().with_max_iterations(1),
            Failure::IterationLimit,
        ),
    ];
    for (options, expected) in failures {
        let mut workspace = Workspace::new();
        let cold = problem
            .solve_with(PlanGuess::Spline, &mut workspace)
            .expect("cold");
        let warm = problem
            .solve_with(PlanGuess::Plan(&cold), &mut workspace)
            .expect("warm");
        workspace.recycle(cold);
        // (the budget from the warm plan, the iteration limit from the spline: one iteration
        // from the warm plan would converge)
        let guess = match expected {
            Failure::TimeLimit => PlanGuess::Plan(&warm),
            _ => PlanGuess::Spline,
        };
        let failed = problem
            .clone()
            .with_options(options)
            .solve_with(guess, &mut workspace)
            .expect_err("a failure");
        assert_eq!(failed.failure, expected, "{failed}");
        workspace.recycle(*failed.last.expect("the iterate"));
        let before = allocations();
        let again = problem
            .solve_with(PlanGuess::Plan(&warm), &mut workspace)
            .expect("warm again");
        let count = allocations() - before;
        assert_eq!(count, 0, "{count} allocations after {expected:?}");
        assert!(again.certificate.min_reduced_hessian_eig > 0.0);
    }
}

// the double pendulum's receding-horizon controller, shared with the examples
#[path = "../examples/common/pendulum.rs"]
mod pendulum;

/// A control period of the receding horizon (the real-time iterations' feedback from the
/// measured state, the shift and the next preparation, the first torque and the plant's step)
/// allocates nothing: 300 periods of the swing-up of `examples/mpc_swing_up.rs`, counted from
/// period 50.
#[test]
fn a_receding_horizon_period_allocates_nothing() {
    use pendulum::{Controller, Replan, models, plant_step};
    let (model, plant) = models();
    let mut jet = [0.0; 4];
    let mut z = plant.legendre(&SVector::from(jet));
    let mut controller = Controller::new(&model, &jet).expect("swing-up");
    let (mut counted, mut certified) = (0, 0);
    for period in 0..300 {
        let before = allocations();
        let outcome = controller.replan(&jet);
        (z, jet) = plant_step(&plant, &z, &jet, controller.torque()).expect("plant step");
        if period >= 50 {
            counted += allocations() - before;
            certified += usize::from(outcome == Replan::Converged);
        }
        assert_ne!(outcome, Replan::Failed, "period {period}");
    }
    assert_eq!(counted, 0, "allocations in 250 periods");
    // the work was real: the pendulum is upright and the re-plans converged
    let off = (jet[0] - std::f64::consts::PI).abs().max(jet[1].abs());
    assert!(off < 1e-2 && certified > 200, "{jet:?} {certified}");
}

// the receding-horizon benchmark's controller, shared with `examples/mpc.rs`
#[path = "../examples/common/upright.rs"]
mod upright;

/// A control period of real-time iterations (the feedback step from the measured state, a
/// second preparation and feedback for two iterations, the torque, the shift and the
/// preparation for the next period, and the plant's step) allocates nothing: 100 periods of
/// the benchmark of `examples/mpc.rs` with its (+8, -8) kick at period 25, counted from
/// period 5, with one and with two iterations a period.
#[test]
fn a_real_time_iteration_period_allocates_nothing() {
    use upright::{Controller, KICK_PERIOD, Mode, UPRIGHT, deviation};
    let (model, plant) = pendulum::upright_models();
    for mode in [Mode::Rti(1), Mode::Rti(2)] {
        let mut controller = Controller::new(&model, mode).expect("upright");
        let mut jet = UPRIGHT;
        let mut z = plant.legendre(&SVector::from(jet));
        let (mut counted, mut largest) = (0, 0.0_f64);
        for period in 0..100 {
            if period == KICK_PERIOD {
                jet[2] += 8.0;
                jet[3] -= 8.0;
                z = plant.legendre(&SVector::from(jet));
            }
            let before = allocations();
            let applied = controller.control(&jet);
            let failed = controller.prepare();
            (z, jet) = pendulum::plant_step(&plant, &z, &jet, applied.tau).expect("plant step");
            if period >= 5 {
                counted += allocations() - before;
            }
            assert!(!applied.failed() && !failed, "{mode:?}, period {period}");
            largest = largest.max(deviation(&jet));
        }
        assert_eq!(counted, 0, "{mode:?}: allocations in 95 periods");
        // the work was real: the kick moved the pendulum
        assert!(largest > 0.5, "{mode:?}: {largest}");
    }
}
