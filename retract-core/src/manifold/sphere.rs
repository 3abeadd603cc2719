//! Systems on the unit sphere $S^2$ in moving gnomonic charts.
//!
//! A Lagrangian written in ambient coordinates ($q, q', \dots \in \mathbb{R}^3$,
//! `#[higher_order_lagrangian(order = k, sphere)]`) is generated as a system on
//! $\mathbb{R}^2$ composed with the chart [`Chart`] $\varphi(y) = s/|s|$,
//! $s = c + y_0 e_1 + y_1 e_2$, whose frame $(c, e_1, e_2)$ is a run-time parameter
//! ([`SphereSystem`]). A [`SphereState`] is a chart and a state $z = (x, p)$ in it. A step
//! ([`step`]) runs the integrator of a discretization map on $S^2$ ([`SphereMap`], e.g. the
//! projection midpoint) written in the chart centred at the current point, then moves to the
//! chart centred at the new point: the jet by the lift of the transition map, the momenta by
//! its inverse transpose (a cotangent lift, so exactly symplectic).
//!
//! Why this route: the maps on $S^2$ are intrinsic (their integrator on $T^*(T^{(k-1)}S^2)$
//! does not depend on the chart it is computed in), so the step is the same symplectic map
//! whichever chart computes it, and the chart centred at the current point keeps every
//! coordinate small and away from the chart's boundary (the equator of $c$). The point is
//! $\varphi(y)$, a unit vector to rounding at every step, and the rotation-equivariance of
//! the maps and of the chart change gives discrete Noether conservation
//! ([`SphereState::momentum`]) for rotation-invariant Lagrangians.
//!
//! Transitions between gnomonic charts are linear-fractional: in homogeneous coordinates
//! $w = (1, y)$ and the frame matrix $F = [c\ e_1\ e_2]$, chart $b$ sees the point of chart
//! $a$ at $\psi(w) = E_b^T F_a w / (c_b \cdot F_a w)$ (the normalisation cancels). Along a
//! jet, $\psi^{(j)}$ follows from Leibniz' rule for $\psi\thinspace d = n$ with $n = E_b^T F_a w$,
//! $d = c_b \cdot F_a w$:
//! $$\psi^{(j)} = \Big(n^{(j)} - \sum_{i=1}^{j} \tbinom{j}{i} d^{(i)} \psi^{(j-i)}\Big) / d.$$

use nalgebra::{Matrix2x3, Matrix3, Matrix3x2, SMatrix, SVector, Vector2, Vector3};

use crate::manifold::{CentredSystem, MovingChart};
use crate::numeric::newton::NewtonOptions;
use crate::scheme::lifted::{Blocks, join, split};
use crate::scheme::map::DiscretizationMap;
use crate::scheme::step::StepReport;
use crate::{Error, Lagrangian, LiftedSystem};

/// The longest jet handled here: $q, \dots, q^{(2k-1)}$ for $k \le 4$.
const MAX_JET: usize = 8;

/// How far from orthonormal a chart frame, and from the unit sphere a state's point, may be
/// ([`SphereState::validate`]): both are exact to rounding ($\sim 10^{-16}$) for every state
/// built here.
const ON_SPHERE: f64 = 1e-12;

/// A jet of vectors, $w^{(0)}, \dots$ (the first `len` entries are used).
type Jet<const D: usize> = [SVector<f64, D>; MAX_JET];

/// A generated Lagrangian on $S^2$ (`#[higher_order_lagrangian(order = k, sphere)]`): a
/// system on $\mathbb{R}^2$ whose chart frame $[c, e_1, e_2]$ is a parameter.
pub trait SphereSystem: Copy {
    /// The chart frame $[c, e_1, e_2]$ (9 numbers).
    fn chart(&self) -> [f64; 9];
    /// The same system in the chart with frame `chart`.
    fn with_chart(&self, chart: [f64; 9]) -> Self;
}

/// A discretization map on $S^2$, written in a gnomonic chart (generated with
/// `#[discretization_map]` over the chart frame): the map of the chart with frame `chart`.
pub trait SphereMap<const K: usize> {
    /// The map in one chart.
    type InChart: DiscretizationMap<2, K>;
    /// The map written in the chart with frame `chart` $= [c, e_1, e_2]$.
    fn in_chart(&self, chart: [f64; 9]) -> Self::InChart;
}

