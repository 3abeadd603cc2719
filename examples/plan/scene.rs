//! Scene files of the `plan` example: TOML parsed strictly (an unknown key is an error, not
//! ignored) and every value checked, with messages that name the key.
//!
//! ```toml
//! horizon = 4.0             # T, finite and >= 0.01 (MIN_HORIZON)
//! steps = 400               # N >= 1 (h = T / N)
//! barrier = 1e-2            # tau of the final solve, finite and > 0
//! continuation = [1.0, 0.1] # optional: barrier weights solved first, each finite and > 0
//! [start]                   # q(0) and q'(0): (x, y, theta)
//! position = [-2.0, 0.3, 0.0]
//! velocity = [1.0, 0.0, 0.0]
//! [goal]                    # q(T) and q'(T)
//! position = [2.0, 0.3, 1.57]
//! velocity = [1.0, 0.0, 0.0]
//! [[obstacles]]             # any number of discs; `center` is accepted for `centre`
//! centre = [0.0, 0.0]
//! radius = 1.0              # finite and > 0
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use serde::Deserialize;

/// The most steps a scene may ask for: the planner holds every state of the plan and its
/// first guess in memory.
pub const MAX_STEPS: i64 = 1_000_000;

/// The shortest horizon a scene may ask for. The planner's first guess is differentiated
/// over fixed time offsets of up to about 1e-3 (the central differences of `Curve::from_fn`,
/// eps^(1/5) = 7e-4 for the third derivative, and the guess's own pushes around the discs),
/// so the horizon must be long against them: over a shorter one the guess is sampled far
/// outside [0, T], where its Hermite path in t / T grows without bound (at T = 1e-300 it
/// overflowed, and the error blamed the guess's curve instead of the horizon).
pub const MIN_HORIZON: f64 = 0.01;

/// A checked scene: every number finite, the horizon at least [`MIN_HORIZON`], barrier
/// weights and radii positive, at least one step.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The horizon T.
    pub horizon: f64,
    /// The number of steps N.
    pub steps: usize,
    /// The barrier weight tau of the final solve.
    pub barrier: f64,
    /// Barrier weights solved before `barrier`, each warm-starting the next.
    pub continuation: Vec<f64>,
    /// q(0) and q'(0).
    pub start: Boundary,
    /// q(T) and q'(T).
    pub goal: Boundary,
    /// The disc obstacles.
    pub obstacles: Vec<Obstacle>,
}

/// Position and velocity (x, y, theta) at one end of the plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boundary {
    /// (x, y, theta).
    pub position: [f64; 3],
    /// (x', y', theta').
    pub velocity: [f64; 3],
}

impl Boundary {
    /// The jet (q, q') as one array.
    pub fn jet(&self) -> [f64; 6] {
        let (p, v) = (self.position, self.velocity);
        [p[0], p[1], p[2], v[0], v[1], v[2]]
    }
}

/// A disc obstacle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Obstacle {
    /// Its centre (x, y).
    pub centre: [f64; 2],
    /// Its radius.
    pub radius: f64,
}

/// Why a scene could not be loaded.
#[derive(Debug)]
pub struct SceneError {
    /// The file, when the scene came from one.
    pub path: Option<PathBuf>,
    /// What went wrong.
    pub reason: Reason,
}

/// What went wrong with a scene.
#[derive(Debug)]
pub enum Reason {
    /// The file could not be read (missing, unreadable, not UTF-8).
    Read(std::io::Error),
    /// The text is not a scene: TOML syntax, an unknown or missing key, a wrong type.
    Toml(toml::de::Error),
    /// A value breaks a rule: `key` must be `requirement`, and is `got`.
    Invalid {
        /// The key, as a path into the file (e.g. `obstacles[2].radius`).
        key: String,
        /// What the value must be.
        requirement: &'static str,
        /// What it is.
        got: String,
    },
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Reason::Read(e) = &self.reason {
            return match &self.path {
                Some(path) => write!(f, "cannot read scene file `{}`: {e}", path.display()),
                None => write!(f, "cannot read the scene: {e}"),
            };
        }
        if let Some(path) = &self.path {
            write!(f, "scene file `{}`: ", path.display())?;
        }
        match &self.reason {
            Reason::Invalid {
                key,
                requirement,
                got,
            } => write!(f, "{key} must be {requirement}, got {got}"),
            Reason::Toml(e) => write!(f, "{}", e.to_string().trim_end()),
            Reason::Read(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.reason {
            Reason::Read(e) => Some(e),
            Reason::Toml(e) => Some(e),
            Reason::Invalid { .. } => None,
        }
    }
}

/// The scene in the file at `path`.
///
/// # Errors
/// A [`SceneError`] naming the path: the file cannot be read, is not a scene, or breaks a rule.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let in_file = |reason| SceneError {
        path: Some(path.to_path_buf()),
        reason,
    };
    let text = std::fs::read_to_string(path).map_err(|e| in_file(Reason::Read(e)))?;
    parse(&text).map_err(|e| in_file(e.reason))
}

