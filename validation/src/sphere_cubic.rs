//! Speed against error on $S^2$: the Riemannian cubic ($L = \frac12 |D_t q'|^2$) between
//! given points and velocities, built three ways and measured against the exact cubic.
//!
//! - `retract`: the boundary-value problem solved by the optimizer in the gnomonic chart
//!   centred between the two points (`#[higher_order_lagrangian(order = 2, sphere)]`, the
//!   midpoint scheme, $N$ steps, error $O(h^2)$); between the nodes the plan's cubic Hermite
//!   interpolant ([`Plan::evaluate`]).
//! - `retract-extrapolated`: Richardson extrapolation of the plans with $N$, $2N$ and $4N$
//!   steps (`solve_extrapolated`, error $O(h^6)$ at the nodes); between the nodes the cubic
//!   Hermite interpolant of the extrapolated jets, $O(h^4)$.
//! - `decasteljau`: the geodesic Bézier curve of the control points $p_0$,
//!   $p_1 = \exp_{p_0}(v_0 T/3)$, $p_2 = \exp_{p_3}(-v_3 T/3)$, $p_3$, evaluated at $N + 1$
//!   times by the de Casteljau algorithm with great-circle interpolation (slerp). Its end
//!   velocities are $3 \log_{p_0}(p_1) / T = v_0$ and $-3 \log_{p_3}(p_2) / T = v_3$ exactly
//!   (Popiel and Noakes, 2007), so the adjustment of the control points that matches the end
//!   velocities is the identity on the sphere (its quasi-geodesics are geodesics). It is a
//!   different curve from the cubic: its error does not go to zero with $N$.
//!
//! The exact cubic: the embedded Euler-Lagrange equation $D_t^3 V + R(D_t V, V) V = 0$ as the
//! first-order system in $(q, V, A, J)$ of `examples/common/sphere_cubic.rs`, integrated by
//! classical RK4, shot from $(p_0, v_0)$ by Newton on the unknown $(A, J)(0)$ (four tangent
//! components) until $q(T) = p_3$ and $V(T) = v_3$ to $10^{-13}$.
//!
//! Error: the largest geodesic distance $\arccos(q \cdot q_\mathrm{exact})$ over
//! [`SAMPLES`]$\,+ 1$ equally spaced times of $[0, T]$. Time: the wall time that builds the
//! curve at the resolution (the solves for `retract`, the control points and the $N + 1$
//! evaluations for `decasteljau`), best of interleaved rounds ([`crate::timing`]).

use std::hint::black_box;
use std::io::Write;

use retract::bvp::{OptimalControlProblem, Plan, PlanGuess, PlanOptions};
use retract::nalgebra::{Matrix4, Vector2, Vector3, Vector4};
use retract::sphere::{Chart, SphereSystem};

use crate::Error;
use crate::timing::{Timed, interleaved, write_head};

/// The Riemannian cubic's Lagrangian and the embedded equation (shared with `retract`'s
/// sphere example and tests).
#[path = "../../examples/common/sphere_cubic.rs"]
mod model;

pub use model::Data;

/// The equally spaced times (intervals of $[0, T]$) at which errors are measured; a multiple
/// of every resolution of [`RESOLUTIONS`].
pub const SAMPLES: usize = 512;

/// The resolutions $N$ of the report.
pub const RESOLUTIONS: [usize; 6] = [8, 16, 32, 64, 128, 256];

/// RK4 steps per sample interval of the exact cubic (4096 steps over $[0, T]$).
pub const SUBSTEPS: usize = 8;

/// The names of the timed closures, per resolution of [`RESOLUTIONS`].
const NAMES: [[&str; 3]; 6] = [
    ["retract/8", "extrapolated/8", "decasteljau/8"],
    ["retract/16", "extrapolated/16", "decasteljau/16"],
    ["retract/32", "extrapolated/32", "decasteljau/32"],
    ["retract/64", "extrapolated/64", "decasteljau/64"],
    ["retract/128", "extrapolated/128", "decasteljau/128"],
    ["retract/256", "extrapolated/256", "decasteljau/256"],
];

