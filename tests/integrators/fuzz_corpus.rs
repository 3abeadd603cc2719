//! A fixed sample of the grammar fuzzer's Lagrangians
//! (`retract-codegen/tests/expansion/grammar_fuzz.rs`, fixed seed, smooth mode: every singular
//! operation with an argument bounded away from its singular set), compiled through the
//! macro, with the generated gradient and Hessian checked against fourth-order central
//! finite differences at 8 points each. The section between the markers is written by the
//! fuzzer (`RETRACT_BLESS_CORPUS=1 cargo test -p retract-codegen --test expansion`), which
//! also fails when it differs from what the generator makes.

#![allow(unused_variables, unused_mut, clippy::all)]

use crate::common::{fd, grad_entry, hess_entry, shifted};
use retract::nalgebra::SVector;
use retract::{Lagrangian, higher_order_lagrangian};

/// Gradient and Hessian of `l` at 8 points of [-1, 1]^(N (K + 1)) against finite
/// differences (relative tolerance 1e-7 of the largest entry).
fn check<L: Lagrangian<N, K>, const N: usize, const K: usize>(name: &str, l: &L) {
    let mut state = 0x2545_f491_4f6c_dd1d_u64 ^ name.len() as u64;
    let mut uniform = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        2.0 * ((state >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    };
    let m = N * (K + 1);
    let eps = 1e-3;
    for _ in 0..8 {
        let x: [SVector<f64, N>; K] = core::array::from_fn(|_| SVector::from_fn(|_, _| uniform()));
        let u = SVector::<f64, N>::from_fn(|_, _| uniform());
        assert!(l.lagrangian(&x, &u).is_finite(), "{name}: L not finite");
        let g = l.gradient(&x, &u);
        let h = l.hessian(&x, &u);
        let g_scale = (0..m).map(|c| grad_entry(&g, c).abs()).fold(1.0, f64::max);
        let h_scale = (0..m * m)
            .map(|e| hess_entry(&h, e / m, e % m).abs())
            .fold(1.0, f64::max);
        for c in 0..m {
            let want = fd(
                |t| {
                    let (x, u) = shifted(&x, &u, c, t);
                    l.lagrangian(&x, &u)
                },
                eps,
            );
            let got = grad_entry(&g, c);
            assert!(
                (got - want).abs() <= 1e-7 * g_scale,
                "{name}: dL/dv{c} = {got:e}, finite differences {want:e}"
            );
            for b in 0..m {
                let want = fd(
                    |t| {
                        let (x, u) = shifted(&x, &u, b, t);
                        grad_entry(&l.gradient(&x, &u), c)
                    },
                    eps,
                );
                let got = hess_entry(&h, c, b);
                assert!(
                    (got - want).abs() <= 1e-7 * h_scale,
                    "{name}: d2L/dv{c}dv{b} = {got:e}, finite differences {want:e}"
                );
            }
        }
    }
}

#[test]
fn compiled_fuzz_corpus_derivatives_match_finite_differences() {
    corpus::corpus_checks();
}

/// Generated, one line per Lagrangian as the fuzzer prints it (not formatted).
#[rustfmt::skip]
mod corpus {
use super::*;

// ---- BEGIN GENERATED (retract-codegen/tests/expansion/grammar_fuzz.rs) ----
#[higher_order_lagrangian(order = 2)]
fn fuzz_0(q: f64, dq: f64, ddq: f64, obs0: &[[f64; 1]], a1: f64, c2: [f64; 1]) -> f64 { const N_I: i32 = 2; const C_0: f64 = 1.25; let t0 = f64::hypot((2.0 + (f64::hypot(a1, 1.0 + (q).powi(2))).tanh()).recip(), 1.0 + ((2.0 + ((0.5 * (1.45).sin()).exp()).tanh()).recip()).powi(2)); let t1 = a1; let mut acc = 0.0; acc -= (2.0 + (C_0).tanh()).recip() - ((q).sin() * 1.37); acc -= -((0.5 * (c2[0]).sin()).exp()); for i in 0..4 { acc += q; } for o in obs0 { acc -= q + 1.41; } 0.5 * (ddq * ddq) + acc + (f64::hypot(t0, 1.0 + ((0.5 * (t0).sin()).exp()).powi(2))).atan2(2.0 + (f64::hypot((a1).sin() * 1.36, 1.0 + ((1.0 + 0.5 * (q).sin()).abs() * (c2[0])).powi(2))).cos()) }

#[higher_order_lagrangian(order = 2)]
fn fuzz_1(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], obs0: &[[f64; 2]]) -> f64 { let t0 = 0.78 - ((1.0 + ((q[0]).sin() * 0.51).powi(2)).sqrt()); let t1 = ((1.0 + (q[1]).powi(2)).sqrt()).sin() * 0.98 - (1.11); let t2 = (0.5 * ((q[1]).powi(3) + 1.22).sin()).exp(); let mut acc = 0.0; acc -= -((0.5 * (0.90).sin()).exp()); acc *= -(1.67) + q[0]; for i in 0..1 { acc += (1.0 + 0.5 * (dq[0]).sin()).abs() * (dq[0]); } for o in obs0 { acc += f64::hypot(q[1], 1.0 + (1.71).powi(2)); } 0.5 * (0.59 * ddq[0].powi(2) + 1.54 * ddq[1].powi(2)) + acc + (1.0 + ((1.0 + (1.48).powi(2)).sqrt() + q[0]) * ((1.0 + (1.48).powi(2)).sqrt() + q[0])).powf(0.67) }

#[higher_order_lagrangian(order = 1)]
fn fuzz_2(q: [f64; 1], dq: [f64; 1], a0: f64, obs1: &[[f64; 1]], obs2: &[[f64; 3]]) -> f64 { let t0 = q[0]; let mut acc = 0.0; acc -= (0.5 * (a0).tanh()).tan() + ((1.0 + (1.83) * (1.83)).powf(1.00)).cos(); for i in 0..3 { acc += (1.90).sin() * 0.74; } for o in obs1 { acc += t0 - (0.67); } 0.5 * (1.90 * dq[0].powi(2)) + acc + ((2.0 + (q[0]).tanh()).recip()).powi(2) }

#[higher_order_lagrangian(order = 1)]
fn fuzz_3(q: f64, dq: f64, obs0: &[[f64; 3]], c1: [f64; 2]) -> f64 { let t0 = 0.04; let t1 = (q - (1.86) - ((0.88) * (1.22))) * (((1.89) * (q)) * ((1.0 + (0.54).powi(2)).sqrt())); let t2 = 1.49; let mut acc = 0.0; acc *= q; for o in obs0 { acc += (1.0 + (c1[1]) * (c1[1])).powf(1.35); } 0.5 * (dq * dq) + acc + (0.5 * ((1.0 + (q) * (q)).powf(1.26)).sin()).exp() }

#[higher_order_lagrangian(order = 1)]
fn fuzz_4(q: f64, dq: f64, obs0: &[[f64; 1]]) -> f64 { let t0 = (0.5 * (f64::hypot(q, 1.0 + ((1.0 + (0.16) * (0.16)).powf(1.44)).powi(2))).sin()).exp(); let t1 = ((2.0 + ((0.50) / (1.5 + (q).cos())).tanh()).recip()) / (1.5 + (t0).cos()); let t2 = (1.0 + 0.5 * ((0.93) / (1.5 + (f64::hypot(q, 1.0 + (q).powi(2))).cos())).sin()).abs() * ((q).powi(2)); let mut acc = 0.0; acc *= ((0.5 * (0.76).sin()).exp()) * (f64::hypot(t0, 1.0 + (1.11).powi(2))); acc += f64::ln(2.0 + (q).sin()); acc += (0.5 * (q).tanh()).tan() + (-(t2)).cos(); for i in 0..1 { acc += (1.78).atan2(2.0 + (q).cos()); } for o in obs0 { acc -= 0.25; } 0.5 * (dq * dq) + acc + (-(1.16)) * ((0.5 * (-(0.57)).tanh()).tan() + (-(t0)).cos()) }

#[higher_order_lagrangian(order = 1)]
fn fuzz_5(q: [f64; 1], dq: [f64; 1]) -> f64 { let t0 = (1.74).sin() * 0.60; let t1 = (1.0 + (0.55) * (0.55)).powf(1.35); let mut acc = 0.0; acc -= (2.0 + ((0.71) / (1.5 + (0.36).cos())).tanh()).recip(); acc += ((1.0 + 0.5 * (t0).sin()).abs() * (1.04)).atan2(2.0 + ((1.0 + (1.90) * (1.90)).powf(0.67)).cos()); acc *= -(q[0]) + (1.0 + (1.05) * (1.05)).powf(0.78); 0.5 * (0.93 * dq[0].powi(2)) + acc + (1.0 + 0.5 * ((q[0]).sin() * 1.33 - (1.12 + q[0])).sin()).abs() * (1.18) }

#[higher_order_lagrangian(order = 2)]
fn fuzz_6(q: f64, dq: f64, ddq: f64, obs0: &[[f64; 1]], a1: f64) -> f64 { const N_I: i32 = 2; const C_0: f64 = 1.25; let t0 = (2.0 + (1.69).tanh()).recip() - ((2.0 + (q).tanh()).recip()) - ((2.0 + ((q) * (1.23)).tanh()).recip()); let t1 = (1.0 + (f64::hypot(dq, 1.0 + ((0.56) / (1.5 + (1.30).cos())).powi(2))).powi(2)).sqrt(); let t2 = ((0.5 * (a1).tanh()).tan() + ((1.0 + 0.5 * (dq).sin()).abs() * (1.09)).cos()) * (((a1).atan2(2.0 + (t1).cos())) / (1.5 + (0.27).cos())); let mut acc = 0.0; acc -= ((a1) * (q)) * (q); acc += t2; for o in obs0 { acc -= 0.65; } 0.5 * (ddq * ddq) + acc + dq }

#[higher_order_lagrangian(order = 1)]
fn fuzz_7(q: f64, dq: f64) -> f64 { let t0 = 1.61; let mut acc = 0.0; for i in 0..1 { acc += (1.0 + (q) * (q)).powf(0.79); } 0.5 * (dq * dq) + acc + (2.0 + (f64::hypot(t0, 1.0 + (q).powi(2)) - ((0.81).sin() * 1.29)).tanh()).recip() }

#[higher_order_lagrangian(order = 2)]
fn fuzz_8(q: f64, dq: f64, ddq: f64, c0: [f64; 3]) -> f64 { let t0 = ((0.33) / (1.5 + (c0[0] + q).cos())).powi(3); let t1 = c0[2] - ((1.0 + 0.5 * (q).sin()).abs() * ((1.20) / (1.5 + (q).cos()))); let t2 = (0.5 * ((2.0 + (t0).tanh()).recip() + f64::hypot(1.84, 1.0 + (0.32).powi(2))).tanh()).tan() + (0.45).cos(); let mut acc = 0.0; acc += q; acc *= dq; acc += (0.5 * (q).tanh()).tan() + ((1.0 + (q) * (q)).powf(1.16)).cos(); 0.5 * (ddq * ddq) + acc + (0.5 * (dq).tanh()).tan() + (((1.0 + (q).powi(2)).sqrt()).atan2(2.0 + ((1.0 + (q).powi(2)).sqrt()).cos())).cos() }

#[higher_order_lagrangian(order = 2)]
fn fuzz_9(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1]) -> f64 { let t0 = ((1.0 + 0.5 * (dq[0]).sin()).abs() * ((q[0]).powi(1))).atan2(2.0 + (1.42 + 1.51 - (q[0] - (0.69))).cos()); let t1 = 0.04; let mut acc = 0.0; acc *= (0.5 * (f64::ln(2.0 + (0.71).sin())).sin()).exp(); acc *= 1.98; 0.5 * (1.22 * ddq[0].powi(2)) + acc + 1.91 }

