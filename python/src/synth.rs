//! `dofplan.synth`: path, function and motion generation on a loaded
//! mechanism, by the library's search (`dofplan::synth`), the request and
//! the options as `dofplan synth` makes them from its flags. The result is
//! the CLI's `--json` document and the best solution's file text (written
//! into the mechanism's own text, comments and key order kept, and
//! verified from there).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use dofplan::model::{Format, Model};
use dofplan::synth::planar::{problem, synthesize, Constraints, Kind, Request};
use dofplan::synth::search::Options;
use dofplan::synth::spatial;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::mechanism::Mechanism;

/// What to synthesise, as `dofplan synth`'s flags say it (a dict, its keys
/// the fields' names: the Python half makes it).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
pub struct Goal {
    /// "path", "function" or "motion".
    kind: String,
    /// The targets as a CSV text (the columns the CLI's target files have).
    targets: String,
    /// `--marker` (path, motion), `--output` (function), `--body` (motion).
    marker: Option<String>,
    output: Option<String>,
    body: Option<String>,
    /// `--timing`: Some(true) given, Some(false) free, None as the columns say.
    given: Option<bool>,
    input: Option<String>,
    vary: Option<Vec<String>>,
    /// `--bounds X0,Y0,X1,Y1` (or with Z in space) for every varied point.
    bounds: Option<Vec<f64>>,
    /// `--bounds NAME=…`, by point.
    point_bounds: Vec<(String, Vec<f64>)>,
    full_turn: bool,
    min_transmission: Option<f64>,
    max_ratio: Option<f64>,
    seed: u64,
    time_limit: f64,
    target: Option<f64>,
    population: Option<usize>,
    evaluations: Option<usize>,
}

/// Runs a synthesis on `mech`: the CLI's JSON document and the best
/// solution's file, or a `DofplanError` with the CLI's message.
pub fn run(py: Python<'_>, mech: &Mechanism, goal: Goal) -> PyResult<(String, String)> {
    if !(goal.time_limit.is_finite() && goal.time_limit > 0.0) {
        return Err(PyValueError::new_err(format!(
            "time_limit must be a positive number of seconds, not {}",
            goal.time_limit
        )));
    }
    let (text, format) = mech.source_text();
    let format = if format == "json" {
        Format::Json
    } else {
        Format::Toml
    };
    let cancel = Arc::new(AtomicBool::new(false));
    let options = Options {
        seed: goal.seed,
        time_limit: Duration::from_secs_f64(goal.time_limit),
        target: goal.target.unwrap_or(0.0),
        population: goal.population,
        evaluations: goal.evaluations,
        cancel: Some(cancel.clone()),
        ..Options::default()
    };
    let name = mech.file().to_string();
    let search = || -> Result<(String, String), String> {
        match &mech.model {
            Model::Planar(m) => {
                let request = planar_request(&goal)?;
                let problem = problem(m, &request).map_err(|e| about(&name, e))?;
                let s = synthesize(m, &text, format, &problem, &options, &mut |_| {});
                let s = solved(&name, s)?;
                let mut out = Vec::new();
                dofplan::report::planar::synth::write_json(m, &problem, &s, &mut out)
                    .map_err(|e| e.to_string())?;
                Ok((
                    String::from_utf8_lossy(&out).into_owned(),
                    s.solutions[0].text.clone(),
                ))
            }
            Model::Spatial(m) => {
                let request = spatial_request(&goal, &name)?;
                let problem = spatial::problem(m, &request).map_err(|e| about(&name, e))?;
                let s = spatial::synthesize(m, &text, format, &problem, &options, &mut |_| {});
                let s = solved(&name, s)?;
                let mut out = Vec::new();
                dofplan::report::spatial::synth::write_json(m, &problem, &s, &mut out)
                    .map_err(|e| e.to_string())?;
                Ok((
                    String::from_utf8_lossy(&out).into_owned(),
                    s.solutions[0].text.clone(),
                ))
            }
        }
    };
    let (found, interrupted) = interruptible(py, &cancel, search);
    if let Some(e) = interrupted {
        return Err(e);
    }
    found.map_err(crate::errors::DofplanError::new_err)
}

/// Runs `work` on a thread of its own, the lock released, while this one
/// looks at Python's signals every `POLL`: on Ctrl-C (or any signal handler
/// that raises) `cancel` is set, the search stops at its next generation,
/// and the handler's exception is returned beside the work's result.
fn interruptible<T: Send>(
    py: Python<'_>,
    cancel: &AtomicBool,
    work: impl FnOnce() -> T + Send,
) -> (T, Option<PyErr>) {
    const POLL: Duration = Duration::from_millis(50);
    py.detach(|| {
        std::thread::scope(|scope| {
            let running = scope.spawn(work);
            let mut interrupted = None;
            while !running.is_finished() {
                std::thread::sleep(POLL);
                if interrupted.is_none() {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        cancel.store(true, Ordering::Relaxed);
                        interrupted = Some(e);
                    }
                }
            }
            match running.join() {
                Ok(found) => (found, interrupted),
                // A panic in the search is a bug: carried on as one, not
                // turned into a Python error that hides it.
                Err(panic) => std::panic::resume_unwind(panic),
            }
        })
    })
}

