//! Coefficients of splitting methods for $H = H_0 + H_V$ (the free flow $e^{tA}$ of $H_0$ and
//! the kick $K_t$ of $H_V$, [`crate::scheme::split`]):
//!
//! $$\Psi_h = e^{a_{s+1} h A} \circ K_{b_s h} \circ e^{a_s h A} \circ \dots \circ
//!   K_{b_1 h} \circ e^{a_1 h A}, \qquad \sum_i a_i = \sum_i b_i = 1,$$
//!
//! symplectic for any coefficients and symmetric when both lists are palindromes. A
//! composition of Strang steps $\gamma_s, \dots, \gamma_1$ is the case $b_i = \gamma_i$,
//! $a_1 = \gamma_1/2$, $a_i = (\gamma_{i-1} + \gamma_i)/2$, $a_{s+1} = \gamma_s/2$: adjacent
//! half free flows fused into one, since $e^{sA} e^{tA} = e^{(s+t)A}$.
//!
//! # Why Runge-Kutta-Nyström methods apply
//! With $B = H_V = -V(x_0)$, a function of $x_0$ alone, $\lbrace B, H_0\rbrace = -\nabla V \cdot x_1$ is a
//! function of $x$ alone, so $\lbrace B, \lbrace B, H_0\rbrace\rbrace = 0$: a stronger identity than the
//! $\lbrace B, \lbrace B, \lbrace B, H_0\rbrace\rbrace\rbrace = 0$ of $H = \tfrac12 |p|^2 + V(q)$ that Runge-Kutta-Nyström (RKN)
//! splitting methods assume (kicks as their $B$, free flows as their $A$). Every order
//! condition such a method drops is therefore also void here, and it reaches its order
//! (`tests/integrators/splitting_methods.rs` measures it by step refinement).
//!
//! # References
//! - S. Blanes, P. C. Moan, "Practical symplectic partitioned Runge-Kutta and
//!   Runge-Kutta-Nyström methods", J. Comput. Appl. Math. 142 (2002) 313-330, Table 3:
//!   SRKN$_6^b$ (order 4), SRKN$_{11}^b$ and SRKN$_{14}^a$ (order 6). The digits are the
//!   paper's as transcribed in Principia's `integrators/methods.hpp`
//!   (github.com/mockingbirdnest/Principia); the last coefficient of each half is computed
//!   from $\sum a_i = \sum b_i = 1$, as in the paper.
//! - W. Kahan, R.-C. Li (1997) and H. Yoshida (1990) for the compositions
//!   ([`crate::scheme::compose`]).

use crate::Error;
use crate::scheme::compose::{self, MAX_STAGES};

/// Most kicks of a supported method (the order-8 triple jump's 27 Strang steps).
pub const MAX_KICKS: usize = MAX_STAGES;

/// A splitting method: the free-flow fractions $a_1, \dots, a_{s+1}$ and the kick fractions
/// $b_1, \dots, b_s$ of the module docs, with the order it reaches on $H_0 + H_V$.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplittingMethod {
    flows: [f64; MAX_KICKS + 1],
    kicks: [f64; MAX_KICKS],
    len: usize,
    order: u32,
}

/// Blanes-Moan SRKN$_6^b$, kick-first: $b_1, b_2, b_3$ ($b_4 = 1 - 2(b_1 + b_2 + b_3)$) and
/// $a_1, a_2$ ($a_3 = 1/2 - a_1 - a_2$).
#[allow(clippy::excessive_precision)]
const BM_SRKN6B: ([f64; 3], [f64; 2]) = (
    [
        0.082_984_406_417_405_2,
        0.396_309_801_498_368,
        -0.039_056_304_922_348_6,
    ],
    [0.245_298_957_184_271, 0.604_872_665_711_080],
);

/// Blanes-Moan SRKN$_{11}^b$, kick-first: $b_1, \dots, b_5$ ($b_6 = 1/2 - \sum$) and
/// $a_1, \dots, a_5$ ($a_6 = 1 - 2 \sum$).
#[allow(clippy::excessive_precision)]
const BM_SRKN11B: ([f64; 5], [f64; 5]) = (
    [
        0.041_464_998_518_262_4,
        0.198_128_671_918_067,
        -0.040_006_192_104_153_3,
        0.075_253_984_301_580_7,
        -0.011_511_387_420_687_9,
    ],
    [
        0.123_229_775_946_271,
        0.290_553_797_799_558,
        -0.127_049_212_625_417,
        -0.246_331_761_062_075,
        0.357_208_872_795_928,
    ],
);

/// Blanes-Moan SRKN$_{14}^a$, flow-first: $a_1, \dots, a_7$ ($a_8 = 1 - 2\sum$) and
/// $b_1, \dots, b_6$ ($b_7 = 1/2 - \sum$).
#[allow(clippy::excessive_precision)]
const BM_SRKN14A: ([f64; 7], [f64; 6]) = (
    [
        0.037_859_319_840_611_6,
        0.102_635_633_102_435,
        -0.025_867_888_266_558_7,
        0.314_241_403_071_447,
        -0.130_144_459_517_415,
        0.106_417_700_369_543,
        -0.008_794_243_128_510_58,
    ],
    [
        0.091_719_152_624_461_65,
        0.183_983_170_005_006,
        -0.056_534_365_832_888_27,
        0.004_914_688_774_712_854,
        0.143_761_127_168_358,
        0.328_567_693_746_804,
    ],
);

