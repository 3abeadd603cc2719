//! The reduced step: Newton on the nonlinear core only.
//!
//! When the Hessian of $L$ depends on a few jet components $y$ (the core, e.g. the position
//! of a body in a barrier potential) and on no component of the top derivative, the
//! theta-scheme residual splits as
//!
//! $$F(z_0, w) = A\thinspace w + B\thinspace z_0 + n(y), \qquad y = P w + (1-\theta) E z_0,$$
//!
//! with $y$ the core values at the evaluation point ($E$ picks the core components of a
//! state, $P = \theta E$ those of $w$), $A = A(h, \theta)$ and $B = B(h, \theta)$ independent
//! of the state, and $n$ nonzero only in a few rows (the forces). Then
//! $w = -A^{-1}(B z_0 + n(y))$, and $y$ solves the small system
//!
//! $$r(y) = y - G z_0 + K n(y) = 0, \qquad K = P A^{-1}, \qquad
//!   G = (1-\theta) E - K B, \qquad \partial r/\partial y = I + K\thinspace \partial n/\partial y,$$
//!
//! $R$ unknowns instead of $M$. After Newton the step is
//!
//! $$w = T z_0 - A^{-1} n(y), \qquad T = -A^{-1} B.$$
//!
//! $A^{-1}$, $K$, $G$ and $T$ depend on $(h, \theta)$ and the parameters only and are cached by
//! [`ReducedStepper`] ([`ReducedFactors`]). The macro emits $A$, $B$, $n$ and
//! $\partial n/\partial y$, the irreducible blocks of $A$, the factors in closed form where a
//! symbolic elimination of the blocks finds one ([`ClosedForm`]), and the products with the
//! cached factors as straight-line code over their nonzeros, with the factors' constant
//! entries written in. The result is the same $z_1$ as the general step, to rounding; on the
//! obstacle system, built with fat LTO, a step with the domain check and without the
//! corrections below ([`crate::StepOptions::compensated`] off) takes 1.15x to 1.18x the time
//! of the fastest guarded step written by hand for $h$ and $\theta$ fixed at compile time,
//! 1.37x to 1.39x with the corrections (`cargo build --profile release-lto -p
//! retract-validation --example report && ./target/release-lto/examples/report --steps`).
//!
//! Cached, $T$ and $A^{-1}$ are rounded once, so every step would apply the same slightly
//! non-symplectic linear map, and a quadratic invariant would drift linearly (the angular
//! momentum of a rotation-invariant system: $6.5 \cdot 10^{-17}$ per step). The factors
//! therefore carry their rounding errors,
//!
//! $$T_{lo} = -A^{-1}(A T + B), \qquad A^{-1}_{lo} = A^{-1}(E - A\thinspace A^{-1})$$
//!
//! ([`ReducedFactors::t_lo`], [`ReducedFactors::a_inv_lo`]: the residuals summed compensated,
//! so that they are the residuals of the rounded factors, not rounding noise; $E$ the unit
//! columns at the forced rows), and the step computes
//!
//! $$w = (T + T_{lo})\thinspace z_0 - (A^{-1} + A^{-1}_{lo})\thinspace n(y),$$
//!
//! each entry a sum of the terms of $T$ and $A^{-1}$ in two halves (the terms of $n$, known
//! last, summed apart so that one addition follows $n$, in the plain sums too; in a row
//! without them, two halves of its terms): $b$, the half without a term of factor $\pm 1$
//! (the late one, of $n$'s terms where there are, if both qualify), and $a$, the other. The
//! corrections $c$ ($T_{lo} z_0 - A^{-1}_{lo} n$) are added to $b$ first,
//! $\mathrm{fl}(a + \mathrm{fl}(b + c))$ ([`sum_folded`]): where $b$ is small against $a$
//! (the terms of $n$ and the factors off the unit diagonal carry powers of $h$, the unit terms
//! the state), $\mathrm{fl}(b + c)$ keeps $c$ far below the last bit of the entry, so that
//! the corrections enter its one rounding (added after it, a correction below the last bit
//! would be lost); where $b$ dominates, a correction below half the last bit of $b$ is lost,
//! as without the corrections. A row with unit terms in both halves has an exact last addition
//! instead ([`sum_corrected`]: its rounding error by TwoSum, the corrections added to it). The
//! angular momentum of the rotation-invariant Pais-Uhlenbeck oscillator then stays within
//! $1.8 \cdot 10^{-12}$ over $10^7$ steps (it drifted $6.5 \cdot 10^{-10}$; with the exact
//! last addition in every row $2.1 \cdot 10^{-12}$, the step 1.26 to 1.28 times slower on the
//! obstacle system). Each entry summed fully compensated (Dot2 of Ogita, Rump and Oishi: every
//! product and addition error-free) kept the momentum within $6.3 \cdot 10^{-13}$ but made
//! the step 3x slower.
//!
//! A step returns a finite state or an error: $w$ is finite when
//! $\sum_j |z_{0,j}| + \sum_q |n_q|$ is below [`ReducedFactors::finite_below`], and the state
//! (its first $S$ entries) is checked entry by entry otherwise.

mod blocks;

use core::cell::Cell;

use nalgebra::{SMatrix, SVector};

use crate::numeric::newton::{self, Problem, all_finite, max_abs, sum_abs};
use crate::scheme::step::StepReport;
use crate::{Error, LiftedSystem, StepOptions};
use blocks::{Block, BlockWork};

