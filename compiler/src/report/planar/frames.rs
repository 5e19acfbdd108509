//! The frames of `dofplan simulate` and `drag` on planar files, written as
//! they are solved: a summary naming every run of frames that broke alike,
//! one JSON document, or one CSV row per frame; and drawn as an SVG.

use std::io::{self, Write};
use std::path::Path;

use dofplan_runtime::planar::Pose;
use dofplan_runtime::{Animate, Driver, FrameStatus, Options};
use serde_json::{json, Map, Value};

use crate::format::number;
use crate::interp::Interpreter;
use crate::model::{MarkerId, Mechanism, Sweep};
use crate::numeric::planar::drag::Drag;
use crate::numeric::PureNewton;
use crate::plan::Plan;
use crate::render::{render, SvgOptions};
use crate::simulate::{frames, marker_positions, sweep_requests, Frame};

use crate::report::summary::{Describe, Explain, Summary};
use crate::report::{error, precise, Form, FrameProgress, Outcome};

/// What moves the mechanism through a sweep.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// The plan: closed-form steps.
    Plan,
    /// Newton–Raphson on every mobile link (the baseline).
    Newton,
}

/// `dofplan simulate` of a planar file: `sweep` run by `solver`, the frames
/// written in `form` as they are solved, and drawn into `svg`.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    m: &Mechanism,
    plan: &Plan,
    sweep: &Sweep,
    options: Options,
    solver: Solver,
    form: Form,
    svg: Option<&Path>,
    progress: &mut dyn FrameProgress,
    out: &mut dyn Write,
) -> Outcome {
    let mut driver: Box<dyn Animate> = match solver {
        Solver::Plan => Box::new(Driver::new(Interpreter::new(plan.clone()), options)),
        Solver::Newton => Box::new(Driver::new(PureNewton::new(m), options)),
    };
    let report = sweep_report(m, plan, sweep, solver);
    let requested = sweep_requests(sweep, m.inputs.len());
    output(
        &report,
        frames(driver.as_mut(), requested),
        form,
        svg,
        progress,
        out,
    )
}

/// The report of a sweep (`simulate`, `analyze`): its title, the inputs'
/// names, and how a break is explained.
pub fn sweep_report<'a>(m: &'a Mechanism, plan: &'a Plan, sweep: &Sweep, solver: Solver) -> Report<'a> {
    let input = sweep.primary().input;
    let name = m.inputs[input].name.clone();
    let ranges: Vec<String> = sweep
        .inputs
        .iter()
        .map(|s| {
            format!(
                "{} from {} to {}",
                m.inputs[s.input].name,
                precise(s.from),
                precise(s.to)
            )
        })
        .collect();
    Report {
        m,
        title: format!("{}: {} frames, {}", m.name, sweep.steps, ranges.join(", ")),
        input_names: m.inputs.iter().map(|i| i.name.clone()).collect(),
        value_name: name,
        value: Box::new(move |inputs, f| f(inputs[input])),
        explain: Box::new(move |step| match solver {
            Solver::Plan => plan.explain(step as usize),
            Solver::Newton => "Newton-Raphson on every mobile link".to_string(),
        }),
        trace: sweep.trace.clone(),
        targets: false,
    }
}

/// `dofplan drag` of a planar file (`place` names it): `marker` pinned to
/// `steps` targets evenly spaced from `from` (default: where it is drawn)
/// to `to`, the inputs released; the frames written in `form` as they are
/// solved, and drawn into `svg`.
#[allow(clippy::too_many_arguments)]
pub fn drag(
    m: &Mechanism,
    place: &str,
    marker: &str,
    from: Option<[f64; 2]>,
    to: [f64; 2],
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
            place,
            &format!("no marker `{marker}` to drag"),
            &format!("markers are: {}", names.join(", ")),
        )));
    };
    let solver = match Drag::new(m, id) {
        Ok(d) => d,
        Err(e) => return Ok(Err(format!("{place}: error: {e}"))),
    };
    let from = from.unwrap_or(m.marker(id).at);
    let targets = (0..steps).map(move |i| {
        let t = if steps == 1 {
            1.0
        } else {
            i as f64 / (steps - 1) as f64
        };
        [from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
    });
    let point = |p: &[f64], f: fn(f64) -> String| format!("({}, {})", f(p[0]), f(p[1]));
    let report = Report {
        m,
        title: format!(
            "{}: {steps} frames, drag of {marker} from {} to {}",
            m.name,
            point(&from, precise),
            point(&to, precise)
        ),
        input_names: vec![format!("{marker}.x"), format!("{marker}.y")],
        value_name: "target".into(),
        value: Box::new(point),
        explain: Box::new(|_| format!("drag of {marker}")),
        trace: vec![id],
        targets: true,
    };
    let mut driver = Driver::new(solver, options);
    output(&report, frames(&mut driver, targets), form, svg, progress, out)
}