/// The KKT tolerances of the optimizer's solves: order 2 (the default; a tighter one moves
/// its error by a relative 1e-8 and takes a fourth iteration), extrapolated (below the
/// extrapolation's node errors).
pub const TOLERANCE: [f64; 2] = [1e-9, 1e-11];

/// Boundary data of a cubic: $q(0) = p_0$, $q'(0) = v_0$, $q(T) = p_3$, $q'(T) = v_3$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// The start point (a unit vector).
    pub p0: Vector3<f64>,
    /// The start velocity (tangent at `p0`).
    pub v0: Vector3<f64>,
    /// The end point (a unit vector).
    pub p3: Vector3<f64>,
    /// The end velocity (tangent at `p3`).
    pub v3: Vector3<f64>,
    /// The duration $T$.
    pub t_end: f64,
}

impl Boundary {
    /// The data of the report, without symmetry: from $(1, 0, 0)$ with velocity
    /// $(0, 1, 0.5)$ to $(0, 0.6, 0.8)$, 90 degrees away, with velocity
    /// $(-1.2, 0.3, -0.225)$, $T = 1$.
    pub fn report() -> Self {
        Self {
            p0: Vector3::new(1.0, 0.0, 0.0),
            v0: Vector3::new(0.0, 1.0, 0.5),
            p3: Vector3::new(0.0, 0.6, 0.8),
            v3: Vector3::new(-1.2, 0.3, -0.225),
            t_end: 1.0,
        }
    }
}

/// The geodesic distance $\operatorname{atan2}(|a \times b|, a \cdot b)$ of two unit vectors.
pub fn distance(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// The exponential map $\exp_p(v) = \cos|v|\, p + \sin|v|\, v / |v|$ of the unit sphere.
pub fn exp(p: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let angle = v.norm();
    if angle < 1e-300 {
        return *p;
    }
    p * angle.cos() + v * (angle.sin() / angle)
}

/// The great-circle interpolation
/// $\mathrm{slerp}(a, b, s) = (\sin((1 - s)\theta)\, a + \sin(s \theta)\, b) / \sin\theta$,
/// $\theta$ the angle of the unit vectors $a$, $b$ (the normalised chord for $\theta$ below
/// $10^{-8}$); any real $s$.
pub fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, s: f64) -> Vector3<f64> {
    let theta = distance(a, b);
    if theta < 1e-8 {
        return (a * (1.0 - s) + b * s).normalize();
    }
    (a * ((1.0 - s) * theta).sin() + b * (s * theta).sin()) / theta.sin()
}

/// The geodesic Bézier curve of four control points on the unit sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bezier {
    /// $p_0, p_1, p_2, p_3$.
    pub points: [Vector3<f64>; 4],
    /// The duration $T$ (the curve is $\beta(t / T)$).
    pub t_end: f64,
}

impl Bezier {
    /// The control points of `boundary`: $p_1 = \exp_{p_0}(v_0 T / 3)$,
    /// $p_2 = \exp_{p_3}(-v_3 T / 3)$.
    pub fn new(boundary: &Boundary) -> Self {
        let b = boundary;
        Self {
            points: [
                b.p0,
                exp(&b.p0, &(b.v0 * (b.t_end / 3.0))),
                exp(&b.p3, &(b.v3 * (-b.t_end / 3.0))),
                b.p3,
            ],
            t_end: b.t_end,
        }
    }

    /// The point at time $t$ by de Casteljau: three levels of [`slerp`] at $s = t / T$.
    pub fn at(&self, t: f64) -> Vector3<f64> {
        let s = t / self.t_end;
        let [a, b, c, d] = &self.points;
        let (ab, bc, cd) = (slerp(a, b, s), slerp(b, c, s), slerp(c, d, s));
        slerp(&slerp(&ab, &bc, s), &slerp(&bc, &cd, s), s)
    }

    /// The curve at the $n + 1$ times $t_i = i T / n$, into `points` (cleared first).
    pub fn sample_into(&self, n: usize, points: &mut Vec<Vector3<f64>>) {
        points.clear();
        points.extend((0..=n).map(|i| self.at(i as f64 * self.t_end / n as f64)));
    }
}

