//! The peers `retract` is measured against, one implementation each:
//! - hand-written midpoint steps of the SE(2) obstacle system (tau = [`TAU`], h = [`H`]): a
//!   dense 12x12 Newton with the Jacobian by hand, by dual numbers (num-dual) or by central
//!   finite differences, a hand-reduced 3x3 Newton on $q_\theta$, with and without the
//!   generated step's domain check, and the tight reduced step (Newton on the two nonlinear
//!   unknowns, a closed-form 2x2 solve, the guard in one expression);
//! - RK4 and DOP853 (ode_solvers) on the plain first-order system ([`Plain`]), their best
//!   form, and DOP853 on a generated system's Hamilton equations ([`Hamilton`]).

use num_dual::{DualNum, jacobian};
use ode_solvers::{Dop853, System};
use retract::LiftedSystem;
use retract::nalgebra::{SMatrix, SVector, Vector3};
use retract::newton::{NewtonOptions, Problem, solve};

use crate::Error;
use crate::systems::{H, TAU, Z};

/// grad V and Hess V of V = tau / (x^2 + y^2 - 1) (the theta row and column are zero).
fn grad_hess(q: &Vector3<f64>) -> (Vector3<f64>, SMatrix<f64, 3, 3>) {
    let s = q[0] * q[0] + q[1] * q[1] - 1.0;
    let g = Vector3::new(
        -2.0 * TAU * q[0] / (s * s),
        -2.0 * TAU * q[1] / (s * s),
        0.0,
    );
    let mut hess = SMatrix::<f64, 3, 3>::zeros();
    for a in 0..2 {
        for b in 0..2 {
            let delta = if a == b { 1.0 } else { 0.0 };
            hess[(a, b)] = -2.0 * TAU * delta / (s * s) + 8.0 * TAU * q[a] * q[b] / (s * s * s);
        }
    }
    (g, hess)
}

/// The dense midpoint residual on z_1 = (q, v, p0, p1), generic for dual numbers:
/// F_q = q1 - q0 - h v_th, F_v = v1 - v0 - h p1_th, F_p0 = p0_1 - p0_0 - h grad V(q_th),
/// F_p1 = p1_1 - p1_0 + h p0_th.
pub fn dense_residual<T: DualNum<Primitive = f64> + Copy>(
    z0: &Z,
    z1: &SVector<T, 12>,
) -> SVector<T, 12> {
    let h = H;
    let half = |i: usize| (z1[i] + z0[i]) * 0.5;
    let (x, y) = (half(0), half(1));
    let s = x * x + y * y - 1.0;
    let gv = [
        x * (-2.0 * TAU) / (s * s),
        y * (-2.0 * TAU) / (s * s),
        T::from(0.0),
    ];
    SVector::from_fn(|r, _| match r / 3 {
        0 => z1[r] - z0[r] - half(r + 3) * h,
        1 => z1[r] - z0[r] - half(r + 6) * h,
        2 => z1[r] - z0[r] - gv[r - 6] * h,
        _ => z1[r] - z0[r] + half(r - 3) * h,
    })
}

/// The hand-written Jacobian of [`dense_residual`].
pub fn dense_jacobian(z0: &Z, z1: &Z) -> SMatrix<f64, 12, 12> {
    let mut j = SMatrix::<f64, 12, 12>::identity();
    let q_th = Vector3::new(
        0.5 * (z0[0] + z1[0]),
        0.5 * (z0[1] + z1[1]),
        0.5 * (z0[2] + z1[2]),
    );
    let (_, hess) = grad_hess(&q_th);
    for i in 0..3 {
        j[(i, 3 + i)] = -0.5 * H;
        j[(3 + i, 9 + i)] = -0.5 * H;
        j[(9 + i, 6 + i)] = 0.5 * H;
        for b in 0..3 {
            j[(6 + i, b)] = -0.5 * H * hess[(i, b)];
        }
    }
    j
}

