//! Generated sample Lagrangians for tests and benchmarks of the expansion.

use proc_macro2::TokenStream;

/// `#[higher_order_lagrangian(order = 2)]` on R^n with `obstacles` barrier terms unrolled
/// from a loop over a parameter array:
/// L = 1/2 |q''|^2 + sum_j tau / ((q_0 - c_3j)^2 + (q_1 - c_3j+1)^2 - c_3j+2^2).
/// Returns (attribute, item).
pub fn obstacle_field(n: usize, obstacles: usize) -> (TokenStream, TokenStream) {
    let attr = "order = 2".parse().unwrap_or_default();
    let second = if n > 1 { "q[1]" } else { "0.0" };
    let item = format!(
        "fn field(q: [f64; {n}], dq: [f64; {n}], ddq: [f64; {n}], tau: f64, c: [f64; {len}]) -> f64 {{
            let mut l = 0.0;
            for i in 0..{n} {{ l += 0.5 * ddq[i].powi(2); }}
            for j in 0..{obstacles} {{
                let s = (q[0] - c[3 * j]).powi(2) + ({second} - c[3 * j + 1]).powi(2)
                    - c[3 * j + 2].powi(2);
                l += tau / s;
            }}
            l
        }}",
        len = (3 * obstacles).max(1)
    );
    (attr, item.parse().unwrap_or_default())
}

/// `#[mechanical_system]` on the planar n-link chain written as T - V (unit links, unit
/// point masses at the link ends, joint angles relative to the previous link, every joint
/// driven): the velocities of the masses accumulate link by link,
/// v_j = v_{j-1} + phi_j' (cos phi_j, sin phi_j) with phi_j = q_0 + ... + q_j, and
/// l = sum_j 1/2 |v_j|^2 + 9.81 (sum_{b <= j} cos phi_b). The text of
/// `examples/common/mechanical.rs`'s `energy_chain!`. Returns (attribute, item).
pub fn energy_chain(n: usize) -> (TokenStream, TokenStream) {
    let item = format!(
        "fn chain(q: [f64; {n}], dq: [f64; {n}]) -> f64 {{
            let (mut phi, mut dphi) = (0.0, 0.0);
            let (mut vx, mut vz, mut height) = (0.0, 0.0, 0.0);
            let mut energy = 0.0;
            for i in 0..{n} {{
                phi += q[i];
                dphi += dq[i];
                vx += phi.cos() * dphi;
                vz += phi.sin() * dphi;
                height -= phi.cos();
                energy += 0.5 * (vx * vx + vz * vz) - 9.81 * height;
            }}
            energy
        }}"
    );
    (TokenStream::new(), item.parse().unwrap_or_default())
}
