//! R^n: the jet is the argument list as written, its own chart (the defaults of
//! [`Chart`](super::Chart)).

use super::Chart;

/// R^n, the space of a function written without a space option.
pub(crate) struct Flat;

impl Chart for Flat {
    fn option(&self) -> Option<&'static str> {
        None
    }

    fn description(&self, dim: usize) -> String {
        format!("R^{dim}")
    }
}
