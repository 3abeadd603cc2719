//! Speed of one step of the paper's SE(2) obstacle system (tau = 1e-2, h = 0.01, midpoint)
//! near its closest approach to the disc, and of the 400-step run, for:
//! - generated, reduced (Newton on the 2 core unknowns, `ReducedStepper`), with and without
//!   the domain check;
//! - generated, general (Newton on all 15 unknowns, `retract::step`);
//! - hand-written dense 12x12 Newton (u = p_1,theta eliminated by hand, Jacobian by hand);
//! - hand-written reduced 3x3 Newton on q_theta (the limit), without and with the generated
//!   step's domain check;
//! - the dense 12x12 residual with a forward-mode dual-number Jacobian (num-dual);
//! - the dense 12x12 residual with a central finite-difference Jacobian.
//!
//! Criterion times each; a ratio table, timed in the same run (best of repeated batches),
//! is printed first. Run: `cargo bench -p retract-validation --bench step`.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use num_dual::{DualNum, jacobian};
use retract::higher_order_lagrangian;
use retract::nalgebra::{SMatrix, SVector, Vector3};
use retract::newton::{NewtonOptions, Problem, solve};
use retract::{
    LiftedSystem, ReducedFactors, ReducedScheme, ReducedStepper, StepOptions, step, trajectory,
};

#[higher_order_lagrangian(order = 2)]
fn rigid_body(q: [f64; 3], _dq: [f64; 3], ddq: [f64; 3], tau: f64, r: f64) -> f64 {
    0.5 * (ddq[0].powi(2) + ddq[1].powi(2) + ddq[2].powi(2))
        + tau / (q[0].powi(2) + q[1].powi(2) - r * r)
}

const TAU: f64 = 1e-2;
const H: f64 = 0.01;
type Z = SVector<f64, 12>;

/// grad V and Hess V of V = tau / (x^2 + y^2 - 1) (the theta row and column are zero).
fn grad_hess(q: &Vector3<f64>) -> (Vector3<f64>, SMatrix<f64, 3, 3>) {
    let s = q[0] * q[0] + q[1] * q[1] - 1.0;
    let g = Vector3::new(
        -2.0 * TAU * q[0] / (s * s),
        -2.0 * TAU * q[1] / (s * s),
        0.0,
    );
    let mut hess = SMatrix::<f64, 3, 3>::zeros();
    for a in 0..2 {
        for b in 0..2 {
            let delta = if a == b { 1.0 } else { 0.0 };
            hess[(a, b)] = -2.0 * TAU * delta / (s * s) + 8.0 * TAU * q[a] * q[b] / (s * s * s);
        }
    }
    (g, hess)
}

/// The dense midpoint residual on z_1 = (q, v, p0, p1), generic for dual numbers:
/// F_q = q1 - q0 - h v_th, F_v = v1 - v0 - h p1_th, F_p0 = p0_1 - p0_0 - h grad V(q_th),
/// F_p1 = p1_1 - p1_0 + h p0_th.
fn dense_residual<T: DualNum<Primitive = f64> + Copy>(
    z0: &Z,
    z1: &SVector<T, 12>,
) -> SVector<T, 12> {
    let h = H;
    let half = |i: usize| (z1[i] + z0[i]) * 0.5;
    let (x, y) = (half(0), half(1));
    let s = x * x + y * y - 1.0;
    let gv = [
        x * (-2.0 * TAU) / (s * s),
        y * (-2.0 * TAU) / (s * s),
        T::from(0.0),
    ];
    SVector::from_fn(|r, _| match r / 3 {
        0 => z1[r] - z0[r] - half(r + 3) * h,
        1 => z1[r] - z0[r] - half(r + 6) * h,
        2 => z1[r] - z0[r] - gv[r - 6] * h,
        _ => z1[r] - z0[r] + half(r - 3) * h,
    })
}

