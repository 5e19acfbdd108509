//! The paths the fuzz targets (`fuzz/`) drive over arbitrary files, shared
//! with the regression tests (`tests/inputs/fuzz_regressions.rs`) so that every
//! input the fuzzer found is replayed through exactly the same code.
//!
//! Each function takes the raw bytes of a file and panics only when dofplan
//! misbehaves: a panic inside dofplan, an error whose source span does not
//! point into the file, or a frame reported as met whose joints do not hold.

use dofplan::analysis::planar::rank::rank_mobility;
use dofplan::analysis::{analyse, PlanError};
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Location, MarkerId, Mechanism, ModelError};
use dofplan::numeric::planar::drag::Drag;
use dofplan::plan::Plan;
use dofplan::simulate::{max_relative_residual, run, sweep_inputs, Frame};
use dofplan_runtime::{BranchPolicy, BreakPolicy, FrameStatus, Options};

/// Frames of the file's sweep that the interpreter target runs: enough to
/// cross a break or a branch, few enough that each input stays fast.
pub const SWEEP_FRAMES: usize = 12;

/// A frame reported as met (solved, or moved to a searched break point)
/// must hold every joint to this, relative to the mechanism's size. Looser
/// than the bundled files' 1e-9: fuzzed files are near-singular on purpose.
pub const RESIDUAL_TOLERANCE: f64 = 1e-6;

/// What a run reached, for the regression tests to report.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Outcome {
    /// The file loaded (else it was rejected with an error).
    pub loaded: bool,
    /// A plan was found.
    pub planned: bool,
    /// Frames run (sweep, extreme inputs and drag).
    pub frames: usize,
}

/// The file's format as the fuzz targets guess it: JSON when it starts with
/// `{` (after white space), else TOML.
pub fn guess_format(data: &[u8]) -> Format {
    match data.iter().find(|b| !b.is_ascii_whitespace()) {
        Some(b'{') => Format::Json,
        _ => Format::Toml,
    }
}

/// Loads `data` as a mechanism file in `format` and checks its errors: every
/// source span must lie inside the text on character boundaries (the CLI
/// cuts a snippet out of it), and every diagnostic must render. `None` if
/// the bytes are not UTF-8 text (rejected before parsing, by `load_file`).
pub fn load(data: &[u8], format: Format) -> Option<Result<Mechanism, ModelError>> {
    let text = std::str::from_utf8(data).ok()?;
    let loaded = load_str("fuzz.mech", text, format);
    if let Err(e) = &loaded {
        assert!(!e.diagnostics.is_empty(), "an error without a diagnostic");
        for d in &e.diagnostics {
            let mut locations = vec![&d.location];
            locations.extend(d.notes.iter().map(|n| &n.location));
            for location in locations {
                if let Location::Span(span) = location {
                    assert!(
                        text.get(span.clone()).is_some(),
                        "span {span:?} is not inside the text ({} bytes): {}",
                        text.len(),
                        d.message
                    );
                }
                let _ = d.position(location);
            }
        }
        let _ = e.to_string();
    }
    Some(loaded)
}

/// The planner's path: load, analyse (mobility, equations, plan, branch
/// choice at the drawn pose), the rank cross-check, and the plan's
/// explanation. Returns the mechanism and its plan when there is one.
pub fn plan(data: &[u8]) -> (Outcome, Option<(Mechanism, Plan)>) {
    let mut outcome = Outcome::default();
    let Some(Ok(m)) = load(data, guess_format(data)) else {
        return (outcome, None);
    };
    outcome.loaded = true;
    let analysis = analyse(&m);
    let _ = rank_mobility(&m);
    let _ = analysis.mobility.class();
    match analysis.plan {
        Ok(plan) => {
            let _ = plan.explain_all();
            outcome.planned = true;
            (outcome, Some((m, plan)))
        }
        Err(e) => {
            // The analysis reports its own bugs as this error ("internal
            // error ... please report it"): a file must never cause it.
            assert!(
                !matches!(e, PlanError::DrawnPoseMismatch { .. }),
                "plan error on a valid file: {e}"
            );
            (outcome, None)
        }
    }
}

