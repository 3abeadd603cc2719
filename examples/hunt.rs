//! A failure hunt for the optimizer: families of variants of the constrained suite's problems
//! (C1-C3 of `../shared/BENCHMARKS.md`: horizons, bounds, step counts and first guesses the
//! suite does not fix), each solved at the default options, one line per solve:
//!
//! `<family> <variant> outcome=<certified|failure> J=<J> iterations=<n> time_ms=<t>`
//!
//! then per family the number of solves, of certified ones, of each failure, and the sum of
//! the certified solves' iterations. The failures are the solver's (`Failure`'s variant
//! names); a plan's `J` and iterations are printed where the failure carries one. A change
//! to the optimizer is judged by comparing two runs solve for solve (`--compare`): the solves
//! certified in one run only, the costs that moved, and the iterations of the solves
//! certified in both.
//!
//! Run: `cargo run --release --example hunt -- FAMILY [FILTER]` with FAMILY `cartpole`,
//! `quadrotor`, `parking` or `all` (FILTER: a substring of the variant), and
//! `cargo run --release --example hunt -- --compare BEFORE.txt AFTER.txt` on two saved
//! outputs. Without arguments it prints this usage.

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::time::Instant;

use retract::bvp::{Curve, OptimalControlProblem, Placement, Plan, PlanError, PlanGuess, Variable};
use retract::nalgebra::SVector;

#[path = "common/cart_pole.rs"]
mod cart_pole;
use cart_pole::{CartForce, CartPole, PoleTorque};

#[path = "common/parking.rs"]
mod parking;
use parking::{CarEffort, SideSlip, Turning};

#[path = "common/quadrotor.rs"]
mod quadrotor;
use quadrotor::{Clearance, Lateral, Quadrotor, Rotors};

/// The first guesses of a variant.
#[derive(Clone, Copy, Debug)]
enum Guess {
    /// The smoothstep (`PlanGuess::Spline`), or the suite's own curve where it has one.
    Suite,
    /// The straight line from start to goal, at constant speed.
    Line,
    /// Zero everywhere but the fixed ends.
    Zero,
}

impl Guess {
    fn name(self) -> &'static str {
        match self {
            Guess::Suite => "suite",
            Guess::Line => "line",
            Guess::Zero => "zero",
        }
    }
}

/// A solve's outcome and, for a certified one, its iterations.
struct Row {
    outcome: String,
    iterations: Option<usize>,
}

/// One solve's outcome, printed as a line and kept in `rows`.
fn record<const N: usize, const X: usize>(
    rows: &mut Vec<Row>,
    family: &str,
    variant: &str,
    start: Instant,
    result: Result<Plan<N, X>, PlanError<N, X>>,
) {
    let ms = start.elapsed().as_secs_f64() * 1e3;
    let (outcome, plan) = match &result {
        Ok(plan) => ("certified".to_string(), Some(plan)),
        Err(e) => {
            let debug = format!("{:?}", e.failure);
            let name = debug
                .split(|c: char| !c.is_alphanumeric())
                .next()
                .unwrap_or("Unknown")
                .to_string();
            (name, e.last.as_deref())
        }
    };
    let (cost, iterations) = plan.map_or(("-".to_string(), "-".to_string()), |p| {
        (format!("{:.8}", p.cost), p.iterations.to_string())
    });
    println!(
        "{family} {variant} outcome={outcome} J={cost} iterations={iterations} time_ms={ms:.1}"
    );
    let certified = result.as_ref().ok().map(|p| p.iterations);
    rows.push(Row {
        outcome,
        iterations: certified,
    });
}

/// A guess's data, owned: built before the solve borrows it.
enum GuessData<const N: usize, const X: usize> {
    Suite,
    Line(Curve<'static, N>),
    Path(Vec<SVector<f64, X>>, Vec<SVector<f64, N>>),
}

impl<const N: usize, const X: usize> GuessData<N, X> {
    /// The data of `guess` for a problem from rest at `start` to rest at `goal` over `t_end`
    /// with `steps` steps.
    fn new(guess: Guess, start: [f64; N], goal: [f64; N], t_end: f64, steps: usize) -> Self {
        match guess {
            Guess::Suite => GuessData::Suite,
            Guess::Line => GuessData::Line(Curve::from_fn(move |t| {
                core::array::from_fn(|a| start[a] + (goal[a] - start[a]) * t / t_end)
            })),
            Guess::Zero => {
                let mut x = vec![SVector::<f64, X>::zeros(); steps + 1];
                for a in 0..N {
                    x[0][a] = start[a];
                    x[steps][a] = goal[a];
                }
                GuessData::Path(x, vec![SVector::zeros(); steps])
            }
        }
    }

    /// The solver's guess: the suite's is `suite` if given, else the smoothstep.
    fn plan_guess<'a>(&'a self, suite: Option<&'a Curve<'a, N>>) -> PlanGuess<'a, N, X> {
        match self {
            GuessData::Suite => suite.map_or(PlanGuess::Spline, PlanGuess::Curve),
            GuessData::Line(curve) => PlanGuess::Curve(curve),
            GuessData::Path(x, u) => PlanGuess::Path { x, u },
        }
    }
}

