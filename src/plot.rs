//! SVG figures of curves (feature `plot`): plane paths around discs ([`plane`]), stacked
//! panels against a common axis ([`panels`]) and curves on the unit sphere ([`sphere`]).
//!
//! Drawn with [plotters](https://docs.rs/plotters) and its SVG backend, without system fonts
//! (the SVG names the font `sans-serif`; the viewer picks it). Curves get the colours of a
//! fixed six-colour cycle and a legend entry each; non-finite points are left out of the axis
//! ranges.
//!
//! ```no_run
//! use retract::plot::{self, Curve, Scale};
//!
//! let circle: Vec<(f64, f64)> =
//!     (0..=100).map(|i| (0.06 * i as f64).cos()).map(|c| (c, (1.0 - c * c).sqrt())).collect();
//! plot::plane("path.svg".as_ref(), "a path", &[Curve::new("arc", circle)], &[(0.0, 0.0, 0.5)])?;
//! let decay: Vec<(f64, f64)> = (1..=10).map(|i| (i as f64, 10f64.powi(-i))).collect();
//! plot::panels(
//!     "decay.svg".as_ref(),
//!     "convergence",
//!     "steps",
//!     &[("error", vec![Curve::new("midpoint", decay)])],
//!     Scale::Log,
//! )?;
//! # Ok::<(), retract::plot::Error>(())
//! ```

use std::fmt;
use std::path::Path;

use plotters::prelude::*;

/// A failed figure: no finite point to scale the axes by, a non-positive value on a log
/// axis, or an error of plotters (e.g. the file could not be written), as text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error(String);

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "plot: {}", self.0)
    }
}

impl std::error::Error for Error {}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for Error {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        Self(e.to_string())
    }
}

/// A curve and its legend label.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// The legend entry.
    pub label: String,
    /// The points $(x, y)$, joined in order.
    pub points: Vec<(f64, f64)>,
}

impl Curve {
    /// The curve through `points` labelled `label`.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
        }
    }
}

/// The axes of [`panels`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// Linear axes, each padded by 5 % of its range; curves without markers.
    Linear,
    /// Logarithmic axes (ticks labelled `1e-5`, ...), for sweeps: every point marked. The
    /// axis ranges are those of the points with $x, y > 0$ (the others cannot be drawn).
    Log,
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// The box $(x_{\min}, x_{\max}, y_{\min}, y_{\max})$ of the finite points.
fn bounds<'a>(points: impl Iterator<Item = &'a (f64, f64)>) -> Result<[f64; 4], Error> {
    bounds_of(points, |_| true)
}

/// The box of the finite points that `keep` accepts.
fn bounds_of<'a>(
    points: impl Iterator<Item = &'a (f64, f64)>,
    keep: impl Fn(&(f64, f64)) -> bool,
) -> Result<[f64; 4], Error> {
    let mut b = [
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    for &(x, y) in points.filter(|p| keep(p)) {
        if x.is_finite() && y.is_finite() {
            b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
        }
    }
    if b[0] > b[1] {
        return Err(Error("no finite point to draw".into()));
    }
    Ok(b)
}

/// `lo..hi` widened by 5 % of its length (at least $10^{-9}$) on each side.
fn padded(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad)..(hi + pad)
}

