//! Attitude models on SO(3): the minimum-torque rigid body
//! L = 1/2 |J Omega' + Omega x J Omega|^2 written in body coordinates (`so3`, which the macro
//! composes with a Gibbs chart), composed with a Gibbs chart by hand (to check the former), and
//! in Z-Y-X Euler angles; a sun keep-out cone on the boresight in each, and the slew's boundary
//! data. Shared by `examples/attitude.rs` and the tests (by path).
#![allow(dead_code)] // each user takes a subset

use retract::bvp::{OptimalControlProblem, PlanOptions};
use retract::nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3, Vector4};
use retract::se3;
use retract::so3::{centred, chart_point};
use retract::{helper, higher_order_lagrangian, jet_function};

/// The inertia of the spacecraft.
pub const INERTIA: [f64; 3] = [1.0, 2.0, 3.0];
/// The slew: a turn by 170 degrees about the world y axis in `SLEW_TIME` s, rest to rest.
pub const SLEW_DEGREES: f64 = 170.0;
/// Its duration.
pub const SLEW_TIME: f64 = 10.0;
/// The boresight, in body axes.
pub const BORESIGHT: [f64; 3] = [0.0, 0.0, 1.0];
/// The half-angle of the sun keep-out cone, in degrees.
pub const CONE_DEGREES: f64 = 20.0;

/// The sun, in world axes: 60 degrees from the start's boresight towards +x (on the straight
/// slew's path), a little off its plane.
pub fn sun() -> Vector3<f64> {
    Vector3::new(60f64.to_radians().sin(), 0.15, 60f64.to_radians().cos()).normalize()
}

/// 1/2 |tau|^2 with tau = J w' + w x J w, J = diag(j), of the body velocity `w` and its
/// derivative `dw`.
#[helper]
pub fn effort(w: [f64; 3], dw: [f64; 3], j: [f64; 3]) -> f64 {
    let t0 = j[0] * dw[0] + (w[1] * j[2] * w[2] - w[2] * j[1] * w[1]);
    let t1 = j[1] * dw[1] + (w[2] * j[0] * w[0] - w[0] * j[2] * w[2]);
    let t2 = j[2] * dw[2] + (w[0] * j[1] * w[1] - w[1] * j[0] * w[0]);
    0.5 * (t0 * t0 + t1 * t1 + t2 * t2)
}

