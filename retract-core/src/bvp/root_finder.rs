//! The legacy root finder: Newton's method on the discrete necessary conditions, kept as a
//! cross-check of the optimizer ([`super::OptimalControlProblem`], the planner's one front:
//! its [`super::PlanGuess`], [`super::PlanOptions`] and [`super::Plan`] are the vocabulary of
//! planning; the types here are the root finder's own and are not re-exported).
//!
//! Given the jet $x = (q, \dots, q^{(k-1)})$ at both ends, $x(0) = a$ and $x(T) = b$, and
//! $N$ steps of $h = T/N$, the unknowns are the whole discrete trajectory
//! $v = (z_0, u_0, z_1, u_1, \dots, u_{N-1}, z_N)$ and the equations
//!
//! $$x(z_0) = a, \qquad F(z_i, (z_{i+1}, u_i)) = 0 \ (i < N), \qquad x(z_N) = b,$$
//!
//! with $F$ the theta-scheme residual of [`LiftedSystem`]. Newton's method with backtracking
//! on $|R|^2$ solves them. Its linear system is solved in $O(N)$ by condensing
//! ([`LinearSolver::Condensed`], the default): each step's unknowns are eliminated through
//! its linearised step map $\delta w_i = \Phi_i \delta z_i + c_i$, which leaves an
//! $nk \times nk$ system for the free initial momenta. [`BoundaryValueProblem::solve_reduced`]
//! forms $\Phi_i$ from the cached factors of a [`ReducedScheme`] (a rank-$R$ update of a
//! constant matrix) instead of a dense LU per step. The banded LU of the whole Jacobian
//! ($k_l = k_u = nk + M - 1$ in this ordering, [`crate::banded`]) is the fallback.
//!
//! The first guess is the Hermite polynomial of degree $2k - 1$ between the boundary jets
//! (the $V = 0$ spline), mapped through the system's Legendre map, or a previous solution
//! (warm start, [`BvpSolution::shifted`] for receding horizons, [`continuation`] in a
//! parameter). A solution whose clearance to an obstacle is negative is an error
//! ([`Error::ThroughObstacle`]): inside an obstacle the cost is unbounded below, so such a
//! stationary point is not a plan; so is one with a step that the singularity guard refuses,
//! run on every step as a step runs it, between the nodes too
//! ([`Error::SolutionOutsideDomain`]).

//!
//! It solves the KKT system of the transcription without looking at the cost, so it can stop
//! at a saddle or a maximum; [`super::OptimalControlProblem`] is the optimizer.

mod condense;

use nalgebra::{DMatrix, DVector, SVector};

use super::guess::Hermite;
use crate::banded::BandMatrix;
use crate::newton::lane_sum;
use crate::{Error, LiftedSystem, ReducedScheme};
use condense::{Linearized, ReducedStepMap, StepMap, general_step_map};

/// Options of the boundary-value solve.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BvpOptions {
    /// The scheme parameter $\theta$ (1/2: midpoint).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub theta: f64,
    /// Converged when $|R|_\infty \le$ this.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub residual_tolerance: f64,
    /// Newton iteration cap.
    pub max_iterations: usize,
    /// Armijo constant of the backtracking line search.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub armijo: f64,
    /// Step halvings per iteration.
    pub max_backtracks: usize,
    /// How the Newton direction is computed.
    pub linear_solver: LinearSolver,
}

/// How the boundary-value Newton direction is computed. Both give the same direction up to
/// rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum LinearSolver {
    /// Eliminate each step's unknowns through its linearised step map and solve the
    /// remaining $nk \times nk$ system for the free initial momenta (cost $O(N)$ small dense
    /// products); the banded LU below when that fails (a singular step map or end system, or
    /// no descent along the direction).
    Condensed,
    /// The banded LU with partial pivoting of the whole Jacobian ([`crate::banded`]).
    Banded,
}

impl Default for BvpOptions {
    fn default() -> Self {
        Self {
            theta: 0.5,
            residual_tolerance: 1e-10,
            max_iterations: 50,
            armijo: 1e-4,
            max_backtracks: 40,
            linear_solver: LinearSolver::Condensed,
        }
    }
}

impl BvpOptions {
    /// Whether these are options at all (options read back from a file hold whatever numbers
    /// they were given): $\theta \in [0, 1]$, `max_iterations` $\ge 1$, a finite
    /// `residual_tolerance` $\ge 0$ and $0 <$ `armijo` $\le 1/2$. Every solve runs it first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `theta` for $\theta$, `options` for the others, its
    /// requirement naming the field.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |name, requirement| Err(Error::InvalidArgument { name, requirement });
        if !(0.0..=1.0).contains(&self.theta) {
            return invalid("theta", "theta must lie in [0, 1]");
        }
        let tolerance = self.residual_tolerance;
        if self.max_iterations == 0 || !(tolerance.is_finite() && tolerance >= 0.0) {
            return invalid(
                "options",
                "need max_iterations >= 1 and a finite tolerance >= 0",
            );
        }
        // (the test is |R|^2 <= (1 - 2 armijo alpha) |R_0|^2: past 1/2 no step passes)
        if !(self.armijo > 0.0 && self.armijo <= 0.5) {
            return invalid("options", "need 0 < armijo <= 1/2");
        }
        Ok(())
    }

    /// Sets the residual tolerance.
    pub fn with_residual_tolerance(mut self, tolerance: f64) -> Self {
        self.residual_tolerance = tolerance;
        self
    }

    /// Sets the iteration cap.
    pub fn with_max_iterations(mut self, max_iterations: usize) -> Self {
        self.max_iterations = max_iterations;
        self
    }

    /// Sets $\theta$.
    pub fn with_theta(mut self, theta: f64) -> Self {
        self.theta = theta;
        self
    }

    /// Sets how the Newton direction is computed.
    pub fn with_linear_solver(mut self, linear_solver: LinearSolver) -> Self {
        self.linear_solver = linear_solver;
        self
    }
}

