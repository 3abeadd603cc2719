//! A failure hunt for the optimizer: families of variants of the constrained suite's problems
//! (`../shared/BENCHMARKS.md` C1-C5) and of the swing-up suite, each solved once at the
//! DEFAULT options, so that a change to the optimizer can be compared solve for solve with its
//! parent commit. One line per solve,
//! `<family> <variant> outcome=<certified|Failure> J=<J|-> iterations=<n> time_ms=<t>`, where
//! the variant is a run of `key=value` words (`T=2.5 F=8 N=250 guess=line`), the outcome
//! `certified` or the failure's variant name (`NotAMinimum(k)` with its negative directions),
//! `J` the certified plan's cost (`-` on a failure), `iterations` those of the last iterate on
//! a failure (0 without one; a free-time search's of all its solves); a failure's line ends
//! with ` # <its message>`. After each
//! family a line `summary <family> solves=<n> certified=<c> failures=<kind:count,...>
//! certified_iterations=<sum over the certified> time_s=<t>`.
//!
//! The families (guesses: `spline` the smoothstep `PlanGuess::Spline`, `line` the straight
//! line q(t) = q0 + (qT - q0) t / T at constant speed, `zero` the zero path; neither of the
//! last two meets the boundary jets):
//! - `cartpole`: C1, F in {5, 6, 8, 10, 12, 20, inf} (inf: no bound), T in {2, 2.5, 3, 4} at
//!   N = 100 T, and T = 2.5 at N = 20 T and 320 T; guesses spline, line, zero (126 solves).
//! - `quadrotor`: C2, f in {6, 10, 15, 30}, T in {2, 3}, N in {100 T, 300 T}, the disc
//!   present or not; guesses spline, line, zero (96 solves; the line and the smoothstep both
//!   run through the disc's centre).
//! - `parking`: C3, xbox in {0.4, 0.6, 0.8, inf}, T in {5, 6, 8}, N in {10 T, 100 T, 300 T};
//!   guesses `waypoints` (the suite's spline, its times scaled to T) and `line` (sideways:
//!   degenerate for this car, a named failure is the expected result) (72 solves).
//! - `chain`: C4 (the chain as its energy, `examples/common/mechanical.rs`), n in {3, 7},
//!   joint limit in {1, 2, inf}, T in {1.5, 2, 3}, N in {20 T, 100 T}, the smoothstep
//!   (36 solves; n = 3 with limit 1 has its goal 1.5 outside the bound: refused).
//! - `mintime`: C5, F in {8, 10, 15}, box |x| <= {0.3, 0.5, 0.8, 1, inf}, N in {50, 100,
//!   200}, first T in {2, 3, 4} (the search's T in [0.5, 5]); J is T + the effort, the
//!   iterations those of all its solves (on a failure: the attached plan's). (Boxes 0.8 and 1
//!   never bind: 0.3 and 0.5 are added.) (135 solves.)
//! - `swing`: the swing-up suite (`examples/swing_up.rs`): the double pendulum, the cart-pole
//!   (pole torque 0) and the acrobot (shoulder torque 0), T in {1.5, 2, 3, 4}, N in {100 T,
//!   300 T}; guesses spline, line, zero (72 solves; `swing_up.rs` starts the acrobot's longer
//!   horizons from the previous plan, here every solve starts cold).
//!
//! Run: `cargo run --release --example hunt -- FAMILY [FILTER]` (FAMILY one of the above or
//! `all`; FILTER a substring of the variant, e.g. `"guess=line"` or `"T=2 "`), and no argument
//! prints the usage. Every family runs in under 2 minutes in `--release` on the 2-core
//! machine (2026-11-28, load about 4: cartpole 111 s, quadrotor 28 s, parking 20 s, chain
//! 63 s, mintime 25 s, swing 57 s); no grid was shrunk, two were widened (mintime's boxes,
//! swing's guesses). The solves are deterministic: two runs differ only in `time_ms`.
//!
//! A last argument `--adaptive` runs every solve with the adaptive barrier update
//! (`BarrierUpdate::Adaptive`) instead of the default.
//!
//! Compare two runs (e.g. the parent commit's and a change's output):
//! `cargo run --release --example hunt -- --compare A.txt B.txt` lists per family the solves
//! certified in one but not the other, the costs that moved by more than 1e-6 relative, the
//! solves found in one file only, and the iteration totals over the solves certified in both.

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::io::Write;
use std::time::Instant;