/// Plane curves with obstacle discs `(cx, cy, r)` (grey) and start (circle) / end (cross)
/// markers, equal axis scales, as a 720 x 720 SVG at `path`.
///
/// # Errors
/// [`Error`] when no point or disc is finite, or plotters fails (e.g. writing the file).
pub fn plane(
    path: &Path,
    title: &str,
    curves: &[Curve],
    discs: &[(f64, f64, f64)],
) -> Result<(), Error> {
    let disc_points: Vec<(f64, f64)> = discs
        .iter()
        .flat_map(|&(x, y, r)| [(x - r, y - r), (x + r, y + r)])
        .collect();
    let [x0, x1, y0, y1] = bounds(
        curves
            .iter()
            .flat_map(|c| c.points.iter())
            .chain(&disc_points),
    )?;
    let span = (x1 - x0).max(y1 - y0);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let root = SVGBackend::new(path, (720, 720)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d(
            padded(cx - span / 2.0, cx + span / 2.0),
            padded(cy - span / 2.0, cy + span / 2.0),
        )?;
    chart.configure_mesh().x_desc("x").y_desc("y").draw()?;
    for &(x, y, r) in discs {
        let circle: Vec<(f64, f64)> = (0..=128)
            .map(|i| {
                let a = i as f64 / 128.0 * std::f64::consts::TAU;
                (x + r * a.cos(), y + r * a.sin())
            })
            .collect();
        chart.draw_series(std::iter::once(Polygon::new(
            circle,
            RGBColor(200, 200, 200).filled(),
        )))?;
    }
    draw_curves(&mut chart, curves, Markers::Ends)?;
    root.present()?;
    Ok(())
}

/// Stacked panels of curves against a common x axis labelled `x_label`, each panel a
/// (y label, curves) pair and 320 pixels high, 800 wide, as an SVG at `path`.
///
/// # Errors
/// [`Error`] for no panel, a panel without a finite point (with [`Scale::Log`]: without a
/// finite point with $x, y > 0$), or when plotters fails (e.g. writing the file).
pub fn panels(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[(&str, Vec<Curve>)],
    scale: Scale,
) -> Result<(), Error> {
    if panels.is_empty() {
        return Err(Error("no panel to draw".into()));
    }
    let height = 320 * u32::try_from(panels.len()).map_err(|_| Error("too many panels".into()))?;
    let root = SVGBackend::new(path, (800, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 18))?;
    let areas = root.split_evenly((panels.len(), 1));
    for (area, (y_label, curves)) in areas.iter().zip(panels) {
        let points = curves.iter().flat_map(|c| c.points.iter());
        let [x0, x1, y0, y1] = match scale {
            Scale::Linear => bounds(points),
            Scale::Log => bounds_of(points, |&(x, y)| x > 0.0 && y > 0.0),
        }
        .map_err(|e| Error(format!("panel `{y_label}`: {}", e.0)))?;
        let mut chart = ChartBuilder::on(area);
        chart.margin(12).x_label_area_size(36).y_label_area_size(64);
        match scale {
            Scale::Log => {
                let mut chart = chart.build_cartesian_2d(
                    (x0 * 0.8..x1 * 1.25).log_scale(),
                    (y0 * 0.5..y1 * 2.0).log_scale(),
                )?;
                chart
                    .configure_mesh()
                    .x_desc(x_label)
                    .y_desc(*y_label)
                    .x_label_formatter(&|v| power_of_ten(*v))
                    .y_label_formatter(&|v| power_of_ten(*v))
                    .draw()?;
                draw_curves(&mut chart, curves, Markers::Points)?;
            }
            Scale::Linear => {
                let mut chart = chart.build_cartesian_2d(padded(x0, x1), padded(y0, y1))?;
                chart
                    .configure_mesh()
                    .x_desc(x_label)
                    .y_desc(*y_label)
                    .draw()?;
                draw_curves(&mut chart, curves, Markers::None)?;
            }
        }
    }
    root.present()?;
    Ok(())
}

/// A log-axis tick label: `1e-5` rather than the rounded `9.999999999999998e-6`.
fn power_of_ten(v: f64) -> String {
    let exponent = v.log10().round();
    let mantissa = v / 10f64.powf(exponent);
    if (mantissa - 1.0).abs() < 1e-6 {
        format!("1e{exponent}")
    } else {
        format!("{v:.1e}")
    }
}

/// Which points of a curve get a marker.
#[derive(Clone, Copy)]
enum Markers {
    None,
    /// every point (sweeps)
    Points,
    /// start (circle) and end (cross)
    Ends,
}

fn draw_curves<'a, DB, CT>(
    chart: &mut ChartContext<'a, DB, CT>,
    curves: &[Curve],
    markers: Markers,
) -> Result<(), Error>
where
    DB: DrawingBackend + 'a,
    CT: CoordTranslate<From = (f64, f64)>,
{
    for (i, c) in curves.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        chart
            .draw_series(LineSeries::new(
                c.points.iter().copied(),
                color.stroke_width(2),
            ))?
            .label(c.label.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        match markers {
            Markers::None => {}
            Markers::Points => {
                chart.draw_series(c.points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
            }
            Markers::Ends => {
                if let (Some(&first), Some(&last)) = (c.points.first(), c.points.last()) {
                    chart.draw_series(std::iter::once(Circle::new(first, 5, color.filled())))?;
                    chart.draw_series(std::iter::once(Cross::new(
                        last,
                        6,
                        color.stroke_width(2),
                    )))?;
                }
            }
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

type Point = [f64; 3];

fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: Point, b: Point) -> Point {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: Point) -> Point {
    let n = dot(a, a).sqrt();
    a.map(|c| c / n)
}

/// The orthographic projection along `eye` (z up): screen axes `right` and `up`.
struct View {
    eye: Point,
    up: Point,
    right: Point,
}

impl View {
    fn new(eye: Point) -> Result<Self, Error> {
        let eye = unit(eye);
        let up = unit([-eye[0] * eye[2], -eye[1] * eye[2], 1.0 - eye[2] * eye[2]]);
        if !(eye.iter().chain(&up).all(|v| v.is_finite())) {
            return Err(Error(
                "the view direction must be finite, nonzero and not vertical".into(),
            ));
        }
        Ok(Self {
            eye,
            up,
            right: cross(up, eye),
        })
    }

    /// The screen point of `p` and whether `p` faces the eye.
    fn project(&self, p: Point) -> ((f64, f64), bool) {
        (
            (dot(p, self.right), dot(p, self.up)),
            dot(p, self.eye) >= 0.0,
        )
    }

    /// The screen polylines of the parts of `points` on the visible side.
    fn visible_runs(&self, points: &[Point]) -> Vec<Vec<(f64, f64)>> {
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &p in points {
            let (xy, front) = self.project(p);
            match (front, runs.last_mut()) {
                (true, Some(run)) => run.push(xy),
                (false, Some(run)) if !run.is_empty() => runs.push(Vec::new()),
                _ => {}
            }
        }
        runs.into_iter().filter(|r| r.len() > 1).collect()
    }
}

/// The circle on the unit sphere at angular radius `radius` around `axis`.
fn small_circle(axis: Point, radius: f64) -> Vec<Point> {
    let axis = unit(axis);
    let helper = if axis[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = unit(cross(axis, helper));
    let e2 = cross(axis, e1);
    let (c, s) = (radius.cos(), radius.sin());
    (0..=180)
        .map(|i| {
            let a = i as f64 / 180.0 * std::f64::consts::TAU;
            core::array::from_fn(|k| axis[k] * c + (e1[k] * a.cos() + e2[k] * a.sin()) * s)
        })
        .collect()
}

/// An orthographic view of the unit sphere from the direction `eye` (z up), as a 720 x 720
/// SVG at `path`: the outline, a 30-degree graticule, the caps `(axis, angular radius)`
/// (orange) and the curves `(label, points on the sphere)`, each only on the visible side,
/// the curves with start (circle) and end (cross) markers.
///
/// # Errors
/// [`Error`] for a view direction that is zero, not finite or vertical, or when plotters
/// fails (e.g. writing the file).
pub fn sphere(
    path: &Path,
    title: &str,
    eye: [f64; 3],
    curves: &[(String, Vec<[f64; 3]>)],
    caps: &[([f64; 3], f64)],
) -> Result<(), Error> {
    let view = View::new(eye)?;
    let root = SVGBackend::new(path, (720, 720)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .build_cartesian_2d(-1.1..1.1, -1.1..1.1)?;
    let grey = RGBColor(200, 200, 200);
    let outline: Vec<(f64, f64)> = small_circle(view.eye, std::f64::consts::FRAC_PI_2)
        .iter()
        .map(|&p| view.project(p).0)
        .collect();
    chart.draw_series(std::iter::once(PathElement::new(
        outline,
        BLACK.stroke_width(1),
    )))?;
    let parallels = (-60..=60)
        .step_by(30)
        .map(|d| small_circle([0.0, 0.0, 1.0], (90.0 - f64::from(d)).to_radians()));
    let meridians = (0..180).step_by(30).map(|d| {
        let a = f64::from(d).to_radians();
        small_circle([-a.sin(), a.cos(), 0.0], std::f64::consts::FRAC_PI_2)
    });
    for line in parallels.chain(meridians) {
        for run in view.visible_runs(&line) {
            chart.draw_series(std::iter::once(PathElement::new(run, grey)))?;
        }
    }
    for &(axis, radius) in caps {
        for run in view.visible_runs(&small_circle(axis, radius)) {
            chart.draw_series(std::iter::once(Polygon::new(
                run.clone(),
                RGBColor(255, 200, 120).mix(0.6).filled(),
            )))?;
            chart.draw_series(std::iter::once(PathElement::new(
                run,
                RGBColor(255, 127, 14),
            )))?;
        }
    }
    let projected: Vec<Curve> = curves
        .iter()
        .map(|(label, points)| {
            let front = view.visible_runs(points).into_iter().flatten().collect();
            Curve::new(label.clone(), front)
        })
        .collect();
    draw_curves(&mut chart, &projected, Markers::Ends)?;
    root.present()?;
    Ok(())
}