/// A system whose step reduces to its nonlinear core of `R` variables (emitted by the macro;
/// see the module docs for the formulas).
pub trait ReducedScheme<const S: usize, const M: usize, const R: usize>:
    LiftedSystem<S, M>
{
    /// Flat index $j n + i$ (into $z$ and $w$) of the jet component of each core variable.
    const CORE: [usize; R];

    /// The rows of $F$ where $n(y)$ is not identically zero (the forced rows), ascending.
    const FORCED: &'static [usize];

    /// The irreducible blocks of $A$ as (rows, columns), ascending: $A$ is block diagonal after
    /// permuting rows and columns by them, so each block is factorised on its own.
    const BLOCKS: &'static [(&'static [usize], &'static [usize])];

    /// $A = \partial F / \partial w$ at fixed $y$.
    fn linear_part(&self, h: f64, theta: f64) -> SMatrix<f64, M, M>;

    /// $B = \partial F / \partial z_0$ at fixed $y$.
    fn initial_part(&self, h: f64, theta: f64) -> SMatrix<f64, M, S>;

    /// $G z_0$, the core values of the step without forces.
    fn core_offset(
        &self,
        factors: &ReducedFactors<S, M, R>,
        z0: &SVector<f64, S>,
    ) -> SVector<f64, R>;

    /// $r(y) = y - \text{offset} + K n(y)$ and $\partial r / \partial y = I + K\thinspace\partial n/\partial y$.
    fn core_system(
        &self,
        factors: &ReducedFactors<S, M, R>,
        offset: &SVector<f64, R>,
        y: &SVector<f64, R>,
        h: f64,
        theta: f64,
    ) -> (SVector<f64, R>, SMatrix<f64, R, R>);

    /// Writes $T = -A^{-1} B$ and the columns of $A^{-1}$ at [`Self::FORCED`] into the zero
    /// matrices `t` and `a_inv` from closed-form expressions in $h$, $\theta$ and the
    /// parameters (the macro eliminates the blocks of $A$ symbolically), and says what they
    /// are; [`ClosedForm::None`] (the default) where there is no closed form.
    /// [`ReducedFactors::new`] checks the result and factorises numerically otherwise.
    fn closed_form_factors(
        &self,
        h: f64,
        theta: f64,
        t: &mut SMatrix<f64, M, S>,
        a_inv: &mut SMatrix<f64, M, M>,
    ) -> ClosedForm {
        let _ = (h, theta, t, a_inv);
        ClosedForm::None
    }

    /// $\partial n / \partial y$ (zero outside the rows [`Self::FORCED`]).
    fn forcing_jacobian(&self, y: &SVector<f64, R>, h: f64, theta: f64) -> SMatrix<f64, M, R>;

    /// $r(y) = y - \text{offset} + K n$ for the forcing $n = n(y)$ given (no evaluation).
    fn core_residual(
        &self,
        factors: &ReducedFactors<S, M, R>,
        offset: &SVector<f64, R>,
        y: &SVector<f64, R>,
        forcing: &SVector<f64, M>,
    ) -> SVector<f64, R>;

    /// $K n(y)$: the fixed-point step from the force-free guess $y_0 = G z_0$ is
    /// $y_1 = y_0 - K n(y_0)$. By default [`Self::core_residual`] at
    /// $y = \text{offset} = 0$ with the forcing [`Self::forcing`]; the macro emits the products
    /// with the entries of $K$ multiplied into those of $n$ with their operands known first
    /// (no multiplication by $K$ after $n$, and no $y - \text{offset}$ term, whose
    /// $y_0 - y_0$ the compiler cannot drop: operations on the step's critical path).
    fn core_forcing(
        &self,
        factors: &ReducedFactors<S, M, R>,
        y: &SVector<f64, R>,
        h: f64,
        theta: f64,
    ) -> SVector<f64, R> {
        let zero = SVector::zeros();
        self.core_residual(factors, &zero, &zero, &self.forcing(y, h, theta))
    }

    /// $n(y)$ (zero outside the rows [`Self::FORCED`]).
    fn forcing(&self, y: &SVector<f64, R>, h: f64, theta: f64) -> SVector<f64, M>;

    /// $w = (T + T_{lo}) z_0 - (A^{-1} + A^{-1}_{lo}) n$ for the forcing $n = n(y)$ at the
    /// solved core, the corrections inside the one rounding of each entry (module docs).
    fn recover(
        &self,
        factors: &ReducedFactors<S, M, R>,
        z0: &SVector<f64, S>,
        forcing: &SVector<f64, M>,
    ) -> SVector<f64, M>;

    /// $w = T z_0 - A^{-1} n$ without the corrections of [`Self::recover`] (each entry one
    /// rounded sum; [`crate::StepOptions::compensated`] off). By default [`Self::recover`];
    /// the macro emits the plain sums.
    fn recover_plain(
        &self,
        factors: &ReducedFactors<S, M, R>,
        z0: &SVector<f64, S>,
        forcing: &SVector<f64, M>,
    ) -> SVector<f64, M> {
        self.recover(factors, z0, forcing)
    }
}

/// What [`ReducedScheme::closed_form_factors`] wrote.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClosedForm {
    /// Nothing: factorise numerically.
    None,
    /// Polynomials in $h$, $\theta$ and the parameters (every pivot of the symbolic
    /// elimination was a nonzero constant): exact up to rounding when finite.
    Polynomial,
    /// Rational functions: a pivot was an expression, which may nearly vanish for some
    /// $(h, \theta)$, so the result is checked against $A$ and $B$ before use.
    Rational,
}

