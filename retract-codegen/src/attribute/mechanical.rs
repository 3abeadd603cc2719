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
use crate::front::lower::{Guard, Lower};
use crate::front::signature::{Attribute, Kind, Signature};
use crate::ir::graph::{Graph, Id};
use crate::mechanics::euler_lagrange::{self, EulerLagrange, NotMechanical};
use crate::mechanics::{self, Mechanics, Reduced};
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
    if let Some(chain) = helper::chain_if_named(&attr, "mechanical_system", &item)? {
        return Ok(chain);
    }
    let actuation = actuation::parse(attr.clone())?;
    pipeline::run(&mut MechanicalPasses { actuation }, attr, item)
}

/// The passes of `#[mechanical_system]`, with the actuation read from the options.
struct MechanicalPasses {
    actuation: Actuation,
}

/// l and its guarded expressions, as lowered.
struct Lowered {
    root: Id,
    guards: Vec<Guard>,
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
    /// d2L/du2 is accepted for the optimal-control Lagrangian), or why there are none.
    fn build(
        graph: &mut Graph,
        sig: Signature,
        root: Id,
        guards: Vec<Guard>,
    ) -> Result<Self, mechanics::Degenerate> {
        let (n, k) = (sig.dim, sig.order);
        let mech = mechanics::build_with(graph, root, n, k, k == 2)?;
        let guards = mechanics::guards_at_step_points(graph, guards, &sig);
        let reduced = mechanics::reduce(graph, &mech.gradient, &mech.hessian, n, k);
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
    actuated: Vec<usize>,
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
        let root = lower.body(&function.block);
        Lowered {
            root,
            guards: std::mem::take(&mut lower.guards),
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
        let euler_lagrange = euler_lagrange::build(graph, lowered.root, n, &actuated)
            .map_err(|reason| not_mechanical(sig, reason))?;
        let cost =
            euler_lagrange::effort(graph, &euler_lagrange.tau, &actuated, self.actuation.weight);
        let dq = sig.jet[1].span();
        let system =
            System::build(graph, order_two(sig), cost, lowered.guards.clone()).map_err(|_| {
                syn::Error::new(
                    dq,
                    "the actuated rows of the mass matrix vanish: no actuator moves the system",
                )
            })?;
        let plant = System::build(graph, plant_signature(sig), lowered.root, lowered.guards)
            .map_err(|_| not_mechanical(sig, NotMechanical::Singular))?;
        Ok(Derived {
            system,
            plant,
            euler_lagrange,
            actuated,
        })
    }

    fn emit(&self, function: &ItemFn, _: &Signature, graph: &Graph, d: Derived) -> TokenStream {
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
            &d.actuated,
        ));
        out
    }
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
        // fully actuated by default: no equality
        let out = expand("", "", ENERGY).unwrap();
        assert!(
            out.contains("pub const UNACTUATED: [usize; 0] = []"),
            "{out}"
        );
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
        assert!(err("sphere", "", ENERGY).contains("unsupported option"));
        assert!(err("", "", "q[0].cos()").contains("no kinetic energy"));
        assert!(err("", "", "dq[0] + q[0]").contains("linear in `dq`"));
        let singular = err("", "", "0.5 * (dq[0] + dq[1]).powi(2) - q[1].cos()");
        assert!(singular.contains("singular constant matrix"), "{singular}");
        // a parameter of the jet's type with another name is a parameter
        assert!(expand("", ", k: [f64; 2]", ENERGY).is_ok());
    }
}
