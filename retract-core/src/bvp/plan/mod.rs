//! What a solve returns: the plan with its certificate, the real-time result, and the
//! failures with their advice.

use nalgebra::SVector;

pub(super) mod certificate;
pub(super) mod duals;
pub(super) mod failure;
pub(super) mod violations;

use super::dynamics::Dynamics;
use super::guess::Hermite;
use super::iterate::blocks;
use crate::Error;
pub use certificate::Certificate;
use certificate::advice;
use duals::Duals;
pub use failure::Failure;
use violations::Violations;

/// A plan: a certified local minimum of the transcription.
///
/// With `serde`, NaN and infinite numbers (in the last iterate of a failed solve) are written
/// as the strings `"NaN"`, `"inf"` and `"-inf"` and read back, as in [`Certificate`]. A plan
/// read back holds whatever numbers it was given: its uses ([`Self::evaluate`],
/// [`Self::try_shifted`]) check it first ([`Self::validate`]).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Plan<const N: usize, const X: usize> {
    /// Step size $h = T/N$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub h: f64,
    /// The scheme parameter.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub theta: f64,
    /// Jets $x_i = (q, \dots, q^{(k-1)})(t_i)$, $i = 0, \dots, N$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub x: Vec<SVector<f64, X>>,
    /// Top derivatives $u_i$ at the evaluation points, $i < N$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub u: Vec<SVector<f64, N>>,
    /// Ostrogradsky momenta $p_i$ recovered from the multipliers: $z_i = (x_i, p_i)$ is the
    /// state of the lifted scheme (empty where a failed solve did not recover them).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub momenta: Vec<SVector<f64, X>>,
    /// $J = \sum_i h\thinspace L(x_{\theta,i}, u_i)$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub cost: f64,
    /// SQP iterations (the Newton steps of feasibility restoration phases included).
    pub iterations: usize,
    /// Residuals and curvature at this point.
    pub certificate: Certificate,
    /// The largest constraint violation at the nodes, at the evaluation points and along the
    /// interpolant ([`Violations`]).
    #[cfg_attr(feature = "serde", serde(default))]
    pub violations: Violations,
    /// The multipliers, slacks and barrier parameter at this point: a warm start from this
    /// plan ([`PlanGuess::Plan`](super::PlanGuess::Plan)) starts from them too.
    #[cfg_attr(feature = "serde", serde(default))]
    pub duals: Duals<N>,
}

impl<const N: usize, const X: usize> Plan<N, X> {
    /// The times $t_i = i h$ of the jets $x_i$, $i = 0, \dots, N$.
    pub fn times(&self) -> Vec<f64> {
        (0..self.x.len()).map(|i| i as f64 * self.h).collect()
    }

    /// The state $z_i = (x_i, p_i)$ by blocks ([`crate::State`]: $q^{(j)}$, $p_j$ by name), or
    /// `None` past the end; `X` $= nk$ is checked at compile time.
    pub fn state<const K: usize>(&self, i: usize) -> Option<crate::State<N, K>> {
        const { assert!(N * K == X, "X must equal N K") };
        Some(crate::State {
            x: blocks::<N, K, X>(self.x.get(i)?),
            p: blocks::<N, K, X>(self.momenta.get(i)?),
        })
    }