/// A gnomonic chart of $S^2$: $\varphi(y) = s / |s|$, $s = c + y_0 e_1 + y_1 e_2$, with $c$
/// a unit vector and $(e_1, e_2)$ an orthonormal basis of its tangent plane. It covers the
/// open hemisphere $c \cdot q > 0$; $\varphi^{-1}(q) = (e_1 \cdot q, e_2 \cdot q) / (c \cdot q)$.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Chart {
    /// The centre $c = \varphi(0)$.
    pub centre: Vector3<f64>,
    /// $e_1 = \partial_{y_0} \varphi(0)$.
    pub e1: Vector3<f64>,
    /// $e_2 = c \times e_1 = \partial_{y_1} \varphi(0)$.
    pub e2: Vector3<f64>,
}

impl Chart {
    /// The chart centred at `point / |point|`, with $e_1$ the coordinate axis least aligned
    /// with it, made orthogonal to it.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a point that is zero or not finite.
    pub fn at(point: &Vector3<f64>) -> Result<Self, Error> {
        let norm = point.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return Err(Error::InvalidArgument {
                name: "point",
                requirement: "finite and nonzero",
            });
        }
        let c = point / norm;
        let axis = (0..3)
            .min_by(|&a, &b| c[a].abs().total_cmp(&c[b].abs()))
            .unwrap_or(0);
        Ok(Self::with_first_axis(c, Vector3::ith(axis, 1.0)))
    }

    /// The chart centred at the unit vector `c` with $e_1$ along the part of `axis`
    /// orthogonal to `c` (which must not be parallel to `c`).
    fn with_first_axis(c: Vector3<f64>, axis: Vector3<f64>) -> Self {
        let e1 = (axis - c * c.dot(&axis)).normalize();
        Self {
            centre: c,
            e1,
            e2: c.cross(&e1),
        }
    }

    /// The chart centred at the unit vector `point`, its $e_1$ the part of this chart's $e_1$
    /// orthogonal to `point` (a frame carried along a path), or [`Chart::at`] where that
    /// part is short.
    fn carried_to(&self, point: &Vector3<f64>) -> Self {
        let c = point.normalize();
        if (self.e1 - c * c.dot(&self.e1)).norm() > 0.5 {
            Self::with_first_axis(c, self.e1)
        } else {
            Self::at(&c).unwrap_or(*self)
        }
    }

    /// The frame as the chart parameter of a generated system or map:
    /// $[c_0, c_1, c_2, e_{1,0}, \dots, e_{2,2}]$.
    pub fn params(&self) -> [f64; 9] {
        let (c, a, b) = (self.centre, self.e1, self.e2);
        [c[0], c[1], c[2], a[0], a[1], a[2], b[0], b[1], b[2]]
    }

    /// The point $\varphi(y)$.
    pub fn point(&self, y: &Vector2<f64>) -> Vector3<f64> {
        (self.centre + self.e1 * y[0] + self.e2 * y[1]).normalize()
    }

    /// The chart coordinates $(y, y', \dots)$ of the ambient jet $(q, q', \dots)$ of a curve:
    /// $y^{(j)} = D^j \varphi^{-1}(q)$, the jet of its central projection (so only the part
    /// of the jet tangent to the sphere matters). At most 8 derivatives.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when the jet is longer than 8, not finite, or $q$ is not
    /// in the chart's open hemisphere $c \cdot q > 0$.
    pub fn coordinates<const J: usize>(
        &self,
        jet: &[Vector3<f64>; J],
    ) -> Result<[Vector2<f64>; J], Error> {
        let finite = jet.iter().all(|v| v.iter().all(|c| c.is_finite()));
        if J == 0 || J > MAX_JET || !finite || jet[0].dot(&self.centre) <= 0.0 {
            return Err(Error::InvalidArgument {
                name: "jet",
                requirement: "1 to 8 finite vectors, q in the chart's hemisphere (c . q > 0)",
            });
        }
        let into = Fractional {
            num: self.basis().transpose(),
            den: self.centre,
        };
        let mut w = [Vector3::zeros(); MAX_JET];
        w[..J].copy_from_slice(jet);
        let (y, _) = into.jet(&w, J);
        Ok(core::array::from_fn(|j| y[j]))
    }

    /// The ambient jet $(q, q', \dots)$ of the chart jet $(y, y', \dots)$: $q^{(j)} = D^j
    /// \varphi(y)$ (at most 8 derivatives; the rest are zero).
    pub fn ambient<const J: usize>(&self, y: &[Vector2<f64>; J]) -> [Vector3<f64>; J] {
        let f = self.frame();
        let mut s = [Vector3::zeros(); MAX_JET];
        for (j, yj) in y.iter().take(MAX_JET).enumerate() {
            let w = Vector3::new(if j == 0 { 1.0 } else { 0.0 }, yj[0], yj[1]);
            s[j] = f * w;
        }
        let q = normalised_jet(&s, J.min(MAX_JET));
        core::array::from_fn(|j| if j < MAX_JET { q[j] } else { Vector3::zeros() })
    }

    /// $F = [c\ e_1\ e_2]$.
    fn frame(&self) -> Matrix3<f64> {
        Matrix3::from_columns(&[self.centre, self.e1, self.e2])
    }

    /// Whether this is a chart (one read back from a file, or written field by field, holds
    /// whatever vectors it was given; [`Self::at`] makes only charts): its frame
    /// $(c, e_1, e_2)$ orthonormal to $10^{-12}$ (NaN fails). [`SphereState::validate`] runs
    /// it.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `chart`.
    pub fn validate(&self) -> Result<(), Error> {
        let f = self.frame();
        let gram = f.transpose() * f - Matrix3::identity();
        if gram.iter().all(|g| g.abs() <= ON_SPHERE) {
            Ok(())
        } else {
            Err(Error::InvalidArgument {
                name: "chart",
                requirement: "its frame (c, e1, e2) must be orthonormal to 1e-12",
            })
        }
    }

    /// $E = [e_1\ e_2]$.
    fn basis(&self) -> Matrix3x2<f64> {
        Matrix3x2::from_columns(&[self.e1, self.e2])
    }
}