const GUESSES: [Guess; 3] = [Guess::Suite, Guess::Line, Guess::Zero];

/// C1's cart-pole: the pole torque 0 at the midpoints, |F| <= `limit` there (none if
/// infinite), over horizons, step counts and guesses.
fn cart_pole_family(filter: &str, rows: &mut Vec<Row>) {
    let (mc, mp, l, g) = (1.0, 0.3, 0.5, 9.81);
    let system = CartPole::new(mc, mp, l);
    let unactuated = PoleTorque::new(mp, l, g);
    let force = CartForce::new(mc, mp, l);
    let (start, goal) = ([0.0, 0.0], [0.0, PI]);
    for t_end in [2.0, 2.5, 3.0, 4.0] {
        let mut counts = vec![(100.0 * t_end) as usize];
        if t_end == 2.5 {
            counts.extend([50, 800]);
        }
        for steps in counts {
            for limit in [5.0, 6.0, 8.0, 10.0, 12.0, 20.0, f64::INFINITY] {
                for guess in GUESSES {
                    let variant = format!("T={t_end},F={limit},N={steps},guess={}", guess.name());
                    if !variant.contains(filter) {
                        continue;
                    }
                    let mut problem = OptimalControlProblem::new(
                        &system,
                        &[0.0; 4],
                        &[goal[0], goal[1], 0.0, 0.0],
                        t_end,
                        steps,
                    )
                    .with_equality(&unactuated);
                    if limit.is_finite() {
                        problem = problem.with_function_bounds(&force, -limit, limit);
                    }
                    let data = GuessData::new(guess, start, goal, t_end, steps);
                    let clock = Instant::now();
                    record(
                        rows,
                        "cartpole",
                        &variant,
                        clock,
                        problem.solve(data.plan_guess(None)),
                    );
                }
            }
        }
    }
}

/// C2's quadrotor: no lateral force, thrusts in [0, fmax] at the midpoints, the disc (if
/// `disc`) at nodes and midpoints.
fn quadrotor_family(filter: &str, rows: &mut Vec<Row>) {
    let (m, inertia, arm) = (1.0, 0.01, 0.1);
    let system = Quadrotor::new(m, inertia, arm);
    let no_lateral = Lateral::new(m);
    let thrusts = Rotors::new(m, inertia, arm);
    let clearance = Clearance::new();
    let (start, goal) = ([0.0; 3], [2.0, 1.0, 0.0]);
    for t_end in [2.0, 3.0] {
        for steps in [(100.0 * t_end) as usize, (300.0 * t_end) as usize] {
            for fmax in [6.0, 10.0, 15.0, 30.0] {
                for disc in [true, false] {
                    for guess in GUESSES {
                        let variant = format!(
                            "T={t_end},f={fmax},N={steps},disc={disc},guess={}",
                            guess.name()
                        );
                        if !variant.contains(filter) {
                            continue;
                        }
                        let mut problem = OptimalControlProblem::new(
                            &system,
                            &[0.0; 6],
                            &[goal[0], goal[1], goal[2], 0.0, 0.0, 0.0],
                            t_end,
                            steps,
                        )
                        .with_equality(&no_lateral)
                        .with_vector_bounds(&thrusts, &[0.0; 2], &[fmax; 2]);
                        if disc {
                            problem = problem.with_inequality(&clearance);
                        }
                        let data = GuessData::new(guess, start, goal, t_end, steps);
                        let clock = Instant::now();
                        let result = problem.solve(data.plan_guess(None));
                        record(rows, "quadrotor", &variant, clock, result);
                    }
                }
            }
        }
    }
}

/// C3's car: no side slip and the turning radius at the midpoints, |x| <= `xbox` at nodes
/// and midpoints (none if infinite); the suite's guess is its waypoint spline.
fn parking_family(filter: &str, rows: &mut Vec<Row>) {
    let system = CarEffort::new();
    let (slip, turn) = (SideSlip::new(), Turning::new());
    let (start, goal) = ([0.0; 3], [0.0, 0.5, 0.0]);
    for t_end in [5.0, 6.0, 8.0] {
        let times = [0.0, 0.25, 0.5, 0.75, 1.0].map(|s| s * t_end);
        let Ok(waypoints) = Curve::through_waypoints(&times, &parking::WAYPOINTS) else {
            println!("parking T={t_end}: the waypoints give no curve");
            continue;
        };
        for steps in [(10.0 * t_end) as usize, (100.0 * t_end) as usize] {
            for xbox in [0.4, 0.6, 0.8, f64::INFINITY] {
                for guess in [Guess::Suite, Guess::Line] {
                    let variant = format!("T={t_end},x={xbox},N={steps},guess={}", guess.name());
                    if !variant.contains(filter) {
                        continue;
                    }
                    let mut problem = OptimalControlProblem::new(
                        &system,
                        &[0.0; 6],
                        &[goal[0], goal[1], goal[2], 0.0, 0.0, 0.0],
                        t_end,
                        steps,
                    )
                    .with_equality(&slip)
                    .with_inequality_at(&turn, Placement::Midpoints);
                    if xbox.is_finite() {
                        problem = problem.with_bounds(Variable::Jet(0), -xbox, xbox);
                    }
                    let data = GuessData::new(guess, start, goal, t_end, steps);
                    let clock = Instant::now();
                    let result = problem.solve(data.plan_guess(Some(&waypoints)));
                    record(rows, "parking", &variant, clock, result);
                }
            }
        }
    }
}

