//! First guesses from a path $q(t)$: a closure, a closure with its derivatives, or waypoints.

use nalgebra::SVector;

use super::iterate::Iterate;
use crate::state::{Jet, State};
use crate::{Error, Lagrangian, LiftedSystem};

/// A path $t \mapsto q(t) \in \mathbb{R}^N$ that the solvers sample into a first guess: the
/// library forms the jets $(q, \dots, q^{(2k-1)})(t_i)$ at the nodes $t_i = i h$, the top
/// derivatives $u_i = q^{(k)}((i + \theta) h)$ for the optimizer ([`super::PlanGuess::Curve`])
/// and the momenta by the Legendre map for the root finder ([`Self::states`], for
/// [`super::root_finder::Guess::States`]).
///
/// Three ways to give it:
/// - [`Self::from_fn`]: $q(t)$ alone; derivatives by central differences,
///   $q^{(j)}(t) \approx d^{-j} \sum_{m=0}^{j} (-1)^m \binom{j}{m}\thinspace
///   q(t + (j/2 - m) d)$ with $d = \varepsilon^{1/(j+2)}$ ($\varepsilon$ the machine epsilon,
///   $t$ in the units of the problem), error $O(d^2)$;
/// - [`Self::from_derivatives`]: $q^{(j)}(t)$ for every $j$ from the caller;
/// - [`Self::through_waypoints`]: the natural cubic spline through $(t_i, q_i)$ ($C^2$,
///   $q'' = 0$ at both ends; its derivatives above the third are 0).
///
/// # Example
/// A guess that bends over the unit disc instead of the straight line through it, as
/// waypoints (the optimizer refuses a first guess through the obstacle):
/// ```
/// use retract::bvp::{Curve, OptimalControlProblem, PlanGuess};
/// use retract::higher_order_lagrangian;
///
/// /// Minimum acceleration past the unit disc: L = 1/2 |q''|^2 + tau / (|q|^2 - 1).
/// #[higher_order_lagrangian(order = 2)]
/// fn disc(q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
///     0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
/// }
///
/// let system = Disc::new(1e-2);
/// let (start, goal) = ([-2.0, 0.0, 1.0, 0.0], [2.0, 0.0, 1.0, 0.0]);
/// let over = Curve::through_waypoints(&[0.0, 2.0, 4.0], &[[-2.0, 0.0], [0.0, 1.3], [2.0, 0.0]])?;
/// let problem = OptimalControlProblem::new(&system, &start, &goal, 4.0, 200);
/// let plan = problem.solve(PlanGuess::Curve(&over))?;
/// assert!(plan.x.iter().all(|x| x[0].hypot(x[1]) > 1.0)); // it passes above the disc
/// assert!(plan.evaluate(2.0)?[1] > 1.0);
/// // the same path as a closure, and as states for the root finder
/// let bump = Curve::from_fn(|t: f64| [t - 2.0, 1.3 * (std::f64::consts::PI * t / 4.0).sin()]);
/// assert_eq!(bump.states(&system, 4.0, 200)?.len(), 201);
/// let again = problem.solve(PlanGuess::Curve(&bump))?;
/// assert!((again.cost - plan.cost).abs() < 1e-6 * plan.cost);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Curve<'a, const N: usize> {
    kind: Kind<'a, N>,
}

// (`Send + Sync`: a guess is shared by the threads of a batch or a multi-start)
type Function<'a, const N: usize> = Box<dyn Fn(f64) -> [f64; N] + Send + Sync + 'a>;
type Derivatives<'a, const N: usize> = Box<dyn Fn(f64, usize) -> [f64; N] + Send + Sync + 'a>;

enum Kind<'a, const N: usize> {
    Function(Function<'a, N>),
    Derivatives(Derivatives<'a, N>),
    Spline(Spline<N>),
}

impl<const N: usize> core::fmt::Debug for Curve<'_, N> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match &self.kind {
            Kind::Function(_) => f.write_str("Curve::from_fn(..)"),
            Kind::Derivatives(_) => f.write_str("Curve::from_derivatives(..)"),
            Kind::Spline(s) => write!(f, "Curve::through_waypoints({} points)", s.times.len()),
        }
    }
}

fn invalid(name: &'static str, requirement: &'static str) -> Error {
    Error::InvalidArgument { name, requirement }
}

/// $\binom{j}{m}$.
fn binomial(j: usize, m: usize) -> f64 {
    (0..m).fold(1.0, |c, i| c * (j - i) as f64 / (i + 1) as f64)
}

