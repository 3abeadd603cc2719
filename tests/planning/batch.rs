//! Many plans at once (`retract::bvp::solve_batch`, `solve_multistart`): multi-start finds
//! the cheaper of two minima of the one-disc scene, and a batch of starts gives the plans of
//! the solves one by one.

use crate::common;

use common::models::{DISC_GOAL, DISC_START, OneDisc};

use retract::bvp::{Curve, OptimalControlProblem, PlanGuess, solve_batch};

/// The one-disc scene's Hermite cubic (unit speed along x) with a bump of `height` in y.
fn bumped(height: f64) -> Curve<'static, 2> {
    Curve::from_fn(move |t| {
        let s = t / 4.0;
        [
            -2.0 + t,
            0.2 + height * 16.0 * s * s * (1.0 - s) * (1.0 - s),
        ]
    })
}

/// The one-disc scene (N = 100) has a minimum above the disc and a costlier one below it:
/// from a guess bumped below and one bumped above, both solves are certified at different
/// costs, and multi-start names the one above (the start and goal lie above the centre).
#[test]
fn multistart_finds_the_cheaper_side_of_the_disc() {
    let system = OneDisc { tau: 1e-2 };
    let problem = OptimalControlProblem::new(&system, &DISC_START, &DISC_GOAL, 4.0, 100);
    let (below, above) = (bumped(-1.6), bumped(1.3));
    let multi = problem.solve_multistart(&[PlanGuess::Curve(&below), PlanGuess::Curve(&above)]);
    let [Ok(low), Ok(high)] = &multi.outcomes[..] else {
        panic!("{:?}", multi.outcomes);
    };
    assert!(
        low.x.iter().any(|x| x[1] < -1.0),
        "the first plan passes below"
    );
    assert!(
        high.x.iter().any(|x| x[1] > 1.0),
        "the second plan passes above"
    );
    assert!(
        high.cost < low.cost - 1e-3,
        "{} against {}",
        high.cost,
        low.cost
    );
    assert_eq!(multi.best, Some(1));
    assert_eq!(multi.best_plan().map(|p| p.cost), Some(high.cost));
}

/// A batch of eight starts of the one-disc scene returns, in order, the plans of the solves
/// one by one (the same iterates bit for bit), whatever thread solved each.
#[test]
fn a_batch_of_starts_gives_the_plans_one_by_one() {
    let system = OneDisc { tau: 1e-2 };
    let above = bumped(1.3);
    let starts: Vec<[f64; 4]> = (0..8)
        .map(|i| {
            let mut s = DISC_START;
            s[1] += 0.05 * i as f64;
            s
        })
        .collect();
    let jobs: Vec<_> = (starts.iter())
        .map(|s| {
            let problem = OptimalControlProblem::new(&system, s, &DISC_GOAL, 4.0, 100);
            (problem, PlanGuess::Curve(&above))
        })
        .collect();
    let batch = solve_batch(&jobs);
    for ((problem, guess), outcome) in jobs.iter().zip(&batch) {
        let (Ok(alone), Ok(in_batch)) = (problem.solve(*guess), outcome) else {
            panic!("not certified: {outcome:?}");
        };
        assert_eq!(alone.x, in_batch.x);
        assert_eq!(alone.cost.to_bits(), in_batch.cost.to_bits());
    }
    let costs: Vec<f64> = batch
        .iter()
        .filter_map(|o| o.as_ref().ok())
        .map(|p| p.cost)
        .collect();
    assert!(costs.windows(2).all(|w| w[0] != w[1]), "{costs:?}");
}
