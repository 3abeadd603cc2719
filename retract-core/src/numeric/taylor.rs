//! Numbers for differentiating a rational function at run time: truncated Taylor series
//! ([`Taylor`]), first- and second-order dual numbers ([`Dual`], [`Hyper`]), all without
//! heap.
//!
//! A function written once over a [`Scalar`] and evaluated on `Taylor<Hyper<V>, D>` gives, in
//! one pass, the Taylor coefficients along a curve of its value, its gradient and its Hessian
//! in $V$ variables. [`crate::scheme::map::TaylorLift`] uses this to lift a discretization map to
//! $T^{(k-1)}Q$ at any order without generating the lift's code.
//!
//! Only the field operations are provided ($+$, $-$, $\times$, $/$ and negation, with an `f64`
//! on the right): enough for rational maps such as the projection maps of a sphere.

// (the product and quotient rules add and multiply inside `Mul` and `Div`; the symmetric
// Hessians are filled by index pairs)
#![allow(clippy::suspicious_arithmetic_impl, clippy::needless_range_loop)]

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A number the field operations act on, with `f64` constants on the right: generic code
/// writes `x * 2.0` and `-x + 1.0`. (A bound such as `f64: Sub<T>` would let it write
/// `1.0 - x`, but it also takes over `f64 - f64` in that code, so there is none.)
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
{
    /// The constant $c$.
    fn constant(c: f64) -> Self;
    /// $1 / x$.
    fn recip(self) -> Self;
    /// The Stumpff function $c_k(x)$ ([`crate::numeric::special`]), differentiated by
    /// $c_k' = \tfrac12 (k\thinspace c_{k+2} - c_{k+1})$. On [`Taylor`] series of up to 16 terms
    /// (a longer series does not compile).
    fn stumpff(self, k: u32) -> Self;
}

impl Scalar for f64 {
    #[inline(always)]
    fn constant(c: f64) -> Self {
        c
    }
    #[inline(always)]
    fn recip(self) -> Self {
        1.0 / self
    }
    #[inline(always)]
    fn stumpff(self, k: u32) -> Self {
        crate::numeric::special::stumpff(k, self)
    }
}

/// $c_k(s)$, $c_k'(s) = \tfrac12 (k c_{k+2} - c_{k+1})$ and
/// $c_k''(s) = \tfrac14 (k (k+2) c_{k+4} - (2k+1) c_{k+3} + c_{k+2})$.
fn stumpff_and_derivatives(k: u32, s: f64) -> [f64; 3] {
    let c = |i: u32| crate::numeric::special::stumpff(k.saturating_add(i), s);
    let kf = k as f64;
    [
        c(0),
        0.5 * (kf * c(2) - c(1)),
        0.25 * (kf * (kf + 2.0) * c(4) - (2.0 * kf + 1.0) * c(3) + c(2)),
    ]
}

/// A second-order dual number in $V$ variables: $f$, its gradient $g$ and its Hessian $H$
/// (full and symmetric). Products follow $(fg)'' = f'' g + 2 f' g' + f g''$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hyper<const V: usize> {
    /// The value $f$.
    pub f: f64,
    /// $\partial f / \partial z_a$.
    pub g: [f64; V],
    /// $\partial^2 f / \partial z_a \partial z_b$.
    pub h: [[f64; V]; V],
}

impl<const V: usize> Hyper<V> {
    /// The variable $z_a$ with value `value`: gradient $e_a$, Hessian 0.
    ///
    /// # Panics
    /// If `a` $\ge V$.
    pub fn variable(value: f64, a: usize) -> Self {
        let mut x = Self::constant(value);
        x.g[a] = 1.0;
        x
    }

