//! One step of the lifted theta-scheme, and trajectories.
//!
//! A step solves $F(z_0, w) = 0$ (see [`LiftedSystem`]) for $w = (z_1, \dots)$ by
//! [`newton::solve`](crate::numeric::newton::solve()) from the explicit predictor
//! [`LiftedSystem::predictor`]. [`step`] neither allocates nor panics.

use nalgebra::{SMatrix, SVector};

use crate::numeric::newton::{self, NewtonOptions, Problem};
use crate::{Error, LiftedSystem};

/// Options of a step: the scheme parameter $\theta$ and the Newton options.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepOptions {
    /// $\theta \in [0, 1]$; $1/2$ (the default) is the lifted midpoint rule, order 2;
    /// 0 and 1 are the two symplectic Euler methods, order 1.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub theta: f64,
    /// Options of the Newton solve.
    pub newton: NewtonOptions,
    /// Check every step against the domain of the Lagrangian
    /// ([`LiftedSystem::check_domain`]) at $x_0$, $x_\theta$, $x_1$ and along the chord as
    /// [`Self::chord_spacing`] says; on by default.
    pub check_domain: bool,
    /// Longest piece of the chord $x(s) = (1-s) x_0 + s x_1$, $s \in [0, 1]$, of a step that
    /// the domain check treats as a whole, in the max-norm of the jet $x$ (all of
    /// $x_0, \dots, x_{k-1}$, in the units of the state); $0.02$ by default, `f64::INFINITY`
    /// checks only the three points of [`LiftedSystem::check_domain`]. With
    /// [`Self::check_domain`] on, a step whose chord has max-norm length
    /// $\ell = \Vert x_1 - x_0\Vert_\infty$ above the spacing $d$ is cut into
    /// $m = \min(\lceil \ell / d \rceil, m_{\max})$ equal pieces ($m_{\max}$ =
    /// [`Self::max_chord_pieces`]), and each piece is checked like a step of its own (at its two
    /// ends and its midpoint, with the top derivative $u$ of the step), after the step itself.
    ///
    /// What this guarantees, and what not: the checked points are at most
    /// $\ell / (2m)$ apart along the chord (max-norm): at most half the spacing, or
    /// $\ell / (2 m_{\max})$ when the cap binds. A guarded expression
    /// that leaves its domain on a piece of the chord longer than that is reported. A
    /// violation on a shorter piece (an obstacle thinner than that, or a chord grazing a
    /// region) can still be missed: sampling is not a proof. The chord is the straight segment
    /// between the step's end points; the scheme evaluates $L$ only at $x_\theta$, and the
    /// continuous motion between $x_0$ and $x_1$ is not checked. A step shorter than the
    /// spacing (the common case for small $h$) costs one max-norm of $x_1 - x_0$ beyond the
    /// three points; a longer one about one more `check_domain` per piece.
    ///
    /// Where every guarded expression is a polynomial of degree at most 2 in the jet
    /// ([`LiftedSystem::guards_quadratic`], e.g. $x^2 + y^2 - r^2$ of a disc), the three points
    /// decide the chord exactly (the quadratic through them is the expression) and no piece
    /// is checked.
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub chord_spacing: f64,
    /// The most pieces a step's chord is cut into (see [`Self::chord_spacing`]); 16 by
    /// default, at most [`MAX_CHORD_PIECES`]; 0 or 1 check only the three points.
    pub max_chord_pieces: u32,
    /// When a trajectory stops at a domain violation, bisect the step size to locate the
    /// crossing time ([`Interrupted::crossing_time`]); off by default.
    pub locate_crossing: bool,
    /// In [`trajectory`]: when a step fails to converge, retry it as 2, 4, ... substeps, at
    /// most this many halvings (reported in [`StepReport::halvings`]); 0 (the default) stops
    /// at the first failure. Domain violations are never retried. At most [`MAX_HALVINGS`]
    /// halvings ($2^{30}$ substeps) are tried, whatever this says: a larger value acts as
    /// [`MAX_HALVINGS`], so that [`StepReport::halvings`] $= m$ always means $2^m$ substeps.
    pub max_halvings: u32,
    /// In [`crate::ReducedStepper`]: recover the step's unknowns with the rounding corrections
    /// of the cached factors, $w = (T + T_{lo}) z_0 - (A^{-1} + A^{-1}_{lo}) n$
    /// ([`crate::ReducedScheme::recover`], [`crate::scheme::reduced`]); on by default. Off, each entry
    /// is one rounded sum of $T z_0 - A^{-1} n$ ([`crate::ReducedScheme::recover_plain`]): the
    /// step is about a fifth cheaper (a quarter over a run of dependent steps), and every step
    /// applies the same rounded linear map, so a quadratic invariant (an angular momentum)
    /// drifts linearly instead of staying at rounding. The other steps ignore it.
    #[cfg_attr(feature = "serde", serde(default = "compensated_by_default"))]
    pub compensated: bool,
    /// The energy check of [`step`] and [`crate::forced::forced_step`], off by default
    /// (`f64::INFINITY`): with a tolerance $\epsilon$, a converged step is refused with
    /// [`Error::UnresolvedStep`] when
    /// $|H(z_1) - H(z_0) - W| > \epsilon E + 10^{-9} (|H(z_0)| + |H(z_1)|)$, with $W$ the
    /// work of the force ($f \cdot (q_1 - q_0)$, zero without one) and
    /// $E = \sum_i |p_i'||\Delta x_i| + |x_i'||\Delta p_i|$ the energy the step exchanges
    /// between its positions and momenta ($z' = (x', p')$ the vector field at $z_0$, as the
    /// explicit predictor has it; $\Delta = z_1 - z_0$). A trajectory halves a refused step
    /// when [`Self::max_halvings`] allows. The check costs two evaluations of $H$ (each a
    /// Legendre inversion) and is skipped when $H$ cannot be evaluated at either end; the
    /// other steppers ignore it.
    ///
    /// What it catches: a root that continues a step too long for the motion, at another
    /// energy. A double pendulum spun at 140 rad/s with $h = 0.02$ converges to twice its
    /// energy, a ratio $|H(z_1) - H(z_0) - W| / E$ of 0.24; $h/2, \dots, h/16$ give 0.19,
    /// 0.10, 0.036, 0.010 ($O(h^2)$ at $\theta = 1/2$): $\epsilon = 0.05$ refuses the first
    /// three and halving ends within 1.1 % of 16 substeps. Why it is off by default: the
    /// ratio does not separate such roots from legitimate steps in general. Measured on
    /// the test suite's legitimate steps: 0.057 for symplectic Euler ($\theta = 0$, first
    /// order, $h = 0.05$), 0.065 for the scheme at $k = 4$, 0.115 in a property test of
    /// random systems, 0.06 to 0.45 for steps of ordinary size near or past a barrier, and
    /// 0.26 to 30 for steps that end just short of a singular point, where the rates at
    /// $z_0$ understate the exchange. Switch it on for a smooth mechanical system at
    /// $\theta = 1/2$ that may be driven faster than its step resolves (a plant under
    /// disturbances).
    #[cfg_attr(feature = "serde", serde(default = "energy_tolerance_by_default"))]
    #[cfg_attr(
        all(feature = "serde", feature = "std"),
        serde(with = "crate::serde_float")
    )]
    pub energy_tolerance: f64,
}

