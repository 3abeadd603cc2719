//! Integration tests of planning: the optimizer, the root finder, inequalities, extrapolation,
//! and the typed states, plan evaluation and path guesses around them.
//!
//! One test crate per group (fewer crates build and link faster): each module was a test
//! crate of its own; `common` holds the shared helpers and Lagrangians.

#[path = "../common/mod.rs"]
mod common;

mod attitude_slew;
mod batch;
mod budgets;
mod bvp;
mod car;
mod degenerate;
mod extrapolate;
mod free_end;
mod free_time;
mod inequalities;
mod mechanical;
mod mpc;
mod optimize;
mod placement;
mod plan_sensitivity;
mod realtime;
mod restoration;
mod sensitivity;
mod stage_systems;
mod typed_data;
mod vector_bounds;
mod warm_start;

// the systems written as their energy, shared with the example
#[path = "../../examples/common/mechanical.rs"]
mod mechanical_models;

// the cart-pole of the swing-up suite, shared with the examples
#[path = "../../examples/common/cart_pole.rs"]
mod cart_pole;

// the car's models and U-turn, shared with the example
#[path = "../../examples/common/car.rs"]
mod car_models;

// the parking car of the constrained suite, shared with `examples/constrained.rs`
#[path = "../../examples/common/parking.rs"]
mod parking;
// the quadrotor of the constrained suite, shared with `examples/constrained.rs`
#[path = "../../examples/common/quadrotor.rs"]
mod quadrotor;

// the double pendulum's models and receding-horizon loop, shared with the examples
#[path = "../../examples/common/pendulum.rs"]
mod pendulum;

// the receding-horizon benchmark's controller and loop, shared with `examples/mpc.rs`
#[path = "../../examples/common/upright.rs"]
mod upright;

// the spacecraft's attitude models and slew, shared with the example
#[path = "../../examples/common/attitude.rs"]
mod attitude;