    /// $\phi(f)$ by the chain rule, from $\phi(f)$, $\phi'(f)$ and $\phi''(f)$:
    /// gradient $\phi' g$, Hessian $\phi' H + \phi'' g g^T$.
    #[inline(always)]
    fn chain(self, value: f64, d1: f64, d2: f64) -> Self {
        let mut h = [[0.0; V]; V];
        for a in 0..V {
            for b in a..V {
                let v = d1 * self.h[a][b] + d2 * self.g[a] * self.g[b];
                (h[a][b], h[b][a]) = (v, v);
            }
        }
        Self {
            f: value,
            g: self.g.map(|g| d1 * g),
            h,
        }
    }

    /// Every component of `self` and `other` combined by `op`.
    #[inline(always)]
    fn zip(self, other: Self, op: impl Fn(f64, f64) -> f64) -> Self {
        Self {
            f: op(self.f, other.f),
            g: core::array::from_fn(|a| op(self.g[a], other.g[a])),
            h: core::array::from_fn(|a| core::array::from_fn(|b| op(self.h[a][b], other.h[a][b]))),
        }
    }

    /// Every component scaled by $c$.
    #[inline(always)]
    fn scaled(self, c: f64) -> Self {
        Self {
            f: self.f * c,
            g: self.g.map(|g| g * c),
            h: self.h.map(|row| row.map(|v| v * c)),
        }
    }
}

impl<const V: usize> Scalar for Hyper<V> {
    #[inline(always)]
    fn constant(c: f64) -> Self {
        Self {
            f: c,
            g: [0.0; V],
            h: [[0.0; V]; V],
        }
    }
    /// $\phi = 1/f$: $\phi' = -1/f^2$, $\phi'' = 2/f^3$.
    #[inline(always)]
    fn recip(self) -> Self {
        let r = 1.0 / self.f;
        self.chain(r, -r * r, 2.0 * r * r * r)
    }
    fn stumpff(self, k: u32) -> Self {
        let [c, d1, d2] = stumpff_and_derivatives(k, self.f);
        self.chain(c, d1, d2)
    }
}

impl<const V: usize> Add for Hyper<V> {
    type Output = Self;
    #[inline(always)]
    fn add(self, other: Self) -> Self {
        self.zip(other, |a, b| a + b)
    }
}

impl<const V: usize> Sub for Hyper<V> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        self.zip(other, |a, b| a - b)
    }
}

impl<const V: usize> Mul for Hyper<V> {
    type Output = Self;
    /// $(fg, f g' + g f', f g'' + g f'' + f' g'^T + g' f'^T)$.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        // the Hessian is symmetric: the upper triangle, mirrored
        let mut h = [[0.0; V]; V];
        for a in 0..V {
            for b in a..V {
                let v = self.f * o.h[a][b]
                    + o.f * self.h[a][b]
                    + self.g[a] * o.g[b]
                    + o.g[a] * self.g[b];
                (h[a][b], h[b][a]) = (v, v);
            }
        }
        Self {
            f: self.f * o.f,
            g: core::array::from_fn(|a| self.f * o.g[a] + o.f * self.g[a]),
            h,
        }
    }
}

impl<const V: usize> Div for Hyper<V> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}

impl<const V: usize> Neg for Hyper<V> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.scaled(-1.0)
    }
}

/// A first-order dual number in $V$ variables: $f$ and its gradient $g$ (what
/// [`Hyper`] computes without the Hessian).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual<const V: usize> {
    /// The value $f$.
    pub f: f64,
    /// $\partial f / \partial z_a$.
    pub g: [f64; V],
}

impl<const V: usize> Dual<V> {
    /// The variable $z_a$ with value `value`: gradient $e_a$.
    ///
    /// # Panics
    /// If `a` $\ge V$.
    pub fn variable(value: f64, a: usize) -> Self {
        let mut x = Self::constant(value);
        x.g[a] = 1.0;
        x
    }

    /// Every component scaled by $c$.
    #[inline(always)]
    fn scaled(self, c: f64) -> Self {
        Self {
            f: self.f * c,
            g: self.g.map(|g| g * c),
        }
    }
}