/// The factors of the reduced step for one $(h, \theta)$ (formulas in the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct ReducedFactors<const S: usize, const M: usize, const R: usize> {
    /// Step size.
    pub h: f64,
    /// Theta of the scheme.
    pub theta: f64,
    /// The columns of $A^{-1}$ at the forced rows ([`ReducedScheme::FORCED`]); the other
    /// columns are zero (the step never multiplies them).
    pub a_inv: SMatrix<f64, M, M>,
    /// The rounding error of `a_inv`: $A^{-1}(E - A\thinspace a^{-1})$ at the forced columns ($E$
    /// their unit columns; the other columns are zero), the residual summed compensated, as `t_lo`
    /// for `t`.
    pub a_inv_lo: SMatrix<f64, M, M>,
    /// $K = \theta\thinspace E A^{-1}$ (rows of $A^{-1}$ at the core components, times $\theta$),
    /// at the forced columns as `a_inv`.
    pub k: SMatrix<f64, R, M>,
    /// $G = (1-\theta) E - K B = (1-\theta) E + \theta E T$.
    pub g: SMatrix<f64, R, S>,
    /// $T = -A^{-1} B$, rounded.
    pub t: SMatrix<f64, M, S>,
    /// The rounding error of `t`: $T_{lo} = -A^{-1}(A T + B)$ with $A T + B$ summed
    /// compensated, so that $T + T_{lo}$ is $-A^{-1} B$ to about $u^2$ (relative, $u$ the unit
    /// roundoff); at most the nonzeros of `t`. [`ReducedScheme::recover`] adds $T_{lo} z_0$
    /// inside the one rounding of each entry of $w$ (module docs).
    pub t_lo: SMatrix<f64, M, S>,
    /// $f_{\max} / (2 g)$ with $f_{\max}$ the largest finite double and $g$ the largest entry
    /// of $|T|$ and $|A^{-1}|$: when $\sum_j |z_{0,j}| + \sum_q |n_q|$ is below it, every
    /// entry of $w = T z_0 - A^{-1} n$ is finite (its magnitude is at most $g$ times that sum;
    /// the corrections `t_lo` and `a_inv_lo`, about $u$ times `t` and `a_inv`, stay within the
    /// factor 2), so the step needs no check of $w$.
    pub finite_below: f64,
}

impl<const S: usize, const M: usize, const R: usize> ReducedFactors<S, M, R> {
    /// The factors of `system` for $(h, \theta)$.
    ///
    /// # Errors
    /// [`Error::SingularJacobian`] (iteration 0) if $A$ is singular (only for degenerate
    /// $h$ and $\theta$); [`Error::NonFinite`] if a parameter makes $A$ or $B$ non-finite.
    pub fn new<Sys>(system: &Sys, h: f64, theta: f64) -> Result<Self, Error>
    where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        let mut factors = Self::zeroed(h, theta);
        factors.compute(system, h, theta, true)?;
        Ok(factors)
    }

    /// The factors by LU of the blocks of $A$, never from the closed form (to check it).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn factorised<Sys>(system: &Sys, h: f64, theta: f64) -> Result<Self, Error>
    where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        let mut factors = Self::zeroed(h, theta);
        factors.compute(system, h, theta, false)?;
        Ok(factors)
    }

    /// Factors of zeros for $(h, \theta)$, to be computed ([`Self::compute`]).
    fn zeroed(h: f64, theta: f64) -> Self {
        Self {
            h,
            theta,
            a_inv: SMatrix::zeros(),
            a_inv_lo: SMatrix::zeros(),
            k: SMatrix::zeros(),
            g: SMatrix::zeros(),
            t: SMatrix::zeros(),
            t_lo: SMatrix::zeros(),
            finite_below: 0.0,
        }
    }

    /// Computes the factors of `system` for $(h, \theta)$ in place (a cached slot is
    /// overwritten, no copy of the factors): block by block of $A$ ([`blocks`]), $T$ and
    /// $A^{-1}$ from the closed form where `closed_form` allows and it is accepted for the
    /// block, else by LU of the block, then their corrections with the same LU factors; then
    /// $K$, $G$ and the finiteness bound. On an error the factors are unspecified.
    ///
    /// # Errors
    /// As [`Self::new`].
    fn compute<Sys>(
        &mut self,
        system: &Sys,
        h: f64,
        theta: f64,
        closed_form: bool,
    ) -> Result<(), Error>
    where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        let a = system.linear_part(h, theta);
        let b = system.initial_part(h, theta);
        if !(all_finite(&a) && all_finite(&b)) {
            return Err(Error::NonFinite {
                iteration: 0,
                location: "linear part of the reduced step",
            });
        }
        (self.h, self.theta) = (h, theta);
        // (a slice's fill is one memset; the matrix's own runs entry by entry; the columns of
        // a_inv and a_inv_lo outside the forced ones are zero from `zeroed` on: never written)
        for m in [&mut self.t, &mut self.t_lo] {
            m.as_mut_slice().fill(0.0);
        }
        for &q in Sys::FORCED {
            for m in [&mut self.a_inv, &mut self.a_inv_lo] {
                m.column_mut(q).as_mut_slice().fill(0.0);
            }
        }
        let closed = if closed_form {
            system.closed_form_factors(h, theta, &mut self.t, &mut self.a_inv)
        } else {
            ClosedForm::None
        };
        let mut work = BlockWork::new();
        let (mut covered, mut largest) = (0, 0.0f64);
        for &(rows, cols) in Sys::BLOCKS {
            covered += rows.len();
            let block = work.factor::<Sys, R>(&a, &b, Block { rows, cols }, closed, self)?;
            largest = largest.max(block);
        }
        if covered != M {
            return Err(Error::SingularJacobian { iteration: 0 });
        }
        self.derive::<Sys>(largest);
        Ok(())
    }

    /// $K$, $G$ and the finiteness bound from $T$, $A^{-1}$ and the largest magnitude of
    /// their entries.
    fn derive<Sys>(&mut self, largest: f64)
    where
        Sys: ReducedScheme<S, M, R> + ?Sized,
    {
        let theta = self.theta;
        for (m, &core) in Sys::CORE.iter().enumerate() {
            for c in 0..M {
                self.k[(m, c)] = theta * self.a_inv[(core, c)];
            }
            for c in 0..S {
                let own = if c == core { 1.0 - theta } else { 0.0 };
                self.g[(m, c)] = theta * self.t[(core, c)] + own;
            }
        }
        self.finite_below = f64::MAX / (2.0 * largest.max(1.0));
    }
}