/// How the dense Newton gets its Jacobian.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DenseJacobian {
    /// By hand ([`dense_jacobian`]).
    Hand,
    /// Forward-mode dual numbers (num-dual).
    Dual,
    /// Central finite differences.
    FiniteDifferences,
}

/// The dense 12x12 midpoint system from `z0`.
pub struct Dense<'a> {
    /// The state the step starts from.
    pub z0: &'a Z,
    /// How the Jacobian is computed.
    pub jacobian: DenseJacobian,
}

impl Problem<12> for Dense<'_> {
    fn residual(&self, z1: &Z) -> Z {
        dense_residual(self.z0, z1)
    }

    fn jacobian(&self, z1: &Z) -> SMatrix<f64, 12, 12> {
        match self.jacobian {
            DenseJacobian::Hand => dense_jacobian(self.z0, z1),
            DenseJacobian::Dual => jacobian(|z| dense_residual(self.z0, &z), z1).1,
            DenseJacobian::FiniteDifferences => SMatrix::from_fn(|r, c| {
                let eps = 1e-7 * (1.0 + z1[c].abs());
                let (mut plus, mut minus) = (*z1, *z1);
                plus[c] += eps;
                minus[c] -= eps;
                (dense_residual(self.z0, &plus)[r] - dense_residual(self.z0, &minus)[r])
                    / (2.0 * eps)
            }),
        }
    }
}

/// One midpoint step by a dense Newton on [`Dense`] from an explicit predictor.
///
/// # Errors
/// [`Error::Retract`] if Newton fails.
pub fn dense_step(z0: &Z, jacobian: DenseJacobian) -> Result<Z, Error> {
    let guess = z0
        + SVector::from_fn(|r, _| match r / 3 {
            0 => H * z0[r + 3],
            1 => H * z0[r + 6],
            3 => -H * z0[r - 3],
            _ => 0.0,
        });
    Ok(solve(&Dense { z0, jacobian }, guess, &NewtonOptions::default())?.w)
}

/// Hand-reduced midpoint step: y = q_theta solves
/// y - (q0 + h/2 v0 + h^2/4 p1_0 - h^3/8 p0_0) + h^4/16 grad V(y) = 0; the rest is explicit.
pub struct Core {
    /// The force-free midpoint $q_0 + h/2\thinspace v_0 + h^2/4\thinspace p_{1,0} - h^3/8\thinspace p_{0,0}$.
    pub c0: Vector3<f64>,
}

impl Problem<3> for Core {
    fn residual(&self, y: &Vector3<f64>) -> Vector3<f64> {
        y - self.c0 + grad_hess(y).0 * (H.powi(4) / 16.0)
    }
    fn jacobian(&self, y: &Vector3<f64>) -> SMatrix<f64, 3, 3> {
        SMatrix::identity() + grad_hess(y).1 * (H.powi(4) / 16.0)
    }
}

/// One midpoint step by the hand-reduced 3x3 Newton ([`Core`]).
///
/// # Errors
/// [`Error::Retract`] if Newton fails.
pub fn hand_reduced_step(z0: &Z) -> Result<Z, Error> {
    let (q, v, p0, p1) = (
        z0.fixed_rows::<3>(0),
        z0.fixed_rows::<3>(3),
        z0.fixed_rows::<3>(6),
        z0.fixed_rows::<3>(9),
    );
    let c0 = q + v * (H / 2.0) + p1 * (H * H / 4.0) - p0 * (H.powi(3) / 8.0);
    let guess = c0 - grad_hess(&c0).0 * (H.powi(4) / 16.0);
    let y = solve(&Core { c0 }, guess, &NewtonOptions::default())?.w;
    let g = grad_hess(&y).0;
    let p0_1 = p0 + g * H;
    let p0_th = p0 + g * (H / 2.0);
    let p1_1 = p1 - p0_th * H;
    let u = p1 - p0_th * (H / 2.0);
    let v1 = v + u * H;
    let q1 = y * 2.0 - q;
    let mut z1 = Z::zeros();
    z1.fixed_rows_mut::<3>(0).copy_from(&q1);
    z1.fixed_rows_mut::<3>(3).copy_from(&v1);
    z1.fixed_rows_mut::<3>(6).copy_from(&p0_1);
    z1.fixed_rows_mut::<3>(9).copy_from(&p1_1);
    Ok(z1)
}