/// [`StepOptions::energy_tolerance`]'s default (off), for configurations written before it
/// existed.
#[cfg(feature = "serde")]
fn energy_tolerance_by_default() -> f64 {
    f64::INFINITY
}

/// [`StepOptions::compensated`]'s default, for configurations written before it existed.
#[cfg(feature = "serde")]
fn compensated_by_default() -> bool {
    true
}

impl Default for StepOptions {
    fn default() -> Self {
        Self {
            theta: 0.5,
            newton: NewtonOptions::default(),
            check_domain: true,
            chord_spacing: 0.02,
            max_chord_pieces: 16,
            locate_crossing: false,
            max_halvings: 0,
            compensated: true,
            energy_tolerance: f64::INFINITY,
        }
    }
}

impl StepOptions {
    /// Sets $\theta$.
    pub fn with_theta(mut self, theta: f64) -> Self {
        self.theta = theta;
        self
    }

    /// Sets the Newton options.
    pub fn with_newton(mut self, newton: NewtonOptions) -> Self {
        self.newton = newton;
        self
    }

    /// Switches the domain check on or off.
    pub fn with_domain_check(mut self, on: bool) -> Self {
        self.check_domain = on;
        self
    }

    /// Sets the chord spacing and the cap on chord pieces of the domain check
    /// ([`Self::chord_spacing`]).
    pub fn with_chord_check(mut self, spacing: f64, max_pieces: u32) -> Self {
        self.chord_spacing = spacing;
        self.max_chord_pieces = max_pieces;
        self
    }

    /// Switches the location of a domain crossing on or off.
    pub fn with_crossing_location(mut self, on: bool) -> Self {
        self.locate_crossing = on;
        self
    }

    /// Switches the rounding corrections of the reduced step on or off
    /// ([`Self::compensated`]).
    pub fn with_compensation(mut self, on: bool) -> Self {
        self.compensated = on;
        self
    }

    /// Sets the tolerance of the energy check ([`Self::energy_tolerance`]; `f64::INFINITY`:
    /// off).
    pub fn with_energy_tolerance(mut self, tolerance: f64) -> Self {
        self.energy_tolerance = tolerance;
        self
    }

    /// Sets the number of step halvings a trajectory may try on a failed step.
    pub fn with_max_halvings(mut self, max_halvings: u32) -> Self {
        self.max_halvings = max_halvings;
        self
    }

    #[inline]
    pub(crate) fn validate(&self, h: f64) -> Result<(), Error> {
        // plain comparisons (NaN fails each): this runs every step
        if self.theta >= 0.0
            && self.theta <= 1.0
            && h * 0.0 == 0.0
            && h != 0.0
            && self.chord_spacing > 0.0
            && self.max_chord_pieces <= MAX_CHORD_PIECES
            && self.energy_tolerance >= 0.0
        {
            return self.newton.validate();
        }
        self.invalid(h)
    }

    /// Why `theta` or `h` is invalid (the slow path of `validate`).
    #[cold]
    fn invalid(&self, h: f64) -> Result<(), Error> {
        if !(0.0..=1.0).contains(&self.theta) {
            return Err(Error::InvalidArgument {
                name: "theta",
                requirement: "theta must lie in [0, 1]",
            });
        }
        if !(h.is_finite() && h != 0.0) {
            return Err(Error::InvalidArgument {
                name: "h",
                requirement: "the step size must be finite and non-zero",
            });
        }
        if !(self.chord_spacing > 0.0 && self.max_chord_pieces <= MAX_CHORD_PIECES) {
            return Err(Error::InvalidArgument {
                name: "chord_spacing",
                requirement: "the chord spacing must be > 0 (infinity: the three points only) \
                              and max_chord_pieces at most MAX_CHORD_PIECES",
            });
        }
        if self.energy_tolerance.is_nan() || self.energy_tolerance < 0.0 {
            return Err(Error::InvalidArgument {
                name: "energy_tolerance",
                requirement: "the energy tolerance must be >= 0 (infinity: no check)",
            });
        }
        self.newton.validate()
    }
}

/// The most halvings a trajectory tries on a failed step ([`StepOptions::max_halvings`]):
/// the last retry is $2^{30}$ substeps of $h / 2^{30}$.
pub const MAX_HALVINGS: u32 = 30;

/// The largest [`StepOptions::max_chord_pieces`]: a step's chord is cut into at most this
/// many pieces (one `check_domain` each, about 10 ns for the planar rigid body).
pub const MAX_CHORD_PIECES: u32 = 1024;

/// The domain check of a step from `z0` to the unknowns `w`: the three points of
/// [`LiftedSystem::check_domain`], then the pieces of the chord of
/// [`StepOptions::chord_spacing`] when the chord is longer than the spacing, unless the
/// three points decide the chord ([`LiftedSystem::guards_quadratic`], with $\theta$ not
/// within $10^{-3}$ of an end).
///
/// # Errors
/// The first violated condition.
#[inline(always)]
pub fn check_step_domain<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    options: &StepOptions,
) -> Result<(), crate::DomainViolation>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    check_step_domain_with(system, z0, w, options, || *w)
}

/// [`check_step_domain`] with the unknowns of the chord's pieces from `unknowns` (called
/// only on the cold path, where the chord is cut; it must return `w`): the hot path reads
/// only the entries of `w` that [`LiftedSystem::check_domain`] and the chord's length read,
/// so a caller that builds `w` in place computes no other entry (the reduced step's top
/// derivative, where the guards do not read it).
#[inline(always)]
pub(crate) fn check_step_domain_with<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    options: &StepOptions,
    unknowns: impl FnOnce() -> SVector<f64, M>,
) -> Result<(), crate::DomainViolation>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    system.check_domain(z0, w, options.theta)?;
    // quadratic guards: the three points decide the chord (`guards_quadratic`)
    if system.guards_quadratic() && options.theta > 1e-3 && options.theta < 1.0 - 1e-3 {
        return Ok(());
    }
    // |x1 - x0|_inf over the jet (the first half of the state); NaN compares false and is
    // caught by the three points above
    let half = S / 2;
    let length = z0
        .iter()
        .zip(w.iter())
        .take(half)
        .fold(0.0f64, |m, (a, b)| m.max((b - a).abs()));
    if length > options.chord_spacing {
        check_chord(system, z0, &unknowns(), length, options)
    } else {
        Ok(())
    }
}