/// The scene in the TOML text `text`.
///
/// # Errors
/// A [`SceneError`] (without a path): the text is not a scene or breaks a rule.
pub fn parse(text: &str) -> Result<Scene, SceneError> {
    let raw: RawScene = toml::from_str(text).map_err(|e| SceneError {
        path: None,
        reason: Reason::Toml(e),
    })?;
    raw.check()
        .map_err(|reason| SceneError { path: None, reason })
}

/// The scene as written: lists of any length and signed integers, checked by
/// [`RawScene::check`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    horizon: f64,
    steps: i64,
    barrier: f64,
    #[serde(default)]
    continuation: Vec<f64>,
    start: RawBoundary,
    goal: RawBoundary,
    #[serde(default)]
    obstacles: Vec<RawObstacle>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBoundary {
    position: Vec<f64>,
    velocity: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObstacle {
    #[serde(alias = "center")]
    centre: Vec<f64>,
    radius: f64,
}

fn invalid(key: impl Into<String>, requirement: &'static str, got: impl ToString) -> Reason {
    Reason::Invalid {
        key: key.into(),
        requirement,
        got: got.to_string(),
    }
}

/// `value` if it is finite.
fn finite(key: &str, value: f64) -> Result<f64, Reason> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(invalid(key, "a finite number", value))
    }
}

/// `value` if it is finite and > 0.
fn positive(key: &str, value: f64) -> Result<f64, Reason> {
    if finite(key, value)? > 0.0 {
        Ok(value)
    } else {
        Err(invalid(key, "> 0", value))
    }
}

/// The `L` finite numbers of the list `values`.
fn array<const L: usize>(
    key: &str,
    values: &[f64],
    requirement: &'static str,
) -> Result<[f64; L], Reason> {
    let Ok(array) = <[f64; L]>::try_from(values) else {
        return Err(invalid(
            key,
            requirement,
            format!("{} numbers", values.len()),
        ));
    };
    for (i, &v) in array.iter().enumerate() {
        finite(&format!("{key}[{i}]"), v)?;
    }
    Ok(array)
}

impl RawBoundary {
    fn check(&self, key: &str) -> Result<Boundary, Reason> {
        let triple = "exactly 3 numbers (x, y, theta)";
        Ok(Boundary {
            position: array(&format!("{key}.position"), &self.position, triple)?,
            velocity: array(&format!("{key}.velocity"), &self.velocity, triple)?,
        })
    }
}