impl<'a, const N: usize> Curve<'a, N> {
    /// The path $q(t)$, its derivatives by central differences (see the type docs). The
    /// closure is called at times up to $(2k-1) d / 2 \approx 0.004$ beyond the horizon
    /// $[0, T]$, so it must be defined there.
    pub fn from_fn(q: impl Fn(f64) -> [f64; N] + Send + Sync + 'a) -> Self {
        Self {
            kind: Kind::Function(Box::new(q)),
        }
    }

    /// The path from its derivatives: `derivative(t, j)` $= q^{(j)}(t)$, called for
    /// $j = 0, \dots, 2k-1$ (the root finder's momenta need them all; the optimizer only
    /// $j \le k$).
    pub fn from_derivatives(
        derivative: impl Fn(f64, usize) -> [f64; N] + Send + Sync + 'a,
    ) -> Self {
        Self {
            kind: Kind::Derivatives(Box::new(derivative)),
        }
    }

    /// The natural cubic spline through the waypoints $(t_i, q_i)$: a cubic on each
    /// $[t_i, t_{i+1}]$, $C^2$ at the waypoints, $q'' = 0$ at the first and last. It is
    /// defined on $[t_0, t_m]$, which must contain the horizon $[0, T]$ of the problem it
    /// guesses for.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for fewer than 2 waypoints, as many times as points not
    /// given, times not finite and strictly increasing, or points not finite.
    pub fn through_waypoints(times: &[f64], points: &[[f64; N]]) -> Result<Self, Error> {
        Spline::new(times, points).map(|spline| Self {
            kind: Kind::Spline(spline),
        })
    }

    /// $q^{(j)}(t)$.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a non-finite value, or $t$ outside the waypoints' span.
    pub fn derivative(&self, t: f64, j: usize) -> Result<SVector<f64, N>, Error> {
        let value = match &self.kind {
            Kind::Function(q) => {
                let d = f64::EPSILON.powf(1.0 / (j as f64 + 2.0));
                let mut sum = SVector::<f64, N>::zeros();
                for m in 0..=j {
                    let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
                    let at = t + (j as f64 / 2.0 - m as f64) * d;
                    sum += SVector::from(q(at)) * (sign * binomial(j, m));
                }
                sum / d.powi(j as i32)
            }
            Kind::Derivatives(derivative) => SVector::from(derivative(t, j)),
            Kind::Spline(spline) => spline.derivative(t, j)?,
        };
        if value.iter().all(|v| v.is_finite()) {
            Ok(value)
        } else {
            Err(invalid(
                "curve",
                "the path and its derivatives must be finite at the sampled times",
            ))
        }
    }

    /// The derivative data $(q, \dots, q^{(2k-1)})(t)$.
    ///
    /// # Errors
    /// As [`Self::derivative`].
    pub fn jet<const K: usize>(&self, t: f64) -> Result<Jet<N, K>, Error> {
        let mut jet = Jet {
            lower: [SVector::zeros(); K],
            upper: [SVector::zeros(); K],
        };
        for j in 0..K {
            jet.lower[j] = self.derivative(t, j)?;
            jet.upper[j] = self.derivative(t, K + j)?;
        }
        Ok(jet)
    }

    /// The states $z_i = \mathrm{Leg}((q, \dots, q^{(2k-1)})(t_i))$ at $t_i = i T / N$,
    /// $i = 0, \dots, N$ (`t_end` $= T$, `steps` $= N$): the first guess
    /// [`super::root_finder::Guess::States`] of the root finder.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for `t_end` not finite and positive, no steps, more states
    /// than fit in memory, or as [`Self::derivative`]; [`Error::NonFinite`] for non-finite
    /// momenta.
    pub fn states<Sys, const K: usize, const S: usize, const M: usize>(
        &self,
        system: &Sys,
        t_end: f64,
        steps: usize,
    ) -> Result<Vec<SVector<f64, S>>, Error>
    where
        Sys: Lagrangian<N, K> + LiftedSystem<S, M> + ?Sized,
    {
        let h = horizon(t_end, steps)?;
        let mut states = Vec::new();
        states
            .try_reserve_exact(steps.saturating_add(1))
            .map_err(|_| invalid("steps", "the states of the guess must fit in memory"))?;
        for i in 0..=steps {
            let jet = self.jet::<K>(i as f64 * h)?;
            states.push(State::from_jet(system, &jet)?.to_vector());
        }
        Ok(states)
    }

