//! The frames of `dofplan simulate` and `drag` on spatial files, streamed
//! one by one as a summary, JSON or CSV, and drawn as an SVG.

use std::io::Write;
use std::path::Path;

use dofplan_runtime::spatial::{Pose3, Vec3};
use dofplan_runtime::{Driver, FrameStatus, Options};
use serde_json::{json, Map, Value};

use crate::format::{number, rounded};
use crate::interp::spatial::Interpreter;
use crate::model::spatial::Mechanism;
use crate::model::Sweep;
use crate::plan::spatial::{step_number, Plan};
use crate::render::spatial::{render_spatial, SpatialFrame};
use crate::simulate::spatial::{marker_positions, residual};
use crate::simulate::sweep_requests;

use crate::report::summary::{Describe, Summary};
use crate::report::{error, Form, FrameProgress, Outcome};

/// Every frame of `sweep` run through `plan` from the drawing, kept for a
/// picture (what `simulate --svg` draws).
pub(crate) fn sweep_frames(plan: Plan, sweep: &Sweep, inputs: usize) -> Vec<SpatialFrame> {
    let mut driver = Driver::new(Interpreter::new(plan), Options::default());
    sweep_requests(sweep, inputs)
        .map(|requested| {
            let status = driver.frame(&requested);
            SpatialFrame {
                requested,
                status,
                poses: driver.poses().to_vec(),
            }
        })
        .collect()
}

/// `dofplan simulate` of a spatial file: frames streamed one by one.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    m: &Mechanism,
    plan: &Plan,
    sweep: &Sweep,
    options: Options,
    form: Form,
    svg: Option<&Path>,
    progress: &mut dyn FrameProgress,
    out: &mut dyn Write,
) -> Outcome {
    let names: Vec<String> = m.inputs.iter().map(|i| i.name.clone()).collect();
    let requests = sweep_requests(sweep, m.inputs.len());
    // The drawing traces what the sweep run traces.
    let mut drawn = m.clone();
    drawn.sweep = Some(sweep.clone());
    let svg = svg.map(|p| (p, &drawn));
    // The planar summary's title.
    let ranges: Vec<String> = (sweep.inputs.iter())
        .map(|s| {
            format!(
                "{} from {} to {}",
                m.inputs[s.input].name,
                rounded(s.from, 9),
                rounded(s.to, 9)
            )
        })
        .collect();
    let title = format!("{}: {} frames, {}", m.name, sweep.steps, ranges.join(", "));
    let input = sweep.primary().input;
    let value = move |inputs: &[f64], f: fn(f64) -> String| f(inputs[input]);
    frames(
        m,
        plan,
        &names,
        requests,
        sweep.steps,
        options,
        form,
        svg,
        &title,
        (&m.inputs[input].name, &value),
        progress,
        out,
    )
}

/// `dofplan drag` of a spatial file: the marker pinned to targets evenly
/// spaced from `from` (default: where it is drawn) to `to`, the inputs
/// released.
#[allow(clippy::too_many_arguments)]
pub fn drag(
    m: &Mechanism,
    marker: &str,
    from: Option<[f64; 3]>,
    to: [f64; 3],
    steps: usize,
    options: Options,
    form: Form,
    svg: Option<&Path>,
    progress: &mut dyn FrameProgress,
    out: &mut dyn Write,
) -> Outcome {
    let Some(id) = m.find_marker(marker) else {
        let names: Vec<String> = m.all_markers().map(|id| m.marker_name(id)).collect();
        return Ok(Err(error(
            &m.source.name,
            &format!("no marker `{marker}` to drag"),
            &format!("markers are: {}", names.join(", ")),
        )));
    };
    if m.bodies[id.body].fixed {
        return Ok(Err(error(
            &m.source.name,
            &format!("`{marker}` is on a fixed body and cannot be dragged"),
            "drag a marker of a moving body",
        )));
    }
    let free = crate::numeric::spatial::released(m);
    let plan = crate::numeric::spatial::drag_plan(m, id);
    let from = from.unwrap_or(m.marker(id).at);
    let n = steps.max(1);
    let requests = (0..n).map(move |i| {
        let t = if n == 1 { 1.0 } else { i as f64 / (n - 1) as f64 };
        (0..3)
            .map(|k| from[k] + t * (to[k] - from[k]))
            .collect::<Vec<f64>>()
    });
    let names = vec!["target.x".to_string(), "target.y".into(), "target.z".into()];
    // The drawing traces the dragged marker.
    let mut drawn = free.clone();
    drawn.sweep = Some(Sweep::single(0, 0.0, 0.0, n, vec![id]));
    let svg = svg.map(|p| (p, &drawn));
    let point = |p: [f64; 3]| {
        format!(
            "({}, {}, {})",
            rounded(p[0], 9),
            rounded(p[1], 9),
            rounded(p[2], 9)
        )
    };
    let title = format!(
        "{}: {n} frames, drag of {marker} from {} to {}",
        m.name,
        point(from),
        point(to)
    );
    let value = |p: &[f64], f: fn(f64) -> String| format!("({}, {}, {})", f(p[0]), f(p[1]), f(p[2]));
    frames(
        &free,
        &plan,
        &names,
        requests,
        n,
        options,
        form,
        svg,
        &title,
        ("target", &value),
        progress,
        out,
    )
}