/// The binomial coefficient $\binom{j}{i}$.
fn binomial(j: usize, i: usize) -> f64 {
    (0..i).fold(1.0, |c, t| c * (j - t) as f64 / (t + 1) as f64)
}

/// A linear-fractional map $\psi(w) = N w / (d \cdot w)$ from $\mathbb{R}^3$ to
/// $\mathbb{R}^2$, applied along jets (module docs).
#[derive(Clone, Copy, Debug)]
struct Fractional {
    num: Matrix2x3<f64>,
    den: Vector3<f64>,
}

impl Fractional {
    /// The transition from the homogeneous coordinates $(1, y)$ of chart `from` to the
    /// coordinates of chart `to`.
    fn transition(from: &Chart, to: &Chart) -> Self {
        let f = from.frame();
        Self {
            num: to.basis().transpose() * f,
            den: f.transpose() * to.centre,
        }
    }

    /// $\psi^{(j)}$ and the denominators $d^{(j)} = d \cdot w^{(j)}$ for $j <$ `len`.
    fn jet(&self, w: &Jet<3>, len: usize) -> (Jet<2>, [f64; MAX_JET]) {
        let mut d = [0.0; MAX_JET];
        let mut psi = [Vector2::zeros(); MAX_JET];
        for j in 0..len {
            d[j] = self.den.dot(&w[j]);
            let mut acc = self.num * w[j];
            for i in 1..=j {
                acc -= psi[j - i] * (binomial(j, i) * d[i]);
            }
            psi[j] = acc / d[0];
        }
        (psi, d)
    }

    /// The derivative of $\psi^{(j)}$, $j <$ `len`, in the direction $(\delta N, \delta d,
    /// \delta w)$, from Leibniz' rule differentiated:
    /// $d\thinspace\delta\psi^{(j)} = \delta n^{(j)} - \sum_{i=0}^{j} \binom{j}{i} \delta d^{(i)}
    /// \psi^{(j-i)} - \sum_{i=1}^{j} \binom{j}{i} d^{(i)} \delta\psi^{(j-i)}$.
    fn tangent(
        &self,
        w: &Jet<3>,
        (psi, d): &(Jet<2>, [f64; MAX_JET]),
        delta: (&Matrix2x3<f64>, &Vector3<f64>, &Jet<3>),
        len: usize,
    ) -> Jet<2> {
        let (dnum, dden, dw) = delta;
        let mut dd = [0.0; MAX_JET];
        let mut out = [Vector2::zeros(); MAX_JET];
        for j in 0..len {
            dd[j] = dden.dot(&w[j]) + self.den.dot(&dw[j]);
            let mut acc = dnum * w[j] + self.num * dw[j];
            for i in 0..=j {
                acc -= psi[j - i] * (binomial(j, i) * dd[i]);
            }
            for i in 1..=j {
                acc -= out[j - i] * (binomial(j, i) * d[i]);
            }
            out[j] = acc / d[0];
        }
        out
    }
}

