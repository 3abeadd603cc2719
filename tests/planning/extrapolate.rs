//! Richardson extrapolation of plans (`OptimalControlProblem::solve_extrapolated`): the plain
//! cost converges at order 2 and the extrapolated one at order >= 4, the extrapolation at a
//! moderate N agrees with one at a much larger N within its error estimate, and for the
//! minimum-acceleration spline it recovers the exact continuous cost.

use crate::common;

use common::models::{DISC_GOAL, DISC_START, OneDisc, disc_bump_guess};
use retract::bvp::{Extrapolated, OptimalControlProblem, PlanError, PlanGuess, PlanOptions};
use retract::higher_order_lagrangian;

fn disc_problem(steps: usize) -> OptimalControlProblem<'static, OneDisc, 2, 2, 4> {
    static SYSTEM: OneDisc = OneDisc { tau: 1e-2 };
    OptimalControlProblem::new(&SYSTEM, &DISC_START, &DISC_GOAL, 4.0, steps)
}

fn extrapolate_disc(
    steps: usize,
    options: PlanOptions,
) -> Result<Extrapolated<2, 4>, PlanError<2, 4>> {
    let (x, u) = disc_bump_guess(steps);
    disc_problem(steps)
        .with_options(options)
        .solve_extrapolated(PlanGuess::Path { x: &x, u: &u })
}

/// Observed orders log2((Q_N - Q_2N) / (Q_2N - Q_4N)) of values at N, 2N, 4N, ...
fn orders(values: &[f64]) -> Vec<f64> {
    values
        .windows(3)
        .map(|w| ((w[0] - w[1]) / (w[1] - w[2])).log2())
        .collect()
}

/// Over N = 20, 40, 80, 160 the plain cost J_N converges at order 2 (successive differences
/// shrink by 4) and the extrapolated cost at order >= 4 (measured: 6, the O(h^6) of two
/// Richardson levels); the finer solves of the warm-started ladder take few iterations.
#[test]
fn plain_cost_converges_at_order_two_and_extrapolated_at_order_six() {
    let sweep = [20, 40, 80, 160];
    let runs: Vec<Extrapolated<2, 4>> = sweep
        .iter()
        .map(|&n| extrapolate_disc(n, PlanOptions::default()).unwrap())
        .collect();
    let plain: Vec<f64> = runs.iter().map(|e| e.plans[0].cost).collect();
    let extrapolated: Vec<f64> = runs.iter().map(|e| e.cost).collect();
    for (n, e) in sweep.iter().zip(&runs) {
        println!(
            "N = {n}: J_N = {:.15}, extrapolated {:.15} (estimate {:.1e}), iterations {:?}",
            e.plans[0].cost,
            e.cost,
            e.cost_error,
            e.iterations()
        );
        let [_, fine, finest] = e.iterations();
        assert!(
            fine <= 4 && finest <= 2,
            "N = {n}: iterations {:?}",
            e.iterations()
        );
    }
    let (plain_orders, extrapolated_orders) = (orders(&plain), orders(&extrapolated));
    println!("orders: plain {plain_orders:?}, extrapolated {extrapolated_orders:?}");
    for order in plain_orders {
        assert!((order - 2.0).abs() < 0.05, "plain order {order}");
    }
    for order in extrapolated_orders {
        assert!(order > 5.0, "extrapolated order {order}");
    }
}

/// At N = 100 the extrapolated cost, boundary momenta and jets agree with the extrapolation
/// at N = 400 (plans with 400, 800 and 1600 steps, solved to the tolerance 1e-10; the SQP's
/// relative stationarity stalls near 1e-10 at 3200 steps and near 3e-9 at 6400) to 1e-9
/// relative, and the error estimates are at least the actual errors (they estimate the
/// O(h^4) error of the first level, so they are pessimistic for the O(h^6) second level:
/// measured 100 to 1000 times the actual error).
#[test]
fn extrapolation_agrees_with_a_fine_reference_within_its_estimate() {
    let reference = extrapolate_disc(400, PlanOptions::default().with_tolerance(1e-10)).unwrap();
    let coarse = extrapolate_disc(100, PlanOptions::default()).unwrap();
    let cost_error = (coarse.cost - reference.cost).abs();
    println!(
        "cost {:.15} vs {:.15}: error {cost_error:.1e}, estimate {:.1e}",
        coarse.cost, reference.cost, coarse.cost_error
    );
    assert!(cost_error < 1e-9 * reference.cost);
    assert!(cost_error <= coarse.cost_error);
    let p = coarse.boundary_momenta().unwrap();
    let p_estimate = coarse.boundary_momenta_error().unwrap();
    let p_reference = reference.boundary_momenta().unwrap();
    for ((p, estimate), p_reference) in p.iter().zip(&p_estimate).zip(&p_reference) {
        let scale = p_reference.amax();
        for r in 0..4 {
            let error = (p[r] - p_reference[r]).abs();
            println!("p[{r}] error {error:.1e}, estimate {:.1e}", estimate[r]);
            assert!(error < 1e-9 * scale, "momentum {r}: error {error:e}");
            assert!(
                error <= estimate[r],
                "momentum {r}: {error:e} > {:e}",
                estimate[r]
            );
        }
    }
    // jets: the largest error over the nodes against the largest estimate (a component's
    // estimate can vanish where its h^4 coefficient changes sign; at the fixed ends both are
    // at the level of the solves' feasibility)
    let scale = reference.x.iter().map(|x| x.amax()).fold(0.0, f64::max);
    let mut largest = (0.0_f64, 0.0_f64);
    for (i, (x, estimate)) in coarse.x.iter().zip(&coarse.x_error).enumerate() {
        let error = (x - reference.x[4 * i]).amax();
        assert!(error < 1e-9 * scale, "x_{i}: error {error:e}");
        largest = (largest.0.max(error), largest.1.max(estimate.amax()));
    }
    println!(
        "jets: largest error {:.1e}, estimate {:.1e}",
        largest.0, largest.1
    );
    assert!(largest.0 <= largest.1);
}