/// Drives `plan` through `requests` and writes each frame as it comes.
#[allow(clippy::too_many_arguments)]
fn frames(
    m: &Mechanism,
    plan: &Plan,
    input_names: &[String],
    requests: impl Iterator<Item = Vec<f64>>,
    total: usize,
    options: Options,
    form: Form,
    svg: Option<(&Path, &Mechanism)>,
    title: &str,
    (value_name, value): (&str, &Describe),
    progress: &mut dyn FrameProgress,
    out: &mut dyn Write,
) -> Outcome {
    let mut driver = Driver::new(Interpreter::new(plan.clone()), options);
    let names: Vec<String> = m.all_markers().map(|id| m.marker_name(id)).collect();
    match form {
        Form::Text => writeln!(out, "{title}")?,
        Form::Csv => writeln!(out, "{}", csv_head(input_names, &names).join(","))?,
        Form::Json => writeln!(
            out,
            "{{\"name\": {}, \"dimension\": 3, \"frames\": [",
            json!(m.name)
        )?,
    }
    let explain = |step: u32| explained(plan, step);
    let mut summary = Summary::new(value_name, value, &explain);
    let mut kept: Vec<SpatialFrame> = Vec::new();
    let mut worst: f64 = 0.0;
    progress.start(Some(total));
    for (i, requested) in requests.enumerate() {
        progress.tick(i);
        let status = driver.frame(&requested);
        let poses = driver.poses();
        let res = residual(m, poses, driver.inputs());
        worst = worst.max(res);
        let markers = marker_positions(m, poses);
        if svg.is_some() {
            kept.push(SpatialFrame {
                requested: requested.clone(),
                status,
                poses: poses.to_vec(),
            });
        }
        match form {
            Form::Csv => {
                let row = csv_row(i, status, driver.inputs(), &markers, res);
                writeln!(out, "{}", row.join(","))?;
            }
            Form::Json => {
                let frame = frame_value(
                    m,
                    &names,
                    input_names,
                    i,
                    status,
                    &requested,
                    driver.inputs(),
                    poses,
                    &markers,
                    res,
                );
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "  {frame}{sep}")?;
            }
            Form::Text => summary.frame(out, i, &requested, driver.inputs(), &status)?,
        }
    }
    progress.finish();
    if let Some((path, drawn)) = svg {
        if let Err(e) = std::fs::write(path, render_spatial(drawn, &kept)) {
            return Ok(Err(format!(
                "{}: error: cannot write the SVG: {e}",
                path.display()
            )));
        }
    }
    match form {
        Form::Json => writeln!(out, "]}}")?,
        Form::Csv => {}
        Form::Text => {
            let counts = summary.end(out)?;
            writeln!(out, "{counts}; largest joint residual {worst:.2e}")?;
            if let Some((path, _)) = svg {
                writeln!(out, "wrote {}", path.display())?;
            }
        }
    }
    Ok(Ok(()))
}

/// A step as the summary cites it: numbered and explained as `dofplan
/// plan` does.
fn explained(plan: &Plan, step: u32) -> (usize, String) {
    let shown = step_number(step);
    if shown < plan.steps.len() {
        (shown, plan.explain(shown))
    } else {
        (shown, String::new())
    }
}

/// The header of `simulate --csv` and `drag --csv`: the frame, its status
/// and the inputs (or the drag's target), every marker's position, the
/// joint residual.
fn csv_head(input_names: &[String], names: &[String]) -> Vec<String> {
    let mut head: Vec<String> = vec!["frame".into(), "status".into()];
    head.extend(input_names.iter().cloned());
    for n in names {
        for c in ["x", "y", "z"] {
            head.push(format!("{n}.{c}"));
        }
    }
    head.push("residual".into());
    head
}

/// Frame `i`'s row of the CSV, in the columns of [`csv_head`].
fn csv_row(i: usize, status: FrameStatus, inputs: &[f64], markers: &[Vec3], res: f64) -> Vec<String> {
    let mut row = vec![i.to_string(), status.name().to_string()];
    row.extend(inputs.iter().map(|v| number(*v)));
    for p in markers {
        row.extend(p.iter().map(|v| number(*v)));
    }
    row.push(number(res));
    row
}

/// One frame as `simulate --json` writes it: its number, status, the
/// inputs requested and reached, every marker (by "body.marker", `names`),
/// every body's rotation and position, and the largest joint residual.
#[allow(clippy::too_many_arguments)]
pub fn frame_value(
    m: &Mechanism,
    names: &[String],
    input_names: &[String],
    i: usize,
    status: FrameStatus,
    requested: &[f64],
    inputs: &[f64],
    poses: &[Pose3],
    markers: &[Vec3],
    res: f64,
) -> Value {
    let mut mk = Map::new();
    for (n, p) in names.iter().zip(markers) {
        mk.insert(n.clone(), json!(p));
    }
    let mut bodies = Map::new();
    for (b, pose) in m.bodies.iter().zip(poses) {
        bodies.insert(
            b.name.clone(),
            json!({"rotation": pose.rot.m, "position": pose.pos}),
        );
    }
    json!({
        "frame": i,
        "status": status.name(),
        "requested": requested,
        "inputs": input_names.iter().zip(inputs).map(|(n, v)| (n.clone(), json!(v))).collect::<Map<String, Value>>(),
        "markers": Value::Object(mk),
        "bodies": Value::Object(bodies),
        "residual": res,
    })
}