/// $s = \mathrm{fl}(a + b)$ and its rounding error $a + b - s$ (Knuth's TwoSum: exact
/// unless $s$ overflows).
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let b_virtual = s - a;
    (s, (a - (s - b_virtual)) + (b - b_virtual))
}

/// $\mathrm{fl}(s + ((a - (s - b_v)) + ((b - b_v) + c)))$ with $s = \mathrm{fl}(a + b)$ and
/// $b_v = \mathrm{fl}(s - a)$, that is $\mathrm{fl}(s + (e + c))$ up to the rounding of the
/// error terms, $(s, e)$ = [`two_sum`]$(a, b)$: the sum $a + b$ with the
/// small correction $c$ added inside its one rounding (the last addition of a row of
/// [`ReducedScheme::recover`], generated, with terms of factor $\pm 1$ in both halves, whose
/// corrections $c$ would be lost below the last bit of $a + b$; the other rows use
/// [`sum_folded`]). Where $b$ is known last, the correction joins $b$'s half of the error
/// first, $e + c = (a - (s - b_v)) + ((b - b_v) + c)$ with $b_v = s - a$: one addition fewer
/// after $b$ than $(e + c)$, and the same value up to the rounding of the error terms
/// ($u^2 |s|$, $u$ the unit roundoff).
#[inline(always)]
pub fn sum_corrected(a: f64, b: f64, c: f64) -> f64 {
    let s = a + b;
    let b_virtual = s - a;
    s + ((a - (s - b_virtual)) + ((b - b_virtual) + c))
}

/// $\mathrm{fl}(a + \mathrm{fl}(b + c))$: the sum $a + b$ with the small correction $c$
/// added to $b$ first, for a $b$ small against $a$ (the last addition of a row of
/// [`ReducedScheme::recover`], generated, $b$ the terms of $n$ or of the factors scaled by
/// powers of $h$). Where $|b| \le 2^{-k} |a|$, $\mathrm{fl}(b + c)$ misses $b + c$ by at most
/// $2^{-k}$ of the last bit of the sum, so that $c$ enters the one rounding of $a + b + c$ as
/// in [`sum_corrected`], the result differing from it with a probability of about $2^{-k}$
/// and then by one unit in the last place; where $b$ dominates, $c$ below half its last bit
/// is lost (as without the correction). Two operations instead of [`sum_corrected`]'s eight.
#[inline(always)]
pub fn sum_folded(a: f64, b: f64, c: f64) -> f64 {
    a + (b + c)
}

/// $p = \mathrm{fl}(a b)$ and its rounding error $a b - p$: a fused multiply-add where `std`
/// and the target's `fma` feature make it one instruction, else Dekker's product by Veltkamp
/// splitting (17 flops, branch-free). The error is exact unless it underflows; where Dekker's
/// splitting overflows ($|a|$ or $|b|$ above about $2^{996}$) or $p$ is not finite, it is 0.
#[inline(always)]
pub fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, Split::new(a).product_error(Split::new(b), p))
}

/// A double $x$ with its Veltkamp halves $x = x_{hi} + x_{lo}$, $x_{hi}$ the upper 26
/// significant bits (where `std` and the target's `fma` feature give a fused multiply-add,
/// only $x$: the halves are not needed). Splitting an operand once saves the split in every
/// product it enters.
#[derive(Clone, Copy, Debug)]
struct Split {
    value: f64,
    #[cfg(not(all(feature = "std", target_feature = "fma")))]
    hi: f64,
    #[cfg(not(all(feature = "std", target_feature = "fma")))]
    lo: f64,
}

impl Split {
    /// $x$ and its halves: $x_{hi} = c - (c - x)$ with $c = (2^{27} + 1) x$, $x_{lo} = x - x_{hi}$.
    #[inline(always)]
    fn new(value: f64) -> Self {
        #[cfg(not(all(feature = "std", target_feature = "fma")))]
        {
            // 2^27 + 1 splits a double into two halves of at most 26 significant bits each
            const SPLIT: f64 = 134_217_729.0;
            let c = SPLIT * value;
            let hi = c - (c - value);
            Self {
                value,
                hi,
                lo: value - hi,
            }
        }
        #[cfg(all(feature = "std", target_feature = "fma"))]
        Self { value }
    }