#[higher_order_lagrangian(order = 2)]
fn fuzz_10(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 { let t0 = -((0.5 * ((0.5 * (q[1]).sin()).exp()).sin()).exp()); let mut acc = 0.0; for i in 0..3 { acc += (dq[0]).sin() * 0.54; } 0.5 * (0.77 * ddq[0].powi(2) + 0.53 * ddq[1].powi(2)) + acc + f64::hypot((1.0 + (q[0]).powi(2)).sqrt(), 1.0 + (1.81 + 0.98).powi(2)) - (f64::hypot(-(0.25), 1.0 + ((1.0 + (dq[0]).powi(2)).sqrt()).powi(2))) }

#[higher_order_lagrangian(order = 2)]
fn fuzz_11(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1]) -> f64 { let t0 = (f64::ln(2.0 + (1.68).sin())).atan2(2.0 + ((2.0 + (0.02).tanh()).recip()).cos()) + (1.0 + ((1.0 + (0.10) * (0.10)).powf(0.99)) * ((1.0 + (0.10) * (0.10)).powf(0.99))).powf(0.32); let t1 = (2.0 + ((0.5 * (1.02).sin()).exp() + (1.0 + (1.78).powi(2)).sqrt()).tanh()).recip(); let mut acc = 0.0; acc -= -((0.5 * (dq[0]).sin()).exp()); for i in 0..1 { acc += (1.0 + (1.25) * (1.25)).powf(0.44); } 0.5 * (0.68 * ddq[0].powi(2)) + acc + (2.0 + (q[0]).tanh()).recip() }