/// Where Newton starts.
#[derive(Clone, Copy, Debug)]
pub enum Guess<'a, const S: usize, const M: usize> {
    /// The Hermite spline of degree $2k-1$ between the boundary jets.
    Spline,
    /// A previous solution with the same number of steps (warm start).
    Solution(&'a BvpSolution<S, M>),
    /// States $z_0, \dots, z_N$ of a path chosen by the caller (e.g. around an obstacle);
    /// the top derivatives come from [`LiftedSystem::predictor`] at each state.
    /// [`Curve::states`](super::Curve::states) forms them from a path $q(t)$ or waypoints.
    States(&'a [SVector<f64, S>]),
}

/// A solved boundary-value problem.
///
/// With `serde`, NaN and infinite numbers are written as the strings `"NaN"`, `"inf"` and
/// `"-inf"` and read back, as in [`super::Certificate`]. A solution read back holds whatever
/// numbers it was given: its uses ([`Self::shifted`], a warm start
/// [`Guess::Solution`]) check it first ([`Self::validate`]).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BvpSolution<const S: usize, const M: usize> {
    /// Step size $h = T/N$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub h: f64,
    /// The scheme parameter used.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub theta: f64,
    /// $z_0, \dots, z_N$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub states: Vec<SVector<f64, S>>,
    /// The Newton unknowns $w_i = (z_{i+1}, u_i)$ of each step.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub unknowns: Vec<SVector<f64, M>>,
    /// $J = \sum_i h\thinspace L(x_{\theta,i}, u_i)$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub cost: f64,
    /// Minimum clearance to each obstacle over $z_0..z_N$ (empty without a clearance function).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::list"))]
    pub clearance: Vec<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// $|R|_\infty$ at the solution.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub residual_norm: f64,
}

impl<const S: usize, const M: usize> BvpSolution<S, M> {
    /// The times $t_i = i h$ of the states, $i = 0, \dots, N$.
    pub fn times(&self) -> Vec<f64> {
        (0..self.states.len()).map(|i| i as f64 * self.h).collect()
    }

    /// State $z_i$ by blocks ([`crate::State`]: $q^{(j)}$, $p_j$ by name), or `None` past the
    /// end; `S` $= 2nk$ is checked at compile time.
    pub fn state<const N: usize, const K: usize>(&self, i: usize) -> Option<crate::State<N, K>> {
        self.states.get(i).map(crate::State::from_vector)
    }

    /// The top derivative $u_i = q^{(k)}$ at the evaluation point of step $i$ (the last $n$
    /// entries of the unknowns $w_i$), or `None` past the last step; `N` $= M - S$ is
    /// checked at compile time.
    pub fn top_derivative<const N: usize>(&self, i: usize) -> Option<SVector<f64, N>> {
        const { assert!(N + S == M, "N must equal M - S") };
        self.unknowns
            .get(i)
            .map(|w| w.fixed_rows::<N>(S).into_owned())
    }

    /// Whether this is a solution at all (a solution read back from a file holds whatever
    /// numbers it was given): at least one step, $N + 1$ states for $N$ unknowns, a finite
    /// step $h > 0$ with $T = N h$ finite, $\theta \in [0, 1]$, and every state and unknown
    /// finite. The cost, the clearances and the residual describe the solution and are not
    /// checked. Its uses ([`Self::shifted`], a warm start [`Guess::Solution`]) run it first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `solution`, its requirement saying which condition
    /// fails.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |requirement| {
            Err(Error::InvalidArgument {
                name: "solution",
                requirement,
            })
        };
        let steps = self.unknowns.len();
        if steps == 0 || self.states.len() != steps + 1 {
            return invalid("it needs N >= 1 unknowns and N + 1 states");
        }
        if !(self.h > 0.0 && (self.h * steps as f64).is_finite()) {
            return invalid("its step h must be finite and > 0, and T = N h finite");
        }
        if !(0.0..=1.0).contains(&self.theta) {
            return invalid("its theta must lie in [0, 1]");
        }
        if !(self.states.iter().all(|z| all_finite(z.as_slice()))
            && self.unknowns.iter().all(|w| all_finite(w.as_slice())))
        {
            return invalid("its states and unknowns must be finite");
        }
        Ok(())
    }

    /// The solution shifted one step forward in time, for a receding-horizon warm start:
    /// $z_i \leftarrow z_{i+1}$, the new last step one integrator step from the old end
    /// (repeating the last step's unknowns if that step fails). A solution that fails
    /// [`Self::validate`] (e.g. read back from a damaged file) is returned unchanged, and a
    /// warm start from it is refused in turn.
    pub fn shifted<Sys>(&self, system: &Sys) -> Self
    where
        Sys: LiftedSystem<S, M> + ?Sized,
    {
        let mut out = self.clone();
        let (Some(&last_z), Some(&last_w)) = (self.states.last(), self.unknowns.last()) else {
            return out;
        };
        if self.validate().is_err() {
            return out;
        }
        let options = crate::StepOptions::default().with_theta(self.theta);
        let next_w = system
            .predictor(&last_z, self.h, self.theta)
            .and_then(|guess| crate::step::solve_step(system, &last_z, guess, self.h, &options))
            .map(|(w, _)| w)
            .unwrap_or(last_w);
        out.states.remove(0);
        out.states.push(system.state(&next_w));
        out.unknowns.remove(0);
        out.unknowns.push(next_w);
        out
    }
}

