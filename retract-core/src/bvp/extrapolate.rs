//! Richardson extrapolation of plans over N, 2N, 4N (to be written).

/// A plan extrapolated to $h \to 0$ (to be written).
#[derive(Clone, Debug, PartialEq)]
pub struct Extrapolated;