    /// The optimizer's guess: jets $x_i = (q, \dots, q^{(k-1)})(t_i)$ and top derivatives
    /// $u_i = q^{(k)}((i + \theta) h)$.
    pub(super) fn sample<const K: usize, const X: usize>(
        &self,
        t_end: f64,
        steps: usize,
        theta: f64,
    ) -> Result<Iterate<N, X>, Error> {
        const { assert!(N * K == X, "X must equal N K") };
        let h = horizon(t_end, steps)?;
        let mut x = Vec::with_capacity(steps + 1);
        for i in 0..=steps {
            let t = i as f64 * h;
            let mut jet = SVector::<f64, X>::zeros();
            for j in 0..K {
                jet.fixed_rows_mut::<N>(j * N)
                    .copy_from(&self.derivative(t, j)?);
            }
            x.push(jet);
        }
        let u = (0..steps)
            .map(|i| self.derivative((i as f64 + theta) * h, K))
            .collect::<Result<_, _>>()?;
        Ok(Iterate { x, u })
    }
}

/// $h = T / N$ for a valid horizon.
fn horizon(t_end: f64, steps: usize) -> Result<f64, Error> {
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(invalid("t_end", "the horizon must be finite and positive"));
    }
    if steps == 0 {
        return Err(invalid("steps", "at least one step is needed"));
    }
    Ok(t_end / steps as f64)
}

/// The natural cubic spline through $(t_i, y_i)$ with second derivatives $M_i$: on
/// $[t_i, t_{i+1}]$, $h_i = t_{i+1} - t_i$, $a = (t_{i+1} - t)/h_i$, $b = 1 - a$,
/// $S = a y_i + b y_{i+1} + ((a^3 - a) M_i + (b^3 - b) M_{i+1}) h_i^2 / 6$.
struct Spline<const N: usize> {
    times: Vec<f64>,
    points: Vec<SVector<f64, N>>,
    /// $M_i = S''(t_i)$.
    second: Vec<SVector<f64, N>>,
}