impl RawScene {
    fn check(&self) -> Result<Scene, Reason> {
        let horizon = positive("horizon", self.horizon)?;
        if horizon < MIN_HORIZON {
            return Err(invalid(
                "horizon",
                "at least 0.01 (MIN_HORIZON: the first guess is differentiated over time \
                 offsets of up to 1e-3)",
                format!("{horizon:e}"),
            ));
        }
        let steps = usize::try_from(self.steps)
            .ok()
            .filter(|_| (1..=MAX_STEPS).contains(&self.steps))
            .ok_or_else(|| invalid("steps", "an integer from 1 to 1000000", self.steps))?;
        let barrier = positive("barrier", self.barrier)?;
        let continuation = self
            .continuation
            .iter()
            .enumerate()
            .map(|(i, &w)| positive(&format!("continuation[{i}]"), w))
            .collect::<Result<_, _>>()?;
        let start = self.start.check("start")?;
        let goal = self.goal.check("goal")?;
        let obstacles = self
            .obstacles
            .iter()
            .enumerate()
            .map(|(j, o)| {
                let key = format!("obstacles[{j}]");
                Ok(Obstacle {
                    centre: array(
                        &format!("{key}.centre"),
                        &o.centre,
                        "exactly 2 numbers (x, y)",
                    )?,
                    radius: positive(&format!("{key}.radius"), o.radius)?,
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(Scene {
            horizon,
            steps,
            barrier,
            continuation,
            start,
            goal,
            obstacles,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A valid scene with two obstacles; `edit` replaces one line of it.
    const VALID: &str = "\
horizon = 4.0
steps = 400
barrier = 1e-2
continuation = [1.0, 0.1]

[start]
position = [-2.0, 0.3, 0.0]
velocity = [1.0, 0.0, 0.0]

[goal]
position = [2.0, 0.3, 1.5]
velocity = [1.0, 0.0, 0.0]

[[obstacles]]
centre = [0.0, 0.0]
radius = 1.0

[[obstacles]]
centre = [1.0, 2.0]
radius = 0.5
";

    /// `VALID` with the first line starting with `from` replaced by `to`.
    fn edit(from: &str, to: &str) -> String {
        let mut done = false;
        let lines: Vec<String> = VALID
            .lines()
            .map(|line| {
                if !done && line.starts_with(from) {
                    done = true;
                    to.to_string()
                } else {
                    line.to_string()
                }
            })
            .collect();
        assert!(done, "no line starts with `{from}`");
        lines.join("\n")
    }

    /// The message of the error of `text`.
    fn message(text: &str) -> String {
        parse(text).expect_err("an invalid scene").to_string()
    }

    fn contains_all(message: &str, words: &[&str]) {
        for word in words {
            assert!(message.contains(word), "`{message}` lacks `{word}`");
        }
    }

    #[test]
    fn the_valid_scene_parses() {
        let scene = parse(VALID).expect("valid");
        assert_eq!(scene.steps, 400);
        assert_eq!(scene.continuation, vec![1.0, 0.1]);
        assert_eq!(scene.start.jet(), [-2.0, 0.3, 0.0, 1.0, 0.0, 0.0]);
        assert_eq!(
            scene.obstacles,
            vec![
                Obstacle {
                    centre: [0.0, 0.0],
                    radius: 1.0
                },
                Obstacle {
                    centre: [1.0, 2.0],
                    radius: 0.5
                }
            ]
        );
    }

    #[test]
    fn a_singular_obstacle_table_is_an_unknown_key() {
        // `[[obstacle]]` was ignored: the plan went straight through the disc
        let text = VALID.replace("[[obstacles]]", "[[obstacle]]");
        contains_all(&message(&text), &["unknown field `obstacle`", "obstacles"]);
    }

    #[test]
    fn unknown_keys_are_errors_in_every_table() {
        for (from, to, unknown) in [
            ("horizon", "horizn = 4.0", "horizn"),
            (
                "position = [-2.0",
                "posiiton = [-2.0, 0.3, 0.0]",
                "posiiton",
            ),
            ("radius = 1.0", "radius = 1.0\nradiu = 2.0", "radiu"),
        ] {
            contains_all(
                &message(&edit(from, to)),
                &[&format!("unknown field `{unknown}`")],
            );
        }
    }

    #[test]
    fn center_is_an_alias_of_centre() {
        let scene = parse(&edit("centre = [1.0, 2.0]", "center = [1.0, 2.0]")).expect("valid");
        assert_eq!(scene.obstacles[1].centre, [1.0, 2.0]);
    }

    #[test]
    fn a_missing_file_names_its_path() {
        let path = Path::new("examples/scenes/no_such_scene.toml");
        let text = load(path).expect_err("missing").to_string();
        contains_all(
            &text,
            &["examples/scenes/no_such_scene.toml", "cannot read"],
        );
    }

    #[test]
    fn an_invalid_value_in_a_file_names_the_file_and_the_key() {
        let path = std::env::temp_dir().join(format!("retract_scene_{}.toml", std::process::id()));
        std::fs::write(&path, edit("radius = 0.5", "radius = -1")).expect("writable");
        let result = load(&path);
        std::fs::remove_file(&path).ok();
        let text = result.expect_err("invalid").to_string();
        contains_all(
            &text,
            &[
                &path.display().to_string(),
                "obstacles[1].radius must be > 0, got -1",
            ],
        );
    }

    #[test]
    fn each_invalid_value_is_named() {
        let cases = [
            (
                "radius = 0.5",
                "radius = -1",
                "obstacles[1].radius must be > 0, got -1",
            ),
            (
                "radius = 1.0",
                "radius = 0",
                "obstacles[0].radius must be > 0, got 0",
            ),
            (
                "radius = 1.0",
                "radius = nan",
                "obstacles[0].radius must be a finite number, got NaN",
            ),
            ("barrier", "barrier = -0.5", "barrier must be > 0, got -0.5"),
            ("barrier", "barrier = 0.0", "barrier must be > 0, got 0"),
            (
                "barrier",
                "barrier = inf",
                "barrier must be a finite number, got inf",
            ),
            (
                "steps",
                "steps = 0",
                "steps must be an integer from 1 to 1000000",
            ),
            ("steps", "steps = -3", "got -3"),
            ("steps", "steps = 2000000", "got 2000000"),
            ("horizon", "horizon = 0.0", "horizon must be > 0, got 0"),
            (
                "horizon",
                "horizon = -inf",
                "horizon must be a finite number, got -inf",
            ),
            (
                "horizon",
                "horizon = nan",
                "horizon must be a finite number, got NaN",
            ),
            (
                "continuation",
                "continuation = [1.0, -0.1]",
                "continuation[1] must be > 0, got -0.1",
            ),
            (
                "continuation",
                "continuation = [inf]",
                "continuation[0] must be a finite number, got inf",
            ),
            (
                "centre = [0.0, 0.0]",
                "centre = [0.0, 0.0, 1.0]",
                "obstacles[0].centre must be exactly 2 numbers (x, y), got 3 numbers",
            ),
            (
                "centre = [1.0, 2.0]",
                "centre = [1.0]",
                "obstacles[1].centre must be exactly 2 numbers (x, y), got 1 numbers",
            ),
            (
                "centre = [1.0, 2.0]",
                "center = [1.0, nan]",
                "obstacles[1].centre[1] must be a finite number, got NaN",
            ),
            (
                "position = [-2.0",
                "position = [-2.0, 0.3]",
                "start.position must be exactly 3 numbers (x, y, theta), got 2 numbers",
            ),
            (
                "velocity = [1.0",
                "velocity = [1.0, 0.0, 0.0, 0.0]",
                "start.velocity must be exactly 3 numbers (x, y, theta), got 4 numbers",
            ),
            (
                "position = [2.0",
                "position = [2.0, inf, 0.0]",
                "goal.position[1] must be a finite number, got inf",
            ),
        ];
        for (from, to, expected) in cases {
            contains_all(&message(&edit(from, to)), &[expected]);
        }
    }

    /// A positive horizon too short for the first guess (issue 33, item 7: 1e-300 failed with
    /// an error about the guess's `curve`) is named as the horizon.
    #[test]
    fn a_horizon_too_short_for_the_guess_is_named() {
        for (value, got) in [("1e-300", "got 1e-300"), ("1e-3", "got 1e-3")] {
            contains_all(
                &message(&edit("horizon", &format!("horizon = {value}"))),
                &["horizon must be at least 0.01", got],
            );
        }
        let shortest = parse(&edit("horizon", "horizon = 0.01")).expect("valid");
        assert_eq!(shortest.horizon, MIN_HORIZON);
    }

    #[test]
    fn missing_keys_and_wrong_types_are_named() {
        contains_all(&message(&edit("barrier", "")), &["missing field `barrier`"]);
        contains_all(&message(&edit("steps", "steps = 400.5")), &["steps"]);
        contains_all(
            &message(&edit("radius = 1.0", "radius = \"big\"")),
            &["radius"],
        );
    }

    #[test]
    fn the_shipped_scenes_parse() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
        for name in ["narrow_gap.toml", "one_disc.toml", "slalom.toml"] {
            let scene = load(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"));
            assert!(!scene.obstacles.is_empty(), "{name}");
        }
        // and any other scene shipped with them
        for entry in std::fs::read_dir(&dir).expect("examples/scenes") {
            let path = entry.expect("an entry").path();
            if path.extension().is_some_and(|e| e == "toml") {
                load(&path).unwrap_or_else(|e| panic!("{e}"));
            }
        }
    }
}
