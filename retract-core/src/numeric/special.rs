//! Special functions that the exponential maps of the rotation and rigid-motion groups need
//! and that are entire in the squared angle, so that generated code stays straight-line
//! through zero rotation.
//!
//! The Stumpff functions
//!
//! $$c_k(s) = \sum_{m \ge 0} \frac{(-s)^m}{(2m + k)!}$$
//!
//! are entire in $s$; for $s = \theta^2 > 0$, $c_0 = \cos\theta$, $c_1 = \sin\theta / \theta$,
//! $c_2 = (1 - \cos\theta)/\theta^2$ and $c_3 = (\theta - \sin\theta)/\theta^3$. They satisfy
//! $c_k(s) = 1/k! - s\thinspace c_{k+2}(s)$ and are closed under differentiation:
//!
//! $$c_k'(s) = \tfrac12 \big(k\thinspace c_{k+2}(s) - c_{k+1}(s)\big),$$
//!
//! which is what `#[higher_order_lagrangian]` and `#[discretization_map]` differentiate
//! `stumpff(k, s)` by, and what [`crate::numeric::taylor::Scalar::stumpff`] lifts.

/// Entries of the tables below.
const TABLE: usize = 256;

/// $1/(n (n+1))$: the ratio of consecutive terms of the series, without a division.
const RATIOS: [f64; TABLE] = {
    let mut t = [0.0; TABLE];
    let mut n = 1;
    while n < TABLE {
        t[n] = 1.0 / ((n * (n + 1)) as f64);
        n += 1;
    }
    t
};

/// $1/k!$, with $k!$ the running product in `f64` (exact up to $k = 22$; 0 from $k = 171$,
/// where $k!$ overflows).
const INVERSE_FACTORIALS: [f64; TABLE] = {
    let mut t = [0.0; TABLE];
    let (mut k, mut factorial) = (0, 1.0);
    while k < TABLE {
        if k > 1 {
            factorial *= k as f64;
        }
        t[k] = 1.0 / factorial;
        k += 1;
    }
    t
};

/// The Stumpff function $c_k(s)$ (module docs): to a few units in the last place where it is
/// well conditioned, for $|s| \le 100$; for $s < -709^2$ the closed forms overflow and the
/// value is $+\infty$.
///
/// Where $|s| \le \max(4, (k+1)(k+2))$ the series is summed until its terms no longer change
/// the sum: its terms fall from the first or nearly so, so little cancels. Beyond, $c_0$ and
/// $c_1$ are taken in closed form ($\cos$, $\sin$, or $\cosh$, $\sinh$ for $s < 0$) and raised
/// by $c_{j+2} = (1/j! - c_j)/s$, which is stable there because $(j+1)(j+2) < |s|$. A NaN $s$
/// gives NaN.
///
/// ```
/// use retract_core::stumpff;
/// let theta: f64 = 0.7;
/// let c2 = (1.0 - theta.cos()) / (theta * theta);
/// assert!((stumpff(2, theta * theta) - c2).abs() < 1e-15);
/// assert_eq!(stumpff(3, 0.0), 1.0 / 6.0);
/// ```
pub fn stumpff(k: u32, s: f64) -> f64 {
    let size = s.abs();
    let kf = k as f64;
    if size <= (4.0f64).max((kf + 1.0) * (kf + 2.0)) || s.is_nan() {
        series(k, s)
    } else {
        raised(k, s)
    }
}

/// $\sum_m (-s)^m / (2m + k)!$ until a term no longer changes the sum.
fn series(k: u32, s: f64) -> f64 {
    let k = k as usize;
    // 1/k! underflows from k = 171 on, and the terms with it
    let Some(&first) = INVERSE_FACTORIALS.get(k) else {
        return 0.0;
    };
    let mut term = first;
    let mut sum = term;
    for m in 0..200 {
        let a = 2 * m + k + 1;
        let ratio = if a < TABLE {
            RATIOS[a]
        } else {
            1.0 / (a as f64 * (a + 1) as f64)
        };
        term *= -s * ratio;
        let next = sum + term;
        if next == sum {
            break;
        }
        sum = next;
    }
    sum
}

