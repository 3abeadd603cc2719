//! Mechanical systems written as their energy T - V (`#[mechanical_system]`): the double
//! pendulum of the swing-up suite, the planar quadrotor of the constrained suite (C2) driven
//! through its actuation matrix B(q), and the planar n-link chain (C4). Shared by
//! `examples/energy.rs` and the tests (by path).
#![allow(dead_code)] // each user takes a subset

use retract::{helper, mechanical_system};

/// The double pendulum of the swing-up suite as its energy (angles from the downward
/// vertical, the second relative to the first, point masses at the rod ends): fully actuated,
/// so the generated cost is 1/2 |tau|^2.
#[mechanical_system]
pub fn double_pendulum_energy(
    q: [f64; 2],
    dq: [f64; 2],
    m1: f64,
    m2: f64,
    l1: f64,
    l2: f64,
    g: f64,
) -> f64 {
    // the positions of the two masses, differentiated by hand only for their velocities
    let (a, b) = (q[0], q[0] + q[1]);
    let (da, db) = (dq[0], dq[0] + dq[1]);
    let v1 = [l1 * a.cos() * da, l1 * a.sin() * da];
    let v2 = [v1[0] + l2 * b.cos() * db, v1[1] + l2 * b.sin() * db];
    let kinetic =
        0.5 * m1 * (v1[0] * v1[0] + v1[1] * v1[1]) + 0.5 * m2 * (v2[0] * v2[0] + v2[1] * v2[1]);
    let potential = -(m1 + m2) * g * l1 * a.cos() - m2 * g * l2 * b.cos();
    kinetic - potential
}

/// The generalized forces of the two rotor thrusts of the planar quadrotor, the columns of
/// B(q): each pushes along the body axis (-sin(theta), cos(theta)) at the arm a, the first
/// turning it by -a, the second by +a.
#[helper]
pub fn rotor_forces(q: [f64; 3], arm: f64) -> ([f64; 3], [f64; 3]) {
    let (s, c) = (q[2].sin(), q[2].cos());
    ([-s, c, -arm], [-s, c, arm])
}

/// The planar quadrotor of the constrained suite (C2) as its energy, q = (x, z, theta):
/// T = m/2 (x'^2 + z'^2) + I/2 theta'^2, V = m g z, driven by the rotor thrusts u = (f1, f2)
/// through B(q) (`rotor_forces`). The generated u = (B^T B)^{-1} B^T tau is the suite's
/// f1,2 = Th/2 -+ tq/(2a), and the passive equality a^T tau = 2 a (fx cos(theta) + fz
/// sin(theta)) its lateral force.
#[mechanical_system(input_matrix = rotor_forces)]
pub fn quadrotor_energy(q: [f64; 3], dq: [f64; 3], m: f64, inertia: f64, arm: f64, g: f64) -> f64 {
    let kinetic = 0.5 * m * (dq[0] * dq[0] + dq[1] * dq[1]) + 0.5 * inertia * dq[2] * dq[2];
    kinetic - m * g * q[1]
}

/// The planar n-link chain of the constrained suite (C4) as its energy: unit links, unit
/// point masses at the link ends, joint angles relative to the previous link (q_0 from the
/// downward vertical), g = 9.81; every joint driven. The velocities of the masses accumulate
/// link by link (phi the absolute angle): v_j = v_{j-1} + phi_j' (cos phi_j, sin phi_j).
#[macro_export]
macro_rules! energy_chain {
    ($name:ident, $n:literal) => {
        #[doc = concat!("The ", stringify!($n), "-link chain as T - V (see `energy_chain!`).")]
        #[retract::mechanical_system]
        pub fn $name(q: [f64; $n], dq: [f64; $n]) -> f64 {
            let (mut phi, mut dphi) = (0.0, 0.0);
            let (mut vx, mut vz, mut height) = (0.0, 0.0, 0.0);
            let mut energy = 0.0;
            for i in 0..$n {
                phi += q[i];
                dphi += dq[i];
                vx += phi.cos() * dphi;
                vz += phi.sin() * dphi;
                height -= phi.cos();
                energy += 0.5 * (vx * vx + vz * vz) - 9.81 * height;
            }
            energy
        }
    };
}