    /// The jet $x(t) = (q, \dots, q^{(k-1)})(t)$ at any $t \in [0, T]$, $T = N h$: on the step
    /// $t_i \le t \le t_{i+1}$ the Hermite interpolant of degree $2k-1$ in each coordinate
    /// that matches the plan's jets $x_i$ at $t_i$ and $x_{i+1}$ at $t_{i+1}$ (for $k = 2$,
    /// with $s = (t - t_i)/h$ and $v = q'$: $q(t) = (2s^3 - 3s^2 + 1) q_i + (s^3 - 2s^2 + s) h
    /// v_i + (3s^2 - 2s^3) q_{i+1} + (s^3 - s^2) h v_{i+1}$). It reproduces polynomials of degree
    /// $2k-1$ exactly and is $C^{k-1}$ across the nodes, where it equals the plan's jets.
    ///
    /// ```
    /// use retract_core::bvp::{OptimalControlProblem, PlanGuess};
    /// use retract_core::models::PlanarBarrier;
    ///
    /// let system = PlanarBarrier { tau: 0.0, radius: 1.0, mass: 1.0 };
    /// let problem = OptimalControlProblem::new(&system, &[0.0; 4], &[1.0, 2.0, 0.0, 0.0], 1.0, 40);
    /// let plan = problem.solve(PlanGuess::Spline)?;
    /// // the continuous optimum from rest to rest is the smoothstep q(T) (3 s^2 - 2 s^3)
    /// let x = plan.evaluate(0.3)?;
    /// let smooth = 3.0 * 0.3f64.powi(2) - 2.0 * 0.3f64.powi(3);
    /// assert!((x[0] - smooth).abs() < 1e-3 && (x[1] - 2.0 * smooth).abs() < 1e-3);
    /// assert_eq!(plan.evaluate(plan.times()[20])?, plan.x[20]); // a node: the plan's jet
    /// assert!(plan.evaluate(1.5).is_err()); // outside [0, T]
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `plan` for a plan that fails [`Self::validate`] or
    /// whose interpolant is not finite at $t$ (a step $h$ too long for its jets, e.g.
    /// $h^{2k-1}$ overflowing), named `t` for $t$ outside $[0, T]$ (beyond a relative
    /// $10^{-12}$ for rounding) or not finite.
    pub fn evaluate(&self, t: f64) -> Result<SVector<f64, X>, Error> {
        self.validate()?;
        let steps = self.u.len();
        let t_end = self.h * steps as f64;
        let slack = 1e-12 * t_end;
        if !(t >= -slack && t <= t_end + slack) {
            return Err(Error::InvalidArgument {
                name: "t",
                requirement: "a plan is evaluated at times 0 <= t <= T = N h",
            });
        }
        let t = t.clamp(0.0, t_end);
        if t == t_end {
            return Ok(self.x[steps]);
        }
        // the step holding t; at a node (t = i h up to the rounding of t / h) the one it starts
        let mut i = ((t / self.h) as usize).min(steps - 1);
        if i + 1 < steps && (i + 1) as f64 * self.h <= t {
            i += 1;
        }
        let local = t - i as f64 * self.h;
        let not_finite = Error::InvalidArgument {
            name: "plan",
            requirement: "its interpolant must be finite: the step h is too long for its jets",
        };
        let piece = Hermite::new(
            self.x[i].as_slice(),
            self.x[i + 1].as_slice(),
            self.h,
            N,
            X / N,
        )
        .map_err(|_| not_finite)?;
        let x = SVector::<f64, X>::from_fn(|r, _| piece.jet_entry(r, local));
        if x.iter().all(|v| v.is_finite()) {
            Ok(x)
        } else {
            Err(not_finite)
        }
    }

