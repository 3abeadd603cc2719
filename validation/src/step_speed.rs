//! One step of the paper's SE(2) obstacle system (tau = 1e-2, h = 0.01, midpoint) near its
//! closest approach to the disc, generated and hand-written, and the paper's 400-step run:
//! the measurements of `benches/step.rs` and of the report.
//!
//! The variants of one step, timed in interleaved rounds ([`crate::timing`]):
//! - generated, reduced (Newton on the 2 core unknowns, `ReducedStepper`), with and without
//!   the domain check, without the rounding corrections (`StepOptions::compensated` off),
//!   and without both;
//! - generated, general (Newton on all 15 unknowns, `retract::step`);
//! - the hand-written peers of [`crate::peers`]: dense 12x12 Newton (Jacobian by hand, by
//!   dual numbers, by finite differences) and the reduced 3x3 Newton on $q_\theta$, without
//!   and with the generated step's domain check;
//! - the tight hand-written reduced step with the guard ([`tight_guarded_step`]); the faster
//!   of it and the guarded 3x3 Newton is the limit the generated step is measured against
//!   (`step ratio generated/hand-written`).

use std::hint::black_box;
use std::io::Write;

use retract::nalgebra::SVector;
use retract::newton::Problem;
use retract::{LiftedSystem, ReducedFactors, ReducedScheme, ReducedStepper, StepOptions, step};

use crate::Error;
use crate::peers::{
    Core, Dense, DenseJacobian, dense_jacobian, dense_residual, dense_step, hand_guarded_step,
    hand_reduced_step, tight_guarded_step,
};
use crate::systems::{H, PAPER_STEPS, RigidBody, Z, paper_start};
use crate::timing::{Row, Timed, best_ns, best_of, format_ns, interleaved, write_rows};

/// Generated, reduced step (domain check on).
pub const REDUCED: &str = "generated, reduced (2 unknowns)";
/// Generated, reduced step, domain check off.
pub const REDUCED_UNCHECKED: &str = "generated, reduced, domain check off";
/// Generated, reduced step, domain check and rounding corrections off.
pub const REDUCED_PLAIN: &str = "generated, reduced, check and corrections off";
/// Generated, reduced step, domain check on, rounding corrections off.
pub const REDUCED_UNCOMPENSATED: &str = "generated, reduced, check on, corrections off";
/// The tight hand-written reduced step with the guard ([`tight_guarded_step`]).
pub const TIGHT: &str = "hand-written tight reduced step (2x2 closed form), guard";
/// Generated, general step.
pub const GENERAL: &str = "generated, general (15 unknowns)";
/// Hand-written dense Newton.
pub const HAND_DENSE: &str = "hand-written dense 12x12 Newton";
/// Hand-written reduced Newton.
pub const HAND_REDUCED: &str = "hand-written reduced 3x3 Newton";
/// Hand-written reduced Newton with the domain check.
pub const HAND_GUARDED: &str = "hand-written reduced 3x3 Newton, domain check";
/// Dense Newton, dual-number Jacobian.
pub const DUAL: &str = "dense 12x12, dual-number Jacobian (num-dual)";
/// Dense Newton, finite-difference Jacobian.
pub const FINITE_DIFFERENCES: &str = "dense 12x12, finite-difference Jacobian";

