//! The planner's speed: the measurements of `benches/bvp.rs` and of the report.
//!
//! - Solve time against the number of steps $N$ ([`against_n`]): the root finder's reduced
//!   condensed solve (`solve_reduced`) on the SE(2) scene (one disc, T = 4, residual
//!   tolerance 1e-10, from the spline guess) for N = 100 .. 3200.
//! - At N = 400 ([`at_400`]): the three linear solvers of the root finder and its warm
//!   re-solve after a shift by one step (receding horizon).
//! - The optimizer (`OptimalControlProblem`) against the root finder (`solve_reduced`)
//!   ([`races`]): the one-disc scene of `../shared/BENCHMARKS.md` from its bump guess and the
//!   SE(2) scene from the spline guess, N = 400, cold and warm (after a shift by one step);
//!   both must reach the same cost (to 1e-8).
//! - Richardson extrapolation ([`extrapolation`]): `solve_extrapolated` on the one-disc scene
//!   for N = 40, 50, 100 (tolerance 1e-9), its errors against an extrapolation at N = 400
//!   solved to 1e-10.
//!
//! Each measurement solves its problems once (the iterations and costs it reports), then hands
//! its timed closures to `measure`: the report times them in interleaved rounds
//! ([`crate::timing::interleaved`]), the bench hands them to criterion. Each closure is one
//! solve from a guess built beforehand.

use std::hint::black_box;
use std::io::Write;
use std::time::Instant;

use retract::bvp::root_finder::{
    BoundaryValueProblem, BvpOptions, BvpSolution, Guess, LinearSolver,
};
use retract::bvp::{OptimalControlProblem, Plan, PlanError, PlanGuess, PlanOptions};
use retract::nalgebra::SVector;
use retract::{Lagrangian, LiftedSystem, ReducedScheme};

use crate::Error;
use crate::models::{DISC_GOAL, DISC_START, OneDisc, Scene};
use crate::timing::{Row, Samples, Timed, format_ns, interleaved, paired_ratio, write_head};

/// The SE(2) scene's obstacle (centre x, y, radius).
pub const SE2_OBSTACLES: [[f64; 3]; 1] = [[0.0, -0.6, 1.0]];
/// The SE(2) scene's start jet (x, y, theta and their rates).
pub const SE2_START: [f64; 6] = [-2.0, 0.5, 0.0, 0.0, 0.0, 0.0];
/// The SE(2) scene's goal jet.
pub const SE2_GOAL: [f64; 6] = [2.0, 0.5, 1.0, 0.0, 0.0, 0.0];
/// The horizon of both scenes.
pub const T_END: f64 = 4.0;
/// The step count of the comparisons at one size.
pub const STEPS: usize = 400;
/// The step counts of [`against_n`].
pub const AGAINST_N: [usize; 6] = [100, 200, 400, 800, 1600, 3200];
/// The names of [`against_n`]'s solves (criterion's ids), one per entry of [`AGAINST_N`].
pub const AGAINST_N_NAMES: [&str; 6] = [
    "solve_reduced/se2_obstacle_N100",
    "solve_reduced/se2_obstacle_N200",
    "solve_reduced/se2_obstacle_N400",
    "solve_reduced/se2_obstacle_N800",
    "solve_reduced/se2_obstacle_N1600",
    "solve_reduced/se2_obstacle_N3200",
];

/// The SE(2) scene (tau = 0.05, one disc).
pub fn se2_scene() -> Scene<'static> {
    Scene {
        tau: 0.05,
        obstacles: &SE2_OBSTACLES,
    }
}

/// The one-disc scene (tau = 1e-2).
pub fn one_disc() -> OneDisc {
    OneDisc { tau: 1e-2 }
}