use retract::bvp::{
    BarrierUpdate, Curve, Failure, FreeTime, FreeTimePlan, OptimalControlProblem, Placement, Plan,
    PlanError, PlanGuess, PlanOptions, Variable,
};

/// The options of every solve: the defaults, with the adaptive barrier update
/// ([`BarrierUpdate::Adaptive`]) when the command line ends with `--adaptive`.
fn options() -> PlanOptions {
    let adaptive = std::env::args().any(|a| a == "--adaptive");
    let update = if adaptive {
        BarrierUpdate::Adaptive
    } else {
        BarrierUpdate::Monotone
    };
    PlanOptions::default().with_barrier_update(update)
}

#[path = "common/cart_pole.rs"]
mod cart_pole;
use cart_pole::{CartForce, CartPole, MinTimeCartPole, PoleTorque};

#[path = "common/quadrotor.rs"]
mod quadrotor;
use quadrotor::{Clearance, Lateral, Quadrotor, Rotors};

#[path = "common/parking.rs"]
mod parking;
use parking::{CarEffort, SideSlip, Turning};

#[path = "common/mechanical.rs"]
mod mechanical;
energy_chain!(chain3, 3);
energy_chain!(chain7, 7);

#[path = "common/pendulum.rs"]
mod pendulum;
use pendulum::{ElbowCost, ShoulderTorque, TorqueCost};

const G: f64 = 9.81;

const USAGE: &str = "usage: hunt FAMILY [FILTER]   FAMILY: cartpole quadrotor parking chain \
                     mintime swing all; FILTER: a substring of the variant\n       \
                     hunt --compare A.txt B.txt\n       \
                     (a last argument --adaptive: the adaptive barrier update)";

/// One solve as the hunt records it.
struct Solve {
    /// `certified` or the failure's short name.
    outcome: String,
    /// The certified plan's cost.
    cost: Option<f64>,
    /// The plan's iterations, or the last iterate's on a failure (0 without one).
    iterations: usize,
    /// The failure's message.
    message: Option<String>,
}

/// A failure's variant name (`NotAMinimum(k)` with its negative directions).
fn failure_name(failure: &Failure) -> String {
    if let Failure::NotAMinimum {
        negative_directions,
    } = failure
    {
        return format!("NotAMinimum({negative_directions})");
    }
    let debug = format!("{failure:?}");
    let end = debug.find(['(', ' ', '{']).unwrap_or(debug.len());
    debug[..end].to_string()
}

impl Solve {
    fn certified(cost: f64, iterations: usize) -> Self {
        Self {
            outcome: "certified".into(),
            cost: Some(cost),
            iterations,
            message: None,
        }
    }

    fn failure(outcome: String, iterations: usize, message: String) -> Self {
        Self {
            outcome,
            cost: None,
            iterations,
            message: Some(message),
        }
    }
}

/// A failure's record: the last iterate's iterations (the search's, all its solves', for a
/// free-time search that certified no horizon).
fn failed<const N: usize, const X: usize>(error: &PlanError<N, X>) -> Solve {
    let iterations = match error.failure {
        Failure::FreeTimeSearch { iterations, .. } => iterations,
        _ => error.last.as_ref().map_or(0, |last| last.iterations),
    };
    Solve::failure(failure_name(&error.failure), iterations, error.to_string())
}

/// A fixed-horizon solve's record.
fn planned<const N: usize, const X: usize>(result: Result<Plan<N, X>, PlanError<N, X>>) -> Solve {
    result.map_or_else(
        |error| failed(&error),
        |plan| Solve::certified(plan.cost, plan.iterations),
    )
}

/// A free-time solve's record: J = w T + the effort, the iterations of all its solves.
fn planned_free<const N: usize, const X: usize>(
    result: Result<FreeTimePlan<N, X>, PlanError<N, X>>,
) -> Solve {
    result.map_or_else(
        |error| failed(&error),
        |free| Solve::certified(free.cost, free.iterations),
    )
}

/// A family's running tally.
struct Family<'f> {
    name: &'static str,
    filter: &'f str,
    solves: usize,
    certified: usize,
    failures: BTreeMap<String, usize>,
    iterations: usize,
    start: Instant,
}

impl<'f> Family<'f> {
    fn new(name: &'static str, filter: &'f str) -> Self {
        Self {
            name,
            filter,
            solves: 0,
            certified: 0,
            failures: BTreeMap::new(),
            iterations: 0,
            start: Instant::now(),
        }
    }