/// The jet of $q = s / |s|$ along the jet of $s$ ($|s|$ by Leibniz' rule for $|s|^2 = s
/// \cdot s$, then $q$ by Leibniz' rule for $q\thinspace|s| = s$).
fn normalised_jet(s: &Jet<3>, len: usize) -> Jet<3> {
    let mut r = [0.0; MAX_JET];
    let mut q = [Vector3::zeros(); MAX_JET];
    for j in 0..len {
        let ss: f64 = (0..=j).map(|i| binomial(j, i) * s[i].dot(&s[j - i])).sum();
        r[j] = if j == 0 {
            num_traits::Float::sqrt(ss)
        } else {
            let cross: f64 = (1..j).map(|i| binomial(j, i) * r[i] * r[j - i]).sum();
            (ss - cross) / (2.0 * r[0])
        };
        let mut acc = s[j];
        for i in 1..=j {
            acc -= q[j - i] * (binomial(j, i) * r[i]);
        }
        q[j] = acc / r[0];
    }
    q
}

/// The homogeneous jet $w^{(0)} = (1, y)$, $w^{(j)} = (0, y^{(j)})$ of a chart jet.
fn homogeneous<const K: usize>(x: &Blocks<2, K>) -> Jet<3> {
    let mut w = [Vector3::zeros(); MAX_JET];
    for (j, xj) in x.iter().enumerate() {
        w[j] = Vector3::new(if j == 0 { 1.0 } else { 0.0 }, xj[0], xj[1]);
    }
    w
}

/// A state of a system on $S^2$ of order `K` (state size `S` $= 4K$): the chart and
/// $z = (x, p)$ in it, $x = (y, \dots, y^{(k-1)})$.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SphereState<const K: usize, const S: usize> {
    /// The chart the state is written in.
    pub chart: Chart,
    /// The state $z = (x, p)$ in the chart.
    pub z: SVector<f64, S>,
}

impl<const K: usize, const S: usize> SphereState<K, S> {
    const SIZES: () = assert!(S == 4 * K && K >= 1 && 2 * K <= MAX_JET, "S must equal 4 K");

    /// The state of `system` with ambient jet `jet` $= (q, q', \dots, q^{(2k-1)})$
    /// (Legendre transform in the chart centred at $q$); the jet is read through the chart,
    /// so only its tangent part matters.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when the jet does not have $2k$ finite entries, or $q$ is
    /// not a unit vector or $q'$ not tangent at it (to $10^{-9}$).
    pub fn from_ambient<Sys, const M: usize>(
        system: &Sys,
        jet: &[Vector3<f64>],
    ) -> Result<Self, Error>
    where
        Sys: SphereSystem + LiftedSystem<S, M>,
    {
        let () = Self::SIZES;
        let invalid = Error::InvalidArgument {
            name: "jet",
            requirement: "2k finite vectors (q, ..., q^(2k-1)) with |q| = 1 and q . q' = 0 \
                          (to 1e-9)",
        };
        let finite = jet.iter().all(|v| v.iter().all(|c| c.is_finite()));
        if jet.len() != 2 * K || !finite {
            return Err(invalid);
        }
        let (q, dq) = (jet[0], jet[1]);
        if (q.norm() - 1.0).abs() > 1e-9 || q.dot(&dq).abs() > 1e-9 * (1.0 + dq.norm()) {
            return Err(invalid);
        }
        let chart = Chart::at(&q)?;
        let mut fixed = [Vector3::zeros(); MAX_JET];
        fixed[..2 * K].copy_from_slice(jet);
        let y = chart.coordinates(&fixed)?;
        let mut full = SVector::<f64, S>::zeros();
        for (j, yj) in y.iter().take(2 * K).enumerate() {
            full.fixed_rows_mut::<2>(2 * j).copy_from(yj);
        }
        let z = system.with_chart(chart.params()).legendre(&full);
        Ok(Self { chart, z })
    }