/// What the output of a run of frames needs besides the frames: how to
/// name the inputs, how to explain a step, which markers to trace.
pub struct Report<'a> {
    /// The mechanism run.
    pub m: &'a Mechanism,
    /// The summary's first line: what is run.
    pub title: String,
    /// The names of the inputs, keys of JSON's "inputs" and CSV columns.
    pub input_names: Vec<String>,
    /// What the summary calls the driven value ("theta", "target")…
    pub value_name: String,
    /// …and how it writes that value from a frame's inputs.
    pub value: Box<Describe<'a>>,
    /// A step's explanation, as `dofplan plan` gives it.
    pub explain: Box<dyn Fn(u32) -> String + 'a>,
    /// The markers whose paths the SVG draws.
    pub trace: Vec<MarkerId>,
    /// The frames' requested values are a drag's targets, drawn in the SVG.
    pub targets: bool,
}

/// Writes the frames as they come, in `form`, keeping them only when an SVG
/// is to be drawn from them.
fn output(
    r: &Report,
    frames: impl Iterator<Item = Frame>,
    form: Form,
    svg: Option<&Path>,
    progress: &mut dyn FrameProgress,
    out: &mut dyn Write,
) -> Outcome {
    // Steps of a planar plan are shown by their own index.
    let explain = |step: u32| (step as usize, (r.explain)(step));
    let explain: &Explain = &explain;
    let mut writer: Box<dyn FrameWriter + '_> = match form {
        Form::Json => Box::new(JsonFrames { r, count: 0 }),
        Form::Csv => Box::new(CsvFrames { r }),
        Form::Text => Box::new(TextFrames {
            title: &r.title,
            summary: Summary::new(&r.value_name, &*r.value, explain),
        }),
    };
    writer.begin(out)?;
    let mut kept = Vec::new();
    progress.start(frames.size_hint().1);
    for (i, f) in frames.enumerate() {
        writer.frame(out, i, &f)?;
        if svg.is_some() {
            kept.push(f);
        }
        progress.tick(i + 1);
    }
    progress.finish();
    writer.end(out)?;
    if let Some(path) = svg {
        let options = SvgOptions {
            targets: if r.targets {
                kept.iter().map(|f| [f.requested[0], f.requested[1]]).collect()
            } else {
                Vec::new()
            },
            ..SvgOptions::default()
        };
        let text = render(r.m, &kept, &r.trace, &options);
        if let Err(e) = std::fs::write(path, text) {
            return Ok(Err(format!(
                "{}: error: cannot write the SVG: {e}",
                path.display()
            )));
        }
        if form == Form::Text {
            writeln!(out, "wrote {}", path.display())?;
        }
    }
    Ok(Ok(()))
}

/// Writes frames one at a time.
trait FrameWriter {
    /// Before the first frame.
    fn begin(&mut self, out: &mut dyn Write) -> io::Result<()>;
    /// Frame number `index`.
    fn frame(&mut self, out: &mut dyn Write, index: usize, f: &Frame) -> io::Result<()>;
    /// After the last frame.
    fn end(&mut self, out: &mut dyn Write) -> io::Result<()>;
}

/// `{"mechanism": …, "frames": [ … ]}`, written a frame at a time (one a
/// line) so no frame is kept.
struct JsonFrames<'r, 'a> {
    r: &'r Report<'a>,
    count: usize,
}

impl FrameWriter for JsonFrames<'_, '_> {
    fn begin(&mut self, out: &mut dyn Write) -> io::Result<()> {
        writeln!(
            out,
            "{{\n  \"mechanism\": {},\n  \"frames\": [",
            json!(self.r.m.name)
        )
    }

    fn frame(&mut self, out: &mut dyn Write, _: usize, f: &Frame) -> io::Result<()> {
        if self.count > 0 {
            writeln!(out, ",")?;
        }
        self.count += 1;
        write!(out, "    ")?;
        serde_json::to_writer(&mut *out, &frame_json(self.r, f))?;
        Ok(())
    }

    fn end(&mut self, out: &mut dyn Write) -> io::Result<()> {
        if self.count > 0 {
            writeln!(out)?;
        }
        writeln!(out, "  ]\n}}")
    }
}

