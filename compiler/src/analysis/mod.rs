//! Plan-time analysis, one folder per dimension: [`planar`] (Grübler's
//! mobility, propagation and contraction by dyads, the rank test, Grashof)
//! and [`spatial`] (Kramer's DOF analysis with the plan-fragment table). Each
//! turns a model into a plan IR and chooses the branches that reproduce the
//! drawn pose; what both share lives here: the assembly ranges of the inputs
//! (found by running any solver) and the progress report of a long analysis.

pub mod planar;
pub mod ranges;
pub mod spatial;

pub use planar::{analyse, analyse_with, Analysis, Class, Equation, Mobility, PlanError, Sourced};

/// How far a long analysis is, for a progress display: `done` of `total`
/// units of the named stage ("plan": equations used; "branches": the drawn
/// pose's run; "rank": Jacobian rows eliminated). Reported often and
/// cheaply; a display throttles itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// "plan", "branches" or "rank".
    pub stage: &'static str,
    /// Units done.
    pub done: usize,
    /// Units in all.
    pub total: usize,
}

/// The file name without its directories (plans and generated code must not
/// depend on where the file was read from).
pub(crate) fn file_name(path: &str) -> String {
    std::path::Path::new(path)
        .file_name()
        .map_or_else(|| path.to_string(), |f| f.to_string_lossy().into_owned())
}