/// The palindrome `half, centre, reversed half` into `out`; its length.
fn palindrome(half: &[f64], centre: Option<f64>, out: &mut [f64]) -> usize {
    let n = half.len();
    out[..n].copy_from_slice(half);
    let mut len = n;
    if let Some(c) = centre {
        out[len] = c;
        len += 1;
    }
    for (i, &v) in half.iter().rev().enumerate() {
        out[len + i] = v;
    }
    len + n
}

/// The centre that makes a palindrome with this `half` sum to 1.
fn centre(half: &[f64]) -> f64 {
    1.0 - 2.0 * half.iter().sum::<f64>()
}

impl SplittingMethod {
    /// The method from its flow fractions $a_1, \dots, a_{s+1}$ and kick fractions
    /// $b_1, \dots, b_s$, claimed to have `order`.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] unless `flows.len() == kicks.len() + 1`, $1 \le s \le$
    /// [`MAX_KICKS`], every fraction is finite and each list sums to 1 (to $10^{-12}$).
    pub fn new(flows: &[f64], kicks: &[f64], order: u32) -> Result<Self, Error> {
        let s = kicks.len();
        let sums = |v: &[f64]| (v.iter().sum::<f64>() - 1.0).abs() < 1e-12;
        let finite = flows.iter().chain(kicks).all(|v| v.is_finite());
        if s == 0 || s > MAX_KICKS || flows.len() != s + 1 || !finite {
            return Err(Error::InvalidArgument {
                name: "coefficients",
                requirement: "s kick fractions and s + 1 flow fractions, 1 <= s <= 27, finite",
            });
        }
        if !sums(flows) || !sums(kicks) {
            return Err(Error::InvalidArgument {
                name: "coefficients",
                requirement: "the flow fractions and the kick fractions each sum to 1",
            });
        }
        let mut method = Self {
            flows: [0.0; MAX_KICKS + 1],
            kicks: [0.0; MAX_KICKS],
            len: s,
            order,
        };
        method.flows[..=s].copy_from_slice(flows);
        method.kicks[..s].copy_from_slice(kicks);
        Ok(method)
    }

    /// The composition of Strang steps with fractions `gamma` (summing to 1) and the free
    /// flows between them fused (module docs); `order` is the composition's.
    ///
    /// # Errors
    /// As [`SplittingMethod::new`].
    pub fn from_composition(gamma: &[f64], order: u32) -> Result<Self, Error> {
        let s = gamma.len();
        let mut flows = [0.0; MAX_KICKS + 1];
        if s == 0 || s > MAX_KICKS {
            return Self::new(&[], gamma, order);
        }
        flows[0] = 0.5 * gamma[0];
        for i in 1..s {
            flows[i] = 0.5 * (gamma[i - 1] + gamma[i]);
        }
        flows[s] = 0.5 * gamma[s - 1];
        Self::new(&flows[..=s], gamma, order)
    }

    /// The cheapest composition of Strang's splitting of `order` (2, 4, 6 or 8) of
    /// [`compose::coefficients`], with fused free flows: the same map as
    /// `compose::compose(|z, h| split::split_step(..), ..)` to rounding, with one free flow
    /// per kick instead of two.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for another order.
    pub fn composition(order: u32) -> Result<Self, Error> {
        let (gamma, len) = compose::coefficients(order)?;
        Self::from_composition(&gamma[..len], order)
    }

    /// Blanes and Moan's SRKN$_6^b$: order 4 with 6 gradients per step (7 kicks, the last one
    /// at the next step's first point, which [`crate::scheme::split_stepper::SplitStepper`] reuses).
    pub fn blanes_moan_4() -> Self {
        let (b, a) = BM_SRKN6B;
        let a_centre = 0.5 - a.iter().sum::<f64>();
        Self::from_halves(&[a[0], a[1], a_centre], None, &b, Some(centre(&b)), true, 4)
    }

    /// Blanes and Moan's SRKN$_{11}^b$: order 6 with 11 gradients per step (12 kicks, the
    /// last at the next step's first point).
    pub fn blanes_moan_6() -> Self {
        let (b, a) = BM_SRKN11B;
        let b_centre = 0.5 - b.iter().sum::<f64>();
        let kicks = [b[0], b[1], b[2], b[3], b[4], b_centre];
        Self::from_halves(&a, Some(centre(&a)), &kicks, None, true, 6)
    }

