//! The dual part of a plan: the multipliers of the stage equalities, the inequalities' slacks
//! and multipliers, and the barrier parameter at the end, kept for a primal-dual warm start
//! ([`super::PlanGuess::Plan`]).

use nalgebra::SVector;

/// The multipliers and slacks of a plan's last iterate.
///
/// The inequalities $g \ge 0$ are held as $g - s = 0$, $s > 0$, with multipliers $z$ of
/// $s \ge 0$ per unit time (the transcription's multiplier is $h z$). Those placed at the
/// steps' evaluation points are listed step by step (the same number at every step $i < N$),
/// those placed at the nodes node by node (every interior node $0 < i < N$). At a plan,
/// $z s = \mu$ with $\mu$ = `barrier`, the barrier parameter per unit time at its floor.
/// With `serde`, non-finite numbers are written as in [`super::Certificate`].
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Duals<const N: usize> {
    /// The multipliers $y_i$ of the stage equalities of step $i$ (component $j$ for
    /// equality $j$).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::vectors"))]
    pub equalities: Vec<SVector<f64, N>>,
    /// The slacks $s$ of the inequalities at the evaluation points (step-major).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::list"))]
    pub step_slacks: Vec<f64>,
    /// Their multipliers $z$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::list"))]
    pub step_multipliers: Vec<f64>,
    /// The slacks $s$ of the inequalities at the interior nodes (node-major).
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::list"))]
    pub node_slacks: Vec<f64>,
    /// Their multipliers $z$.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float::list"))]
    pub node_multipliers: Vec<f64>,
    /// The barrier parameter $\mu$ per unit time.
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_float"))]
    pub barrier: f64,
}

impl<const N: usize> Duals<N> {
    /// Whether these duals fit a problem of `steps` steps with `at_steps` inequalities at
    /// every evaluation point and `at_nodes` at every interior node: the lengths match and
    /// every slack and multiplier is positive and finite.
    pub(in crate::bvp) fn fit(&self, steps: usize, at_steps: usize, at_nodes: usize) -> bool {
        let (on_steps, on_nodes) = (steps * at_steps, steps.saturating_sub(1) * at_nodes);
        let positive = |v: &[f64]| v.iter().all(|e| *e > 0.0 && e.is_finite());
        self.equalities.len() == steps
            && self.step_slacks.len() == on_steps
            && self.step_multipliers.len() == on_steps
            && self.node_slacks.len() == on_nodes
            && self.node_multipliers.len() == on_nodes
            && self.barrier.is_finite()
            && [
                &self.step_slacks,
                &self.step_multipliers,
                &self.node_slacks,
                &self.node_multipliers,
            ]
            .iter()
            .all(|v| positive(v))
    }

    /// Shifts these duals of a plan of `steps` steps one step later, in place
    /// ([`super::Plan::shifted`]): every step's and every interior node's block moved one
    /// forward, the last one repeated.
    pub(in crate::bvp) fn shift(&mut self, steps: usize) {
        let (per_step, per_node) = (
            self.step_slacks.len() / steps.max(1),
            self.node_slacks.len() / steps.saturating_sub(1).max(1),
        );
        shift_blocks(&mut self.equalities, 1);
        shift_blocks(&mut self.step_slacks, per_step);
        shift_blocks(&mut self.step_multipliers, per_step);
        shift_blocks(&mut self.node_slacks, per_node);
        shift_blocks(&mut self.node_multipliers, per_node);
    }
}

/// Moves the blocks of `len` entries one block forward (block $i$ takes block $i + 1$), the
/// last one kept (so repeated).
fn shift_blocks<T: Copy>(entries: &mut [T], len: usize) {
    if len == 0 || entries.len() < 2 * len {
        return;
    }
    entries.copy_within(len.., 0);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifting_moves_each_block_one_step_and_repeats_the_last() {
        // 3 steps with one inequality each, 2 interior nodes with two each
        let duals = Duals::<1> {
            equalities: vec![
                SVector::from([1.0]),
                SVector::from([2.0]),
                SVector::from([3.0]),
            ],
            step_slacks: vec![1.0, 2.0, 3.0],
            step_multipliers: vec![4.0, 5.0, 6.0],
            node_slacks: vec![10.0, 11.0, 20.0, 21.0],
            node_multipliers: vec![12.0, 13.0, 22.0, 23.0],
            barrier: 1e-9,
        };
        assert!(duals.fit(3, 1, 2));
        assert!(!duals.fit(3, 2, 1));
        let mut shifted = duals.clone();
        shifted.shift(3);
        let first: Vec<f64> = shifted.equalities.iter().map(|y| y[0]).collect();
        assert_eq!(first, vec![2.0, 3.0, 3.0]);
        assert_eq!(shifted.step_slacks, vec![2.0, 3.0, 3.0]);
        assert_eq!(shifted.step_multipliers, vec![5.0, 6.0, 6.0]);
        assert_eq!(shifted.node_slacks, vec![20.0, 21.0, 20.0, 21.0]);
        assert_eq!(shifted.node_multipliers, vec![22.0, 23.0, 22.0, 23.0]);
    }
}
