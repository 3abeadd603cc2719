//! The chart stages, by space: a function on the sphere (`sphere`), on SO(3) (`so3`) or on
//! SE(3) (`se3`) is composed with its chart before it is differentiated.
//!
//! Each space is one implementation of [`Chart`]: the composition and what the emitted items
//! say and do about the chart (its docs, the runtime trait that reads and moves the chart's
//! frame, the frame after `new`). The stages and the emission ask [`of`] for the chart of a
//! space, so that a new manifold is a module here, its arm in [`of`] and its runtime.

pub(crate) mod se3;
pub(crate) mod so3;
pub(crate) mod sphere;

use proc_macro2::TokenStream;

use crate::front::signature::{Kind, Param, Signature, Space};
use crate::ir::graph::{Graph, Id};

/// `roots` composed with the chart of `sig`'s space, with the signature of the composed
/// function (the chart's frame appended to the parameters); unchanged on R^n.
pub fn compose(graph: &mut Graph, sig: Signature, roots: &[Id]) -> (Signature, Vec<Id>) {
    let Some(chart) = of(sig.space) else {
        return (sig, roots.to_vec());
    };
    let roots = chart.compose(graph, &sig, roots);
    (chart_signature(&sig), roots)
}

/// A chart of a manifold on which a Lagrangian or jet function is written: the generated
/// system works in the chart, whose frame is a run-time parameter (`Space::chart_param`)
/// that the runtime reads and moves through a trait of `retract_core`.
pub(crate) trait Chart: Sync {
    /// `roots` (the function and its guarded expressions, in the arguments as written)
    /// rewritten in the chart jet; the frame is parameter number `sig.params.len()`.
    fn compose(&self, graph: &mut Graph, sig: &Signature, roots: &[Id]) -> Vec<Id>;

    /// Where the generated system lives, for its docs: the space and its chart.
    fn description(&self) -> &'static str;

    /// The arguments of L as written, for the docs of a Lagrangian of order `k`.
    fn arguments(&self, k: usize) -> String {
        format!("q, ..., q^({k})")
    }

    /// What the top argument of an order-`k` Lagrangian holds, for messages.
    fn top(&self, k: usize) -> String {
        format!("q^({k})")
    }

    /// The runtime's trait of a system in this chart: the module of `retract_core`, the
    /// trait, and its methods that read and replace the frame.
    fn runtime(&self) -> [&'static str; 4];

    /// The doc of the frame's field in the parameter struct.
    fn frame_doc(&self) -> &'static str;

    /// The frame after `new`.
    fn initial_frame(&self) -> TokenStream;
}

/// The chart of `space`; `None` on R^n.
pub(crate) fn of(space: Space) -> Option<&'static dyn Chart> {
    match space {
        Space::Flat => None,
        Space::Sphere => Some(&sphere::Sphere),
        Space::So3 => Some(&so3::So3),
        Space::Se3 => Some(&se3::Se3),
    }
}

/// The signature of the composed function: the chart's dimension (2 on the sphere, the
/// length of a body rate on a group), and the parameters of `sig` followed by the chart's
/// frame (`Space::chart_param`).
pub fn chart_signature(sig: &Signature) -> Signature {
    let mut chart = sig.clone();
    chart.dim = match sig.space.body_coordinates() {
        Some((_, rate)) => rate,
        None if sig.space == Space::Sphere => 2,
        None => sig.dim,
    };
    if let Some((name, len)) = sig.space.chart_param() {
        chart.params.push(Param {
            name: syn::Ident::new(name, proc_macro2::Span::call_site()),
            kind: Kind::Array(len),
        });
    }
    chart
}
