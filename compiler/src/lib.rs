//! dofplan: a plan compiler for mechanisms.
//!
//! ```text
//! file ──load──▶ model ──analyse──▶ plan IR ──┬─▶ interpreter ─┐
//!                                              └─▶ emitter ──▶ Rust source
//!                                          both call the runtime's steps
//! ```
//!
//! - [`model`]: reading and validating mechanism files (TOML or JSON).
//! - [`analysis`]: mobility, DOF bookkeeping, contraction by loci and dyads.
//! - [`plan`]: the plan IR, the contract between analysis and back ends.
//! - [`interp`]: executes a plan loaded at run time.
//! - [`emit`]: writes a plan as straight-line Rust.
//! - [`numeric`]: pure Newton–Raphson (the baseline without analysis).
//! - [`build`]: the `build.rs` API.
//! - [`assemble`]: moves the markers of a roughly drawn file to where its
//!   joints close (`dofplan assemble`).
//! - [`render`]: the SVG picture of a sweep or a drag.
//! - [`report`]: the reports of the CLI's commands (`check`, …), as text
//!   or JSON.
//! - [`mod@format`]: how numbers are printed, the same in every output.

pub mod analysis;
pub mod assemble;
pub mod build;
pub mod conflict;
pub mod edit;
pub mod emit;
pub mod format;
pub mod interp;
pub mod model;
pub mod numeric;
pub mod plan;
pub mod render;
pub mod report;
pub mod simulate;

pub use conflict::{load_any, load_any_str, load_file, load_str};