/// The data at the `intervals + 1` times $t_k = k T / \text{intervals}$ of the cubic from
/// `start`, by RK4 with `substeps` steps per interval.
pub fn trajectory(start: Data, t_end: f64, intervals: usize, substeps: usize) -> Vec<Data> {
    let dt = t_end / intervals as f64;
    let mut y = start;
    let mut samples = vec![y];
    for _ in 0..intervals {
        y = model::reference(y, dt, substeps);
        samples.push(y);
    }
    samples
}

/// An orthonormal basis of the tangent plane at the unit vector `p`, its first vector along
/// the tangent part of `along` (which must not be parallel to `p`).
fn tangent_basis(p: &Vector3<f64>, along: &Vector3<f64>) -> [Vector3<f64>; 2] {
    let e1 = (along - p * p.dot(along)).normalize();
    [e1, p.cross(&e1)]
}

/// The shooting problem: unknowns $(A, J)(0)$ in a tangent basis at $p_0$, residual
/// $(q(T) - p_3, V(T) - v_3)$ in a tangent basis at $p_3$.
struct Shooting<'a> {
    boundary: &'a Boundary,
    at_start: [Vector3<f64>; 2],
    at_end: [Vector3<f64>; 2],
    steps: usize,
}

impl Shooting<'_> {
    /// The initial data of the unknowns `u`.
    fn start(&self, u: &Vector4<f64>) -> Data {
        let [e1, e2] = self.at_start;
        let b = self.boundary;
        [b.p0, b.v0, e1 * u[0] + e2 * u[1], e1 * u[2] + e2 * u[3]]
    }

    /// The residual at `u`.
    fn residual(&self, u: &Vector4<f64>) -> Vector4<f64> {
        let b = self.boundary;
        let [q, v, _, _] = model::reference(self.start(u), b.t_end, self.steps);
        let [f1, f2] = self.at_end;
        let (dq, dv) = (q - b.p3, v - b.v3);
        Vector4::new(dq.dot(&f1), dq.dot(&f2), dv.dot(&f1), dv.dot(&f2))
    }
}

/// The initial data $(p_0, v_0, A(0), J(0))$ of the cubic with the boundary data, by Newton
/// shooting with RK4 of `steps` steps (Jacobian by central differences). The first guess is
/// the Euclidean cubic in the tangent plane at $p_0$ towards $\log_{p_0}(p_3)$ with $v_3$
/// projected there.
///
/// # Errors
/// [`Error::Reference`] if the residual does not fall below $10^{-13}$ in 30 iterations.
pub fn exact_start(boundary: &Boundary, steps: usize) -> Result<Data, Error> {
    let b = boundary;
    let shooting = Shooting {
        boundary: b,
        at_start: tangent_basis(&b.p0, &b.v0),
        at_end: tangent_basis(&b.p3, &b.v3),
        steps,
    };
    let chord = b.p3 - b.p0 * b.p0.dot(&b.p3);
    let log = chord.normalize() * distance(&b.p0, &b.p3);
    let v3 = b.v3 - b.p0 * b.p0.dot(&b.v3);
    let t = b.t_end;
    let a0 = (log * 6.0 - b.v0 * (4.0 * t) - v3 * (2.0 * t)) / (t * t);
    let j0 = ((b.v0 + v3) * (6.0 * t) - log * 12.0) / (t * t * t);
    let [e1, e2] = shooting.at_start;
    let mut u = Vector4::new(a0.dot(&e1), a0.dot(&e2), j0.dot(&e1), j0.dot(&e2));
    let mut r = shooting.residual(&u);
    for _ in 0..30 {
        if r.amax() < 1e-13 {
            return Ok(shooting.start(&u));
        }
        let delta = 1e-6;
        let jacobian = Matrix4::from_fn(|row, col| {
            let step = Vector4::ith(col, delta);
            (shooting.residual(&(u + step))[row] - shooting.residual(&(u - step))[row])
                / (2.0 * delta)
        });
        let correction = jacobian
            .lu()
            .solve(&r)
            .ok_or_else(|| Error::Reference("the shooting Jacobian is singular".into()))?;
        u -= correction;
        r = shooting.residual(&u);
    }
    Err(Error::Reference(format!(
        "the shooting did not converge: residual {:.1e}",
        r.amax()
    )))
}

