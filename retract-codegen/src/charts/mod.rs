//! The spaces a function can live on, each behind one trait [`Chart`]: R^n (`flat`), the
//! sphere (`sphere`), SO(3) (`so3`) and SE(3) (`se3`). A function on a manifold is composed
//! with its chart before it is differentiated, so that the later stages see R^n.
//!
//! Everything the pipeline knows about a space is in its implementation of [`Chart`]: the
//! attribute option that selects it and the arguments it requires (for the front end), the
//! composition, the chart's dimension, and what the emitted items say and do about the chart
//! (its docs, its frame: the run-time parameter, the runtime trait that reads and moves it,
//! its value after `new`). The rest of the crate asks [`Space::chart`] for a space's chart,
//! so that a new manifold is a module here plus its registration in [`Space`]. This module
//! imports only the expression graph (`ir`): the front end reads the spaces from here.

pub(crate) mod flat;
pub(crate) mod se3;
pub(crate) mod so3;
pub(crate) mod sphere;

use proc_macro2::TokenStream;

use crate::ir::graph::{Graph, Id};

/// The configuration space of a Lagrangian or jet function: the registration of the spaces,
/// each one variant, its option in [`Space::OPTIONS`] and its arm in [`Space::chart`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Space {
    /// R^n: the jet is the argument list as written (`flat`).
    Flat,
    /// The unit sphere S^2 (`sphere`): the jet is ambient (`[f64; 3]`) and the generated
    /// system works in a gnomonic chart (`charts::sphere`).
    Sphere,
    /// The rotation group SO(3) (`so3`): the arguments are the rotation R (`[f64; 9]`, row
    /// major) and the body velocity Omega with its derivatives (`[f64; 3]`); the generated
    /// system works in a Gibbs chart centred at a rotation (`charts::so3`).
    So3,
    /// The rigid motions SE(3) (`se3`): the arguments are the pose g = (R, p) (`[f64; 12]`,
    /// R row major, then the position p) and the body velocity xi = (Omega, v), v = R^T p',
    /// with its derivatives (`[f64; 6]`); the generated system works in the product chart
    /// (Gibbs chart of R, position in the centre's axes) centred at a pose (`charts::se3`).
    Se3,
}

impl Space {
    /// The spaces an attribute option selects, in the order the messages list them.
    pub const OPTIONS: [Space; 3] = [Space::Sphere, Space::So3, Space::Se3];

    /// The space's chart: its behaviour in every stage.
    pub fn chart(self) -> &'static dyn Chart {
        match self {
            Space::Flat => &flat::Flat,
            Space::Sphere => &sphere::Sphere,
            Space::So3 => &so3::So3,
            Space::Se3 => &se3::Se3,
        }
    }

    /// The options of [`Space::OPTIONS`] in backticks, separated by `separator` but the last
    /// two by `last` (for messages: "`sphere`, `so3`, `se3`").
    pub fn option_list(separator: &str, last: &str) -> String {
        let names: Vec<String> = Space::OPTIONS
            .iter()
            .filter_map(|space| space.chart().option())
            .map(|name| format!("`{name}`"))
            .collect();
        match names.split_last() {
            Some((tail, [])) => tail.clone(),
            Some((tail, init)) => format!("{}{last}{tail}", init.join(separator)),
            None => String::new(),
        }
    }
}

/// The frame of a chart: the run-time parameter appended after the user's parameters, which
/// the runtime reads and moves through a trait of `retract_core`.
pub(crate) struct Frame {
    /// The parameter's name.
    pub name: &'static str,
    /// Its length: a parameter `[f64; len]`.
    pub len: usize,
    /// The runtime's trait of a system in this chart (in `retract_core::__private`) and its
    /// methods that read and replace the frame.
    pub runtime: [&'static str; 3],
    /// The doc of the frame's field in the parameter struct.
    pub doc: &'static str,
    /// The frame after `new`.
    pub initial: fn() -> TokenStream,
}

/// A space on which a Lagrangian or jet function is written, with its chart: the generated
/// system works in the chart, whose frame (if any) is a run-time parameter. R^n is its own
/// chart, and the defaults are those of R^n.
pub(crate) trait Chart: Sync {
    /// The attribute option that selects the space; `None` for R^n, the default.
    fn option(&self) -> Option<&'static str>;

    /// The chart's frame; `None` on R^n.
    fn frame(&self) -> Option<Frame> {
        None
    }

    /// For a function written in body coordinates on a group (`so3`, `se3`): the length of
    /// the group element's argument and of each body rate's (the chart's dimension).
    fn body_coordinates(&self) -> Option<(usize, usize)> {
        None
    }

    /// The dimension of the chart of a function whose jet arguments have `dim` components.
    fn chart_dim(&self, dim: usize) -> usize {
        self.body_coordinates().map_or(dim, |(_, rate)| rate)
    }

    /// The length `len` of the array `[f64; len]` that the space requires of jet argument
    /// `i` (0 for q) of an order-`order` function as written; `None` where it requires
    /// nothing (the argument then has the type of q).
    fn required_argument(&self, _order: usize, _i: usize) -> Option<usize> {
        None
    }

    /// The message for jet argument `i`, `name`, of type `found` where
    /// [`Chart::required_argument`] requires another, written for a Lagrangian.
    fn wrong_argument(&self, order: usize, i: usize, name: &syn::Ident, found: &str) -> String {
        let expected = self.required_argument(order, i).unwrap_or_default();
        format!(
            "argument {} (`{name}`) must be `[f64; {expected}]`, not {found}",
            i + 1
        )
    }

    /// The message for an order-`order` function with only `found` arguments, fewer than
    /// its jet; `None` for the message of R^n.
    fn missing_arguments(&self, _order: usize, _found: usize) -> Option<String> {
        None
    }

    /// `roots` (the function and its guarded expressions, in the arguments as written of an
    /// order-`order` function) rewritten in the chart jet; the frame is parameter number
    /// `frame`. Unchanged on R^n.
    fn compose(&self, _graph: &mut Graph, _order: usize, _frame: u32, roots: &[Id]) -> Vec<Id> {
        roots.to_vec()
    }

    /// Where the generated system lives, for its docs: the space and its chart, for jet
    /// arguments of `dim` components.
    fn description(&self, dim: usize) -> String;

    /// The arguments of L as written, for the docs of a Lagrangian of order `k`.
    fn arguments(&self, k: usize) -> String {
        format!("q, ..., q^({k})")
    }

    /// What the top argument of an order-`k` Lagrangian holds, for messages.
    fn top(&self, k: usize) -> String {
        format!("q^({k})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registered_space_has_its_own_option_and_frame() {
        let flat = Space::Flat.chart();
        assert!(flat.option().is_none() && flat.frame().is_none());
        assert_eq!(flat.chart_dim(5), 5);
        let mut names = Vec::new();
        for space in Space::OPTIONS {
            let chart = space.chart();
            let option = chart.option().expect("an option selects the space");
            let frame = chart.frame().expect("a manifold's chart has a frame");
            assert!(frame.len > 0 && !frame.doc.is_empty());
            names.push(option);
            names.push(frame.name);
        }
        let count = names.len();
        names.sort_unstable();
        names.dedup();
        assert_eq!(
            names.len(),
            count,
            "options and frames share a name: {names:?}"
        );
        assert_eq!(Space::option_list(", ", " or "), "`sphere`, `so3` or `se3`");
    }
}
