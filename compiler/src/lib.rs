//! dofplan: a plan compiler for mechanisms.
//!
//! ```text
//! file ──load──▶ model ──analyse──▶ plan IR ──┬─▶ interpreter ─┐
//!                                              └─▶ emitter ──▶ Rust source
//!                                          both call the runtime's steps
//! ```
//!
//! Load a file, plan it, and run the plan through the interpreter (the
//! `build.rs` route, [`build`], compiles the same plan into Rust instead):
//!
//! ```
//! use dofplan_runtime::{Driver, Options};
//!
//! let text = r#"
//! name = "fourbar"
//! [bodies.ground]
//! fixed = true
//! markers = { A = [0, 0], D = [4, 0] }
//! [bodies.crank]
//! markers = { A = [0, 0], B = [1, 1] }
//! [bodies.coupler]
//! markers = { B = [1, 1], C = [4.5, 2.5] }
//! [bodies.rocker]
//! markers = { C = [4.5, 2.5], D = [4, 0] }
//! [joints.A]
//! kind = "revolute"
//! markers = ["ground.A", "crank.A"]
//! [joints.B]
//! kind = "revolute"
//! markers = ["crank.B", "coupler.B"]
//! [joints.C]
//! kind = "revolute"
//! markers = ["coupler.C", "rocker.C"]
//! [joints.D]
//! kind = "revolute"
//! markers = ["rocker.D", "ground.D"]
//! [inputs.theta]
//! kind = "angle"
//! joint = "A"
//! "#;
//! // Validated, and joints open as drawn diagnosed (`conflict`).
//! let m = dofplan::load_str("fourbar.toml", text, dofplan::model::Format::Toml)?;
//! // Planned ahead of time: one closed-form step per body here.
//! let plan = dofplan::analysis::analyse(&m).plan?;
//! println!("{}", plan.explain_all());
//! // Run at move time, frame after frame, from the drawn pose.
//! let mut driver = Driver::new(dofplan::interp::Interpreter::new(plan), Options::default());
//! for theta in [0.0, 30.0, 60.0] {
//!     assert!(driver.frame(&[theta]).is_solved());
//!     // Joint C holds: coupler.C and rocker.C are at one point.
//!     let (c1, c2) = (m.find_marker("coupler.C").unwrap(), m.find_marker("rocker.C").unwrap());
//!     let p1 = driver.poses()[c1.body].world(m.marker(c1).at);
//!     let p2 = driver.poses()[c2.body].world(m.marker(c2).at);
//!     assert!((p1[0] - p2[0]).hypot(p1[1] - p2[1]) < 1e-12);
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! - [`model`]: reading and validating mechanism files (TOML or JSON).
//! - [`conflict`]: which joints cannot all close, for a drawing whose
//!   joints are open; [`load_file`] and [`load_str`] run it.
//! - [`analysis`]: mobility, DOF bookkeeping, contraction by loci and dyads.
//! - [`plan`]: the plan IR, the contract between analysis and back ends.
//! - [`interp`]: executes a plan loaded at run time.
//! - [`emit`]: writes a plan as straight-line Rust.
//! - [`numeric`]: pure Newton–Raphson (the baseline without analysis).
//! - [`build`]: the `build.rs` API.
//! - [`assemble`]: moves the markers of a roughly drawn file to where its
//!   joints close (`dofplan assemble`).
//! - [`render`]: the SVG picture of a sweep or a drag.
//! - [`edit`]: the editor's documents, sessions and edits (`dofplan edit`).
//! - [`simulate`]: sweeps, frames and the kinematics `analyze` reports.
//! - [`synth`]: design parameters (the drawn joint positions), candidates
//!   planned from them, and exact derivatives with respect to them.
//! - [`import`]: mechanisms written for other tools (Pyslvs's PMKS
//!   expressions) as dofplan mechanism files (`dofplan import`).
//! - [`report`]: the reports of the CLI's commands (`check`, …), as text
//!   or JSON.
//! - [`mod@format`]: how numbers are printed, the same in every output.

pub mod analysis;
pub mod assemble;
pub mod build;
pub mod conflict;
pub mod edit;
pub mod emit;
pub mod forces;
pub mod format;
pub mod import;
pub mod interp;
pub mod model;
pub mod numeric;
pub mod plan;
pub mod render;
pub mod report;
pub mod simulate;
pub mod synth;

pub use conflict::{load_any, load_any_str, load_file, load_str};