/// The interpreter's path: the planner's, then a few frames of the file's
/// sweep, extreme input values, and a short drag of one marker. Frames
/// reported as met must hold their joints; the rest must only not panic or
/// hang.
pub fn interpret(data: &[u8]) -> Outcome {
    let (mut outcome, planned) = plan(data);
    let Some((m, plan)) = planned else {
        return outcome;
    };
    // The policies come from the input's length, so a replay is exact.
    let options = Options {
        breaking: [BreakPolicy::Limit, BreakPolicy::Search, BreakPolicy::Stretch][data.len() % 3],
        branch: [BranchPolicy::Keep, BranchPolicy::Nearest][data.len() / 3 % 2],
        ..Options::default()
    };
    if !m.inputs.is_empty() {
        let mut requested = sweep_inputs(&m, Some(SWEEP_FRAMES));
        // The loader takes only finite ends, so every value lies between.
        for inputs in &requested {
            assert!(
                inputs.iter().all(|v| v.is_finite()),
                "a sweep between finite ends asks for {inputs:?}"
            );
        }
        let frames = run(Interpreter::new(plan.clone()), options, &requested);
        check_frames(&m, &frames, "sweep");
        outcome.frames += frames.len();
        // Values no sweep in the bundled files reaches, each input in turn;
        // non-finite ones need only not panic.
        requested.clear();
        for k in 0..m.inputs.len() {
            for v in [1e9, -1e300, f64::MAX, f64::MIN_POSITIVE, f64::NAN, f64::INFINITY] {
                let mut inputs = vec![0.0; m.inputs.len()];
                inputs[k] = v;
                requested.push(inputs);
            }
        }
        let frames = run(Interpreter::new(plan), options, &requested);
        outcome.frames += frames.len();
    }
    if let Some(id) = drag_marker(&m) {
        if let Ok(solver) = Drag::new(&m, id) {
            let from = m.marker(id).at;
            let size = m.size();
            let targets: Vec<Vec<f64>> = [0.0, 0.1, 0.3, 10.0]
                .iter()
                .map(|t| vec![from[0] + t * size, from[1] - 0.5 * t * size])
                .collect();
            let frames = run(solver, options, &targets);
            check_frames(&m, &frames, "drag");
            outcome.frames += frames.len();
        }
    }
    outcome
}

/// The marker the interpreter target drags: the sweep's first traced
/// marker, else the last marker of the last mobile body. Mechanisms with
/// many bodies are skipped: the drag's Newton–Raphson on every body would
/// make each input too slow to fuzz.
fn drag_marker(m: &Mechanism) -> Option<MarkerId> {
    if m.bodies.len() > 24 {
        return None;
    }
    if let Some(id) = m.sweep.as_ref().and_then(|s| s.trace.first()) {
        if !m.bodies[id.body].fixed {
            return Some(*id);
        }
    }
    let body = m.bodies.iter().rposition(|b| !b.fixed && !b.markers.is_empty())?;
    Some(MarkerId {
        body,
        marker: m.bodies[body].markers.len() - 1,
    })
}

/// Every frame but a stretched one (whose residual is its report) holds its
/// joints: a solved or searched frame at the inputs it reached, a limited
/// one at the last valid pose it stayed at.
fn check_frames(m: &Mechanism, frames: &[Frame], what: &str) {
    // The drag's inputs are its target, not the mechanism's (released):
    // check its joints and constraints only.
    let mut free = m.clone();
    free.inputs.clear();
    for (i, f) in frames.iter().enumerate() {
        if matches!(f.status, FrameStatus::Stretched { .. }) {
            continue;
        }
        let r = if what == "drag" {
            max_relative_residual(&free, &f.poses, &[])
        } else {
            max_relative_residual(m, &f.poses, &f.inputs)
        };
        assert!(
            r <= RESIDUAL_TOLERANCE, // false for NaN too
            "{what} frame {i} ({}, inputs {:?}) holds no valid pose: relative residual {r:e}",
            f.status.name(),
            f.inputs
        );
    }
}
