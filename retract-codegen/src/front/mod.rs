//! The front end: the attribute's options and the function's signature (`signature`: order,
//! dimension, parameters, space), then the body lowered to the expression graph (`lower`),
//! with every error of the input at its span.

pub(crate) mod lower;
pub(crate) mod signature;