/// The largest distance between `points` and the exact points (same times).
fn max_distance(points: &[Vector3<f64>], exact: &[Vector3<f64>]) -> f64 {
    points
        .iter()
        .zip(exact)
        .map(|(p, q)| distance(p, q))
        .fold(0.0, f64::max)
}

/// The optimizer's problem of `boundary` with `steps` steps, in the chart centred between
/// the two points: the chart, the system and the boundary jets $(y, y')$.
struct Charted {
    chart: Chart,
    system: model::Cubic,
    start: [f64; 4],
    goal: [f64; 4],
    t_end: f64,
}

impl Charted {
    fn new(boundary: &Boundary) -> Result<Self, Error> {
        let chart = Chart::at(&(boundary.p0 + boundary.p3))?;
        let jet = |q: Vector3<f64>, v: Vector3<f64>| -> Result<[f64; 4], Error> {
            let [y, dy] = chart.coordinates(&[q, v])?;
            Ok([y[0], y[1], dy[0], dy[1]])
        };
        Ok(Self {
            chart,
            system: model::Cubic::new().with_chart(chart.params()),
            start: jet(boundary.p0, boundary.v0)?,
            goal: jet(boundary.p3, boundary.v3)?,
            t_end: boundary.t_end,
        })
    }

    /// The problem with `steps` steps and the KKT tolerance `tolerance`.
    fn problem(
        &self,
        steps: usize,
        tolerance: f64,
    ) -> OptimalControlProblem<'_, model::Cubic, 2, 2, 4> {
        OptimalControlProblem::new(&self.system, &self.start, &self.goal, self.t_end, steps)
            .with_options(PlanOptions::default().with_tolerance(tolerance))
    }

    /// The plan's curve on the sphere at the `SAMPLES + 1` times $k T / $ `SAMPLES`.
    fn points(&self, plan: &Plan<2, 4>) -> Result<Vec<Vector3<f64>>, Error> {
        (0..=SAMPLES)
            .map(|k| {
                let x = plan.evaluate(k as f64 * self.t_end / SAMPLES as f64)?;
                Ok(self.chart.point(&Vector2::new(x[0], x[1])))
            })
            .collect()
    }
}

/// One method at one resolution: its error and its time.
#[derive(Clone, Debug)]
pub struct Point {
    /// The resolution $N$.
    pub steps: usize,
    /// The largest geodesic distance to the exact cubic.
    pub error: f64,
    /// The best time (ns) of building the curve.
    pub time_ns: f64,
}

/// The measurements of the report.
#[derive(Clone, Debug)]
pub struct SphereCubic {
    /// The residual of the exact cubic's boundary data, $\max(|q(T) - p_3|, |V(T) - v_3|)$.
    pub boundary_residual: f64,
    /// `retract`, order 2, per resolution.
    pub retract: Vec<Point>,
    /// `retract` extrapolated from $N$, $2N$, $4N$, per resolution.
    pub extrapolated: Vec<Point>,
    /// The error of the extrapolated plans at their coarse nodes only.
    pub extrapolated_nodes: Vec<f64>,
    /// de Casteljau, per resolution.
    pub decasteljau: Vec<Point>,
    /// The interleaved rounds.
    pub rounds: usize,
}

/// The errors of the three methods at `steps` (module docs).
fn errors(
    charted: &Charted,
    bezier: &Bezier,
    exact: &[Vector3<f64>],
    steps: usize,
) -> Result<[f64; 4], Error> {
    let failed = |e: retract::bvp::PlanError<2, 4>| Error::Plan(e.to_string());
    let plan = charted
        .problem(steps, TOLERANCE[0])
        .solve(PlanGuess::Spline)
        .map_err(failed)?;
    let retract = max_distance(&charted.points(&plan)?, exact);
    let e = charted
        .problem(steps, TOLERANCE[1])
        .solve_extrapolated(PlanGuess::Spline)
        .map_err(failed)?;
    let mut extrapolated = e.plans[0].clone();
    extrapolated.x.clone_from(&e.x);
    let on_curve = max_distance(&charted.points(&extrapolated)?, exact);
    let stride = SAMPLES / steps;
    let nodes =
        e.x.iter()
            .enumerate()
            .map(|(i, x)| {
                distance(
                    &charted.chart.point(&Vector2::new(x[0], x[1])),
                    &exact[i * stride],
                )
            })
            .fold(0.0, f64::max);
    let casteljau = (0..=SAMPLES)
        .map(|k| bezier.at(k as f64 * bezier.t_end / SAMPLES as f64))
        .zip(exact)
        .map(|(p, q)| distance(&p, q))
        .fold(0.0, f64::max);
    Ok([retract, on_curve, nodes, casteljau])
}

