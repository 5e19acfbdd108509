//! `dofplan analyze --forces` on a planar file: what each input must
//! supply over the sweep (`forces::planar::input_forces`), as a summary
//! (each input's peak force or torque and where), JSON (simulate's frames
//! with `"input_force"`) or CSV, streamed frame by frame.

use std::io::Write;

use dofplan_runtime::{Driver, FrameStatus, Options};
use serde_json::{json, Map, Value};

use super::frames::{frame_json, sweep_report, Solver};
use crate::forces::planar::{input_forces, Moving};
use crate::format::number;
use crate::interp::{Interpreter, RateError};
use crate::model::{InputKind, Mechanism, Sweep};
use crate::plan::{num, Plan};
use crate::report::{Form, Outcome};
use crate::simulate::{sweep_rates, sweep_requests, Frame};

/// Runs the sweep with each frame's input forces: statics when `rate` is
/// None (the mechanism held at each pose: no inertia, dampers idle),
/// kinetostatics at the first swept input's `rate` (radians or length per
/// second, the others in proportion, no acceleration) when given.
pub fn run(
    m: &Mechanism,
    plan: &Plan,
    sweep: &Sweep,
    rate: Option<f64>,
    form: Form,
    out: &mut dyn Write,
) -> Outcome {
    if m.loads.is_empty() {
        return Ok(Err(format!(
            "{}: error: the file gives no masses, gravity or loads, so every force is 0\n  help: add [loads.NAME] entries, [gravity] g = [0, -9.81] with bodies' `mass`, `centre` and `inertia` (see docs/guide/forces.md)",
            m.source.name
        )));
    }
    let interp = Interpreter::new(plan.clone());
    let mut driver = Driver::new(interp.clone(), Options::default());
    let report = sweep_report(m, plan, sweep, Solver::Plan);
    let rates = rate.map(|r| sweep_rates(m, sweep, r));
    let zero = vec![0.0; m.inputs.len()];
    let moving = rates.as_ref().map(|r| Moving {
        rates: r,
        accelerations: &zero,
    });
    let names: Vec<&str> = m.inputs.iter().map(|i| i.name.as_str()).collect();
    match form {
        Form::Json => writeln!(
            out,
            "{{\n  \"mechanism\": {},\n  \"forces\": {},\n  \"frames\": [",
            json!(m.name),
            json!(if rate.is_some() { "kinetostatic" } else { "static" })
        )?,
        Form::Csv => {
            let mut head = vec!["frame".to_string()];
            head.extend(names.iter().map(|n| n.to_string()));
            head.push("status".into());
            head.extend(names.iter().map(|n| format!("{n}.force")));
            writeln!(out, "{}", head.join(","))?;
        }
        Form::Text => {}
    }
    let primary = sweep.primary().input;
    // Per input: the largest |force| and the primary input's value there.
    let mut peaks: Vec<Option<(f64, f64)>> = vec![None; m.inputs.len()];
    let (mut singular, mut unsolved) = (0usize, 0usize);
    let total = sweep.steps;
    for (i, requested) in sweep_requests(sweep, m.inputs.len()).enumerate() {
        let status = driver.frame(&requested);
        let forces: Option<Result<Vec<f64>, RateError>> = (status == FrameStatus::Solved)
            .then(|| input_forces(m, &interp, driver.state(), driver.inputs(), moving));
        match &forces {
            Some(Ok(q)) => {
                for (peak, &v) in peaks.iter_mut().zip(q) {
                    if peak.is_none_or(|(best, _)| v.abs() > best.abs()) {
                        *peak = Some((v, requested[primary]));
                    }
                }
            }
            Some(Err(_)) => singular += 1,
            None => unsolved += 1,
        }
        match form {
            Form::Json => {
                let frame = Frame {
                    requested: requested.clone(),
                    inputs: driver.inputs().to_vec(),
                    status,
                    poses: driver.poses().to_vec(),
                    numeric: driver.numeric(),
                };
                let mut o = frame_json(&report, &frame);
                o["input_force"] = match &forces {
                    Some(Ok(q)) => Value::Object(
                        names
                            .iter()
                            .zip(q)
                            .map(|(n, v)| (n.to_string(), json!(v)))
                            .collect::<Map<_, _>>(),
                    ),
                    _ => Value::Null,
                };
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "    {o}{sep}")?;
            }
            Form::Csv => {
                let mut row = vec![i.to_string()];
                row.extend(requested.iter().map(|v| number(*v)));
                row.push(status.name().to_string());
                match &forces {
                    Some(Ok(q)) => row.extend(q.iter().map(|v| number(*v))),
                    // Not solved, or a dead point: no number, not a huge one.
                    _ => row.extend(std::iter::repeat_n(String::new(), names.len())),
                }
                writeln!(out, "{}", row.join(","))?;
            }
            Form::Text => {}
        }
    }
    match form {
        Form::Json => writeln!(out, "  ]\n}}")?,
        Form::Csv => {}
        Form::Text => summary(m, sweep, rate, &peaks, (unsolved, singular), out)?,
    }
    Ok(Ok(()))
}

/// The text summary: how the sweep ran, each input's peak force or
/// torque and where, the frames without one.
fn summary(
    m: &Mechanism,
    sweep: &Sweep,
    rate: Option<f64>,
    peaks: &[Option<(f64, f64)>],
    (unsolved, singular): (usize, usize),
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let primary = sweep.primary().input;
    let how = match rate {
        None => "held still at each pose (statics)".to_string(),
        Some(r) => format!(
            "running with {} at {} (kinetostatics)",
            m.inputs[primary].name,
            rate_text(m.inputs[primary].kind, r)
        ),
    };
    writeln!(out, "{}: {} frames, {how}", m.name, sweep.steps)?;
    for (input, peak) in m.inputs.iter().zip(peaks) {
        let what = match input.kind {
            InputKind::Angle => "torque",
            InputKind::Slide => "force",
        };
        match peak {
            Some((v, x)) => writeln!(
                out,
                "  input {}: peak {what} {} at {}",
                input.name,
                num(*v),
                at_input(&m.inputs[primary], *x)
            )?,
            None => writeln!(out, "  input {}: no frame solved", input.name)?,
        }
    }
    if unsolved > 0 {
        writeln!(out, "  {unsolved} frames not solved (no forces there)")?;
    }
    if singular > 0 {
        writeln!(
            out,
            "  {singular} frames at a dead point (the input force is not defined there)"
        )?;
    }
    Ok(())
}

/// "theta = 45°", "s = 0.5": where on the sweep a value was found.
fn at_input(input: &crate::model::Input, x: f64) -> String {
    let unit = if input.kind == InputKind::Angle { "°" } else { "" };
    format!("{} = {}{unit}", input.name, num(x))
}

/// "2 rad/s", "0.5 length/s".
fn rate_text(kind: InputKind, r: f64) -> String {
    match kind {
        InputKind::Angle => format!("{} rad/s", num(r)),
        InputKind::Slide => format!("{} length/s", num(r)),
    }
}