/// The hand-written step with the generated step's domain check: s = x^2 + y^2 - 1 is finite,
/// non-zero and of one sign at q_0, q_theta and q_1.
///
/// # Errors
/// [`Error::Retract`] if Newton fails, [`Error::Domain`] if the check fails.
pub fn hand_guarded_step(z0: &Z) -> Result<Z, Error> {
    let z1 = hand_reduced_step(z0)?;
    let s = |x: f64, y: f64| x * x + y * y - 1.0;
    let (a, b, c) = (
        s(z0[0], z0[1]),
        s(0.5 * (z0[0] + z1[0]), 0.5 * (z0[1] + z1[1])),
        s(z1[0], z1[1]),
    );
    let positive = a > 0.0 && b > 0.0 && c > 0.0 && a.max(b).max(c) < f64::INFINITY;
    let negative = a < 0.0 && b < 0.0 && c < 0.0 && a.min(b).min(c) > f64::NEG_INFINITY;
    if positive || negative {
        Ok(z1)
    } else {
        Err(Error::Domain("the hand-written guarded step"))
    }
}

/// The tight hand-written reduced step, a peer at the limit of the algorithm. The theta
/// row of [`Core`] is linear ($\partial V/\partial\theta = 0$, so $y_\theta = c_{0,\theta}$);
/// Newton runs on the two nonlinear unknowns $w = (y_x, y_y)$ of
/// $r(w) = a(s)\thinspace w - c$, $a = 1 - 2\tau k/s^2$, $s = |w|^2 - 1$, $k = h^4/16$, from
/// the explicit predictor $a(s(c))\thinspace c$, until $\Vert r\Vert_\infty \le 10^{-14}$ or
/// a step $\Vert\Delta\Vert_\infty \le 10^{-15} + 10^{-10}\Vert w\Vert_\infty$ (the
/// library's default tests). The Jacobian $a I + b\thinspace w w^T$
/// ($b = 8\tau k/s^3$) is solved in closed form (Sherman-Morrison,
/// $J^{-1} r = (r - t\thinspace w)/a$ with $t = b\thinspace (w \cdot r)/m$,
/// $m = a + b|w|^2$), with three divisions an iteration ($1/s$, then $1/a$ and $1/m$
/// together). The guard is the generated guard's test in one expression: $s$ finite and of
/// one sign at $q_0$, $q_\theta$ and $q_1$, and outside the disc the minimum of $s$ along
/// the chord (a quadratic, $s_0 - p^2/|d|^2$ with $d = q_1 - q_0$, $p = q_0 \cdot d$, where
/// its vertex lies inside the step) above $10^{-9}$ of the largest sample. No rounding
/// compensation.
///
/// # Errors
/// [`Error::Domain`] if Newton does not converge in 50 iterations or the guard fails.
pub fn tight_guarded_step(z0: &Z) -> Result<Z, Error> {
    let k2 = 2.0 * TAU * H * H * H * H / 16.0;
    let (q, v, p0, p1) = (
        z0.fixed_rows::<3>(0),
        z0.fixed_rows::<3>(3),
        z0.fixed_rows::<3>(6),
        z0.fixed_rows::<3>(9),
    );
    let c = q + v * (H / 2.0) + p1 * (H * H / 4.0) - p0 * (H * H * H / 8.0);
    // the explicit predictor a(s(c)) c
    let s_c = c[0] * c[0] + c[1] * c[1] - 1.0;
    let a_c = 1.0 - k2 / (s_c * s_c);
    let (mut x, mut y) = (c[0] * a_c, c[1] * a_c);
    let mut found = None;
    for _ in 0..50 {
        let s = x * x + y * y - 1.0;
        let inv_s = 1.0 / s;
        let inv_s2 = inv_s * inv_s;
        let a = 1.0 - k2 * inv_s2;
        let (rx, ry) = (a * x - c[0], a * y - c[1]);
        if rx.abs().max(ry.abs()) <= 1e-14 {
            found = Some((s, inv_s2));
            break;
        }
        let b = 4.0 * k2 * inv_s2 * inv_s;
        let m = a + b * (x * x + y * y);
        // (two independent divisions: they overlap in the divider)
        let (inv_a, inv_m) = (1.0 / a, 1.0 / m);
        let t = b * (x * rx + y * ry) * inv_m;
        x -= (rx - t * x) * inv_a;
        y -= (ry - t * y) * inv_a;
    }
    let Some((s_th, inv_s2)) = found else {
        return Err(Error::Domain("the tight hand-written step: no convergence"));
    };
    let q1 = Vector3::new(2.0 * x - q[0], 2.0 * y - q[1], 2.0 * c[2] - q[2]);
    let s0 = q[0] * q[0] + q[1] * q[1] - 1.0;
    let s1 = q1[0] * q1[0] + q1[1] * q1[1] - 1.0;
    // s along the chord q0 + sigma d is the quadratic s0 + 2 sigma p + sigma^2 |d|^2; outside
    // the disc its minimum inside the step, s0 - p^2/|d|^2, must stay clear of zero (relative
    // 1e-9, as the generated guard's fit); inside, s is convex along the chord
    let (dx, dy) = (q1[0] - q[0], q1[1] - q[1]);
    let (p, dd) = (q[0] * dx + q[1] * dy, dx * dx + dy * dy);
    let scale = s0.max(s_th).max(s1);
    let clear = !(p < 0.0 && -p < dd) || s0 * dd - p * p > 1e-9 * scale * dd;
    let one_sign = s0 * s_th > 0.0 && s0 * s1 > 0.0 && (s0 * s_th * s1).is_finite();
    if !(one_sign && (s0 < 0.0 || clear)) {
        return Err(Error::Domain("the tight hand-written step: the guard"));
    }
    let g = Vector3::new(x, y, 0.0) * (-2.0 * TAU * inv_s2);
    let p0_th = p0 + g * (H / 2.0);
    let mut z1 = Z::zeros();
    z1.fixed_rows_mut::<3>(0).copy_from(&q1);
    z1.fixed_rows_mut::<3>(3)
        .copy_from(&(v + (p1 - p0_th * (H / 2.0)) * H));
    z1.fixed_rows_mut::<3>(6).copy_from(&(p0 + g * H));
    z1.fixed_rows_mut::<3>(9).copy_from(&(p1 - p0_th * H));
    Ok(z1)
}

