//! The reports of the `dofplan` commands, written as the CLI prints them:
//! `check` of planar ([`check`]) and spatial ([`spatial`]) files. The
//! editor shows the same texts in its panels.
//!
//! Reports are written to any [`std::io::Write`] and say whether the
//! command succeeded; printing, exit codes and progress displays are the
//! caller's.

pub mod check;
pub mod spatial;

/// An input value where the pose is (held, or a break point): up to 9
/// decimals, the precision a break point is searched to.
fn precise(x: f64) -> String {
    crate::format::rounded(x, 9)
}