/// The pieces of the chord of a step longer than the spacing, each checked as a step of its
/// own at its ends and its midpoint (out of line: the cold path). Checking pieces rather than
/// points at other `theta` keeps whatever [`LiftedSystem::check_domain`] infers from its
/// three samples local to a short piece.
#[inline(never)]
fn check_chord<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    w: &SVector<f64, M>,
    length: f64,
    options: &StepOptions,
) -> Result<(), crate::DomainViolation>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    // ceil(length / spacing) >= 2 here; `as` saturates (an infinite length gives the cap)
    let wanted = num_traits::Float::ceil(length / options.chord_spacing) as u32;
    let pieces = wanted.min(options.max_chord_pieces.min(MAX_CHORD_PIECES));
    if pieces < 2 {
        return Ok(());
    }
    let count = f64::from(pieces);
    // the point at s of the chord, as a state (only its jet x enters the guards) and as the
    // unknowns of a piece ending there (the top derivative u of the step kept)
    let mut start = *z0;
    for j in 1..=pieces {
        let s = f64::from(j) / count;
        let mut end = *z0;
        for (e, (a, b)) in end.iter_mut().zip(z0.iter().zip(w.iter())) {
            *e = (1.0 - s) * a + s * b;
        }
        let mut unknowns = *w;
        for (u, e) in unknowns.iter_mut().zip(end.iter()) {
            *u = *e;
        }
        system.check_domain(&start, &unknowns, 0.5)?;
        start = end;
    }
    Ok(())
}

/// The unknowns $w = (z, u)$ of a step that ends at `z` with the top derivative `u` (entries
/// of $w$ beyond `z` and `u` zero).
#[cfg(feature = "std")]
pub(crate) fn unknowns_at<const S: usize, const M: usize>(
    z: &SVector<f64, S>,
    u: &[f64],
) -> SVector<f64, M> {
    SVector::from_fn(|r, _| {
        if r < S {
            z[r]
        } else {
            u.get(r - S).copied().unwrap_or(0.0)
        }
    })
}

/// The domain check of the state `z` alone, with the top derivative `u`: a step of length zero
/// (its three points coincide), so only what must hold at every point is checked: a
/// denominator finite and non-zero, a `sqrt` argument $\ge 0$, an `ln` argument and a `powf`
/// base $> 0$. Which side of a denominator's zero `z` lies on is not a condition (the guard
/// asks only that the side not change along a step); [`check_same_side`] compares two states.
///
/// # Errors
/// The first violated condition.
#[cfg(feature = "std")]
pub(crate) fn check_point_domain<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z: &SVector<f64, S>,
    u: &[f64],
) -> Result<(), crate::DomainViolation>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    system.check_domain(z, &unknowns_at::<S, M>(z, u), 0.5)
}

/// Whether the states `a` and `b` lie on the same side of every guarded expression, without
/// looking at any path between them: the check of a "step" from `a` to `b` at $\theta = 1$,
/// whose evaluation point is `b` itself (and where the generated guard does not fit a
/// quadratic between the points), with the top derivative `u` at both.
///
/// # Errors
/// The first guarded expression whose sign differs (or that fails at either state).
#[cfg(feature = "std")]
pub(crate) fn check_same_side<Sys, const S: usize, const M: usize>(
    system: &Sys,
    a: &SVector<f64, S>,
    b: &SVector<f64, S>,
    u: &[f64],
) -> Result<(), crate::DomainViolation>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    system.check_domain(a, &unknowns_at::<S, M>(b, u), 1.0)
}

/// The parameters of the system ([`LiftedSystem::check_parameters`]), then the initial state
/// of a trajectory against the domain of the Lagrangian ([`check_point_domain`]), with its
/// own top derivative (from the predictor; zero if the vector field cannot be evaluated
/// there). A non-finite parameter is [`Error::NonFiniteParameter`], whatever the options (a
/// guarded expression that holds it is not finite at any state, which is no fault of the
/// state); a finite state that fails is [`Error::InitialStateOutsideDomain`]; non-finite
/// states are left to the driver.
#[cfg(feature = "std")]
fn check_initial_state<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    options: &StepOptions,
) -> Result<(), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    system.check_parameters()?;
    if !options.check_domain || !z0.iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    let w = system
        .predictor(z0, 0.0, 0.5)
        .ok()
        .filter(|w| w.iter().all(|v| v.is_finite()));
    let u = w.as_ref().map_or(&[][..], |w| &w.as_slice()[S.min(M)..]);
    check_point_domain::<Sys, S, M>(system, z0, u)
        .map_err(|violation| Error::given(crate::error::Given::InitialState, violation))
}

/// What the Newton solve of one step reported.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepReport {
    /// Newton iterations used (summed over substeps).
    pub iterations: usize,
    /// $|F|_\infty$ at the accepted solution (the largest over substeps).
    pub residual_norm: f64,
    /// How often the step was halved before it converged ([`StepOptions::max_halvings`]).
    pub halvings: u32,
}

/// $F(z_0, \cdot) - c$ of one step as a Newton [`Problem`], $c$ a constant `offset` (an
/// external force, [`crate::scheme::forced`]) or zero.
struct StepProblem<'a, Sys: ?Sized, const S: usize, const M: usize> {
    system: &'a Sys,
    z0: &'a SVector<f64, S>,
    h: f64,
    theta: f64,
    offset: Option<&'a SVector<f64, M>>,
}

impl<Sys, const S: usize, const M: usize> Problem<M> for StepProblem<'_, Sys, S, M>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    fn residual(&self, w: &SVector<f64, M>) -> SVector<f64, M> {
        let f = self.system.residual(self.z0, w, self.h, self.theta);
        match self.offset {
            Some(c) => f - c,
            None => f,
        }
    }

    fn jacobian(&self, w: &SVector<f64, M>) -> SMatrix<f64, M, M> {
        self.system.jacobian(self.z0, w, self.h, self.theta)
    }
}

/// Solves one step from the guess `guess` and returns all unknowns $w$; checks the domain
/// of the Lagrangian when `options.check_domain` is set.
///
/// # Errors
/// Invalid `h` or options, any Newton failure, or [`Error::Domain`].
pub fn solve_step<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    guess: SVector<f64, M>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, M>, StepReport), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    options.validate(h)?;
    solve_validated(system, z0, guess, h, options)
}

