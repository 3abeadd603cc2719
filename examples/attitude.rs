//! Attitude on SO(3) (`retract::so3`).
//!
//! 1. A 170-degree rest-to-rest slew about the world y axis in 10 s with minimum torque,
//!    L = 1/2 |J Omega' + Omega x J Omega|^2 written in body coordinates (`so3`), free and
//!    with a sun keep-out cone on the boresight (a hard constraint, the sun in world axes),
//!    planned by the optimizer in the Gibbs chart centred halfway; the boresight's paths and the torque are drawn to `docs/attitude.svg` and
//!    `docs/attitude_torque.svg`.
//! 2. The same slew in Z-Y-X Euler angles, whose pitch passes 90 degrees, where the rates no
//!    longer determine the rotation's velocity (gimbal lock).
//! 3. The free rigid body through the same singularity: the Cayley and the exponential
//!    midpoint maps in moving charts against the midpoint rule in Euler angles, and long runs
//!    of the former.
//! 4. A fully actuated rigid body in SE(3), written in body coordinates (`se3`) and planned in
//!    the product chart at the identity, flying among spheres while it turns, each sphere a
//!    hard constraint; and a free body whose centre of mass is off the pose's origin, stepped
//!    in moving SE(3) charts by the Cayley-midpoint and the exponential maps.
//!
//! Run: `cargo run --release --example attitude [-- boresight.svg torque.svg]`

#[path = "common/attitude.rs"]
mod attitude;
mod common;

use std::time::Instant;

use attitude::{
    BORESIGHT, CONE_DEGREES, ClearOfSphere, EulerSunClearance, INERTIA, SLEW_DEGREES, SLEW_TIME,
    SPHERES, euler_body, euler_reference, gibbs_problem, gibbs_slew, slew_body, slew_cone, sun,
};
use retract::bvp::{OptimalControlProblem, Plan, PlanGuess, PlanOptions};
use retract::map::{self, DiscretizationMap, TaylorLift};
use retract::nalgebra::{Isometry3, Matrix3, SVector, UnitQuaternion, Vector3};
use retract::plot::{self, Curve, Scale};
use retract::se3::{self, Se3ExpMidpoint1, Se3Midpoint1};
use retract::so3::{
    CayleyMidpoint, CayleyMidpoint1, ExpMidpoint, ExpMidpoint1, chart_quaternion, orientation,
    recentre, world_momentum,
};
use retract::{LiftedSystem, NewtonOptions, StepOptions};

/// J Omega' + Omega x J Omega: the torque of body velocity `omega` and acceleration `domega`.
fn torque(omega: &Vector3<f64>, domega: &Vector3<f64>) -> Vector3<f64> {
    let j = Vector3::from(INERTIA);
    domega.component_mul(&j) + omega.cross(&omega.component_mul(&j))
}

/// A chart of the slew: the rotation, Omega and Omega' of a jet (q, q', q'').
trait SlewChart {
    fn rotation(&self, q: &Vector3<f64>) -> UnitQuaternion<f64>;
    fn rates(&self, q: &Vector3<f64>, dq: &Vector3<f64>, ddq: &Vector3<f64>) -> [Vector3<f64>; 2];
}

/// The Gibbs chart centred at the quaternion.
struct Gibbs(UnitQuaternion<f64>);

impl SlewChart for Gibbs {
    fn rotation(&self, y: &Vector3<f64>) -> UnitQuaternion<f64> {
        self.0 * chart_quaternion(y)
    }
    /// Omega = s (y' - y x y'), Omega' = s (y'' - y x y'') - s^2 (y . y') (y' - y x y').
    fn rates(&self, y: &Vector3<f64>, dy: &Vector3<f64>, ddy: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let s = 2.0 / (1.0 + y.norm_squared());
        let v = dy - y.cross(dy);
        [v * s, (ddy - y.cross(ddy)) * s - v * (s * s * y.dot(dy))]
    }
}

/// Z-Y-X Euler angles (yaw, pitch, roll).
struct Euler;

