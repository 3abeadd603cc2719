//! Speed against error.
//!
//! 1. The paper's obstacle IVP (SE(2), tau = 1e-2, q(0) = (-2, 1.05, 0), q'(0) = (1, 0, 0.5),
//!    T = 4): final error against a tight reference versus wall time for the midpoint rule
//!    and its compositions of order 4, 6, 8 (all on the generated reduced step), the explicit
//!    splitting methods (`retract::split_stepper`): Strang's splitting and its compositions
//!    of order 4, 6, 8 with fused free flows (and the order-6 one as per-stage
//!    `split::split_step` calls, the form before), Blanes and Moan's RKN methods SRKN6b
//!    (order 4), SRKN11b and SRKN14a (order 6), and SRKN14a without the singularity guard;
//!    and classical RK4 and adaptive DOP853 (ode_solvers) on the plain first-order system
//!    y' = (q', q'', q''', -grad V) (their best form, no checks). Prints
//!    `work-precision 1e-8: best=..., DOP853 ..., ratio ...` (over the guarded methods) and
//!    `work-precision 1e-8 without the guard: ...`.
//! 2. The bounded Pais-Uhlenbeck oscillator (MATH.md; w1 = 1, w2 = sqrt 2, eps = -0.05) over
//!    10^6 midpoint steps of h = 0.1 (T = 10^5): max |H - H(0)| so far against time for the
//!    midpoint rule, the order-4 composition at 3h (same number of implicit solves), RK4 and
//!    DOP853 with their step size or tolerance chosen to cost about as much as the midpoint
//!    run.
//!
//! Writes docs/work_precision.svg and docs/energy_long_run.svg and prints the tables.
//! Run: `cargo run --release -p retract-validation --example work_precision`

#[path = "../../examples/common/mod.rs"]
mod common;

use std::time::Instant;

use ode_solvers::{Dop853, System};
use retract::compose::compose;
use retract::diagnostics::rk4_step;
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;
use retract::plot::{self, Scale};
use retract::split::{Separable, split_step};
use retract::split_methods::SplittingMethod;
use retract::split_stepper::SplitStepper;
use retract::{LiftedSystem, ReducedScheme, ReducedStepper, StepOptions};

#[higher_order_lagrangian(order = 2)]
fn rigid_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
        + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

#[higher_order_lagrangian(order = 2)]
fn pais_uhlenbeck(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], w1: f64, w2: f64, eps: f64) -> f64 {
    let r2 = q[0].powi(2) + q[1].powi(2);
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2))
        - 0.5 * (w1 * w1 + w2 * w2) * (dq[0].powi(2) + dq[1].powi(2))
        + 0.5 * w1 * w1 * w2 * w2 * r2
        + eps * r2 * r2
}

/// Hamilton's equations of a generated system for ode_solvers (its own nalgebra version).
struct Hamilton<'a, Sys, const M: usize>(&'a Sys);

impl<Sys: LiftedSystem<S, M>, const S: usize, const M: usize>
    System<f64, ode_solvers::SVector<f64, S>> for Hamilton<'_, Sys, M>
{
    fn system(
        &self,
        _t: f64,
        y: &ode_solvers::SVector<f64, S>,
        dy: &mut ode_solvers::SVector<f64, S>,
    ) {
        let z = SVector::<f64, S>::from_column_slice(y.as_slice());
        let f = self
            .0
            .vector_field(&z)
            .unwrap_or_else(|_| SVector::repeat(f64::NAN));
        dy.as_mut_slice().copy_from_slice(f.as_slice());
    }
}