/// [`solve_step`] for options already checked (the step paths validate once per step).
fn solve_validated<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    guess: SVector<f64, M>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, M>, StepReport), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    solve_offset(system, z0, guess, h, options, None)
}

/// [`solve_validated`] for the residual $F(z_0, w) - c$ with a constant `offset` $c$.
pub(crate) fn solve_offset<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    guess: SVector<f64, M>,
    h: f64,
    options: &StepOptions,
    offset: Option<&SVector<f64, M>>,
) -> Result<(SVector<f64, M>, StepReport), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    let problem = StepProblem {
        system,
        z0,
        h,
        theta: options.theta,
        offset,
    };
    let solution = newton::solve_validated(&problem, guess, &options.newton)?;
    if options.check_domain {
        check_step_domain(system, z0, &solution.w, options).map_err(Error::Domain)?;
    }
    Ok((
        solution.w,
        StepReport {
            iterations: solution.iterations,
            residual_norm: solution.residual_norm,
            halvings: 0,
        },
    ))
}

/// One step $z_1 = \Psi_h(z_0)$ of the theta-scheme, from the explicit predictor.
///
/// # Example
/// Without a potential ($\tau = 0$: $L = \tfrac12|q''|^2$) the midpoint step has a closed
/// form. With $p_1 = q''$ and $p_0 = -q'''$ the scheme is linear and gives
/// $q_1 = q_0 + h q_0' + \tfrac{h^2}{2} p_{1,0} - \tfrac{h^3}{4} p_{0,0}$,
/// $q_1' = q_0' + h p_{1,0} - \tfrac{h^2}{2} p_{0,0}$, $p_{1,1} = p_{1,0} - h p_{0,0}$,
/// $p_{0,1} = p_{0,0}$:
/// ```
/// use nalgebra::SVector;
/// use retract_core::models::PlanarBarrier;
/// use retract_core::{LiftedSystem, StepOptions, step};
///
/// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
/// // the jet (q, q', q'', q''') -> the state z = (q, q', p0, p1), blocks of 2
/// let jet = SVector::<f64, 8>::from_column_slice(&[2.0, 0.0, 1.0, 0.5, 0.2, 0.0, 0.1, -0.3]);
/// let z0 = system.legendre(&jet);
/// let h = 0.1;
/// let (z1, _) = step(&system, &z0, h, &StepOptions::default())?;
/// for i in 0..2 {
///     let (q, dq, p0, p1) = (z0[i], z0[2 + i], z0[4 + i], z0[6 + i]);
///     let expected = [
///         q + h * dq + h * h / 2.0 * p1 - h * h * h / 4.0 * p0,
///         dq + h * p1 - h * h / 2.0 * p0,
///         p0,
///         p1 - h * p0,
///     ];
///     for (block, value) in expected.into_iter().enumerate() {
///         assert!((z1[2 * block + i] - value).abs() < 1e-14);
///     }
/// }
/// # Ok::<(), retract_core::Error>(())
/// ```
///
/// # Errors
/// Invalid `h` or options, a predictor that cannot be evaluated at $z_0$ (e.g. a
/// non-finite state), or any Newton failure.
pub fn step<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, S>, StepReport), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    options.validate(h)?;
    let solved = system.predictor(z0, h, options.theta).and_then(|guess| {
        let (w, report) = solve_validated(system, z0, guess, h, options)?;
        check_energy(system, z0, &guess, &w, h, options, None)?;
        Ok((w, report))
    });
    let (w, report) = solved.map_err(|e| name_parameter(system, e))?;
    Ok((system.state(&w), report))
}

/// The energy check of a converged step ([`StepOptions::energy_tolerance`]): from `z0` to
/// the state in `w`, with the vector field at `z0` read off the explicit predictor `guess`
/// ($z' = (\text{guess}_{1..S} - z_0) / h$) and the work $W = \sum_i c_{S/2+i} \Delta x_i / h$
/// of a constant residual `offset` $c$ (the impulse $h f$ of a force,
/// [`crate::scheme::forced`]; zero without one).
///
/// # Errors
/// [`Error::UnresolvedStep`] when
/// $|H(z_1) - H(z_0) - W| > \epsilon E + 10^{-9} (|H(z_0)| + |H(z_1)|)$; nothing when $H$
/// cannot be evaluated at either end.
pub(crate) fn check_energy<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    guess: &SVector<f64, M>,
    w: &SVector<f64, M>,
    h: f64,
    options: &StepOptions,
    offset: Option<&SVector<f64, M>>,
) -> Result<(), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    if options.energy_tolerance == f64::INFINITY {
        return Ok(());
    }
    let z1 = system.state(w);
    let (Ok(h0), Ok(h1)) = (system.hamiltonian(z0), system.hamiltonian(&z1)) else {
        return Ok(());
    };
    let half = S / 2;
    let (mut exchanged, mut work) = (0.0, 0.0);
    for i in 0..half {
        let (dx, dp) = (z1[i] - z0[i], z1[half + i] - z0[half + i]);
        let (x_rate, p_rate) = ((guess[i] - z0[i]) / h, (guess[half + i] - z0[half + i]) / h);
        exchanged += p_rate.abs() * dx.abs() + x_rate.abs() * dp.abs();
        if let Some(c) = offset {
            work += c[half + i] * dx / h;
        }
    }
    let energy_error = (h1 - h0 - work).abs();
    // a comparison that NaN fails: an energy that is not finite is not refused here
    if energy_error > options.energy_tolerance * exchanged + 1e-9 * (h0.abs() + h1.abs()) {
        return Err(Error::UnresolvedStep {
            energy_error,
            exchanged,
        });
    }
    Ok(())
}

/// A non-finite value met by a step, reported as the parameter that causes it when one is
/// not finite ([`LiftedSystem::check_parameters`], run only on this failure path); any other
/// error unchanged.
pub(crate) fn name_parameter<Sys, const S: usize, const M: usize>(system: &Sys, e: Error) -> Error
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    match e {
        Error::NonFinite { .. } => system.check_parameters().err().unwrap_or(e),
        _ => e,
    }
}

#[cfg(feature = "std")]
/// States $z_0, \dots, z_m$ at $t_i = i h$ and the Newton report of each step.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Trajectory<const S: usize> {
    /// The step size $h$.
    pub h: f64,
    /// $z_i$, starting with the initial state.
    pub states: Vec<SVector<f64, S>>,
    /// `reports[i]` is the report of the step from `states[i]` to `states[i + 1]`.
    pub reports: Vec<StepReport>,
}