#[higher_order_lagrangian(order = 1)]
fn fuzz_12(q: [f64; 2], dq: [f64; 2], obs0: &[[f64; 3]]) -> f64 { let t0 = q[1]; let t1 = (0.61).powi(2); let t2 = ((1.0 + (0.49).powi(2)).sqrt()).atan2(2.0 + ((0.41) / (1.5 + (f64::ln(2.0 + (0.47).sin())).cos())).cos()); let mut acc = 0.0; acc *= (q[0]) / (1.5 + (1.26).cos()); for i in 0..1 { acc += f64::hypot(t1, 1.0 + (q[1]).powi(2)); } for o in obs0 { acc += f64::ln(2.0 + (0.81).sin()); } 0.5 * (1.92 * dq[0].powi(2) + 0.90 * dq[1].powi(2)) + acc + (1.60) / (1.5 + (q[1]).cos()) }

#[higher_order_lagrangian(order = 2)]
fn fuzz_13(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], a0: f64) -> f64 { const N_I: i32 = 2; const C_0: f64 = 1.25; let t0 = (1.0 + (((dq[0]).sin() * 0.92) * (f64::hypot(dq[0], 1.0 + (0.99).powi(2)))) * (((dq[0]).sin() * 0.92) * (f64::hypot(dq[0], 1.0 + (0.99).powi(2))))).powf(1.29); let t1 = (2.0 + ((1.0 + ((q[1]) / (1.5 + (a0).cos())) * ((q[1]) / (1.5 + (a0).cos()))).powf(0.35)).tanh()).recip(); let t2 = (1.0 + ((dq[1] + 0.30).powi(3)) * ((dq[1] + 0.30).powi(3))).powf(1.44); let mut acc = 0.0; acc *= (1.0 + (f64::ln(2.0 + (dq[0]).sin())).powi(2)).sqrt(); for i in 0..2 { acc += f64::hypot(t0, 1.0 + (t2).powi(2)); } 0.5 * (1.71 * ddq[0].powi(2) + 1.25 * ddq[1].powi(2)) + acc + (q[1]).powi(1) + (1.0 + ((dq[0]) / (1.5 + (dq[0]).cos())) * ((dq[0]) / (1.5 + (dq[0]).cos()))).powf(0.61) }

