//! What `analyze` does alike in either dimension: input rates, the
//! summary's header, the extremes of a traced marker and its dead points,
//! the rates of a JSON report's head and the rate keys of its frames, the
//! traced markers' series and the plots written from them.

use std::io::{self, Write};
use std::path::Path;

use serde_json::{json, Value};

use super::{Form, Outcome};

use crate::interp::RateError;
use crate::model::{Input, InputKind};
use crate::plan::num;

/// An input's rate as summaries and plots print it: an angle's in degrees
/// per second with radians per second after it (what `--rate` takes), a
/// slide's in length units per second. `per_second` is in the input's own
/// units (degrees for an angle).
pub(crate) fn rate_text(kind: InputKind, per_second: f64) -> String {
    match kind {
        InputKind::Angle => format!("{}°/s ({} rad/s)", num(per_second), num(per_second.to_radians())),
        InputKind::Slide => format!("{} length units/s", num(per_second)),
    }
}

/// The summary's first line: the mechanism, the frames and each moving
/// input's rate, or, when every rate is zero (`--rate 0`), that nothing
/// moves.
pub(crate) fn header(name: &str, frames: usize, inputs: &[Input], rates: &[f64]) -> String {
    let moving: Vec<String> = (inputs.iter().zip(rates))
        .filter(|(_, r)| **r != 0.0)
        .map(|(i, r)| format!("{} at {}", i.name, rate_text(i.kind, *r)))
        .collect();
    if moving.is_empty() {
        format!("{name}: {frames} frames, every input at rest (rate 0): every speed and acceleration is 0")
    } else {
        format!("{name}: {frames} frames, {}", moving.join(", "))
    }
}

pub(crate) use super::at_input;

/// Two values agree to this relative tolerance: a speed that varies less
/// over the sweep is constant (its largest value is round-off, found
/// anywhere).
const SAME: f64 = 1e-9;

/// A traced marker's summary line from its frames' (input, speed,
/// acceleration): for each, the largest value and the first input where
/// it is reached, or, when it does not change over the sweep, its value
/// "throughout". `None` when no frame has rates.
pub(crate) fn extremes(name: &str, points: &[(f64, f64, f64)], at: &dyn Fn(f64) -> String) -> Option<String> {
    let describe = |what: &str, value: &dyn Fn(&(f64, f64, f64)) -> f64| -> Option<String> {
        let values = || points.iter().map(value).filter(|v| v.is_finite());
        let hi = values().fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))))?;
        let lo = values().fold(hi, f64::min);
        let tolerance = SAME * hi.abs().max(1.0);
        if hi - lo <= tolerance {
            return Some(format!("{what} {} throughout", num(hi)));
        }
        let first = points.iter().find(|p| value(p) >= hi - tolerance)?;
        Some(format!("largest {what} {} at {}", num(hi), at(first.0)))
    };
    let speed = describe("speed", &|p| p.1)?;
    let accel = describe("acceleration", &|p| p.2)?;
    Some(format!("  {name}: {speed}, {accel}"))
}

/// A frame's rates, by marker (velocity, acceleration) and by body
/// (angular velocity, acceleration): planar or spatial.
pub(super) type Rates<'r, P, W> = (&'r [P], &'r [P], &'r [W], &'r [W]);

/// The keys `analyze --json` adds to a frame, planar or spatial:
/// "velocity" and "acceleration" by "body.marker" (`names`), "angular"
/// with each body's "omega" and "alpha"; where there are no rates, those
/// null and "singular" (a dead point) or "unavailable" (rates the plan does
/// not give) saying why.
pub(crate) fn rate_keys<'a, P: serde::Serialize, W: serde::Serialize>(
    o: &mut Value,
    bodies: impl Iterator<Item = &'a str>,
    names: &[String],
    moving: Result<Rates<'_, P, W>, &RateError>,
) {
    match moving {
        Ok((velocity, acceleration, omega, alpha)) => {
            let by_name = |v: &[P]| -> Value {
                Value::Object(names.iter().zip(v).map(|(n, p)| (n.clone(), json!(p))).collect())
            };
            o["velocity"] = by_name(velocity);
            o["acceleration"] = by_name(acceleration);
            o["angular"] = Value::Object(
                bodies
                    .enumerate()
                    .map(|(b, body)| (body.to_string(), json!({"omega": omega[b], "alpha": alpha[b]})))
                    .collect(),
            );
        }
        Err(e) => {
            o["velocity"] = Value::Null;
            o["acceleration"] = Value::Null;
            o["angular"] = Value::Null;
            let key = if matches!(e, RateError::Singular) {
                "singular"
            } else {
                "unavailable"
            };
            o[key] = json!(e.to_string());
        }
    }
}

/// The input rates of a JSON report's head, by input name.
pub(crate) fn rates_json(inputs: &[Input], rates: &[f64]) -> Value {
    Value::Object(
        (inputs.iter().zip(rates))
            .map(|(i, r)| (i.name.clone(), json!(r)))
            .collect(),
    )
}

/// One traced marker's samples over the sweep (planar or spatial), for the
/// summary and the plots.
pub(crate) struct Series<S> {
    /// "body.marker".
    pub name: String,
    /// One sample a frame.
    pub points: Vec<S>,
}

impl<S> Series<S> {
    /// The series of the traced markers (indices into `names`), empty.
    pub fn traced(names: &[String], traced: &[usize]) -> Vec<Series<S>> {
        (traced.iter())
            .map(|&k| Series {
                name: names[k].clone(),
                points: Vec::new(),
            })
            .collect()
    }
}

/// The summary's line on dead points, when the sweep met any: how many
/// frames and the first.
pub(crate) fn write_dead_points(out: &mut dyn Write, singular: &[usize]) -> io::Result<()> {
    if let Some(first) = singular.first() {
        writeln!(
            out,
            "  {} frame(s) at a dead point (rates singular), the first frame {first}",
            singular.len()
        )?;
    }
    Ok(())
}

/// Draws the plots with `draw` (given the swept input's axis label and its
/// rate as text) to `path`, and says so in a text report; or the error why
/// they could not be drawn or written.
pub(crate) fn write_plots(
    path: &Path,
    input: &Input,
    rate: f64,
    form: Form,
    out: &mut dyn Write,
    draw: impl FnOnce(&str, &str) -> Result<String, String>,
) -> Outcome {
    let axis = match input.kind {
        InputKind::Angle => format!("{} (degrees)", input.name),
        InputKind::Slide => format!("{} (length)", input.name),
    };
    match draw(&axis, &rate_text(input.kind, rate)) {
        Ok(text) => {
            if let Err(e) = std::fs::write(path, text) {
                return Ok(Err(format!(
                    "{}: error: cannot write the plots: {e}",
                    path.display()
                )));
            }
        }
        Err(e) => {
            return Ok(Err(format!(
                "{}: error: cannot draw the plots: {e}",
                path.display()
            )));
        }
    }
    if form == Form::Text {
        writeln!(out, "wrote {}", path.display())?;
    }
    Ok(Ok(()))
}