    /// Whether this is a plan at all (a plan read back from a file holds whatever numbers it
    /// was given): at least one step, $N + 1$ jets for $N$ top derivatives and $N + 1$
    /// momenta (or none), a finite step $h > 0$ with $T = N h$ finite, $\theta \in [0, 1]$,
    /// and every jet, top derivative and momentum finite. The certificate, the cost and the
    /// duals describe the plan and are not checked (a failed solve's are NaN). Uses of a plan
    /// ([`Self::evaluate`], [`Self::try_shifted`]) run it first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `plan`, its requirement saying which condition fails.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |requirement| {
            Err(Error::InvalidArgument {
                name: "plan",
                requirement,
            })
        };
        let steps = self.u.len();
        if N == 0 || X == 0 || !X.is_multiple_of(N) {
            return invalid("its jets must hold k >= 1 blocks of the N top derivatives");
        }
        if steps == 0
            || self.x.len() != steps + 1
            || !(self.momenta.is_empty() || self.momenta.len() == steps + 1)
        {
            return invalid(
                "it needs N >= 1 top derivatives, N + 1 jets and N + 1 momenta (or none)",
            );
        }
        if !(self.h > 0.0 && (self.h * steps as f64).is_finite()) {
            return invalid("its step h must be finite and > 0, and T = N h finite");
        }
        if !(0.0..=1.0).contains(&self.theta) {
            return invalid("its theta must lie in [0, 1]");
        }
        let finite = |v: &[f64]| v.iter().all(|e| e.is_finite());
        if !(self.x.iter().all(|x| finite(x.as_slice()))
            && self.u.iter().all(|u| finite(u.as_slice()))
            && self.momenta.iter().all(|p| finite(p.as_slice())))
        {
            return invalid("its jets, top derivatives and momenta must be finite");
        }
        Ok(())
    }

    /// The plan shifted one step forward in time, for a receding-horizon warm start
    /// ([`PlanGuess::Plan`](super::PlanGuess::Plan)): $x_i \leftarrow x_{i+1}$, $u_i \leftarrow u_{i+1}$, the last
    /// top derivative repeated and the new last jet one step of the scheme's $x$-equations
    /// from the old end with it. The momenta and the duals are shifted alike (the last ones
    /// repeated); the certificate is that of the unshifted plan.
    ///
    /// # Errors
    /// As [`Self::validate`]; [`Error::InvalidArgument`] named `plan` when the new last jet is
    /// not finite (a step $h$ too long for the scheme's $x$-equations).
    pub fn try_shifted(&self) -> Result<Self, Error> {
        self.validate()?;
        let mut out = self.clone();
        out.try_shift()?;
        Ok(out)
    }

    /// [`Self::try_shifted`] in place (no allocation); on an error the plan is unchanged.
    ///
    /// # Errors
    /// As [`Self::try_shifted`].
    pub fn try_shift(&mut self) -> Result<(), Error> {
        self.validate()?;
        let (Some(&last_x), Some(&last_u)) = (self.x.last(), self.u.last()) else {
            return Ok(());
        };
        let next = Dynamics::<N, X>::new(self.h, self.theta).next(&last_x, &last_u);
        if !next.iter().all(|v| v.is_finite()) {
            return Err(Error::InvalidArgument {
                name: "plan",
                requirement: "its last jet stepped by h must be finite: h is too long for it",
            });
        }
        self.x.remove(0);
        self.x.push(next);
        self.u.remove(0);
        self.u.push(last_u);
        if let Some(&last_p) = self.momenta.last() {
            self.momenta.remove(0);
            self.momenta.push(last_p);
        }
        self.duals.shift(self.u.len());
        Ok(())
    }

    /// [`Self::try_shifted`], with a plan it refuses returned unchanged (one that fails
    /// [`Self::validate`], e.g. read back from a damaged file, or whose step $h$ is too long
    /// for the scheme): [`Self::try_shifted`] says why, and [`Self::evaluate`] refuses such a
    /// plan in turn.
    pub fn shifted(&self) -> Self {
        self.try_shifted().unwrap_or_else(|_| self.clone())
    }
}

/// The result of [`OptimalControlProblem::solve_real_time`](super::OptimalControlProblem::solve_real_time).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RealTime<const N: usize, const X: usize> {
    /// The last iterate (a certified minimum only if `converged`).
    pub plan: Plan<N, X>,
    /// Whether the KKT and second-order conditions hold at `plan`.
    pub converged: bool,
}

/// A failed solve: the reason and, where there was one, the last iterate with its residuals
/// (its `certificate` describes it; it is not a minimum). Its `Debug` output summarises the
/// iterate instead of listing it.
#[derive(Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PlanError<const N: usize, const X: usize> {
    /// Why.
    pub failure: Failure,
    /// The last iterate (the best by the merit function).
    pub last: Option<Box<Plan<N, X>>>,
}

impl<const N: usize, const X: usize> PlanError<N, X> {
    /// A failure before the first iterate was formed.
    pub(in crate::bvp) fn without_iterate(failure: Failure) -> Self {
        Self {
            failure,
            last: None,
        }
    }
}

impl<const N: usize, const X: usize> core::fmt::Display for PlanError<N, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}", self.failure)?;
        if let Some(last) = &self.last {
            let c = &last.certificate;
            if matches!(self.failure, Failure::FreeTimeSearch { .. }) {
                // (the iterations are the search's, in the failure)
                let horizon = last.h * last.u.len() as f64;
                write!(f, " (the best plan: T = {horizon}, J = {:e})", last.cost)?;
                return Ok(());
            }
            write!(
                f,
                " (after {} iterations: cost {:e}, stationarity {:e}, feasibility {:e})",
                last.iterations, last.cost, c.stationarity, c.feasibility
            )?;
            if matches!(self.failure, Failure::IterationLimit | Failure::TimeLimit) {
                write!(f, "; {}", advice(c, last.iterations))?;
            }
        }
        Ok(())
    }
}

