//! The attributes of `retract`: `#[higher_order_lagrangian]` (a Lagrangian into an
//! integrator and an optimal-control cost), `#[mechanical_system]` (an energy T - V into its
//! inverse dynamics and an optimal-control problem), `#[jet_function]` (a function of the jet into a
//! constraint), `#[discretization_map]` (a discretization map into its lift) and `#[helper]`
//! (a function shared by them). The expansions live in `retract-codegen`.
#![forbid(unsafe_code)]

use proc_macro::TokenStream;

/// Turns a higher-order Lagrangian L(q, q', ..., q^(k)) written as a Rust function into a
/// type with L's gradient and Hessian, the Ostrogradsky momenta and the residual and Jacobian
/// of the lifted midpoint scheme, all differentiated at compile time into straight-line,
/// allocation-free code: an integrator (`retract::step`) and an optimal-control cost
/// (`retract::OptimalControlProblem`). A runnable example is in the docs of `retract`, which
/// re-exports this attribute.
///
/// The first k + 1 arguments are the jet q, q', ..., q^(k) (`[f64; N]`, or `f64` for
/// N = 1); later arguments are parameters (`f64`, `[f64; M]`, `&[[f64; M]]`) and become
/// public fields of the generated type (`Obstacle`, from the function's name, or
/// `name = ...`). The function stays callable. Options: `order = k` (1..=4, required),
/// `name = TypeName`, `guard = false` (no singularity guard), `sphere` (a Lagrangian on the
/// unit sphere written in ambient coordinates, `[f64; 3]`: composed with a gnomonic chart,
/// see `retract::sphere`), `so3` (a Lagrangian on the rotation group written in body
/// coordinates: the arguments are the rotation R, `[f64; 9]` row major, then the body
/// angular velocity Omega and its derivatives up to Omega^(k-1), `[f64; 3]` each; composed
/// with a Gibbs chart whose centre is the field `so3_centre`, see `retract::so3`). See the
/// `retract` crate docs for the generated API.
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
/// Hessian), e.g. a stage constraint of the optimal-control solver (a runnable example is in
/// the docs of `retract`, which re-exports this attribute).
///
/// The signature, the body and the options (`order = k`, required; `name = TypeName`;
/// `sphere`; `so3`) follow
/// `#[higher_order_lagrangian]`, but g may be linear in, or independent of, q^(k): only
/// `value`, `gradient` and `hessian` in (x, u) are generated, on a type named after the
/// function (`PoleTorque`) with the parameters as public fields and `new`. The function
/// stays callable.
///
/// A function returning `[f64; m]` (1 <= m <= 64; the body ends with an array: a literal, a
/// local array or a helper's result) becomes a `retract::VectorJetFunction` instead: each
/// component g_c with its own value, gradient and Hessian, bounded component by component
/// by `OptimalControlProblem::with_vector_bounds`.
#[proc_macro_attribute]
pub fn jet_function(attr: TokenStream, item: TokenStream) -> TokenStream {
    retract_codegen::expand_jet_function(attr.into(), item.into()).into()
}

/// Turns a discretization map R_d(q, v) = (R1(q, v), R2(q, v)) on a chart of Q = R^n into a
/// `retract::map::DiscretizationMap<n, k>` on T^(k-1)Q, for the integrator of any
/// discretization map (`retract::map::step`, paper Prop. 5.1); a runnable example is in the
/// docs of `retract`, which re-exports this attribute.
///
/// The arguments are the point q and the tangent vector v (`[f64; N]`, or `f64` for N = 1),
/// then parameters (`f64`, `[f64; M]`); the body is `let` bindings of scalars (as in a
/// Lagrangian) ending with the pair of points as array literals `([R1_0, ...], [R2_0, ...])`.
/// Options: `order = k` (1..=4, required: the order of the Lagrangians it serves),
/// `name = TypeName`, `check = false`.
///
/// Generated: the function (still callable); a type named after it in UpperCamelCase
/// (`BentMidpoint`) with the parameters as public fields, `new`, `DIMENSION` and `ORDER`;
/// and the impl of `DiscretizationMap<n, k>` for the map lifted to T^(k-1)Q: with
/// x = (q, q', ..., q^(k-1)) and xi = (v, v', ..., v^(k-1)), block j of the lifted R_a is
/// the total derivative
///
/// ```text
/// R_a,j(x, xi) = D^j R_a(q, v),   D q^(i) = q^(i+1),  D v^(i) = v^(i+1)
/// ```
///
/// (`points`), its Jacobians in x and xi (`jacobians`) and the Hessian of
/// w2 . R2 - w1 . R1 in (x, xi) for run-time covectors w1, w2 (`covector_hessian`), all
/// differentiated at compile time into straight-line, allocation-free code.
///
/// Checked at compile time, each failure an error at the component of the returned arrays
/// it concerns: R_d(q, 0) = (q, q) and d_v R2 - d_v R1 = I at v = 0. A condition holds if
/// the simplifier reduces it to an identity; otherwise it is tested at 4 pseudo-random
/// points (q_a in [-1, 1], parameter components in [0.25, 1.25]) with relative tolerance
/// 1e-12, which catches every map that violates it on an open set of those points but not
/// one that violates it only on a set of measure zero. A condition that depends on a
/// user constant (whose value the macro cannot see) is an error. `check = false` skips the
/// checks, for maps that are discretization maps only on a submanifold, such as the
/// projection (q + v)/|q + v| on the sphere written in ambient coordinates.
#[proc_macro_attribute]
pub fn discretization_map(attr: TokenStream, item: TokenStream) -> TokenStream {
    retract_codegen::expand_discretization_map(attr.into(), item.into()).into()
}