    /// Whether this is a state on the sphere (one read back from a file, or written field by
    /// field, holds whatever numbers it was given): its chart frame $(c, e_1, e_2)$
    /// orthonormal to $10^{-12}$, $z$ finite, and its point $\varphi(y)$ a unit vector to
    /// $10^{-12}$. Chart coordinates $y$ so large that $|c + y_0 e_1 + y_1 e_2|$ overflows
    /// put the point at $(0, 0, 0)$ (or NaN): such a state is refused. [`step`] and
    /// [`Self::recentred`] run it first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] named `chart` for a frame that is not orthonormal, named
    /// `state` for a point off the unit sphere; [`Error::NonFinite`] for a non-finite $z$.
    pub fn validate(&self) -> Result<(), Error> {
        self.chart.validate()?;
        if !self.z.iter().all(|v| v.is_finite()) {
            return Err(Error::NonFinite {
                iteration: 0,
                location: "state",
            });
        }
        let off = (self.point().norm() - 1.0).abs();
        if off.is_nan() || off > ON_SPHERE {
            return Err(Error::InvalidArgument {
                name: "state",
                requirement: "its point phi(y) must lie on the unit sphere to 1e-12: chart \
                              coordinates y so large that |c + y0 e1 + y1 e2| overflows do not",
            });
        }
        Ok(())
    }

    /// The chart jet $x$ and momenta $p$.
    fn parts(&self) -> (Blocks<2, K>, Blocks<2, K>) {
        let () = Self::SIZES;
        split::<2, K, S>(&self.z)
    }

    /// The point $q = \varphi(y)$ on the sphere.
    pub fn point(&self) -> Vector3<f64> {
        self.chart.point(&self.parts().0[0])
    }

    /// The ambient jet $(q, q', \dots, q^{(k-1)})$: the lift of the chart, $q^{(j)} = D^j
    /// \varphi(y)$.
    pub fn ambient_jet(&self) -> [Vector3<f64>; K] {
        self.chart.ambient(&self.parts().0)
    }

    /// The same state in the chart `to`: the jet by the lift of the transition $\psi$, the
    /// momenta by $p_b = T^{-T} p_a$ with $T = \partial x_b / \partial x_a$.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] when the point is not in the open hemisphere of `to`,
    /// [`Error::SingularJacobian`] or [`Error::NonFinite`] if the transition fails.
    pub fn in_chart(&self, to: &Chart) -> Result<Self, Error> {
        let (x, p) = self.parts();
        let psi = Fractional::transition(&self.chart, to);
        let w = homogeneous(&x);
        let values = psi.jet(&w, K);
        if values.1[0].is_nan() || values.1[0] <= 0.0 {
            return Err(Error::InvalidArgument {
                name: "chart",
                requirement: "centred within 90 degrees of the point",
            });
        }
        // T^T as the leading block of an S x S system, the identity below it
        let mut tt = SMatrix::<f64, S, S>::identity();
        let zero = (Matrix2x3::zeros(), Vector3::zeros());
        for col in 0..2 * K {
            let mut dw = [Vector3::zeros(); MAX_JET];
            dw[col / 2][1 + col % 2] = 1.0;
            let column = psi.tangent(&w, &values, (&zero.0, &zero.1, &dw), K);
            for (j, cj) in column.iter().take(K).enumerate() {
                tt[(col, 2 * j)] = cj[0];
                tt[(col, 2 * j + 1)] = cj[1];
            }
        }
        let mut rhs = SVector::<f64, S>::zeros();
        for (j, pj) in p.iter().enumerate() {
            rhs.fixed_rows_mut::<2>(2 * j).copy_from(pj);
        }
        let solved = crate::numeric::linalg::solve(&tt, &rhs)
            .ok_or(Error::SingularJacobian { iteration: 0 })?;
        let x_b: Blocks<2, K> = core::array::from_fn(|j| values.0[j]);
        let p_b: Blocks<2, K> = core::array::from_fn(|j| solved.fixed_rows::<2>(2 * j).into());
        let z = join::<2, K, S>(&x_b, &p_b);
        if z.iter().all(|v| v.is_finite()) {
            Ok(Self { chart: *to, z })
        } else {
            Err(Error::NonFinite {
                iteration: 0,
                location: "chart change",
            })
        }
    }