impl<const N: usize, const X: usize> core::fmt::Debug for PlanError<N, X> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let mut d = f.debug_struct("PlanError");
        d.field("failure", &self.failure);
        if let Some(last) = &self.last {
            d.field("steps", &last.u.len())
                .field("iterations", &last.iterations)
                .field("cost", &last.cost)
                .field("certificate", &last.certificate);
        }
        d.finish()
    }
}

impl<const N: usize, const X: usize> std::error::Error for PlanError<N, X> {}

#[cfg(test)]
mod tests {
    use nalgebra::SVector;

    use super::certificate::{LONG_RUN, advice};
    use super::{Certificate, Duals, Plan, Violations};
    use crate::Error;

    fn residuals(stationarity: f64, feasibility: f64) -> Certificate {
        Certificate {
            stationarity,
            feasibility,
            complementarity: 0.0,
            negative_directions: 0,
            min_reduced_hessian_eig: f64::NAN,
        }
    }

    /// The advice after a budget ran out follows the residuals and the iterations spent: a
    /// converged iterate is not told to iterate more, an infeasible one to check its
    /// constraints, and one that has not settled in a long run not to raise the budget.
    #[test]
    fn the_advice_of_a_spent_budget_matches_the_iterate() {
        assert!(advice(&residuals(1e-6, 1e-9), 50).contains("will not improve"));
        assert!(advice(&residuals(1.0, 1e-2), 50).contains("far from feasible"));
        assert!(advice(&residuals(1.0, 1e-9), 50).contains("raise max_iterations"));
        let long = advice(&residuals(5.3, 2.7e-9), LONG_RUN);
        assert!(
            long.contains("unlikely to help") && !long.contains("raise"),
            "{long}"
        );
    }

    /// A plan of `steps` steps along the line $q(t) = (t, 2t)$ over $T = 1$: jets $(q, q')$,
    /// top derivatives $q'' = 0$, zero momenta, finite residuals (so that plans compare
    /// equal).
    fn line(steps: usize) -> Plan<2, 4> {
        let h = 1.0 / steps as f64;
        Plan {
            h,
            theta: 0.5,
            x: (0..=steps)
                .map(|i| {
                    let t = i as f64 * h;
                    SVector::from([t, 2.0 * t, 1.0, 2.0])
                })
                .collect(),
            u: vec![SVector::zeros(); steps],
            momenta: vec![SVector::zeros(); steps + 1],
            cost: 0.0,
            iterations: 1,
            certificate: Certificate {
                min_reduced_hessian_eig: 0.5,
                ..residuals(0.0, 0.0)
            },
            violations: Violations::default(),
            duals: Duals::default(),
        }
    }

    /// `line(4)` changed by `edit`.
    fn edited(edit: impl FnOnce(&mut Plan<2, 4>)) -> Plan<2, 4> {
        let mut plan = line(4);
        edit(&mut plan);
        plan
    }

    /// Plans whose data cannot be a plan, each with what is wrong with it.
    fn hostile() -> Vec<(&'static str, Plan<2, 4>)> {
        vec![
            ("h = 1e308 (T = N h overflows)", edited(|p| p.h = 1e308)),
            ("h NaN", edited(|p| p.h = f64::NAN)),
            ("h infinite", edited(|p| p.h = f64::INFINITY)),
            ("h = 0", edited(|p| p.h = 0.0)),
            ("h < 0", edited(|p| p.h = -0.25)),
            ("theta = 2", edited(|p| p.theta = 2.0)),
            ("theta NaN", edited(|p| p.theta = f64::NAN)),
            ("a NaN jet", edited(|p| p.x[2][1] = f64::NAN)),
            ("an infinite jet", edited(|p| p.x[4][3] = f64::INFINITY)),
            (
                "an infinite top derivative",
                edited(|p| p.u[1][0] = f64::INFINITY),
            ),
            ("a NaN momentum", edited(|p| p.momenta[3][2] = f64::NAN)),
            ("a top derivative missing", edited(|p| p.u.truncate(3))),
            ("a jet too many", edited(|p| p.x.push(SVector::zeros()))),
            ("a momentum missing", edited(|p| p.momenta.truncate(4))),
            (
                "no steps",
                edited(|p| {
                    p.x.truncate(1);
                    p.u.clear();
                    p.momenta.truncate(1);
                }),
            ),
        ]
    }

