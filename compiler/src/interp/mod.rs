//! The plan interpreter: executes a plan IR loaded at run time (the CLI on
//! a user's file, an editor) by calling, for each step, the same runtime
//! function the generated code calls. One folder per dimension, each an
//! `Interpreter` implementing `dofplan_runtime::Solver`.

pub mod planar;
pub mod spatial;

pub use dofplan_runtime::real::RateError;
pub use planar::{InterpState, Interpreter};