/// Turns a mechanical Lagrangian l(q, q') = T - V written as a Rust function into its
/// inverse dynamics and an optimal-control problem of order 2, differentiated at compile
/// time: with D the total time derivative and Q_nc(q, q') the non-conservative generalized
/// forces (`forces = f`, none by default),
///
/// ```text
/// tau(q, q', q'') = D dl/dq' - dl/dq - Q_nc = M(q, q') q'' + d2l/dq'dq q' - dl/dq - Q_nc,
/// M = d2l/dq'2
/// ```
///
/// is the generalized force the motion needs from the inputs u in R^m, tau = B(q) u. The
/// generated type (named after the function in UpperCamelCase, or `name = ...`; the
/// parameters are its public fields, as for `#[higher_order_lagrangian]`) has the methods
/// `tau(&q, &dq, &ddq)`, `mass_matrix(&q, &dq)`, `nonconservative_force(&q, &dq)`,
/// `input(&q, &dq, &ddq)` (the u the motion needs) and `input_force(&q, &u)` (B(q) u), with
/// `input_functions = true` also `input_functions()` (each u_j a `retract::InputComponent`, a
/// `JetFunction` with its gradient and Hessian, for bounds on the inputs through
/// `with_function_bounds`; off by default, as each costs a symbolic Hessian), and is
/// itself the optimal-control Lagrangian of order 2 (`retract::Lagrangian<n, 2>`,
/// `LiftedSystem`, for `retract::OptimalControlProblem`)
///
/// ```text
/// L(q, q', q'') = R/2 |u|^2 + C(q, q', u),   u = u(q, q', q''),
/// ```
///
/// with C the user's cost (`cost = f`, none by default), while what no input can supply must
/// vanish: the passive equalities `unactuated_torques()` (each a `retract::TorqueComponent`,
/// a `JetFunction`), handed to the problem by `with_equalities`. The actuation is either
///
/// - `actuated = [i, ...]` (the actuated coordinates, indices of q; all of them by default):
///   u = tau on them, tau_c = 0 on the others; or
/// - `input_matrix = f`, B(q) with m = n or n - 1 columns of full rank: u = B^{-1} tau (square)
///   or u = (B^T B)^{-1} B^T tau, and then the one equality a(q)^T tau = 0 with
///   a_i = (-1)^i det B_(i) (B without row i), which spans what B^T annihilates: tau = B u
///   exactly where it holds.
///
/// For plant simulation, `plant()` is l itself as a system of order 1 (the type
/// `<Type>Plant`): `retract::forced::forced_step(&plant, &z0, &force, h, &options)` with
/// `force = system.input_force(&q, &u)` (plus `nonconservative_force` at the step's midpoint
/// where there are forces) is the forced midpoint rule (discrete Lagrange-d'Alembert), with
/// the typed errors of every step. A runnable example is in the docs of `retract`, which
/// re-exports this attribute.
///
/// The arguments are q and q' (`[f64; N]`, or `f64` for N = 1), then the parameters; the body
/// follows the rules of `#[higher_order_lagrangian]` (helpers included). The functions of
/// `forces`, `input_matrix` and `cost` are helpers (`#[helper]` before the system, or `fn`s in
/// its body) whose arguments are taken by name from the system's (q, q' and the parameters;
/// `u: [f64; m]` for the cost): `fn damping(dq: [f64; 2], c: f64) -> [f64; 2]` returns Q_nc,
/// `fn thrust(q: [f64; 3], r: f64) -> ([f64; 3], [f64; 3])` the columns of B (`[f64; n]`
/// for one input), `fn effort(q: [f64; 2], u: [f64; 1], k: f64) -> f64` the cost. Options:
/// `actuated = [i, ...]` or `input_matrix = f`, `forces = f`, `cost = f`, `weight = R` (a
/// positive literal, 1 by default), `input_functions = true`, `name = TypeName`,
/// `guard = false`, `helpers = [...]`,
/// `order = 1` (the only order). Errors at the span: an order other than 1 or an argument that
/// looks like q'' (`ddq`), an actuated index out of range or repeated, `actuated` with
/// `input_matrix`, a function that is not a helper, takes an argument the system does not
/// have or returns the wrong shape, an actuation matrix with too many or too few columns or
/// constant without full column rank, a Lagrangian without kinetic energy, linear in q', or
/// with a constant singular mass matrix.
#[proc_macro_attribute]
pub fn mechanical_system(attr: TokenStream, item: TokenStream) -> TokenStream {
    retract_codegen::expand_mechanical_system(attr.into(), item.into()).into()
}

/// Marks a helper function that Lagrangians and stage constraints of the same crate may call:
/// `#[helper] fn torque(q: [f64; 2], dq: [f64; 2], ddq: [f64; 2]) -> [f64; 2] { ... }`, then
/// `#[higher_order_lagrangian(order = 2, helpers = [torque])]` (or `#[jet_function(...)]`) on
/// each function that calls it. The helper's arguments are `f64` or `[f64; n]`, it returns an
/// `f64`, an array or a tuple of them, and its body is what a Lagrangian may contain; each
/// call is inlined, so the derivatives see through it. The function stays callable. A helper
/// is visible to the items after it in its module (it travels as a `macro_rules!` of the same
/// name).
#[proc_macro_attribute]
pub fn helper(attr: TokenStream, item: TokenStream) -> TokenStream {
    retract_codegen::expand_helper(attr.into(), item.into()).into()
}

/// The end of a `helpers = [...]` chain (generated code only; see [`macro@helper`]).
#[doc(hidden)]
#[proc_macro]
pub fn expand_with_helpers(input: TokenStream) -> TokenStream {
    retract_codegen::expand_with_helpers(input.into()).into()
}
