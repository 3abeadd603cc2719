//! The emission of the generated code: the token helpers shared by every item (`helpers`)
//! and the straight-line bodies of a scalar function of the jet (`scalar`), shared by the
//! `Lagrangian` and `JetFunction` impls.

pub(crate) mod helpers;
pub(crate) mod scalar;