/// Minimum acceleration: the continuous minimiser is the cubic Hermite spline.
#[higher_order_lagrangian(order = 2)]
fn acceleration(_q: [f64; 2], _dq: [f64; 2], ddq: [f64; 2]) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2))
}

const SPLINE_START: [f64; 4] = [0.0, 0.0, 1.0, -1.0];
const SPLINE_GOAL: [f64; 4] = [1.0, 2.0, 0.0, 1.0];
const SPLINE_T: f64 = 2.0;

/// The integral of 1/2 |q''|^2 over the cubic Hermite spline between the boundary jets: per
/// coordinate q = a + v_a t + c_2 t^2 + c_3 t^3 with c_3 T^3 = E T - 2 D, c_2 T^2 = 3 D - E T
/// (D = b - a - v_a T, E = v_b - v_a), and the integral of 1/2 (2 c_2 + 6 c_3 t)^2 is
/// 2 c_2^2 T + 6 c_2 c_3 T^2 + 6 c_3^2 T^3.
fn spline_cost() -> f64 {
    let t = SPLINE_T;
    (0..2)
        .map(|a| {
            let (q0, v0) = (SPLINE_START[a], SPLINE_START[2 + a]);
            let (q1, v1) = (SPLINE_GOAL[a], SPLINE_GOAL[2 + a]);
            let (d, e) = (q1 - q0 - v0 * t, v1 - v0);
            let c3 = (e * t - 2.0 * d) / t.powi(3);
            let c2 = (3.0 * d - e * t) / (t * t);
            2.0 * c2 * c2 * t + 6.0 * c2 * c3 * t * t + 6.0 * c3 * c3 * t.powi(3)
        })
        .sum()
}

/// For L = 1/2 |q''|^2 the extrapolated cost is the exact cost of the continuous minimiser,
/// the cubic Hermite spline (J_N itself is off by O(h^2); here J_N - J = 3 / (N^2 - 1), so
/// the second level is off by O(h^6): 1.2e-11 at N = 40).
#[test]
fn extrapolated_spline_cost_is_the_exact_cost() {
    let exact = spline_cost();
    let system = Acceleration::new();
    let extrapolated =
        OptimalControlProblem::new(&system, &SPLINE_START, &SPLINE_GOAL, SPLINE_T, 40)
            .solve_extrapolated(PlanGuess::Spline)
            .unwrap();
    let plain = extrapolated.plans[0].cost;
    println!(
        "exact {exact}, J_40 {plain}, extrapolated {} (estimate {:.1e})",
        extrapolated.cost, extrapolated.cost_error
    );
    assert!((plain - exact).abs() > 1e-3);
    assert!((extrapolated.cost - exact).abs() < 1e-10 * exact);
    assert!((extrapolated.cost - exact).abs() <= extrapolated.cost_error);
}

/// `solve_extrapolated_with` in one workspace, twice (the second time in the workspace the
/// first sized), gives the extrapolation of `solve_extrapolated` bit for bit: the cost, its
/// estimate and the three plans.
#[test]
fn an_extrapolation_in_a_kept_workspace_is_the_same() {
    let (x, u) = disc_bump_guess(40);
    let guess = PlanGuess::Path { x: &x, u: &u };
    let problem = disc_problem(40);
    let fresh = problem.solve_extrapolated(guess).unwrap();
    let mut workspace = retract::bvp::Workspace::new();
    for round in 0..2 {
        let kept = problem
            .solve_extrapolated_with(guess, &mut workspace)
            .unwrap();
        assert_eq!(kept.cost.to_bits(), fresh.cost.to_bits(), "round {round}");
        assert_eq!(kept.cost_error.to_bits(), fresh.cost_error.to_bits());
        for (a, b) in kept.plans.iter().zip(&fresh.plans) {
            assert_eq!(a.x, b.x, "round {round}");
            assert_eq!(a.iterations, b.iterations);
        }
    }
}