#[higher_order_lagrangian(order = 2)]
fn fuzz_14(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1], a0: f64, c1: [f64; 1]) -> f64 { const N_I: i32 = 2; const C_0: f64 = 1.25; let t0 = (1.0 + 0.5 * (q[0]).sin()).abs() * (((q[0]) / (1.5 + (a0).cos())) * (0.22)); let t1 = 0.90; let t2 = ((C_0) * ((dq[0]).sin() * 0.88)).atan2(2.0 + ((dq[0]).sin() * 0.44).cos()); let mut acc = 0.0; for i in 0..4 { acc += f64::ln(2.0 + (q[0]).sin()); } 0.5 * (1.67 * ddq[0].powi(2)) + acc + (0.5 * ((1.0 + ((c1[0]).sin() * 1.14).powi(2)).sqrt()).tanh()).tan() + (((1.0 + (C_0).powi(2)).sqrt()).atan2(2.0 + (C_0).cos())).cos() }

#[higher_order_lagrangian(order = 2)]
fn fuzz_15(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> f64 { let t0 = (0.05) / (1.5 + (f64::hypot((1.0 + (q[1]) * (q[1])).powf(1.45), 1.0 + ((0.40).atan2(2.0 + (0.40).cos())).powi(2))).cos()); let t1 = ((dq[1]).sin() * 0.93).atan2(2.0 + ((t0).sin() * 1.00).cos()) + (0.5 * (dq[1]).tanh()).tan() + (0.16).cos(); let t2 = (dq[1]) / (1.5 + (f64::hypot((0.5 * (0.74).sin()).exp(), 1.0 + ((1.0 + (dq[0]).powi(2)).sqrt()).powi(2))).cos()); let mut acc = 0.0; acc += f64::ln(2.0 + (0.88).sin()); acc *= (q[1] + 0.94) * (1.92); acc += ((1.0 + 0.5 * (1.40).sin()).abs() * (q[0])).powi(2); 0.5 * (0.95 * ddq[0].powi(2) + 1.23 * ddq[1].powi(2)) + acc + f64::ln(2.0 + ((2.0 + ((1.0 + (0.27) * (0.27)).powf(1.27)).tanh()).recip()).sin()) }

#[higher_order_lagrangian(order = 1)]
fn fuzz_16(q: [f64; 1], dq: [f64; 1], a0: f64, a1: f64) -> f64 { let mut acc = 0.0; acc *= q[0]; acc -= ((q[0]) * (1.37)) / (1.5 + ((0.74) * (1.18)).cos()); for i in 0..1 { acc += (a0) * (1.97); } 0.5 * (1.63 * dq[0].powi(2)) + acc + (0.5 * ((1.0 + (q[0]) * (q[0])).powf(0.34)).tanh()).tan() + ((2.0 + (0.74).tanh()).recip()).cos() }

#[higher_order_lagrangian(order = 2)]
fn fuzz_17(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1], a0: f64) -> f64 { const N_I: i32 = 2; const C_0: f64 = 1.25; let t0 = (1.0 + 0.5 * (q[0]).sin()).abs() * ((1.0 + 0.5 * (dq[0] - (dq[0])).sin()).abs() * ((0.95) * (C_0))); let t1 = dq[0]; let t2 = (0.5 * (q[0]).tanh()).tan() + (q[0] - (dq[0])).cos(); let mut acc = 0.0; 0.5 * (0.70 * ddq[0].powi(2)) + acc + f64::ln(2.0 + ((C_0 + q[0]).atan2(2.0 + (1.63).cos())).sin()) }