/// The planar request.
fn planar_request(goal: &Goal) -> Result<Request, String> {
    let kind = match goal.kind.as_str() {
        "path" => Kind::Path {
            marker: goal.marker.clone().unwrap_or_default(),
            given: goal.given,
        },
        "function" => Kind::Function {
            output: goal.output.clone().unwrap_or_default(),
        },
        "motion" => Kind::Motion {
            body: goal.body.clone().unwrap_or_default(),
            marker: goal.marker.clone(),
            given: goal.given,
        },
        other => return Err(format!("a goal is path, function or motion, not {other:?}")),
    };
    let (bounds, point_bounds) = boxes::<4>(goal)?;
    Ok(Request {
        kind,
        targets: ("targets.csv".into(), goal.targets.clone()),
        input: goal.input.clone(),
        vary: goal.vary.clone(),
        bounds,
        point_bounds,
        constraints: Constraints {
            full_turn: goal.full_turn,
            min_transmission: goal.min_transmission,
            max_ratio: goal.max_ratio,
        },
    })
}

/// The spatial request, or what spatial synthesis does not do (the CLI's
/// words).
fn spatial_request(goal: &Goal, name: &str) -> Result<spatial::Request, String> {
    if goal.min_transmission.is_some() {
        return Err(format!(
            "{name}: error: min_transmission bounds the transmission angles of planar four-bar loops, and a spatial file has none; bound the links with max_ratio, or keep the input turning with full_turn"
        ));
    }
    let kind = match goal.kind.as_str() {
        "path" => spatial::Kind::Path {
            marker: goal.marker.clone().unwrap_or_default(),
            given: goal.given,
        },
        "function" => spatial::Kind::Function {
            output: goal.output.clone().unwrap_or_default(),
        },
        "motion" if goal.given == Some(false) => {
            return Err(format!(
                "{name}: error: free timing of a motion works on planar files only for now"
            ))
        }
        "motion" => spatial::Kind::Motion {
            body: goal.body.clone().unwrap_or_default(),
            marker: goal.marker.clone(),
        },
        other => return Err(format!("a goal is path, function or motion, not {other:?}")),
    };
    let (bounds, point_bounds) = boxes::<6>(goal)?;
    Ok(spatial::Request {
        kind,
        targets: ("targets.csv".into(), goal.targets.clone()),
        input: goal.input.clone(),
        vary: goal.vary.clone(),
        bounds,
        point_bounds,
        constraints: spatial::Constraints {
            full_turn: goal.full_turn,
            max_ratio: goal.max_ratio,
        },
    })
}

/// The boxes of N numbers (x0, y0, x1, y1; or with z in space).
#[allow(clippy::type_complexity)]
fn boxes<const N: usize>(goal: &Goal) -> Result<(Option<[f64; N]>, Vec<(String, [f64; N])>), String> {
    let one = |what: &str, v: &[f64]| -> Result<[f64; N], String> {
        let b: [f64; N] = v
            .try_into()
            .map_err(|_| format!("{what} is {N} numbers (the low corner, then the high one), not {v:?}"))?;
        let h = N / 2;
        if b.iter().any(|x| !x.is_finite()) || (0..h).any(|k| b[k] >= b[k + h]) {
            return Err(format!(
                "{what} must be finite with each low coordinate below its high one: {v:?}"
            ));
        }
        Ok(b)
    };
    let bounds = goal.bounds.as_deref().map(|v| one("bounds", v)).transpose()?;
    let points = (goal.point_bounds.iter())
        .map(|(n, v)| one(&format!("the bounds of {n}"), v).map(|b| (n.clone(), b)))
        .collect::<Result<_, _>>()?;
    Ok((bounds, points))
}

/// `e` about `name` unless it already says where it is.
fn about(name: &str, e: String) -> String {
    if e.contains(": error: ") {
        e
    } else {
        format!("{name}: error: {e}")
    }
}

/// The synthesis, or the CLI's message for none found.
fn solved(
    name: &str,
    found: Result<dofplan::synth::solution::Synthesis, String>,
) -> Result<dofplan::synth::solution::Synthesis, String> {
    match found {
        Ok(s) if !s.solutions.is_empty() => Ok(s),
        Ok(_) => Err(format!(
            "{name}: error: no candidate in the box met the targets and the constraints; widen the bounds, relax the constraints or give more time_limit"
        )),
        Err(e) => Err(format!("{name}: error: {e}")),
    }
}
