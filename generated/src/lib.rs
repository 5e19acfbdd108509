//! Compiled plans of every mechanism bundled in `mechanisms/`, generated at
//! build time by `build.rs` through `dofplan::build`.
//!
//! Each mechanism is a module (`fourbar`, `stress_50`, …) with a `State`,
//! a `solve` function and a `Plan` to drive with
//! [`dofplan_runtime::Driver`].

include!(concat!(env!("OUT_DIR"), "/mechanisms.rs"));
