//! The singularity guard: a step that crosses a pole of the Lagrangian is an error naming the
//! expression, the trajectory keeps every state before it, and the crossing time can be
//! located. Every guarded kind (division, sqrt, ln, powf, asin) is exercised, with cbrt, log2 and
//! ln_1p.

use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::{DomainKind, Error, LiftedSystem, StepOptions, step, trajectory};

#[higher_order_lagrangian(order = 2)]
pub(crate) fn disc(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

#[higher_order_lagrangian(order = 2)]
pub(crate) fn discs(
    q: [f64; 2],
    _dq: [f64; 2],
    ddq: [f64; 2],
    tau: f64,
    obstacles: &[[f64; 3]],
) -> f64 {
    let mut l = 0.5 * (ddq[0].powi(2) + ddq[1].powi(2));
    for o in obstacles {
        l += tau / ((q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]);
    }
    l
}

#[higher_order_lagrangian(order = 1)]
fn with_sqrt(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.1 * q.sqrt()
}

#[higher_order_lagrangian(order = 1)]
fn with_ln(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.1 * q.ln()
}

#[higher_order_lagrangian(order = 1)]
fn with_powf(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.1 * q.powf(1.5)
}

#[higher_order_lagrangian(order = 1)]
fn with_cbrt(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.01 * q.cbrt()
}

#[higher_order_lagrangian(order = 1)]
fn with_log2(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.01 * q.log2() + 0.01 * (q + 1.0).log10()
}

#[higher_order_lagrangian(order = 1)]
fn with_ln_1p(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.01 * (q - 1.0).ln_1p()
}

#[higher_order_lagrangian(order = 1)]
fn with_asin(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + 0.1 * (1.0 - q).asin() + 0.1 * (0.5 * q).acos()
}

/// The case of the issue: the exact solution reaches the circle near t = 1.955.
const HEADING_IN: [f64; 8] = [-2.0, 1.19, 1.0, -0.1, 0.0, 0.0, 0.0, 0.0];

fn run_until_crossing(h: f64) -> retract::Interrupted<8> {
    let system = Disc { tau: 1e-2, r: 1.0 };
    let z0 = system.legendre(&SVector::from_column_slice(&HEADING_IN));
    let steps = (3.0 / h).round() as usize;
    let options = StepOptions::default().with_crossing_location(true);
    trajectory(&system, &z0, h, steps, &options).expect_err("the path crosses the circle")
}

#[test]
fn crossing_is_reported_near_t_1955_at_two_step_sizes() {
    for h in [0.01, 0.001] {
        let stop = run_until_crossing(h);
        let Error::Domain(violation) = stop.error else {
            panic!("h = {h}: expected a domain error, got {}", stop.error);
        };
        assert_eq!(violation.kind, DomainKind::Denominator);
        assert_eq!(violation.expression, "q[0].powi(2) + q[1].powi(2) - r * r");
        assert!(
            (1.94..1.97).contains(&stop.time()),
            "h = {h}: stopped at t = {}",
            stop.time()
        );
        let crossing = stop.crossing_time.expect("located");
        println!(
            "h = {h}: stopped at step from t = {}, crossing located at t = {crossing}",
            stop.time()
        );
        assert!(
            (crossing - 1.955).abs() < 5e-3,
            "h = {h}: crossing at {crossing}"
        );
        assert!(crossing >= stop.time() && crossing <= stop.time() + h);
        // nothing before the failed step is lost, and every kept state is outside the disc
        assert_eq!(stop.trajectory.states.len(), stop.step + 1);
        assert!(
            stop.trajectory
                .states
                .iter()
                .all(|z| z[0].hypot(z[1]) > 1.0)
        );
        let message = stop.to_string();
        assert!(
            message.contains("changed sign") && message.contains("to t ="),
            "{message}"
        );
    }
}

#[test]
fn without_the_guard_the_same_step_passes_silently() {
    let system = Disc { tau: 1e-2, r: 1.0 };
    let z0 = system.legendre(&SVector::from_column_slice(&HEADING_IN));
    let stop = run_until_crossing(0.01);
    let z = stop.trajectory.states[stop.step];
    let unchecked = StepOptions::default().with_domain_check(false);
    let (z1, _) = step(&system, &z, 0.01, &unchecked).expect("Newton does not notice");
    assert!(
        z1[0].hypot(z1[1]) < 1.0,
        "the unchecked step lands inside the disc"
    );
    let run = trajectory(&system, &z0, 0.01, stop.step + 1, &unchecked).expect("no error");
    assert!(run.states[stop.step + 1][0].hypot(run.states[stop.step + 1][1]) < 1.0);
}

#[test]
fn grazing_trajectory_that_stays_outside_is_not_flagged() {
    let system = Disc { tau: 1e-6, r: 1.0 };
    let z0 = system.legendre(&SVector::from_column_slice(&[
        -2.0, 1.001, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ]));
    let run = trajectory(&system, &z0, 0.001, 4000, &StepOptions::default()).unwrap();
    let closest = run
        .states
        .iter()
        .map(|z| z[0].hypot(z[1]) - 1.0)
        .fold(f64::INFINITY, f64::min);
    assert!(
        closest > 0.0 && closest < 2e-3,
        "closest distance {closest:e}"
    );
}

#[test]
fn obstacle_in_a_parameter_list_is_named_by_index() {
    let obstacles = [[5.0, 5.0, 1.0], [0.0, 0.0, 1.0]];
    let system = Discs {
        tau: 1e-2,
        obstacles: &obstacles,
    };
    let z0 = system.legendre(&SVector::from_column_slice(&HEADING_IN));
    let stop = trajectory(&system, &z0, 0.01, 300, &StepOptions::default()).unwrap_err();
    match stop.error {
        Error::Domain(v) => {
            assert_eq!(v.element, Some(1));
            assert_eq!(
                v.expression,
                "(q[0] - o[0]).powi(2) + (q[1] - o[1]).powi(2) - o[2] * o[2]"
            );
        }
        other => panic!("expected a domain error, got {other}"),
    }
    assert!((1.94..1.97).contains(&stop.time()));
}

/// q(0) = 0.05, q'(0) = -1: q reaches 0 at t = 0.05, inside a step of h = 0.06 whose
/// evaluation point (q = 0.02) is still regular, so Newton converges and only the guard sees
/// the end of the step at q < 0.
fn first_step_kind<Sys: LiftedSystem<2, 3>>(system: &Sys) -> Result<(), Error> {
    let z0 = system.legendre(&SVector::from([0.05, -1.0]));
    step(system, &z0, 0.06, &StepOptions::default()).map(|_| ())
}

#[test]
fn every_guarded_kind_is_checked() {
    let expect = |result: Result<(), Error>, kind: DomainKind, expression: &str| match result {
        Err(Error::Domain(v)) => {
            assert_eq!(v.kind, kind);
            assert_eq!(v.expression, expression);
        }
        other => panic!("expected {kind:?}, got {other:?}"),
    };
    expect(first_step_kind(&WithSqrt {}), DomainKind::SqrtArgument, "q");
    expect(first_step_kind(&WithLn {}), DomainKind::LnArgument, "q");
    expect(first_step_kind(&WithPowf {}), DomainKind::PowfBase, "q");
    // the methods beyond the elementary ones: cbrt (singular derivative at 0), log2, ln_1p, asin
    expect(first_step_kind(&WithCbrt {}), DomainKind::Denominator, "q");
    expect(first_step_kind(&WithLog2 {}), DomainKind::LnArgument, "q");
    expect(
        first_step_kind(&WithLn1p {}),
        DomainKind::LnArgument,
        "1 + (q - 1.0)",
    );
    expect(
        first_step_kind(&WithAsin {}),
        DomainKind::AsinArgument,
        "1.0 - q",
    );
    let message = first_step_kind(&WithAsin {}).unwrap_err().to_string();
    assert!(
        message.contains("of asin or acos left (-1, 1)"),
        "{message}"
    );
    // and a regular step of the same systems passes
    let z0 = WithSqrt {}.legendre(&SVector::from([1.0, -1.0]));
    assert!(step(&WithSqrt {}, &z0, 0.06, &StepOptions::default()).is_ok());
}

/// `q[1] / q[1] + 0.0 * (1.0 / q[0])` is NaN where q[1] = 0 or q[0] = 0, and 1 elsewhere.
#[allow(clippy::eq_op)]
#[higher_order_lagrangian(order = 2)]
fn folded_terms(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0] * ddq[0] + ddq[1] * ddq[1]) + q[1] / q[1] + 0.0 * (1.0 / q[0])
}

