//! The `#[higher_order_lagrangian]` and `#[jet_function]` attributes of `retract`; the
//! expansions live in `retract-codegen`.
#![forbid(unsafe_code)]

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
/// `name = TypeName`. See the `retract` crate docs for the generated API.
///
/// The type name is the function's in UpperCamelCase; where that is not a type name (`_1`,
/// `_2d_arm`, `self_`) the macro asks for `name = ...`. Compile-time integers (indices, loop
/// bounds, `powi` exponents) are i64 with overflow checks; indices go up to 4 294 967 295,
/// range loops unroll at most 10 000 statements; beyond, an error at the span. Constants
/// are folded exactly as f64 evaluates them (NaN and infinities included).
///
/// Limits (beyond them, an error at the span, never an abort): dimension times order
/// n k <= 64 (n <= 64 at order 1, 32 at order 2, 21 at order 3, 16 at order 4), which keeps
/// the expansion within seconds; parameter arrays `[f64; M]` and lists `&[[f64; M]]` with
/// M <= 4 294 967 295; the unrolled statements of range loops, above. Any input within them
/// expands to code that nests at most 66 levels (long chains of `let`s and unrolled
/// recurrences are cut into temporaries), so rustc does not overflow its stack on it.
#[proc_macro_attribute]
pub fn higher_order_lagrangian(attr: TokenStream, item: TokenStream) -> TokenStream {
    retract_codegen::expand(attr.into(), item.into()).into()
}

/// Turns a scalar function of the jet into a `retract::JetFunction` (value, gradient and
/// Hessian), e.g. a stage constraint of the optimal-control solver.
///
/// ```text
/// #[jet_function(order = 2)]
/// fn pole_torque(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2], mp: f64, l: f64, g: f64) -> f64 {
///     mp * l * q[1].cos() * ddq[0] + mp * l * l * ddq[1] + mp * g * l * q[1].sin()
/// }
/// ```
///
/// The signature, the body and the options (`order = k`, required; `name = TypeName`) follow
/// `#[higher_order_lagrangian]`, but g may be linear in, or independent of, q^(k): only
/// `value`, `gradient` and `hessian` in (x, u) are generated, on a type named after the
/// function (`PoleTorque`) with the parameters as public fields and `new`. The function
/// stays callable.
#[proc_macro_attribute]
pub fn jet_function(attr: TokenStream, item: TokenStream) -> TokenStream {
    retract_codegen::expand_jet_function(attr.into(), item.into()).into()
}
