//! The SVG figures of `retract::plot` (feature `plot`): each figure is SVG with its title and
//! labels; bad input (NaN, a log scale over negative values, no panels, a degenerate view
//! direction, an unwritable path) is an error, not a panic.

use retract::plot::{Curve, Scale, panels, plane, sphere};

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("retract-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn arc() -> Vec<(f64, f64)> {
    (1..=50)
        .map(|i| (0.05 * f64::from(i), (0.05 * f64::from(i)).sin() + 1.0))
        .collect()
}

#[test]
fn figures_are_svg_with_their_labels() {
    let path = scratch("plane.svg");
    plane(
        &path,
        "a plane",
        &[Curve::new("arc", arc())],
        &[(1.0, 0.0, 0.5)],
    )
    .unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("a plane") && svg.contains("arc"));
    let path = scratch("panels.svg");
    let panel = |label| (label, vec![Curve::new("sweep", arc())]);
    panels(
        &path,
        "two",
        "t",
        &[panel("first"), panel("second")],
        Scale::Log,
    )
    .unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(
        svg.contains("height=\"640\"") && svg.contains("second"),
        "{svg:.300}"
    );
    let path = scratch("sphere.svg");
    let equator = (0..=36)
        .map(|i| {
            [
                f64::from(i * 10).to_radians().cos(),
                f64::from(i * 10).to_radians().sin(),
                0.0,
            ]
        })
        .collect();
    let caps = [([1.0, 0.0, 0.0], 0.3)];
    sphere(
        &path,
        "globe",
        [1.0, -0.2, 0.4],
        &[("equator".into(), equator)],
        &caps,
    )
    .unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().contains("equator"));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let path = scratch("bad.svg");
    let nan = Curve::new("nan", vec![(f64::NAN, 1.0)]);
    assert!(plane(&path, "", std::slice::from_ref(&nan), &[]).is_err());
    assert!(panels(&path, "", "t", &[], Scale::Linear).is_err());
    assert!(panels(&path, "", "t", &[("y", vec![nan])], Scale::Linear).is_err());
    let negative = Curve::new("negative", vec![(1.0, -1.0), (0.0, 1.0)]);
    assert!(panels(&path, "", "t", &[("y", vec![negative])], Scale::Log).is_err());
    assert!(sphere(&path, "", [0.0, 0.0, 1.0], &[], &[]).is_err());
    assert!(sphere(&path, "", [0.0; 3], &[], &[]).is_err());
    let missing = std::path::Path::new("/nonexistent-directory/figure.svg");
    let err = plane(missing, "", &[Curve::new("arc", arc())], &[]).unwrap_err();
    assert!(err.to_string().starts_with("plot: "), "{err}");
}
