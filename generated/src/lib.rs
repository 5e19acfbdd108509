//! Compiled plans of every mechanism bundled in `mechanisms/`, generated at
//! build time by `build.rs` through `dofplan::build`.
//!
//! Each mechanism is a module (`fourbar`, `stress_50`, …) with a `State`,
//! a `solve` function and a `Plan` to drive with
//! [`dofplan_runtime::Driver`]. The spatial ones of `mechanisms/spatial/`
//! (`rssr`, `stewart`, …) are modules too, listed in `SPATIAL_MECHANISMS`
//! and picked by name with `spatial_driver`.

include!(concat!(env!("OUT_DIR"), "/mechanisms.rs"));

/// Every mechanism above again (but the spatial stress chains), with its
/// steps split into functions of two or three steps — the form
/// `dofplan::emit` gives a plan too large for one function — so that the
/// tests check that form on every mechanism.
pub mod chunked {
    include!(concat!(env!("OUT_DIR"), "/chunked.rs"));
}

/// The stress chains of 10 to 2,000 four-bar loops of the user guide's
/// scaling table ("Plan time by size" in docs/guide/performance.md;
/// `dofplan_gen::stress::stress_chain`), compiled by
/// `dofplan::emit::emit` as a user's build.rs compiles them: above about
/// 280 steps in the split form, the repeated steps rolled into a loop over
/// a table. `driver(loops, options)` picks one.
pub mod chains {
    include!(concat!(env!("OUT_DIR"), "/chains.rs"));
}
