//! A plan's certificate: the residuals and the curvature a plan is certified with, and the
//! advice a failure gives from them.

/// What a returned plan is certified to satisfy.
///
/// The residuals of a failed solve's last iterate may be NaN (not computed) or infinite; with
/// `serde`, a non-finite field is written as the string `"NaN"`, `"inf"` or `"-inf"` and read
/// back from it (or from `null`, as NaN), so that formats without such numbers (JSON) hold
/// them; finite fields are plain numbers.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Certificate {
    /// Max-norm of the gradient of the Lagrangian of the transcription, with the multipliers
    /// of the last subproblem, divided by $h \max(1, |\nabla L|_\infty, s_d)$: stationarity
    /// per unit time relative to the size of the gradient of $L$ and to IPOPT's scale of the
    /// multipliers, $s_d = \bar\lambda / 100$ with $\bar\lambda$ the mean modulus of the
    /// stage equalities', the inequalities' ($h z$) and the momenta's components.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub stationarity: f64,
    /// Max-norm of the constraint violation (dynamics defects, boundary data, stage
    /// equalities).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub feasibility: f64,
    /// $\max_j z_j g_j$ over the inequalities $g_j \ge 0$ with their multipliers $z_j$ (0
    /// without inequalities): how far the interior-point iterate is from complementarity.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub complementarity: f64,
    /// Negative eigenvalues of the reduced Hessian (0 for a returned plan).
    pub negative_directions: usize,
    /// The smallest eigenvalue of $Z^T \nabla^2 J\thinspace Z$, $Z$ an orthonormal basis of the
    /// null space of the constraint Jacobian in the variables $(x_1, \dots, x_{N-1}, u_0, \dots,
    /// u_{N-1})$ and the free components of $x_0$ and $x_N$; positive for a strict local
    /// minimum. With inequalities, the active ones enter as the penalties of the second-order
    /// check (a lower bound on the value on their null space too). Exactly 0 where the
    /// reduced Hessian is positive semidefinite and singular: a minimum, but not a strict one
    /// (the cost is flat to second order along some direction, e.g. ends that nothing fixes).
    /// $+\infty$ where the constraints leave no direction (e.g. $N = k$ steps between fixed
    /// ends: the plan is the one path that meets them). NaN if
    /// [`PlanOptions::min_eigenvalue`](crate::bvp::PlanOptions::min_eigenvalue) is off (the
    /// inertia count proves positivity either way).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub min_reduced_hessian_eig: f64,
}

/// The iterations after which a budget that ran out is not advised to be raised (the
/// constrained suite's hardest solve needs 1784).
pub(super) const LONG_RUN: usize = 2000;

/// What to do about a budget that ran out, from the residuals the last iterate reached after
/// `iterations`.
pub(super) fn advice(c: &Certificate, iterations: usize) -> &'static str {
    if c.feasibility <= 1e-6 && c.stationarity <= 1e-4 {
        "the iterate is feasible and nearly stationary: more iterations will not improve it \
         beyond rounding; a looser tolerance accepts it (or raise the acceptable level)"
    } else if c.feasibility.is_nan() || c.feasibility > 1e-3 {
        "the iterate is still far from feasible: start from a guess that satisfies the \
         constraints, or check that they can hold together"
    } else if iterations >= LONG_RUN {
        "the iteration is not settling: more iterations are unlikely to help; start from \
         another guess (one closer to a solution, or inside the constraints)"
    } else {
        "raise max_iterations, or start from a better guess"
    }
}

/// A certificate with nothing computed: the residuals NaN.
pub(in crate::bvp) fn unknown_certificate() -> Certificate {
    Certificate {
        stationarity: f64::NAN,
        feasibility: f64::NAN,
        complementarity: f64::NAN,
        negative_directions: 0,
        min_reduced_hessian_eig: f64::NAN,
    }
}