    /// Solves the variant (if the filter takes it) and prints its line.
    fn solve(&mut self, variant: &str, run: impl FnOnce() -> Solve) {
        if !variant.contains(self.filter) {
            return;
        }
        let start = Instant::now();
        let solve = run();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let cost = solve.cost.map_or("-".into(), |j| format!("{j:.8}"));
        let message = solve.message.map_or(String::new(), |m| format!(" # {m}"));
        println!(
            "{} {variant} outcome={} J={cost} iterations={} time_ms={ms:.1}{message}",
            self.name, solve.outcome, solve.iterations
        );
        let _ = std::io::stdout().flush();
        self.solves += 1;
        if solve.cost.is_some() {
            self.certified += 1;
            self.iterations += solve.iterations;
        } else {
            *self.failures.entry(solve.outcome).or_default() += 1;
        }
    }

    fn summary(self) {
        let failures: Vec<String> = self
            .failures
            .iter()
            .map(|(kind, count)| format!("{kind}:{count}"))
            .collect();
        let failures = if failures.is_empty() {
            "-".into()
        } else {
            failures.join(",")
        };
        println!(
            "summary {} solves={} certified={} failures={failures} certified_iterations={} \
             time_s={:.1}",
            self.name,
            self.solves,
            self.certified,
            self.iterations,
            self.start.elapsed().as_secs_f64()
        );
    }
}

/// A first guess by name.
#[derive(Clone, Copy)]
enum Guess {
    /// The smoothstep (`PlanGuess::Spline`).
    Spline,
    /// The straight line from start to goal at constant speed.
    Line,
    /// q = 0 with every derivative.
    Zero,
}

impl Guess {
    fn name(self) -> &'static str {
        match self {
            Guess::Spline => "spline",
            Guess::Line => "line",
            Guess::Zero => "zero",
        }
    }

    /// The path of the guess from `from` to `to` in `t_end` (none for the smoothstep).
    fn curve<const N: usize>(
        self,
        from: [f64; N],
        to: [f64; N],
        t_end: f64,
    ) -> Option<Curve<'static, N>> {
        match self {
            Guess::Spline => None,
            Guess::Line => Some(Curve::from_derivatives(move |t, j| {
                std::array::from_fn(|a| match j {
                    0 => from[a] + (to[a] - from[a]) * t / t_end,
                    1 => (to[a] - from[a]) / t_end,
                    _ => 0.0,
                })
            })),
            Guess::Zero => Some(Curve::from_derivatives(|_, _| [0.0; N])),
        }
    }
}

/// The solver's guess for an optional path: the smoothstep without one.
fn plan_guess<'a, const N: usize, const X: usize>(
    curve: &'a Option<Curve<'a, N>>,
) -> PlanGuess<'a, N, X> {
    curve.as_ref().map_or(PlanGuess::Spline, PlanGuess::Curve)
}

/// A bound's name in a variant: its value, or `inf` for none.
fn bound(value: Option<f64>) -> String {
    value.map_or("inf".into(), |v| v.to_string())
}

/// The steps for a horizon at `per_second` steps a second.
fn steps(t_end: f64, per_second: f64) -> usize {
    (per_second * t_end).round() as usize
}

const ALL_GUESSES: [Guess; 3] = [Guess::Spline, Guess::Line, Guess::Zero];

fn cartpole(filter: &str) {
    let mut family = Family::new("cartpole", filter);
    let (mc, mp, l) = (1.0, 0.3, 0.5);
    let system = CartPole::new(mc, mp, l);
    let unactuated = PoleTorque::new(mp, l, G);
    let force = CartForce::new(mc, mp, l);
    let (from, to) = ([0.0, 0.0], [0.0, PI]);
    let limits = [5.0, 6.0, 8.0, 10.0, 12.0, 20.0].map(Some);
    let grid = [
        (2.0, 100.0),
        (2.5, 100.0),
        (3.0, 100.0),
        (4.0, 100.0),
        (2.5, 20.0),
        (2.5, 320.0),
    ];
    for (t_end, per_second) in grid {
        let n = steps(t_end, per_second);
        for limit in limits.into_iter().chain([None]) {
            for guess in ALL_GUESSES {
                let variant = format!("T={t_end} F={} N={n} guess={}", bound(limit), guess.name());
                family.solve(&variant, || {
                    let curve = guess.curve(from, to, t_end);
                    let mut problem = OptimalControlProblem::new(
                        &system,
                        &[0.0; 4],
                        &[0.0, PI, 0.0, 0.0],
                        t_end,
                        n,
                    )
                    .with_equality(&unactuated);
                    if let Some(limit) = limit {
                        problem = problem.with_function_bounds(&force, -limit, limit);
                    }
                    planned(problem.with_options(options()).solve(plan_guess(&curve)))
                });
            }
        }
    }
    family.summary();
}