    /// Every use of a plan refuses one whose data cannot be a plan (issue 33, item 7: a plan
    /// with h = 1e308 evaluated to `Ok(NaN)`); a valid one evaluates.
    #[test]
    fn a_plan_that_cannot_be_one_is_refused_on_use() {
        let valid = line(4);
        let x = valid.evaluate(0.3).expect("a valid plan");
        assert!(
            (x - SVector::from([0.3, 0.6, 1.0, 2.0])).amax() < 1e-15,
            "{x}"
        );
        assert_eq!(valid.validate(), Ok(()));
        let shifted = valid.try_shifted().expect("a valid plan");
        assert_eq!(shifted, valid.shifted());
        assert!((shifted.x[4] - SVector::from([1.25, 2.5, 1.0, 2.0])).amax() < 1e-15);
        for (what, plan) in hostile() {
            for t in [0.0, 0.1, 0.25] {
                let result = plan.evaluate(t);
                assert!(
                    matches!(result, Err(Error::InvalidArgument { name: "plan", .. })),
                    "{what}, t = {t}: {result:?}"
                );
            }
            let refused = plan.validate().expect_err(what);
            assert_eq!(plan.try_shifted().expect_err(what), refused, "{what}");
            assert!(
                refused.to_string().contains("invalid argument `plan`"),
                "{refused}"
            );
            // shifted returns it unchanged (NaN fields compared by their Debug form)
            assert_eq!(
                format!("{:?}", plan.shifted()),
                format!("{plan:?}"),
                "{what}"
            );
        }
        // a plan without momenta (a failed solve's) is a plan
        let mut bare = line(4);
        bare.momenta.clear();
        assert!(bare.validate().is_ok() && bare.evaluate(0.5).is_ok());
        // T = N h finite, but a step too long for the interpolant: not Ok(NaN) either
        let mut long = line(1);
        long.h = 1e308;
        assert!(long.validate().is_ok());
        assert!(long.try_shifted().is_err());
        for t in [0.0, 0.5e308] {
            let result = long.evaluate(t);
            assert!(
                matches!(result, Err(Error::InvalidArgument { name: "plan", .. })),
                "t = {t}: {result:?}"
            );
        }
    }

