#![allow(unused)]
use retract::higher_order_lagrangian;

// Recursion is refused at the first repeated call (not after 16 levels of copies), and a
// tree of helper calls too large to inline is refused once.
#[higher_order_lagrangian(order = 2)]
fn recursive(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1]) -> f64 {
    #[allow(unconditional_recursion)]
    fn thrice(x: f64) -> f64 {
        thrice(x) + thrice(x) + thrice(x)
    }
    fn ping(x: f64) -> f64 {
        pong(x)
    }
    fn pong(x: f64) -> f64 {
        ping(x)
    }
    0.5 * ddq[0] * ddq[0] + thrice(q[0]) + ping(dq[0])
}

#[higher_order_lagrangian(order = 2)]
fn fan_out(q: [f64; 1], dq: [f64; 1], ddq: [f64; 1]) -> f64 {
    fn f0(x: f64) -> f64 {
        x.sin()
    }
    fn f1(x: f64) -> f64 {
        f0(x) + f0(x) + f0(x)
    }
    fn f2(x: f64) -> f64 {
        f1(x) + f1(x) + f1(x)
    }
    fn f3(x: f64) -> f64 {
        f2(x) + f2(x) + f2(x)
    }
    fn f4(x: f64) -> f64 {
        f3(x) + f3(x) + f3(x)
    }
    fn f5(x: f64) -> f64 {
        f4(x) + f4(x) + f4(x)
    }
    fn f6(x: f64) -> f64 {
        f5(x) + f5(x) + f5(x)
    }
    fn f7(x: f64) -> f64 {
        f6(x) + f6(x) + f6(x)
    }
    fn f8(x: f64) -> f64 {
        f7(x) + f7(x) + f7(x)
    }
    fn f9(x: f64) -> f64 {
        f8(x) + f8(x) + f8(x)
    }
    0.5 * ddq[0] * ddq[0] + f9(q[0])
}

fn main() {}
