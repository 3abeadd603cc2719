//! The stepping path allocates nothing: a counting global allocator sees zero allocations
//! during steps (predictor, Newton, domain check), a Newton solve, the symplecticity
//! diagnostic and an RK4 step of a generated system.

mod common;

use common::models::Scene;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use retract::diagnostics::{rk4_step, symplecticity_error};
use retract::nalgebra::SVector;
use retract::{LiftedSystem, StepOptions, step};

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

struct Counting;

// SAFETY: forwards to the system allocator unchanged; only counts calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

#[test]
fn stepping_allocates_nothing() {
    let obstacles = [[0.0, 0.0, 1.0], [3.0, 2.0, 0.5]];
    let system = Scene {
        tau: 1e-2,
        obstacles: &obstacles,
    };
    let jet = SVector::<f64, 12>::from_column_slice(&[
        -2.0, 1.05, 0.0, 1.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    ]);
    let z0 = system.legendre(&jet);
    let options = StepOptions::default();
    let before = allocations();
    let mut z = z0;
    let mut iterations = 0;
    for _ in 0..400 {
        let (next, report) = step(&system, &z, 0.01, &options).expect("regular step");
        z = next;
        iterations += report.iterations;
    }
    let sympl = symplecticity_error(&system, &z, 0.01, &options).expect("regular");
    let explicit = rk4_step(&system, &z, 0.01).expect("regular");
    let after = allocations();
    assert_eq!(after - before, 0, "allocations on the stepping path");
    // the work was real
    assert!(iterations > 400 && sympl < 1e-12 && explicit[0] > z0[0]);
    // and the counter works: a Vec allocates
    let v: Vec<f64> = Vec::with_capacity(4);
    assert!(allocations() > after && v.capacity() >= 4);
}

/// A stage constraint with a run-time list: linear in q''.
#[retract::jet_function(order = 2)]
fn clearance_rate(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], discs: &[[f64; 3]]) -> f64 {
    let mut s = ddq[0] * dq[1] - ddq[1] * dq[0];
    for d in discs {
        s += (-((q[0] - d[0]).powi(2) + (q[1] - d[1]).powi(2)).sqrt()).exp() * d[2];
    }
    s
}

#[test]
fn jet_functions_allocate_nothing() {
    use retract::JetFunction;
    let discs = [[0.0, 0.0, 1.0], [3.0, 2.0, 0.5]];
    let g = ClearanceRate::new(&discs);
    let x = [SVector::from([1.0, 2.0]), SVector::from([0.5, -0.5])];
    let u = SVector::from([0.3, 0.1]);
    let before = allocations();
    let mut acc = 0.0;
    for _ in 0..100 {
        acc += g.value(&x, &u) + g.gradient(&x, &u).u[0] + g.hessian(&x, &u).xu[1][(0, 0)];
    }
    let after = allocations();
    assert_eq!(after - before, 0, "allocations in a jet function");
    assert!(acc.is_finite() && acc != 0.0);
}