impl<const V: usize> Scalar for Dual<V> {
    #[inline(always)]
    fn constant(c: f64) -> Self {
        Self { f: c, g: [0.0; V] }
    }
    /// $1/f$ with gradient $-g/f^2$.
    #[inline(always)]
    fn recip(self) -> Self {
        let r = 1.0 / self.f;
        Self {
            f: r,
            g: self.g.map(|g| -r * r * g),
        }
    }
    fn stumpff(self, k: u32) -> Self {
        // c_k and c_k' = (k c_{k+2} - c_{k+1}) / 2 (no second derivative)
        let c = |i: u32| crate::numeric::special::stumpff(k.saturating_add(i), self.f);
        let (c, d1) = (c(0), 0.5 * (f64::from(k) * c(2) - c(1)));
        Self {
            f: c,
            g: self.g.map(|g| d1 * g),
        }
    }
}

impl<const V: usize> Add for Dual<V> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            f: self.f + o.f,
            g: core::array::from_fn(|a| self.g[a] + o.g[a]),
        }
    }
}

impl<const V: usize> Sub for Dual<V> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            f: self.f - o.f,
            g: core::array::from_fn(|a| self.g[a] - o.g[a]),
        }
    }
}

impl<const V: usize> Mul for Dual<V> {
    type Output = Self;
    /// $(fg, f g' + g f')$.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            f: self.f * o.f,
            g: core::array::from_fn(|a| self.f * o.g[a] + o.f * self.g[a]),
        }
    }
}

impl<const V: usize> Div for Dual<V> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}

impl<const V: usize> Neg for Dual<V> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.scaled(-1.0)
    }
}

/// The longest series [`Scalar::stumpff`] lifts.
const MAX_SERIES: usize = 16;

/// A truncated Taylor series $\sum_{j < D} c_j t^j$ with coefficients in a [`Scalar`]:
/// `c[j]` is $f^{(j)}(0) / j!$. Products are Cauchy products; the reciprocal follows
/// $r_0 = 1/b_0$, $r_j = -r_0 \sum_{1 \le i \le j} b_i r_{j-i}$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taylor<T, const D: usize> {
    /// The normalised coefficients $f^{(j)}(0) / j!$.
    pub c: [T; D],
}

impl<T: Scalar, const D: usize> Taylor<T, D> {
    /// The series of a curve from its derivatives at 0: `c[j]` $=$ `derivatives[j]` $/ j!$.
    pub fn from_derivatives(derivatives: [T; D]) -> Self {
        let mut factorial = 1.0;
        let mut c = derivatives;
        for (j, cj) in c.iter_mut().enumerate().skip(1) {
            factorial *= j as f64;
            *cj = *cj / factorial;
        }
        Self { c }
    }

    /// The derivatives at 0: $j!$ `c[j]`.
    pub fn derivatives(&self) -> [T; D] {
        let mut factorial = 1.0;
        let mut d = self.c;
        for (j, dj) in d.iter_mut().enumerate().skip(1) {
            factorial *= j as f64;
            *dj = *dj * factorial;
        }
        d
    }
}

