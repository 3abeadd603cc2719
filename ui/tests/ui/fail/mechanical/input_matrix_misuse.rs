#![allow(unused)]
use retract::{helper, mechanical_system};

#[helper]
fn push() -> [f64; 2] {
    [1.0, 0.0]
}

// the actuation is the actuated coordinates or the matrix B(q), not both
#[mechanical_system(actuated = [0], input_matrix = push)]
fn cart(q: [f64; 2], dq: [f64; 2]) -> f64 {
    0.5 * dq[0] * dq[0] + 0.5 * dq[1] * dq[1] - q[1].cos()
}

// two inputs that push the same way: B does not have full column rank
#[mechanical_system(input_matrix = twins)]
fn twin(q: [f64; 2], dq: [f64; 2]) -> f64 {
    fn twins() -> ([f64; 2], [f64; 2]) {
        ([1.0, 0.0], [2.0, 0.0])
    }
    0.5 * dq[0] * dq[0] + 0.5 * dq[1] * dq[1] - q[1].cos()
}

// one input for three coordinates leaves two passive directions
#[mechanical_system(input_matrix = lift)]
fn body(q: [f64; 3], dq: [f64; 3]) -> f64 {
    fn lift(q: [f64; 3]) -> [f64; 3] {
        [-q[2].sin(), q[2].cos(), 0.0]
    }
    0.5 * (dq[0] * dq[0] + dq[1] * dq[1] + dq[2] * dq[2]) - q[1]
}

fn main() {}