impl<const N: usize> Spline<N> {
    fn new(times: &[f64], points: &[[f64; N]]) -> Result<Self, Error> {
        if times.len() < 2 || times.len() != points.len() {
            return Err(invalid(
                "waypoints",
                "need at least 2 waypoints and one time per waypoint",
            ));
        }
        if !times.iter().all(|t| t.is_finite()) || !times.windows(2).all(|w| w[0] < w[1]) {
            return Err(invalid(
                "times",
                "waypoint times must be finite and strictly increasing",
            ));
        }
        if !points.iter().flatten().all(|v| v.is_finite()) {
            return Err(invalid("waypoints", "waypoints must be finite"));
        }
        let y: Vec<SVector<f64, N>> = points.iter().map(|p| SVector::from(*p)).collect();
        let m = times.len() - 1;
        let h: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        // h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (slope_i - slope_{i-1}),
        // i = 1..m-1, M_0 = M_m = 0: the Thomas algorithm (diagonally dominant)
        let mut second = vec![SVector::<f64, N>::zeros(); m + 1];
        let mut diagonal = vec![0.0; m + 1];
        let mut rhs = vec![SVector::<f64, N>::zeros(); m + 1];
        for i in 1..m {
            diagonal[i] = 2.0 * (h[i - 1] + h[i]);
            rhs[i] = ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1]) * 6.0;
            if i > 1 {
                let factor = h[i - 1] / diagonal[i - 1];
                diagonal[i] -= factor * h[i - 1];
                let previous = rhs[i - 1];
                rhs[i] -= previous * factor;
            }
        }
        for i in (1..m).rev() {
            second[i] = (rhs[i] - second[i + 1] * h[i]) / diagonal[i];
        }
        if !second.iter().all(|s| s.iter().all(|v| v.is_finite())) {
            return Err(invalid(
                "times",
                "waypoint times too close together for a finite spline",
            ));
        }
        Ok(Self {
            times: times.to_vec(),
            points: y,
            second,
        })
    }

    fn derivative(&self, t: f64, j: usize) -> Result<SVector<f64, N>, Error> {
        let (first, last) = (self.times[0], self.times[self.times.len() - 1]);
        let slack = 1e-12 * (last - first);
        if !(t >= first - slack && t <= last + slack) {
            return Err(invalid(
                "curve",
                "the waypoints' times must span the horizon [0, T]",
            ));
        }
        let i = self
            .times
            .partition_point(|&ti| ti <= t)
            .clamp(1, self.times.len() - 1)
            - 1;
        let h = self.times[i + 1] - self.times[i];
        let b = (t - self.times[i]) / h;
        let a = 1.0 - b;
        let (y0, y1, m0, m1) = (
            self.points[i],
            self.points[i + 1],
            self.second[i],
            self.second[i + 1],
        );
        Ok(match j {
            0 => y0 * a + y1 * b + (m0 * (a * a * a - a) + m1 * (b * b * b - b)) * (h * h / 6.0),
            1 => {
                (y1 - y0) / h - m0 * ((3.0 * a * a - 1.0) * h / 6.0)
                    + m1 * ((3.0 * b * b - 1.0) * h / 6.0)
            }
            2 => m0 * a + m1 * b,
            3 => (m1 - m0) / h,
            _ => SVector::zeros(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spline through samples of a cubic with zero second derivative at both ends is not
    /// that cubic in general, but a spline through points of a straight line is the line,
    /// and the spline interpolates, is C^2 at an interior waypoint and has S'' = 0 at the ends.
    #[test]
    fn spline_interpolates_and_is_twice_continuous() {
        let times = [0.0, 0.5, 1.7, 3.0];
        let points = [[0.0, 1.0], [1.0, -1.0], [0.5, 2.0], [2.0, 0.0]];
        let curve = Curve::through_waypoints(&times, &points).unwrap();
        for (t, p) in times.iter().zip(&points) {
            let q = curve.derivative(*t, 0).unwrap();
            assert!(
                (q - SVector::from(*p)).amax() < 1e-14,
                "t = {t}: {q} vs {p:?}"
            );
        }
        for j in 0..3 {
            let left = curve.derivative(1.7 - 1e-9, j).unwrap();
            let right = curve.derivative(1.7 + 1e-9, j).unwrap();
            assert!((left - right).amax() < 1e-6, "q^({j}) jumps at 1.7");
        }
        for t in [0.0, 3.0] {
            assert!(curve.derivative(t, 2).unwrap().amax() < 1e-13);
        }
        let line = Curve::through_waypoints(&[0.0, 1.0, 3.0], &[[1.0], [3.0], [7.0]]).unwrap();
        for t in [0.0, 0.3, 1.0, 2.2, 3.0] {
            assert!((line.derivative(t, 0).unwrap()[0] - (1.0 + 2.0 * t)).abs() < 1e-14);
            assert!((line.derivative(t, 1).unwrap()[0] - 2.0).abs() < 1e-14);
        }
    }

    #[test]
    fn waypoints_are_validated() {
        let one = Curve::through_waypoints(&[0.0], &[[0.0]]);
        let unequal = Curve::through_waypoints(&[0.0, 1.0], &[[0.0]]);
        let decreasing = Curve::through_waypoints(&[0.0, 1.0, 1.0], &[[0.0], [1.0], [2.0]]);
        let nan_time = Curve::through_waypoints(&[0.0, f64::NAN], &[[0.0], [1.0]]);
        let nan_point = Curve::through_waypoints(&[0.0, 1.0], &[[0.0], [f64::INFINITY]]);
        for result in [one, unequal, decreasing, nan_time, nan_point] {
            assert!(matches!(result, Err(Error::InvalidArgument { .. })));
        }
        let short = Curve::through_waypoints(&[0.0, 1.0], &[[0.0], [1.0]]).unwrap();
        assert!(short.derivative(1.5, 0).is_err());
        assert!(short.derivative(-0.1, 0).is_err());
        assert!(short.derivative(f64::NAN, 0).is_err());
    }

    /// Central differences of q = (sin 2t, t^5) against the exact derivatives: relative
    /// error below 1e-4 up to the fifth derivative (a k = 3 state needs them).
    #[test]
    fn finite_differences_match_exact_derivatives() {
        let curve = Curve::from_fn(|t: f64| [(2.0 * t).sin(), t.powi(5)]);
        let exact = |t: f64, j: usize| {
            let sine =
                2f64.powi(j as i32) * (2.0 * t + j as f64 * std::f64::consts::FRAC_PI_2).sin();
            let falling: f64 = (0..j).map(|i| (5 - i) as f64).product();
            let power = if j <= 5 {
                falling * t.powi(5 - j as i32)
            } else {
                0.0
            };
            [sine, power]
        };
        for t in [0.0, 0.4, 1.3] {
            for j in 0..6 {
                let approx = curve.derivative(t, j).unwrap();
                let want = exact(t, j);
                for a in 0..2 {
                    let scale = 1.0 + want[a].abs();
                    assert!(
                        (approx[a] - want[a]).abs() < 1e-4 * scale,
                        "q^({j})_{a}({t}) = {} vs {}",
                        approx[a],
                        want[a]
                    );
                }
            }
        }
    }

    #[test]
    fn non_finite_paths_are_errors() {
        let curve = Curve::from_derivatives(|t: f64, j| [if j == 3 { f64::NAN } else { t }]);
        assert!(curve.derivative(0.5, 2).is_ok());
        assert!(curve.jet::<1>(0.5).is_ok()); // k = 1 needs q and q' only
        assert!(curve.jet::<2>(0.5).is_err());
        assert!(curve.sample::<2, 2>(1.0, 4, 0.5).is_ok()); // u = q'' only
        assert!(curve.sample::<2, 2>(f64::NAN, 4, 0.5).is_err());
        assert!(curve.sample::<2, 2>(1.0, 0, 0.5).is_err());
    }
}
