//! The macro on hostile but valid inputs: they compile to code that computes what the
//! annotated function computes, with the right derivatives. (Inputs that must be rejected are
//! in `ui/tests/ui/fail/signature/function_name_that_makes_no_type_name.rs` and
//! `ui/tests/ui/fail/expressions/loop_too_long_at_the_i64_limits.rs`; the expansion
//! itself is tested in `retract-codegen/tests/expansion/extreme_inputs.rs`.)

use retract::Lagrangian;
use retract::higher_order_lagrangian;
use retract::nalgebra::SVector;

// ---- function names that camel-case to no type name, with `name = ...` ----------

#[higher_order_lagrangian(order = 1, name = Arm2d)]
fn _2d_arm(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq - q.cos()
}

#[higher_order_lagrangian(order = 1, name = SelfLike)]
fn self_(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + q
}

#[test]
fn a_function_name_that_makes_no_type_name_compiles_with_an_explicit_name() {
    let (x, u) = ([SVector::from([0.3])], SVector::from([0.5]));
    assert_eq!(Arm2d {}.lagrangian(&x, &u), _2d_arm(0.3, 0.5));
    assert_eq!(SelfLike {}.lagrangian(&x, &u), self_(0.3, 0.5));
}

// ---- integers at the ends of i32 and i64 ----------------------------------------

#[higher_order_lagrangian(order = 1)]
fn extreme_exponent(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + q.powi(-2147483648)
}

#[higher_order_lagrangian(order = 1)]
#[allow(clippy::reversed_empty_ranges)]
fn extreme_loops(q: f64, dq: f64) -> f64 {
    let mut l = 0.5 * dq * dq;
    // three iterations just below i64::MAX, two from i64::MIN
    for _i in 9223372036854775805i64..=9223372036854775807i64 {
        l += q;
    }
    for _i in -9223372036854775808i64..-9223372036854775806i64 {
        l += 10.0 * q;
    }
    l
}

#[test]
fn extreme_exponents_and_loop_bounds_give_exact_values_and_derivatives() {
    let n = i32::MIN;
    let sys = ExtremeExponent {};
    for q in [1.0_f64, -1.0, 1.0 + 1e-9, -1.0 + 1e-9, 0.999_999_9] {
        let (x, u) = ([SVector::from([q])], SVector::from([0.25]));
        let want = f64::from(n) * q.powi(n) / q; // n q^(n-1)
        let got = sys.gradient(&x, &u).x[0][0];
        assert!(
            (got - want).abs() <= 1e-12 * want.abs(),
            "q = {q}: {got:e} != {want:e}"
        );
        assert_eq!(sys.lagrangian(&x, &u), extreme_exponent(q, 0.25));
        // the second derivative n (n - 1) q^(n - 2) = (n - 1) * dL/dq / q
        let want = (f64::from(n) - 1.0) * want / q;
        let got = sys.hessian(&x, &u).xx[0][0][(0, 0)];
        assert!(
            (got - want).abs() <= 1e-12 * want.abs(),
            "q = {q}: {got:e} != {want:e}"
        );
    }
    let sys = ExtremeLoops {};
    let (x, u) = ([SVector::from([0.7])], SVector::from([0.2]));
    assert_eq!(sys.lagrangian(&x, &u), extreme_loops(0.7, 0.2));
    assert_eq!(sys.gradient(&x, &u).x[0][0], 23.0);
}

// ---- indices above u16::MAX ------------------------------------------------------

#[higher_order_lagrangian(order = 1)]
fn long_parameters(q: f64, dq: f64, c: [f64; 70000], obs: &[[f64; 70000]]) -> f64 {
    let mut l = 0.5 * dq * dq + c[69999] * q + c[65536] * q * q;
    for o in obs {
        l += o[69999] * q.sin();
    }
    l
}

#[test]
fn indices_above_u16_read_the_right_entries() {
    // values at the indices read, and large ones where truncated or wrapped indices land
    let fill = |c: &mut [f64; 70000]| {
        c[69999] = 2.0;
        c[65536] = 3.0;
        c[65535] = 100.0; // the index truncated to u16::MAX
        c[0] = 1000.0; // 65 536 mod 65 536
        c[4463] = 1000.0; // 69 999 mod 65 536
    };
    let mut obs = vec![[0.0; 70000]; 2];
    obs.iter_mut().for_each(fill);
    let mut sys = Box::new(LongParameters {
        c: [0.0; 70000],
        obs: &obs,
    });
    fill(&mut sys.c);
    let (q, dq): (f64, f64) = (0.4, 0.3);
    let (x, u) = ([SVector::from([q])], SVector::from([dq]));
    // dL/dq = c[69999] + 2 c[65536] q + sum over obs of o[69999] cos q
    let want = 2.0 + 2.0 * 3.0 * q + 2.0 * 2.0 * q.cos();
    let got = sys.gradient(&x, &u).x[0][0];
    assert!((got - want).abs() < 1e-12, "{got} != {want}");
    let direct = long_parameters(q, dq, sys.c, &obs);
    assert!((sys.lagrangian(&x, &u) - direct).abs() < 1e-12);
}

// ---- constants that are NaN or infinite at compile time -------------------------

#[higher_order_lagrangian(order = 1)]
#[allow(clippy::zero_divided_by_zero, clippy::eq_op)]
fn nan_constant(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + (0.0 / 0.0) * q
}

#[higher_order_lagrangian(order = 1)]
#[allow(clippy::eq_op)]
fn infinite_difference(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + (1e308 * 10.0 - 1e308 * 10.0) + q
}

#[higher_order_lagrangian(order = 1)]
fn negative_zero(q: f64, dq: f64) -> f64 {
    0.5 * dq * dq + (1.0 / -0.0) * q.exp()
}

#[test]
fn non_finite_constants_evaluate_as_the_function_does() {
    let (q, dq) = (0.5, 0.25);
    let (x, u) = ([SVector::from([q])], SVector::from([dq]));
    let value = NanConstant {}.lagrangian(&x, &u);
    assert!(value.is_nan() && nan_constant(q, dq).is_nan(), "{value}");
    assert!(NanConstant {}.gradient(&x, &u).x[0][0].is_nan());
    let value = InfiniteDifference {}.lagrangian(&x, &u);
    assert!(
        value.is_nan() && infinite_difference(q, dq).is_nan(),
        "{value}"
    );
    let value = NegativeZero {}.lagrangian(&x, &u);
    assert_eq!(value, negative_zero(q, dq));
    assert_eq!(value, f64::NEG_INFINITY);
}
