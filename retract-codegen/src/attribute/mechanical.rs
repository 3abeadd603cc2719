//! `#[mechanical_system]` as a plain function, `TokenStream -> TokenStream`: its passes of
//! the pipeline (`crate::pipeline`). The body, a mechanical Lagrangian l(q, q') = T - V, is
//! lowered as a Lagrangian of order 1; the mechanics pass derives its Euler-Lagrange
//! operator tau (`mechanics::euler_lagrange`), the optimal-control Lagrangian of order 2,
//! L = R/2 sum tau_a^2 over the actuated coordinates, and the mechanics of L as
//! `#[higher_order_lagrangian]` would, and those of l itself for the plant; the emission is
//! L's system and l's plant (`emit::system_items`) and the inverse dynamics with the
//! unactuated components of tau (`emit::mechanical`).

use proc_macro2::{Span, TokenStream};
use syn::ItemFn;

use super::helper;
use crate::emit::mechanical::mechanical_impl;
use crate::emit::{Emission, system_items};
use crate::front::actuation::{self, Actuation};
use crate::front::lower::{Guard, Lower, Returned};
use crate::front::signature::{Attribute, Kind, Signature};
use std::collections::HashMap;

use crate::ir::diff::substitute;
use crate::ir::graph::{Graph, Id, Var};
use crate::mechanics::euler_lagrange::{
    self, BadInputMatrix, EulerLagrange, Inputs, NotMechanical,
};
use crate::mechanics::{self, Derivation, Mechanics, Reduced};
use crate::pipeline::{self, Passes, fail_softly};

/// Expands `#[mechanical_system(attr)] item`; on error, the original item plus
/// `compile_error!`s. Never panics.
pub fn expand_mechanical_system(attr: TokenStream, item: TokenStream) -> TokenStream {
    fail_softly(item.clone(), try_expand_mechanical_system(attr, item))
}

/// The expansion, or the errors of the input combined into one `syn::Error`.
pub fn try_expand_mechanical_system(
    attr: TokenStream,
    item: TokenStream,
) -> syn::Result<TokenStream> {
    let actuation = actuation::parse(attr.clone())?;
    let named: Vec<syn::Ident> = actuation.functions().cloned().collect();
    if let Some(chain) = helper::chain_if_named_or_used(&attr, "mechanical_system", &item, &named)?
    {
        return Ok(chain);
    }
    pipeline::run(&mut MechanicalPasses { actuation }, attr, item)
}

/// The passes of `#[mechanical_system]`, with the actuation read from the options.
struct MechanicalPasses {
    actuation: Actuation,
}

/// l and its guarded expressions, as lowered, with the values of the functions the options
/// name: Q_nc, the columns of B, and the cost C with u_j as the placeholder `Var::Core(j)`.
struct Lowered {
    root: Id,
    guards: Vec<Guard>,
    forces: Option<Vec<Id>>,
    columns: Option<Vec<Vec<Id>>>,
    cost: Option<Id>,
}

/// A system to emit: its signature, its mechanics, its guards, the reduced step.
struct System {
    sig: Signature,
    mech: Mechanics,
    guards: Vec<(Guard, [Id; 3])>,
    reduced: Option<Reduced>,
}

impl System {
    /// The mechanics of the Lagrangian `root` of signature `sig` (a constant singular
    /// d2L/du2 is accepted for the optimal-control Lagrangian), built structurally where
    /// `structural`, or why there are none.
    fn build(
        graph: &mut Graph,
        sig: Signature,
        root: Id,
        guards: Vec<Guard>,
        structural: bool,
    ) -> Result<Self, mechanics::Degenerate> {
        let (n, k) = (sig.dim, sig.order);
        let how = Derivation {
            singular_allowed: k == 2,
            structural,
        };
        let mech = mechanics::build_with(graph, root, n, k, how)?;
        let guards = mechanics::guards_at_step_points(graph, guards, &sig);
        // (the structural Hessian holds the rows of u alone: no reduced step, which needs all)
        let reduced = if how.structural {
            None
        } else {
            mechanics::reduce(graph, &mech.gradient, &mech.hessian, n, k)
        };
        Ok(System {
            sig,
            mech,
            guards,
            reduced,
        })
    }