fn quadrotor(filter: &str) {
    let mut family = Family::new("quadrotor", filter);
    let (m, inertia, arm) = (1.0, 0.01, 0.1);
    let system = Quadrotor::new(m, inertia, arm);
    let no_lateral = Lateral::new(m);
    let thrusts = Rotors::new(m, inertia, arm);
    let disc = Clearance::new();
    let goal = [2.0, 1.0, 0.0, 0.0, 0.0, 0.0];
    let (from, to) = ([0.0; 3], [goal[0], goal[1], goal[2]]);
    for t_end in [2.0, 3.0] {
        for per_second in [100.0, 300.0] {
            let n = steps(t_end, per_second);
            for fmax in [6.0, 10.0, 15.0, 30.0] {
                for with_disc in [true, false] {
                    for guess in ALL_GUESSES {
                        let variant = format!(
                            "T={t_end} f={fmax} N={n} disc={} guess={}",
                            if with_disc { "yes" } else { "no" },
                            guess.name()
                        );
                        family.solve(&variant, || {
                            let curve = guess.curve(from, to, t_end);
                            let mut problem =
                                OptimalControlProblem::new(&system, &[0.0; 6], &goal, t_end, n)
                                    .with_equality(&no_lateral)
                                    .with_vector_bounds(&thrusts, &[0.0; 2], &[fmax; 2]);
                            if with_disc {
                                problem = problem.with_inequality(&disc);
                            }
                            planned(problem.with_options(options()).solve(plan_guess(&curve)))
                        });
                    }
                }
            }
        }
    }
    family.summary();
}

fn parking(filter: &str) {
    let mut family = Family::new("parking", filter);
    let system = CarEffort::new();
    let (slip, turn) = (SideSlip::new(), Turning::new());
    let goal = [0.0, 0.5, 0.0, 0.0, 0.0, 0.0];
    let (from, to) = ([0.0; 3], [goal[0], goal[1], goal[2]]);
    for t_end in [5.0, 6.0, 8.0] {
        for per_second in [10.0, 100.0, 300.0] {
            let n = steps(t_end, per_second);
            for xbox in [Some(0.4), Some(0.6), Some(0.8), None] {
                for guess in ["waypoints", "line"] {
                    let variant = format!("T={t_end} xbox={} N={n} guess={guess}", bound(xbox));
                    family.solve(&variant, || {
                        let curve = if guess == "line" {
                            Guess::Line.curve(from, to, t_end)
                        } else {
                            let times = [0.0, 0.25, 0.5, 0.75, 1.0].map(|s| s * t_end);
                            match Curve::through_waypoints(&times, &parking::WAYPOINTS) {
                                Ok(curve) => Some(curve),
                                Err(e) => {
                                    return Solve::failure("GuessError".into(), 0, e.to_string());
                                }
                            }
                        };
                        let mut problem =
                            OptimalControlProblem::new(&system, &[0.0; 6], &goal, t_end, n)
                                .with_equality(&slip)
                                // (the turning radius at the midpoints only, as the suite places it)
                                .with_inequality_at(&turn, Placement::Midpoints);
                        if let Some(xbox) = xbox {
                            problem = problem.with_bounds(Variable::Jet(0), -xbox, xbox);
                        }
                        planned(problem.with_options(options()).solve(plan_guess(&curve)))
                    });
                }
            }
        }
    }
    family.summary();
}

/// The chain C4 with `$n` links from rest at 0 to rest at q_i = `$goal`, each joint in
/// [-limit, limit] (no bound for `None`), from the smoothstep.
macro_rules! chain_solve {
    ($system:expr, $n:literal, $goal:expr, $t_end:expr, $steps:expr, $limit:expr) => {{
        let mut end = [0.0; 2 * $n];
        end[..$n].fill($goal);
        let mut problem =
            OptimalControlProblem::new(&$system, &[0.0; 2 * $n], &end, $t_end, $steps);
        if let Some(limit) = $limit {
            for joint in 0..$n {
                problem = problem.with_bounds(Variable::Jet(joint), -limit, limit);
            }
        }
        planned(problem.with_options(options()).solve(PlanGuess::Spline))
    }};
}