/// The body velocity and its derivative in the Gibbs chart, (Omega, Omega'):
/// Omega = s (y' - y x y'), s = 2 / (1 + |y|^2), and
/// Omega' = s (y'' - y x y'') - s^2 (y . y') (y' - y x y').
#[helper]
pub fn gibbs_rates(y: [f64; 3], dy: [f64; 3], ddy: [f64; 3]) -> [f64; 6] {
    let s = 2.0 / (1.0 + y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    let yv = y[0] * dy[0] + y[1] * dy[1] + y[2] * dy[2];
    let v0 = dy[0] - (y[1] * dy[2] - y[2] * dy[1]);
    let v1 = dy[1] - (y[2] * dy[0] - y[0] * dy[2]);
    let v2 = dy[2] - (y[0] * dy[1] - y[1] * dy[0]);
    let a0 = ddy[0] - (y[1] * ddy[2] - y[2] * ddy[1]);
    let a1 = ddy[1] - (y[2] * ddy[0] - y[0] * ddy[2]);
    let a2 = ddy[2] - (y[0] * ddy[1] - y[1] * ddy[0]);
    [
        s * v0,
        s * v1,
        s * v2,
        s * a0 - s * s * yv * v0,
        s * a1 - s * s * yv * v1,
        s * a2 - s * s * yv * v2,
    ]
}

/// The minimum-torque rigid body in the Gibbs chart: 1/2 |J Omega' + Omega x J Omega|^2
/// with the rates of [`gibbs_rates`].
#[higher_order_lagrangian(order = 2, helpers = [gibbs_rates, effort])]
pub fn min_torque(y: [f64; 3], dy: [f64; 3], ddy: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    let r = gibbs_rates(y, dy, ddy);
    effort([r[0], r[1], r[2]], [r[3], r[4], r[5]], [j1, j2, j3])
}

/// The minimum-torque rigid body written on SO(3) in body coordinates (`so3`):
/// L = 1/2 |J Omega' + Omega x J Omega|^2; the macro composes it with the Gibbs chart
/// centred at the parameter `so3_centre`, giving [`min_torque`].
#[higher_order_lagrangian(order = 2, so3, helpers = [effort])]
pub fn body_min_torque(_r: [f64; 9], w: [f64; 3], dw: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    effort(w, dw, [j1, j2, j3])
}

/// The boresight's clearance from the sun cone on SO(3) (`so3`): cos(cone) - (R b) . s with
/// b = e_z, R b the third column of R (row major: r[2], r[5], r[8]) and `sun` in world axes.
#[jet_function(order = 2, so3)]
pub fn sun_clearance(
    r: [f64; 9],
    _w: [f64; 3],
    _dw: [f64; 3],
    sun: [f64; 3],
    cos_cone: f64,
) -> f64 {
    cos_cone - (r[2] * sun[0] + r[5] * sun[1] + r[8] * sun[2])
}

/// The hand-composed chart form [`min_torque`] with [`INERTIA`].
pub fn gibbs_body() -> MinTorque {
    MinTorque {
        j1: INERTIA[0],
        j2: INERTIA[1],
        j3: INERTIA[2],
    }
}

/// The boresight's clearance from the sun cone in the Gibbs chart: cos(cone) - b . s with
/// b = R(y) e_z, R(y) = ((1 - |y|^2) I + 2 y y^T + 2 [y]x) / (1 + |y|^2), and `sun` in the
/// chart centre's axes.
#[jet_function(order = 2)]
pub fn gibbs_sun_clearance(
    y: [f64; 3],
    _dy: [f64; 3],
    _ddy: [f64; 3],
    sun: [f64; 3],
    cos_cone: f64,
) -> f64 {
    let n = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
    let bx = 2.0 * (y[0] * y[2] + y[1]) / (1.0 + n);
    let by = 2.0 * (y[1] * y[2] - y[0]) / (1.0 + n);
    let bz = (1.0 - n + 2.0 * y[2] * y[2]) / (1.0 + n);
    cos_cone - (bx * sun[0] + by * sun[1] + bz * sun[2])
}

/// The minimum-torque rigid body in Z-Y-X Euler angles q = (yaw, pitch, roll),
/// R = R_z(yaw) R_y(pitch) R_x(roll): Omega = (roll' - yaw' sin pitch,
/// pitch' cos roll + yaw' sin roll cos pitch, -pitch' sin roll + yaw' cos roll cos pitch)
/// and its total derivative. The map from rates to Omega loses rank at pitch = +-pi/2.
#[higher_order_lagrangian(order = 2, helpers = [effort])]
pub fn euler_torque(q: [f64; 3], dq: [f64; 3], ddq: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    let (sp, cp) = (q[1].sin(), q[1].cos());
    let (sr, cr) = (q[2].sin(), q[2].cos());
    let (yaw, pitch, roll) = (dq[0], dq[1], dq[2]);
    let (yaw2, pitch2, roll2) = (ddq[0], ddq[1], ddq[2]);
    let w0 = roll - yaw * sp;
    let w1 = pitch * cr + yaw * sr * cp;
    let w2 = -pitch * sr + yaw * cr * cp;
    let d0 = roll2 - yaw2 * sp - yaw * pitch * cp;
    let d1 = pitch2 * cr - pitch * roll * sr + yaw2 * sr * cp + yaw * roll * cr * cp
        - yaw * pitch * sr * sp;
    let d2 = -pitch2 * sr - pitch * roll * cr + yaw2 * cr * cp
        - yaw * roll * sr * cp
        - yaw * pitch * cr * sp;
    effort([w0, w1, w2], [d0, d1, d2], [j1, j2, j3])
}

/// The Euler-angle system with [`INERTIA`].
pub fn euler_body() -> EulerTorque {
    EulerTorque {
        j1: INERTIA[0],
        j2: INERTIA[1],
        j3: INERTIA[2],
    }
}

/// The boresight's clearance from the sun cone in Euler angles: b = R e_z =
/// (cos yaw sin pitch cos roll + sin yaw sin roll, sin yaw sin pitch cos roll - cos yaw sin
/// roll, cos pitch cos roll).
#[jet_function(order = 2)]
pub fn euler_sun_clearance(
    q: [f64; 3],
    _dq: [f64; 3],
    _ddq: [f64; 3],
    sun: [f64; 3],
    cos_cone: f64,
) -> f64 {
    let (sy, cy) = (q[0].sin(), q[0].cos());
    let (sp, cp) = (q[1].sin(), q[1].cos());
    let (sr, cr) = (q[2].sin(), q[2].cos());
    let bx = cy * sp * cr + sy * sr;
    let by = sy * sp * cr - cy * sr;
    let bz = cp * cr;
    cos_cone - (bx * sun[0] + by * sun[1] + bz * sun[2])
}

/// The slew's end rotations: the identity and the turn about world y.
pub fn slew_ends() -> (UnitQuaternion<f64>, UnitQuaternion<f64>) {
    let turn = UnitQuaternion::from_scaled_axis(Vector3::y() * SLEW_DEGREES.to_radians());
    (UnitQuaternion::identity(), turn)
}

/// The Gibbs chart of the slew: centred halfway (a turn by half the slew), where both ends
/// lie at |y| = tan(slew / 4); returns the centre and the start and goal jets (at rest).
pub fn gibbs_slew() -> (UnitQuaternion<f64>, [f64; 6], [f64; 6]) {
    let (start, goal) = slew_ends();
    let centre = UnitQuaternion::from_scaled_axis(Vector3::y() * (SLEW_DEGREES / 2.0).to_radians());
    let jet = |g: &UnitQuaternion<f64>| {
        let y = chart_point(&centre, g).expect("less than a half-turn from the centre");
        [y[0], y[1], y[2], 0.0, 0.0, 0.0]
    };
    (centre, jet(&start), jet(&goal))
}

/// The body form [`body_min_torque`] with [`INERTIA`], its chart centred at `centre`.
pub fn slew_body(centre: &UnitQuaternion<f64>) -> BodyMinTorque {
    centred(
        &BodyMinTorque::new(INERTIA[0], INERTIA[1], INERTIA[2]),
        centre,
    )
}

/// The sun cone on SO(3) ([`sun_clearance`], the sun in world axes), its chart centred at
/// `centre`.
pub fn slew_cone(centre: &UnitQuaternion<f64>) -> SunClearance {
    let cone = SunClearance::new(sun().into(), CONE_DEGREES.to_radians().cos());
    centred(&cone, centre)
}

/// The hand-composed sun cone in the Gibbs chart centred at `centre` (the sun in the
/// centre's axes): [`slew_cone`] written out, to check it.
pub fn gibbs_cone(centre: &UnitQuaternion<f64>) -> GibbsSunClearance {
    let sun = centre.inverse() * sun();
    GibbsSunClearance::new(sun.into(), CONE_DEGREES.to_radians().cos())
}

/// The slew of the body form `system` (centred as the jets' chart) with `steps` steps (the
/// cone is added by the caller).
pub fn gibbs_problem<'a>(
    system: &'a BodyMinTorque,
    start: &[f64; 6],
    goal: &[f64; 6],
    steps: usize,
) -> OptimalControlProblem<'a, BodyMinTorque, 3, 2, 6> {
    OptimalControlProblem::new(system, start, goal, SLEW_TIME, steps)
        .with_options(PlanOptions::default().with_min_eigenvalue(true))
}

