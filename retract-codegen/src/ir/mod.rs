//! The intermediate representation: the flat, hash-consed expression graph (`graph`: children
//! before parents, one node per distinct subexpression) and its symbolic differentiation
//! (`diff`: one rule per operation, memoised forward mode, substitution and total
//! derivatives).

pub(crate) mod diff;
pub(crate) mod graph;