/// Folding keeps the domain: the generated L equals the function as written, NaN where it
/// is (before, `x / x -> 1` and `0 * x -> 0` made it 1 + 1/2 |u|^2 everywhere), and a step
/// across q[0] = 0 is refused by the guard, naming the denominator.
#[test]
fn folded_terms_keep_the_function_and_its_guard() {
    use retract::Lagrangian;
    let system = FoldedTerms {};
    let u = SVector::from([0.3, -0.4]);
    let at = |q0: f64, q1: f64| {
        let x = [SVector::from([q0, q1]), SVector::from([0.2, 0.1])];
        (
            system.lagrangian(&x, &u),
            folded_terms([q0, q1], [0.2, 0.1], [0.3, -0.4]),
        )
    };
    let (generated, written) = at(0.7, -1.2);
    assert!((generated - written).abs() < 1e-15 && (generated - 1.125).abs() < 1e-15);
    for (q0, q1) in [(0.0, 1.0), (1.0, 0.0)] {
        let (generated, written) = at(q0, q1);
        assert!(
            generated.is_nan() && written.is_nan(),
            "{generated} at ({q0}, {q1})"
        );
    }
    // moving right through q[0] = 0 at unit speed
    let z0 = system.legendre(&SVector::from([-0.05, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]));
    match step(&system, &z0, 0.1, &StepOptions::default()) {
        Err(Error::Domain(v)) => {
            assert_eq!((v.kind, v.expression), (DomainKind::Denominator, "q[0]"));
        }
        other => panic!("a step across q[0] = 0: {other:?}"),
    }
}