fn chain(filter: &str) {
    let mut family = Family::new("chain", filter);
    let (three, seven) = (Chain3::new(), Chain7::new());
    for links in [3, 7] {
        for limit in [Some(1.0), Some(2.0), None] {
            for t_end in [1.5, 2.0, 3.0] {
                for per_second in [20.0, 100.0] {
                    let n = steps(t_end, per_second);
                    let variant = format!("n={links} limit={} T={t_end} N={n}", bound(limit));
                    family.solve(&variant, || {
                        if links == 3 {
                            chain_solve!(three, 3, 1.5, t_end, n, limit)
                        } else {
                            chain_solve!(seven, 7, 0.5, t_end, n, limit)
                        }
                    });
                }
            }
        }
    }
    family.summary();
}

fn mintime(filter: &str) {
    let mut family = Family::new("mintime", filter);
    let system = MinTimeCartPole::new(1.0, 0.3, 0.5, G);
    let (passive, force) = (system.unactuated_torques(), system.input_functions());
    for limit in [8.0, 10.0, 15.0] {
        for cart_box in [Some(0.3), Some(0.5), Some(0.8), Some(1.0), None] {
            for n in [50, 100, 200] {
                for t_first in [2.0, 3.0, 4.0] {
                    let variant = format!("F={limit} box={} N={n} T0={t_first}", bound(cart_box));
                    family.solve(&variant, || {
                        let mut problem = OptimalControlProblem::new(
                            &system,
                            &[0.0; 4],
                            &[0.0, PI, 0.0, 0.0],
                            t_first,
                            n,
                        )
                        .with_equalities(&passive)
                        .with_function_bounds(&force[0], -limit, limit);
                        if let Some(cart_box) = cart_box {
                            problem = problem.with_bounds(Variable::Jet(0), -cart_box, cart_box);
                        }
                        planned_free(
                            problem
                                .with_options(options())
                                .solve_free_time(FreeTime::new(0.5, 5.0, 1.0), PlanGuess::Spline),
                        )
                    });
                }
            }
        }
    }
    family.summary();
}

fn swing(filter: &str) {
    let mut family = Family::new("swing", filter);
    let pendulum = TorqueCost::new(1.0, 1.0, 1.0, 1.0, G);
    let cart = CartPole::new(1.0, 0.3, 0.5);
    let unactuated = PoleTorque::new(0.3, 0.5, G);
    let acrobot = ElbowCost::new(1.0, 1.0, 1.0, 1.0, G);
    let passive = ShoulderTorque::new(1.0, 1.0, 1.0, 1.0, G);
    let (hanging, upright, pole_up) = ([0.0; 4], [PI, 0.0, 0.0, 0.0], [0.0, PI, 0.0, 0.0]);
    for problem_name in ["pendulum", "cartpole", "acrobot"] {
        let goal = if problem_name == "cartpole" {
            pole_up
        } else {
            upright
        };
        for t_end in [1.5, 2.0, 3.0, 4.0] {
            for per_second in [100.0, 300.0] {
                let n = steps(t_end, per_second);
                for guess in ALL_GUESSES {
                    let variant = format!("{problem_name} T={t_end} N={n} guess={}", guess.name());
                    family.solve(&variant, || {
                        let curve = guess.curve([0.0; 2], [goal[0], goal[1]], t_end);
                        let guess = plan_guess(&curve);
                        planned(match problem_name {
                            "pendulum" => {
                                OptimalControlProblem::new(&pendulum, &hanging, &goal, t_end, n)
                                    .with_options(options())
                                    .solve(guess)
                            }
                            "cartpole" => {
                                OptimalControlProblem::new(&cart, &hanging, &goal, t_end, n)
                                    .with_equality(&unactuated)
                                    .with_options(options())
                                    .solve(guess)
                            }
                            _ => OptimalControlProblem::new(&acrobot, &hanging, &goal, t_end, n)
                                .with_equality(&passive)
                                .with_options(options())
                                .solve(guess),
                        })
                    });
                }
            }
        }
    }
    family.summary();
}

/// A family's run, given the filter.
type Run = fn(&str);

/// One solve's line of a hunt's output: (family, variant, outcome, J, iterations).
type Line = (String, String, String, Option<f64>, usize);

