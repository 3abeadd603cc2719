//! The attributes, one module each: `#[higher_order_lagrangian]` (`lagrangian`),
//! `#[jet_function]` (`jet_function`), `#[discretization_map]` (`map`), and `#[helper]` with
//! the re-entry of an attribute that names helpers (`helper`). Each reads its item, runs the
//! stages (`front`, `charts`, `mechanics`, `emit`) and returns the generated items, or the
//! item unchanged with its errors.

pub(crate) mod helper;
pub(crate) mod jet_function;
pub(crate) mod lagrangian;
pub(crate) mod map;