/// Per-obstacle clearance of a state: writes one signed distance per obstacle into `out`
/// (negative inside).
pub type ClearanceFn<'a, const S: usize> = &'a (dyn Fn(&SVector<f64, S>, &mut [f64]) + Sync);

/// A boundary-value problem: a system, the boundary jets, the horizon and the step count.
pub struct BoundaryValueProblem<'a, Sys: ?Sized, const S: usize, const M: usize> {
    system: &'a Sys,
    start: &'a [f64],
    goal: &'a [f64],
    t_end: f64,
    steps: usize,
    options: BvpOptions,
    clearance: Option<(usize, ClearanceFn<'a, S>)>,
}

/// Index layout of the unknowns and equations.
#[derive(Clone, Copy)]
struct Layout {
    s: usize,
    m: usize,
    nk: usize,
    steps: usize,
}

impl Layout {
    fn size(&self) -> usize {
        self.steps * self.m + self.s
    }
    fn z(&self, i: usize) -> usize {
        i * self.m
    }
    fn u(&self, i: usize) -> usize {
        i * self.m + self.s
    }
    /// Column of entry `c` of w_i = (z_{i+1}, u_i).
    fn w(&self, i: usize, c: usize) -> usize {
        if c < self.s {
            self.z(i + 1) + c
        } else {
            self.u(i) + c - self.s
        }
    }
    fn row(&self, i: usize) -> usize {
        self.nk + i * self.m
    }
    fn bandwidth(&self) -> usize {
        self.nk + self.m - 1
    }
}

/// The error for a problem too large to hold in memory.
const TOO_LARGE: Error = Error::InvalidArgument {
    name: "steps",
    requirement: "the unknowns of the boundary-value problem must fit in memory",
};

/// `len` copies of `value`, or [`TOO_LARGE`] (named `name`) when they cannot be allocated:
/// never a capacity overflow panic or an allocation abort.
fn filled<T: Clone>(len: usize, value: T, name: &'static str) -> Result<Vec<T>, Error> {
    let mut out = Vec::new();
    out.try_reserve_exact(len)
        .map_err(|_| Error::InvalidArgument {
            name,
            requirement: "the unknowns of the boundary-value problem must fit in memory",
        })?;
    out.resize(len, value);
    Ok(out)
}

/// The boundary data against the domain of the Lagrangian, before any iteration: `start` and
/// `goal` (states whose jets are the boundary jets) each alone
/// ([`crate::step::check_point_domain`]: [`Error::StartOutsideDomain`],
/// [`Error::GoalOutsideDomain`]), then against each other
/// ([`crate::step::check_same_side`]: [`Error::BoundariesSeparated`], a guarded expression
/// with opposite signs at the two ends, which every path between them must cross). No guess
/// changes the boundary jets, so none can repair these. The guards are evaluated with the
/// guess's top derivatives at the ends (`u_start`, `u_goal`) and a violation counts only if it
/// persists with $u = 0$: a guard on the top derivative that a different guess could satisfy
/// is left to the checks of the guess.
///
/// # Errors
/// The first failure, start before goal.
pub(super) fn check_boundary<Sys, const S: usize, const M: usize>(
    system: &Sys,
    start: &SVector<f64, S>,
    goal: &SVector<f64, S>,
    u_start: &[f64],
    u_goal: &[f64],
) -> Result<(), Error>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    use crate::error::Given;
    use crate::step::{check_point_domain, check_same_side};
    let zero = [0.0; 0];
    // the violation with the guess's u, if it persists with u = 0
    let both = |check: &dyn Fn(&[f64]) -> Result<(), crate::DomainViolation>, u: &[f64]| match (
        check(u),
        check(&zero),
    ) {
        (Err(violation), Err(_)) => Err(violation),
        _ => Ok(()),
    };
    both(
        &|u| check_point_domain::<Sys, S, M>(system, start, u),
        u_start,
    )
    .map_err(|violation| Error::given(Given::Start, violation))?;
    both(
        &|u| check_point_domain::<Sys, S, M>(system, goal, u),
        u_goal,
    )
    .map_err(|violation| Error::given(Given::Goal, violation))?;
    both(
        &|u| check_same_side::<Sys, S, M>(system, start, goal, u),
        u_start,
    )
    .map_err(|violation| Error::given(Given::Separated, violation))
}