/// DOP853 (ode_solvers' defaults: safety 0.9, step factors in [1/3, 6]) on the state of a
/// generated system (its Hamilton equations, [`Hamilton`]) with rtol = atol = `tol` and steps
/// at most `h_max`: the states after every accepted step (its dense output is not used: in
/// ode_solvers 0.6.2 it is inaccurate for coarse output intervals), and the number of
/// accepted steps.
#[allow(clippy::type_complexity)]
fn dop853<Sys: LiftedSystem<S, M>, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    t_end: f64,
    tol: f64,
    h_max: f64,
) -> Result<(Vec<(f64, SVector<f64, S>)>, u32), Box<dyn std::error::Error>> {
    dop853_on(Hamilton::<Sys, M>(system), z0, t_end, tol, h_max)
}

/// [`dop853`] on any right-hand side `f`.
#[allow(clippy::type_complexity)]
fn dop853_on<F: System<f64, ode_solvers::SVector<f64, S>>, const S: usize>(
    f: F,
    y0: &SVector<f64, S>,
    t_end: f64,
    tol: f64,
    h_max: f64,
) -> Result<(Vec<(f64, SVector<f64, S>)>, u32), Box<dyn std::error::Error>> {
    let y0 = ode_solvers::SVector::<f64, S>::from_column_slice(y0.as_slice());
    let mut solver = Dop853::from_param(
        f,
        0.0,
        t_end,
        t_end,
        y0,
        tol,
        tol,
        0.9,
        0.0,
        0.333,
        6.0,
        h_max,
        0.0,
        u32::MAX,
        1000,
        ode_solvers::dop_shared::OutputType::Sparse,
    );
    let stats = solver.integrate().map_err(|e| format!("DOP853: {e:?}"))?;
    let states = solver
        .x_out()
        .iter()
        .zip(solver.y_out())
        .map(|(t, y)| (*t, SVector::from_column_slice(y.as_slice())))
        .collect();
    Ok((states, stats.accepted_steps))
}

/// The obstacle model's Euler-Lagrange equation as a plain first-order system, the peers'
/// best form: y = (q, q', q'', q'''), y' = (q', q'', q''', -grad V(q)) with
/// V = tau / (q_0^2 + q_1^2 - r^2), so -grad V = 2 tau (q_0, q_1, 0) / d^2.
#[derive(Clone, Copy)]
struct Plain {
    tau: f64,
    r: f64,
}

impl Plain {
    fn rhs(&self, y: &SVector<f64, 12>) -> SVector<f64, 12> {
        let d = y[0] * y[0] + y[1] * y[1] - self.r * self.r;
        let c = 2.0 * self.tau / (d * d);
        let mut dy = SVector::<f64, 12>::zeros();
        dy.fixed_rows_mut::<9>(0).copy_from(&y.fixed_rows::<9>(3));
        dy[9] = c * y[0];
        dy[10] = c * y[1];
        dy
    }

    /// Classical RK4 with `steps` steps to `t_end`.
    fn rk4(&self, y0: &SVector<f64, 12>, t_end: f64, steps: usize) -> SVector<f64, 12> {
        let h = t_end / steps as f64;
        (0..steps).fold(*y0, |y, _| {
            let k1 = self.rhs(&y);
            let k2 = self.rhs(&(y + k1 * (h / 2.0)));
            let k3 = self.rhs(&(y + k2 * (h / 2.0)));
            let k4 = self.rhs(&(y + k3 * h));
            y + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
        })
    }
}

impl System<f64, ode_solvers::SVector<f64, 12>> for Plain {
    fn system(
        &self,
        _t: f64,
        y: &ode_solvers::SVector<f64, 12>,
        dy: &mut ode_solvers::SVector<f64, 12>,
    ) {
        let f = self.rhs(&SVector::from_column_slice(y.as_slice()));
        dy.as_mut_slice().copy_from_slice(f.as_slice());
    }
}

/// The state at `t_end` from [`dop853`].
fn dop853_end<Sys: LiftedSystem<S, M>, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    t_end: f64,
    tol: f64,
    h_max: f64,
) -> Result<(SVector<f64, S>, u32), String> {
    let (states, steps) = dop853(system, z0, t_end, tol, h_max).map_err(|e| e.to_string())?;
    let end = states
        .last()
        .map(|s| s.1)
        .ok_or("DOP853 returned no state")?;
    Ok((end, steps))
}