    /// $x y - p$ for $p = \mathrm{fl}(x y)$: exact (Dekker:
    /// $((x_{hi} y_{hi} - p) + x_{hi} y_{lo} + x_{lo} y_{hi}) + x_{lo} y_{lo}$, or one fused
    /// multiply-add) unless it underflows; 0 where it is not finite.
    #[inline(always)]
    fn product_error(self, other: Self, p: f64) -> f64 {
        #[cfg(all(feature = "std", target_feature = "fma"))]
        let e = self.value.mul_add(other.value, -p);
        #[cfg(not(all(feature = "std", target_feature = "fma")))]
        let e = ((self.hi * other.hi - p) + self.hi * other.lo + self.lo * other.hi)
            + self.lo * other.lo;
        if e.is_finite() { e } else { 0.0 }
    }
}

/// A compensated sum of products (Dot2 of Ogita, Rump and Oishi, "Accurate sum and dot
/// product", SIAM J. Sci. Comput. 26, 2005): the rounding errors of every product
/// ([`two_product`]) and every addition ([`two_sum`]) are summed apart and added once at the
/// end, as accurate as a sum in twice the working precision rounded once. The residuals of
/// the factors' corrections are summed with it.
#[derive(Clone, Copy, Debug)]
struct Dot2 {
    sum: f64,
    error: f64,
}

impl Dot2 {
    /// The sum of one exact term.
    fn exact(value: f64) -> Self {
        Self {
            sum: value,
            error: 0.0,
        }
    }

    /// Adds a term known exactly (a product by a power of two).
    #[inline(always)]
    fn add_exact(&mut self, p: f64) {
        let (sum, error) = two_sum(self.sum, p);
        self.sum = sum;
        self.error += error;
    }

    /// Adds the product $a b$ of two split operands.
    #[inline(always)]
    fn add_split_product(&mut self, a: Split, b: Split) {
        let p = a.value * b.value;
        let product_error = a.product_error(b, p);
        let (sum, error) = two_sum(self.sum, p);
        self.sum = sum;
        self.error += error + product_error;
    }

    /// The sum, rounded once.
    fn value(self) -> f64 {
        self.sum + self.error
    }
}

/// How many $(h, \theta)$ factorisations a [`ReducedStepper`] keeps (6.9 KB each for the
/// planar rigid body, $S = 12$, $M = 15$: 111 KB in the stepper itself, no heap; empty slots
/// are not written when the stepper is made). The least recently used pair is
/// replaced, so a controller that cycles through at most this many distinct step sizes
/// factorises once per size: every composition of [`crate::scheme::compose`] (at most 8 distinct
/// stage sizes), a controller alternating up to 16 sizes. A cycle through more sizes than
/// this, or an adaptive controller whose sizes never repeat, factorises on every step with a
/// size not used among the last `CACHE_SIZE` distinct ones
/// ([`ReducedStepper::factorisations`] counts them).
pub const CACHE_SIZE: usize = 16;

/// Steps a [`ReducedScheme`] with Newton on its core; caches [`ReducedFactors`] for the
/// [`CACHE_SIZE`] most recently used $(h, \theta)$ pairs (least recently used replaced). No
/// heap.
///
/// # Example
/// The obstacle system of the paper: its Hessian depends on the position $q$ only, so the
/// macro reduces the step from $M = 15$ Newton unknowns to $R = 2$. The reduced step is the
/// same map as [`crate::step()`], and a constant step size factorises once:
/// ```
/// use retract::nalgebra::SVector;
/// use retract::{LiftedSystem, ReducedStepper, StepOptions, higher_order_lagrangian, step};
///
/// #[higher_order_lagrangian(order = 2)]
/// fn obstacle(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64) -> f64 {
///     0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
///         + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
/// }
///
/// let system = Obstacle::new(1e-2);
/// assert_eq!(Obstacle::REDUCED_UNKNOWNS, 2); // the core: x and y of the body
/// let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
/// let mut general = system.legendre(&SVector::from(jet));
/// let mut reduced = general;
/// let (mut stepper, options) = (ReducedStepper::new(&system), StepOptions::default());
/// for _ in 0..200 {
///     general = step(&system, &general, 0.01, &options)?.0;
///     reduced = stepper.step(&reduced, 0.01, &options)?.0;
///     assert!((general - reduced).amax() < 1e-10 * general.amax());
/// }
/// assert_eq!(stepper.factorisations(), 1);
/// # Ok::<(), retract::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct ReducedStepper<'a, Sys: ?Sized, const S: usize, const M: usize, const R: usize> {
    system: &'a Sys,
    factors: [Option<ReducedFactors<S, M, R>>; CACHE_SIZE],
    /// When each slot was last used (0: never); only stamped when the slot in use changes.
    used: [u64; CACHE_SIZE],
    clock: u64,
    /// The slot of the last step, looked at first (a constant step size never scans).
    last: usize,
    /// Factors computed so far (cache misses).
    factorisations: usize,
}

/// $r(y)$ of the module docs as a Newton problem. One call computes $r$ and its Jacobian; the
/// last point is kept, since the solver asks for the Jacobian where it evaluated the residual.
struct CoreProblem<'a, Sys: ?Sized, const S: usize, const M: usize, const R: usize> {
    system: &'a Sys,
    factors: &'a ReducedFactors<S, M, R>,
    offset: SVector<f64, R>,
    last: Cell<Evaluation<R>>,
}

/// $y$, $r(y)$ and $\partial r/\partial y$.
type Evaluation<const R: usize> = (SVector<f64, R>, SVector<f64, R>, SMatrix<f64, R, R>);