/// Measures every method at every resolution of `resolutions` (each a divisor of
/// [`SAMPLES`]), the times over `rounds` interleaved rounds.
///
/// # Errors
/// [`Error::Reference`] if the exact cubic cannot be computed, [`Error::Plan`] if a solve
/// fails, [`Error::Retract`] for data outside the chart.
pub fn measure(resolutions: &[usize], rounds: usize) -> Result<SphereCubic, Error> {
    let boundary = Boundary::report();
    let start = exact_start(&boundary, SAMPLES * SUBSTEPS)?;
    let samples = trajectory(start, boundary.t_end, SAMPLES, SUBSTEPS);
    let [q, v, _, _] = samples[SAMPLES];
    let boundary_residual = (q - boundary.p3).norm().max((v - boundary.v3).norm());
    let exact: Vec<Vector3<f64>> = samples.iter().map(|d| d[0]).collect();
    let charted = Charted::new(&boundary)?;
    let bezier = Bezier::new(&boundary);
    let mut result = SphereCubic {
        boundary_residual,
        retract: Vec::new(),
        extrapolated: Vec::new(),
        extrapolated_nodes: Vec::new(),
        decasteljau: Vec::new(),
        rounds,
    };
    for (i, &steps) in resolutions.iter().enumerate() {
        if !SAMPLES.is_multiple_of(steps) {
            return Err(Error::Reference(format!(
                "resolution {steps} does not divide {SAMPLES}"
            )));
        }
        let [retract, extrapolated, nodes, casteljau] = errors(&charted, &bezier, &exact, steps)?;
        let times = time(
            &charted,
            &boundary,
            steps,
            rounds,
            NAMES[i.min(NAMES.len() - 1)],
        );
        let point = |error, time_ns| Point {
            steps,
            error,
            time_ns,
        };
        result.retract.push(point(retract, times[0]));
        result.extrapolated.push(point(extrapolated, times[1]));
        result.extrapolated_nodes.push(nodes);
        result.decasteljau.push(point(casteljau, times[2]));
    }
    Ok(result)
}