    /// Blanes and Moan's SRKN$_{14}^a$: order 6 with 14 gradients per step, flow first; per
    /// gradient the most accurate of their order-6 methods.
    pub fn blanes_moan_6a() -> Self {
        let (a, b) = BM_SRKN14A;
        let b_centre = 0.5 - b.iter().sum::<f64>();
        let kicks = [b[0], b[1], b[2], b[3], b[4], b[5], b_centre];
        Self::from_halves(&a, Some(centre(&a)), &kicks, None, false, 6)
    }

    /// A symmetric method from the halves of its palindromes (and their centres); a
    /// `kick_first` method gets zero end flows ($a_1 = a_{s+1} = 0$). The built-in tables
    /// only: their lengths and sums are tested, not checked here.
    fn from_halves(
        flows_half: &[f64],
        flows_centre: Option<f64>,
        kicks_half: &[f64],
        kicks_centre: Option<f64>,
        kick_first: bool,
        order: u32,
    ) -> Self {
        let mut flows = [0.0; MAX_KICKS + 1];
        let first = usize::from(kick_first);
        let nf = first + palindrome(flows_half, flows_centre, &mut flows[first..]) + first;
        let mut kicks = [0.0; MAX_KICKS];
        let len = palindrome(kicks_half, kicks_centre, &mut kicks);
        debug_assert_eq!(nf, len + 1, "s + 1 flows for s kicks");
        Self {
            flows,
            kicks,
            len,
            order,
        }
    }

    /// The order the method reaches on $H_0 + H_V$.
    pub fn order(&self) -> u32 {
        self.order
    }

    /// The free-flow fractions $a_1, \dots, a_{s+1}$.
    pub fn flows(&self) -> &[f64] {
        &self.flows[..=self.len]
    }

    /// The kick fractions $b_1, \dots, b_s$.
    pub fn kicks(&self) -> &[f64] {
        &self.kicks[..self.len]
    }

    /// Gradients of $V$ per step when consecutive steps share the end kick's gradient: $s$
    /// minus one when the method begins and ends with a kick ($a_1 = a_{s+1} = 0$).
    pub fn gradients_per_step(&self) -> usize {
        if self.starts_with_kick() {
            self.len - 1
        } else {
            self.len
        }
    }

    /// Whether $a_1 = a_{s+1} = 0$ (the method begins and ends with a kick).
    pub fn starts_with_kick(&self) -> bool {
        self.flows[0] == 0.0 && self.flows[self.len] == 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn is_palindrome(v: &[f64]) -> bool {
        v.iter().zip(v.iter().rev()).all(|(a, b)| a == b)
    }

    #[test]
    fn the_built_in_methods_are_symmetric_and_consistent() {
        let methods = [
            (SplittingMethod::blanes_moan_4(), 7, 6),
            (SplittingMethod::blanes_moan_6(), 12, 11),
            (SplittingMethod::blanes_moan_6a(), 14, 14),
        ];
        for (method, kicks, gradients) in methods {
            assert_eq!(method.kicks().len(), kicks);
            assert_eq!(method.flows().len(), kicks + 1);
            assert_eq!(method.gradients_per_step(), gradients);
            assert!(is_palindrome(method.flows()) && is_palindrome(method.kicks()));
            for list in [method.flows(), method.kicks()] {
                let sum: f64 = list.iter().sum();
                assert!((sum - 1.0).abs() < 1e-15, "{sum}");
            }
        }
    }

    #[test]
    fn the_computed_centres_match_the_published_ones() {
        // the centres as printed (Principia's transcription of Blanes and Moan, Table 3)
        let bm4 = SplittingMethod::blanes_moan_4();
        assert!((bm4.kicks()[3] - 0.119_524_194_013_150_8).abs() < 1e-15);
        assert!((bm4.flows()[3] + 0.350_171_622_895_351).abs() < 1e-15);
        let bm6 = SplittingMethod::blanes_moan_6();
        assert!((bm6.flows()[6] - 0.204_777_054_291_47).abs() < 1e-15);
        assert!((bm6.kicks()[5] - 0.236_669_924_786_931_1).abs() < 1e-15);
        let bm6a = SplittingMethod::blanes_moan_6a();
        assert!((bm6a.flows()[7] - 0.207_305_069_056_895_4).abs() < 1e-15);
        assert!((bm6a.kicks()[6] + 0.196_411_466_486_454_23).abs() < 1e-15);
    }

    #[test]
    fn a_composition_fuses_its_half_flows() {
        let (gamma, len) = compose::coefficients(4).unwrap();
        let method = SplittingMethod::composition(4).unwrap();
        assert_eq!(method.kicks(), &gamma[..len]);
        let flows = method.flows();
        assert_eq!(flows[0], 0.5 * gamma[0]);
        assert_eq!(flows[1], 0.5 * (gamma[0] + gamma[1]));
        assert!(!method.starts_with_kick());
        assert!(SplittingMethod::composition(5).is_err());
        assert!(SplittingMethod::new(&[0.5, 0.5], &[0.9], 2).is_err());
        assert!(SplittingMethod::new(&[0.5], &[1.0], 2).is_err());
        assert!(SplittingMethod::new(&[0.5, f64::NAN], &[1.0], 2).is_err());
    }
}
