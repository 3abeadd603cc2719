//! Real-time iterations in two phases (`RealTimeIteration`): the feedback step is the
//! tangential predictor of the solution in the start, and the API refuses what it cannot do.

use crate::pendulum::{HORIZON, STEPS, upright_models};
use crate::upright::UPRIGHT;
use retract::bvp::{Failure, OptimalControlProblem, PlanGuess};

/// The largest difference of the jets and top derivatives of two iterates.
fn distance(
    (x, u): (
        &[retract::nalgebra::SVector<f64, 4>],
        &[retract::nalgebra::SVector<f64, 2>],
    ),
    plan: &retract::bvp::Plan<2, 4>,
) -> f64 {
    let dx = x.iter().zip(&plan.x).map(|(a, b)| (a - b).amax());
    let du = u.iter().zip(&plan.u).map(|(a, b)| (a - b).amax());
    dx.chain(du).fold(0.0, f64::max)
}

/// Prepared at the upright plan and fed a start moved by `delta` along a fixed direction,
/// one feedback step lands within O(delta^2) of the plan solved from the moved start (a
/// Newton step of the KKT conditions with the start as a parameter): the error is far below
/// the plan's own change and grows by at least about 4 when delta doubles (here by 8: the
/// problem is symmetric under the reflection q - (pi, 0) -> -(q - (pi, 0)), so the plan is an
/// odd function of the start's change and its second-order term vanishes). From the
/// predicted start itself the step is zero.
#[test]
fn the_feedback_step_is_the_tangential_predictor() {
    let (model, _) = upright_models();
    let problem = OptimalControlProblem::new(&model, &UPRIGHT, &UPRIGHT, HORIZON, STEPS);
    let plan = problem.solve(PlanGuess::Spline).expect("upright");
    let mut rti = problem
        .real_time_iteration(PlanGuess::Plan(&plan))
        .expect("rti");
    problem.prepare(&mut rti).expect("prepared");
    let still = problem.feedback(&mut rti, &UPRIGHT).expect("feedback");
    assert!(still.step < 1e-9 && still.start_change == 0.0, "{still:?}");
    let direction = [0.02, -0.03, 1.0, -1.0];
    let mut errors = Vec::new();
    for delta in [0.01, 0.02] {
        let start = std::array::from_fn(|r| UPRIGHT[r] + delta * direction[r]);
        let mut rti = problem
            .real_time_iteration(PlanGuess::Plan(&plan))
            .expect("rti");
        problem.prepare(&mut rti).expect("prepared");
        let fed = problem.feedback(&mut rti, &start).expect("feedback");
        assert!((fed.start_change - delta).abs() < 1e-15, "{fed:?}");
        assert_eq!(rti.x()[0].as_slice(), start.as_slice());
        let moved = OptimalControlProblem::new(&model, &start, &UPRIGHT, HORIZON, STEPS);
        let exact = moved.solve(PlanGuess::Plan(&plan)).expect("moved");
        let error = distance((rti.x(), rti.u()), &exact);
        let change = distance((&plan.x, &plan.u), &exact);
        assert!(
            error < 0.05 * change,
            "delta {delta}: {error:e} against {change:e}"
        );
        errors.push(error);
    }
    let ratio = errors[1] / errors[0];
    assert!((3.5..9.0).contains(&ratio), "{errors:?}");
}

/// A feedback before any preparation, and a problem with inequalities (a full step has no
/// fraction-to-the-boundary rule), are refused with a reason.
#[test]
fn the_real_time_iteration_refuses_what_it_cannot_do() {
    let (model, _) = upright_models();
    let problem = OptimalControlProblem::new(&model, &UPRIGHT, &UPRIGHT, HORIZON, STEPS);
    let mut rti = problem.real_time_iteration(PlanGuess::Spline).expect("rti");
    let refused = problem
        .feedback(&mut rti, &UPRIGHT)
        .expect_err("unprepared");
    assert!(matches!(refused, Failure::Invalid(_)), "{refused}");
    assert!(refused.to_string().contains("prepared"), "{refused}");
    // once prepared it goes, and the preparation is used up by a feedback
    problem.prepare(&mut rti).expect("prepared");
    problem.feedback(&mut rti, &UPRIGHT).expect("feedback");
    assert!(problem.feedback(&mut rti, &UPRIGHT).is_err());
    // bounds on the top derivative are taken (they clamp the applied input); others are not
    let inputs = problem.clone().with_input_bounds([-50.0; 2], [50.0; 2]);
    inputs
        .real_time_iteration(PlanGuess::Spline)
        .expect("input bounds");
    let bounded = problem.with_state_bounds(1, [-50.0; 2], [50.0; 2]);
    let error = bounded
        .real_time_iteration(PlanGuess::Spline)
        .expect_err("inequalities");
    assert!(
        matches!(&error.failure, Failure::Invalid(e) if e.to_string().contains("no other inequalities")),
        "{error}"
    );
}