impl<T: Scalar, const D: usize> Scalar for Taylor<T, D> {
    #[inline(always)]
    fn constant(c: f64) -> Self {
        Self {
            c: core::array::from_fn(|j| T::constant(if j == 0 { c } else { 0.0 })),
        }
    }
    #[inline(always)]
    fn recip(self) -> Self {
        const { assert!(D >= 1, "a series has at least its constant term") };
        let r0 = self.c[0].recip();
        let mut r = [r0; D];
        for j in 1..D {
            let mut sum = self.c[1] * r[j - 1];
            for i in 2..=j {
                sum = sum + self.c[i] * r[j - i];
            }
            r[j] = -(r0 * sum);
        }
        Self { c: r }
    }
    /// $\sum_{j < D} c_k^{(j)}(a_0)\thinspace \delta^j / j!$ for the series $a_0 + \delta$, with
    /// $c_k^{(j)} = \sum_i \alpha_{j,i} c_{k+i}$ from the derivative rule.
    fn stumpff(self, k: u32) -> Self {
        const { assert!(D <= MAX_SERIES, "series of up to 16 terms") };
        let a0 = self.c[0];
        let mut delta = self;
        delta.c[0] = T::constant(0.0);
        // alpha[i]: the coefficient of c_{k+i} in c_k^(j), for i <= 2 j
        let mut alpha = [0.0; 2 * MAX_SERIES + 1];
        alpha[0] = 1.0;
        // c_{k+i}(a0) for every i <= 2 (D - 1), once each
        let mut values = [T::constant(0.0); 2 * MAX_SERIES + 1];
        for (i, v) in values.iter_mut().enumerate().take(2 * D.max(1) - 1) {
            *v = a0.stumpff(k.saturating_add(i as u32));
        }
        let (mut power, mut factorial) = (Self::constant(1.0), 1.0);
        let mut out = Self::constant(0.0);
        for j in 0..D {
            let mut derivative = T::constant(0.0);
            for (a, v) in alpha.iter().zip(values).take(2 * j + 1) {
                if *a != 0.0 {
                    derivative = derivative + v * *a;
                }
            }
            for (o, p) in out.c.iter_mut().zip(power.c) {
                *o = *o + p * derivative / factorial;
            }
            power = power * delta;
            factorial *= (j + 1) as f64;
            // c_m -> (m c_{m+2} - c_{m+1}) / 2, from the top down
            for i in (0..=2 * j).rev() {
                let a = core::mem::take(&mut alpha[i]);
                alpha[i + 2] += 0.5 * (f64::from(k) + i as f64) * a;
                alpha[i + 1] -= 0.5 * a;
            }
        }
        out
    }
}

impl<T: Scalar, const D: usize> Add for Taylor<T, D> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            c: core::array::from_fn(|j| self.c[j] + o.c[j]),
        }
    }
}

impl<T: Scalar, const D: usize> Sub for Taylor<T, D> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            c: core::array::from_fn(|j| self.c[j] - o.c[j]),
        }
    }
}

impl<T: Scalar, const D: usize> Mul for Taylor<T, D> {
    type Output = Self;
    /// The Cauchy product $c_j = \sum_{i \le j} a_i b_{j-i}$.
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self {
            c: core::array::from_fn(|j| {
                let mut sum = self.c[0] * o.c[j];
                for i in 1..=j {
                    sum = sum + self.c[i] * o.c[j - i];
                }
                sum
            }),
        }
    }
}

impl<T: Scalar, const D: usize> Div for Taylor<T, D> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        self * o.recip()
    }
}

impl<T: Scalar, const D: usize> Neg for Taylor<T, D> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            c: self.c.map(|c| -c),
        }
    }
}

/// The operations with an `f64` on the right (on the constant term for $+$ and $-$), for
/// [`Dual`], [`Hyper`] and [`Taylor`].
macro_rules! mixed_ops {
    ($ty:ty, [$($generics:tt)*], $add:expr, $scale:expr) => {
        impl<$($generics)*> Add<f64> for $ty {
            type Output = Self;
            #[inline(always)]
            fn add(self, c: f64) -> Self {
                $add(self, c)
            }
        }
        impl<$($generics)*> Sub<f64> for $ty {
            type Output = Self;
            #[inline(always)]
            fn sub(self, c: f64) -> Self {
                $add(self, -c)
            }
        }
        impl<$($generics)*> Mul<f64> for $ty {
            type Output = Self;
            #[inline(always)]
            fn mul(self, c: f64) -> Self {
                $scale(self, c)
            }
        }
        impl<$($generics)*> Div<f64> for $ty {
            type Output = Self;
            #[inline(always)]
            fn div(self, c: f64) -> Self {
                $scale(self, 1.0 / c)
            }
        }
    };
}

