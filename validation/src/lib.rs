//! Benchmarks (`benches/`), the speed report and the work-precision comparison with ODE
//! peers (`examples/report.rs`, `examples/work_precision.rs`) and the heavier test suites of
//! `retract` (the property tests of the generated derivatives, `tests/`; the compile-fail tests
//! of the macros are in `ui/`). It is kept apart so that `cargo run --example ...` in `retract`
//! does not build criterion, proptest, num-dual or ode_solvers.
//!
//! The library holds what the benches and the examples share, one implementation each: the
//! systems ([`systems`]), the peers ([`peers`]: hand-written steps, dual-number and
//! finite-difference Newton, RK4 and DOP853 on plain right-hand sides), the timing
//! ([`timing`]: interleaved rounds) and the measurements ([`step_speed`], [`guard_cost`],
//! [`work_precision`], [`long_run`], [`planner_speed`], [`batch_speed`], [`expansion_cost`],
//! [`sphere_cubic`], [`receding_horizon`]), which [`report`] runs and prints in one go.

pub mod batch_speed;
mod error;
pub mod expansion_cost;
pub mod guard_cost;
pub mod long_run;
/// The Lagrangians shared with `retract`'s integration tests (`tests/common/models.rs`).
#[path = "../../tests/common/models.rs"]
pub mod models;
pub mod peers;
/// The double pendulum of `retract`'s examples (`examples/common/pendulum.rs`).
#[path = "../../examples/common/pendulum.rs"]
mod pendulum;
pub mod planner_speed;
pub mod receding_horizon;
pub mod report;
pub mod sphere_cubic;
pub mod step_speed;
pub mod systems;
pub mod timing;
/// The receding-horizon loop of `retract`'s examples (`examples/common/upright.rs`).
#[path = "../../examples/common/upright.rs"]
mod upright;
pub mod work_precision;

pub use error::Error;