/// $c_k$ from the closed forms of $c_0$ and $c_1$ by $c_{j+2} = (1/j! - c_j)/s$.
fn raised(k: u32, s: f64) -> f64 {
    use num_traits::Float;
    let x = Float::sqrt(s.abs());
    // c_0 and c_1 in closed form, and c_2 = 2 sin(x/2)^2 / s (2 sinh(x/2)^2 / |s| for s < 0),
    // which does not cancel where cos x is near 1
    let (c0, c1, c2) = if s > 0.0 {
        let half = Float::sin(x / 2.0);
        (Float::cos(x), Float::sin(x) / x, 2.0 * half * half / s)
    } else {
        let half = Float::sinh(x / 2.0);
        (Float::cosh(x), Float::sinh(x) / x, -2.0 * half * half / s)
    };
    let (mut j, mut c) = match k {
        0 => (0, c0),
        _ if k % 2 == 1 => (1, c1),
        _ => (2, c2),
    };
    while j < k {
        let inverse = if (j as usize) < TABLE {
            INVERSE_FACTORIALS[j as usize]
        } else {
            0.0
        };
        c = (inverse - c) / s;
        j += 2;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// k! as the running product in f64.
    fn factorial(k: u32) -> f64 {
        (2..=k).fold(1.0, |f, j| f * j as f64)
    }

    /// The closed forms for s = theta^2 > 0 (module docs), where they do not cancel.
    fn closed(k: u32, theta: f64) -> f64 {
        let s = theta * theta;
        match k {
            0 => theta.cos(),
            1 => theta.sin() / theta,
            2 => (1.0 - theta.cos()) / s,
            3 => (theta - theta.sin()) / (s * theta),
            _ => unreachable!(),
        }
    }

    #[test]
    fn the_low_functions_are_their_closed_forms() {
        for theta in [0.5, 1.0, 1.9, 2.1, 3.0, 5.0, 9.0] {
            for k in 0..4 {
                let (a, b) = (stumpff(k, theta * theta), closed(k, theta));
                assert!(
                    (a - b).abs() < 4e-16 * b.abs().max(1.0),
                    "k={k} {theta}: {a} {b}"
                );
            }
        }
        // the hyperbolic side: c_0(-x^2) = cosh x, c_1 = sinh x / x
        for x in [0.3f64, 1.5, 2.5, 6.0] {
            let (a, b) = (stumpff(0, -x * x), x.cosh());
            assert!((a - b).abs() < 1e-15 * b, "{x}: {a} {b}");
            let (a, b) = (stumpff(1, -x * x), x.sinh() / x);
            assert!((a - b).abs() < 1e-15 * b, "{x}: {a} {b}");
        }
    }

    #[test]
    fn the_recurrence_and_the_values_at_zero_hold() {
        for k in 0..12 {
            assert_eq!(stumpff(k, 0.0), 1.0 / factorial(k));
            // on both sides of every switch between the series and the recurrence
            for s in [
                -50.0, -7.0, -0.4, 0.3, 3.9, 4.1, 11.0, 13.0, 31.0, 43.0, 57.0, 80.0,
            ] {
                let (lhs, rhs) = (stumpff(k, s), 1.0 / factorial(k) - s * stumpff(k + 2, s));
                let scale = 1.0 / factorial(k) + (s * stumpff(k + 2, s)).abs();
                assert!(
                    (lhs - rhs).abs() < 2e-15 * scale,
                    "k={k} s={s}: {lhs} {rhs}"
                );
            }
        }
    }

    #[test]
    fn the_derivative_is_the_shifted_combination() {
        // c_k'(s) = (k c_{k+2} - c_{k+1}) / 2 against central differences
        for k in 0..8 {
            for s in [-3.0, -0.2, 0.0, 0.5, 3.9, 7.0, 25.0] {
                let e = 1e-5 * (1.0 + f64::abs(s));
                let fd = (stumpff(k, s + e) - stumpff(k, s - e)) / (2.0 * e);
                let exact = 0.5 * (k as f64 * stumpff(k + 2, s) - stumpff(k + 1, s));
                assert!(
                    (fd - exact).abs() < 1e-8 * exact.abs().max(1e-3),
                    "k={k} s={s}"
                );
            }
        }
    }

    #[test]
    fn the_values_match_an_independent_evaluation_to_rounding() {
        // c_k(s) from its series summed in 60-digit arithmetic (mpmath), rounded to f64
        let table = [
            (0, 9.0, -0.9899924966004454),
            (2, 9.0, 0.2211102774000495),
            (3, 9.0, 0.10588444414593084),
            (5, 20.0, 0.005290372537455235),
            (8, 60.0, 1.3820046684020302e-05),
            (4, -16.0, 0.0715165345156894),
        ];
        for (k, s, exact) in table {
            let value = stumpff(k, s);
            assert!(
                (value - exact).abs() < 8e-16 * exact.abs(),
                "k={k} s={s}: {value:e}"
            );
        }
    }

    #[test]
    fn nan_stays_nan() {
        assert!(stumpff(2, f64::NAN).is_nan());
    }
}