impl<Sys, const S: usize, const M: usize, const R: usize> CoreProblem<'_, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    fn evaluate(&self, y: &SVector<f64, R>) -> Evaluation<R> {
        let last = self.last.get();
        if last.0 == *y {
            return last;
        }
        let f = self.factors;
        let (r, j) = self.system.core_system(f, &self.offset, y, f.h, f.theta);
        self.last.set((*y, r, j));
        (*y, r, j)
    }

    /// Newton on $r(y) = 0$ for a step whose fixed-point guess $y_1 = y_0 - r(y_0)$ (from the
    /// force-free guess $y_0 = G z_0$) does not meet the residual test (large steps, stiff
    /// forces): from the Newton step $y_0 - J_0^{-1} r(y_0)$ if it lowers the residual below
    /// $|r(y_0)|$, else from $y_0$. Returns the solution and $n(y)$ there.
    #[inline(never)]
    fn solve(
        system: &Sys,
        factors: &ReducedFactors<S, M, R>,
        offset: SVector<f64, R>,
        fixed_point: SVector<f64, R>,
        newton: &crate::NewtonOptions,
    ) -> Result<(newton::Solution<R>, SVector<f64, M>), Error> {
        let (h, theta) = (factors.h, factors.theta);
        let (r0, j0) = system.core_system(factors, &offset, &offset, h, theta);
        let guess = match crate::numeric::linalg::solve(&j0, &r0) {
            Some(step) => offset - step,
            None => fixed_point,
        };
        let n = system.forcing(&guess, h, theta);
        let r = system.core_residual(factors, &offset, &guess, &n);
        let norm = max_abs(&r);
        let finite = all_finite(&r);
        if finite && newton.converged(norm, norm) {
            let solution = newton::Solution {
                w: guess,
                iterations: 0,
                residual_norm: norm,
            };
            return Ok((solution, n));
        }
        let start = if finite && norm < max_abs(&r0) {
            let j = system.core_system(factors, &offset, &guess, h, theta).1;
            (guess, r, j)
        } else {
            (offset, r0, j0)
        };
        let problem = CoreProblem {
            system,
            factors,
            offset,
            last: Cell::new(start),
        };
        let solution = newton::solve_validated(&problem, start.0, newton)?;
        Ok((solution, system.forcing(&solution.w, h, theta)))
    }
}

impl<Sys, const S: usize, const M: usize, const R: usize> Problem<R>
    for CoreProblem<'_, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    fn residual(&self, y: &SVector<f64, R>) -> SVector<f64, R> {
        self.evaluate(y).1
    }

    fn jacobian(&self, y: &SVector<f64, R>) -> SMatrix<f64, R, R> {
        self.evaluate(y).2
    }
}