/// Checks that every variant computes the general step's state from `z` (to 1e-12).
///
/// # Errors
/// [`Error::Disagree`] for a variant that does not; the step's own errors.
pub fn check_variants(system: &RigidBody, z: &Z) -> Result<(), Error> {
    let options = StepOptions::default();
    let reference = step(system, z, H, &options)?.0;
    let mut reduced = ReducedStepper::new(system);
    let plain = options.with_domain_check(false).with_compensation(false);
    let uncompensated = options.with_compensation(false);
    let variants: [(&'static str, Z); 9] = [
        (REDUCED, reduced.step(z, H, &options)?.0),
        (REDUCED_PLAIN, reduced.step(z, H, &plain)?.0),
        (REDUCED_UNCOMPENSATED, reduced.step(z, H, &uncompensated)?.0),
        (TIGHT, tight_guarded_step(z)?),
        (HAND_DENSE, dense_step(z, DenseJacobian::Hand)?),
        (HAND_REDUCED, hand_reduced_step(z)?),
        (HAND_GUARDED, hand_guarded_step(z)?),
        (DUAL, dense_step(z, DenseJacobian::Dual)?),
        (
            FINITE_DIFFERENCES,
            dense_step(z, DenseJacobian::FiniteDifferences)?,
        ),
    ];
    for (variant, other) in variants {
        let difference = (reference - other).amax();
        if difference >= 1e-12 {
            return Err(Error::Disagree {
                variant,
                difference,
            });
        }
    }
    Ok(())
}

/// The Newton system (residual and Jacobian) of one step, per variant: best time (ns) over
/// `batches` batches.
///
/// # Errors
/// The predictor's or the factors' errors.
pub fn newton_systems(
    system: &RigidBody,
    z: &Z,
    batches: usize,
) -> Result<Vec<(&'static str, f64)>, Error> {
    let w = system.predictor(z, H, 0.5)?;
    let factors = ReducedFactors::new(system, H, 0.5)?;
    let offset = system.core_offset(&factors, z);
    let y = SVector::<f64, 2>::new(z[0], z[1]);
    let w12 = w.fixed_rows::<12>(0).into_owned();
    let core = Core {
        c0: retract::nalgebra::Vector3::new(z[0], z[1], z[2]),
    };
    let dense = |jacobian| Dense { z0: z, jacobian };
    let (dual, fd) = (
        dense(DenseJacobian::Dual),
        dense(DenseJacobian::FiniteDifferences),
    );
    Ok(vec![
        (
            GENERAL,
            best_ns(batches, 20_000, || {
                black_box(system.residual(black_box(z), &w, H, 0.5));
                black_box(system.jacobian(black_box(z), &w, H, 0.5));
            }),
        ),
        (
            REDUCED,
            best_ns(batches, 20_000, || {
                black_box(system.core_system(&factors, &offset, black_box(&y), H, 0.5));
            }),
        ),
        (
            HAND_DENSE,
            best_ns(batches, 20_000, || {
                black_box(dense_residual(black_box(z), &w12));
                black_box(dense_jacobian(black_box(z), &w12));
            }),
        ),
        (
            HAND_REDUCED,
            best_ns(batches, 20_000, || {
                black_box(core.residual(black_box(&core.c0)));
                black_box(core.jacobian(black_box(&core.c0)));
            }),
        ),
        (
            DUAL,
            best_ns(batches, 5_000, || {
                black_box(dual.jacobian(black_box(&w12)));
            }),
        ),
        (
            FINITE_DIFFERENCES,
            best_ns(batches, 5_000, || {
                black_box(fd.jacobian(black_box(&w12)));
            }),
        ),
    ])
}

/// One step from `z` per variant, timed in `rounds` interleaved rounds; the cheap variants
/// make `calls` calls a sample, the dense ones a twentieth of that and the finite-difference
/// one a hundredth.
pub fn steps(system: &RigidBody, z: &Z, rounds: usize, calls: usize) -> Vec<Row> {
    let options = StepOptions::default();
    let unchecked = options.with_domain_check(false);
    let plain = unchecked.with_compensation(false);
    let uncompensated = options.with_compensation(false);
    let (mut reduced, mut reduced_unchecked, mut reduced_plain, mut reduced_uncompensated) = (
        ReducedStepper::new(system),
        ReducedStepper::new(system),
        ReducedStepper::new(system),
        ReducedStepper::new(system),
    );
    let (slow, slowest) = ((calls / 20).max(1), (calls / 100).max(1));
    interleaved(
        rounds,
        &mut [
            Timed::new(REDUCED, calls, &mut || {
                black_box(reduced.step(black_box(z), H, &options).map(|s| s.0[0]).ok());
            }),
            Timed::new(REDUCED_UNCHECKED, calls, &mut || {
                let s = reduced_unchecked.step(black_box(z), H, &unchecked);
                black_box(s.map(|s| s.0[0]).ok());
            }),
            Timed::new(REDUCED_PLAIN, calls, &mut || {
                let s = reduced_plain.step(black_box(z), H, &plain);
                black_box(s.map(|s| s.0[0]).ok());
            }),
            Timed::new(REDUCED_UNCOMPENSATED, calls, &mut || {
                let s = reduced_uncompensated.step(black_box(z), H, &uncompensated);
                black_box(s.map(|s| s.0[0]).ok());
            }),
            Timed::new(TIGHT, calls, &mut || {
                black_box(tight_guarded_step(black_box(z)).ok());
            }),
            Timed::new(GENERAL, slow, &mut || {
                black_box(step(system, black_box(z), H, &options).map(|s| s.0[0]).ok());
            }),
            Timed::new(HAND_DENSE, slow, &mut || {
                black_box(dense_step(black_box(z), DenseJacobian::Hand).ok());
            }),
            Timed::new(HAND_REDUCED, calls, &mut || {
                black_box(hand_reduced_step(black_box(z)).ok());
            }),
            Timed::new(HAND_GUARDED, calls, &mut || {
                black_box(hand_guarded_step(black_box(z)).ok());
            }),
            Timed::new(DUAL, slow, &mut || {
                black_box(dense_step(black_box(z), DenseJacobian::Dual).ok());
            }),
            Timed::new(FINITE_DIFFERENCES, slowest, &mut || {
                let s = dense_step(black_box(z), DenseJacobian::FiniteDifferences);
                black_box(s.ok());
            }),
        ],
    )
}

/// The reduced stepper's 400-step run from a fresh stepper (domain check on).
pub const RUN_REDUCED: &str = "generated reduced, domain check on";
/// The hand-written guarded 400-step run.
pub const RUN_HAND_GUARDED: &str = "hand-written reduced, domain check on";
/// The reduced stepper's 400-step run, domain check off.
pub const RUN_REDUCED_UNCHECKED: &str = "generated reduced, domain check off";
/// The reduced stepper's 400-step run, domain check and rounding corrections off.
pub const RUN_REDUCED_PLAIN: &str = "generated reduced, check and corrections off";
/// The hand-written 400-step run.
pub const RUN_HAND: &str = "hand-written reduced, domain check off";
/// The factors of one step size (a cache miss of the reduced stepper).
pub const FACTORS: &str = "factors of a new step size (`ReducedFactors::new`)";

/// The paper's 400-step run (each step waits on the last, the reduced runs from a fresh
/// stepper), generated and hand-written, with and without the domain check, and the cost of
/// the factors of a new step size: `rounds` interleaved rounds of `calls` runs each.
///
/// # Errors
/// A run that fails (checked once before timing).
pub fn paper_runs(system: &RigidBody, rounds: usize, calls: usize) -> Result<Vec<Row>, Error> {
    let options = StepOptions::default();
    let unchecked = options.with_domain_check(false);
    let plain = unchecked.with_compensation(false);
    let z0 = paper_start(system);
    let reduced_run = |options: &StepOptions| -> Result<Z, Error> {
        let mut stepper = ReducedStepper::new(system);
        let mut z = z0;
        for _ in 0..PAPER_STEPS {
            z = stepper.step(&z, H, options)?.0;
        }
        Ok(z)
    };
    let hand_run = |step: fn(&Z) -> Result<Z, Error>| -> Result<Z, Error> {
        (0..PAPER_STEPS).try_fold(z0, |z, _| step(&z))
    };
    reduced_run(&options)?;
    reduced_run(&unchecked)?;
    reduced_run(&plain)?;
    hand_run(hand_guarded_step)?;
    hand_run(hand_reduced_step)?;
    Ok(interleaved(
        rounds,
        &mut [
            Timed::new(RUN_REDUCED, calls, &mut || {
                black_box(reduced_run(&options).ok());
            }),
            Timed::new(RUN_HAND_GUARDED, calls, &mut || {
                black_box(hand_run(hand_guarded_step).ok());
            }),
            Timed::new(RUN_REDUCED_UNCHECKED, calls, &mut || {
                black_box(reduced_run(&unchecked).ok());
            }),
            Timed::new(RUN_HAND, calls, &mut || {
                black_box(hand_run(hand_reduced_step).ok());
            }),
            Timed::new(RUN_REDUCED_PLAIN, calls, &mut || {
                black_box(reduced_run(&plain).ok());
            }),
            Timed::new(FACTORS, calls * 10, &mut || {
                black_box(ReducedFactors::new(system, black_box(H), 0.5).ok());
            }),
        ],
    ))
}

/// Writes the step table (time, ratio to the generated reduced step), the ratios of the
/// generated reduced step with the guard (without and with the rounding corrections) to the
/// faster hand-written guarded step (the tight one or the 3x3 Newton), and the like-for-like ratios of the generated and the hand-written
/// reduced steps, as markdown.
///
/// # Errors
/// [`Error::Io`].
pub fn write_steps(out: &mut dyn Write, rows: &[Row], rounds: usize) -> Result<(), Error> {
    writeln!(
        out,
        "One step, SE(2) obstacle system near its closest approach, h = 0.01 (best of {rounds} \
         interleaved rounds):\n"
    )?;
    writeln!(out, "| one step | time | vs generated reduced |")?;
    writeln!(out, "|---|---|---|")?;
    let reduced = best_of(rows, REDUCED);
    for row in rows {
        let t = row.samples.best();
        writeln!(
            out,
            "| {} | {} | {:.2}x |",
            row.name,
            format_ns(t),
            t / reduced
        )?;
    }
    let (unchecked, hand, guarded) = (
        best_of(rows, REDUCED_UNCHECKED),
        best_of(rows, HAND_REDUCED),
        best_of(rows, HAND_GUARDED),
    );
    // the limit: the faster of the two hand-written guarded steps in these rounds
    let tight = best_of(rows, TIGHT).min(best_of(rows, HAND_GUARDED));
    writeln!(
        out,
        "\nstep ratio generated/hand-written: {:.2} (guard, no compensation), {:.2} \
         (compensated)",
        best_of(rows, REDUCED_UNCOMPENSATED) / tight,
        reduced / tight,
    )?;
    writeln!(
        out,
        "\nstep ratios: generated/hand-written reduced {:.2}x (check off), {:.2}x (check on; \
         {:.2}x the hand-written step without it), {:.2}x (check and corrections off); \
         dense/generated {:.1}x, dual/generated {:.1}x",
        unchecked / hand,
        reduced / guarded,
        reduced / hand,
        best_of(rows, REDUCED_PLAIN) / hand,
        best_of(rows, HAND_DENSE) / reduced,
        best_of(rows, DUAL) / reduced,
    )?;
    Ok(())
}

/// Writes the table of [`paper_runs`] and the ratios of generated to hand-written runs.
///
/// # Errors
/// [`Error::Io`].
pub fn write_runs(out: &mut dyn Write, rows: &[Row], rounds: usize) -> Result<(), Error> {
    writeln!(
        out,
        "\nThe paper's 400-step run (tau = 1e-2, from a fresh stepper; best of {rounds} \
         interleaved rounds):\n"
    )?;
    write_rows(out, "400-step run", rows)?;
    writeln!(
        out,
        "\nrun ratios: generated/hand-written {:.2}x (check on), {:.2}x (check off), {:.2}x \
         (check and corrections off)",
        best_of(rows, RUN_REDUCED) / best_of(rows, RUN_HAND_GUARDED),
        best_of(rows, RUN_REDUCED_UNCHECKED) / best_of(rows, RUN_HAND),
        best_of(rows, RUN_REDUCED_PLAIN) / best_of(rows, RUN_HAND),
    )?;
    Ok(())
}

/// The reduced stepper, each step with a step size it has not factorised recently.
pub const CHANGING_REDUCED: &str = "generated reduced, new step size each step";
/// The general step with the same step sizes.
pub const CHANGING_GENERAL: &str = "generated general, same step sizes";
/// The factors alone of the same step sizes.
pub const CHANGING_FACTORS: &str = "factors of each step size (`ReducedFactors::new`)";

/// How many distinct step sizes [`changing_step_sizes`] cycles through: four times the
/// stepper's cache of 16, so that every step misses it (checked).
const DISTINCT_SIZES: usize = 64;

/// The step sizes of [`changing_step_sizes`]: `DISTINCT_SIZES` sizes within 3 % of [`H`],
/// as an adaptive controller would choose them.
fn step_sizes() -> [f64; DISTINCT_SIZES] {
    core::array::from_fn(|k| H * (0.97 + 0.06 * k as f64 / DISTINCT_SIZES as f64))
}

/// One step from `z` with a step size that changes from call to call (every call of the
/// reduced stepper computes new factors), for the reduced stepper, the general step and the
/// factors alone: `rounds` interleaved rounds of `calls` calls each; with the reduced
/// stepper's factorisations per step over one cycle of the sizes (1: every step a cache miss).
///
/// # Errors
/// A step that fails (each size checked once before timing, the two steps agreeing to 1e-12).
pub fn changing_step_sizes(
    system: &RigidBody,
    z: &Z,
    rounds: usize,
    calls: usize,
) -> Result<(Vec<Row>, f64), Error> {
    let options = StepOptions::default();
    let sizes = step_sizes();
    let mut stepper = ReducedStepper::new(system);
    for &h in &sizes {
        let (general, reduced) = (
            step(system, z, h, &options)?.0,
            stepper.step(z, h, &options)?.0,
        );
        let difference = (general - reduced).amax();
        if difference >= 1e-12 {
            return Err(Error::Disagree {
                variant: CHANGING_REDUCED,
                difference,
            });
        }
    }
    // a second cycle through the sizes factorises on every step again
    let before = stepper.factorisations();
    for &h in &sizes {
        stepper.step(z, h, &options)?;
    }
    let misses = (stepper.factorisations() - before) as f64 / DISTINCT_SIZES as f64;
    let (mut k_reduced, mut k_general, mut k_factors) = (0, 0, 0);
    let next = |k: &mut usize| {
        *k = (*k + 1) % DISTINCT_SIZES;
        sizes[*k]
    };
    let rows = interleaved(
        rounds,
        &mut [
            Timed::new(CHANGING_REDUCED, calls, &mut || {
                let h = next(&mut k_reduced);
                black_box(stepper.step(black_box(z), h, &options).map(|s| s.0[0]).ok());
            }),
            Timed::new(CHANGING_GENERAL, calls, &mut || {
                let h = next(&mut k_general);
                black_box(step(system, black_box(z), h, &options).map(|s| s.0[0]).ok());
            }),
            Timed::new(CHANGING_FACTORS, calls, &mut || {
                let h = next(&mut k_factors);
                black_box(ReducedFactors::new(system, black_box(h), 0.5).ok());
            }),
        ],
    );
    Ok((rows, misses))
}

/// Writes the table of [`changing_step_sizes`] and the ratio of the reduced stepper's time to
/// the general step's.
///
/// # Errors
/// [`Error::Io`].
pub fn write_changing(
    out: &mut dyn Write,
    rows: &[Row],
    misses: f64,
    rounds: usize,
) -> Result<(), Error> {
    writeln!(
        out,
        "\nOne step with a new step size each step ({DISTINCT_SIZES} sizes within 3 % of \
         h = 0.01, SE(2) obstacle system near its closest approach; best of {rounds} \
         interleaved rounds):\n"
    )?;
    write_rows(out, "one step", rows)?;
    writeln!(
        out,
        "\nreduced/general with changing step sizes: {:.2}x (factorisations per reduced step: \
         {misses})",
        best_of(rows, CHANGING_REDUCED) / best_of(rows, CHANGING_GENERAL)
    )?;
    Ok(())
}
