//! The chart stages, by space: a function on the sphere (`sphere`) or on SO(3) (`so3`) is
//! composed with its chart (`crate::sphere`, `crate::so3`) before it is differentiated.

use crate::graph::{Graph, Id};
use crate::signature::{Signature, Space};
use crate::{so3, sphere};

/// `roots` composed with the chart of `sig`'s space, with the signature of the composed
/// function (the chart's frame appended to the parameters); unchanged on R^n.
pub fn compose(graph: &mut Graph, sig: Signature, roots: &[Id]) -> (Signature, Vec<Id>) {
    match sig.space {
        Space::Flat => (sig, roots.to_vec()),
        Space::Sphere => (
            sphere::chart_signature(&sig),
            sphere::compose(graph, &sig, roots),
        ),
        Space::So3 => (so3::chart_signature(&sig), so3::compose(graph, &sig, roots)),
    }
}
