//! Progress of long work on large files, shown on standard error when it is
//! a terminal (never in a pipe or a log): loading, then the analysis's own
//! stages as it reports them ([`dofplan::analysis::Progress`]).

use std::cell::Cell;
use std::io::IsTerminal;
use std::path::Path;
use std::time::{Duration, Instant};

use dofplan::analysis::Progress;
use dofplan::load_file;
use dofplan::model::{Mechanism, ModelError};
use dofplan::report::FrameProgress;
use indicatif::{ProgressBar, ProgressStyle};

/// Files from this size on (bytes: about 500 four-bar loops) show progress;
/// smaller ones are done before a bar would be read.
const LARGE_FILE: u64 = 256 * 1024;

/// A progress display, hidden unless the file is large and standard error
/// is a terminal.
pub struct Bar {
    bar: Option<ProgressBar>,
    /// The stage shown.
    stage: Cell<&'static str>,
}

impl Bar {
    /// The display for work on `file`.
    pub fn for_file(file: &Path) -> Bar {
        let large = std::fs::metadata(file).is_ok_and(|m| m.len() >= LARGE_FILE);
        let bar = (large && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new_spinner();
            bar.enable_steady_tick(Duration::from_millis(100));
            bar
        });
        Bar {
            bar,
            stage: Cell::new(""),
        }
    }

    /// Loads the file under the stage "loading" (the display is removed if
    /// that fails, so the error prints cleanly).
    pub fn load(&self, file: &Path) -> Result<Mechanism, ModelError> {
        self.stage("loading");
        let loaded = load_file(file);
        if loaded.is_err() {
            self.finish();
        }
        loaded
    }

    /// A stage without a count ("loading").
    pub fn stage(&self, name: &'static str) {
        if let Some(bar) = &self.bar {
            bar.set_style(
                ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("a valid template"),
            );
            bar.set_message(name);
            self.stage.set(name);
        }
    }

    /// What the analysis reports: its stage and how far it is.
    pub fn report(&self, p: Progress) {
        let Some(bar) = &self.bar else { return };
        bar.set_length(p.total as u64);
        bar.set_position(p.done as u64);
        if self.stage.get() != p.stage {
            let style = ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {pos}/{len} {elapsed}")
                .expect("a valid template")
                .progress_chars("=> ");
            bar.set_style(style);
            bar.set_message(p.stage);
            self.stage.set(p.stage);
        }
    }

    /// Runs `f`, which prints the result: the display stays on standard
    /// error meanwhile (as `stage`), except while standard output shares
    /// its terminal, where it is hidden so the two do not mix.
    pub fn around_output<R>(&self, stage: &'static str, f: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some(bar) if std::io::stdout().is_terminal() => bar.suspend(f),
            Some(_) => {
                self.stage(stage);
                f()
            }
            None => f(),
        }
    }

    /// Removes the display.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.finish();
    }
}

/// Progress of a long run of frames (`simulate`, `drag`): a bar on standard
/// error once the run has taken a second — shorter runs never show one —
/// when standard error is a terminal and standard output is not (the
/// frames are written there, and a bar would break their lines).
pub struct FrameBar {
    total: u64,
    start: Instant,
    shown: Option<ProgressBar>,
    possible: bool,
}

impl FrameBar {
    /// How long a run goes before its bar appears.
    const AFTER: Duration = Duration::from_secs(1);

    /// The display of a run of `total` frames (`None`: unknown).
    pub fn new(total: Option<usize>) -> FrameBar {
        FrameBar {
            total: total.unwrap_or(0) as u64,
            start: Instant::now(),
            shown: None,
            possible: std::io::stderr().is_terminal() && !std::io::stdout().is_terminal(),
        }
    }

    /// `done` frames are written.
    pub fn tick(&mut self, done: usize) {
        // Checking the clock every frame would cost more than a small
        // frame: every 64th.
        if !self.possible || !done.is_multiple_of(64) {
            return;
        }
        if self.shown.is_none() && self.start.elapsed() >= Self::AFTER {
            let bar = ProgressBar::new(self.total).with_elapsed(self.start.elapsed());
            let template = if self.total > 0 {
                "frames [{bar:30}] {pos}/{len} {elapsed}"
            } else {
                "frames {pos} {elapsed}"
            };
            bar.set_style(
                ProgressStyle::with_template(template)
                    .expect("a valid template")
                    .progress_chars("=> "),
            );
            self.shown = Some(bar);
        }
        if let Some(bar) = &self.shown {
            bar.set_position(done as u64);
        }
    }
}

impl Drop for FrameBar {
    fn drop(&mut self) {
        if let Some(bar) = &self.shown {
            bar.finish_and_clear();
        }
    }
}

/// The [`FrameBar`] of a run the library's reports drive: made when the
/// run starts, removed when it ends.
#[derive(Default)]
pub struct Frames(Option<FrameBar>);

impl FrameProgress for Frames {
    fn start(&mut self, total: Option<usize>) {
        self.0 = Some(FrameBar::new(total));
    }

    fn tick(&mut self, done: usize) {
        if let Some(bar) = &mut self.0 {
            bar.tick(done);
        }
    }

    fn finish(&mut self) {
        self.0 = None;
    }
}
