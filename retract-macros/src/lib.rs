//! The `#[higher_order_lagrangian]` attribute of `retract`.
//!
//! It reads a Lagrangian written as a plain Rust function, differentiates it symbolically at
//! compile time and emits straight-line code for the `retract_core` traits. The stages, one
//! module each: `signature` (order, dimension, parameters) -> `lower` (body to a
//! hash-consed expression graph) -> `mechanics` (gradient, Hessian, momenta, scheme) ->
//! `codegen` (one `let` per shared node). `expand` is an ordinary function over
//! `proc_macro2` tokens, unit-tested without the compiler.
#![forbid(unsafe_code)]

mod codegen;
mod diff;
mod expand;
mod graph;
mod lower;
mod mechanics;
mod signature;

use proc_macro::TokenStream;

/// Turns a higher-order Lagrangian into an integrator.
///
/// ```text
/// #[higher_order_lagrangian(order = 2)]
/// fn obstacle(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], tau: f64) -> f64 {
///     0.5 * (ddq[0].powi(2) + ddq[1].powi(2)) + tau / (q[0].powi(2) + q[1].powi(2) - 1.0)
/// }
/// ```
///
/// The first k + 1 arguments are the jet q, q', ..., q^(k) (`[f64; N]`, or `f64` for
/// N = 1); later arguments are parameters (`f64`, `[f64; M]`, `&[[f64; M]]`) and become
/// public fields of the generated type (`Obstacle`, from the function's name, or
/// `name = ...`). The function stays callable. Options: `order = k` (1..=4, required),
/// `name = TypeName`.
#[proc_macro_attribute]
pub fn higher_order_lagrangian(attr: TokenStream, item: TokenStream) -> TokenStream {
    expand::expand(attr.into(), item.into()).into()
}