/// Best wall time (seconds) over `repeats` runs of `f`, and its last result.
fn timed<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = f();
    for _ in 0..repeats {
        let t = Instant::now();
        out = f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out)
}

/// `steps` steps of the composition of `order` on the reduced stepper.
fn composed<Sys, const S: usize, const M: usize, const R: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    t_end: f64,
    steps: usize,
    order: u32,
) -> Result<SVector<f64, S>, retract::Error>
where
    Sys: ReducedScheme<S, M, R>,
{
    let options = StepOptions::default();
    let mut stepper = ReducedStepper::new(system);
    let h = t_end / steps as f64;
    let mut z = *z0;
    for _ in 0..steps {
        z = compose(|z, h| stepper.step(z, h, &options), &z, h, order)?.0;
    }
    Ok(z)
}

/// `steps` steps of Strang's splitting composed to `order`, each stage a full
/// `split_step` (two half free flows, the guard and the checks per stage): the form before
/// `retract::split_stepper`, kept for comparison.
fn split_per_stage<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    t_end: f64,
    steps: usize,
    order: u32,
) -> Result<SVector<f64, S>, retract::Error>
where
    Sys: Separable<3, 2> + LiftedSystem<S, M>,
{
    let options = StepOptions::default();
    let h = t_end / steps as f64;
    let mut z = *z0;
    for _ in 0..steps {
        z = compose(|z, h| split_step(system, z, h, &options), &z, h, order)?.0;
    }
    Ok(z)
}

/// `steps` steps of the splitting `method` ([`SplitStepper`]; default options, the guard on
/// unless `guard` is false).
fn split<Sys, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, 12>,
    t_end: f64,
    steps: usize,
    (method, guard): (SplittingMethod, bool),
) -> Result<SVector<f64, 12>, retract::Error>
where
    Sys: Separable<3, 2> + LiftedSystem<12, M>,
{
    let options = StepOptions::default().with_domain_check(guard);
    let mut stepper = SplitStepper::<Sys, 3, 2, 12>::new(system, method)?;
    let h = t_end / steps as f64;
    let mut z = *z0;
    for _ in 0..steps {
        z = stepper.step(&z, h, &options)?.0;
    }
    Ok(z)
}

/// One method's sweep: a table row per point (final error against `reference`, best wall
/// time of 5 runs) and its curve.
fn sweep<T: Copy>(
    name: &str,
    points: &[T],
    label: impl Fn(T) -> String,
    run: impl Fn(T) -> Result<SVector<f64, 12>, String>,
    reference: &SVector<f64, 12>,
) -> plot::Curve {
    let mut curve = Vec::new();
    for &point in points {
        let (time, end) = timed(5, || run(point));
        match end {
            Ok(end) => {
                let error = (end - reference).amax();
                println!(
                    "| {name} | {} | {error:.2e} | {:.1} us |",
                    label(point),
                    time * 1e6
                );
                curve.push((time, error.max(1e-16)));
            }
            Err(e) => println!("| {name} | {} | stopped: {e} | - |", label(point)),
        }
    }
    plot::Curve::new(name, curve)
}