/// The plant's step of a control period in `pieces` forced-midpoint steps under the held
/// torque `tau` (a plant spun at 50 rad/s turns about a radian a period).
fn plant_pieces(
    plant: &crate::pendulum::Plant,
    z: &retract::nalgebra::SVector<f64, 4>,
    tau: [f64; 2],
    pieces: usize,
) -> (retract::nalgebra::SVector<f64, 4>, [f64; 4]) {
    use retract::nalgebra::SVector;
    use retract::{Lagrangian, StepOptions, forced::forced_step};
    let h = HORIZON / STEPS as f64 / pieces as f64;
    let mut z = *z;
    for _ in 0..pieces {
        z = forced_step(plant, &z, &SVector::from(tau), h, &StepOptions::default())
            .expect("plant step")
            .0;
    }
    let q = SVector::<f64, 2>::from([z[0], z[1]]);
    let p = SVector::<f64, 2>::from([z[2], z[3]]);
    let dq = plant
        .top_derivative(&[q], &p, &SVector::zeros())
        .expect("velocity");
    (z, [q[0], q[1], dq[0], dq[1]])
}

/// 1000 re-plans of the benchmark's controller on its problem with the input bounds
/// |q''_a| <= 100, the plant's velocity kicked every 50 periods by (+k, -k) with k rising to
/// 50 rad/s (signs alternating), with the library's status (`Control`): every applied input is
/// finite and within the bounds, the chosen plan's input clamped exactly when it is outside;
/// a period whose re-plan was not applied (failed, or a real-time Newton step above 1e3) applies
/// the shifted plan's input and says why; an applied re-plan is converged only with its step
/// at most 1e-6, and every other is reported unconverged. With one and two real-time
/// iterations a period (the library's `control`) and with full solves (each within 2 ms, as a
/// controller's deadline); the kicks make real work (unconverged re-plans, clamped inputs and
/// real-time fallbacks are reported).
#[test]
fn no_input_outside_the_bounds_and_no_unconverged_plan_unreported() {
    use crate::upright::{Controller, Mode};
    use retract::LiftedSystem;
    use retract::bvp::{Fallback, InputSource};
    let (model, plant) = upright_models();
    let (limit, max_step) = (100.0, 100.0);
    for mode in [Mode::Rti(1), Mode::Rti(2), Mode::Full] {
        let mut controller = Controller::with_input_limit(&model, mode, limit)
            .expect("upright")
            .with_time_budget(std::time::Duration::from_millis(2))
            .with_max_step(max_step);
        let mut jet = UPRIGHT;
        let mut z = plant.legendre(&retract::nalgebra::SVector::from(jet));
        let (mut unconverged, mut clamped, mut shifted, mut step_limited) = (0, 0, 0, 0);
        for period in 0..1000 {
            if period % 50 == 25 {
                let k =
                    2.5 * (period / 50 + 1) as f64 * if period % 100 == 25 { 1.0 } else { -1.0 };
                jet[2] += k;
                jet[3] -= k;
                z = plant.legendre(&retract::nalgebra::SVector::from(jet));
            }
            let fallback = controller.input();
            let applied = controller.control(&jet);
            controller.prepare();
            let status = applied.status;
            let at = format!("{mode:?}, period {period}: {applied:?}");
            assert!(
                applied
                    .input
                    .iter()
                    .all(|v| v.is_finite() && v.abs() <= limit),
                "{at}"
            );
            assert!(applied.tau.iter().all(|t| t.is_finite()), "{at}");
            match status.source {
                InputSource::Shifted(reason) => {
                    assert_eq!(applied.planned, fallback, "{at}");
                    assert!(!status.converged() && !status.replanned(), "{at}");
                    shifted += 1;
                    if reason == Fallback::StepLimit {
                        assert!(status.step > max_step, "{at}");
                        step_limited += 1;
                    }
                }
                InputSource::Converged => {
                    assert!(mode == Mode::Full || status.step <= 1e-6, "{at}");
                }
                InputSource::Unconverged => {
                    assert!(status.step > 1e-6 && status.step <= max_step, "{at}");
                    unconverged += 1;
                }
            }
            let clamp = applied.planned.map(|v| v.clamp(-limit, limit));
            assert_eq!(applied.input, clamp, "{at}");
            assert_eq!(status.clamped, clamp != applied.planned, "{at}");
            clamped += usize::from(status.clamped);
            (z, jet) = plant_pieces(&plant, &z, applied.tau, 8);
        }
        eprintln!(
            "{mode:?}: {unconverged} unconverged, {clamped} clamped, {shifted} shifted \
             ({step_limited} at the step limit)"
        );
        match mode {
            Mode::Full => assert!(shifted > 0, "{mode:?}: {shifted}"),
            Mode::Rti(_) => assert!(
                unconverged > 0 && clamped > 0 && step_limited > 0,
                "{mode:?}: {unconverged} {clamped} {step_limited}"
            ),
        }
    }
}