/// The obstacle model's Euler-Lagrange equation as a plain first-order system, the peers'
/// best form: y = (q, q', q'', q'''), y' = (q', q'', q''', -grad V(q)) with
/// V = tau / (q_0^2 + q_1^2 - r^2), so -grad V = 2 tau (q_0, q_1, 0) / d^2.
#[derive(Clone, Copy, Debug)]
pub struct Plain {
    /// The barrier weight.
    pub tau: f64,
    /// The disc's radius.
    pub r: f64,
}

impl Plain {
    /// The right-hand side at `y`.
    pub fn rhs(&self, y: &Z) -> Z {
        let d = y[0] * y[0] + y[1] * y[1] - self.r * self.r;
        let c = 2.0 * self.tau / (d * d);
        let mut dy = Z::zeros();
        dy.fixed_rows_mut::<9>(0).copy_from(&y.fixed_rows::<9>(3));
        dy[9] = c * y[0];
        dy[10] = c * y[1];
        dy
    }

    /// Classical RK4 with `steps` steps to `t_end`.
    pub fn rk4(&self, y0: &Z, t_end: f64, steps: usize) -> Z {
        let h = t_end / steps as f64;
        (0..steps).fold(*y0, |y, _| {
            let k1 = self.rhs(&y);
            let k2 = self.rhs(&(y + k1 * (h / 2.0)));
            let k3 = self.rhs(&(y + k2 * (h / 2.0)));
            let k4 = self.rhs(&(y + k3 * h));
            y + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)
        })
    }
}