/// One frame as `simulate --json` writes it.
pub fn frame_json(r: &Report, f: &Frame) -> Value {
    let m = r.m;
    let named = |vals: &[f64]| -> Value {
        Value::Object(
            r.input_names
                .iter()
                .zip(vals)
                .map(|(n, v)| (n.clone(), json!(v)))
                .collect(),
        )
    };
    let mut o = Map::new();
    o.insert("inputs".into(), named(&f.requested));
    // A frame the sweep has not reached has no pose: null, not the drawing.
    let unreached = matches!(f.status, FrameStatus::Unreached { .. });
    o.insert(
        "reached".into(),
        if unreached { Value::Null } else { named(&f.inputs) },
    );
    o.insert("status".into(), json!(f.status.name()));
    if let Some((k, v)) = status_json(r, &f.status) {
        o.insert(k.into(), v);
    }
    if unreached {
        o.insert("markers".into(), Value::Null);
        o.insert("bodies".into(), Value::Null);
        return Value::Object(o);
    }
    if let Some(n) = &f.numeric {
        o.insert(
            "newton".into(),
            json!({
                "outcome": format!("{:?}", n.outcome).to_lowercase(),
                "iterations": n.iterations,
                "residual": n.residual,
                "rank": n.rank,
            }),
        );
    }
    o.insert(
        "markers".into(),
        Value::Object(
            marker_positions(m, &f.poses)
                .into_iter()
                .map(|(k, p)| (k, json!(p)))
                .collect(),
        ),
    );
    o.insert(
        "bodies".into(),
        Value::Object(
            m.bodies
                .iter()
                .zip(&f.poses)
                .map(|(b, p)| {
                    let pose = json!({"angle": angle(p), "x": p.at[0], "y": p.at[1]});
                    (b.name.clone(), pose)
                })
                .collect(),
        ),
    );
    Value::Object(o)
}

/// A body's rotation from its drawn pose in degrees, in (−180, 180]: the
/// `angle` of `simulate --json` and of the Python package's poses.
pub fn angle(p: &Pose) -> f64 {
    let a = p.rot.degrees();
    // atan2 gives −180 for a half turn whose sine rounded to −0.
    if a <= -180.0 {
        a + 360.0
    } else {
        a
    }
}

/// The "break" or "stretch" detail of a frame that was not solved.
fn status_json(r: &Report, status: &FrameStatus) -> Option<(&'static str, Value)> {
    let brk = |b: &dofplan_runtime::Break| {
        json!({
            "step": b.step,
            "explanation": (r.explain)(b.step),
            "reason": b.kind.describe(),
            "gap": b.gap,
        })
    };
    match status {
        FrameStatus::Solved => None,
        FrameStatus::Limited { brk: b } | FrameStatus::Unreached { brk: b } => Some(("break", brk(b))),
        FrameStatus::Searched { brk: b, reached } => Some(("break", {
            let mut v = brk(b);
            v["reached"] = json!(reached);
            v
        })),
        FrameStatus::Stretched { step, residual } => Some((
            "stretch",
            json!({"step": step, "explanation": (r.explain)(*step), "residual": residual}),
        )),
    }
}

/// One CSV row per frame.
struct CsvFrames<'r, 'a> {
    r: &'r Report<'a>,
}

impl FrameWriter for CsvFrames<'_, '_> {
    fn begin(&mut self, out: &mut dyn Write) -> io::Result<()> {
        let m = self.r.m;
        let mut header = vec!["frame".to_string()];
        header.extend(self.r.input_names.iter().cloned());
        header.push("status".into());
        for id in m.all_markers() {
            let n = m.marker_name(id);
            header.push(format!("{n}.x"));
            header.push(format!("{n}.y"));
        }
        for b in &m.bodies {
            for field in ["angle", "x", "y"] {
                header.push(format!("{}.{field}", b.name));
            }
        }
        writeln!(out, "{}", header.join(","))
    }

    fn frame(&mut self, out: &mut dyn Write, index: usize, f: &Frame) -> io::Result<()> {
        let mut row = vec![index.to_string()];
        row.extend(f.requested.iter().map(|v| number(*v)));
        row.push(f.status.name().to_string());
        if matches!(f.status, FrameStatus::Unreached { .. }) {
            // No pose: empty cells, not the drawing's numbers.
            let cells = 2 * self.r.m.all_markers().count() + 3 * f.poses.len();
            row.extend(std::iter::repeat_n(String::new(), cells));
            return writeln!(out, "{}", row.join(","));
        }
        for (_, p) in marker_positions(self.r.m, &f.poses) {
            row.push(number(p[0]));
            row.push(number(p[1]));
        }
        for p in &f.poses {
            row.push(number(angle(p)));
            row.push(number(p.at[0]));
            row.push(number(p.at[1]));
        }
        writeln!(out, "{}", row.join(","))
    }

    fn end(&mut self, _: &mut dyn Write) -> io::Result<()> {
        Ok(())
    }
}

/// The text summary of a planar run (`cli/summary.rs`): the title, the
/// runs of frames that broke alike, the counts.
struct TextFrames<'r> {
    title: &'r str,
    summary: Summary<'r>,
}

impl FrameWriter for TextFrames<'_> {
    fn begin(&mut self, out: &mut dyn Write) -> io::Result<()> {
        writeln!(out, "{}", self.title)
    }

    fn frame(&mut self, out: &mut dyn Write, index: usize, f: &Frame) -> io::Result<()> {
        self.summary.frame(out, index, &f.requested, &f.inputs, &f.status)
    }

    fn end(&mut self, out: &mut dyn Write) -> io::Result<()> {
        let counts = self.summary.end(out)?;
        writeln!(out, "{counts}")
    }
}