/// The hand-written Jacobian of `dense_residual`.
fn dense_jacobian(z0: &Z, z1: &Z) -> SMatrix<f64, 12, 12> {
    let mut j = SMatrix::<f64, 12, 12>::identity();
    let q_th = Vector3::new(
        0.5 * (z0[0] + z1[0]),
        0.5 * (z0[1] + z1[1]),
        0.5 * (z0[2] + z1[2]),
    );
    let (_, hess) = grad_hess(&q_th);
    for i in 0..3 {
        j[(i, 3 + i)] = -0.5 * H;
        j[(3 + i, 9 + i)] = -0.5 * H;
        j[(9 + i, 6 + i)] = 0.5 * H;
        for b in 0..3 {
            j[(6 + i, b)] = -0.5 * H * hess[(i, b)];
        }
    }
    j
}

enum Jacobian {
    Hand,
    Dual,
    FiniteDifferences,
}

struct Dense<'a> {
    z0: &'a Z,
    jacobian: Jacobian,
}

impl Problem<12> for Dense<'_> {
    fn residual(&self, z1: &Z) -> Z {
        dense_residual(self.z0, z1)
    }

    fn jacobian(&self, z1: &Z) -> SMatrix<f64, 12, 12> {
        match self.jacobian {
            Jacobian::Hand => dense_jacobian(self.z0, z1),
            Jacobian::Dual => jacobian(|z| dense_residual(self.z0, &z), z1).1,
            Jacobian::FiniteDifferences => SMatrix::from_fn(|r, c| {
                let eps = 1e-7 * (1.0 + z1[c].abs());
                let (mut plus, mut minus) = (*z1, *z1);
                plus[c] += eps;
                minus[c] -= eps;
                (dense_residual(self.z0, &plus)[r] - dense_residual(self.z0, &minus)[r])
                    / (2.0 * eps)
            }),
        }
    }
}

fn dense_step(z0: &Z, jacobian: Jacobian) -> Z {
    let guess = z0
        + SVector::from_fn(|r, _| match r / 3 {
            0 => H * z0[r + 3],
            1 => H * z0[r + 6],
            3 => -H * z0[r - 3],
            _ => 0.0,
        });
    let options = NewtonOptions::default();
    solve(&Dense { z0, jacobian }, guess, &options)
        .expect("dense step")
        .w
}

/// Hand-reduced midpoint step: y = q_theta solves
/// y - (q0 + h/2 v0 + h^2/4 p1_0 - h^3/8 p0_0) + h^4/16 grad V(y) = 0; the rest is explicit.
struct Core {
    c0: Vector3<f64>,
}

impl Problem<3> for Core {
    fn residual(&self, y: &Vector3<f64>) -> Vector3<f64> {
        y - self.c0 + grad_hess(y).0 * (H.powi(4) / 16.0)
    }
    fn jacobian(&self, y: &Vector3<f64>) -> SMatrix<f64, 3, 3> {
        SMatrix::identity() + grad_hess(y).1 * (H.powi(4) / 16.0)
    }
}

fn hand_reduced_step(z0: &Z) -> Z {
    let (q, v, p0, p1) = (
        z0.fixed_rows::<3>(0),
        z0.fixed_rows::<3>(3),
        z0.fixed_rows::<3>(6),
        z0.fixed_rows::<3>(9),
    );
    let c0 = q + v * (H / 2.0) + p1 * (H * H / 4.0) - p0 * (H.powi(3) / 8.0);
    let guess = c0 - grad_hess(&c0).0 * (H.powi(4) / 16.0);
    let y = solve(&Core { c0 }, guess, &NewtonOptions::default())
        .expect("core")
        .w;
    let g = grad_hess(&y).0;
    let p0_1 = p0 + g * H;
    let p0_th = p0 + g * (H / 2.0);
    let p1_1 = p1 - p0_th * H;
    let u = p1 - p0_th * (H / 2.0);
    let v1 = v + u * H;
    let q1 = y * 2.0 - q;
    let mut z1 = Z::zeros();
    z1.fixed_rows_mut::<3>(0).copy_from(&q1);
    z1.fixed_rows_mut::<3>(3).copy_from(&v1);
    z1.fixed_rows_mut::<3>(6).copy_from(&p0_1);
    z1.fixed_rows_mut::<3>(9).copy_from(&p1_1);
    z1
}