#[cfg(feature = "std")]
impl<const S: usize> Trajectory<S> {
    /// The times $t_i = i h$ of the states, $i = 0, \dots, m$.
    pub fn times(&self) -> Vec<f64> {
        (0..self.states.len()).map(|i| i as f64 * self.h).collect()
    }

    /// The largest number of Newton iterations of any step (0 for no step).
    pub fn max_iterations(&self) -> usize {
        self.reports.iter().map(|r| r.iterations).max().unwrap_or(0)
    }

    /// The mean number of Newton iterations per step (0 for no step).
    pub fn mean_iterations(&self) -> f64 {
        if self.reports.is_empty() {
            return 0.0;
        }
        self.reports
            .iter()
            .map(|r| r.iterations as f64)
            .sum::<f64>()
            / self.reports.len() as f64
    }

    /// Whether this is a trajectory a stepper could have returned (one read back from a
    /// file holds whatever it was given): $h$ non-zero and every time $t_i = i h$ finite
    /// ([`Self::times`]), every state finite, and
    /// one report per step, `reports.len() + 1 == states.len()` (both empty for a trajectory
    /// interrupted before its first state).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `trajectory`, saying which.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |requirement| {
            Err(Error::InvalidArgument {
                name: "trajectory",
                requirement,
            })
        };
        let last_time = self.states.len().saturating_sub(1) as f64 * self.h;
        if !(self.h.is_finite() && self.h != 0.0 && last_time.is_finite()) {
            return invalid("its step size must be non-zero, and its times i h finite");
        }
        if !self.states.iter().all(|z| z.iter().all(|v| v.is_finite())) {
            return invalid("its states must be finite");
        }
        if self.reports.len() + 1 != self.states.len().max(1) {
            return invalid("it must hold one report per step: one state more than reports");
        }
        Ok(())
    }
}

#[cfg(feature = "std")]
/// A trajectory that stopped at a failed step. Nothing computed before it is lost.
///
/// Its `Debug` output summarises the trajectory (step size, number of states and reports,
/// the last state) instead of listing every state.
#[derive(Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Interrupted<const S: usize> {
    /// The states up to and including the last valid one.
    pub trajectory: Trajectory<S>,
    /// Index of the failed step (from `states[step]`).
    pub step: usize,
    /// Why the step failed.
    pub error: Error,
    /// For a domain violation with [`StepOptions::locate_crossing`]: the time at which the
    /// trajectory leaves the domain, located by bisection of the step size to $10^{-12} h$.
    pub crossing_time: Option<f64>,
}

#[cfg(feature = "std")]
impl<const S: usize> Interrupted<S> {
    /// Time $t = \text{step} \cdot h$ at which the failed step started.
    pub fn time(&self) -> f64 {
        self.step as f64 * self.trajectory.h
    }
}

#[cfg(feature = "std")]
impl<const S: usize> core::fmt::Display for Interrupted<S> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "step {} from t = {} to t = {} failed: {}",
            self.step,
            self.time(),
            self.time() + self.trajectory.h,
            self.error
        )?;
        if let Some(t) = self.crossing_time {
            write!(f, " (crossing located at t = {t})")?;
        }
        Ok(())
    }
}

#[cfg(feature = "std")]
impl<const S: usize> core::fmt::Debug for Interrupted<S> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        /// The trajectory as counts and its last state.
        struct Summary<'a, const S: usize>(&'a Trajectory<S>);
        impl<const S: usize> core::fmt::Debug for Summary<'_, S> {
            fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
                let trajectory = self.0;
                f.debug_struct("Trajectory")
                    .field("h", &trajectory.h)
                    .field("states", &trajectory.states.len())
                    .field("reports", &trajectory.reports.len())
                    .field(
                        "last_state",
                        &trajectory.states.last().map(|z| z.as_slice()),
                    )
                    .finish()
            }
        }
        f.debug_struct("Interrupted")
            .field("step", &self.step)
            .field("error", &self.error)
            .field("crossing_time", &self.crossing_time)
            .field("trajectory", &Summary(&self.trajectory))
            .finish()
    }
}

#[cfg(feature = "std")]
impl<const S: usize> core::error::Error for Interrupted<S> {}

/// A one-step map `(z, h, options) -> (z_1, report)`: [`step`] or
/// [`crate::ReducedStepper::step`].
pub trait OneStep<const S: usize>:
    FnMut(&SVector<f64, S>, f64, &StepOptions) -> Result<(SVector<f64, S>, StepReport), Error>
{
}

impl<F, const S: usize> OneStep<S> for F where
    F: FnMut(&SVector<f64, S>, f64, &StepOptions) -> Result<(SVector<f64, S>, StepReport), Error>
{
}

#[cfg(feature = "std")]
/// Runs `steps` steps of size `h` from `z0`, each from the explicit predictor.
///
/// # Example
/// The barrier $V = \tau/(|q|^2 - r^2)$ is invariant under rotations, so by Noether the
/// angular momentum $q \times p_0 + q' \times p_1$ is conserved; it is quadratic, and the
/// midpoint rule conserves quadratic invariants exactly, so it holds to rounding (and the
/// Newton tolerance) along a pass that the barrier bends:
/// ```
/// use nalgebra::SVector;
/// use retract_core::models::PlanarBarrier;
/// use retract_core::{LiftedSystem, StepOptions, trajectory};
///
/// let system = PlanarBarrier { tau: 1e-2, radius: 1.0, mass: 1.0 };
/// let jet = SVector::<f64, 8>::from_column_slice(&[-2.0, 1.2, 1.0, -0.1, 0.0, 0.1, 0.1, 0.0]);
/// let run = trajectory(&system, &system.legendre(&jet), 0.01, 400, &StepOptions::default())?;
/// assert_eq!(run.states.len(), 401);
/// let cross = |a: f64, b: f64, c: f64, d: f64| a * d - b * c;
/// let angular = |z: &SVector<f64, 8>| {
///     cross(z[0], z[1], z[4], z[5]) + cross(z[2], z[3], z[6], z[7])
/// };
/// let first = angular(&run.states[0]); // 0.22
/// // q x q' alone is not conserved: the barrier turns the velocity
/// let last = &run.states[400];
/// assert!((cross(last[0], last[1], last[2], last[3]) - cross(-2.0, 1.2, 1.0, -0.1)).abs() > 1e-3);
/// for z in &run.states {
///     assert!((angular(z) - first).abs() < 1e-11 * first.abs());
/// }
/// # Ok::<(), retract_core::Interrupted<8>>(())
/// ```
///
/// Before the first step the parameters are checked: a non-finite one stops the trajectory
/// at step 0 with [`Error::NonFiniteParameter`] naming it. With [`StepOptions::check_domain`]
/// on, `z0` itself is checked next: a state where a guarded expression of $L$ fails (a
/// denominator vanishes, a `sqrt` argument is negative, an `ln` argument is not positive)
/// stops the trajectory at step 0 with [`Error::InitialStateOutsideDomain`] (no state kept). Which side of a denominator's zero
/// `z0` lies on is not known to the guard: a state inside a barrier obstacle
/// $\tau / (|q - c|^2 - r^2)$ is reported only when a step crosses the circle
/// ([`Error::Domain`]).
///
/// # Errors
/// [`Interrupted`], with the trajectory computed so far, at the first failed step (with no
/// state at all for a non-finite parameter, a non-finite `z0` or one outside the domain, or
/// with [`Error::InvalidArgument`] for `steps` whose states and reports cannot be allocated,
/// e.g. $2^{40}$ or `usize::MAX`).
pub fn trajectory<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z0: &SVector<f64, S>,
    h: f64,
    steps: usize,
    options: &StepOptions,
) -> Result<Trajectory<S>, Interrupted<S>>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    drive_checked(
        |z: &SVector<f64, S>, h, o: &StepOptions| step(system, z, h, o),
        |z: &SVector<f64, S>| check_initial_state::<Sys, S, M>(system, z, options),
        z0,
        h,
        steps,
        options,
    )
}