/// The free rigid body in Z-Y-X Euler angles: L = 1/2 Omega . J Omega with Omega of
/// [`euler_torque`]; its Legendre map is singular at pitch = +-pi/2.
#[higher_order_lagrangian(order = 1)]
pub fn euler_free(q: [f64; 3], dq: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    let (sp, cp) = (q[1].sin(), q[1].cos());
    let (sr, cr) = (q[2].sin(), q[2].cos());
    let w0 = dq[2] - dq[0] * sp;
    let w1 = dq[1] * cr + dq[0] * sr * cp;
    let w2 = -dq[1] * sr + dq[0] * cr * cp;
    0.5 * (j1 * w0 * w0 + j2 * w1 * w1 + j3 * w2 * w2)
}

/// Euler's equations J Omega' = (J Omega) x Omega with q' = q (0, Omega) / 2 from the
/// identity with body velocity `omega`, by RK4 with `steps` steps: the rotation at `t`.
pub fn euler_reference(omega: Vector3<f64>, t: f64, steps: usize) -> UnitQuaternion<f64> {
    let j = Vector3::from(INERTIA);
    let rhs = |q: &Vector4<f64>, w: &Vector3<f64>| {
        let dw = j.component_mul(w).cross(w).component_div(&j);
        let v = Vector3::new(q[1], q[2], q[3]);
        let dv = w * q[0] + v.cross(w);
        (Vector4::new(-v.dot(w), dv[0], dv[1], dv[2]) * 0.5, dw)
    };
    let h = t / steps as f64;
    let (mut q, mut w) = (Vector4::new(1.0, 0.0, 0.0, 0.0), omega);
    for _ in 0..steps {
        let (a1, b1) = rhs(&q, &w);
        let (a2, b2) = rhs(&(q + a1 * (h / 2.0)), &(w + b1 * (h / 2.0)));
        let (a3, b3) = rhs(&(q + a2 * (h / 2.0)), &(w + b2 * (h / 2.0)));
        let (a4, b4) = rhs(&(q + a3 * h), &(w + b3 * h));
        q += (a1 + a2 * 2.0 + a3 * 2.0 + a4) * (h / 6.0);
        w += (b1 + b2 * 2.0 + b3 * 2.0 + b4) * (h / 6.0);
    }
    UnitQuaternion::new_normalize(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// The free rigid body in the Gibbs chart: L = 1/2 Omega . J Omega with
/// Omega = 2 (y' - y x y') / (1 + |y|^2).
#[higher_order_lagrangian(order = 1)]
pub fn gibbs_free(y: [f64; 3], dy: [f64; 3], j1: f64, j2: f64, j3: f64) -> f64 {
    let s = 2.0 / (1.0 + y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    let w0 = s * (dy[0] - (y[1] * dy[2] - y[2] * dy[1]));
    let w1 = s * (dy[1] - (y[2] * dy[0] - y[0] * dy[2]));
    let w2 = s * (dy[2] - (y[0] * dy[1] - y[1] * dy[0]));
    0.5 * (j1 * w0 * w0 + j2 * w1 * w1 + j3 * w2 * w2)
}

/// The free body with [`INERTIA`] in the Gibbs chart.
pub fn gibbs_free_body() -> GibbsFree {
    GibbsFree {
        j1: INERTIA[0],
        j2: INERTIA[1],
        j3: INERTIA[2],
    }
}

/// A fully actuated rigid body in SE(3) composed with the product chart at the identity by
/// hand, x = (y, p): its attitude in the Gibbs chart and its position p in world axes (to
/// check [`body_flight`]); the effort 1/2 |tau|^2 + 1/2 |m p''|^2 of the body torque and
/// the force.
#[higher_order_lagrangian(order = 2, helpers = [gibbs_rates, effort])]
pub fn se3_effort(
    x: [f64; 6],
    dx: [f64; 6],
    ddx: [f64; 6],
    j1: f64,
    j2: f64,
    j3: f64,
    mass: f64,
) -> f64 {
    let r = gibbs_rates(
        [x[0], x[1], x[2]],
        [dx[0], dx[1], dx[2]],
        [ddx[0], ddx[1], ddx[2]],
    );
    let force = mass * mass * (ddx[3] * ddx[3] + ddx[4] * ddx[4] + ddx[5] * ddx[5]);
    effort([r[0], r[1], r[2]], [r[3], r[4], r[5]], [j1, j2, j3]) + 0.5 * force
}

/// The body of [`se3_effort`] with [`INERTIA`] and mass 1.
pub fn se3_body() -> Se3Effort {
    Se3Effort {
        j1: INERTIA[0],
        j2: INERTIA[1],
        j3: INERTIA[2],
        mass: 1.0,
    }
}

/// The spheres the body flies among: (centre, radius).
pub const SPHERES: [([f64; 3], f64); 3] = [
    ([1.2, 0.15, 0.0], 0.5),
    ([2.4, -0.25, 0.1], 0.45),
    ([3.4, 0.3, -0.1], 0.4),
];

/// The flight: from rest at the origin, unrotated, to rest at (4.5, 0, 0) turned by 120
/// degrees about the axis (0.2, 0.3, 1), in 6 s; the jets in the product chart at the
/// identity (`retract::se3::chart_point`).
/// (About a principal axis the planar turn is a stationary point by symmetry, and for the
/// largest inertia not a minimum: the optimizer reports `NotAMinimum` there.)
pub fn se3_flight() -> ([f64; 12], [f64; 12], f64) {
    let axis = Vector3::new(0.2, 0.3, 1.0).normalize();
    let turn = UnitQuaternion::from_scaled_axis(axis * 120f64.to_radians());
    let end = Isometry3::from_parts(Translation3::new(4.5, 0.0, 0.0), turn);
    let point = se3::chart_point(&Isometry3::identity(), &end).expect("less than a half-turn");
    let mut goal = [0.0; 12];
    goal[..6].copy_from_slice(point.as_slice());
    ([0.0; 12], goal, 6.0)
}

/// A fully actuated rigid body written on SE(3) in body coordinates (`se3`): the effort
/// 1/2 |tau|^2 + 1/2 |f|^2 of the body torque tau = J Omega' + Omega x J Omega and the body
/// force f = m (v' + Omega x v) (|f| = |m p''|, since p'' = R (v' + Omega x v)); the macro
/// composes it with the product chart centred at `se3_centre`, giving [`se3_effort`].
#[higher_order_lagrangian(order = 2, se3, helpers = [effort])]
pub fn body_flight(
    _g: [f64; 12],
    xi: [f64; 6],
    dxi: [f64; 6],
    j1: f64,
    j2: f64,
    j3: f64,
    mass: f64,
) -> f64 {
    let f0 = mass * (dxi[3] + xi[1] * xi[5] - xi[2] * xi[4]);
    let f1 = mass * (dxi[4] + xi[2] * xi[3] - xi[0] * xi[5]);
    let f2 = mass * (dxi[5] + xi[0] * xi[4] - xi[1] * xi[3]);
    let w = [xi[0], xi[1], xi[2]];
    let dw = [dxi[0], dxi[1], dxi[2]];
    effort(w, dw, [j1, j2, j3]) + 0.5 * (f0 * f0 + f1 * f1 + f2 * f2)
}

/// [`body_flight`] with [`INERTIA`] and mass 1, its chart at the identity (where the chart
/// jet of the position is the position).
pub fn flight_body() -> BodyFlight {
    BodyFlight::new(INERTIA[0], INERTIA[1], INERTIA[2], 1.0)
}

/// The position's clearance from a sphere on SE(3) (`se3`): |p - centre|^2 - radius^2 with
/// p = g[9..12] in world axes.
#[jet_function(order = 2, se3)]
pub fn clear_of_sphere(
    g: [f64; 12],
    _xi: [f64; 6],
    _dxi: [f64; 6],
    centre: [f64; 3],
    radius: f64,
) -> f64 {
    let (a, b, c) = (g[9] - centre[0], g[10] - centre[1], g[11] - centre[2]);
    a * a + b * b + c * c - radius * radius
}

/// The free rigid body on SE(3) (`se3`) whose centre of mass sits at `r` in the body frame,
/// so that rotation and translation of the pose couple: L = 1/2 Omega . J Omega +
/// 1/2 m |v + Omega x r|^2, J the inertia about the centre of mass.
#[higher_order_lagrangian(order = 1, se3)]
pub fn offset_free_body(
    _g: [f64; 12],
    xi: [f64; 6],
    j1: f64,
    j2: f64,
    j3: f64,
    m: f64,
    r: [f64; 3],
) -> f64 {
    let c0 = xi[3] + xi[1] * r[2] - xi[2] * r[1];
    let c1 = xi[4] + xi[2] * r[0] - xi[0] * r[2];
    let c2 = xi[5] + xi[0] * r[1] - xi[1] * r[0];
    0.5 * (j1 * xi[0] * xi[0] + j2 * xi[1] * xi[1] + j3 * xi[2] * xi[2])
        + 0.5 * m * (c0 * c0 + c1 * c1 + c2 * c2)
}

/// The centre of mass of [`offset_body`] in the body frame.
pub const OFFSET: [f64; 3] = [0.3, -0.2, 0.5];

/// [`offset_free_body`] with [`INERTIA`], mass 2 and its centre of mass at [`OFFSET`].
pub fn offset_body() -> OffsetFreeBody {
    OffsetFreeBody::new(INERTIA[0], INERTIA[1], INERTIA[2], 2.0, OFFSET)
}
