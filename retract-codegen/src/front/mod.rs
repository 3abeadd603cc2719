//! The front end: the attribute's options and the function's signature (`signature`: order,
//! dimension, parameters, space; `actuation`: the actuated coordinates of
//! `#[mechanical_system]`), then the body lowered to the expression graph (`lower`),
//! with every error of the input at its span.

pub(crate) mod actuation;
pub(crate) mod lower;
pub(crate) mod signature;