/// Whether every entry is finite: $\sum_i 0 \cdot v_i = 0$, NaN exactly when some $v_i$ is
/// not finite (summed in four lanes, so the loop vectorises and does not branch).
fn all_finite(v: &[f64]) -> bool {
    lane_sum(v, |x| x * 0.0) == 0.0
}

/// $\max_i |v_i|$ (NaN entries are skipped by `f64::max`; callers check finiteness).
fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// $\sum_i v_i^2$: not finite if an entry is not (or the sum overflows).
fn squared_norm(v: &[f64]) -> f64 {
    lane_sum(v, |x| x * x)
}

impl<'a, Sys, const S: usize, const M: usize> BoundaryValueProblem<'a, Sys, S, M>
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    /// The problem $x(0) = $ `start`, $x(T) = $ `goal` (each $nk$ numbers: $q, q', \dots,
    /// q^{(k-1)}$, blocks of $n$) over $T = $ `t_end` with `steps` steps.
    pub fn new(
        system: &'a Sys,
        start: &'a [f64],
        goal: &'a [f64],
        t_end: f64,
        steps: usize,
    ) -> Self {
        Self {
            system,
            start,
            goal,
            t_end,
            steps,
            options: BvpOptions::default(),
            clearance: None,
        }
    }

    /// Sets the options.
    pub fn with_options(mut self, options: BvpOptions) -> Self {
        self.options = options;
        self
    }

    /// Checks the clearance to `obstacles` obstacles on every state of the solution.
    pub fn with_clearance(mut self, obstacles: usize, clearance: ClearanceFn<'a, S>) -> Self {
        self.clearance = Some((obstacles, clearance));
        self
    }

    fn layout(&self) -> Layout {
        Layout {
            s: S,
            m: M,
            nk: S / 2,
            steps: self.steps,
        }
    }

    fn h(&self) -> f64 {
        self.t_end / self.steps as f64
    }

    fn validate(&self) -> Result<(), Error> {
        self.system.check_parameters()?;
        let nk = S / 2;
        let invalid = |name, requirement| Err(Error::InvalidArgument { name, requirement });
        if M != S + Sys::DIMENSION {
            return invalid(
                "system",
                "the boundary-value solver needs the general unknowns w = (z_1, u)",
            );
        }
        if self.start.len() != nk || self.goal.len() != nk {
            return invalid(
                "start/goal",
                "boundary data must hold q, ..., q^(k-1): n k numbers",
            );
        }
        if !all_finite(self.start) || !all_finite(self.goal) {
            return invalid("start/goal", "boundary data must be finite");
        }
        if self.steps == 0 {
            return invalid("steps", "at least one step is needed");
        }
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return invalid("t_end", "the horizon must be finite and positive");
        }
        self.options.validate()?;
        // the unknowns, their index arithmetic and the obstacle buffers must be addressable
        // (whether they can be allocated is checked when they are)
        let bytes = self
            .steps
            .checked_mul(M)
            .and_then(|n| n.checked_add(S))
            .and_then(|n| n.checked_mul(8 * core::mem::size_of::<f64>()));
        if bytes.is_none_or(|b| b > isize::MAX as usize) {
            return invalid(
                "steps",
                "the unknowns of the boundary-value problem must fit in memory",
            );
        }
        if let Some((count, _)) = self.clearance
            && count > isize::MAX as usize / (2 * core::mem::size_of::<f64>())
        {
            return invalid(
                "obstacles",
                "the clearances of the obstacles must fit in memory",
            );
        }
        Ok(())
    }

    /// The Hermite-spline guess, through the Legendre map.
    fn spline_guess(&self) -> Result<Vec<f64>, Error> {
        let (n, k) = (Sys::DIMENSION, Sys::ORDER);
        let spline = Hermite::new(self.start, self.goal, self.t_end, n, k)?;
        let layout = self.layout();
        let h = self.h();
        let mut v = filled(layout.size(), 0.0, "steps")?;
        for step in 0..=self.steps {
            let t = step as f64 * h;
            let jet = SVector::<f64, S>::from_fn(|r, _| spline.jet_entry(r, t));
            let z = self.system.legendre(&jet);
            v[layout.z(step)..layout.z(step) + S].copy_from_slice(z.as_slice());
            if step < self.steps {
                let t_mid = t + self.options.theta * h;
                for i in 0..n {
                    v[layout.u(step) + i] = spline.derivative(i, k, t_mid);
                }
            }
        }
        Ok(v)
    }

    fn guess_from_solution(&self, guess: &BvpSolution<S, M>) -> Result<Vec<f64>, Error> {
        guess.validate()?;
        if guess.states.len() != self.steps + 1 || guess.unknowns.len() != self.steps {
            return Err(Error::InvalidArgument {
                name: "guess",
                requirement: "a warm start needs a solution with the same number of steps",
            });
        }
        let layout = self.layout();
        let mut v = filled(layout.size(), 0.0, "steps")?;
        for (i, z) in guess.states.iter().enumerate() {
            v[layout.z(i)..layout.z(i) + S].copy_from_slice(z.as_slice());
        }
        for (i, w) in guess.unknowns.iter().enumerate() {
            v[layout.u(i)..layout.u(i) + M - S].copy_from_slice(&w.as_slice()[S..]);
        }
        Ok(v)
    }

    fn guess_from_states(&self, states: &[SVector<f64, S>]) -> Result<Vec<f64>, Error> {
        if states.len() != self.steps + 1 {
            return Err(Error::InvalidArgument {
                name: "guess",
                requirement: "a guess needs N + 1 states",
            });
        }
        let layout = self.layout();
        let mut v = filled(layout.size(), 0.0, "steps")?;
        for (i, z) in states.iter().enumerate() {
            v[layout.z(i)..layout.z(i) + S].copy_from_slice(z.as_slice());
            if i < self.steps {
                let w = self.system.predictor(z, self.h(), self.options.theta)?;
                v[layout.u(i)..layout.u(i) + M - S].copy_from_slice(&w.as_slice()[S..]);
            }
        }
        Ok(v)
    }

    fn state(&self, v: &[f64], i: usize) -> SVector<f64, S> {
        let at = self.layout().z(i);
        SVector::from_column_slice(&v[at..at + S])
    }

    fn unknowns(&self, v: &[f64], i: usize) -> SVector<f64, M> {
        // w_i = (z_{i+1}, u_i): two contiguous pieces of v
        let layout = self.layout();
        let mut w = SVector::<f64, M>::zeros();
        let (z_next, u) = w.as_mut_slice().split_at_mut(S);
        z_next.copy_from_slice(&v[layout.z(i + 1)..layout.z(i + 1) + S]);
        u.copy_from_slice(&v[layout.u(i)..layout.u(i) + M - S]);
        w
    }

    fn residual(&self, v: &[f64], out: &mut [f64]) {
        let layout = self.layout();
        let (h, theta, nk) = (self.h(), self.options.theta, layout.nk);
        for j in 0..nk {
            out[j] = v[layout.z(0) + j] - self.start[j];
            out[layout.row(self.steps) + j] = v[layout.z(self.steps) + j] - self.goal[j];
        }
        for i in 0..self.steps {
            let f = self
                .system
                .residual(&self.state(v, i), &self.unknowns(v, i), h, theta);
            out[layout.row(i)..layout.row(i) + M].copy_from_slice(f.as_slice());
        }
    }

    fn jacobian(&self, v: &[f64], band: &mut BandMatrix) {
        let layout = self.layout();
        let (h, theta, nk) = (self.h(), self.options.theta, layout.nk);
        band.clear();
        for j in 0..nk {
            band.set(j, layout.z(0) + j, 1.0);
            band.set(layout.row(self.steps) + j, layout.z(self.steps) + j, 1.0);
        }
        for i in 0..self.steps {
            let (z, w) = (self.state(v, i), self.unknowns(v, i));
            let a = self.system.jacobian_initial(&z, &w, h, theta);
            let b = self.system.jacobian(&z, &w, h, theta);
            let row = layout.row(i);
            for r in 0..M {
                for c in 0..S {
                    let value = a[(r, c)];
                    if value != 0.0 {
                        band.set(row + r, layout.z(i) + c, value);
                    }
                }
                for c in 0..M {
                    let value = b[(r, c)];
                    if value != 0.0 {
                        band.set(row + r, layout.w(i, c), value);
                    }
                }
            }
        }
    }

    /// Solves the problem from `guess`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for inconsistent data; boundary data no guess can repair,
    /// before any iteration: a start or goal inside an obstacle of the clearance function
    /// ([`Error::BoundaryInObstacle`]), outside the domain of the Lagrangian
    /// ([`Error::StartOutsideDomain`], [`Error::GoalOutsideDomain`]) or on the other side of
    /// one of its singularities than the other end ([`Error::BoundariesSeparated`]);
    /// [`Error::GuessThroughObstacle`] for a first guess through an obstacle; Newton failures
    /// ([`Error::NonFinite`], [`Error::SingularJacobian`],
    /// [`Error::BoundaryValueLineSearchFailed`], [`Error::BoundaryValueNoConvergence`]);
    /// [`Error::ThroughObstacle`] for a solution with negative clearance;
    /// [`Error::SolutionOutsideDomain`] for one with a step the singularity guard refuses.
    pub fn solve(&self, guess: Guess<'_, S, M>) -> Result<BvpSolution<S, M>, Error> {
        let system = self.system;
        let (h, theta) = (self.h(), self.options.theta);
        self.solve_with(
            guess,
            &|z: &SVector<f64, S>,
              w: &SVector<f64, M>,
              f: &SVector<f64, M>,
              out: &mut Linearized<S, M>| {
                general_step_map(system, z, w, f, h, theta, out)
            },
        )
    }

    /// [`Self::solve`] with the linearised step maps of a [`ReducedScheme`]: the same Newton
    /// iterates, with each step's linearisation from the cached factors of the reduced step
    /// (a rank-$R$ update of a constant map) instead of a dense factorisation per step.
    ///
    /// # Errors
    /// As [`Self::solve`]; a singular linear part is [`Error::SingularJacobian`].
    pub fn solve_reduced<const R: usize>(
        &self,
        guess: Guess<'_, S, M>,
    ) -> Result<BvpSolution<S, M>, Error>
    where
        Sys: ReducedScheme<S, M, R>,
    {
        self.validate()?;
        let (h, theta) = (self.h(), self.options.theta);
        let map = ReducedStepMap::new(self.system, h, theta)?;
        self.solve_with(
            guess,
            &|z: &SVector<f64, S>,
              w: &SVector<f64, M>,
              f: &SVector<f64, M>,
              out: &mut Linearized<S, M>| map.linearize(z, w, f, out),
        )
    }

    fn solve_with(
        &self,
        guess: Guess<'_, S, M>,
        linearize: StepMap<'_, S, M>,
    ) -> Result<BvpSolution<S, M>, Error> {
        self.validate()?;
        let layout = self.layout();
        let size = layout.size();
        // every buffer before the guess, so that a problem too large for memory stops here
        let mut r = filled(size, 0.0, "steps")?;
        let mut delta = filled(size, 0.0, "steps")?;
        let mut trial = filled(size, 0.0, "steps")?;
        let mut r_trial = filled(size, 0.0, "steps")?;
        let mut maps = filled(self.steps, Linearized::zeros(), "steps")?;
        let mut buffer = filled(self.obstacles(), 0.0, "obstacles")?;
        let mut v = match guess {
            Guess::Spline => self.spline_guess()?,
            Guess::Solution(previous) => self.guess_from_solution(previous)?,
            Guess::States(states) => self.guess_from_states(states)?,
        };
        self.check_ends(&v, &mut buffer)?;
        if let Some((obstacle, step, clearance)) = self.first_collision(&v, &mut buffer) {
            return Err(Error::GuessThroughObstacle {
                obstacle,
                step,
                clearance,
            });
        }
        let options = &self.options;
        self.residual(&v, &mut r);
        if !all_finite(&v) || !all_finite(&r) {
            return Err(Error::NonFinite {
                iteration: 0,
                location: "boundary-value residual of the first guess",
            });
        }
        let mut band: Option<BandMatrix> = None;
        let mut r_norm = max_abs(&r);
        let mut iterations = 0;
        while r_norm > options.residual_tolerance {
            if iterations == options.max_iterations {
                return Err(Error::BoundaryValueNoConvergence {
                    iterations,
                    residual_norm: r_norm,
                });
            }
            iterations += 1;
            // the condensed direction (O(N) small dense work); the banded factorisation of the
            // whole Jacobian if condensing fails or its direction is not a descent direction
            let mut accepted = options.linear_solver == LinearSolver::Condensed
                && condensed_direction(self, &v, &r, &mut delta, linearize, &mut maps)
                && self.line_search(&v, &r, &delta, &mut trial, &mut r_trial);
            if !accepted {
                if band.is_none() {
                    let bw = layout.bandwidth();
                    band = Some(BandMatrix::try_zeros(size, bw, bw).ok_or(TOO_LARGE)?);
                }
                let Some(band) = band.as_mut() else {
                    return Err(TOO_LARGE);
                };
                self.banded_direction(&v, &r, band, &mut delta, iterations)?;
                accepted = self.line_search(&v, &r, &delta, &mut trial, &mut r_trial);
            }
            if !accepted {
                return Err(Error::BoundaryValueLineSearchFailed {
                    iteration: iterations,
                    residual_norm: r_norm,
                });
            }
            std::mem::swap(&mut v, &mut trial);
            std::mem::swap(&mut r, &mut r_trial);
            r_norm = max_abs(&r);
        }
        self.finish(&v, &mut buffer, iterations, r_norm)
    }

    /// The Newton direction from the banded LU of the whole Jacobian.
    fn banded_direction(
        &self,
        v: &[f64],
        r: &[f64],
        band: &mut BandMatrix,
        delta: &mut [f64],
        iteration: usize,
    ) -> Result<(), Error> {
        self.jacobian(v, band);
        band.factor()
            .map_err(|_| Error::SingularJacobian { iteration })?;
        for (d, ri) in delta.iter_mut().zip(r) {
            *d = -ri;
        }
        band.solve(delta);
        if all_finite(delta) {
            Ok(())
        } else {
            Err(Error::SingularJacobian { iteration })
        }
    }

    /// Backtracking along `delta` from `v` (residual `r`): on success `trial` holds the
    /// accepted point and `r_trial` its residual.
    fn line_search(
        &self,
        v: &[f64],
        r: &[f64],
        delta: &[f64],
        trial: &mut [f64],
        r_trial: &mut [f64],
    ) -> bool {
        let options = &self.options;
        let phi = squared_norm(r);
        let mut alpha = 1.0;
        for _ in 0..=options.max_backtracks {
            for ((t, vi), di) in trial.iter_mut().zip(v).zip(delta) {
                *t = vi + alpha * di;
            }
            self.residual(trial, r_trial);
            // one pass: a residual with a non-finite entry has a non-finite |r|^2
            let phi_trial = squared_norm(r_trial);
            if phi_trial.is_finite() && phi_trial <= (1.0 - 2.0 * options.armijo * alpha) * phi {
                return true;
            }
            alpha *= 0.5;
        }
        false
    }

    /// The boundary data that no guess can repair: the guess's first and last states with
    /// their jets set to `start` and `goal` (momenta and top derivatives of the guess), each
    /// inside no obstacle of the clearance function ([`Error::BoundaryInObstacle`]), then
    /// [`check_boundary`]. `buffer` holds one clearance per obstacle.
    fn check_ends(&self, v: &[f64], buffer: &mut [f64]) -> Result<(), Error> {
        let nk = S / 2;
        let end = |i: usize, jet: &[f64]| {
            let mut z = self.state(v, i);
            for (e, &x) in z.iter_mut().zip(jet).take(nk) {
                *e = x;
            }
            z
        };
        let (start, goal) = (end(0, self.start), end(self.steps, self.goal));
        if let Some((_, f)) = self.clearance {
            for (end, z) in [("start", &start), ("goal", &goal)] {
                f(z, buffer);
                if let Some((obstacle, &clearance)) = buffer
                    .iter()
                    .enumerate()
                    .find(|(_, c)| c.is_nan() || **c < 0.0)
                {
                    return Err(Error::BoundaryInObstacle {
                        end,
                        obstacle,
                        clearance,
                    });
                }
            }
        }
        let layout = self.layout();
        let u = |i: usize| &v[layout.u(i)..layout.u(i) + M - S];
        check_boundary::<Sys, S, M>(self.system, &start, &goal, u(0), u(self.steps - 1))
    }

    /// The number of obstacles of the clearance function (0 without one).
    fn obstacles(&self) -> usize {
        self.clearance.map_or(0, |(count, _)| count)
    }

    /// The first (obstacle, state, clearance) with negative (or NaN) clearance; `buffer` holds
    /// one clearance per obstacle.
    fn first_collision(&self, v: &[f64], buffer: &mut [f64]) -> Option<(usize, usize, f64)> {
        let (_, f) = self.clearance?;
        for step in 0..=self.steps {
            f(&self.state(v, step), buffer);
            if let Some((obstacle, &c)) = buffer
                .iter()
                .enumerate()
                .find(|(_, c)| c.is_nan() || **c < 0.0)
            {
                return Some((obstacle, step, c));
            }
        }
        None
    }

    /// The singularity guard of every step of a converged solution, as a step runs it
    /// ([`crate::step::check_step_domain`]: the evaluation point, both nodes and the chord
    /// between them).
    fn guard(&self, states: &[SVector<f64, S>], unknowns: &[SVector<f64, M>]) -> Result<(), Error> {
        let options = crate::StepOptions::default().with_theta(self.options.theta);
        for (step, (z0, w)) in states.iter().zip(unknowns).enumerate() {
            crate::step::check_step_domain(self.system, z0, w, &options)
                .map_err(|violation| Error::solution_outside_domain(step, violation))?;
        }
        Ok(())
    }

    fn finish(
        &self,
        v: &[f64],
        buffer: &mut [f64],
        iterations: usize,
        residual_norm: f64,
    ) -> Result<BvpSolution<S, M>, Error> {
        let (h, theta) = (self.h(), self.options.theta);
        let mut states = filled(self.steps + 1, SVector::zeros(), "steps")?;
        for (i, z) in states.iter_mut().enumerate() {
            *z = self.state(v, i);
        }
        let mut unknowns = filled(self.steps, SVector::zeros(), "steps")?;
        for (i, w) in unknowns.iter_mut().enumerate() {
            *w = self.unknowns(v, i);
        }
        let cost = states
            .iter()
            .zip(&unknowns)
            .map(|(z, w)| self.system.step_cost(z, w, h, theta))
            .sum();
        if let Some((obstacle, step, clearance)) = self.first_collision(v, buffer) {
            return Err(Error::ThroughObstacle {
                obstacle,
                step,
                clearance,
            });
        }
        self.guard(&states, &unknowns)?;
        let mut clearance = Vec::new();
        if let Some((count, f)) = self.clearance {
            clearance = filled(count, f64::INFINITY, "obstacles")?;
            for z in &states {
                f(z, buffer);
                for (best, &c) in clearance.iter_mut().zip(buffer.iter()) {
                    *best = best.min(c);
                }
            }
        }
        Ok(BvpSolution {
            h,
            theta,
            states,
            unknowns,
            cost,
            clearance,
            iterations,
            residual_norm,
        })
    }
}