    /// NaN and infinite fields of a plan (a failed solve's certificate, its cost, its iterate)
    /// round-trip through JSON as "NaN", "inf" and "-inf"; finite ones stay plain numbers, and
    /// `null` (what a plain `f64` field wrote) reads as NaN (issue 33, item 7).
    #[cfg(feature = "serde")]
    #[test]
    fn non_finite_fields_round_trip_through_json() {
        let mut plan = edited(|p| {
            p.cost = f64::NAN;
            p.certificate = super::certificate::unknown_certificate();
            p.certificate.complementarity = f64::INFINITY;
            p.violations = Violations {
                nodes: f64::NAN,
                midpoints: f64::NEG_INFINITY,
                interpolant: 0.5,
            };
            p.x[2][1] = f64::NAN;
            p.momenta[1][0] = f64::NEG_INFINITY;
            p.duals.barrier = f64::NAN;
            p.duals.step_slacks = vec![f64::INFINITY, 1.0];
            p.duals.equalities = vec![SVector::from([f64::NAN, 1.0])];
        });
        let json = serde_json::to_string(&plan).unwrap();
        for field in [
            r#""cost":"NaN""#,
            r#""stationarity":"NaN""#,
            r#""feasibility":"NaN""#,
            r#""complementarity":"inf""#,
            r#""min_reduced_hessian_eig":"NaN""#,
            r#""nodes":"NaN""#,
            r#""midpoints":"-inf""#,
            r#"[0.5,"NaN",1.0,2.0]"#,
            r#"["-inf",0.0,0.0,0.0]"#,
            r#""barrier":"NaN""#,
            r#""step_slacks":["inf",1.0]"#,
            r#""equalities":[["NaN",1.0]]"#,
            // finite values stay numbers
            r#""h":0.25"#,
            r#""theta":0.5"#,
            r#""interpolant":0.5"#,
            r#""x":[[0.0,0.0,1.0,2.0],"#,
        ] {
            assert!(json.contains(field), "{json} lacks {field}");
        }
        let back: Plan<2, 4> = serde_json::from_str(&json).unwrap();
        assert!(back.cost.is_nan() && back.certificate.stationarity.is_nan());
        assert_eq!(back.certificate.complementarity, f64::INFINITY);
        assert_eq!(back.violations.midpoints, f64::NEG_INFINITY);
        assert!(back.x[2][1].is_nan() && back.duals.barrier.is_nan());
        assert_eq!(back.momenta[1][0], f64::NEG_INFINITY);
        assert_eq!(serde_json::to_string(&back).unwrap(), json);
        // what a plain f64 field wrote for any non-finite value: null, read as NaN
        let old = json.replace(r#""NaN""#, "null");
        let read: Plan<2, 4> = serde_json::from_str(&old).unwrap();
        assert!(read.cost.is_nan() && read.x[2][1].is_nan() && read.duals.barrier.is_nan());
        // another string is an error that says what is accepted
        let wrong = json.replacen(r#""cost":"NaN""#, r#""cost":"nan""#, 1);
        let error = serde_json::from_str::<Plan<2, 4>>(&wrong).unwrap_err();
        assert!(
            error.to_string().contains(r#""NaN", "inf", "-inf""#),
            "{error}"
        );
        // a finite plan round-trips exactly
        plan = line(4);
        let json = serde_json::to_string(&plan).unwrap();
        assert_eq!(serde_json::from_str::<Plan<2, 4>>(&json).unwrap(), plan);
        // the certificate alone
        let json = serde_json::to_string(&super::certificate::unknown_certificate()).unwrap();
        let read: Certificate = serde_json::from_str(&json).unwrap();
        assert!(read.stationarity.is_nan() && read.min_reduced_hessian_eig.is_nan());
    }

    /// Hostile JSON that reads into a plan is refused by every use of it (issue 33, item 7).
    #[cfg(feature = "serde")]
    #[test]
    fn a_hostile_plan_from_json_is_refused_on_use() {
        type Edit = fn(&mut serde_json::Value);
        let valid = serde_json::to_value(line(4)).unwrap();
        let edits: [(&str, Edit); 8] = [
            ("h = 1e308", |v| v["h"] = 1e308.into()),
            ("h = \"inf\"", |v| v["h"] = "inf".into()),
            ("h = -0.25", |v| v["h"] = (-0.25).into()),
            ("theta = \"NaN\"", |v| v["theta"] = "NaN".into()),
            ("a NaN jet", |v| v["x"][2][1] = "NaN".into()),
            ("an infinite top derivative", |v| {
                v["u"][0][0] = "inf".into()
            }),
            ("a top derivative missing", |v| {
                v["u"].as_array_mut().map(Vec::pop);
            }),
            ("no jets", |v| v["x"] = serde_json::json!([])),
        ];
        for (what, edit) in edits {
            let mut value = valid.clone();
            edit(&mut value);
            let plan: Plan<2, 4> = serde_json::from_value(value)
                .unwrap_or_else(|e| panic!("{what}: the JSON reads ({e})"));
            let result = plan.evaluate(0.1);
            assert!(
                matches!(result, Err(Error::InvalidArgument { name: "plan", .. })),
                "{what}: {result:?}"
            );
            assert!(
                plan.validate().is_err() && plan.try_shifted().is_err(),
                "{what}"
            );
        }
        // a jet with the wrong number of entries does not read
        let mut value = valid;
        value["x"][1] = serde_json::json!([0.25, 0.5, 1.0]);
        assert!(serde_json::from_value::<Plan<2, 4>>(value.clone()).is_err());
        value["x"][1] = serde_json::json!([0.25, 0.5, 1.0, 2.0, 3.0]);
        assert!(serde_json::from_value::<Plan<2, 4>>(value).is_err());
    }
}