/// The solve lines of a hunt's output, in order.
fn parse(path: &str) -> Result<Vec<Line>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut lines = Vec::new();
    for line in text.lines() {
        let line = line.split(" # ").next().unwrap_or("");
        let Some((head, tail)) = line.split_once(" outcome=") else {
            continue;
        };
        let Some((family, variant)) = head.split_once(' ') else {
            continue;
        };
        let mut words = tail.split(' ');
        let outcome = words.next().unwrap_or("").to_string();
        let (mut cost, mut iterations) = (None, 0);
        for word in words {
            if let Some(j) = word.strip_prefix("J=") {
                cost = j.parse().ok();
            } else if let Some(n) = word.strip_prefix("iterations=") {
                iterations = n.parse().unwrap_or(0);
            }
        }
        lines.push((family.into(), variant.into(), outcome, cost, iterations));
    }
    Ok(lines)
}

/// `--compare A B`: per family, what changed from run A to run B.
fn compare(a: &str, b: &str) -> Result<(), String> {
    let (first, second) = (parse(a)?, parse(b)?);
    let key = |l: &Line| (l.0.clone(), l.1.clone());
    let in_b: BTreeMap<_, _> = second.iter().map(|l| (key(l), l)).collect();
    let in_a: BTreeMap<_, _> = first.iter().map(|l| (key(l), l)).collect();
    let mut families: Vec<&String> = Vec::new();
    for l in first.iter().chain(&second) {
        if !families.contains(&&l.0) {
            families.push(&l.0);
        }
    }
    for family in families {
        println!("== {family}");
        let (mut both, mut iterations_a, mut iterations_b) = (0, 0, 0);
        let (mut lost, mut gained, mut moved, mut only) = (0, 0, 0, 0);
        for la in first.iter().filter(|l| &l.0 == family) {
            let Some(lb) = in_b.get(&key(la)) else {
                println!("only in A: {} {} outcome={}", la.0, la.1, la.2);
                only += 1;
                continue;
            };
            match (la.3, lb.3) {
                (Some(ja), Some(jb)) => {
                    both += 1;
                    iterations_a += la.4;
                    iterations_b += lb.4;
                    let relative = (jb - ja).abs() / ja.abs().max(f64::MIN_POSITIVE);
                    if relative > 1e-6 {
                        println!(
                            "J moved: {} {} A={ja:.8} B={jb:.8} rel={relative:.1e} \
                             iterations A={} B={}",
                            la.0, la.1, la.4, lb.4
                        );
                        moved += 1;
                    }
                }
                (Some(ja), None) => {
                    println!(
                        "certified in A only: {} {} A J={ja:.8} iterations={} B outcome={}",
                        la.0, la.1, la.4, lb.2
                    );
                    lost += 1;
                }
                (None, Some(jb)) => {
                    println!(
                        "certified in B only: {} {} B J={jb:.8} iterations={} A outcome={}",
                        la.0, la.1, lb.4, la.2
                    );
                    gained += 1;
                }
                (None, None) if la.2 != lb.2 => {
                    println!("failure changed: {} {} A={} B={}", la.0, la.1, la.2, lb.2);
                }
                (None, None) => {}
            }
        }
        for lb in second.iter().filter(|l| &l.0 == family) {
            if !in_a.contains_key(&key(lb)) {
                println!("only in B: {} {} outcome={}", lb.0, lb.1, lb.2);
                only += 1;
            }
        }
        println!(
            "compare {family} certified_in_A_only={lost} certified_in_B_only={gained} \
             J_moved={moved} in_one_file_only={only} certified_in_both={both} \
             iterations_A={iterations_a} iterations_B={iterations_b}"
        );
    }
    Ok(())
}

fn main() {
    let args: Vec<String> = (std::env::args().skip(1))
        .filter(|a| a != "--adaptive")
        .collect();
    let families: [(&str, Run); 6] = [
        ("cartpole", cartpole),
        ("quadrotor", quadrotor),
        ("parking", parking),
        ("chain", chain),
        ("mintime", mintime),
        ("swing", swing),
    ];
    match args.first().map(String::as_str) {
        None => println!("{USAGE}"),
        Some("--compare") => {
            let [_, a, b] = args.as_slice() else {
                eprintln!("{USAGE}");
                std::process::exit(2);
            };
            if let Err(e) = compare(a, b) {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
        Some(which) => {
            let filter = args.get(1).map_or("", String::as_str);
            let mut ran = false;
            for (name, run) in families {
                if which == name || which == "all" {
                    run(filter);
                    ran = true;
                }
            }
            if !ran {
                eprintln!("unknown family {which}\n{USAGE}");
                std::process::exit(2);
            }
        }
    }
}