    /// The state in the chart centred at its point (the frame carried from the current one).
    ///
    /// # Errors
    /// As [`Self::validate`] and [`Self::in_chart`].
    pub fn recentred(&self) -> Result<Self, Error> {
        self.validate()?;
        let (mut chart, mut z) = (self.chart, self.z);
        Sphere::recentre::<K, S>(&mut chart, &mut z)?;
        Ok(Self { chart, z })
    }

    /// The Noether momentum of rotations: component $a$ is $\mu_a = \sum_j p_j \cdot
    /// \delta_a x_j$, with $\delta_a x$ the chart jet's velocity under the rotation
    /// $q \mapsto q + \epsilon\thinspace e_a \times q$ (every ambient derivative rotates alike).
    /// Conserved by [`step`] for a rotation-invariant Lagrangian.
    pub fn momentum(&self) -> Vector3<f64> {
        let (x, p) = self.parts();
        let psi = Fractional::transition(&self.chart, &self.chart);
        let w = homogeneous(&x);
        let values = psi.jet(&w, K);
        let f = self.chart.frame();
        let zero = [Vector3::zeros(); MAX_JET];
        Vector3::from_fn(|a, _| {
            let omega = Vector3::ith(a, 1.0).cross_matrix() * f;
            let dnum = self.chart.basis().transpose() * omega;
            let dden = omega.transpose() * self.chart.centre;
            let dx = psi.tangent(&w, &values, (&dnum, &dden, &zero), K);
            (0..K).map(|j| p[j].dot(&dx[j])).sum()
        })
    }

    /// The Ostrogradsky Hamiltonian of `system` at this state (independent of the chart).
    ///
    /// # Errors
    /// As [`LiftedSystem::hamiltonian`].
    pub fn hamiltonian<Sys, const M: usize>(&self, system: &Sys) -> Result<f64, Error>
    where
        Sys: SphereSystem + LiftedSystem<S, M>,
    {
        system.with_chart(self.chart.params()).hamiltonian(&self.z)
    }
}

/// The unit sphere $S^2$ in moving gnomonic charts: a chart is a [`Chart`], the point of
/// the chart coordinates $y$ is $\varphi(y)$, and the transition to the chart centred at
/// $\varphi(a)$ (its frame carried from the current one) is [`SphereState::in_chart`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sphere;

impl MovingChart<2> for Sphere {
    type Chart = Chart;
    type Point = Vector3<f64>;

    /// $\varphi(y)$ ([`Chart::point`]).
    fn point(chart: &Chart, y: &Vector2<f64>) -> Vector3<f64> {
        chart.point(y)
    }

    /// $\varphi^{-1}(q) = (e_1 \cdot q, e_2 \cdot q) / (c \cdot q)$ ([`Chart::coordinates`]):
    /// `None` outside the chart's open hemisphere $c \cdot q > 0$.
    fn chart_point(chart: &Chart, q: &Vector3<f64>) -> Option<Vector2<f64>> {
        chart.coordinates(&[*q]).ok().map(|[y]| y)
    }

    /// The chart centred at $\varphi(a)$, its $e_1$ carried from `chart`'s, and
    /// [`SphereState::in_chart`] of `z` (`S` $= 4k$).
    fn transition<const K: usize, const S: usize>(
        chart: &Chart,
        a: &Vector2<f64>,
        z: &SVector<f64, S>,
    ) -> Result<(Chart, SVector<f64, S>), Error> {
        let to = chart.carried_to(&chart.point(a));
        let state = SphereState::<K, S> {
            chart: *chart,
            z: *z,
        };
        Ok((to, state.in_chart(&to)?.z))
    }
}

/// A system on $S^2$ is written in any gnomonic chart: its chart parameter is the frame
/// ([`Chart::params`]).
impl<Sys: SphereSystem> CentredSystem<Sphere, 2> for Sys {
    fn centred(&self, chart: &Chart) -> Self {
        self.with_chart(chart.params())
    }
}