/// What a measurement does with its timed closures: returns one row per closure, in order
/// (the report: [`crate::timing::interleaved`]), or none (a harness that reports itself,
/// such as criterion).
pub type Measure<'m> = &'m mut dyn FnMut(&mut [Timed<'_>]) -> Vec<Row>;

/// One timed solve: what it is, the iterations and cost of a solve before timing, its times
/// (ns; empty if `measure` returned no row for it).
#[derive(Clone, Debug)]
pub struct Solve {
    /// The closure's name.
    pub name: &'static str,
    /// Newton or SQP iterations.
    pub iterations: usize,
    /// The cost reached.
    pub cost: f64,
    /// The per-call times (ns).
    pub samples: Samples,
}

/// Runs `measure` on `closures` and joins its rows to `solves` (the same order).
fn measured(
    measure: Measure<'_>,
    closures: &mut [Timed<'_>],
    solves: Vec<(usize, f64)>,
) -> Vec<Solve> {
    let names: Vec<&'static str> = closures.iter().map(|c| c.name).collect();
    let mut rows = measure(closures).into_iter();
    names
        .into_iter()
        .zip(solves)
        .map(|(name, (iterations, cost))| Solve {
            name,
            iterations,
            cost,
            samples: rows.next().map(|r| r.samples).unwrap_or_default(),
        })
        .collect()
}

/// One call a sample of each of `runs`, named in turn by `names`.
fn named<'a>(
    names: &[&'static str],
    runs: impl IntoIterator<Item = &'a mut dyn FnMut()>,
) -> Vec<Timed<'a>> {
    names
        .iter()
        .zip(runs)
        .map(|(&name, run)| Timed::new(name, 1, run))
        .collect()
}

/// Each closure of `runs` as a trait object, for [`named`].
fn each<F: FnMut()>(runs: &mut [F]) -> impl Iterator<Item = &mut dyn FnMut()> {
    runs.iter_mut().map(|run| run as &mut dyn FnMut())
}

/// The optimizer's failure as the report's error.
fn plan_failed<const N: usize, const X: usize>(e: PlanError<N, X>) -> Error {
    Error::Plan(e.to_string())
}

/// `solve_reduced` on the SE(2) scene from the spline guess for each N of [`AGAINST_N`].
///
/// # Errors
/// A solve that fails.
pub fn against_n(measure: Measure<'_>) -> Result<Vec<Solve>, Error> {
    let system = se2_scene();
    let problems: Vec<_> = AGAINST_N
        .iter()
        .map(|&steps| BoundaryValueProblem::new(&system, &SE2_START, &SE2_GOAL, T_END, steps))
        .collect();
    let solves = problems
        .iter()
        .map(|p| {
            p.solve_reduced(Guess::Spline)
                .map(|s| (s.iterations, s.cost))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut runs: Vec<_> = problems
        .iter()
        .map(|p| {
            move || {
                black_box(p.solve_reduced(Guess::Spline).map(|s| s.cost)).ok();
            }
        })
        .collect();
    Ok(measured(
        measure,
        &mut named(&AGAINST_N_NAMES, each(&mut runs)),
        solves,
    ))
}

/// The condensed solve with the reduced step maps (`solve_reduced`), N = 400.
pub const REDUCED: &str = "solve_reduced/se2_obstacle_N400";
/// The condensed solve with dense step maps (`solve`), N = 400.
pub const DENSE: &str = "solve/se2_obstacle_N400";
/// The banded LU of the whole Jacobian, N = 400.
pub const BANDED: &str = "solve_banded/se2_obstacle_N400";
/// The warm re-solve after a shift by one step, N = 400.
pub const WARM: &str = "warm_resolve/se2_obstacle_N400";

/// The SE(2) scene at N = 400: the three linear solvers from the spline guess and the warm
/// re-solve (`solve_reduced`) of the shifted solution, its start the shifted first state and
/// the goal fixed.
///
/// # Errors
/// A solve that fails.
pub fn at_400(measure: Measure<'_>) -> Result<Vec<Solve>, Error> {
    let system = se2_scene();
    let problem = |solver| {
        BoundaryValueProblem::new(&system, &SE2_START, &SE2_GOAL, T_END, STEPS)
            .with_options(BvpOptions::default().with_linear_solver(solver))
    };
    let (condensed, banded) = (
        problem(LinearSolver::Condensed),
        problem(LinearSolver::Banded),
    );
    let cold = condensed.solve_reduced(Guess::Spline)?;
    let shifted = cold.shifted(&system);
    let start = shifted.states[0].as_slice()[..SE2_START.len()].to_vec();
    let warm = BoundaryValueProblem::new(&system, &start, &SE2_GOAL, T_END, STEPS);
    let solves = [
        cold.clone(),
        condensed.solve(Guess::Spline)?,
        banded.solve(Guess::Spline)?,
        warm.solve_reduced(Guess::Solution(&shifted))?,
    ]
    .map(|s| (s.iterations, s.cost));
    let cost = |s: Result<BvpSolution<12, 15>, retract::Error>| {
        black_box(s.map(|s| s.cost)).ok();
    };
    let mut reduced = || cost(condensed.solve_reduced(Guess::Spline));
    let mut dense = || cost(condensed.solve(Guess::Spline));
    let mut band = || cost(banded.solve(Guess::Spline));
    let mut rewarm = || cost(warm.solve_reduced(Guess::Solution(&shifted)));
    Ok(measured(
        measure,
        &mut named(
            &[REDUCED, DENSE, BANDED, WARM],
            [
                &mut reduced as &mut dyn FnMut(),
                &mut dense,
                &mut band,
                &mut rewarm,
            ],
        ),
        solves.to_vec(),
    ))
}

/// The optimizer against the root finder on one problem: the same guess, the same cost.
#[derive(Clone, Debug)]
pub struct Race {
    /// Scene and start ("one-disc cold", ...).
    pub case: &'static str,
    /// The optimizer's solve.
    pub optimizer: Solve,
    /// The root finder's solve.
    pub root: Solve,
}

impl Race {
    /// The optimizer's time over the root finder's: the median over the rounds of the ratio in
    /// each round ([`paired_ratio`]).
    pub fn ratio(&self) -> f64 {
        paired_ratio(&self.optimizer.samples, &self.root.samples)
    }

    /// Best time of the optimizer over best time of the root finder.
    pub fn best_ratio(&self) -> f64 {
        self.optimizer.samples.best() / self.root.samples.best()
    }

    /// The relative difference of the two costs.
    pub fn cost_difference(&self) -> f64 {
        (self.optimizer.cost - self.root.cost).abs() / self.root.cost.abs()
    }
}

/// The one-disc scene's feasible guess: the root finder's states, the optimizer's jets and its
/// top derivatives.
pub type BumpGuess = (
    Vec<SVector<f64, 8>>,
    Vec<SVector<f64, 4>>,
    Vec<SVector<f64, 2>>,
);

/// The one-disc scene's feasible guess with `steps` steps: the Hermite cubic between the
/// boundary jets (here the straight line at unit speed) plus the bump 1.3 * 16 s^2 (1 - s)^2
/// in y, s = t / T. Returns the root finder's states z_i = (x_i, p_i) (the Legendre map of the
/// guess's derivative data (q, q', q'', q''') at t_i) and the optimizer's jets
/// x_i = (q, q')(t_i) and top derivatives u_i = q'' at the step midpoints.
pub fn bump_guess(system: &OneDisc, steps: usize) -> BumpGuess {
    let h = T_END / steps as f64;
    // the bump and its first three derivatives in t
    let bump = |t: f64| {
        let (s, c) = (t / T_END, 1.3 * 16.0);
        [
            c * s * s * (1.0 - s).powi(2),
            c * (2.0 * s - 6.0 * s * s + 4.0 * s.powi(3)) / T_END,
            c * (2.0 - 12.0 * s + 12.0 * s * s) / T_END.powi(2),
            c * (-12.0 + 24.0 * s) / T_END.powi(3),
        ]
    };
    // (q, q', q'', q''') in blocks of 2
    let derivatives = |t: f64| {
        let b = bump(t);
        SVector::<f64, 8>::from([-2.0 + t, 0.2 + b[0], 1.0, b[1], 0.0, b[2], 0.0, b[3]])
    };
    let times = (0..=steps).map(|i| i as f64 * h);
    let states = times
        .clone()
        .map(|t| system.legendre(&derivatives(t)))
        .collect();
    let x = times
        .map(|t| derivatives(t).fixed_rows::<4>(0).into_owned())
        .collect();
    let u = (0..steps)
        .map(|i| SVector::from([0.0, bump((i as f64 + 0.5) * h)[2]]))
        .collect();
    (states, x, u)
}

/// One scene of [`races`]: its ends, the guesses of both solvers, the closures' names
/// (optimizer cold, root finder cold, optimizer warm, root finder warm) and the cases' names
/// (cold, warm).
struct Scenario<'a, const N: usize, const X: usize, const S: usize, const M: usize> {
    ends: [&'a [f64; X]; 2],
    optimizer_guess: PlanGuess<'a, N, X>,
    root_guess: Guess<'a, S, M>,
    names: [&'static str; 4],
    cases: [&'static str; 2],
}

/// The optimizer against the root finder on both scenes at N = 400, cold and warm: the
/// one-disc scene from the bump guess, then the SE(2) scene from the spline guess. Warm: each
/// solver's solution shifted by one step, its first jet the new start, the goal, T and N
/// fixed.
///
/// # Errors
/// A solve that fails; [`Error::CostsDiffer`] where the two solvers' costs differ by 1e-8
/// (relative) or more.
pub fn races(measure: Measure<'_>) -> Result<Vec<Race>, Error> {
    let disc = one_disc();
    let (states, x, u) = bump_guess(&disc, STEPS);
    let mut out = race(
        &mut *measure,
        &disc,
        Scenario {
            ends: [&DISC_START, &DISC_GOAL],
            optimizer_guess: PlanGuess::Path { x: &x, u: &u },
            root_guess: Guess::States(&states),
            names: [
                "optimize/one_disc_N400",
                "solve_reduced/one_disc_N400",
                "optimize_warm/one_disc_N400",
                "warm_resolve/one_disc_N400",
            ],
            cases: ["one-disc cold", "one-disc warm"],
        },
    )?;
    let se2 = se2_scene();
    out.extend(race(
        measure,
        &se2,
        Scenario {
            ends: [&SE2_START, &SE2_GOAL],
            optimizer_guess: PlanGuess::Spline,
            root_guess: Guess::Spline,
            names: [
                "optimize/se2_obstacle_N400",
                REDUCED,
                "optimize_warm/se2_obstacle_N400",
                WARM,
            ],
            cases: ["se2 cold", "se2 warm"],
        },
    )?);
    Ok(out)
}

/// One scene of [`races`].
fn race<
    Sys,
    const N: usize,
    const K: usize,
    const X: usize,
    const S: usize,
    const M: usize,
    const R: usize,
>(
    measure: Measure<'_>,
    system: &Sys,
    scenario: Scenario<'_, N, X, S, M>,
) -> Result<Vec<Race>, Error>
where
    Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ReducedScheme<S, M, R>,
{
    let [start, goal] = scenario.ends;
    let optimizer = OptimalControlProblem::new(system, start, goal, T_END, STEPS);
    let root = BoundaryValueProblem::new(system, start, goal, T_END, STEPS);
    let (optimizer_guess, root_guess) = (scenario.optimizer_guess, scenario.root_guess);
    let plan = optimizer.solve(optimizer_guess).map_err(plan_failed)?;
    let solution = root.solve_reduced(root_guess)?;
    let shifted_plan = plan.shifted();
    let shifted_solution = solution.shifted(system);
    let mut optimizer_start = [0.0; X];
    optimizer_start.copy_from_slice(shifted_plan.x[0].as_slice());
    let root_start = shifted_solution.states[0].as_slice()[..X].to_vec();
    let optimizer_warm = OptimalControlProblem::new(system, &optimizer_start, goal, T_END, STEPS);
    let root_warm = BoundaryValueProblem::new(system, &root_start, goal, T_END, STEPS);
    let warm_plan = optimizer_warm
        .solve(PlanGuess::Plan(&shifted_plan))
        .map_err(plan_failed)?;
    let warm_solution = root_warm.solve_reduced(Guess::Solution(&shifted_solution))?;
    let solves = vec![
        (plan.iterations, plan.cost),
        (solution.iterations, solution.cost),
        (warm_plan.iterations, warm_plan.cost),
        (warm_solution.iterations, warm_solution.cost),
    ];
    let plan_cost = |p: Result<Plan<N, X>, PlanError<N, X>>| {
        black_box(p.map(|p| p.cost)).ok();
    };
    let root_cost = |s: Result<BvpSolution<S, M>, retract::Error>| {
        black_box(s.map(|s| s.cost)).ok();
    };
    let mut optimizer_cold = || plan_cost(optimizer.solve(optimizer_guess));
    let mut root_cold = || root_cost(root.solve_reduced(root_guess));
    let mut optimizer_rewarm = || plan_cost(optimizer_warm.solve(PlanGuess::Plan(&shifted_plan)));
    let mut root_rewarm = || root_cost(root_warm.solve_reduced(Guess::Solution(&shifted_solution)));
    let runs: [&mut dyn FnMut(); 4] = [
        &mut optimizer_cold,
        &mut root_cold,
        &mut optimizer_rewarm,
        &mut root_rewarm,
    ];
    let mut solves = measured(measure, &mut named(&scenario.names, runs), solves).into_iter();
    let mut races = Vec::new();
    for case in scenario.cases {
        let (Some(optimizer), Some(root)) = (solves.next(), solves.next()) else {
            break;
        };
        let race = Race {
            case,
            optimizer,
            root,
        };
        let difference = race.cost_difference();
        if difference.is_nan() || difference >= 1e-8 {
            return Err(Error::CostsDiffer { case, difference });
        }
        races.push(race);
    }
    Ok(races)
}

/// The step counts of [`extrapolation`].
pub const EXTRAPOLATED: [usize; 3] = [40, 50, 100];
/// The names of [`extrapolation`]'s solves, one per entry of [`EXTRAPOLATED`].
pub const EXTRAPOLATED_NAMES: [&str; 3] = [
    "solve_extrapolated/one_disc_N40",
    "solve_extrapolated/one_disc_N50",
    "solve_extrapolated/one_disc_N100",
];

/// One extrapolated solve against the reference.
#[derive(Clone, Debug)]
pub struct Extrapolation {
    /// The coarse step count N (the solves have N, 2N and 4N steps).
    pub steps: usize,
    /// The cost's error against the reference, relative.
    pub cost_error: f64,
    /// The cost's error estimate, relative to the reference cost.
    pub estimate: f64,
    /// The max-norm error of the momentum p(0).
    pub momentum_error: f64,
    /// The SQP iterations at N, 2N and 4N.
    pub iterations: [usize; 3],
    /// The times of `solve_extrapolated` (ns).
    pub samples: Samples,
}

/// The one-disc scene's jets and top derivatives, from [`bump_guess`].
type Path = (Vec<SVector<f64, 4>>, Vec<SVector<f64, 2>>);

/// The optimizer's guess of a [`Path`].
fn path((x, u): &Path) -> PlanGuess<'_, 2, 4> {
    PlanGuess::Path { x, u }
}

/// Richardson extrapolation on the one-disc scene from the bump guess: for each N of
/// [`EXTRAPOLATED`], `solve_extrapolated` to tolerance 1e-9 against an extrapolation at
/// N = 400 solved to 1e-10 (the reference).
///
/// # Errors
/// A solve that fails.
pub fn extrapolation(measure: Measure<'_>) -> Result<Vec<Extrapolation>, Error> {
    let system = one_disc();
    let guess = |steps: usize| -> Path {
        let (_, x, u) = bump_guess(&system, steps);
        (x, u)
    };
    let problem = |steps: usize, tolerance: f64| {
        OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, T_END, steps)
            .with_options(PlanOptions::default().with_tolerance(tolerance))
    };
    let reference = problem(STEPS, 1e-10)
        .solve_extrapolated(path(&guess(STEPS)))
        .map_err(plan_failed)?;
    let cases: Vec<_> = EXTRAPOLATED
        .iter()
        .map(|&steps| (steps, problem(steps, 1e-9), guess(steps)))
        .collect();
    let mut results = Vec::new();
    for (steps, p, guess) in &cases {
        let e = p.solve_extrapolated(path(guess)).map_err(plan_failed)?;
        results.push(Extrapolation {
            steps: *steps,
            cost_error: (e.cost - reference.cost).abs() / reference.cost,
            estimate: e.cost_error / reference.cost,
            momentum_error: (e.momenta[0] - reference.momenta[0]).amax(),
            iterations: e.iterations(),
            samples: Samples::default(),
        });
    }
    let mut runs: Vec<_> = cases
        .iter()
        .map(|(_, p, guess)| {
            move || {
                black_box(p.solve_extrapolated(path(guess)).map(|e| e.cost)).ok();
            }
        })
        .collect();
    let rows = measure(&mut named(&EXTRAPOLATED_NAMES, each(&mut runs)));
    for (result, row) in results.iter_mut().zip(rows) {
        result.samples = row.samples;
    }
    Ok(results)
}

/// Every measurement of the planner, in interleaved rounds.
#[derive(Clone, Debug)]
pub struct PlannerSpeed {
    /// [`against_n`].
    pub against_n: Vec<Solve>,
    /// [`at_400`].
    pub at_400: Vec<Solve>,
    /// [`races`].
    pub races: Vec<Race>,
    /// [`extrapolation`].
    pub extrapolation: Vec<Extrapolation>,
    /// The rounds of [`against_n`] and [`at_400`].
    pub rounds: usize,
    /// The rounds of [`races`] and [`extrapolation`].
    pub race_rounds: usize,
    /// Wall time of all of them in seconds (the solves before timing included).
    pub seconds: f64,
}

/// Runs every measurement: [`against_n`] and [`at_400`] in `rounds` interleaved rounds,
/// the cheaper [`races`] and [`extrapolation`] in `race_rounds`.
///
/// # Errors
/// The measurements'.
pub fn measure_all(rounds: usize, race_rounds: usize) -> Result<PlannerSpeed, Error> {
    let started = Instant::now();
    let mut measure = |closures: &mut [Timed<'_>]| interleaved(rounds, closures);
    let against_n = against_n(&mut measure)?;
    let at_400 = at_400(&mut measure)?;
    let mut measure = |closures: &mut [Timed<'_>]| interleaved(race_rounds, closures);
    Ok(PlannerSpeed {
        against_n,
        at_400,
        races: races(&mut measure)?,
        extrapolation: extrapolation(&mut measure)?,
        rounds,
        race_rounds,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// A time in ns as milliseconds: "0.31 ms", "10.1 ms".
pub fn format_ms(ns: f64) -> String {
    let ms = ns / 1e6;
    if ms < 10.0 {
        format!("{ms:.2} ms")
    } else {
        format!("{ms:.1} ms")
    }
}

/// Writes every table and line of the planner's part of the report, as markdown.
///
/// # Errors
/// [`Error::Io`].
pub fn write_all(out: &mut dyn Write, speed: &PlannerSpeed) -> Result<(), Error> {
    write_against_n(out, &speed.against_n, speed.rounds)?;
    write_at_400(out, &speed.at_400)?;
    write_races(out, &speed.races, speed.race_rounds)?;
    write_extrapolation(out, &speed.extrapolation, speed.race_rounds)?;
    writeln!(out, "\nplanner: {:.1} s", speed.seconds)?;
    Ok(())
}

/// The table of solve time and time per step against N, and a line with the iterations and
/// the growth of the time per step.
///
/// # Errors
/// [`Error::Io`].
pub fn write_against_n(out: &mut dyn Write, solves: &[Solve], rounds: usize) -> Result<(), Error> {
    writeln!(
        out,
        "\nPlanner: solve time against N (SE(2), one disc, T = 4, from the spline guess, to \
         residual 1e-10, `solve_reduced`; best of {rounds} interleaved rounds):\n"
    )?;
    let rows: Vec<(usize, &Solve)> = AGAINST_N.iter().copied().zip(solves).collect();
    let cells = |f: &dyn Fn(usize, &Solve) -> String| {
        rows.iter()
            .map(|&(n, s)| format!(" {} |", f(n, s)))
            .collect::<String>()
    };
    let steps: Vec<String> = rows.iter().map(|(n, _)| n.to_string()).collect();
    let head: Vec<&str> = ["N"]
        .into_iter()
        .chain(steps.iter().map(String::as_str))
        .collect();
    write_head(out, &head)?;
    writeln!(
        out,
        "| solve |{}",
        cells(&|_, s| format_ms(s.samples.best()))
    )?;
    let per_step = |n: usize, s: &Solve| s.samples.best() / n as f64;
    writeln!(
        out,
        "| per step |{}",
        cells(&|n, s| format_ns(per_step(n, s)))
    )?;
    let iterations: Vec<String> = solves.iter().map(|s| s.iterations.to_string()).collect();
    if let (Some(&(first, a)), Some(&(last, b))) = (rows.first(), rows.last()) {
        writeln!(
            out,
            "\nagainst N: Newton iterations {}; time per step at N = {last} / at N = {first}: \
             {:.2}x",
            iterations.join(", "),
            per_step(last, b) / per_step(first, a)
        )?;
    }
    Ok(())
}

/// The table label of a solve of [`at_400`].
fn at_400_label(name: &str) -> &'static str {
    match name {
        REDUCED => "condensed, reduced step maps (`solve_reduced`)",
        DENSE => "condensed, dense step maps (`solve`)",
        BANDED => "banded LU of the whole Jacobian (`solve`)",
        WARM => "warm re-solve after a shift by one step (`solve_reduced`)",
        _ => "?",
    }
}

/// The table of [`at_400`] (best time and ratio to `solve_reduced`, the median of the ratios
/// within a round) and a line with the ratios.
///
/// # Errors
/// [`Error::Io`].
pub fn write_at_400(out: &mut dyn Write, solves: &[Solve]) -> Result<(), Error> {
    writeln!(
        out,
        "\nPlanner: the linear solvers and the warm re-solve at N = 400 (same scene, same \
         rounds; ratio: the median of the ratios within a round):\n"
    )?;
    write_head(
        out,
        &["N = 400", "Newton iterations", "time", "vs `solve_reduced`"],
    )?;
    let empty = Solve {
        name: "",
        iterations: 0,
        cost: f64::NAN,
        samples: Samples::default(),
    };
    let find = |name: &str| solves.iter().find(|s| s.name == name).unwrap_or(&empty);
    let reduced = &find(REDUCED).samples;
    for s in solves {
        writeln!(
            out,
            "| {} | {} | {} | {:.2}x |",
            at_400_label(s.name),
            s.iterations,
            format_ms(s.samples.best()),
            paired_ratio(&s.samples, reduced)
        )?;
    }
    let ratio = |name: &str| paired_ratio(&find(name).samples, reduced);
    writeln!(
        out,
        "\nlinear solvers N=400: dense step maps {:.1}x, banded LU {:.1}x the reduced step maps \
         ({}); warm re-solve {} iterations, {}",
        ratio(DENSE),
        ratio(BANDED),
        format_ms(reduced.best()),
        find(WARM).iterations,
        format_ms(find(WARM).samples.best()),
    )?;
    Ok(())
}

/// The table of [`races`] and the line of their ratios.
///
/// # Errors
/// [`Error::Io`].
pub fn write_races(out: &mut dyn Write, races: &[Race], rounds: usize) -> Result<(), Error> {
    writeln!(
        out,
        "\nPlanner: the optimizer against the root finder (`solve_reduced`) at N = 400 from the \
         same guess, interleaved, best of {rounds} rounds each; ratio = optimizer / root \
         finder, the median of the ratios within a round (and of the best times):\n"
    )?;
    write_head(
        out,
        &[
            "N = 400",
            "optimizer",
            "root finder",
            "ratio",
            "best / best",
            "iterations (optimizer, root finder)",
            "cost difference",
        ],
    )?;
    for r in races {
        writeln!(
            out,
            "| {} | {} | {} | {:.2}x | {:.2}x | {}, {} | {:.1e} |",
            r.case,
            format_ms(r.optimizer.samples.best()),
            format_ms(r.root.samples.best()),
            r.ratio(),
            r.best_ratio(),
            r.optimizer.iterations,
            r.root.iterations,
            r.cost_difference()
        )?;
    }
    let ratios: Vec<String> = races
        .iter()
        .map(|r| format!("{} {:.2}x", r.case, r.ratio()))
        .collect();
    writeln!(out, "\nratios: {} (target <= 1.2)", ratios.join(", "))?;
    Ok(())
}

/// The table of [`extrapolation`].
///
/// # Errors
/// [`Error::Io`].
pub fn write_extrapolation(
    out: &mut dyn Write,
    rows: &[Extrapolation],
    rounds: usize,
) -> Result<(), Error> {
    writeln!(
        out,
        "\nPlanner: Richardson extrapolation (N, 2N, 4N) on the one-disc scene, tolerance 1e-9, \
         against N = 400 extrapolated at 1e-10 (time best of {rounds} interleaved rounds):\n"
    )?;
    write_head(
        out,
        &[
            "N",
            "cost error",
            "estimate",
            "$p(0)$ error",
            "iterations ($N$, $2N$, $4N$)",
            "time",
        ],
    )?;
    for e in rows {
        let [a, b, c] = e.iterations;
        writeln!(
            out,
            "| {} | {:.1e} | {:.1e} | {:.1e} | {a}, {b}, {c} | {} |",
            e.steps,
            e.cost_error,
            e.estimate,
            e.momentum_error,
            format_ms(e.samples.best())
        )?;
    }
    Ok(())
}
