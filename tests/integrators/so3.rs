//! SO(3) in one Gibbs chart: the free rigid body L = 1/2 Omega . J Omega written with the
//! chart's body velocity Omega = 2 (y' - y x y') / (1 + |y|^2), stepped by the Cayley
//! midpoint map of the group (`retract::so3::CayleyMidpoint`, lifted by `TaylorLift`) and by
//! the exponential one (`ExpMidpoint1`). The Cayley map is a discretization map; both steps
//! are symplectic, conserve the spatial angular momentum to rounding (left equivariance), and
//! converge with order 2 to an RK4 solution of Euler's equations with quaternion kinematics.

#[path = "../../examples/common/attitude.rs"]
pub(crate) mod attitude;

use retract::diagnostics::canonical_structure;
use retract::lifted::Blocks;
use retract::map::{self, DiscretizationMap, TaylorLift};
use retract::nalgebra::{SMatrix, SVector, Vector3};
use retract::so3::{CayleyMidpoint, ExpMidpoint1, parts, rotation, spatial_momentum};
use retract::{LiftedSystem, NewtonOptions};

const J: [f64; 3] = attitude::INERTIA;
const OMEGA0: [f64; 3] = [0.4, 0.9, -0.3];

/// The free rigid body with inertia `J` in the Gibbs chart (`attitude::gibbs_free`).
pub(crate) fn system() -> attitude::GibbsFree {
    attitude::gibbs_free_body()
}

/// The state at the identity with body velocity `OMEGA0` (y = 0, y' = Omega / 2).
fn start() -> SVector<f64, 6> {
    let jet = SVector::<f64, 6>::from([
        0.0,
        0.0,
        0.0,
        OMEGA0[0] / 2.0,
        OMEGA0[1] / 2.0,
        OMEGA0[2] / 2.0,
    ]);
    system().legendre(&jet)
}

/// `steps` steps of size `h` of the Cayley midpoint map.
fn run(h: f64, steps: usize) -> Vec<SVector<f64, 6>> {
    run_with(&TaylorLift(CayleyMidpoint), h, steps)
}

/// `steps` steps of size `h` of `map`.
fn run_with<Map: DiscretizationMap<3, 1>>(map: &Map, h: f64, steps: usize) -> Vec<SVector<f64, 6>> {
    let options = NewtonOptions::default();
    let mut states = vec![start()];
    for _ in 0..steps {
        let z = states[states.len() - 1];
        states.push(
            map::step(&system(), map, &z, h, &options)
                .expect("regular")
                .0,
        );
    }
    states
}

/// The chart point y = vec(q) / q_0 of `attitude::euler_reference` from `OMEGA0` at `t`.
fn reference(t: f64, steps: usize) -> Vector3<f64> {
    let q = attitude::euler_reference(Vector3::from(OMEGA0), t, steps);
    q.imag() / q.w
}

#[test]
fn the_cayley_midpoint_map_is_a_symmetric_discretization_map() {
    let map = TaylorLift(CayleyMidpoint);
    let y: Blocks<3, 1> = [Vector3::new(0.3, -0.5, 0.2)];
    let zero: Blocks<3, 1> = [Vector3::zeros()];
    let (r1, r2) = map.points(&y, &zero);
    assert!((r1[0] - y[0]).amax() < 1e-16 && (r2[0] - y[0]).amax() < 1e-16);
    let jac = map.jacobians(&y, &zero);
    let difference = jac.r2_xi[0][0] - jac.r1_xi[0][0];
    assert!((difference - retract::nalgebra::Matrix3::identity()).amax() < 1e-15);
    let v: Blocks<3, 1> = [Vector3::new(0.1, 0.4, -0.2)];
    let (a1, a2) = map.points(&y, &v);
    let (b1, b2) = map.points(&y, &[-v[0]]);
    assert!((a1[0] - b2[0]).amax() < 1e-16 && (a2[0] - b1[0]).amax() < 1e-16);
}