impl System<f64, ode_solvers::SVector<f64, 12>> for Plain {
    fn system(
        &self,
        _t: f64,
        y: &ode_solvers::SVector<f64, 12>,
        dy: &mut ode_solvers::SVector<f64, 12>,
    ) {
        let f = self.rhs(&SVector::from_column_slice(y.as_slice()));
        dy.as_mut_slice().copy_from_slice(f.as_slice());
    }
}

/// Hamilton's equations of a generated system for ode_solvers (its own nalgebra version);
/// NaN where the vector field is not defined.
pub struct Hamilton<'a, Sys, const M: usize>(pub &'a Sys);

impl<Sys: LiftedSystem<S, M>, const S: usize, const M: usize>
    System<f64, ode_solvers::SVector<f64, S>> for Hamilton<'_, Sys, M>
{
    fn system(
        &self,
        _t: f64,
        y: &ode_solvers::SVector<f64, S>,
        dy: &mut ode_solvers::SVector<f64, S>,
    ) {
        let z = SVector::<f64, S>::from_column_slice(y.as_slice());
        let f = self
            .0
            .vector_field(&z)
            .unwrap_or_else(|_| SVector::repeat(f64::NAN));
        dy.as_mut_slice().copy_from_slice(f.as_slice());
    }
}

/// A DOP853 run: the states after every accepted step and the number of accepted steps.
pub struct Dop853Run<const S: usize> {
    /// (t, y) after every accepted step, from t = 0.
    pub states: Vec<(f64, SVector<f64, S>)>,
    /// Accepted steps.
    pub accepted_steps: u32,
}

impl<const S: usize> Dop853Run<S> {
    /// The state at the end.
    ///
    /// # Errors
    /// [`Error::Peer`] if the run has no state.
    pub fn end(&self) -> Result<SVector<f64, S>, Error> {
        self.states
            .last()
            .map(|s| s.1)
            .ok_or_else(|| Error::Peer("DOP853 returned no state".into()))
    }
}

/// DOP853 (ode_solvers' defaults: safety 0.9, step factors in [1/3, 6]) on the right-hand
/// side `f` from `y0` to `t_end` with rtol = atol = `tol` and steps at most `h_max`. Its
/// dense output is not used: in ode_solvers 0.6.2 it is inaccurate for coarse output
/// intervals.
///
/// # Errors
/// [`Error::Peer`] if DOP853 fails.
pub fn dop853<F: System<f64, ode_solvers::SVector<f64, S>>, const S: usize>(
    f: F,
    y0: &SVector<f64, S>,
    t_end: f64,
    tol: f64,
    h_max: f64,
) -> Result<Dop853Run<S>, Error> {
    let y0 = ode_solvers::SVector::<f64, S>::from_column_slice(y0.as_slice());
    let mut solver = Dop853::from_param(
        f,
        0.0,
        t_end,
        t_end,
        y0,
        tol,
        tol,
        0.9,
        0.0,
        0.333,
        6.0,
        h_max,
        0.0,
        u32::MAX,
        1000,
        ode_solvers::dop_shared::OutputType::Sparse,
    );
    let stats = solver
        .integrate()
        .map_err(|e| Error::Peer(format!("DOP853: {e:?}")))?;
    let states = solver
        .x_out()
        .iter()
        .zip(solver.y_out())
        .map(|(t, y)| (*t, SVector::from_column_slice(y.as_slice())))
        .collect();
    Ok(Dop853Run {
        states,
        accepted_steps: stats.accepted_steps,
    })
}