#[cfg(feature = "std")]
/// [`trajectory`] of a [`crate::ReducedStepper`]: [`drive`] with the initial state checked as
/// in [`trajectory`].
pub(crate) fn drive_system<Sys, const S: usize, const M: usize>(
    system: &Sys,
    one: impl OneStep<S>,
    z0: &SVector<f64, S>,
    h: f64,
    steps: usize,
    options: &StepOptions,
) -> Result<Trajectory<S>, Interrupted<S>>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    drive_checked(
        one,
        |z: &SVector<f64, S>| check_initial_state::<Sys, S, M>(system, z, options),
        z0,
        h,
        steps,
        options,
    )
}

#[cfg(feature = "std")]
/// The trajectory driver over any one-step map: `steps` steps of size `h`, halving a failed
/// step when [`StepOptions::max_halvings`] allows, locating a domain crossing when
/// [`StepOptions::locate_crossing`] is set. The one-step map carries no system, so `z0` is not
/// checked against the domain of the Lagrangian before the first step, as [`trajectory`] and
/// [`crate::ReducedStepper::trajectory`] do.
///
/// # Errors
/// As [`trajectory`], without [`Error::InitialStateOutsideDomain`].
pub fn drive<const S: usize>(
    one: impl OneStep<S>,
    z0: &SVector<f64, S>,
    h: f64,
    steps: usize,
    options: &StepOptions,
) -> Result<Trajectory<S>, Interrupted<S>> {
    drive_checked(one, |_: &SVector<f64, S>| Ok(()), z0, h, steps, options)
}

#[cfg(feature = "std")]
/// [`drive`], with `initial` run on a finite `z0` before the first step (its error stops the
/// trajectory at step 0 with no state kept).
fn drive_checked<const S: usize>(
    mut one: impl OneStep<S>,
    initial: impl FnOnce(&SVector<f64, S>) -> Result<(), Error>,
    z0: &SVector<f64, S>,
    h: f64,
    steps: usize,
    options: &StepOptions,
) -> Result<Trajectory<S>, Interrupted<S>> {
    let mut trajectory = Trajectory {
        h,
        states: Vec::new(),
        reports: Vec::new(),
    };
    if let Err(error) = reserve(&mut trajectory, steps) {
        return Err(Interrupted {
            trajectory,
            step: 0,
            error,
            crossing_time: None,
        });
    }
    if !z0.iter().all(|v| v.is_finite()) {
        return Err(Interrupted {
            trajectory,
            step: 0,
            error: Error::NonFinite {
                iteration: 0,
                location: "initial state",
            },
            crossing_time: None,
        });
    }
    if let Err(error) = initial(z0) {
        return Err(Interrupted {
            trajectory,
            step: 0,
            error,
            crossing_time: None,
        });
    }
    trajectory.states.push(*z0);
    let mut z = *z0;
    for i in 0..steps {
        match step_with_halving(&mut one, &z, h, options) {
            Ok((next, report)) => {
                z = next;
                trajectory.states.push(z);
                trajectory.reports.push(report);
            }
            Err(error) => {
                let crossing_time = match error {
                    Error::Domain(_) if options.locate_crossing => {
                        Some(i as f64 * h + locate_crossing_with(&mut one, &z, h, options))
                    }
                    _ => None,
                };
                return Err(Interrupted {
                    trajectory,
                    step: i,
                    error,
                    crossing_time,
                });
            }
        }
    }
    Ok(trajectory)
}

#[cfg(feature = "std")]
/// Reserves the states and reports of `steps` steps, or [`Error::InvalidArgument`] if they
/// do not fit in memory (`steps + 1` overflows, or the allocation fails): never a capacity
/// overflow panic or an allocation abort.
fn reserve<const S: usize>(trajectory: &mut Trajectory<S>, steps: usize) -> Result<(), Error> {
    let too_many = Error::InvalidArgument {
        name: "steps",
        requirement: "the states and reports of a trajectory must fit in memory",
    };
    let states = steps.checked_add(1).ok_or(too_many)?;
    trajectory
        .states
        .try_reserve_exact(states)
        .map_err(|_| too_many)?;
    trajectory
        .reports
        .try_reserve_exact(steps)
        .map_err(|_| too_many)
}