/// The derivative of a plan with respect to its start (`start_sensitivity`, from the KKT
/// factorisation at the solution) against central differences of solves from starts moved by
/// +-1e-4 along a direction, at a plan away from the upright rest (a moved start, where the
/// plan's second derivative does not vanish): to 1e-6 relative.
#[test]
fn the_start_sensitivity_matches_central_differences() {
    let (model, _) = upright_models();
    let base: [f64; 4] = [UPRIGHT[0] + 0.2, -0.1, 1.0, -0.5];
    let solve = |start: &[f64; 4]| {
        OptimalControlProblem::new(&model, start, &UPRIGHT, HORIZON, STEPS)
            .with_options(retract::bvp::PlanOptions::default().with_tolerance(1e-12))
            .solve(PlanGuess::Spline)
            .expect("solved")
    };
    let problem = OptimalControlProblem::new(&model, &base, &UPRIGHT, HORIZON, STEPS);
    let plan = solve(&base);
    let mut rti = problem
        .real_time_iteration(PlanGuess::Plan(&plan))
        .expect("rti");
    problem.prepare(&mut rti).expect("prepared");
    let eps = 1e-4;
    for direction in [[1.0, 0.0, 0.0, 0.0], [0.3, -0.7, 0.2, 0.5]] {
        let (dx, du) = problem
            .start_sensitivity(&rti, &direction)
            .expect("prepared");
        let moved = |sign: f64| {
            solve(&std::array::from_fn(|r| {
                base[r] + sign * eps * direction[r]
            }))
        };
        let (plus, minus) = (moved(1.0), moved(-1.0));
        let fd_x = plus
            .x
            .iter()
            .zip(&minus.x)
            .map(|(a, b)| (a - b) / (2.0 * eps));
        let fd_u = plus
            .u
            .iter()
            .zip(&minus.u)
            .map(|(a, b)| (a - b) / (2.0 * eps));
        let scale = dx
            .iter()
            .map(|v| v.amax())
            .chain(du.iter().map(|v| v.amax()))
            .fold(0.0, f64::max);
        let error_x = dx
            .iter()
            .zip(fd_x)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max);
        let error_u = du
            .iter()
            .zip(fd_u)
            .map(|(a, b)| (a - b).amax())
            .fold(0.0, f64::max);
        assert!(scale > 0.1, "{scale}");
        assert!(
            error_x.max(error_u) <= 1e-6 * scale,
            "{direction:?}: {error_x:e} {error_u:e} of {scale:e}"
        );
    }
}

/// `clamp_input` puts each component into the intersection of all the problem's bounds on the
/// top derivative (two calls bounding the same component: the tighter side of each), leaves
/// an unbounded side alone, and turns a non-finite component into 0 clamped likewise.
#[test]
fn clamp_input_keeps_the_intersection_of_the_bounds() {
    use retract::bvp::Variable;
    use retract::nalgebra::SVector;
    let (model, _) = upright_models();
    let problem = OptimalControlProblem::new(&model, &UPRIGHT, &UPRIGHT, HORIZON, STEPS)
        .with_input_bounds([-3.0, f64::NEG_INFINITY], [2.0, 5.0])
        .with_bounds(Variable::Top(0), -1.0, 4.0);
    let cases = [
        ([-2.0, 7.0], [-1.0, 5.0]),
        ([10.0, -1e9], [2.0, -1e9]),
        ([0.5, 4.0], [0.5, 4.0]),
        ([f64::NAN, f64::INFINITY], [0.0, 0.0]),
        ([f64::NEG_INFINITY, f64::NAN], [0.0, 0.0]),
    ];
    for (u, expected) in cases {
        let clamped = problem.clamp_input(&SVector::from(u));
        assert_eq!(clamped, SVector::from(expected), "{u:?}");
    }
    // without bounds only the non-finite components change
    let free = OptimalControlProblem::new(&model, &UPRIGHT, &UPRIGHT, HORIZON, STEPS);
    let u = SVector::from([1e12, f64::NAN]);
    assert_eq!(free.clamp_input(&u), SVector::from([1e12, 0.0]));
}