impl<'a, Sys, const S: usize, const M: usize, const R: usize> ReducedStepper<'a, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    /// A stepper for `system` (factors are computed at the first step).
    pub fn new(system: &'a Sys) -> Self {
        Self {
            system,
            // each slot's tag written at run time: `[const { None }; CACHE_SIZE]` is a constant
            // whose bytes are all written (a memset of the whole cache, 1.2 us for the planar
            // rigid body against 10 ns)
            factors: core::array::from_fn(|_| None),
            used: [0; CACHE_SIZE],
            clock: 0,
            last: 0,
            factorisations: 0,
        }
    }

    /// How many times the stepper computed [`ReducedFactors`] (one per cache miss: a step
    /// size and theta not among the [`CACHE_SIZE`] most recently used ones).
    pub fn factorisations(&self) -> usize {
        self.factorisations
    }

    /// Factorises for a new $(h, \theta)$ into the least recently used slot (an empty one
    /// first) (out of line: the cold path).
    #[cold]
    #[inline(never)]
    fn insert(&mut self, h: f64, theta: f64) -> Result<usize, Error> {
        let mut slot = 0;
        for (i, &used) in self.used.iter().enumerate() {
            if used < self.used[slot] {
                slot = i;
            }
        }
        self.factorisations = self.factorisations.saturating_add(1);
        let system = self.system;
        if let Some(entry) = self.factors.get_mut(slot) {
            // computed in the slot itself: no copy of the factors
            let factors = entry.get_or_insert_with(|| ReducedFactors::zeroed(h, theta));
            if let Err(error) = factors.compute(system, h, theta, true) {
                *entry = None;
                return Err(error);
            }
        }
        Ok(slot)
    }

    /// The slot holding $(h, \theta)$ when it is not the last one used: a scan of the
    /// cache, else a new factorisation (validated first); marks the slot as the most
    /// recently used.
    #[inline(never)]
    fn lookup(&mut self, h: f64, options: &StepOptions) -> Result<usize, Error> {
        let theta = options.theta;
        let slot = match self
            .factors
            .iter()
            .position(|f| matches!(f, Some(f) if f.h == h && f.theta == theta))
        {
            Some(slot) => slot,
            None => {
                options.validate(h)?;
                self.insert(h, theta)?
            }
        };
        self.clock = self.clock.wrapping_add(1);
        if let Some(used) = self.used.get_mut(slot) {
            *used = self.clock;
        }
        self.last = slot;
        Ok(slot)
    }

    /// The cached factors for the options' $(h, \theta)$, validated and computed if new (a
    /// cached pair passed [`StepOptions`]' checks when it was inserted; NaN matches none).
    #[inline]
    fn factors(
        &mut self,
        h: f64,
        options: &StepOptions,
    ) -> Result<&ReducedFactors<S, M, R>, Error> {
        let theta = options.theta;
        let hit = matches!(
            self.factors.get(self.last),
            Some(Some(f)) if f.h == h && f.theta == theta
        );
        let slot = if hit {
            self.last
        } else {
            self.lookup(h, options)?
        };
        self.factors
            .get(slot)
            .and_then(Option::as_ref)
            .ok_or(Error::SingularJacobian { iteration: 0 })
    }

    /// One step $z_1 = \Psi_h(z_0)$, the same map as [`crate::step()`].
    ///
    /// # Errors
    /// As [`crate::step()`]; a singular $A$ (only for degenerate $\theta$ and $h$) is
    /// [`Error::SingularJacobian`] at iteration 0.
    pub fn step(
        &mut self,
        z0: &SVector<f64, S>,
        h: f64,
        options: &StepOptions,
    ) -> Result<(SVector<f64, S>, StepReport), Error> {
        let system = self.system;
        self.step_unnamed(z0, h, options)
            .map_err(|e| crate::scheme::step::name_parameter(system, e))
    }

    /// [`Self::step`] before a non-finite value is traced to a parameter.
    fn step_unnamed(
        &mut self,
        z0: &SVector<f64, S>,
        h: f64,
        options: &StepOptions,
    ) -> Result<(SVector<f64, S>, StepReport), Error> {
        options.newton.validate()?;
        let theta = options.theta;
        let system = self.system;
        let factors = self.factors(h, options)?;
        // with sum_q |n_q| below, bounds |w| (ReducedFactors::finite_below), so that w needs no
        // check of its own; z0 is known first, so this is off the critical path
        let state_size = sum_abs(z0);
        let offset = system.core_offset(factors, z0);
        // a non-finite state shows as a non-finite guess or step, and is named as such below
        let state_error = || Error::NonFinite {
            iteration: 0,
            location: "state",
        };
        // the fixed-point step y1 = y0 - r(y0) = y0 - K n(y0) from the force-free guess
        // y0 = G z0: exact up to O(|K dn/dy| |r(y0)|), so for small steps it meets the
        // residual test and no Jacobian is evaluated (Newton would return it with 0
        // iterations)
        let fixed_point = offset - system.core_forcing(factors, &offset, h, theta);
        let n1 = system.forcing(&fixed_point, h, theta);
        let r1 = system.core_residual(factors, &offset, &fixed_point, &n1);
        let norm1 = finite_max_abs(&r1);
        let (solution, forcing) = if all_finite(&r1) && options.newton.converged(norm1, norm1) {
            let solution = newton::Solution {
                w: fixed_point,
                iterations: 0,
                residual_norm: norm1,
            };
            (solution, n1)
        } else {
            CoreProblem::solve(system, factors, offset, fixed_point, &options.newton)
                .map_err(|e| if all_finite(z0) { e } else { state_error() })?
        };
        let forcing_size = Sys::FORCED
            .iter()
            .fold(0.0, |sum, &q| sum + forcing[q].abs());
        let w = recover(system, factors, z0, &forcing, options.compensated);
        // the state: the first S unknowns (an array built in place; nalgebra's `into_owned`
        // of a slice copies through an iterator, out of line). Only it is returned, so only it
        // is checked: the other unknowns (the top derivative) are left to the domain check,
        // and where it does not read them they are not computed at all
        let z1: SVector<f64, S> = SVector::from(core::array::from_fn(|i| w[i]));
        if !(state_size + forcing_size < factors.finite_below || all_finite(&z1)) {
            return Err(if all_finite(z0) {
                Error::NonFinite {
                    iteration: solution.iterations,
                    location: "reduced step",
                }
            } else {
                state_error()
            });
        }
        if options.check_domain {
            // the chord's pieces (the cold path) recover w again: only the entries the
            // guards read are computed here
            let again = || recover_again(system, factors, z0, &forcing, options.compensated);
            crate::scheme::step::check_step_domain_with(system, z0, &w, options, again)
                .map_err(Error::Domain)?;
        }
        Ok((
            z1,
            StepReport {
                iterations: solution.iterations,
                residual_norm: solution.residual_norm,
                halvings: 0,
            },
        ))
    }
}

/// $\max_i |r_i|$ for a finite `r` (with NaN entries it is not [`max_abs`]: a NaN is kept or
/// skipped by its place), by plain comparisons: on the step's critical path, where the
/// zero-initialised lanes of [`max_abs`] and its NaN-skipping maxima cost several dependent
/// operations more.
#[inline(always)]
fn finite_max_abs<const R: usize>(r: &SVector<f64, R>) -> f64 {
    r.iter()
        .map(|v| v.abs())
        .reduce(|m, a| if a > m { a } else { m })
        .unwrap_or(0.0)
}

/// The unknowns $w$ from the solved core's forcing: [`ReducedScheme::recover`], or
/// [`ReducedScheme::recover_plain`] without `compensated` (inlined, so that the step
/// computes only the entries it reads).
#[inline(always)]
fn recover<Sys, const S: usize, const M: usize, const R: usize>(
    system: &Sys,
    factors: &ReducedFactors<S, M, R>,
    z0: &SVector<f64, S>,
    forcing: &SVector<f64, M>,
    compensated: bool,
) -> SVector<f64, M>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    if compensated {
        system.recover(factors, z0, forcing)
    } else {
        system.recover_plain(factors, z0, forcing)
    }
}

/// [`recover`] out of line, for the cold path that needs every entry of $w$ (the chord's
/// pieces).
#[cold]
#[inline(never)]
fn recover_again<Sys, const S: usize, const M: usize, const R: usize>(
    system: &Sys,
    factors: &ReducedFactors<S, M, R>,
    z0: &SVector<f64, S>,
    forcing: &SVector<f64, M>,
    compensated: bool,
) -> SVector<f64, M>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    recover(system, factors, z0, forcing, compensated)
}