/// The hand-written step with the generated step's domain check: s = x^2 + y^2 - 1 is finite,
/// non-zero and of one sign at q_0, q_theta and q_1 (`None` otherwise).
fn hand_guarded_step(z0: &Z) -> Option<Z> {
    let z1 = hand_reduced_step(z0);
    let s = |x: f64, y: f64| x * x + y * y - 1.0;
    let (a, b, c) = (
        s(z0[0], z0[1]),
        s(0.5 * (z0[0] + z1[0]), 0.5 * (z0[1] + z1[1])),
        s(z1[0], z1[1]),
    );
    let positive = a > 0.0 && b > 0.0 && c > 0.0 && a.max(b).max(c) < f64::INFINITY;
    let negative = a < 0.0 && b < 0.0 && c < 0.0 && a.min(b).min(c) > f64::NEG_INFINITY;
    (positive || negative).then_some(z1)
}

fn setup() -> (RigidBody, Z) {
    let system = RigidBody { tau: TAU, r: 1.0 };
    let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let z0 = system.legendre(&Z::from_column_slice(&jet));
    let run = trajectory(&system, &z0, H, 200, &StepOptions::default()).expect("regular");
    (system, run.states[200])
}

/// Best time per call over 20 batches of `n` calls, in nanoseconds.
fn best_ns(n: usize, mut f: impl FnMut()) -> f64 {
    (0..20)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..n {
                f();
            }
            t.elapsed().as_nanos() as f64 / n as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Best time per call of each closure over `rounds` rounds of `n` calls each, the closures
/// taking turns within a round (so a change of the machine's speed during the run affects all
/// alike), in nanoseconds.
fn interleaved_best_ns(rounds: usize, n: usize, fs: &mut [&mut dyn FnMut()]) -> Vec<f64> {
    let mut best = vec![f64::INFINITY; fs.len()];
    for _ in 0..rounds {
        for (f, b) in fs.iter_mut().zip(best.iter_mut()) {
            let t = Instant::now();
            for _ in 0..n {
                f();
            }
            *b = b.min(t.elapsed().as_nanos() as f64 / n as f64);
        }
    }
    best
}

/// Checks that every variant computes the same step, then prints the tables.
fn print_ratios(system: &RigidBody, z: &Z) {
    let options = StepOptions::default();
    let mut reduced = ReducedStepper::new(system);
    // the variants compute the same step
    let reference = step(system, z, H, &options).expect("regular").0;
    let same = |name: &str, other: &Z| {
        let d = (reference - other).amax();
        assert!(d < 1e-12, "{name} differs from the general step by {d:e}");
    };
    same("reduced", &reduced.step(z, H, &options).expect("regular").0);
    same("hand dense", &dense_step(z, Jacobian::Hand));
    same("hand reduced", &hand_reduced_step(z));
    same(
        "hand guarded",
        &hand_guarded_step(z).expect("outside the disc"),
    );
    same("dual", &dense_step(z, Jacobian::Dual));
    print_newton_systems(system, z);
    print_steps(system, z);
    print_interleaved(system, z);
    print_runs();
}

/// The Newton system (residual and Jacobian) of one step, per variant.
fn print_newton_systems(system: &RigidBody, z: &Z) {
    let w = system.predictor(z, H, 0.5).expect("regular");
    let factors = ReducedFactors::new(system, H, 0.5).expect("regular");
    let offset = system.core_offset(&factors, z);
    let y = SVector::<f64, 2>::new(z[0], z[1]);
    let systems: [(&str, f64); 6] = [
        (
            "generated, general (15 unknowns)",
            best_ns(20_000, || {
                black_box(system.residual(black_box(z), &w, H, 0.5));
                black_box(system.jacobian(black_box(z), &w, H, 0.5));
            }),
        ),
        (
            "generated, reduced (2 unknowns)",
            best_ns(20_000, || {
                black_box(system.core_system(&factors, &offset, black_box(&y), H, 0.5));
            }),
        ),
        (
            "hand-written dense 12x12",
            best_ns(20_000, || {
                black_box(dense_residual(
                    black_box(z),
                    &w.fixed_rows::<12>(0).into_owned(),
                ));
                black_box(dense_jacobian(
                    black_box(z),
                    &w.fixed_rows::<12>(0).into_owned(),
                ));
            }),
        ),
        (
            "hand-written reduced 3x3",
            best_ns(20_000, || {
                let core = Core {
                    c0: black_box(Vector3::new(z[0], z[1], z[2])),
                };
                black_box(core.residual(&core.c0));
                black_box(core.jacobian(&core.c0));
            }),
        ),
        (
            "dense residual + dual-number Jacobian",
            best_ns(5_000, || {
                black_box(jacobian(
                    |v| dense_residual(black_box(z), &v),
                    &w.fixed_rows::<12>(0).into_owned(),
                ));
            }),
        ),
        (
            "dense residual + finite differences",
            best_ns(5_000, || {
                let p = Dense {
                    z0: z,
                    jacobian: Jacobian::FiniteDifferences,
                };
                black_box(p.jacobian(&w.fixed_rows::<12>(0).into_owned()));
            }),
        ),
    ];
    println!("\nNewton system (residual + Jacobian), SE(2) obstacle, h = 0.01:");
    for (name, ns) in systems {
        println!("  {name:<40} {ns:>9.1} ns");
    }
}

/// One step per variant, as ratios to the generated reduced step.
fn print_steps(system: &RigidBody, z: &Z) {
    let options = StepOptions::default();
    let mut reduced = ReducedStepper::new(system);
    let unguarded = options.with_domain_check(false);
    let steps: [(&str, f64); 7] = [
        (
            "generated, reduced",
            best_ns(2_000, || {
                black_box(reduced.step(black_box(z), H, &options).map(|s| s.0[0]).ok());
            }),
        ),
        (
            "generated, reduced, domain check off",
            best_ns(2_000, || {
                black_box(
                    reduced
                        .step(black_box(z), H, &unguarded)
                        .map(|s| s.0[0])
                        .ok(),
                );
            }),
        ),
        (
            "generated, general",
            best_ns(2_000, || {
                black_box(step(system, black_box(z), H, &options).map(|s| s.0[0]).ok());
            }),
        ),
        (
            "hand-written dense 12x12",
            best_ns(2_000, || {
                black_box(dense_step(black_box(z), Jacobian::Hand));
            }),
        ),
        (
            "hand-written reduced 3x3",
            best_ns(2_000, || {
                black_box(hand_reduced_step(black_box(z)));
            }),
        ),
        (
            "dense, dual-number Jacobian",
            best_ns(1_000, || {
                black_box(dense_step(black_box(z), Jacobian::Dual));
            }),
        ),
        (
            "dense, finite differences",
            best_ns(1_000, || {
                black_box(dense_step(black_box(z), Jacobian::FiniteDifferences));
            }),
        ),
    ];
    let reduced_ns = steps[0].1;
    println!("\nOne step (ratio = time / generated reduced step):");
    for (name, ns) in steps {
        println!("  {name:<40} {ns:>9.1} ns   {:>6.2}x", ns / reduced_ns);
    }
}

/// The generated and hand-written reduced steps, with and without the domain check, timed
/// interleaved.
fn print_interleaved(system: &RigidBody, z: &Z) {
    let options = StepOptions::default();
    let unguarded = options.with_domain_check(false);
    let (mut guarded, mut unguarded_stepper) =
        (ReducedStepper::new(system), ReducedStepper::new(system));
    let best = interleaved_best_ns(
        60,
        2_000,
        &mut [
            &mut || {
                black_box(guarded.step(black_box(z), H, &options).map(|s| s.0[0]).ok());
            },
            &mut || {
                black_box(
                    unguarded_stepper
                        .step(black_box(z), H, &unguarded)
                        .map(|s| s.0[0])
                        .ok(),
                );
            },
            &mut || {
                black_box(hand_reduced_step(black_box(z)));
            },
            &mut || {
                black_box(hand_guarded_step(black_box(z)));
            },
        ],
    );
    println!(
        "\nInterleaved (60 rounds of 2000 calls each, best):\n  \
         domain check off: generated reduced {:.1} ns, hand-written reduced {:.1} ns ({:.2}x)\n  \
         domain check on:  generated reduced {:.1} ns, hand-written reduced {:.1} ns ({:.2}x; \
         {:.2}x the hand-written step without it)",
        best[1],
        best[2],
        best[1] / best[2],
        best[0],
        best[3],
        best[0] / best[3],
        best[0] / best[2],
    );
}

/// The paper's 400-step run, generated (general and reduced) and hand-written, interleaved.
fn print_runs() {
    let options = StepOptions::default();
    let unguarded = options.with_domain_check(false);
    let (system0, z0) = {
        let s = RigidBody { tau: TAU, r: 1.0 };
        let jet = [-2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let z0 = s.legendre(&Z::from_column_slice(&jet));
        (s, z0)
    };
    let run_general = best_ns(50, || {
        let mut z = z0;
        for _ in 0..400 {
            z = step(&system0, &z, H, &options).expect("regular").0;
        }
        black_box(z);
    });
    // each step waits on the last here; the reduced runs start from a fresh stepper
    let reduced_run = |options: &StepOptions| {
        let mut stepper = ReducedStepper::new(&system0);
        let mut z = z0;
        for _ in 0..400 {
            z = stepper.step(&z, H, options).expect("regular").0;
        }
        black_box(z);
    };
    let runs = interleaved_best_ns(
        200,
        3,
        &mut [
            &mut || reduced_run(&options),
            &mut || {
                let mut z = z0;
                for _ in 0..400 {
                    z = hand_guarded_step(&z).expect("outside the disc");
                }
                black_box(z);
            },
            &mut || reduced_run(&unguarded),
            &mut || {
                let mut z = z0;
                for _ in 0..400 {
                    z = hand_reduced_step(&z);
                }
                black_box(z);
            },
        ],
    );
    println!(
        "\nThe paper's 400-step run (tau = 1e-2, interleaved, best of 200 rounds of 3 runs):\n  \
         domain check on:  generated reduced {:.1} us, hand-written reduced {:.1} us ({:.2}x)\n  \
         domain check off: generated reduced {:.1} us, hand-written reduced {:.1} us ({:.2}x)\n  \
         generated general (domain check on) {:.1} us\n",
        runs[0] / 1e3,
        runs[1] / 1e3,
        runs[0] / runs[1],
        runs[2] / 1e3,
        runs[3] / 1e3,
        runs[2] / runs[3],
        run_general / 1e3
    );
}

fn benches(c: &mut Criterion) {
    let (system, z) = setup();
    print_ratios(&system, &z);
    let options = StepOptions::default();
    let mut group = c.benchmark_group("step/se2_obstacle");
    let mut reduced = ReducedStepper::new(&system);
    group.bench_function("generated_reduced", |b| {
        b.iter(|| reduced.step(black_box(&z), H, &options).map(|s| s.0[0]))
    });
    group.bench_function("generated_general", |b| {
        b.iter(|| step(&system, black_box(&z), H, &options).map(|s| s.0[0]))
    });
    group.bench_function("hand_dense_12", |b| {
        b.iter(|| dense_step(black_box(&z), Jacobian::Hand))
    });
    group.bench_function("hand_reduced_3", |b| {
        b.iter(|| hand_reduced_step(black_box(&z)))
    });
    group.bench_function("dual_dense_12", |b| {
        b.iter(|| dense_step(black_box(&z), Jacobian::Dual))
    });
    group.bench_function("fd_dense_12", |b| {
        b.iter(|| dense_step(black_box(&z), Jacobian::FiniteDifferences))
    });
    group.finish();
}

criterion_group!(step_benches, benches);
criterion_main!(step_benches);