#[test]
fn the_spatial_momentum_is_r_j_omega() {
    // after some steps (y != 0): p . delta_a y against R(y) J Omega(y, y')
    let z = run(0.1, 10)[10];
    let (y, p) = parts(&z);
    // the chart velocity from the momenta: y' solves p = dL/dy' (the Legendre map of L)
    let omega_of = |dy: &Vector3<f64>| (dy - y.cross(dy)) * (2.0 / (1.0 + y.norm_squared()));
    // p = (dOmega/dy')^T J Omega, dOmega/dy' = 2 (I - [y]x) / (1 + |y|^2)
    let b = (retract::nalgebra::Matrix3::identity() - y.cross_matrix())
        * (2.0 / (1.0 + y.norm_squared()));
    let jm = retract::nalgebra::Matrix3::from_diagonal(&Vector3::from(J));
    let dy = (b.transpose() * jm * b).lu().solve(&p).expect("regular");
    let spatial = rotation(&y) * jm * omega_of(&dy);
    let gap = (spatial_momentum(&y, &p) - spatial).amax();
    assert!(gap < 1e-13, "{gap:e}");
}

#[test]
fn the_spatial_momentum_is_conserved_and_the_step_is_symplectic() {
    // to T = 2, a turn by about 2 rad: inside the chart (which ends at a turn by pi; moving
    // charts, as on the sphere, are the next step)
    let drift = |states: &[SVector<f64, 6>]| {
        let (y, p) = parts(&states[0]);
        let m0 = spatial_momentum(&y, &p);
        let largest = states
            .iter()
            .map(|z| {
                let (y, p) = parts(z);
                (spatial_momentum(&y, &p) - m0).amax()
            })
            .fold(0.0, f64::max);
        largest / m0.amax()
    };
    // the Cayley and the exponential midpoint maps
    let states = run(0.005, 400);
    let cayley = drift(&states);
    let exp = drift(&run_with(&ExpMidpoint1, 0.005, 400));
    assert!(
        cayley < 1e-12 && exp < 1e-12,
        "momentum drift {cayley:e}, {exp:e}"
    );
    // the chart's own midpoint rule is symplectic too, but not equivariant: it drifts
    let theta = drift(&run_with(&map::ThetaMap { theta: 0.5 }, 0.005, 400));
    assert!(theta > 1e-8, "theta map drift {theta:e}");
    let symplecticity = |map: &dyn Fn(&SVector<f64, 6>) -> SMatrix<f64, 6, 6>| {
        let (d, j) = (map(&states[7]), canonical_structure::<6>());
        (d.transpose() * j * d - j).amax()
    };
    let options = NewtonOptions::default();
    let errors = [
        symplecticity(&|z| {
            map::step_map_derivative(&system(), &TaylorLift(CayleyMidpoint), z, 0.1, &options)
                .expect("regular")
        }),
        symplecticity(&|z| {
            map::step_map_derivative(&system(), &ExpMidpoint1, z, 0.1, &options).expect("regular")
        }),
    ];
    assert!(
        errors.iter().all(|e| *e < 1e-12),
        "|D^T J D - J| = {errors:?}"
    );
}

#[test]
fn the_cayley_and_exponential_midpoint_steps_have_order_2() {
    let t = 1.0;
    let exact = reference(t, 20_000);
    let cayley = [20, 40, 80].map(|n| (parts(&run(t / n as f64, n)[n]).0 - exact).amax());
    let exp = [20, 40, 80].map(|n| {
        let z = run_with(&ExpMidpoint1, t / n as f64, n)[n];
        (parts(&z).0 - exact).amax()
    });
    for errors in [cayley, exp] {
        for pair in errors.windows(2) {
            let observed = (pair[0] / pair[1]).log2();
            assert!(
                (observed - 2.0).abs() < 0.1,
                "order {observed} ({errors:?})"
            );
        }
    }
}