    /// Its items (`emit::system_items`), and its emission context for more.
    fn emission<'a>(&'a self, function: &'a ItemFn, graph: &'a Graph) -> Emission<'a> {
        Emission::new(
            function,
            &self.sig,
            graph,
            &self.mech,
            &self.guards,
            self.reduced.as_ref(),
        )
    }
}

/// The optimal-control system of order 2 and the plant of order 1, with tau and the
/// actuated coordinates.
struct Derived {
    system: System,
    plant: System,
    euler_lagrange: EulerLagrange,
    /// The actuated coordinates; `None` with an actuation matrix.
    actuated: Option<Vec<usize>>,
}

impl Passes for MechanicalPasses {
    const ATTRIBUTE: Attribute = Attribute::Mechanical;
    type Lowered = Lowered;
    type Derived = Derived;

    fn lower(&mut self, lower: &mut Lower<'_>, function: &ItemFn, sig: &Signature) -> Lowered {
        if let Some(p) = sig.params.first()
            && p.kind == Kind::Array(sig.dim)
            && !sig.scalar_jet
            && p.name.to_string().starts_with("dd")
        {
            lower.errors.push(syn::Error::new(
                p.name.span(),
                format!(
                    "`{}` looks like the acceleration q'': a mechanical Lagrangian is \
                     l(q, q') = T - V, of order 1 (the attribute derives the terms in q'', \
                     M(q) q'', itself); remove it, or rename it if it is a parameter",
                    p.name
                ),
            ));
        }
        // (before the body, whose locals would shadow the arguments taken by name)
        let (forces, columns, cost) = self.named_functions(lower, function, sig);
        let root = lower.body(&function.block);
        Lowered {
            root,
            guards: std::mem::take(&mut lower.guards),
            forces,
            columns,
            cost,
        }
    }

    fn charts(&mut self, _: &mut Graph, sig: Signature, lowered: Lowered) -> (Signature, Lowered) {
        // (a mechanical system lives on R^n: the signature refuses the chart options)
        (sig, lowered)
    }

    fn mechanics(
        &mut self,
        graph: &mut Graph,
        sig: &Signature,
        lowered: Lowered,
    ) -> syn::Result<Derived> {
        let n = sig.dim;
        let actuated = self.actuation.coordinates(n)?;
        let inputs = match lowered.columns {
            Some(columns) => Inputs::Matrix(columns),
            None => Inputs::Coordinates(&actuated),
        };
        let euler_lagrange = euler_lagrange::build(
            graph,
            lowered.root,
            n,
            lowered.forces.as_deref(),
            inputs,
            self.actuation.input_functions,
        )
        .map_err(|reason| match reason {
            Ok(reason) => not_mechanical(sig, reason),
            Err(bad) => bad_input_matrix(&self.actuation, bad, n),
        })?;
        // the user's cost and every guard with u_j in place of its placeholder
        let input = euler_lagrange.input.clone();
        let with_input = |_: &mut Graph, v: Var| match v {
            Var::Core(j) => input.get(j as usize).copied(),
            _ => None,
        };
        let mut memo = HashMap::new();
        let user_cost = lowered
            .cost
            .map(|c| substitute(graph, c, &with_input, &mut memo));
        let mut guards = lowered.guards;
        for guard in &mut guards {
            guard.node = substitute(graph, guard.node, &with_input, &mut memo);
        }
        let cost = euler_lagrange::effort(
            graph,
            &euler_lagrange.input,
            self.actuation.weight,
            user_cost,
        );
        let dq = sig.jet[1].span();
        // (the optimal-control Lagrangian, a function of tau, is built structurally)
        let system =
            System::build(graph, order_two(sig), cost, guards.clone(), true).map_err(|_| {
                syn::Error::new(
                    dq,
                    "the actuated rows of the mass matrix vanish: no actuator moves the system",
                )
            })?;
        // (the plant's guards are those of l: the cost's are no part of it)
        let plant_guards = guards
            .into_iter()
            .filter(|guard| !depends_on_input(graph, guard.node, &euler_lagrange.input))
            .collect();
        // (the plant too where its mass matrix varies: then no reduced step applies, its
        // rows of q' in the Hessian varying, and the symbolic scheme would only add code)
        let varying_mass = euler_lagrange
            .mass
            .iter()
            .any(|&m| mechanics::depends_on(graph, m, &|v| matches!(v, Var::Jet { .. })));
        let plant = System::build(
            graph,
            plant_signature(sig),
            lowered.root,
            plant_guards,
            varying_mass,
        )
        .map_err(|_| not_mechanical(sig, NotMechanical::Singular))?;
        let actuated = self.actuation.input_matrix.is_none().then_some(actuated);
        Ok(Derived {
            system,
            plant,
            euler_lagrange,
            actuated,
        })
    }

