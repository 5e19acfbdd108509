//! Mechanisms written for other tools, turned into dofplan mechanism files.
//!
//! - [`pmks`]: Pyslvs's PMKS expressions (`M[J[R, P[0, 0], L[ground, L1]], …]`)
//!   with their input pairs (`dofplan import`).
//!
//! An importer writes TOML text, not a [`Mechanism`](crate::model::Mechanism):
//! the file is what the user keeps, edits and compiles, so it is what must
//! load. Each importer loads what it wrote before returning it, and reports
//! what it cannot express as a [`ModelError`](crate::model::ModelError)
//! pointing into the foreign text.

pub mod pmks;

pub use pmks::{import_pmks, pmks_to_toml};