/// One step of the integrator of the discretization map `map` on $S^2$ (paper Prop. 5.1),
/// computed in the chart of `state` (centred at its point after [`SphereState::recentred`]
/// or [`SphereState::from_ambient`]), then written in the chart centred at the new point.
///
/// # Errors
/// Those of [`SphereState::validate`] for `state` (a chart frame that is not orthonormal, a
/// non-finite state, a point off the unit sphere, e.g. chart coordinates that overflow it), of
/// [`crate::scheme::map::step`] and of the chart change [`SphereState::recentred`].
pub fn step<Sys, Map, const K: usize, const S: usize, const M: usize>(
    system: &Sys,
    map: &Map,
    state: &SphereState<K, S>,
    h: f64,
    options: &NewtonOptions,
) -> Result<(SphereState<K, S>, StepReport), Error>
where
    Sys: SphereSystem + Lagrangian<2, K> + LiftedSystem<S, M>,
    Map: SphereMap<K>,
{
    state.validate()?;
    let (z, report) = crate::scheme::map::step(
        &system.centred(&state.chart),
        &map.in_chart(state.chart.params()),
        &state.z,
        h,
        options,
    )?;
    let moved = SphereState {
        chart: state.chart,
        z,
    };
    Ok((moved.recentred()?, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::manifold::testing;

    /// A chart jet along y(t) = (a t + b t^2 + t^3 / 3, c t - t^2): (y, y', y'').
    fn curve(t: f64) -> [Vector2<f64>; 3] {
        let (a, b, c) = (0.3, -0.2, 0.5);
        [
            Vector2::new(a * t + b * t * t + t.powi(3) / 3.0, c * t - t * t),
            Vector2::new(a + 2.0 * b * t + t * t, c - 2.0 * t),
            Vector2::new(2.0 * b + 2.0 * t, -2.0),
        ]
    }

    #[test]
    fn transition_jets_match_differences_of_the_transition() {
        let a = Chart::at(&Vector3::new(0.2, -0.3, 1.0)).unwrap();
        let b = Chart::at(&Vector3::new(0.5, 0.1, 1.0)).unwrap();
        let psi = Fractional::transition(&a, &b);
        let at = |t: f64| {
            let c = curve(t);
            let x: Blocks<2, 3> = [c[0], c[1], c[2]];
            psi.jet(&homogeneous(&x), 3).0
        };
        let (t, e) = (0.4, 1e-4);
        let (lo, mid, hi) = (at(t - e), at(t), at(t + e));
        // the transition of the point agrees with the charts, and D psi^(j) = psi^(j+1)
        let direct = b.point(&mid[0]);
        let through = a.point(&curve(t)[0]);
        assert!((direct - through).amax() < 1e-15);
        for j in 0..2 {
            let fd = (hi[j] - lo[j]) / (2.0 * e);
            assert!((fd - mid[j + 1]).amax() < 1e-7, "{j}: {fd} {}", mid[j + 1]);
        }
    }

    #[test]
    fn normalised_jets_match_differences() {
        let s = |t: f64| Vector3::new(1.0 + t * t, 2.0 * t - 1.0, 0.5 + t.powi(3));
        let ds = |t: f64| Vector3::new(2.0 * t, 2.0, 3.0 * t * t);
        let dds = |t: f64| Vector3::new(2.0, 0.0, 6.0 * t);
        let jet = |t: f64| {
            let mut w = [Vector3::zeros(); MAX_JET];
            w[..3].copy_from_slice(&[s(t), ds(t), dds(t)]);
            normalised_jet(&w, 3)
        };
        let (t, e) = (0.7, 1e-4);
        let (lo, mid, hi) = (jet(t - e), jet(t), jet(t + e));
        assert!((mid[0] - s(t).normalize()).amax() < 1e-15);
        for j in 0..2 {
            let fd = (hi[j] - lo[j]) / (2.0 * e);
            assert!((fd - mid[j + 1]).amax() < 1e-7, "{j}");
        }
    }

    /// A chart or a state read from hostile JSON fails its validation, which the steps run.
    #[cfg(feature = "serde")]
    #[test]
    fn a_hostile_chart_or_state_from_json_fails_its_validation() {
        type Edit = fn(&mut serde_json::Value);
        let chart = Chart::at(&Vector3::new(1.0, 2.0, -2.0)).unwrap();
        let state = SphereState::<1, 4> {
            chart,
            z: SVector::from([0.1, -0.2, 0.3, 0.4]),
        };
        let valid = serde_json::to_value(state).unwrap();
        let back: SphereState<1, 4> = serde_json::from_value(valid.clone()).unwrap();
        assert!(back.validate().is_ok() && back.chart.validate().is_ok());
        let edits: [(&str, Edit, &str); 5] = [
            ("e1 scaled", |v| v["chart"]["e1"][0] = 0.9.into(), "chart"),
            (
                "e2 = e1",
                |v| v["chart"]["e2"] = v["chart"]["e1"].clone(),
                "chart",
            ),
            (
                "a zero centre",
                |v| v["chart"]["centre"] = serde_json::json!([0.0, 0.0, 0.0]),
                "chart",
            ),
            (
                "a huge centre",
                |v| v["chart"]["centre"][2] = 1e308.into(),
                "chart",
            ),
            (
                "y = 1e200 (the point overflows)",
                |v| v["z"][0] = 1e200.into(),
                "state",
            ),
        ];
        for (what, edit, name) in edits {
            let mut value = valid.clone();
            edit(&mut value);
            let read: SphereState<1, 4> = serde_json::from_value(value)
                .unwrap_or_else(|e| panic!("{what}: the JSON reads ({e})"));
            let result = read.validate();
            assert!(
                matches!(result, Err(Error::InvalidArgument { name: n, .. }) if n == name),
                "{what}: {result:?}"
            );
            assert_eq!(read.chart.validate().is_err(), name == "chart", "{what}");
        }
    }

    #[test]
    fn a_chart_is_orthonormal_and_carried_frames_stay_close() {
        let c = Chart::at(&Vector3::new(1.0, 2.0, -2.0)).unwrap();
        let f = c.frame();
        assert!((f.transpose() * f - Matrix3::identity()).amax() < 1e-15);
        assert!((c.e1.cross(&c.e2) - c.centre).amax() < 1e-15);
        let next = c.carried_to(&c.point(&Vector2::new(0.01, 0.0)));
        assert!((next.e2 - c.e2).norm() < 1e-3 && (next.e1 - c.e1).norm() < 0.02);
        assert!(Chart::at(&Vector3::zeros()).is_err());
    }

    #[test]
    fn a_transition_there_and_back_is_the_identity_in_the_first_chart() {
        let mut seed = 17;
        for _ in 0..50 {
            let chart = Chart::at(&testing::vector::<3>(&mut seed, 1.0)).unwrap();
            let z: SVector<f64, 8> = testing::vector(&mut seed, 1.0);
            let a: Vector2<f64> = testing::vector(&mut seed, 0.5);
            let (back, z_back) = testing::there_and_back::<Sphere, 2, 2, 8>(&chart, &a, &z);
            // the same centre, the frame turned about it (carried there and back)
            assert!((back.centre - chart.centre).amax() < 1e-12);
            let z_back = SphereState::<2, 8> {
                chart: back,
                z: z_back,
            };
            let z_first = z_back.in_chart(&chart).unwrap().z;
            assert!((z_first - z).amax() < 1e-12, "{z_first} {z}");
        }
    }

    #[test]
    fn recentring_puts_the_point_at_the_origin_and_keeps_the_point() {
        let mut seed = 19;
        for _ in 0..50 {
            let chart = Chart::at(&testing::vector::<3>(&mut seed, 1.0)).unwrap();
            let state = SphereState::<2, 8> {
                chart,
                z: testing::vector(&mut seed, 1.0),
            };
            let moved = state.recentred().unwrap();
            assert!(moved.z.fixed_rows::<2>(0).amax() < 1e-15, "{}", moved.z);
            assert!((moved.point() - state.point()).amax() < 1e-12);
            assert!((moved.chart.centre - state.point()).amax() < 1e-12);
            let (before, after) = (state.momentum(), moved.momentum());
            assert!((after - before).amax() < 1e-12 * (1.0 + before.amax()));
        }
    }

    #[test]
    fn chart_points_invert_points() {
        let chart = Chart::at(&Vector3::new(0.3, -1.0, 0.4)).unwrap();
        let y = Vector2::new(0.7, -1.9);
        let q = Sphere::point(&chart, &y);
        let back = Sphere::chart_point(&chart, &q).unwrap();
        assert!((back - y).amax() < 1e-12, "{back} {y}");
        assert!(Sphere::chart_point(&chart, &-q).is_none());
    }
}
