//! The reports of the `dofplan` commands, written as the CLI prints them:
//! one folder per dimension ([`planar`], [`spatial`]) with the same files:
//! `check.rs` (`dofplan check`), `frames.rs` (the frames of `simulate` and
//! `drag` as a summary, JSON or CSV) and `analyze.rs` (`analyze`'s rates,
//! with the `plots` feature). What both share is here: the run summary
//! ([`summary`]), the assembly ranges ([`ranges`]), what the two `check`
//! reports write alike (`check.rs`) and the two `analyze` reports
//! (`rates.rs`), the forms and errors.
//! The editor shows the same `check` texts in its panels.
//!
//! Reports are written to any [`std::io::Write`] and say whether the
//! command succeeded; printing, exit codes and progress displays are the
//! caller's.

mod check;
pub mod forces;
pub mod planar;
pub mod ranges;
#[cfg(feature = "plots")]
mod rates;
pub mod sensitivity;
pub mod spatial;
pub mod summary;
pub mod synth;

use std::io;

/// What a report of frames comes to. `Err` is a failure to write the
/// output; `Ok(Err(message))` an error about the input or a file written
/// beside it (an SVG), for the caller to show: the command fails.
pub type Outcome = io::Result<Result<(), String>>;

/// The form of the printed frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// A summary naming every break.
    Text,
    /// One JSON document.
    Json,
    /// One CSV row per frame.
    Csv,
}

impl Form {
    /// The form the `--json` and `--csv` flags ask for (JSON wins).
    pub fn of(json: bool, csv: bool) -> Form {
        match (json, csv) {
            (true, _) => Form::Json,
            (_, true) => Form::Csv,
            _ => Form::Text,
        }
    }
}

/// How far a run of frames is, for a progress display (the CLI's bar on a
/// terminal); `()` shows nothing.
pub trait FrameProgress {
    /// A run of `total` frames (`None`: unknown) starts.
    fn start(&mut self, total: Option<usize>);
    /// `done` frames are written.
    fn tick(&mut self, done: usize);
    /// The run is over: the display goes.
    fn finish(&mut self);
}

impl FrameProgress for () {
    fn start(&mut self, _: Option<usize>) {}
    fn tick(&mut self, _: usize) {}
    fn finish(&mut self) {}
}

/// An input value where the pose is (held, or a break point): up to 9
/// decimals, the precision a break point is searched to.
pub(crate) fn precise(x: f64) -> String {
    crate::format::rounded(x, 9)
}

/// An error about `place` (a file) that has no position in it, and what to
/// do, as the CLI prints it.
pub fn error(place: &str, message: &str, help: &str) -> String {
    format!("{place}: error: {message}\n  help: {help}")
}

/// "theta = 45°", "s = 0.5": where on a sweep a value was found, by the
/// swept input's value (every report that names a frame says it so).
pub(crate) fn at_input(input: &crate::model::Input, x: f64) -> String {
    let unit = if input.kind == crate::model::InputKind::Angle {
        "°"
    } else {
        ""
    };
    format!("{} = {}{unit}", input.name, crate::plan::num(x))
}