#[cfg(feature = "std")]
/// One step of size `h`, retried as $2^m$ substeps, $m = 1, \dots, \min(m_{\max}, 30)$
/// ($m_{\max}$ = [`StepOptions::max_halvings`], 30 = [`MAX_HALVINGS`]) when Newton fails,
/// the first that succeeds reported with `halvings` $= m$; domain violations and invalid
/// arguments are not retried.
fn step_with_halving<const S: usize>(
    one: &mut impl OneStep<S>,
    z0: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> Result<(SVector<f64, S>, StepReport), Error> {
    let mut error = match one(z0, h, options) {
        Ok(done) => return Ok(done),
        Err(e) => e,
    };
    for halvings in 1..=options.max_halvings.min(MAX_HALVINGS) {
        if matches!(error, Error::Domain(_) | Error::InvalidArgument { .. }) {
            break;
        }
        let pieces = 1usize << halvings;
        let sub = h / pieces as f64;
        let mut z = *z0;
        let mut report = StepReport {
            halvings,
            ..StepReport::default()
        };
        let mut failed = None;
        for _ in 0..pieces {
            match one(&z, sub, options) {
                Ok((next, r)) => {
                    z = next;
                    report.iterations += r.iterations;
                    report.residual_norm = report.residual_norm.max(r.residual_norm);
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        match failed {
            None => return Ok((z, report)),
            Some(e) => error = e,
        }
    }
    Err(error)
}

/// The largest $\delta \in (0, h]$ (to $10^{-12} h$, by bisection) for which a step of size
/// $\delta$ from `z` stays in the domain of the Lagrangian.
pub fn locate_crossing<Sys, const S: usize, const M: usize>(
    system: &Sys,
    z: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> f64
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    locate_crossing_with(
        &mut |z: &SVector<f64, S>, h, o: &StepOptions| step(system, z, h, o),
        z,
        h,
        options,
    )
}

/// [`locate_crossing`] for any one-step map.
fn locate_crossing_with<const S: usize>(
    one: &mut impl OneStep<S>,
    z: &SVector<f64, S>,
    h: f64,
    options: &StepOptions,
) -> f64 {
    let options = options.with_domain_check(true);
    let (mut inside, mut outside) = (0.0, h);
    while (outside - inside).abs() > 1e-12 * h.abs() {
        let mid = 0.5 * (inside + outside);
        if one(z, mid, &options).is_ok() {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    0.5 * (inside + outside)
}

#[cfg(test)]
#[cfg(feature = "serde")]
mod tests {
    use super::StepOptions;

    #[test]
    fn options_written_before_the_compensation_switch_read_as_compensated()
    -> Result<(), serde_json::Error> {
        let mut json = serde_json::to_value(StepOptions::default().with_compensation(false))?;
        assert_eq!(json["compensated"], false);
        let object = json.as_object_mut();
        assert!(object.is_some(), "options serialize to an object");
        object.map(|o| o.remove("compensated"));
        let read: StepOptions = serde_json::from_value(json)?;
        assert!(read.compensated);
        assert_eq!(read, StepOptions::default());
        Ok(())
    }
}

#[cfg(test)]
#[cfg(feature = "std")]
mod halving {
    use nalgebra::SVector;

    use super::{MAX_HALVINGS, StepOptions, StepReport, step_with_halving};
    use crate::Error;

    /// The result of a one-step map.
    type Stepped = Result<(SVector<f64, 1>, StepReport), Error>;

    /// A one-step map that converges only for steps of at most `largest`, counting its calls
    /// and keeping the smallest step it was asked for.
    fn fails_above<'a>(
        largest: f64,
        calls: &'a mut usize,
        smallest: &'a mut f64,
    ) -> impl FnMut(&SVector<f64, 1>, f64, &StepOptions) -> Stepped + 'a {
        move |z, h, _| {
            *calls += 1;
            *smallest = smallest.min(h);
            if h <= largest {
                Ok((z.add_scalar(h), StepReport::default()))
            } else {
                Err(Error::NoConvergence {
                    iterations: 1,
                    residual_norm: 1.0,
                })
            }
        }
    }

    #[test]
    fn the_halving_count_is_the_base_two_log_of_the_substeps() -> Result<(), Error> {
        let z0 = SVector::<f64, 1>::zeros();
        let options = StepOptions::default().with_max_halvings(40);
        // converges at a quarter step: 2 halvings, 1 + 1 + 4 calls, the whole step taken
        let (mut calls, mut smallest) = (0, f64::INFINITY);
        let mut one = fails_above(0.25, &mut calls, &mut smallest);
        let (z1, report) = step_with_halving(&mut one, &z0, 1.0, &options)?;
        drop(one);
        assert_eq!(report.halvings, 2);
        assert!((z1[0] - 1.0).abs() < 1e-15);
        assert_eq!((calls, smallest), (1 + 1 + 4, 0.25));
        // never converges: one try per count up to the cap, the last at h / 2^30, none after
        // (the count went on to 40 while the pieces stopped at 2^30)
        let (mut calls, mut smallest) = (0, f64::INFINITY);
        let mut one = fails_above(0.0, &mut calls, &mut smallest);
        assert!(step_with_halving(&mut one, &z0, 1.0, &options).is_err());
        drop(one);
        assert_eq!(calls, 1 + MAX_HALVINGS as usize);
        assert_eq!(smallest, 1.0 / f64::from(1u32 << MAX_HALVINGS));
        Ok(())
    }
}

/// Options and trajectories read from hostile JSON are refused on use.
#[cfg(test)]
#[cfg(all(feature = "serde", feature = "std"))]
mod hostile_json {
    use nalgebra::SVector;

    use super::{StepOptions, Trajectory, step, trajectory};
    use crate::models::PlanarBarrier;
    use crate::{Error, LiftedSystem};

    type Edit = fn(&mut serde_json::Value);

    /// A state of the barrier system away from its disc.
    fn start(system: &PlanarBarrier) -> SVector<f64, 8> {
        system.legendre(&SVector::from_column_slice(&[
            -2.0, 1.2, 1.0, -0.1, 0.0, 0.1, 0.1, 0.0,
        ]))
    }

    #[test]
    fn hostile_step_options_are_refused_by_the_step() {
        let system = PlanarBarrier {
            tau: 1e-2,
            radius: 1.0,
            mass: 1.0,
        };
        let valid = serde_json::to_value(StepOptions::default()).unwrap();
        let edits: [(&str, Edit); 9] = [
            ("theta = 2", |v| v["theta"] = 2.0.into()),
            ("theta = -1e-300", |v| v["theta"] = (-1e-300).into()),
            ("chord_spacing = 0", |v| v["chord_spacing"] = 0.0.into()),
            ("max_chord_pieces = 2^32 - 1", |v| {
                v["max_chord_pieces"] = u32::MAX.into()
            }),
            ("energy_tolerance = -1", |v| {
                v["energy_tolerance"] = (-1.0).into()
            }),
            ("max_iterations = 0", |v| {
                v["newton"]["max_iterations"] = 0.into()
            }),
            ("armijo = 0.5", |v| v["newton"]["armijo"] = 0.5.into()),
            ("residual_abs = -1e308", |v| {
                v["newton"]["residual_abs"] = (-1e308).into()
            }),
            ("step_rel = -1", |v| v["newton"]["step_rel"] = (-1.0).into()),
        ];
        let z0 = start(&system);
        assert!(step(&system, &z0, 0.01, &StepOptions::default()).is_ok());
        for (what, edit) in edits {
            let mut value = valid.clone();
            edit(&mut value);
            let options: StepOptions = serde_json::from_value(value)
                .unwrap_or_else(|e| panic!("{what}: the JSON reads ({e})"));
            let result = step(&system, &z0, 0.01, &options);
            assert!(
                matches!(result, Err(Error::InvalidArgument { .. })),
                "{what}: {result:?}"
            );
            let run = trajectory(&system, &z0, 0.01, 3, &options);
            assert!(
                run.is_err_and(|i| matches!(i.error, Error::InvalidArgument { .. })),
                "{what}"
            );
        }
        // options written before the energy check existed read with its default
        let mut old = valid;
        old.as_object_mut().map(|o| o.remove("energy_tolerance"));
        let read: StepOptions = serde_json::from_value(old).unwrap();
        assert_eq!(read, StepOptions::default());
        // the default (infinity, off) and a finite tolerance round-trip
        for options in [
            StepOptions::default(),
            StepOptions::default().with_energy_tolerance(0.05),
        ] {
            let json = serde_json::to_string(&options).unwrap();
            assert_eq!(
                serde_json::from_str::<StepOptions>(&json).unwrap(),
                options,
                "{json}"
            );
        }
    }

    #[test]
    fn non_finite_options_round_trip_and_hostile_floats_are_refused() {
        let system = PlanarBarrier {
            tau: 1e-2,
            radius: 1.0,
            mass: 1.0,
        };
        let z0 = start(&system);
        // an infinite chord spacing (three points only) is written as "inf" and read back
        let options = StepOptions::default().with_chord_check(f64::INFINITY, 16);
        let json = serde_json::to_string(&options).unwrap();
        assert!(json.contains(r#""chord_spacing":"inf""#), "{json}");
        let read: StepOptions = serde_json::from_str(&json).unwrap();
        assert_eq!(read, options);
        assert!(step(&system, &z0, 0.01, &read).is_ok());
        // NaN, written as "NaN" (or null by older files), reads back as NaN and is refused
        let nan = serde_json::to_value(StepOptions::default().with_chord_check(f64::NAN, 16));
        let nan = nan.unwrap();
        assert_eq!(nan["chord_spacing"], "NaN");
        let valid = serde_json::to_value(StepOptions::default()).unwrap();
        let mut null = valid.clone();
        null["chord_spacing"] = serde_json::Value::Null;
        let refused: [(&str, Edit); 2] = [
            ("newton.residual_abs = -inf", |v| {
                v["newton"]["residual_abs"] = "-inf".into()
            }),
            ("theta = NaN", |v| v["theta"] = "NaN".into()),
        ];
        let mut values = vec![("chord_spacing = NaN", nan), ("chord_spacing = null", null)];
        for (what, edit) in refused {
            let mut value = valid.clone();
            edit(&mut value);
            values.push((what, value));
        }
        for (what, value) in values {
            let read: StepOptions = serde_json::from_value(value)
                .unwrap_or_else(|e| panic!("{what}: the JSON reads ({e})"));
            let result = step(&system, &z0, 0.01, &read);
            assert!(
                matches!(result, Err(Error::InvalidArgument { .. })),
                "{what}: {result:?}"
            );
        }
        // strings other than the three names, and other types, are errors of the reading
        let unreadable: [(&str, Edit); 4] = [
            ("chord_spacing = \"infinity\"", |v| {
                v["chord_spacing"] = "infinity".into()
            }),
            ("chord_spacing = \"0.02\"", |v| {
                v["chord_spacing"] = "0.02".into()
            }),
            ("theta = []", |v| v["theta"] = serde_json::json!([])),
            ("newton.step_rel = {}", |v| {
                v["newton"]["step_rel"] = serde_json::json!({})
            }),
        ];
        for (what, edit) in unreadable {
            let mut value = valid.clone();
            edit(&mut value);
            let read = serde_json::from_value::<StepOptions>(value);
            assert!(read.is_err(), "{what}: {read:?}");
        }
        // the solvers' options: every float round-trips, infinite or NaN
        let mut plan = crate::bvp::PlanOptions::default();
        (plan.chord_spacing, plan.acceptable) = (f64::INFINITY, f64::NAN);
        let json = serde_json::to_string(&plan).unwrap();
        let read: crate::bvp::PlanOptions = serde_json::from_str(&json).unwrap();
        assert!(
            read.chord_spacing == f64::INFINITY && read.acceptable.is_nan(),
            "{json}"
        );
        assert_eq!((read.theta, read.tolerance), (plan.theta, plan.tolerance));
        let bvp = crate::bvp::root_finder::BvpOptions {
            residual_tolerance: f64::NEG_INFINITY,
            ..Default::default()
        };
        let json = serde_json::to_string(&bvp).unwrap();
        let read: crate::bvp::root_finder::BvpOptions = serde_json::from_str(&json).unwrap();
        assert_eq!(read, bvp, "{json}");
    }

    #[test]
    fn a_hostile_trajectory_fails_its_validation() {
        let system = PlanarBarrier {
            tau: 1e-2,
            radius: 1.0,
            mass: 1.0,
        };
        let run = trajectory(&system, &start(&system), 0.01, 3, &StepOptions::default())
            .expect("regular");
        let valid = serde_json::to_value(&run).unwrap();
        let back: Trajectory<8> = serde_json::from_value(valid.clone()).unwrap();
        assert!(back.validate().is_ok() && back == run);
        let edits: [(&str, Edit); 6] = [
            ("h = 0", |v| v["h"] = 0.0.into()),
            ("h = -0", |v| v["h"] = (-0.0).into()),
            ("h = 1e308 with 1e308 states", |v| {
                v["h"] = 1e308.into();
                v["states"][1][0] = (-1e308).into();
            }),
            ("a report missing", |v| {
                v["reports"].as_array_mut().map(Vec::pop);
            }),
            ("a report too many", |v| {
                let r = v["reports"][0].clone();
                if let Some(reports) = v["reports"].as_array_mut() {
                    reports.push(r);
                }
            }),
            ("reports without states", |v| {
                v["states"] = serde_json::json!([]);
            }),
        ];
        for (what, edit) in edits {
            let mut value = valid.clone();
            edit(&mut value);
            let read: Trajectory<8> = serde_json::from_value(value)
                .unwrap_or_else(|e| panic!("{what}: the JSON reads ({e})"));
            let result = read.validate();
            assert!(
                matches!(
                    result,
                    Err(Error::InvalidArgument {
                        name: "trajectory",
                        ..
                    })
                ),
                "{what}: {result:?}"
            );
        }
        // an interrupted trajectory with no state at all is valid
        let empty = Trajectory::<8> {
            h: 0.01,
            states: Vec::new(),
            reports: Vec::new(),
        };
        assert!(empty.validate().is_ok());
        let infinite = Trajectory::<8> {
            h: 0.01,
            states: vec![SVector::repeat(f64::INFINITY)],
            reports: Vec::new(),
        };
        assert!(infinite.validate().is_err());
    }
}
