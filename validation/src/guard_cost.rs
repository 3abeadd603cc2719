//! Cost of the singularity guard: one check at the paper's closest approach (the three points;
//! the step's check with the chord rule, where a step of h = 0.01 is shorter than the default
//! spacing 0.02; the chord of a long step, h = 0.1, which a spacing of 0.005 would cut into 16
//! pieces, but whose three points decide it, the disc's guard being quadratic) against the
//! general step it guards, and the paper's 400-step run (`retract::trajectory`) with the
//! domain check on and off. The measurements of
//! `benches/guard.rs` and of the report.

use std::hint::black_box;
use std::io::Write;

use retract::nalgebra::SVector;
use retract::step::{check_step_domain, solve_step};
use retract::{LiftedSystem, StepOptions, step, trajectory};

use crate::Error;
use crate::systems::{H, PAPER_STEPS, RigidBody, Z, closest_approach, paper_start};
use crate::timing::{Row, Timed, best_of, interleaved, write_rows};

/// Pieces of the long step's chord.
pub const PIECES: u32 = 16;

/// The states the guard is timed on.
pub struct GuardCase {
    /// The state at the closest approach.
    pub z: Z,
    /// The solved unknowns of a step of [`H`] from `z` (state and top derivative).
    pub w: SVector<f64, 15>,
    /// The solved unknowns of a step of 0.1 from `z`, whose chord would have [`PIECES`]
    /// pieces under [`GuardCase::fine`] (the disc's guard is quadratic: the three points
    /// decide it).
    pub long: SVector<f64, 15>,
    /// Options with the chord spacing 0.005 and at most [`PIECES`] pieces.
    pub fine: StepOptions,
}

impl GuardCase {
    /// Solves both steps from the closest approach and checks that the long one has
    /// [`PIECES`] pieces and clears the disc.
    ///
    /// # Errors
    /// A failed step; [`Error::Domain`] if the long step is too short or hits the disc.
    pub fn new(system: &RigidBody) -> Result<Self, Error> {
        let z = closest_approach(system)?;
        let unchecked = StepOptions::default().with_domain_check(false);
        let w = solve_step(system, &z, system.predictor(&z, H, 0.5)?, H, &unchecked)?.0;
        let long = system.predictor(&z, 0.1, 0.5)?;
        let long = solve_step(system, &z, long, 0.1, &unchecked)?.0;
        let fine = StepOptions::default().with_chord_check(0.005, PIECES);
        let length = (0..6).map(|i| (long[i] - z[i]).abs()).fold(0.0, f64::max);
        if length <= PIECES as f64 * 0.005 {
            return Err(Error::Domain("the long step (shorter than 16 pieces)"));
        }
        check_step_domain(system, &z, &long, &fine).map_err(|_| Error::Domain("the long step"))?;
        Ok(Self { z, w, long, fine })
    }
}

/// The general step, domain check off.
pub const STEP_UNCHECKED: &str = "general step, domain check off";
/// `check_domain` at the three points.
pub const CHECK_DOMAIN: &str = "`check_domain` (three points)";
/// `check_step_domain` of a short step.
pub const CHECK_SHORT: &str = "`check_step_domain`, step of h = 0.01 (no pieces)";
/// `check_step_domain` of the long step.
pub const CHECK_LONG: &str = "`check_step_domain`, h = 0.1 (quadratic guard: no pieces)";
/// The paper's run, guard on.
pub const RUN_ON: &str = "paper's 400-step run (`trajectory`), guard on";
/// The paper's run, guard off.
pub const RUN_OFF: &str = "paper's 400-step run (`trajectory`), guard off";

/// The guard's costs, `rounds` interleaved rounds; the single checks make `calls` calls a
/// sample, the step a tenth of that, the runs one.
///
/// # Errors
/// [`GuardCase::new`]'s.
pub fn guard_costs(system: &RigidBody, rounds: usize, calls: usize) -> Result<Vec<Row>, Error> {
    let case = GuardCase::new(system)?;
    let (checked, unchecked) = (
        StepOptions::default(),
        StepOptions::default().with_domain_check(false),
    );
    let z0 = paper_start(system);
    let run = |options: &StepOptions| {
        black_box(trajectory(system, &z0, H, PAPER_STEPS, options).map(|t| t.states.len())).ok()
    };
    Ok(interleaved(
        rounds,
        &mut [
            Timed::new(STEP_UNCHECKED, (calls / 10).max(1), &mut || {
                black_box(step(system, black_box(&case.z), H, &unchecked).map(|s| s.0[0])).ok();
            }),
            Timed::new(CHECK_DOMAIN, calls, &mut || {
                black_box(system.check_domain(black_box(&case.z), black_box(&case.w), 0.5)).ok();
            }),
            Timed::new(CHECK_SHORT, calls, &mut || {
                black_box(check_step_domain(
                    system,
                    black_box(&case.z),
                    black_box(&case.w),
                    &checked,
                ))
                .ok();
            }),
            Timed::new(CHECK_LONG, calls, &mut || {
                black_box(check_step_domain(
                    system,
                    black_box(&case.z),
                    black_box(&case.long),
                    &case.fine,
                ))
                .ok();
            }),
            Timed::new(RUN_ON, 1, &mut || {
                run(&checked);
            }),
            Timed::new(RUN_OFF, 1, &mut || {
                run(&unchecked);
            }),
        ],
    ))
}

/// Writes the guard's table and its costs, as markdown.
///
/// # Errors
/// [`Error::Io`].
pub fn write_guard(out: &mut dyn Write, rows: &[Row], rounds: usize) -> Result<(), Error> {
    writeln!(
        out,
        "\nThe singularity guard at the closest approach (best of {rounds} interleaved rounds):\n"
    )?;
    write_rows(out, "guard", rows)?;
    writeln!(
        out,
        "\nguard: check_domain {:.1}% of the step; the long step's check {:.2}x check_domain \
         (its {PIECES} pieces skipped: quadratic guard); run guard on/off {:.2}x",
        100.0 * best_of(rows, CHECK_DOMAIN) / best_of(rows, STEP_UNCHECKED),
        best_of(rows, CHECK_LONG) / best_of(rows, CHECK_DOMAIN),
        best_of(rows, RUN_ON) / best_of(rows, RUN_OFF),
    )?;
    Ok(())
}
