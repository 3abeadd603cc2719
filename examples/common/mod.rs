//! Small SVG plotting helpers shared by the examples (plotters, SVG backend, no system fonts).
#![allow(dead_code)] // each example uses a subset

use std::error::Error;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

/// A curve and its legend label.
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

impl Curve {
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            points,
        }
    }
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// The path of a figure under the repository's `docs/`.
pub fn docs_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs")
        .join(name)
}

fn bounds<'a>(points: impl Iterator<Item = &'a (f64, f64)>) -> (f64, f64, f64, f64) {
    let mut b = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for &(x, y) in points {
        if x.is_finite() && y.is_finite() {
            b = (b.0.min(x), b.1.max(x), b.2.min(y), b.3.max(y));
        }
    }
    b
}

fn padded(lo: f64, hi: f64) -> std::ops::Range<f64> {
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad)..(hi + pad)
}

/// Plane trajectories with obstacle discs `(cx, cy, r)` and start (circle) / end (cross)
/// markers, equal axis scales.
pub fn plane(
    path: &Path,
    title: &str,
    curves: &[Curve],
    discs: &[(f64, f64, f64)],
) -> Result<(), Box<dyn Error>> {
    let disc_points: Vec<(f64, f64)> = discs
        .iter()
        .flat_map(|&(x, y, r)| [(x - r, y - r), (x + r, y + r)])
        .collect();
    let (x0, x1, y0, y1) = bounds(
        curves
            .iter()
            .flat_map(|c| c.points.iter())
            .chain(&disc_points),
    );
    let span = (x1 - x0).max(y1 - y0);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let (w, h) = (720u32, 720u32);
    let root = SVGBackend::new(path, (w, h)).into_drawing_area();
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

/// Stacked panels of curves against a common x axis; each panel is (y label, curves).
pub fn panels(
    path: &Path,
    title: &str,
    x_label: &str,
    panels: &[(&str, Vec<Curve>)],
    log_axes: bool,
) -> Result<(), Box<dyn Error>> {
    let height = 320 * panels.len() as u32;
    let root = SVGBackend::new(path, (800, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 18))?;
    let areas = root.split_evenly((panels.len(), 1));
    for (area, (y_label, curves)) in areas.iter().zip(panels) {
        let (x0, x1, y0, y1) = bounds(curves.iter().flat_map(|c| c.points.iter()));
        let mut chart = ChartBuilder::on(area);
        chart.margin(12).x_label_area_size(36).y_label_area_size(64);
        if log_axes {
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
        } else {
            let mut chart = chart.build_cartesian_2d(padded(x0, x1), padded(y0, y1))?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(*y_label)
                .draw()?;
            draw_curves(&mut chart, curves, Markers::None)?;
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
) -> Result<(), Box<dyn Error>>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
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

/// An orthographic view of the unit sphere from the direction `eye` (a unit vector, z up):
/// the outline, a 30-degree graticule and the caps `(axis, angular radius)` on the visible
/// side, and curves of points on the sphere (their visible parts), with start and end markers.
pub fn sphere(
    path: &Path,
    title: &str,
    eye: [f64; 3],
    curves: &[(String, Vec<[f64; 3]>)],
    caps: &[([f64; 3], f64)],
) -> Result<(), Box<dyn Error>> {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let unit = |a: [f64; 3]| {
        let n = dot(a, a).sqrt();
        a.map(|c| c / n)
    };
    let eye = unit(eye);
    let up = unit([-eye[0] * eye[2], -eye[1] * eye[2], 1.0 - eye[2] * eye[2]]);
    let right = cross(up, eye);
    // the screen point of p and whether p faces the eye
    let project = |p: [f64; 3]| ((dot(p, right), dot(p, up)), dot(p, eye) >= 0.0);
    let visible_runs = |points: &[[f64; 3]]| -> Vec<Vec<(f64, f64)>> {
        let mut runs: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for &p in points {
            let (xy, front) = project(p);
            match (front, runs.last_mut()) {
                (true, Some(run)) => run.push(xy),
                (false, Some(run)) if !run.is_empty() => runs.push(Vec::new()),
                _ => {}
            }
        }
        runs.into_iter().filter(|r| r.len() > 1).collect()
    };
    let circle = |axis: [f64; 3], radius: f64| -> Vec<[f64; 3]> {
        let axis = unit(axis);
        let helper = if axis[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = unit(cross(axis, helper));
        let e2 = cross(axis, e1);
        (0..=180)
            .map(|i| {
                let a = i as f64 / 180.0 * std::f64::consts::TAU;
                let (c, s) = (radius.cos(), radius.sin());
                core::array::from_fn(|k| axis[k] * c + (e1[k] * a.cos() + e2[k] * a.sin()) * s)
            })
            .collect()
    };
    let root = SVGBackend::new(path, (720, 720)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .build_cartesian_2d(-1.1..1.1, -1.1..1.1)?;
    let grey = RGBColor(200, 200, 200);
    let outline: Vec<(f64, f64)> = circle(eye, std::f64::consts::FRAC_PI_2)
        .iter()
        .map(|&p| project(p).0)
        .collect();
    chart.draw_series(std::iter::once(PathElement::new(
        outline,
        BLACK.stroke_width(1),
    )))?;
    for degrees in (-60..=60).step_by(30) {
        let parallel = circle([0.0, 0.0, 1.0], (90.0 - degrees as f64).to_radians());
        for run in visible_runs(&parallel) {
            chart.draw_series(std::iter::once(PathElement::new(run, grey)))?;
        }
    }
    for degrees in (0..180).step_by(30) {
        let a = (degrees as f64).to_radians();
        let meridian = circle([-a.sin(), a.cos(), 0.0], std::f64::consts::FRAC_PI_2);
        for run in visible_runs(&meridian) {
            chart.draw_series(std::iter::once(PathElement::new(run, grey)))?;
        }
    }
    for &(axis, radius) in caps {
        for run in visible_runs(&circle(axis, radius)) {
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
            let front = visible_runs(points).into_iter().flatten().collect();
            Curve::new(label.clone(), front)
        })
        .collect();
    draw_curves(&mut chart, &projected, Markers::Ends)?;
    root.present()?;
    Ok(())
}