/// Solves a sequence of problems whose system depends on a parameter (e.g. a barrier weight
/// from large to small), each warm-started from the previous solution, the first from
/// `first_guess`. Returns the last solution.
///
/// # Errors
/// The first failing solve's error.
#[allow(clippy::too_many_arguments)]
pub fn continuation<Sys, F, const S: usize, const M: usize>(
    make: F,
    parameters: &[f64],
    start: &[f64],
    goal: &[f64],
    t_end: f64,
    steps: usize,
    options: BvpOptions,
    clearance: Option<(usize, ClearanceFn<'_, S>)>,
    first_guess: Guess<'_, S, M>,
) -> Result<BvpSolution<S, M>, Error>
where
    Sys: LiftedSystem<S, M>,
    F: Fn(f64) -> Sys,
{
    let mut previous: Option<BvpSolution<S, M>> = None;
    for &parameter in parameters {
        let system = make(parameter);
        let mut problem =
            BoundaryValueProblem::new(&system, start, goal, t_end, steps).with_options(options);
        if let Some((count, f)) = clearance {
            problem = problem.with_clearance(count, f);
        }
        let guess = match &previous {
            Some(solution) => Guess::Solution(solution),
            None => first_guess,
        };
        previous = Some(problem.solve(guess)?);
    }
    previous.ok_or(Error::InvalidArgument {
        name: "parameters",
        requirement: "continuation needs at least one parameter value",
    })
}

/// The condensed Newton direction.
///
/// Eliminating $\delta w_i = \Phi_i \delta z_i + c_i$ step by step leaves the recursion
/// $\delta z_{i+1} = \Phi^z_i \delta z_i + c^z_i$ ($z$ rows), with $\delta x_0 = -(x_0 - a)$ known and
/// $\delta p_0 = \xi$ free: $\delta z_i = Z_i \xi + \zeta_i$, and $\xi$ solves the $nk \times nk$
/// system $[Z_N]_x \xi = -(x_N - b) - [\zeta_N]_x$. One pass forms each step's map (into its slot
/// of `maps`, one per step) and advances $Z_i$ and $\zeta_i$ with it; a second recovers
/// $\delta z_i$ and $\delta u_i$. Cost $O(N\thinspace nk\thinspace S M)$, no banded matrix. Writes
/// the direction at `v` (residual `r`) into `delta`; `false` if a step map or the end system is
/// singular or the direction is not finite (checked once, on `delta`).
fn condensed_direction<Sys, const S: usize, const M: usize>(
    problem: &BoundaryValueProblem<'_, Sys, S, M>,
    v: &[f64],
    r: &[f64],
    delta: &mut [f64],
    linearize: StepMap<'_, S, M>,
    maps: &mut [Linearized<S, M>],
) -> bool
where
    Sys: LiftedSystem<S, M> + ?Sized,
{
    let layout = problem.layout();
    let (nk, steps) = (layout.nk, problem.steps);
    // the sensitivity Z_i (nk columns) and the offset zeta_i, advanced as each map is formed
    let mut sensitivity: Vec<SVector<f64, S>> = (0..nk)
        .map(|j| SVector::from_fn(|row, _| if row == nk + j { 1.0 } else { 0.0 }))
        .collect();
    let mut zeta = SVector::<f64, S>::from_fn(|row, _| if row < nk { -r[row] } else { 0.0 });
    for (i, map) in maps.iter_mut().enumerate().take(steps) {
        let f = SVector::<f64, M>::from_column_slice(&r[layout.row(i)..layout.row(i) + M]);
        if !linearize(&problem.state(v, i), &problem.unknowns(v, i), &f, map) {
            return false;
        }
        for column in &mut sensitivity {
            *column = map.linear_z(column);
        }
        zeta = map.affine(&zeta).fixed_rows::<S>(0).into_owned();
    }
    let end = layout.row(steps);
    let lhs = DMatrix::<f64>::from_fn(nk, nk, |row, j| sensitivity[j][row]);
    let rhs = DVector::<f64>::from_fn(nk, |row, _| -r[end + row] - zeta[row]);
    let Some(xi) = lhs.lu().solve(&rhs) else {
        return false;
    };
    // second sweep: delta z_i and delta u_i
    let mut dz = SVector::<f64, S>::from_fn(|row, _| if row < nk { -r[row] } else { xi[row - nk] });
    delta[layout.z(0)..layout.z(0) + S].copy_from_slice(dz.as_slice());
    for (i, map) in maps.iter().enumerate().take(steps) {
        let dw = map.affine(&dz);
        delta[layout.z(i + 1)..layout.z(i + 1) + S].copy_from_slice(&dw.as_slice()[..S]);
        delta[layout.u(i)..layout.u(i) + M - S].copy_from_slice(&dw.as_slice()[S..]);
        dz = dw.fixed_rows::<S>(0).into_owned();
    }
    all_finite(delta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::PlanarBarrier;

    #[test]
    fn the_one_pass_norms_see_every_entry() {
        // lengths around the four lanes, the odd entry at every position
        for len in 1..11 {
            for at in 0..len {
                let mut v: Vec<f64> = (0..len).map(|i| i as f64 - 3.5).collect();
                let max = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let sum: f64 = v.iter().map(|x| x * x).sum();
                assert!(all_finite(&v));
                assert_eq!(max_abs(&v), max);
                assert!((squared_norm(&v) - sum).abs() <= 1e-14 * sum);
                v[at] = -9.0;
                assert_eq!(max_abs(&v), 9.0);
                for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                    v[at] = bad;
                    assert!(!all_finite(&v), "{len} {at} {bad}");
                    assert!(!squared_norm(&v).is_finite(), "{len} {at} {bad}");
                }
            }
        }
        assert!(all_finite(&[]));
    }

    #[test]
    fn a_failing_condensation_falls_back_to_the_banded_solve() {
        let system = PlanarBarrier {
            tau: 1e-2,
            radius: 1.0,
            mass: 1.0,
        };
        let (start, goal) = ([-2.0, 1.5, 1.0, 0.0], [2.0, 1.5, 1.0, 0.0]);
        let problem = BoundaryValueProblem::new(&system, &start, &goal, 4.0, 100);
        let never = |_: &SVector<f64, 8>,
                     _: &SVector<f64, 10>,
                     _: &SVector<f64, 10>,
                     _: &mut Linearized<8, 10>| false;
        let fallback = problem.solve_with(Guess::Spline, &never).unwrap();
        let condensed = problem.solve(Guess::Spline).unwrap();
        assert_eq!(fallback.iterations, condensed.iterations);
        for (a, b) in fallback.states.iter().zip(&condensed.states) {
            assert!((a - b).amax() < 1e-10);
        }
    }
}
