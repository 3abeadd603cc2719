//! The chart stages, by space: a function on the sphere (`sphere`), on SO(3) (`so3`) or on
//! SE(3) (`se3`) is composed with its chart (`crate::charts::sphere`, `crate::charts::so3`, `crate::charts::se3`)
//! before it is differentiated.

pub(crate) mod se3;
pub(crate) mod so3;
pub(crate) mod sphere;

use crate::front::signature::{Kind, Param, Signature, Space};
use crate::ir::graph::{Graph, Id};

/// `roots` composed with the chart of `sig`'s space, with the signature of the composed
/// function (the chart's frame appended to the parameters); unchanged on R^n.
pub fn compose(graph: &mut Graph, sig: Signature, roots: &[Id]) -> (Signature, Vec<Id>) {
    let roots = match sig.space {
        Space::Flat => return (sig, roots.to_vec()),
        Space::Sphere => sphere::compose(graph, &sig, roots),
        Space::So3 => so3::compose(graph, &sig, roots),
        Space::Se3 => se3::compose(graph, &sig, roots),
    };
    (chart_signature(&sig), roots)
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