#[cfg(feature = "std")]
impl<Sys, const S: usize, const M: usize, const R: usize> ReducedStepper<'_, Sys, S, M, R>
where
    Sys: ReducedScheme<S, M, R> + ?Sized,
{
    /// `steps` reduced steps of size `h` from `z0`, with the driver of [`crate::trajectory`]
    /// (the parameters and the initial state checked, step halving, domain crossing
    /// location).
    ///
    /// # Errors
    /// [`crate::Interrupted`] with the states before the failed step; a non-finite parameter
    /// is [`Error::NonFiniteParameter`] and a `z0` outside the domain of the Lagrangian
    /// [`Error::InitialStateOutsideDomain`] at step 0, as in [`crate::trajectory`].
    pub fn trajectory(
        &mut self,
        z0: &SVector<f64, S>,
        h: f64,
        steps: usize,
        options: &StepOptions,
    ) -> Result<crate::Trajectory<S>, crate::Interrupted<S>> {
        let system = self.system;
        crate::scheme::step::drive_system::<Sys, S, M>(
            system,
            |z: &SVector<f64, S>, h, o: &StepOptions| self.step(z, h, o),
            z0,
            h,
            steps,
            options,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::{Dot2, Split, sum_corrected, sum_folded, two_product, two_sum};

    /// Uniform draws in [-0.5, 0.5) (xorshift from `state`).
    fn uniform(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    #[test]
    fn the_error_free_transformations_are_exact() {
        let mut next = uniform(0x9e37_79b9_7f4a_7c15);
        for _ in 0..10_000 {
            let (a, b) = (next() * 1e3, next() * 1e-3);
            let (p, e) = two_product(a, b);
            assert_eq!((p, e), (a * b, num_traits::Float::mul_add(a, b, -p)));
            let (s, e) = two_sum(a, b);
            // |a| > |b|: b - (s - a) is exact (Fast2Sum), the rounding error of s
            assert_eq!((s, e), (a + b, b - (s - a)));
        }
        // beyond Dekker's splitting range (or past overflow) the error is finite, never NaN
        assert!(two_product(1e305, 1e-5).1.is_finite());
        assert!(two_product(1e300, 1e300).0.is_infinite());
        assert_eq!(two_product(1e300, 1e300).1, 0.0);
        // a sum that cancels to its rounding errors: Dot2 finds -2^-104, a plain sum 0
        let mut sum = Dot2::exact(1.0);
        let split = |a: f64, b: f64| (Split::new(a), Split::new(b));
        let ((a, b), (c, d)) = (
            split(1.0 + f64::EPSILON, 1.0 - f64::EPSILON),
            split(-1.0, 2.0),
        );
        sum.add_split_product(a, b);
        sum.add_split_product(c, d);
        assert_eq!(sum.value(), -f64::EPSILON * f64::EPSILON);
    }

    #[test]
    fn a_corrected_sum_keeps_a_correction_below_the_last_bit() {
        let mut next = uniform(0x2545_f491_4f6c_dd1d);
        let mut kept = 0;
        for _ in 0..10_000 {
            // a correction of the size of the rounding error of a + b, either order of size
            let (a, b) = (next(), next() * 1e-3);
            let (a, b) = if next() < 0.0 { (a, b) } else { (b, a) };
            let c = next() * f64::EPSILON;
            // the sum a + b + c rounded once (Dot2: correctly rounded up to u^2 |s|)
            let mut exact = Dot2::exact(a);
            exact.add_exact(b);
            exact.add_exact(c);
            let (exact, sum) = (exact.value(), sum_corrected(a, b, c));
            assert_eq!(sum, exact, "{a} + {b} + {c}");
            kept += usize::from(a + b != exact);
        }
        // the correction changed the rounded sum in many of the draws, and was kept
        assert!(kept > 1000, "{kept}");
    }

    #[test]
    fn a_folded_sum_keeps_a_correction_below_the_last_bit_while_the_late_term_is_small() {
        let mut next = uniform(0x6a09_e667_f3bc_c908);
        let (mut kept, mut differ) = (0, 0);
        for _ in 0..10_000 {
            // |b| at most 2^-10 |a|, a correction of the size of the rounding error of a + b
            let a = next() + 1.0;
            let (b, c) = (next() / 1024.0, next() * f64::EPSILON);
            let mut exact = Dot2::exact(a);
            exact.add_exact(b);
            exact.add_exact(c);
            let (exact, sum) = (exact.value(), sum_folded(a, b, c));
            // one unit in the last place at most (|a + b| in [0.5, 1.5]: 2^-53 or 2^-52)
            assert!((sum - exact).abs() <= f64::EPSILON, "{a} + {b} + {c}");
            differ += usize::from(sum != exact);
            kept += usize::from(a + b != exact && sum == exact);
        }
        // the once-rounded sum in all but about 2^-10 of the draws, and the correction kept
        // where it changed the rounding
        assert!(differ < 50, "{differ}");
        assert!(kept > 1000, "{kept}");
        // where the late term dominates, a correction below half its last bit is lost
        // (1.5 + 0.75 ulp - 0.3 ulp rounds to 1.5; b + c rounds back to b)
        let (a, b, c) = (0.75 * f64::EPSILON, 1.5, -0.3 * f64::EPSILON);
        assert_eq!(sum_folded(a, b, c), 1.5 + f64::EPSILON);
        assert_eq!(sum_corrected(a, b, c), 1.5);
    }
}