    fn emit(&self, function: &ItemFn, _: &Signature, graph: &Graph, d: Derived) -> TokenStream {
        // (a parameter may serve only the functions the options name: forces, B, cost)
        let mut function = function.clone();
        function
            .attrs
            .push(syn::parse_quote!(#[allow(unused_variables)]));
        let function = &function;
        let (emission, plant) = (
            d.system.emission(function, graph),
            d.plant.emission(function, graph),
        );
        let mut out = system_items(&emission);
        out.extend(system_items(&plant));
        out.extend(mechanical_impl(
            &emission,
            &plant,
            &d.euler_lagrange,
            d.actuated.as_deref(),
        ));
        out
    }
}

/// The values of the functions the options name: Q_nc, the columns of B, the cost.
type NamedFunctions = (Option<Vec<Id>>, Option<Vec<Vec<Id>>>, Option<Id>);

impl MechanicalPasses {
    /// Lowers the functions the options name (`forces`, `input_matrix`, `cost`), each
    /// checked for its shape at the span of its return type: Q_nc and the columns of B are
    /// arrays of n (a number where n = 1), the cost a number with u_j as `Var::Core(j)`.
    fn named_functions(
        &self,
        lower: &mut Lower<'_>,
        function: &ItemFn,
        sig: &Signature,
    ) -> NamedFunctions {
        let (n, stmts) = (sig.dim, &function.block.stmts);
        let call = |lower: &mut Lower<'_>, name: &syn::Ident, role, extra: &[(&str, Vec<Id>)]| {
            lower.call_by_name(stmts, name, role, extra)
        };
        fn refuse<T>(lower: &mut Lower<'_>, span: Span, msg: String) -> Option<T> {
            lower.errors.push(syn::Error::new(span, msg));
            None
        }
        let array = |returned: Returned| match returned {
            Returned::Array(ids) if ids.len() == n => Some(ids),
            Returned::Number(id) if n == 1 => Some(vec![id]),
            _ => None,
        };
        let forces = self.actuation.forces.as_ref().and_then(|name| {
            let (returned, span) = call(lower, name, "forces", &[])?;
            array(returned).or_else(|| {
                let msg = format!(
                    "`{name}` returns the non-conservative forces Q_nc(q, q'), one per \
                     coordinate: `[f64; {n}]`"
                );
                refuse(lower, span, msg)
            })
        });
        let columns = self.actuation.input_matrix.as_ref().and_then(|name| {
            let (returned, span) = call(lower, name, "input_matrix", &[])?;
            let columns = match returned {
                Returned::Arrays(columns) => columns
                    .into_iter()
                    .map(|c| array(Returned::Array(c)))
                    .collect(),
                single => array(single).map(|c| vec![c]),
            };
            columns.or_else(|| {
                let msg = format!(
                    "`{name}` returns the columns of the actuation matrix B(q), the generalized \
                     force of each input: `[f64; {n}]` for one input, a tuple `([f64; {n}], \
                     [f64; {n}], ...)` for several"
                );
                refuse(lower, span, msg)
            })
        });
        let inputs = match (&columns, self.actuation.coordinates(n)) {
            (Some(columns), _) => columns.len(),
            (None, Ok(actuated)) => actuated.len(),
            (None, Err(_)) => n, // (reported by the mechanics pass)
        };
        let cost = self.actuation.cost.as_ref().and_then(|name| {
            let u: Vec<Id> = (0..inputs)
                .map(|j| lower.g.var(Var::Core(j as u32)))
                .collect();
            match call(lower, name, "cost", &[("u", u)])? {
                (Returned::Number(id), _) => Some(id),
                (_, span) => refuse(
                    lower,
                    span,
                    format!("`{name}` returns the cost C(q, q', u), an `f64`"),
                ),
            }
        });
        (forces, columns, cost)
    }
}

/// Whether `node` depends on an input's expression (a term of the cost).
fn depends_on_input(g: &Graph, node: Id, input: &[Id]) -> bool {
    let mut stack = vec![node];
    let mut seen = std::collections::HashSet::new();
    while let Some(id) = stack.pop() {
        if input.contains(&id) {
            return true;
        }
        if seen.insert(id) {
            stack.extend(crate::ir::graph::children(g.node(id)));
        }
    }
    false
}

/// The error of an actuation matrix that makes no actuation, at the option's value.
fn bad_input_matrix(actuation: &Actuation, bad: BadInputMatrix, n: usize) -> syn::Error {
    let span = actuation
        .input_matrix
        .as_ref()
        .map_or_else(Span::call_site, syn::Ident::span);
    let msg = match bad {
        BadInputMatrix::Rows(rows) => {
            format!("a column of the actuation matrix has {rows} entries, not {n}")
        }
        BadInputMatrix::TooManyInputs(m) => format!(
            "the actuation matrix has {m} columns for {n} coordinates: at most {n} inputs \
             can be told apart"
        ),
        BadInputMatrix::TooManyPassive(m) => format!(
            "the actuation matrix has {m} column{} for {n} coordinates: {} passive directions; \
             an actuation matrix may leave at most one (n - 1 or n columns): use `actuated = \
             [..]` where the inputs drive coordinates",
            if m == 1 { "" } else { "s" },
            n - m
        ),
        BadInputMatrix::RankDeficient => "the actuation matrix does not have full column rank: \
             some input moves nothing, or two inputs move the same way"
            .to_string(),
    };
    syn::Error::new(span, msg)
}

/// The signature of the order-2 optimal-control Lagrangian: `sig` with q'' added to the jet.
fn order_two(sig: &Signature) -> Signature {
    let mut jet = sig.jet.clone();
    jet.push(syn::Ident::new("ddq", Span::call_site()));
    Signature {
        order: 2,
        jet,
        ..sig.clone()
    }
}

/// The signature of the plant: `sig` (of l, order 1) with the type `<Type>Plant`.
fn plant_signature(sig: &Signature) -> Signature {
    let name = &sig.type_name;
    Signature {
        type_name: syn::Ident::new(&format!("{name}Plant"), name.span()),
        ..sig.clone()
    }
}

/// The error of a Lagrangian whose mass matrix is no mass matrix, at q'.
fn not_mechanical(sig: &Signature, reason: NotMechanical) -> syn::Error {
    let dq = &sig.jet[1];
    let msg = match reason {
        NotMechanical::NoVelocity => format!(
            "the Lagrangian does not depend on `{dq}` = q': it has no kinetic energy, so no \
             mass matrix; write l = T - V with T = 1/2 q'^T M(q) q'"
        ),
        NotMechanical::Linear => format!(
            "the Lagrangian is linear in `{dq}` = q': its mass matrix d2l/d{dq}2 vanishes; \
             write l = T - V with T = 1/2 q'^T M(q) q', M positive definite"
        ),
        NotMechanical::Singular => format!(
            "the mass matrix d2l/d{dq}2 is a singular constant matrix (or has a non-finite \
             entry): the accelerations of some coordinates have no inertia; every component of \
             `{dq}` must enter the kinetic energy with a positive weight"
        ),
    };
    syn::Error::new(dq.span(), msg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The expansion of `#[mechanical_system(attr)]` on l(q, q') with `body`, or the messages.
    fn expand(attr: &str, args: &str, body: &str) -> Result<String, String> {
        crate::util::pretty_expansion(
            try_expand_mechanical_system,
            attr,
            &format!("fn cart(q: [f64; 2], dq: [f64; 2]{args}) -> f64 {{ {body} }}"),
        )
    }

    const ENERGY: &str = "0.5 * dq[0] * dq[0] + 0.5 * (1.0 + q[0].powi(2)) * dq[1] * dq[1] \
                          - q[1].cos()";

    #[test]
    fn the_items_of_a_mechanical_system_are_generated() {
        let out = expand("actuated = [1], weight = 2.0", "", ENERGY).unwrap();
        for item in [
            "struct Cart;",
            "struct CartPlant;",
            "pub fn plant(",
            "pub fn input_force(",
            "Lagrangian<2, 1> for CartPlant",
            "pub fn tau(",
            "pub fn mass_matrix(",
            "pub fn unactuated_torques(",
            "pub const ACTUATED: [usize; 1] = [1]",
            "pub const UNACTUATED: [usize; 1] = [0]",
            "MechanicalSystem<2> for Cart",
            "Lagrangian<2, 2> for Cart",
        ] {
            assert!(out.contains(item), "{item} missing:\n{out}");
        }
        // the input functions only where asked for (each costs a symbolic Hessian)
        assert!(!out.contains("fn input_functions(") && !out.contains("fn input_value("));
        // fully actuated by default: no equality
        let out = expand("", "", ENERGY).unwrap();
        assert!(
            out.contains("pub const UNACTUATED: [usize; 0] = []"),
            "{out}"
        );
        let out = expand("actuated = [1], input_functions = true", "", ENERGY).unwrap();
        for item in [
            "pub fn input_functions(",
            "InputComponent<'_, Self>; 1]",
            "fn input_value(",
            "fn input_gradient(",
            "fn input_hessian(",
        ] {
            assert!(out.contains(item), "{item} missing:\n{out}");
        }
    }

    #[test]
    fn what_makes_no_mechanical_system_is_an_error() {
        let err = |attr: &str, args: &str, body: &str| expand(attr, args, body).unwrap_err();
        assert!(err("order = 2", "", ENERGY).contains("is of order 1, not 2"));
        assert!(err("", ", ddq: [f64; 2]", ENERGY).contains("looks like the acceleration"));
        let range = err("actuated = [0, 2]", "", ENERGY);
        assert!(
            range.contains("actuated coordinate 2 out of range"),
            "{range}"
        );
        assert!(err("actuated = [1, 1]", "", ENERGY).contains("listed twice"));
        assert!(err("actuated = []", "", ENERGY).contains("at least one"));
        assert!(err("actuated = [a]", "", ENERGY).contains("integer literals"));
        assert!(err("weight = -1.0", "", ENERGY).contains("positive finite"));
        assert!(err("input_functions = 1", "", ENERGY).contains("`true` or `false`"));
        assert!(err("sphere", "", ENERGY).contains("unsupported option"));
        assert!(err("", "", "q[0].cos()").contains("no kinetic energy"));
        assert!(err("", "", "dq[0] + q[0]").contains("linear in `dq`"));
        let singular = err("", "", "0.5 * (dq[0] + dq[1]).powi(2) - q[1].cos()");
        assert!(singular.contains("singular constant matrix"), "{singular}");
        // a parameter of the jet's type with another name is a parameter
        assert!(expand("", ", k: [f64; 2]", ENERGY).is_ok());
    }

    #[test]
    fn forces_input_matrix_and_cost_are_helpers_taken_by_name() {
        let body = format!(
            "fn damping(dq: [f64; 2], c: f64) -> [f64; 2] {{ [-c * dq[0], -c * dq[1]] }} \
             fn drive(q: [f64; 2]) -> [f64; 2] {{ [1.0, q[0].sin()] }} \
             fn extra(u: [f64; 1], q: [f64; 2]) -> f64 {{ q[0] * u[0] }} {ENERGY}"
        );
        let out = expand(
            "input_matrix = drive, forces = damping, cost = extra",
            ", c: f64",
            &body,
        )
        .unwrap();
        for item in [
            "pub const INPUTS: usize = 1",
            "pub const PASSIVE: [usize; 1] = [0]",
            "pub fn nonconservative_force(",
            "pub fn input(",
        ] {
            assert!(out.contains(item), "{item} missing:\n{out}");
        }
        assert!(!out.contains("pub const ACTUATED"), "{out}");
    }

    /// The n-link chain written as T - V: its expansion (statements, counted as `;`) grows
    /// about linearly from n = 3 to 6 (ratio 2; the n^2 entries of the mass matrix are a
    /// small part). The Euler-Lagrange operator by one forward derivative per coordinate grew
    /// as n^2 (ratio 4), the expansion that differentiated the effort and the scheme
    /// symbolically as n^4.5 to n^5 (ratio 23 to 32).
    #[test]
    fn the_chain_expansion_grows_about_linearly() {
        let statements = |n: usize| {
            let (attr, item) = crate::samples::energy_chain(n);
            let tokens = try_expand_mechanical_system(attr, item).unwrap();
            tokens.to_string().matches(';').count()
        };
        let (small, large) = (statements(3), statements(6));
        let ratio = large as f64 / small as f64;
        println!("chain statements: n = 3: {small}, n = 6: {large}, ratio {ratio:.2}");
        assert!(ratio < 3.0, "{small} -> {large} statements, ratio {ratio}");
    }

    #[test]
    fn misused_functions_are_errors_at_their_spans() {
        let err = |attr: &str, body: &str| {
            expand(attr, ", c: f64", &format!("{body} {ENERGY}")).unwrap_err()
        };
        let two = "fn f(q: [f64; 2]) -> [f64; 2] { [q[0], 0.0] }";
        // a function not in the body is a `#[helper]`'s: the chain calls its macro (rustc
        // reports a missing one at the name)
        let chained = expand("forces = nothing", ", c: f64", ENERGY).unwrap();
        assert!(chained.starts_with("nothing! {"), "{chained}");
        assert!(err("forces = 1.0", "").contains("`forces` names a helper function"));
        let unknown = err("forces = f", "fn f(x: [f64; 2]) -> [f64; 2] { x }");
        assert!(unknown.contains("taken by name"), "{unknown}");
        let scalar = err("forces = f", "fn f(c: f64) -> f64 { c }");
        assert!(scalar.contains("one per coordinate"), "{scalar}");
        let both = err("actuated = [0], input_matrix = f", two);
        assert!(both.contains("exclude each other"), "{both}");
        let three = "fn f(q: [f64; 2]) -> ([f64; 2], [f64; 2], [f64; 2]) { ([1.0, 0.0], [0.0, \
                     1.0], [1.0, 1.0]) }";
        assert!(err("input_matrix = f", three).contains("at most 2 inputs"));
        let parallel = "fn f(q: [f64; 2]) -> ([f64; 2], [f64; 2]) { ([1.0, 0.0], [2.0, 0.0]) }";
        let rank = err("input_matrix = f", parallel);
        assert!(rank.contains("full column rank"), "{rank}");
        let zero = "fn f(q: [f64; 2]) -> [f64; 2] { [0.0, 0.0] }";
        assert!(err("input_matrix = f", zero).contains("full column rank"));
        let cost = err("cost = f", two);
        assert!(cost.contains("an `f64`"), "{cost}");
    }
}
