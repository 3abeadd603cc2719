//! The traits a generated (or hand-written) system implements.
//!
//! A $k$-th order Lagrangian $L(q, q', \dots, q^{(k)})$ on $Q = \mathbb{R}^n$ is seen as
//! $L(x, u)$ with the jet $x = (x_0, \dots, x_{k-1})$, $x_j = q^{(j)}$, and the top
//! derivative $u = q^{(k)}$. Two traits describe it:
//!
//! - [`Lagrangian<N, K>`]: $L$, its gradient and Hessian in $(x, u)$, the Ostrogradsky
//!   momenta (the Legendre map) and the solve of $p_{k-1} = \partial L / \partial u$ for $u$.
//!   Typed by blocks: everything is in terms of `SVector<f64, N>`.
//! - [`LiftedSystem<S, M>`]: the flat interface the runtime drives, with the Hamiltonian
//!   state $z = (x, p) \in \mathbb{R}^S$, $S = 2nk$, and the Newton unknowns
//!   $w = (z_1, u) \in \mathbb{R}^M$, $M = S + n$ for the general scheme. The functions of
//!   [`crate::scheme::lifted`] implement it from a [`Lagrangian`]; [`impl_lifted_system!`](crate::impl_lifted_system)
//!   writes that impl for a concrete type.
//!
//! # Layout of the flat vectors
//! $z = (x_0, \dots, x_{k-1}, p_0, \dots, p_{k-1})$, each block $n$ long; the derivative data
//! of the Legendre map is $(q, q', \dots, q^{(2k-1)})$, also $S = 2nk$ long;
//! $w = (x_{1}, p_{1}, u)$ for the one-step unknowns.

use nalgebra::{SMatrix, SVector};

use crate::{DomainViolation, Error};

/// Blocks of the gradient of $L(x, u)$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gradient<const N: usize, const K: usize> {
    /// `x[j]` $= \partial L / \partial x_j$.
    pub x: [SVector<f64, N>; K],
    /// $\partial L / \partial u$.
    pub u: SVector<f64, N>,
}

/// Blocks of the Hessian of $L(x, u)$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hessian<const N: usize, const K: usize> {
    /// `xx[i][j][(a, b)]` $= \partial^2 L / \partial x_{i,a} \partial x_{j,b}$.
    pub xx: [[SMatrix<f64, N, N>; K]; K],
    /// `xu[j][(a, b)]` $= \partial^2 L / \partial x_{j,a} \partial u_b$.
    pub xu: [SMatrix<f64, N, N>; K],
    /// `uu[(a, b)]` $= \partial^2 L / \partial u_a \partial u_b$.
    pub uu: SMatrix<f64, N, N>,
}

/// A scalar function of the jet at one point $(x, u)$ with its first and second
/// derivatives there ([`Lagrangian::derivatives`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Derivatives<const N: usize, const K: usize> {
    /// The value, $L(x, u)$.
    pub value: f64,
    /// The gradient in $(x, u)$.
    pub gradient: Gradient<N, K>,
    /// The Hessian in $(x, u)$.
    pub hessian: Hessian<N, K>,
}

impl<const N: usize, const K: usize> Gradient<N, K> {
    /// The zero gradient.
    #[inline]
    pub fn zeros() -> Self {
        Self {
            x: [SVector::zeros(); K],
            u: SVector::zeros(),
        }
    }
}

impl<const N: usize, const K: usize> Hessian<N, K> {
    /// The zero Hessian.
    #[inline]
    pub fn zeros() -> Self {
        Self {
            xx: [[SMatrix::zeros(); K]; K],
            xu: [SMatrix::zeros(); K],
            uu: SMatrix::zeros(),
        }
    }
}