mixed_ops!(
    Hyper<V>,
    [const V: usize],
    |x: Hyper<V>, c: f64| Hyper { f: x.f + c, ..x },
    |x: Hyper<V>, c: f64| x.scaled(c)
);
mixed_ops!(
    Dual<V>,
    [const V: usize],
    |x: Dual<V>, c: f64| Dual { f: x.f + c, ..x },
    |x: Dual<V>, c: f64| x.scaled(c)
);
mixed_ops!(
    Taylor<T, D>,
    [T: Scalar, const D: usize],
    |x: Taylor<T, D>, c: f64| {
        let mut y = x;
        y.c[0] = y.c[0] + c;
        y
    },
    |x: Taylor<T, D>, c: f64| Taylor { c: x.c.map(|v| v * c) }
);

#[cfg(test)]
mod tests {
    use super::*;

    /// $f(x, y) = (x^2 y - 3) / (1 + x y^2) + 2x - y/4$, generic.
    fn f<T: Scalar>(x: T, y: T) -> T {
        (x * x * y - 3.0) / (x * y * y + 1.0) + x * 2.0 - y / 4.0
    }

    #[test]
    fn hyper_numbers_match_finite_differences() {
        let (x0, y0) = (0.7, -0.4);
        let v = f(Hyper::<2>::variable(x0, 0), Hyper::variable(y0, 1));
        assert!((v.f - f(x0, y0)).abs() < 1e-15);
        let e = 1e-5;
        let grad = |x: f64, y: f64| {
            [
                (f(x + e, y) - f(x - e, y)) / (2.0 * e),
                (f(x, y + e) - f(x, y - e)) / (2.0 * e),
            ]
        };
        let g = grad(x0, y0);
        for a in 0..2 {
            assert!((v.g[a] - g[a]).abs() < 1e-9, "{a}: {} {}", v.g[a], g[a]);
        }
        let (gx, gy) = (grad(x0 + e, y0), grad(x0, y0 + e));
        let (hx, hy) = (grad(x0 - e, y0), grad(x0, y0 - e));
        for b in 0..2 {
            let dx = (gx[b] - hx[b]) / (2.0 * e);
            let dy = (gy[b] - hy[b]) / (2.0 * e);
            assert!((v.h[0][b] - dx).abs() < 1e-5, "{b}: {} {dx}", v.h[0][b]);
            assert!((v.h[1][b] - dy).abs() < 1e-5, "{b}: {} {dy}", v.h[1][b]);
        }
        assert_eq!(v.h[0][1], v.h[1][0]);
    }

    #[test]
    fn dual_numbers_give_the_gradient_of_hyper_numbers() {
        let (x0, y0) = (0.7, -0.4);
        let d = f(Dual::<2>::variable(x0, 0), Dual::variable(y0, 1));
        let h = f(Hyper::<2>::variable(x0, 0), Hyper::variable(y0, 1));
        assert_eq!(d.f, h.f);
        for a in 0..2 {
            assert!((d.g[a] - h.g[a]).abs() < 1e-15, "{a}");
        }
    }

    #[test]
    fn taylor_series_match_derivatives_along_a_curve() {
        // along x = 0.7 + 0.3 t - t^2, y = -0.4 + 2 t: derivatives of f by differences
        let curve = |t: f64| f(0.7 + 0.3 * t - t * t, -0.4 + 2.0 * t);
        let x = Taylor::from_derivatives([0.7, 0.3, -2.0, 0.0]);
        let y = Taylor::from_derivatives([-0.4, 2.0, 0.0, 0.0]);
        let d = f(x, y).derivatives();
        let e = 1e-3;
        let s = [-2.0, -1.0, 0.0, 1.0, 2.0].map(|k| curve(k * e));
        let fd = [
            s[2],
            (s[3] - s[1]) / (2.0 * e),
            (s[3] - 2.0 * s[2] + s[1]) / (e * e),
            (s[4] - 2.0 * s[3] + 2.0 * s[1] - s[0]) / (2.0 * e * e * e),
        ];
        let tolerance = [1e-15, 1e-5, 1e-5, 1e-3];
        for j in 0..4 {
            let scale = 1.0 + fd[j].abs();
            assert!(
                (d[j] - fd[j]).abs() < tolerance[j] * scale,
                "{j}: {} {}",
                d[j],
                fd[j]
            );
        }
    }

