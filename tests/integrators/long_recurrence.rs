//! A recurrence unrolled 1000 times (or as many chained `let`s) made the
//! macro emit one expression nested about 4000 parentheses deep, on which rustc overflowed its
//! stack (SIGSEGV). The emitted nesting is bounded now: this file compiles, and the code it
//! generates computes the function and its gradient.

use retract::Lagrangian;
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;

/// x <- 0.999 x + 0.001 sin q, 1000 times from x = q.
#[higher_order_lagrangian(order = 1)]
fn recurrence(q: f64, dq: f64) -> f64 {
    let mut x = q;
    for _ in 0..1000 {
        x = x * 0.999 + 0.001 * q.sin();
    }
    0.5 * dq * dq - x * x
}

#[test]
fn a_long_recurrence_compiles_and_differentiates() {
    let sys = Recurrence {};
    for &(q, dq) in &[(0.3, 0.2), (-1.1, 0.7), (2.0, -0.4)] {
        let (x, u) = ([SVector::from([q])], SVector::from([dq]));
        let direct = recurrence(q, dq);
        assert!((sys.lagrangian(&x, &u) - direct).abs() < 1e-12 * direct.abs().max(1.0));
        // closed form: x = a^m q + (1 - a^m) sin q, a = 0.999, m = 1000
        let a = 0.999f64.powi(1000);
        let value = a * q + (1.0 - a) * q.sin();
        let want = -2.0 * value * (a + (1.0 - a) * q.cos());
        let got = sys.gradient(&x, &u).x[0][0];
        assert!((got - want).abs() < 1e-10, "{got} != {want}");
    }
}
