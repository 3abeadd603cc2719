//! The "vanishes" rule of the singularity guard between the three samples of a step, which
//! the generated `check_domain` calls for every guarded factor: the quadratic through the
//! samples $(0, a)$, $(\theta, c)$, $(1, b)$ of the factor along the step must not come
//! within [`VANISH_TOLERANCE`] of the largest sample of zero inside the step.

/// The relative distance from zero below which a guarded factor counts as vanished.
pub const VANISH_TOLERANCE: f64 = 1e-9;

/// The rounding error of the fitted minimum, relative to the largest sample, over
/// $\min(\theta, 1 - \theta)$: below it the fit cannot resolve anything.
pub const FIT_NOISE: f64 = 1e-13;

/// Whether the factor with samples `a` (at $x_0$), `b` (at $x_1$) and `c` (at $x_\theta$),
/// of one sign (the sign rule is checked by the caller), stays clear of zero inside the step.
///
/// With the samples made positive ($\sigma = \operatorname{sgn} a$), the quadratic
/// $p(s) = a + \beta s + \alpha s^2$ through them has $\alpha = A/d$ and $\beta = B/d$ with
/// $d = \theta - \theta^2 > 0$, $A = \theta (b - a) - (c - a)$, $B = (b - a) d - A$. Where
/// $A > 0$ and its vertex $v = -B/(2A)$ lies in $(0, 1)$, its minimum
/// $p(v) = a - B^2/(4 A d)$ must exceed $10^{-9} \max(a, b, c)$ ([`VANISH_TOLERANCE`]); where
/// the smallest sample is below the fit's rounding error
/// $m = 10^{-13} \max(a, b, c) / \min(\theta, 1 - \theta)$ ([`FIT_NOISE`]: a step starting on
/// the boundary, or a factor growing by 13 orders of magnitude within one step) only a minimum
/// below $-m$ (a clear dip through zero) is rejected. Every test is multiplied through by its
/// positive denominator, so no division is computed. The fit is exact for a factor quadratic
/// along the step ($x^2 + y^2 - r^2$, $|q'|^2$), so a step that passes through such a zero
/// between the samples is caught. For $\theta$ within $10^{-3}$ of an end only the sign rule
/// applies (`true`); a NaN sample gives `true` here (the sign rule refuses it).
#[inline(always)]
pub fn clear_of_zero(a: f64, b: f64, c: f64, theta: f64) -> bool {
    if !(theta > 1e-3 && theta < 1.0 - 1e-3) {
        return true;
    }
    let sign = if a < 0.0 { -1.0 } else { 1.0 };
    let (a, b, c) = (sign * a, sign * b, sign * c);
    let d = theta - theta * theta;
    let big_a = theta * (b - a) - (c - a);
    let big_b = (b - a) * d - big_a;
    // alpha > 0 and the vertex -B / (2 A) inside (0, 1)
    if !(big_a > 0.0 && -big_b > 0.0 && -big_b < 2.0 * big_a) {
        return true;
    }
    let scale = a.max(b).max(c);
    let near = theta.min(1.0 - theta);
    let (q, b2) = (4.0 * big_a * d, big_b * big_b);
    if a.min(b).min(c) * near <= FIT_NOISE * scale {
        // p(v) > -m  <=>  (a near + noise scale) 4 A d > B^2 near
        (a * near + FIT_NOISE * scale) * q > b2 * near
    } else {
        // p(v) > tol scale  <=>  (a - tol scale) 4 A d > B^2
        (a - VANISH_TOLERANCE * scale) * q > b2
    }
}

#[cfg(test)]
mod tests {
    use super::{FIT_NOISE, VANISH_TOLERANCE, clear_of_zero};

    /// The rule with the fit's divisions, as written before they were multiplied through.
    fn with_divisions(a: f64, b: f64, c: f64, theta: f64) -> bool {
        if !(theta > 1e-3 && theta < 1.0 - 1e-3) {
            return true;
        }
        let sign = if a < 0.0 { -1.0 } else { 1.0 };
        let (a, b, c) = (sign * a, sign * b, sign * c);
        let scale = a.max(b).max(c);
        let margin = FIT_NOISE * scale / theta.min(1.0 - theta);
        let alpha = ((c - a) - theta * (b - a)) / (theta * theta - theta);
        let beta = (b - a) - alpha;
        let vertex = -beta / (2.0 * alpha);
        if !(alpha > 0.0 && vertex > 0.0 && vertex < 1.0) {
            return true;
        }
        let minimum = a + 0.5 * beta * vertex;
        if a.min(b).min(c) <= margin {
            minimum > -margin
        } else {
            minimum > VANISH_TOLERANCE * scale
        }
    }

    /// The quadratic s(t) = (t - t0)^2 - e sampled at 0, theta, 1: a dip to -e at t0.
    fn samples(t0: f64, e: f64, theta: f64) -> (f64, f64, f64) {
        let s = |t: f64| (t - t0) * (t - t0) - e;
        (s(0.0), s(1.0), s(theta))
    }

    #[test]
    fn a_dip_through_zero_between_the_samples_is_caught() {
        // minimum -1e-3 at t0 = 0.8, the samples at 0, 1/2, 1 all positive
        let (a, b, c) = samples(0.8, 1e-3, 0.5);
        assert!(a > 0.0 && b > 0.0 && c > 0.0);
        assert!(!clear_of_zero(a, b, c, 0.5));
        assert!(!clear_of_zero(-a, -b, -c, 0.5), "mirrored");
        // the same parabola lifted clear of zero passes
        let (a, b, c) = samples(0.8, -1e-3, 0.5);
        assert!(clear_of_zero(a, b, c, 0.5));
        // a vertex outside the step is not a dip inside it
        let (a, b, c) = samples(1.3, 1e-3, 0.5);
        assert!(clear_of_zero(a, b, c, 0.5));
        // near an end of theta only the sign rule applies
        assert!(clear_of_zero(a, b, c, 1e-4));
    }

    #[test]
    fn the_rule_is_the_fit_with_divisions() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut disagree, mut rejected) = (0, 0);
        for _ in 0..200_000 {
            let theta = 0.01 + 0.98 * next();
            let t0 = -0.5 + 2.0 * next();
            let e = (next() - 0.5) * 10f64.powf(-12.0 * next());
            let scale = 10f64.powf(8.0 * next() - 4.0);
            let (a, b, c) = samples(t0, e, theta);
            let (a, b, c) = (a * scale, b * scale, c * scale);
            if !(a > 0.0 && b > 0.0 && c > 0.0) {
                continue;
            }
            let fast = clear_of_zero(a, b, c, theta);
            rejected += usize::from(!fast);
            disagree += usize::from(fast != with_divisions(a, b, c, theta));
        }
        // the two differ only where the minimum is within rounding of a threshold
        assert!(rejected > 1000, "{rejected}");
        assert!(disagree <= 20, "{disagree} disagreements");
    }

    #[test]
    fn nan_samples_are_left_to_the_sign_rule() {
        assert!(clear_of_zero(f64::NAN, 1.0, 1.0, 0.5));
        assert!(clear_of_zero(1.0, f64::NAN, 1.0, 0.5));
        assert!(clear_of_zero(1.0, 1.0, f64::NAN, 0.5));
    }
}