/// The obstacle IVP: the implicit midpoint compositions (reduced step), the explicit
/// splitting and its compositions, and RK4 and DOP853 on the plain first-order system
/// ([`Plain`]), their final states mapped to (x, p) by the Legendre map.
fn obstacle_ivp() -> Result<(), Box<dyn std::error::Error>> {
    let system = RigidBody { tau: 1e-2, r: 1.0 };
    let plain = Plain { tau: 1e-2, r: 1.0 };
    let jet =
        SVector::<f64, 12>::from([-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let z0 = system.legendre(&jet);
    let t_end = 4.0;
    let reference = composed(&system, &z0, t_end, 4000, 8)?;
    let (dop_reference, _) = dop853_end(&system, &z0, t_end, 1e-14, t_end)?;
    println!("Obstacle IVP to T = 4; reference: order-8 composition, 4000 steps");
    println!(
        "(its distance to DOP853 at tol 1e-14: {:.1e})\n",
        (reference - dop_reference).amax()
    );
    println!("| method | steps / tol | final error | wall time |");
    println!("|---|---|---|---|");
    let steps = |n: usize| n.to_string();
    let mut curves = Vec::new();
    let implicit: [(&str, u32, &[usize]); 4] = [
        ("midpoint", 2, &[100, 200, 400, 800, 1600, 3200, 6400]),
        ("composition, order 4", 4, &[20, 40, 80, 160, 320, 640]),
        ("composition, order 6", 6, &[10, 20, 40, 80, 160]),
        ("composition, order 8", 8, &[5, 10, 20, 40, 80]),
    ];
    for (name, order, points) in implicit {
        let run = |n| composed(&system, &z0, t_end, n, order).map_err(|e| e.to_string());
        curves.push(sweep(name, points, steps, run, &reference));
    }
    let per_stage = |n| split_per_stage(&system, &z0, t_end, n, 6).map_err(|e| e.to_string());
    curves.push(sweep(
        "splitting, order 6, per-stage steps",
        &[20, 40, 80, 160, 320],
        steps,
        per_stage,
        &reference,
    ));
    let composition = |order| SplittingMethod::composition(order).map_err(|e| e.to_string());
    let explicit: [(&str, SplittingMethod, &[usize]); 7] = [
        (
            "splitting",
            composition(2)?,
            &[200, 400, 800, 1600, 3200, 6400, 12800],
        ),
        (
            "splitting, order 4",
            composition(4)?,
            &[40, 80, 160, 320, 640, 1280],
        ),
        (
            "splitting, order 6",
            composition(6)?,
            &[20, 40, 80, 160, 320],
        ),
        (
            "splitting, order 8",
            composition(8)?,
            &[10, 20, 40, 80, 160],
        ),
        (
            "splitting, BM SRKN6b",
            SplittingMethod::blanes_moan_4(),
            &[20, 40, 80, 160, 320, 640],
        ),
        (
            "splitting, BM SRKN11b",
            SplittingMethod::blanes_moan_6(),
            &[10, 20, 40, 80, 160],
        ),
        (
            "splitting, BM SRKN14a",
            SplittingMethod::blanes_moan_6a(),
            &[10, 20, 40, 80, 160],
        ),
    ];
    for (name, method, points) in explicit {
        let run = |n| split(&system, &z0, t_end, n, (method, true)).map_err(|e| e.to_string());
        curves.push(sweep(name, points, steps, run, &reference));
    }
    // the peers check nothing: the best splitting without the singularity guard, for scale
    let unguarded = (SplittingMethod::blanes_moan_6a(), false);
    let run = |n| split(&system, &z0, t_end, n, unguarded).map_err(|e| e.to_string());
    curves.push(sweep(
        "BM SRKN14a, guard off",
        &[10, 20, 40, 80],
        steps,
        run,
        &reference,
    ));
    let rk4 = |n| Ok(system.legendre(&plain.rk4(&jet, t_end, n)));
    curves.push(sweep(
        "RK4",
        &[100, 200, 400, 800, 1600, 3200],
        steps,
        rk4,
        &reference,
    ));
    let dop = |tol: f64| {
        let (states, _) = dop853_on(plain, &jet, t_end, tol, t_end).map_err(|e| e.to_string())?;
        let end = states.last().ok_or("DOP853 returned no state")?.1;
        Ok(system.legendre(&end))
    };
    let tolerances = [1e-4, 1e-6, 1e-8, 1e-10, 1e-12];
    curves.push(sweep(
        "DOP853",
        &tolerances,
        |t| format!("tol {t:.0e}"),
        dop,
        &reference,
    ));
    print_at_target(&curves);
    let figure = common::docs_path("work_precision.svg");
    plot::panels(
        &figure,
        "Obstacle IVP to T = 4: final error against wall time",
        "wall time [s]",
        &[("max-norm error at T", curves)],
        Scale::Log,
    )?;
    println!("\nfigure: {}", figure.display());
    Ok(())
}

/// The wall time of every method at a final error of 1e-8, and the line
/// `work-precision 1e-8: best=<method> <t> us, DOP853 <t> us, ratio <best/DOP853>`.
fn print_at_target(curves: &[plot::Curve]) {
    println!("\nWall time at a final error of 1e-8 (log-log interpolation between sweep points):");
    let at_target: Vec<(&str, f64)> = curves
        .iter()
        .filter_map(|c| time_at_error(&c.points, 1e-8).map(|t| (c.label.as_str(), t)))
        .collect();
    for (label, time) in &at_target {
        println!("  {label:<36} {:>7.1} us", time * 1e6);
    }
    let dop = at_target.iter().find(|(label, _)| *label == "DOP853");
    let best = at_target
        .iter()
        .filter(|(label, _)| label.starts_with("composition") || label.starts_with("splitting"))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    if let (Some((_, dop)), Some((label, best))) = (dop, best) {
        println!(
            "work-precision 1e-8: best={label} {:.1} us, DOP853 {:.1} us, ratio {:.2}",
            best * 1e6,
            dop * 1e6,
            best / dop
        );
    }
    let unguarded = at_target
        .iter()
        .find(|(label, _)| label.ends_with("guard off"));
    if let (Some((_, dop)), Some((label, time))) = (dop, unguarded) {
        println!(
            "work-precision 1e-8 without the guard: {label} {:.1} us, ratio {:.2}",
            time * 1e6,
            time / dop
        );
    }
}

/// The wall time at which a sweep of (time, error) points reaches `target`, interpolating
/// log error against log time between the two points that bracket it.
fn time_at_error(points: &[(f64, f64)], target: f64) -> Option<f64> {
    points.windows(2).find_map(|pair| {
        let ((t0, e0), (t1, e1)) = (pair[0], pair[1]);
        (e0 >= target && e1 <= target && e0 > e1).then(|| {
            let s = (e0 / target).ln() / (e0 / e1).ln();
            (t0.ln() + s * (t1 / t0).ln()).exp()
        })
    })
}

/// max |H - H(0)| so far, sampled at t = 10^(k/4).
fn energy_record(
    system: &PaisUhlenbeck,
    z0: &SVector<f64, 8>,
    h: f64,
    steps: usize,
    mut advance: impl FnMut(&SVector<f64, 8>) -> Result<SVector<f64, 8>, retract::Error>,
) -> Result<(f64, Vec<(f64, f64)>), retract::Error> {
    let h0 = system.hamiltonian(z0)?;
    let mut z = *z0;
    let mut worst: f64 = 1e-17;
    let mut record = Vec::new();
    let mut next_sample = 1.0;
    let started = Instant::now();
    for i in 1..=steps {
        z = advance(&z)?;
        worst = worst.max((system.hamiltonian(&z)? - h0).abs());
        let t = i as f64 * h;
        if t >= next_sample {
            record.push((t, worst));
            next_sample *= 10f64.powf(0.25);
        }
    }
    Ok((started.elapsed().as_secs_f64(), record))
}

fn long_run() -> Result<(), Box<dyn std::error::Error>> {
    let system = PaisUhlenbeck {
        w1: 1.0,
        w2: 2f64.sqrt(),
        eps: -0.05,
    };
    let z0 = system.legendre(&SVector::from_column_slice(&[
        0.3, 0.0, 0.0, 0.25, -0.1, 0.05, 0.0, 0.1,
    ]));
    let t_end = 1e5;
    let options = StepOptions::default();
    println!("\nPais-Uhlenbeck, T = 1e5: energy error at matched cost");
    println!(
        "| method | step size / tol | steps | wall time | max abs(H - H0) at T = 1e3 | at T = 1e5 |"
    );
    println!("|---|---|---|---|---|---|");
    let mut curves = Vec::new();
    let mut report =
        |name: &str, detail: String, steps: usize, time: f64, record: Vec<(f64, f64)>| {
            let at = |t: f64| {
                record
                    .iter()
                    .rfind(|p| p.0 <= t * 1.001)
                    .map_or(0.0, |p| p.1)
            };
            println!(
                "| {name} | {detail} | {steps} | {time:.2} s | {:.2e} | {:.2e} |",
                at(1e3),
                at(1e5)
            );
            curves.push(plot::Curve::new(name, record));
        };
    let mut stepper = ReducedStepper::new(&system);
    let h = 0.1;
    let steps = (t_end / h) as usize;
    let (midpoint_time, record) = energy_record(&system, &z0, h, steps, |z| {
        Ok(stepper.step(z, h, &options)?.0)
    })?;
    report("midpoint", format!("h = {h}"), steps, midpoint_time, record);
    let h4 = 3.0 * h;
    let n4 = (t_end / h4) as usize;
    let (time, record) = energy_record(&system, &z0, h4, n4, |z| {
        Ok(compose(|z, s| stepper.step(z, s, &options), z, h4, 4)?.0)
    })?;
    report(
        "composition, order 4",
        format!("h = {h4:.1}"),
        n4,
        time,
        record,
    );
    // RK4: a step costs less than an implicit one; use the step count that costs the same
    let (rk_probe, _) = energy_record(&system, &z0, h, 20_000, |z| rk4_step(&system, z, h))?;
    let rk_steps = (steps as f64 * midpoint_time / (rk_probe * 50.0)).min(1e7) as usize;
    let h_rk = t_end / rk_steps as f64;
    let (time, record) =
        energy_record(&system, &z0, h_rk, rk_steps, |z| rk4_step(&system, z, h_rk))?;
    report("RK4", format!("h = {h_rk:.3}"), rk_steps, time, record);
    // DOP853: the tolerance whose run costs about as much as the midpoint run
    let mut best: Option<(f64, f64)> = None;
    for tol in [1e-6, 1e-8, 1e-10, 1e-12] {
        let (time, _) = timed(0, || {
            dop853(&system, &z0, t_end, tol, t_end)
                .map(|_| ())
                .map_err(|e| e.to_string())
        });
        if best.is_none_or(|(_, t)| {
            (time.ln() - midpoint_time.ln()).abs() < (t.ln() - midpoint_time.ln()).abs()
        }) {
            best = Some((tol, time));
        }
    }
    if let Some((tol, _)) = best {
        let started = Instant::now();
        let (states, steps) = dop853(&system, &z0, t_end, tol, t_end)?;
        let time = started.elapsed().as_secs_f64();
        let h0 = system.hamiltonian(&z0)?;
        let mut worst: f64 = 1e-17;
        let mut record = Vec::new();
        let mut next_sample = 1.0;
        for (t, z) in &states {
            worst = worst.max((system.hamiltonian(z)? - h0).abs());
            if *t >= next_sample {
                record.push((*t, worst));
                next_sample *= 10f64.powf(0.25);
            }
        }
        report(
            "DOP853 (adaptive)",
            format!("tol {tol:.0e}"),
            steps as usize,
            time,
            record,
        );
    }
    let figure = common::docs_path("energy_long_run.svg");
    plot::panels(
        &figure,
        "Pais-Uhlenbeck: max |H - H(0)| up to time t, matched cost",
        "t",
        &[("max energy error", curves)],
        Scale::Log,
    )?;
    println!("\nfigure: {}", figure.display());
    Ok(())
}

fn main() {
    if let Err(e) = obstacle_ivp().and_then(|()| long_run()) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