/// The best times (ns) of the three methods at `steps` over `rounds` interleaved rounds.
fn time(
    charted: &Charted,
    boundary: &Boundary,
    steps: usize,
    rounds: usize,
    names: [&'static str; 3],
) -> [f64; 3] {
    let (order_2, fine) = (
        charted.problem(steps, TOLERANCE[0]),
        charted.problem(steps, TOLERANCE[1]),
    );
    let mut solve = || {
        black_box(order_2.solve(PlanGuess::Spline).map(|p| p.cost)).ok();
    };
    let mut extrapolate = || {
        black_box(fine.solve_extrapolated(PlanGuess::Spline).map(|e| e.cost)).ok();
    };
    let mut points = Vec::new();
    let mut casteljau = || {
        let bezier = Bezier::new(black_box(boundary));
        bezier.sample_into(steps, &mut points);
        black_box(&points);
    };
    // de Casteljau's curve takes microseconds: about 2000 points per sample
    let calls = (2000 / (steps + 1)).max(1);
    let rows = interleaved(
        rounds,
        &mut [
            Timed::new(names[0], 1, &mut solve),
            Timed::new(names[1], 1, &mut extrapolate),
            Timed::new(names[2], calls, &mut casteljau),
        ],
    );
    [0, 1, 2].map(|i| rows[i].samples.best())
}

/// Writes the lines `sphere cubic error=<e> time_us=<t> method=<retract|decasteljau>` (per
/// resolution, `retract` then `decasteljau`) and the table of all three methods.
///
/// # Errors
/// The writer's.
pub fn write(out: &mut dyn Write, result: &SphereCubic) -> std::io::Result<()> {
    writeln!(
        out,
        "\nRiemannian cubic on S^2 from (1, 0, 0), v = (0, 1, 0.5) to (0, 0.6, 0.8), \
         v = (-1.2, 0.3, -0.225), T = 1: error = max geodesic distance to the exact cubic \
         (Newton shooting, RK4 with {} steps, boundary residual {:.1e}) over {} equally spaced \
         times; time = building the curve at resolution N (retract: the solve of N steps, \
         tolerance {:.0e}; extrapolated: N, 2N and 4N, tolerance {:.0e}; de Casteljau: control points \
         and N + 1 points), best of {} interleaved rounds. de Casteljau's curve is another \
         curve than the cubic (same end points and velocities): its error stays.\n",
        SAMPLES * SUBSTEPS,
        result.boundary_residual,
        SAMPLES + 1,
        TOLERANCE[0],
        TOLERANCE[1],
        result.rounds
    )?;
    for (r, d) in result.retract.iter().zip(&result.decasteljau) {
        for (point, method) in [(r, "retract"), (d, "decasteljau")] {
            writeln!(
                out,
                "sphere cubic error={:.3e} time_us={:.2} method={method}",
                point.error,
                point.time_ns * 1e-3
            )?;
        }
    }
    writeln!(out)?;
    write_head(
        out,
        &[
            "N",
            "retract error",
            "retract time",
            "extrapolated error, curve (nodes)",
            "extrapolated time",
            "de Casteljau error",
            "de Casteljau time",
        ],
    )?;
    let rows = result
        .retract
        .iter()
        .zip(&result.extrapolated)
        .zip(&result.extrapolated_nodes)
        .zip(&result.decasteljau);
    for (((r, e), nodes), d) in rows {
        writeln!(
            out,
            "| {} | {:.2e} | {:.1} µs | {:.2e} ({nodes:.1e}) | {:.1} µs | {:.2e} | {:.2} µs |",
            r.steps,
            r.error,
            r.time_ns * 1e-3,
            e.error,
            e.time_ns * 1e-3,
            d.error,
            d.time_ns * 1e-3
        )?;
    }
    writeln!(out, "\n{}", verdict(result))
}

/// Which method is faster at which error: de Casteljau's error (the same at every
/// resolution) and its cheapest time, against the cheapest `retract` run (order 2 or
/// extrapolated) more accurate than that.
pub fn verdict(result: &SphereCubic) -> String {
    let Some(casteljau) = result
        .decasteljau
        .iter()
        .min_by(|a, b| a.time_ns.total_cmp(&b.time_ns))
    else {
        return "no measurement".into();
    };
    let floor = result
        .decasteljau
        .iter()
        .map(|p| p.error)
        .fold(f64::INFINITY, f64::min);
    let better = result
        .retract
        .iter()
        .map(|p| ("retract", p))
        .chain(result.extrapolated.iter().map(|p| ("extrapolated", p)))
        .filter(|(_, p)| p.error < floor)
        .min_by(|a, b| a.1.time_ns.total_cmp(&b.1.time_ns));
    let head = format!(
        "de Casteljau's error is {floor:.1e} at every N (another curve than the cubic), from \
         {:.2} µs (N = {}): at errors of {floor:.1e} and above it is the faster.",
        casteljau.time_ns * 1e-3,
        casteljau.steps,
    );
    match better {
        Some((name, p)) => format!(
            "{head} Below {floor:.1e} only retract reaches; its cheapest run more accurate \
             than de Casteljau is {name} at N = {} ({:.1e} in {:.1} µs, {:.0} times de \
             Casteljau's cheapest time).",
            p.steps,
            p.error,
            p.time_ns * 1e-3,
            p.time_ns / casteljau.time_ns
        ),
        None => format!("{head} No retract run measured here is more accurate."),
    }
}

/// Measures at [`RESOLUTIONS`] over `rounds` rounds and writes the lines and the table
/// ([`measure`], [`write()`]).
///
/// # Errors
/// [`measure`]'s, or [`Error::Io`].
pub fn run(out: &mut dyn Write, rounds: usize) -> Result<SphereCubic, Error> {
    let result = measure(&RESOLUTIONS, rounds)?;
    write(out, &result)?;
    Ok(result)
}