    #[test]
    fn the_reciprocal_series_inverts() {
        let b = Taylor::<f64, 5>::from_derivatives([2.0, -1.0, 3.0, 0.5, -4.0]);
        let one = b * b.recip();
        assert!((one.c[0] - 1.0).abs() < 1e-15);
        assert!(one.c[1..].iter().all(|c| c.abs() < 1e-14), "{:?}", one.c);
    }

    /// The angle theta0 + t as a series, and its square.
    fn angle<const D: usize>(theta0: f64) -> (Taylor<f64, D>, Taylor<f64, D>) {
        let mut theta = Taylor::<f64, D>::constant(theta0);
        theta.c[1] = 1.0;
        (theta, theta * theta)
    }

    #[test]
    fn stumpff_series_are_the_trigonometric_series() {
        // c_0(theta^2) = cos theta and c_2(theta^2) theta^2 = 1 - cos theta along
        // theta = theta0 + t: the coefficients are cos^(j)(theta0) / j!
        for theta0 in [0.0, 0.4, 1.3, 2.9] {
            let (theta, s) = angle::<8>(theta0);
            let (c0, c2) = (s.stumpff(0), s.stumpff(2) * s);
            let mut factorial = 1.0;
            for j in 0..8 {
                if j > 0 {
                    factorial *= j as f64;
                }
                // cos^(j)(x) = cos(x + j pi / 2)
                let exact = (theta0 + j as f64 * core::f64::consts::FRAC_PI_2).cos() / factorial;
                assert!((c0.c[j] - exact).abs() < 1e-14, "{theta0} {j}: {}", c0.c[j]);
                let one_minus = if j == 0 { 1.0 - theta0.cos() } else { -exact };
                assert!((c2.c[j] - one_minus).abs() < 1e-14, "{theta0} {j}");
            }
            // c_1(theta^2) theta = sin theta, through the series' own product
            let c1 = s.stumpff(1) * theta;
            let exact = (theta0 + 3.0 * core::f64::consts::FRAC_PI_2).sin() / 6.0;
            assert!((c1.c[3] - exact).abs() < 1e-14, "{theta0}");
        }
    }

    #[test]
    fn stumpff_of_dual_and_hyper_numbers_match_finite_differences() {
        // c_3(x^2 + x y) at (0.8, -1.9)
        let g = |x: f64, y: f64| (x * x + x * y).stumpff(3);
        let (x0, y0) = (0.8, -1.9);
        let v = {
            let (x, y) = (Hyper::<2>::variable(x0, 0), Hyper::variable(y0, 1));
            (x * x + x * y).stumpff(3)
        };
        let d = {
            let (x, y) = (Dual::<2>::variable(x0, 0), Dual::variable(y0, 1));
            (x * x + x * y).stumpff(3)
        };
        let e = 1e-4;
        let gx = (g(x0 + e, y0) - g(x0 - e, y0)) / (2.0 * e);
        let gy = (g(x0, y0 + e) - g(x0, y0 - e)) / (2.0 * e);
        let gxy = (g(x0 + e, y0 + e) - g(x0 + e, y0 - e) - g(x0 - e, y0 + e) + g(x0 - e, y0 - e))
            / (4.0 * e * e);
        assert!((v.f - g(x0, y0)).abs() < 1e-16 && d.f == v.f);
        assert!((v.g[0] - gx).abs() < 1e-8 && (v.g[1] - gy).abs() < 1e-8);
        assert!(d.g == v.g, "{:?} {:?}", d.g, v.g);
        assert!((v.h[0][1] - gxy).abs() < 1e-6 && v.h[0][1] == v.h[1][0]);
    }
}