impl SlewChart for Euler {
    fn rotation(&self, q: &Vector3<f64>) -> UnitQuaternion<f64> {
        UnitQuaternion::from_euler_angles(q[2], q[1], q[0])
    }
    /// The rates of `attitude::euler_torque`.
    fn rates(&self, q: &Vector3<f64>, dq: &Vector3<f64>, ddq: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let (sp, cp, sr, cr) = (q[1].sin(), q[1].cos(), q[2].sin(), q[2].cos());
        let (yaw, pitch, roll) = (dq[0], dq[1], dq[2]);
        let omega = Vector3::new(
            roll - yaw * sp,
            pitch * cr + yaw * sr * cp,
            -pitch * sr + yaw * cr * cp,
        );
        let domega = Vector3::new(
            ddq[2] - ddq[0] * sp - yaw * pitch * cp,
            ddq[1] * cr - pitch * roll * sr + ddq[0] * sr * cp + yaw * roll * cr * cp
                - yaw * pitch * sr * sp,
            -ddq[1] * sr - pitch * roll * cr + ddq[0] * cr * cp
                - yaw * roll * sr * cp
                - yaw * pitch * cr * sp,
        );
        [omega, domega]
    }
}

/// A solved slew: the boresight's path and the torque's norm at the steps' midpoints.
struct Slew {
    boresight: Vec<[f64; 3]>,
    torque: Vec<(f64, f64)>,
}

/// Prints the slew's table row and returns its paths.
fn report(name: &str, chart: &impl SlewChart, plan: &Plan<3, 6>, ms: f64) -> Slew {
    let mut slew = Slew {
        boresight: Vec::new(),
        torque: Vec::new(),
    };
    let mut closest = f64::INFINITY;
    for i in 0..plan.u.len() {
        let x = (plan.x[i] + plan.x[i + 1]) / 2.0;
        let (q, dq) = (
            x.fixed_rows::<3>(0).into_owned(),
            x.fixed_rows::<3>(3).into_owned(),
        );
        let b = chart.rotation(&q) * Vector3::from(BORESIGHT);
        closest = closest.min(b.dot(&sun()).clamp(-1.0, 1.0).acos().to_degrees());
        let [omega, domega] = chart.rates(&q, &dq, &plan.u[i]);
        slew.boresight.push(b.into());
        slew.torque
            .push(((i as f64 + 0.5) * plan.h, torque(&omega, &domega).norm()));
    }
    let peak = slew.torque.iter().map(|t| t.1).fold(0.0, f64::max);
    println!(
        "| {name} | {:.6} | {} | {ms:.1} | {:.2e} | {closest:.3} | {peak:.4} |",
        plan.cost, plan.iterations, plan.certificate.min_reduced_hessian_eig
    );
    slew
}