/// A scalar function $g(x, u)$ of the jet $x = (q, \dots, q^{(k-1)})$ and the top derivative
/// $u = q^{(k)}$ on $\mathbb{R}^N$ with $K = k$, with its gradient and Hessian: a stage
/// constraint of the optimal-control solver ([`crate::bvp`]), written as plain Rust under
/// `#[jet_function(order = k)]`.
pub trait JetFunction<const N: usize, const K: usize> {
    /// $g(x, u)$.
    fn value(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> f64;

    /// $(\partial g/\partial x_0, \dots, \partial g/\partial x_{k-1}, \partial g/\partial u)$.
    fn gradient(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> Gradient<N, K>;

    /// The Hessian of $g$ in $(x, u)$, by blocks.
    fn hessian(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> Hessian<N, K>;

    /// Whether $g$ depends on the top derivative $u = q^{(k)}$. The optimizer imposes a
    /// constraint that does not at the nodes $x_i$ as well as at the steps' evaluation points
    /// ([`crate::bvp::Placement`]). `#[jet_function]` decides it from the expression; the
    /// default, `true`, is right for any $g$.
    fn involves_top(&self) -> bool {
        true
    }

    /// A name for messages (`#[jet_function]`: the generated type's name).
    fn name(&self) -> &'static str {
        "jet function"
    }
}

/// A vector function $g(x, u) = (g_0, \dots, g_{m-1})$ of the jet and the top derivative on
/// $\mathbb{R}^N$ with $K = k$, component by component with gradients and Hessians: a stage
/// constraint with one bound per component ($\ell_c \le g_c \le u_c$,
/// [`crate::bvp::OptimalControlProblem::with_vector_bounds`]), written as plain Rust returning
/// `[f64; m]` under `#[jet_function(order = k)]`. Each component $c < m$ is evaluated from its
/// own straight-line code, so a component costs what it would as a scalar [`JetFunction`].
pub trait VectorJetFunction<const N: usize, const K: usize> {
    /// The number $m \ge 1$ of components.
    fn components(&self) -> usize;

    /// $g_c(x, u)$ (NaN for $c \ge m$).
    fn component_value(&self, c: usize, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> f64;

    /// $(\partial g_c/\partial x_0, \dots, \partial g_c/\partial x_{k-1}, \partial g_c/\partial u)$
    /// (zero for $c \ge m$).
    fn component_gradient(
        &self,
        c: usize,
        x: &[SVector<f64, N>; K],
        u: &SVector<f64, N>,
    ) -> Gradient<N, K>;

    /// The Hessian of $g_c$ in $(x, u)$, by blocks (zero for $c \ge m$).
    fn component_hessian(
        &self,
        c: usize,
        x: &[SVector<f64, N>; K],
        u: &SVector<f64, N>,
    ) -> Hessian<N, K>;

    /// Whether $g_c$ depends on the top derivative $u = q^{(k)}$ (as
    /// [`JetFunction::involves_top`], component by component; the default, `true`, is right
    /// for any $g$).
    fn component_involves_top(&self, c: usize) -> bool {
        let _ = c;
        true
    }

    /// A name for messages (`#[jet_function]`: the generated type's name).
    fn name(&self) -> &'static str {
        "vector jet function"
    }
}

/// A $k$-th order Lagrangian $L(x, u)$ on $\mathbb{R}^N$ with $K = k$.
pub trait Lagrangian<const N: usize, const K: usize> {
    /// $L(x, u)$.
    fn lagrangian(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> f64;

    /// $(\partial L/\partial x_0, \dots, \partial L/\partial x_{k-1}, \partial L/\partial u)$.
    fn gradient(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> Gradient<N, K>;

    /// The Hessian of $L$ in $(x, u)$, by blocks.
    fn hessian(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> Hessian<N, K>;

    /// $L(x, u)$, its gradient and its Hessian at one point: [`Self::lagrangian`],
    /// [`Self::gradient`] and [`Self::hessian`] in one call (the default makes the three
    /// calls). `#[higher_order_lagrangian]` emits one straight-line body for the three, so
    /// that the subexpressions they share (the trigonometric functions of a mechanical
    /// system, the residual of a least-squares cost) are computed once; its values equal the
    /// three methods' up to the reassociation of sums and products (the last bits).
    fn derivatives(&self, x: &[SVector<f64, N>; K], u: &SVector<f64, N>) -> Derivatives<N, K> {
        Derivatives {
            value: self.lagrangian(x, u),
            gradient: self.gradient(x, u),
            hessian: self.hessian(x, u),
        }
    }

    /// The Ostrogradsky momenta from derivative data, with `lower` $= (q, \dots, q^{(k-1)})$
    /// and `upper` $= (q^{(k)}, \dots, q^{(2k-1)})$:
    /// $p_{k-1} = \partial L/\partial q^{(k)}$,
    /// $p_{j-1} = \partial L/\partial q^{(j)} - D p_j$ for $j = k-1, \dots, 1$, where
    /// $D f = \sum_i \partial f/\partial q^{(i)} \cdot q^{(i+1)}$ is the total derivative.
    fn momenta(
        &self,
        lower: &[SVector<f64, N>; K],
        upper: &[SVector<f64, N>; K],
    ) -> [SVector<f64, N>; K];

    /// Solves $p_{k-1} = \partial L/\partial u\thinspace(x, u)$ for $u$, starting from `guess`.
    ///
    /// The default runs [`crate::numeric::newton::solve`] with the Jacobian
    /// $\partial^2 L / \partial u^2$; a system with a closed-form inverse overrides it.
    ///
    /// # Errors
    /// Any [`Error`] of the Newton solve, e.g. [`Error::SingularJacobian`] for a Lagrangian
    /// degenerate in $u$.
    fn top_derivative(
        &self,
        x: &[SVector<f64, N>; K],
        p_top: &SVector<f64, N>,
        guess: &SVector<f64, N>,
    ) -> Result<SVector<f64, N>, Error> {
        let problem = TopDerivative {
            lagrangian: self,
            x,
            p_top,
        };
        crate::numeric::newton::solve(&problem, *guess, &crate::NewtonOptions::default())
            .map(|solution| solution.w)
    }
}

/// $F(u) = \partial L/\partial u\thinspace(x, u) - p_{k-1}$, the Legendre inversion as a root problem.
struct TopDerivative<'a, L: ?Sized, const N: usize, const K: usize> {
    lagrangian: &'a L,
    x: &'a [SVector<f64, N>; K],
    p_top: &'a SVector<f64, N>,
}

impl<L, const N: usize, const K: usize> crate::numeric::newton::Problem<N>
    for TopDerivative<'_, L, N, K>
where
    L: Lagrangian<N, K> + ?Sized,
{
    fn residual(&self, u: &SVector<f64, N>) -> SVector<f64, N> {
        self.lagrangian.gradient(self.x, u).u - self.p_top
    }

    fn jacobian(&self, u: &SVector<f64, N>) -> SMatrix<f64, N, N> {
        self.lagrangian.hessian(self.x, u).uu
    }
}

/// The lifted theta-scheme of a higher-order Lagrangian, on flat vectors.
///
/// `S` $= 2nk$ is the size of the Hamiltonian state $z = (x, p)$ and `M` the number of
/// Newton unknowns of one step (for the general scheme $M = S + n$: $w = (z_1, u)$). The
/// one-step map with step $h$ and parameter $\theta \in [0, 1]$ is defined by
/// $F(z_0, w) = 0$:
///
/// ```text
/// F_{x,j}   = x_{j,1} - x_{j,0} - h x_{j+1,th}                     (j < k-1)
/// F_{x,k-1} = x_{k-1,1} - x_{k-1,0} - h u
/// F_{p,0}   = p_{0,1} - p_{0,0} - h dL/dx_0 (x_th, u)
/// F_{p,j}   = p_{j,1} - p_{j,0} - h (dL/dx_j (x_th, u) - p_{j-1,th})  (j >= 1)
/// F_u       = p_{k-1,th} - dL/du (x_th, u)
/// x_th = (1 - theta) x_0 + theta x_1,   p_th = theta p_0 + (1 - theta) p_1
/// ```
pub trait LiftedSystem<const S: usize, const M: usize> {
    /// Dimension $n$ of the configuration space.
    const DIMENSION: usize;
    /// Order $k$ of the Lagrangian.
    const ORDER: usize;

    /// The Ostrogradsky Hamiltonian
    /// $H(x, p) = \sum_{j<k-1} p_j \cdot x_{j+1} + p_{k-1} \cdot u - L(x, u)$ with $u$
    /// solving $p_{k-1} = \partial L/\partial u\thinspace(x, u)$.
    ///
    /// # Errors
    /// When the solve for $u$ fails or a value is not finite.
    fn hamiltonian(&self, z: &SVector<f64, S>) -> Result<f64, Error>;

    /// Hamilton's equations $z' = (\partial H/\partial p, -\partial H/\partial x)$:
    /// $x_j' = x_{j+1}$ ($j < k-1$), $x_{k-1}' = u$, $p_0' = \partial L/\partial x_0$,
    /// $p_j' = \partial L/\partial x_j - p_{j-1}$ ($j \ge 1$).
    ///
    /// # Errors
    /// When the solve for $u$ fails or a value is not finite.
    fn vector_field(&self, z: &SVector<f64, S>) -> Result<SVector<f64, S>, Error>;

    /// The Legendre map: derivative data $(q, \dots, q^{(2k-1)})$ to $z = (x, p)$, with
    /// $x_j = q^{(j)}$ and $p$ the Ostrogradsky momenta.
    fn legendre(&self, jet: &SVector<f64, S>) -> SVector<f64, S>;

    /// The residual $F(z_0, w)$ of the trait docs.
    fn residual(
        &self,
        z0: &SVector<f64, S>,
        w: &SVector<f64, M>,
        h: f64,
        theta: f64,
    ) -> SVector<f64, M>;

    /// $\partial F / \partial w$, the Newton matrix.
    fn jacobian(
        &self,
        z0: &SVector<f64, S>,
        w: &SVector<f64, M>,
        h: f64,
        theta: f64,
    ) -> SMatrix<f64, M, M>;

    /// $\partial F / \partial z_0$, for the derivative of the step map
    /// $D\Psi = -[(\partial F/\partial w)^{-1} \partial F/\partial z_0]_{1..S}$.
    fn jacobian_initial(
        &self,
        z0: &SVector<f64, S>,
        w: &SVector<f64, M>,
        h: f64,
        theta: f64,
    ) -> SMatrix<f64, M, S>;

    /// The cost of one step, $h\thinspace L(x_\theta, u)$: summed over a trajectory, the
    /// midpoint-type quadrature of $J = \int L\thinspace dt$.
    fn step_cost(&self, z0: &SVector<f64, S>, w: &SVector<f64, M>, h: f64, theta: f64) -> f64;

    /// An explicit first guess of $w$: one explicit Euler step
    /// $z_1 \approx z_0 + h\thinspace z'(z_0)$ and $u \approx u(z_0)$.
    ///
    /// # Errors
    /// When the vector field at $z_0$ cannot be evaluated.
    fn predictor(&self, z0: &SVector<f64, S>, h: f64, theta: f64)
    -> Result<SVector<f64, M>, Error>;

    /// Whether every parameter of the system is finite: the first that is not, as
    /// [`Error::NonFiniteParameter`] naming it. Steps call it when they meet a non-finite
    /// value, and solves before they start, so a NaN parameter is reported by name rather than
    /// as a non-finite residual. The default (no parameters) is `Ok`.
    ///
    /// # Errors
    /// The first non-finite parameter (component).
    fn check_parameters(&self) -> Result<(), Error> {
        Ok(())
    }

    /// The domain check of a step: every guarded expression of $L$ (denominators, arguments
    /// of `sqrt`, `ln`, `powf`) evaluated at the start $x_0$, the end $x_1$ and the
    /// evaluation point $x_\theta$ of the step from `z0` to the unknowns `w`. A denominator
    /// must keep its sign and not vanish; a `sqrt` argument must stay $\ge 0$; `ln` and `powf`
    /// arguments $> 0$. The default checks nothing.
    ///
    /// # Errors
    /// The first violated condition.
    fn check_domain(
        &self,
        z0: &SVector<f64, S>,
        w: &SVector<f64, M>,
        theta: f64,
    ) -> Result<(), DomainViolation> {
        let _ = (z0, w, theta);
        Ok(())
    }

    /// Whether the three samples of [`Self::check_domain`] decide the whole chord of a step:
    /// every guarded expression is a polynomial of degree at most 2 in the jet, so the
    /// quadratic through its samples at $x_0$, $x_\theta$ and $x_1$ is the expression along the
    /// straight chord, and the check's "stays clear of zero" rule is exact there (for
    /// $\theta$ not within $10^{-3}$ of an end). [`crate::scheme::step::check_step_domain`] then
    /// skips the chord's pieces. Generated systems answer from their guards (for example
    /// `x^2 + y^2 - r^2`: yes; `1 - cos(q)`: no); the default is `false`.
    fn guards_quadratic(&self) -> bool {
        false
    }

    /// The new state $z_1$ inside the unknowns $w$ (its first `S` entries).
    fn state(&self, w: &SVector<f64, M>) -> SVector<f64, S> {
        const { assert!(S <= M, "the unknowns must contain the state") };
        w.fixed_rows::<S>(0).into_owned()
    }
}