/// The family's summary: solves, certified solves, each failure's count and the certified
/// solves' iterations.
fn summary(family: &str, rows: &[Row]) {
    let mut failures = BTreeMap::<&str, usize>::new();
    for row in rows.iter().filter(|r| r.iterations.is_none()) {
        *failures.entry(row.outcome.as_str()).or_default() += 1;
    }
    let certified = rows.iter().filter(|r| r.iterations.is_some()).count();
    let iterations: usize = rows.iter().filter_map(|r| r.iterations).sum();
    println!(
        "summary {family}: solves={} certified={certified} certified_iterations={iterations} failures={failures:?}",
        rows.len()
    );
}

/// A family's runner: the variants whose names contain the filter, their rows kept.
type Family = fn(&str, &mut Vec<Row>);

/// A saved run's lines: (family, variant) -> (outcome, J, iterations).
type Run = BTreeMap<(String, String), (String, Option<f64>, Option<usize>)>;

/// Reads the solve lines of a saved run.
fn read_run(path: &str) -> std::io::Result<Run> {
    let text = std::fs::read_to_string(path)?;
    let mut run = Run::new();
    for line in text.lines() {
        let fields: Vec<&str> = line.split_whitespace().collect();
        let value = |key: &str| {
            fields
                .iter()
                .find_map(|f| f.strip_prefix(key).and_then(|v| v.strip_prefix('=')))
        };
        let (Some(family), Some(variant), Some(outcome)) =
            (fields.first(), fields.get(1), value("outcome"))
        else {
            continue;
        };
        let cost = value("J").and_then(|v| v.parse().ok());
        let iterations = value("iterations").and_then(|v| v.parse().ok());
        let key = (family.to_string(), variant.to_string());
        run.insert(key, (outcome.to_string(), cost, iterations));
    }
    Ok(run)
}

/// Compares two saved runs solve for solve: per family, the solves certified in one only,
/// the certified costs that moved by more than 1e-6 relative, and the iterations of the
/// solves certified in both.
fn compare(before: &str, after: &str) -> std::io::Result<()> {
    let (a, b) = (read_run(before)?, read_run(after)?);
    let mut totals = BTreeMap::<&str, (usize, usize, usize)>::new();
    for (key, (outcome_a, cost_a, it_a)) in &a {
        let Some((outcome_b, cost_b, it_b)) = b.get(key) else {
            continue;
        };
        let (family, variant) = key;
        let (ok_a, ok_b) = (outcome_a == "certified", outcome_b == "certified");
        if ok_a != ok_b {
            println!("{family} {variant}: {outcome_a} -> {outcome_b}");
        }
        if let (true, true, Some(ca), Some(cb)) = (ok_a, ok_b, cost_a, cost_b) {
            if (ca - cb).abs() > 1e-6 * ca.abs().max(1.0) {
                println!("{family} {variant}: J {ca:.8} -> {cb:.8}");
            }
            let entry = totals.entry(family.as_str()).or_default();
            entry.0 += 1;
            entry.1 += it_a.unwrap_or(0);
            entry.2 += it_b.unwrap_or(0);
        }
    }
    for (family, (count, it_a, it_b)) in totals {
        println!("{family}: {count} certified in both, iterations {it_a} -> {it_b}");
    }
    Ok(())
}

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let families: [(&str, Family); 3] = [
        ("cartpole", cart_pole_family),
        ("quadrotor", quadrotor_family),
        ("parking", parking_family),
    ];
    match args.first().map(String::as_str) {
        Some("--compare") if args.len() == 3 => compare(&args[1], &args[2]),
        Some(which) if which == "all" || families.iter().any(|(f, _)| *f == which) => {
            let filter = args.get(1).map_or("", String::as_str);
            for (family, run) in families {
                if which == "all" || which == family {
                    let mut rows = Vec::new();
                    run(filter, &mut rows);
                    summary(family, &rows);
                }
            }
            Ok(())
        }
        _ => {
            println!(
                "usage: hunt FAMILY [FILTER]   (FAMILY: cartpole, quadrotor, parking or all)\n       hunt --compare BEFORE.txt AFTER.txt"
            );
            Ok(())
        }
    }
}
