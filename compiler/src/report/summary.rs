//! The text summary of a run of frames, planar or spatial: every run of
//! frames that broke alike (same status, same step, same reason) as a frame
//! range as soon as it ends, then the counts. Holds one run, never the
//! frames.

use std::io::{self, Write};

use crate::format::rounded;
use crate::plan::num;
use dofplan_runtime::{BreakKind, FrameStatus};

/// Writes a frame's driven value from its inputs, each number with the
/// given format.
pub type Describe<'a> = dyn Fn(&[f64], fn(f64) -> String) -> String + 'a;

/// A step as the user reads it: its number in `dofplan plan` and its
/// explanation.
pub type Explain<'a> = dyn Fn(u32) -> (usize, String) + 'a;

/// A break point's value: to the precision it is found to.
fn precise(x: f64) -> String {
    rounded(x, 9)
}

/// The summary being written.
pub struct Summary<'r> {
    /// What the summary calls the driven value ("theta", "target")…
    value_name: &'r str,
    /// …and how it writes that value from a frame's inputs.
    value: &'r Describe<'r>,
    explain: &'r Explain<'r>,
    /// Frames by status: solved, limited, searched, stretched, unreached.
    counts: [usize; 5],
    run: Option<Run>,
}

/// Consecutive frames that broke alike.
struct Run {
    first: usize,
    last: usize,
    /// The first frame's status.
    status: FrameStatus,
    /// The requested inputs of the first and last frames.
    requested: (Vec<f64>, Vec<f64>),
    /// The reached inputs of the first and last frames.
    reached: (Vec<f64>, Vec<f64>),
    /// The largest gap (a break) or residual (a stretch).
    worst: f64,
}

/// What makes frames break alike: the status, the step, and why (a limit,
/// or another circuit past it; none for a stretch).
type BreakKey = (&'static str, u32, Option<BreakKind>);

/// What makes frames break alike, and how much: its key, and the gap or
/// residual.
fn break_of(status: &FrameStatus) -> Option<(BreakKey, f64)> {
    match status {
        FrameStatus::Solved => None,
        FrameStatus::Limited { brk } | FrameStatus::Searched { brk, .. } | FrameStatus::Unreached { brk } => {
            Some(((status.name(), brk.step, Some(brk.kind)), brk.gap))
        }
        FrameStatus::Stretched { step, residual } => Some(((status.name(), *step, None), *residual)),
    }
}

impl<'r> Summary<'r> {
    /// A summary calling the driven value `value_name`, written by `value`,
    /// with steps shown by `explain`.
    pub fn new(value_name: &'r str, value: &'r Describe<'r>, explain: &'r Explain<'r>) -> Self {
        Summary {
            value_name,
            value,
            explain,
            counts: [0; 5],
            run: None,
        }
    }

    /// Frame number `index`: its requested and reached inputs and status.
    pub fn frame(
        &mut self,
        out: &mut dyn Write,
        index: usize,
        requested: &[f64],
        reached: &[f64],
        status: &FrameStatus,
    ) -> io::Result<()> {
        self.counts[match status {
            FrameStatus::Solved => 0,
            FrameStatus::Limited { .. } => 1,
            FrameStatus::Searched { .. } => 2,
            FrameStatus::Stretched { .. } => 3,
            FrameStatus::Unreached { .. } => 4,
        }] += 1;
        let this = break_of(status);
        let alike = match (&self.run, this) {
            (Some(run), Some((key, _))) => break_of(&run.status).is_some_and(|(k, _)| k == key),
            _ => false,
        };
        if alike {
            let run = self.run.as_mut().expect("alike implies a run");
            run.last = index;
            run.requested.1.clear();
            run.requested.1.extend_from_slice(requested);
            run.reached.1.clear();
            run.reached.1.extend_from_slice(reached);
            run.worst = run.worst.max(this.map_or(0.0, |t| t.1));
            return Ok(());
        }
        self.close(out)?;
        if let Some((_, worst)) = this {
            self.run = Some(Run {
                first: index,
                last: index,
                status: *status,
                requested: (requested.to_vec(), requested.to_vec()),
                reached: (reached.to_vec(), reached.to_vec()),
                worst,
            });
        }
        Ok(())
    }

    /// Writes the last run, and returns the counts line (without its end).
    pub fn end(&mut self, out: &mut dyn Write) -> io::Result<String> {
        self.close(out)?;
        let [solved, limited, searched, stretched, unreached] = self.counts;
        // Unreached frames only occur in sweeps that start out of reach.
        let unreached = if unreached > 0 {
            format!(", {unreached} not reachable")
        } else {
            String::new()
        };
        Ok(format!(
            "{} frames: {solved} solved, {limited} limited, {searched} searched, {stretched} stretched{unreached}",
            self.counts.iter().sum::<usize>()
        ))
    }

    /// Writes the run that has just ended.
    fn close(&mut self, out: &mut dyn Write) -> io::Result<()> {
        let Some(run) = self.run.take() else {
            return Ok(());
        };
        let (value, name_of) = (self.value, self.value_name);
        let (first, last) = (&run.requested.0, &run.requested.1);
        let frames = if run.first == run.last {
            format!("frame {} ({} {})", run.first, name_of, value(first, num))
        } else {
            format!(
                "frames {}–{} ({} {} … {})",
                run.first,
                run.last,
                name_of,
                value(first, num),
                value(last, num)
            )
        };
        // Where the pose is: to the precision a break point is found to.
        let (a, b) = (value(&run.reached.0, precise), value(&run.reached.1, precise));
        let at = if a == b { a } else { format!("{a} … {b}") };
        let up_to = if run.first == run.last { "" } else { "up to " };
        let (name, detail) = match &run.status {
            FrameStatus::Limited { brk }
            | FrameStatus::Searched { brk, .. }
            | FrameStatus::Unreached { brk } => {
                let (step, text) = (self.explain)(brk.step);
                (
                    match run.status {
                        FrameStatus::Limited { .. } => format!("limited, held at {name_of} {at}"),
                        FrameStatus::Unreached { .. } => "not reachable (no pose yet)".to_string(),
                        _ => format!("searched, break point {name_of} {at}"),
                    },
                    if brk.kind == BreakKind::OtherCircuit {
                        // The step and gap are the limit's, not this frame's.
                        format!("{}; the limit was step {step}: {text}", brk.kind.describe())
                    } else {
                        format!(
                            "step {step} broke ({}, gap {up_to}{}): {text}",
                            brk.kind.describe(),
                            num(run.worst)
                        )
                    },
                )
            }
            FrameStatus::Stretched { step, .. } => {
                let (step, text) = (self.explain)(*step);
                (
                    "stretched".to_string(),
                    format!(
                        "step {step} stretched, residual {up_to}{}: {text}",
                        num(run.worst)
                    ),
                )
            }
            FrameStatus::Solved => unreachable!("a run holds broken frames only"),
        };
        writeln!(out, "  {frames}: {name}\n    {detail}")
    }
}