#[higher_order_lagrangian(order = 1)]
fn fuzz_18(q: [f64; 1], dq: [f64; 1], obs0: &[[f64; 3]], obs1: &[[f64; 1]], obs2: &[[f64; 2]]) -> f64 { let t0 = (1.0 + (q[0]) * (q[0])).powf(1.33); let t1 = 0.85; let t2 = q[0]; let mut acc = 0.0; acc *= -((q[0]) * (q[0])); for i in 0..4 { acc += (q[0]) * (t1); } for o in obs0 { acc += (0.5 * (q[0]).sin()).exp(); } 0.5 * (0.58 * dq[0].powi(2)) + acc + q[0] }

#[higher_order_lagrangian(order = 1)]
fn fuzz_19(q: [f64; 1], dq: [f64; 1], a0: f64, a1: f64) -> f64 { let mut acc = 0.0; acc += q[0]; 0.5 * (1.92 * dq[0].powi(2)) + acc + (0.5 * (0.42).sin()).exp() }

pub fn corpus_checks() {
    check::<_, 1, 2>("fuzz_0", &Fuzz0 { obs0: &[[-0.87], [0.99]], a1: 0.42, c2: [0.44] });
    check::<_, 2, 2>("fuzz_1", &Fuzz1 { obs0: &[[-0.14, -0.99], [0.24, 0.66]] });
    check::<_, 1, 1>("fuzz_2", &Fuzz2 { a0: 0.46, obs1: &[[0.29], [-0.31]], obs2: &[[0.84, 0.48, 0.76], [0.98, 0.99, 0.48]] });
    check::<_, 1, 1>("fuzz_3", &Fuzz3 { obs0: &[[-0.66, 0.41, -0.77], [0.13, 0.98, 0.59]], c1: [-0.48, -0.65] });
    check::<_, 1, 1>("fuzz_4", &Fuzz4 { obs0: &[[-0.86], [-0.07]] });
    check::<_, 1, 1>("fuzz_5", &Fuzz5 {  });
    check::<_, 1, 2>("fuzz_6", &Fuzz6 { obs0: &[[-0.78], [-0.92]], a1: 0.57 });
    check::<_, 1, 1>("fuzz_7", &Fuzz7 {  });
    check::<_, 1, 2>("fuzz_8", &Fuzz8 { c0: [-0.82, 0.38, -0.39] });
    check::<_, 1, 2>("fuzz_9", &Fuzz9 {  });
    check::<_, 2, 2>("fuzz_10", &Fuzz10 {  });
    check::<_, 1, 2>("fuzz_11", &Fuzz11 {  });
    check::<_, 2, 1>("fuzz_12", &Fuzz12 { obs0: &[[-0.78, -0.91, -0.02], [0.12, 0.66, 0.72]] });
    check::<_, 2, 2>("fuzz_13", &Fuzz13 { a0: 0.82 });
    check::<_, 1, 2>("fuzz_14", &Fuzz14 { a0: 0.76, c1: [-0.77] });
    check::<_, 2, 2>("fuzz_15", &Fuzz15 {  });
    check::<_, 1, 1>("fuzz_16", &Fuzz16 { a0: 0.78, a1: 0.46 });
    check::<_, 1, 2>("fuzz_17", &Fuzz17 { a0: 0.76 });
    check::<_, 1, 1>("fuzz_18", &Fuzz18 { obs0: &[[0.30, -0.28, -0.57], [-0.14, 0.66, 0.64]], obs1: &[[-0.36], [-0.41]], obs2: &[[0.74, 0.40], [0.49, 0.88]] });
    check::<_, 1, 1>("fuzz_19", &Fuzz19 { a0: 0.93, a1: 0.53 });
}
// ---- END GENERATED ----
}