/// The slews in both charts, free and around the sun cone, as a table; the Gibbs ones' paths.
fn slews(steps: usize) -> Result<Vec<(String, Slew)>, Box<dyn std::error::Error>> {
    println!(
        "## slew by {SLEW_DEGREES} deg in {SLEW_TIME} s, N = {steps}, sun cone {CONE_DEGREES} deg\n"
    );
    println!(
        "| chart, slew | J | iterations | ms | min reduced Hessian eigenvalue | closest to the sun (deg) | peak abs(tau) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let (centre, start, goal) = gibbs_slew();
    let (system, cone) = (slew_body(&centre), slew_cone(&centre));
    let mut drawn = Vec::new();
    for (name, with_cone) in [("free", false), ("sun cone", true)] {
        let mut problem = gibbs_problem(&system, &start, &goal, steps);
        if with_cone {
            problem = problem.with_inequality(&cone);
        }
        let clock = Instant::now();
        let plan = problem.solve(PlanGuess::Spline)?;
        let ms = clock.elapsed().as_secs_f64() * 1e3;
        let slew = report(&format!("Gibbs, {name}"), &Gibbs(centre), &plan, ms);
        drawn.push((format!("{name}: J = {:.4}", plan.cost), slew));
    }
    let euler = euler_body();
    let goal = [0.0, SLEW_DEGREES.to_radians(), 0.0, 0.0, 0.0, 0.0];
    let cone = EulerSunClearance::new(sun().into(), CONE_DEGREES.to_radians().cos());
    for (name, with_cone) in [("free", false), ("sun cone", true)] {
        let mut problem = OptimalControlProblem::new(&euler, &[0.0; 6], &goal, SLEW_TIME, steps)
            .with_options(PlanOptions::default().with_min_eigenvalue(true));
        if with_cone {
            problem = problem.with_inequality(&cone);
        }
        let clock = Instant::now();
        match problem.solve(PlanGuess::Spline) {
            Ok(plan) => {
                let ms = clock.elapsed().as_secs_f64() * 1e3;
                report(&format!("Euler, {name}"), &Euler, &plan, ms);
            }
            Err(e) => {
                let last = e.last.as_deref().map_or(String::new(), |plan| {
                    format!(
                        " after {} iterations (J = {:.6}, stationarity {:.1e})",
                        plan.iterations, plan.cost, plan.certificate.stationarity
                    )
                });
                println!("| Euler, {name} | failed: {}{last} | | | | | |", e.failure);
            }
        }
    }
    Ok(drawn)
}

/// The tumbling body's initial body velocity: mostly about the body y axis, so that from the
/// identity the pitch passes 90 degrees.
const TUMBLE: [f64; 3] = [0.1, 1.0, 0.05];

/// The Cayley midpoint map `map` in moving charts from the identity with body velocity [`TUMBLE`]:
/// `steps` steps of `h`. Returns the rotation at the end, the largest |R^T R - I| and
/// relative change of the spatial momentum over the run, and the time per step in us.
fn moving_charts(
    map: &impl DiscretizationMap<3, 1>,
    h: f64,
    steps: usize,
) -> Result<(UnitQuaternion<f64>, f64, f64, f64), retract::Error> {
    let (system, options) = (attitude::gibbs_free_body(), NewtonOptions::default());
    let jet = SVector::<f64, 6>::from_column_slice(&[
        0.0,
        0.0,
        0.0,
        TUMBLE[0] / 2.0,
        TUMBLE[1] / 2.0,
        TUMBLE[2] / 2.0,
    ]);
    let (mut centre, mut z) = (UnitQuaternion::identity(), system.legendre(&jet));
    let m0 = world_momentum::<1, 6>(&centre, &z);
    let (mut orthogonality, mut drift): (f64, f64) = (0.0, 0.0);
    let clock = Instant::now();
    for _ in 0..steps {
        z = map::step(&system, map, &z, h, &options)?.0;
        recentre::<1, 6>(&mut centre, &mut z)?;
        let r = orientation::<1, 6>(&centre, &z)
            .to_rotation_matrix()
            .into_inner();
        orthogonality = orthogonality.max((r.transpose() * r - Matrix3::identity()).amax());
        drift = drift.max((world_momentum::<1, 6>(&centre, &z) - m0).amax() / m0.amax());
    }
    let us = clock.elapsed().as_secs_f64() * 1e6 / steps as f64;
    Ok((orientation::<1, 6>(&centre, &z), orthogonality, drift, us))
}

/// The midpoint rule in Z-Y-X Euler angles from the identity with body velocity [`TUMBLE`]:
/// the rotation after `steps` steps of `h`, or the error and the time and pitch (degrees) of
/// the failing step.
fn euler_midpoint(h: f64, steps: usize) -> Result<UnitQuaternion<f64>, (retract::Error, f64, f64)> {
    let system = attitude::EulerFree {
        j1: INERTIA[0],
        j2: INERTIA[1],
        j3: INERTIA[2],
    };
    // at the identity the rates (yaw', pitch', roll') are (Omega_z, Omega_y, Omega_x)
    let jet =
        SVector::<f64, 6>::from_column_slice(&[0.0, 0.0, 0.0, TUMBLE[2], TUMBLE[1], TUMBLE[0]]);
    let mut z = system.legendre(&jet);
    for i in 0..steps {
        z = retract::step(&system, &z, h, &StepOptions::default())
            .map_err(|e| (e, i as f64 * h, z[1].to_degrees()))?
            .0;
    }
    Ok(UnitQuaternion::from_euler_angles(z[2], z[1], z[0]))
}

/// The tumbling body to T = 10 s against RK4, and a long run with moving charts.
fn tumbling(long_steps: usize) -> Result<(), Box<dyn std::error::Error>> {
    let (t, steps) = (10.0, 1000);
    let h = t / steps as f64;
    let exact = euler_reference(Vector3::from(TUMBLE), t, 100_000);
    println!("\n## the free body tumbling through pitch = 90 deg, T = {t} s, h = {h}\n");
    println!(
        "| method | rotation error at T (rad) | max abs(R^T R - I) | momentum drift | us/step |"
    );
    println!("|---|---|---|---|---|");
    let runs = [
        (
            "Cayley",
            "generated",
            moving_charts(&CayleyMidpoint1, h, steps)?,
        ),
        (
            "Cayley",
            "run-time Taylor lift",
            moving_charts(&TaylorLift(CayleyMidpoint), h, steps)?,
        ),
        (
            "exponential",
            "generated",
            moving_charts(&ExpMidpoint1, h, steps)?,
        ),
        (
            "exponential",
            "run-time Taylor lift",
            moving_charts(&TaylorLift(ExpMidpoint), h, steps)?,
        ),
    ];
    for (map, name, (end, orthogonality, drift, us)) in runs {
        println!(
            "| {map} midpoint ({name}), moving Gibbs charts | {:.2e} | {orthogonality:.1e} | {drift:.1e} | {us:.2} |",
            end.angle_to(&exact)
        );
    }
    match euler_midpoint(h, steps) {
        Ok(end) => println!(
            "| midpoint rule, Euler angles | {:.2e} | - | - | - |",
            end.angle_to(&exact)
        ),
        Err((e, at, pitch)) => println!(
            "| midpoint rule, Euler angles | failed at t = {at:.2} s (pitch {pitch:.2} deg): {e} | - | - | - |"
        ),
    }
    println!();
    for (name, run) in [
        ("Cayley", moving_charts(&CayleyMidpoint1, h, long_steps)?),
        ("exponential", moving_charts(&ExpMidpoint1, h, long_steps)?),
    ] {
        let (_, orthogonality, drift, us) = run;
        println!(
            "{name} midpoint, moving charts, {long_steps} steps of {h} s: max abs(R^T R - I) = \
             {orthogonality:.1e}, spatial momentum drift {drift:.1e} (relative), {us:.2} us/step"
        );
    }
    println!(
        "\nSE(3), the free body with its centre of mass off the pose's origin, moving product \
         charts, T = {t} s, h = {h}:\n"
    );
    println!(
        "| map | rotation error (rad) | centre of mass error | max abs(R^T R - I) | momentum drift | us/step |"
    );
    println!("|---|---|---|---|---|---|");
    // the product map over as many steps as the SO(3) run, the exponential one over a tenth
    let long = long_steps / 10;
    for (name, run, (long, long_run)) in [
        (
            "Se3Midpoint1 (Cayley x midpoint)",
            se3_moving_charts(&Se3Midpoint1, h, steps)?,
            (long_steps, se3_moving_charts(&Se3Midpoint1, h, long_steps)?),
        ),
        (
            "Se3ExpMidpoint1 (exponential)",
            se3_moving_charts(&Se3ExpMidpoint1, h, steps)?,
            (long, se3_moving_charts(&Se3ExpMidpoint1, h, long)?),
        ),
    ] {
        let [rotation, mass_centre, orthogonality, drift, us] = run;
        println!(
            "| {name}, {steps} steps | {rotation:.2e} | {mass_centre:.2e} | {orthogonality:.1e} | {drift:.1e} | {us:.2} |"
        );
        let [_, mass_centre, orthogonality, drift, us] = long_run;
        println!(
            "| {name}, {long} steps | - | {mass_centre:.2e} | {orthogonality:.1e} | {drift:.1e} | {us:.2} |"
        );
    }
    Ok(())
}

/// The free body with an offset centre of mass ([`attitude::offset_body`]) in moving SE(3)
/// charts from the identity with body velocity ([`TUMBLE`], `v`), `steps` steps of `h` with
/// the generated `map`: the errors of the rotation (rad) and of the centre of
/// mass at the end against the exact motion (Euler's equations by RK4; a straight line), the
/// largest |R^T R - I| and relative change of the spatial momentum, and the time per step in
/// us.
fn se3_moving_charts(
    map: &impl DiscretizationMap<6, 1>,
    h: f64,
    steps: usize,
) -> Result<[f64; 5], retract::Error> {
    let (omega, v) = (Vector3::from(TUMBLE), Vector3::new(0.5, -0.2, 0.3));
    let (mut system, mut centre) = (attitude::offset_body(), Isometry3::identity());
    let mut jet = SVector::<f64, 12>::zeros();
    for i in 0..3 {
        (jet[6 + i], jet[9 + i]) = (omega[i] / 2.0, v[i]);
    }
    let (mut z, options) = (system.legendre(&jet), NewtonOptions::default());
    let (l0, p0) = se3::spatial_momentum::<1, 12>(&centre, &z);
    let (mut orthogonality, mut drift): (f64, f64) = (0.0, 0.0);
    let clock = Instant::now();
    for _ in 0..steps {
        z = map::step(&system, map, &z, h, &options)?.0;
        se3::recentre_system::<_, 1, 12>(&mut system, &mut centre, &mut z)?;
        let r = centre.rotation.to_rotation_matrix().into_inner();
        orthogonality = orthogonality.max((r.transpose() * r - Matrix3::identity()).amax());
        let (l, p) = se3::spatial_momentum::<1, 12>(&centre, &z);
        drift = drift.max(((l - l0).amax() / l0.amax()).max((p - p0).amax() / p0.amax()));
    }
    let us = clock.elapsed().as_secs_f64() * 1e6 / steps as f64;
    let t = h * steps as f64;
    let offset = Vector3::from(attitude::OFFSET);
    let end = se3::pose::<1, 12>(&centre, &z);
    let mass_centre = end.translation.vector + end.rotation * offset;
    let exact_centre = offset + (v + omega.cross(&offset)) * t;
    let rotation_error = if steps <= 10_000 {
        end.rotation.angle_to(&euler_reference(omega, t, 100_000))
    } else {
        f64::NAN
    };
    Ok([
        rotation_error,
        (mass_centre - exact_centre).norm(),
        orthogonality,
        drift,
        us,
    ])
}

/// The smallest clearance |p - c| - r from the spheres at the steps' evaluation points
/// (midpoints, where the constraints are imposed) and along the chords (20 points per step).
fn sphere_clearance(plan: &Plan<6, 12>) -> (f64, f64) {
    let clearance = |x: &SVector<f64, 12>| {
        let p = Vector3::new(x[3], x[4], x[5]);
        SPHERES
            .iter()
            .map(|&(centre, radius)| (p - Vector3::from(centre)).norm() - radius)
            .fold(f64::INFINITY, f64::min)
    };
    let (mut at_midpoints, mut along) = (f64::INFINITY, f64::INFINITY);
    for w in plan.x.windows(2) {
        at_midpoints = at_midpoints.min(clearance(&((w[0] + w[1]) / 2.0)));
        for k in 0..=20 {
            let s = f64::from(k) / 20.0;
            along = along.min(clearance(&(w[0] * (1.0 - s) + w[1] * s)));
        }
    }
    (at_midpoints, along)
}

/// The SE(3) flight among the spheres, free and constrained.
fn flight(steps: usize) -> Result<(), Box<dyn std::error::Error>> {
    let system = attitude::flight_body();
    let (start, goal, time) = attitude::se3_flight();
    let spheres: Vec<ClearOfSphere> = SPHERES
        .iter()
        .map(|&(c, r)| ClearOfSphere::new(c, r))
        .collect();
    println!(
        "\n## SE(3): turning by 120 deg while flying 4.5 among {} spheres, T = {time} s, N = {steps}\n",
        SPHERES.len()
    );
    println!(
        "| flight | J | iterations | ms | min reduced Hessian eigenvalue | least clearance at the midpoints | along the chords |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, avoid) in [("free", false), ("among spheres", true)] {
        let mut problem = OptimalControlProblem::new(&system, &start, &goal, time, steps)
            .with_options(PlanOptions::default().with_min_eigenvalue(true));
        if avoid {
            for sphere in &spheres {
                problem = problem.with_inequality(sphere);
            }
        }
        let clock = Instant::now();
        let plan = problem.solve(PlanGuess::Spline)?;
        let ms = clock.elapsed().as_secs_f64() * 1e3;
        let (at_midpoints, along) = sphere_clearance(&plan);
        println!(
            "| {name} | {:.6} | {} | {ms:.1} | {:.2e} | {at_midpoints:.1e} | {along:.1e} |",
            plan.cost, plan.iterations, plan.certificate.min_reduced_hessian_eig,
        );
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let drawn = slews(200)?;
    slews(400)?;
    let mut args = std::env::args().skip(1).map(std::path::PathBuf::from);
    let boresight_path = args
        .next()
        .unwrap_or_else(|| common::docs_path("attitude.svg"));
    let torque_path = args
        .next()
        .unwrap_or_else(|| common::docs_path("attitude_torque.svg"));
    let paths: Vec<(String, Vec<[f64; 3]>)> = drawn
        .iter()
        .map(|(label, slew)| (label.clone(), slew.boresight.clone()))
        .collect();
    plot::sphere(
        &boresight_path,
        "Boresight of a 170-degree minimum-torque slew: free and around a 20-degree sun cone",
        [1.0, -1.2, 0.6],
        &paths,
        &[(sun().into(), CONE_DEGREES.to_radians())],
    )?;
    let torques: Vec<Curve> = drawn
        .iter()
        .map(|(label, slew)| Curve::new(label.clone(), slew.torque.clone()))
        .collect();
    plot::panels(
        &torque_path,
        "Torque of the slews",
        "t (s)",
        &[("abs(tau)", torques)],
        Scale::Linear,
    )?;
    println!(
        "\nfigures: {}, {}",
        boresight_path.display(),
        torque_path.display()
    );
    flight(120)?;
    tumbling(1_000_000)
}
