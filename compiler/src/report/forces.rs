//! `dofplan analyze --forces`, the part both dimensions share: a sweep
//! whose every solved frame carries each input's force or torque (virtual
//! work) and each joint's reaction (every body's equilibrium), written as
//! a summary (each input's peak, the most loaded joint, the ground), JSON
//! (the dimension's frames with `"input_force"`, `"reactions"`,
//! `"reaction_moments"` and `"shaking"`) or CSV, streamed frame by frame,
//! and plots. Each dimension solves its frames (`planar/forces.rs`,
//! `spatial/forces.rs`) into the `Carried` form this file writes.

use std::io::Write;

use dofplan_runtime::FrameStatus;
use serde_json::{json, Map, Value};

use crate::forces::Advantage;
use crate::format::number;
use crate::interp::RateError;
use crate::model::{Input, InputKind, Sweep};
use crate::plan::num;
use crate::report::{at_input, Form, Outcome};
use crate::simulate::{input_rates, sweep_requests};

/// What the report names, from the mechanism of either dimension.
pub(crate) struct Names<'a> {
    /// The mechanism's name.
    pub name: &'a str,
    /// Its inputs.
    pub inputs: &'a [Input],
    /// Its joints' names.
    pub joints: Vec<&'a str>,
    /// Per joint: whether it carries a moment (listed in
    /// `"reaction_moments"` and the CSV).
    pub moments: Vec<bool>,
    /// Per joint: whether an input drives it (its advantage is not given).
    pub driven: Vec<bool>,
    /// Every marker's "body.marker".
    pub markers: Vec<String>,
    /// 2 or 3.
    pub dimension: usize,
    /// Whether the file has primitive constraints (no reactions then).
    pub constrained: bool,
    /// The axes a joint's reaction is drawn in by the polar plot: the
    /// world's x and y in the plane, the joint's first marker's x and y
    /// (across its axis) in space. Read only by the plots.
    #[cfg_attr(not(feature = "plots"), allow(dead_code))]
    pub polar_axes: (&'a str, &'a str),
}

/// A frame's joint reactions, in either dimension.
pub(crate) struct Carry {
    /// Per joint: the force its first body exerts on its second.
    pub forces: Vec<Vec<f64>>,
    /// Per joint: its moment (one number in the plane, a vector in space).
    pub moments: Vec<Vec<f64>>,
    /// The joints whose reactions are not unique here.
    pub indeterminate: Vec<usize>,
    /// The largest imbalance left on a body.
    pub residual: f64,
    /// The force and the moment on the ground.
    pub shaking: (Vec<f64>, Vec<f64>),
    /// Per joint: its force's components along [`Names::polar_axes`].
    pub polar: Vec<[f64; 2]>,
}

/// What one solved frame carries.
pub(crate) struct Carried {
    /// Each input's force or torque (virtual work).
    pub inputs: Vec<f64>,
    /// The mechanical advantage (one input only; `None` at a dead point).
    pub advantage: Option<Advantage>,
    /// The joints' reactions (`None`: a file with primitive constraints).
    pub reactions: Option<Carry>,
}

/// One frame as the dimension solved it.
pub(crate) struct Solved {
    /// How it went.
    pub status: FrameStatus,
    /// The frame as the dimension's `simulate --json` writes it (only
    /// asked for JSON).
    pub json: Option<Value>,
    /// Its forces (`None`: not solved; an error at a dead point).
    pub carried: Option<Result<Carried, RateError>>,
}

/// A vector's length.
fn size(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// What the summary gathers over the sweep.
#[derive(Default)]
struct Gathered {
    /// Per input: the largest |force| and the primary input's value there.
    inputs: Vec<Option<(f64, f64)>>,
    /// The joint with the largest reaction: (joint, |force|, input value).
    joint: Option<(usize, f64, f64)>,
    /// Joints whose reactions were not unique at some frame.
    indeterminate: std::collections::BTreeSet<usize>,
    /// The largest force and moment on the ground, with the input value
    /// where each is reached.
    ground: Option<((f64, f64), (f64, f64))>,
    /// The largest imbalance the reactions left, and the largest load.
    residual: f64,
    scale: f64,
    unsolved: usize,
    singular: usize,
    constrained: bool,
    /// For the plots: each input's value, and each joint's reaction
    /// magnitude, against the swept input (`None`: no value there).
    input_series: Vec<Vec<(f64, Option<f64>)>>,
    joint_series: Vec<Vec<(f64, Option<f64>)>>,
    /// Per joint, its reaction's components for the polar plot (`None`:
    /// no value there).
    polar_series: Vec<Vec<Option<[f64; 2]>>>,
}

impl Gathered {
    /// A frame with nothing to plot (not solved, a dead point).
    fn gap(&mut self, x: f64) {
        for s in self.input_series.iter_mut().chain(&mut self.joint_series) {
            s.push((x, None));
        }
        for s in &mut self.polar_series {
            s.push(None);
        }
    }

    fn add(&mut self, carried: &Result<Carried, RateError>, x: f64) {
        let c = match carried {
            Ok(c) => c,
            Err(_) => {
                self.singular += 1;
                self.gap(x);
                return;
            }
        };
        for (s, &v) in self.input_series.iter_mut().zip(&c.inputs) {
            s.push((x, Some(v)));
        }
        for (k, s) in self.joint_series.iter_mut().enumerate() {
            s.push((x, (c.reactions.as_ref()).map(|r| size(&r.forces[k]))));
        }
        for (k, s) in self.polar_series.iter_mut().enumerate() {
            s.push((c.reactions.as_ref()).map(|r| r.polar[k]));
        }
        for (peak, &v) in self.inputs.iter_mut().zip(&c.inputs) {
            if peak.is_none_or(|(best, _)| v.abs() > best.abs()) {
                *peak = Some((v, x));
            }
        }
        let Some(r) = &c.reactions else {
            self.constrained = true;
            return;
        };
        for (j, f) in r.forces.iter().enumerate() {
            let size = size(f);
            self.scale = self.scale.max(size);
            // Joints that carry the same load (to round-off) report the
            // first in the file, on every machine.
            if self.joint.is_none_or(|(_, best, _)| size > best * (1.0 + 1e-9)) {
                self.joint = Some((j, size, x));
            }
        }
        self.indeterminate.extend(r.indeterminate.iter().copied());
        self.residual = self.residual.max(r.residual);
        let (force, moment) = (size(&r.shaking.0), size(&r.shaking.1));
        let ((f0, fx), (m0, mx)) = self.ground.unwrap_or(((force, x), (moment, x)));
        self.ground = Some((
            if force > f0 * (1.0 + 1e-9) {
                (force, x)
            } else {
                (f0, fx)
            },
            if moment > m0 * (1.0 + 1e-9) {
                (moment, x)
            } else {
                (m0, mx)
            },
        ));
    }
}

/// How a mechanism runs for kinetostatics: its first swept input's rate
/// and acceleration (radians per second and per second squared for an
/// angle, length units for a slide), the sweep's other inputs in
/// proportion, as `analyze --rate` moves them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Running {
    /// The first swept input's rate.
    pub rate: f64,
    /// Its acceleration.
    pub acceleration: f64,
}

impl Running {
    /// Each input's rate and acceleration in the plan's units (degrees
    /// for an angle).
    pub(crate) fn of(self, inputs: &[Input], sweep: &Sweep) -> (Vec<f64>, Vec<f64>) {
        (
            input_rates(inputs, sweep, self.rate),
            input_rates(inputs, sweep, self.acceleration),
        )
    }

    /// "theta at 10 rad/s" (", accelerating at 2 rad/s²" when it does).
    fn text(self, input: &Input) -> String {
        let mut text = format!("{} at {}", input.name, rate_text(input.kind, self.rate, ""));
        if self.acceleration != 0.0 {
            text += &format!(
                ", accelerating at {}",
                rate_text(input.kind, self.acceleration, "²")
            );
        }
        text
    }
}

/// Where the plots go: the SVG file and the joint whose reaction the
/// polar plot draws (`None`: the most loaded).
#[derive(Clone, Copy, Debug)]
pub struct Plots<'a> {
    /// The SVG file.
    pub svg: &'a std::path::Path,
    /// `--polar JOINT`.
    pub polar: Option<&'a str>,
}

/// Runs the sweep, `frame` solving each requested frame (with its JSON
/// when `Form::Json` asks): statics when `running` is None, kinetostatics
/// as it says otherwise (the caller's `frame` knows which); with `plots`,
/// plots written there.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    names: &Names,
    sweep: &Sweep,
    running: Option<Running>,
    form: Form,
    plots: Option<Plots>,
    out: &mut dyn Write,
    mut frame: impl FnMut(usize, &[f64], bool) -> Solved,
) -> Outcome {
    let polar = match plots.and_then(|p| p.polar) {
        None => None,
        Some(name) => match names.joints.iter().position(|j| *j == name) {
            Some(j) if !names.constrained => Some(j),
            Some(_) => {
                return Ok(Err(format!(
                    "error: --polar {name}: joint reactions are not computed for files with primitive constraints yet"
                )))
            }
            None => {
                return Ok(Err(format!(
                    "error: --polar: `{name}` is not a joint of {}\n  help: its joints are: {}",
                    names.name,
                    names.joints.join(", ")
                )))
            }
        },
    };
    let svg = plots.map(|p| p.svg);
    match form {
        Form::Json => {
            let how = match running {
                None => String::new(),
                Some(r) => format!(
                    "\n  \"rate\": {},\n  \"acceleration\": {},",
                    json!(r.rate),
                    json!(r.acceleration)
                ),
            };
            writeln!(
                out,
                "{{\n  \"mechanism\": {},\n  \"dimension\": {},\n  \"forces\": {},{how}\n  \"frames\": [",
                json!(names.name),
                names.dimension,
                json!(if running.is_some() {
                    "kinetostatic"
                } else {
                    "static"
                })
            )?
        }
        Form::Csv => writeln!(out, "{}", csv_head(names).join(","))?,
        Form::Text => {}
    }
    let primary = sweep.primary().input;
    let mut gathered = Gathered {
        inputs: vec![None; names.inputs.len()],
        input_series: vec![Vec::new(); if svg.is_some() { names.inputs.len() } else { 0 }],
        joint_series: vec![
            Vec::new();
            if svg.is_some() && !names.constrained {
                names.joints.len()
            } else {
                0
            }
        ],
        polar_series: vec![
            Vec::new();
            if svg.is_some() && !names.constrained {
                names.joints.len()
            } else {
                0
            }
        ],
        ..Gathered::default()
    };
    let total = sweep.steps;
    for (i, requested) in sweep_requests(sweep, names.inputs.len()).enumerate() {
        let solved = frame(i, &requested, form == Form::Json);
        match &solved.carried {
            Some(c) => gathered.add(c, requested[primary]),
            None => {
                gathered.unsolved += 1;
                gathered.gap(requested[primary]);
            }
        }
        let carried = solved.carried.and_then(Result::ok);
        match form {
            Form::Json => {
                let mut o = solved.json.unwrap_or(Value::Null);
                add_json(&mut o, names, carried.as_ref());
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "    {o}{sep}")?;
            }
            Form::Csv => {
                let mut row = vec![i.to_string()];
                row.extend(requested.iter().map(|v| number(*v)));
                row.push(solved.status.name().to_string());
                row.extend(csv_values(names, carried.as_ref()));
                writeln!(out, "{}", row.join(","))?;
            }
            Form::Text => {}
        }
    }
    match form {
        Form::Json => writeln!(out, "  ]\n}}")?,
        Form::Csv => {}
        Form::Text => summary(names, sweep, running, &gathered, out)?,
    }
    match svg {
        Some(path) => {
            let swept = &names.inputs[primary];
            let polar = polar.or(gathered.joint.map(|(j, _, _)| j));
            draw(names, swept, running, &gathered, (path, polar), form, out)
        }
        None => Ok(Ok(())),
    }
}

/// Writes the plots to `path`: each input's force against the swept
/// input, then the joints' reactions, the most loaded first, then the
/// `polar` joint's reaction as a polar diagram.
#[cfg(feature = "plots")]
fn draw(
    names: &Names,
    swept: &Input,
    running: Option<Running>,
    g: &Gathered,
    (path, polar): (&std::path::Path, Option<usize>),
    form: Form,
    out: &mut dyn Write,
) -> Outcome {
    let axis = match swept.kind {
        InputKind::Angle => format!("{} (degrees)", swept.name),
        InputKind::Slide => format!("{} (length)", swept.name),
    };
    let how = match running {
        None => "held still".to_string(),
        Some(r) => r.text(swept),
    };
    let inputs: Vec<crate::render::plots::Series> = (names.inputs.iter().zip(&g.input_series))
        .map(|(i, s)| (i.name.as_str(), s.clone()))
        .collect();
    let peak = |s: &[(f64, Option<f64>)]| s.iter().filter_map(|p| p.1).fold(0.0f64, f64::max);
    let mut joints: Vec<crate::render::plots::Series> = (names.joints.iter().zip(&g.joint_series))
        .map(|(j, s)| (*j, s.clone()))
        .collect();
    joints.sort_by(|a, b| peak(&b.1).total_cmp(&peak(&a.1)));
    let polar = polar.map(|j| crate::render::plots::Polar {
        joint: names.joints[j],
        axes: names.polar_axes,
        points: g.polar_series[j].clone(),
    });
    let drawn = crate::render::plots::draw_forces(names.name, (&axis, &how), &inputs, &joints, polar);
    let text = match drawn {
        Ok(text) => text,
        Err(e) => {
            return Ok(Err(format!(
                "{}: error: cannot draw the plots: {e}",
                path.display()
            )))
        }
    };
    if let Err(e) = std::fs::write(path, text) {
        return Ok(Err(format!(
            "{}: error: cannot write the plots: {e}",
            path.display()
        )));
    }
    if form == Form::Text {
        writeln!(out, "wrote {}", path.display())?;
    }
    Ok(Ok(()))
}

/// Without the `plots` feature there is nothing to draw with.
#[cfg(not(feature = "plots"))]
fn draw(
    _: &Names,
    _: &Input,
    _: Option<Running>,
    _: &Gathered,
    (path, _): (&std::path::Path, Option<usize>),
    _: Form,
    _: &mut dyn Write,
) -> Outcome {
    Ok(Err(format!(
        "{}: error: this build has no plots (the `plots` feature is off)",
        path.display()
    )))
}

/// One number in the plane, a vector in space.
fn moment_json(v: &[f64]) -> Value {
    match v {
        [one] => json!(one),
        many => json!(many),
    }
}

/// The keys `--forces --json` adds to a frame: `"input_force"` (input ->
/// force or torque), `"reactions"` (joint -> the force its first body
/// exerts on its second), `"reaction_moments"` (the joints that carry a
/// moment), `"shaking"` (the force and moment the mechanism exerts on the
/// ground), `"mechanical_advantage"` (one input: per joint and marker) and `"indeterminate"` (joints whose reactions are not unique
/// there); null where the frame has none.
fn add_json(o: &mut Value, names: &Names, carried: Option<&Carried>) {
    let Some(c) = carried else {
        o["input_force"] = Value::Null;
        o["reactions"] = Value::Null;
        return;
    };
    let named = |pairs: Vec<(String, Value)>| Value::Object(pairs.into_iter().collect::<Map<_, _>>());
    o["input_force"] = named(
        (names.inputs.iter())
            .map(|i| i.name.clone())
            .zip(c.inputs.iter().map(|v| json!(v)))
            .collect(),
    );
    let Some(r) = &c.reactions else {
        o["reactions"] = Value::Null;
        return;
    };
    o["reactions"] = named(
        (names.joints.iter())
            .map(|j| j.to_string())
            .zip(r.forces.iter().map(|f| json!(f)))
            .collect(),
    );
    let moments: Vec<(String, Value)> = (0..names.joints.len())
        .filter(|&j| names.moments[j])
        .map(|j| (names.joints[j].to_string(), moment_json(&r.moments[j])))
        .collect();
    if !moments.is_empty() {
        o["reaction_moments"] = named(moments);
    }
    o["shaking"] = json!({"force": r.shaking.0, "moment": moment_json(&r.shaking.1)});
    if let Some(a) = &c.advantage {
        // Gear pairs, named after the joints, have no advantage of their own.
        let joints = (0..names.joints.len().min(a.joints.len()))
            .filter(|&j| !names.driven[j])
            .map(|j| (names.joints[j].to_string(), json!(a.joints[j])))
            .collect();
        let markers = (names.markers.iter().cloned())
            .zip(a.markers.iter().map(|v| json!(v)))
            .collect();
        o["mechanical_advantage"] = json!({"joints": named(joints), "markers": named(markers)});
    }
    if !r.indeterminate.is_empty() {
        o["indeterminate"] = json!(r
            .indeterminate
            .iter()
            .map(|&j| names.joints[j])
            .collect::<Vec<_>>());
    }
}

/// The axes' names of a vector: "x", "y" (and "z").
fn axes(names: &Names) -> &'static [&'static str] {
    &["x", "y", "z"][..names.dimension]
}

/// The columns of a joint's moment: "m" in the plane, "mx", "my", "mz" in
/// space.
fn moment_columns(names: &Names) -> Vec<String> {
    match names.dimension {
        2 => vec!["m".into()],
        _ => axes(names).iter().map(|a| format!("m{a}")).collect(),
    }
}

/// The header of `--forces --csv`: frame, inputs, status, each input's
/// force, each joint's reaction (and moment, where it carries one), the
/// force and moment on the ground.
fn csv_head(names: &Names) -> Vec<String> {
    let mut head = vec!["frame".to_string()];
    head.extend(names.inputs.iter().map(|i| i.name.clone()));
    head.push("status".into());
    head.extend(names.inputs.iter().map(|i| format!("{}.force", i.name)));
    for (j, joint) in names.joints.iter().enumerate() {
        head.extend(axes(names).iter().map(|a| format!("{joint}.f{a}")));
        if names.moments[j] {
            head.extend(moment_columns(names).iter().map(|c| format!("{joint}.{c}")));
        }
    }
    head.extend(axes(names).iter().map(|a| format!("shaking.f{a}")));
    head.extend(moment_columns(names).iter().map(|c| format!("shaking.{c}")));
    head
}

/// A frame's numbers in [`csv_head`]'s columns (empty where there are none:
/// not solved, a dead point, primitive constraints).
fn csv_values(names: &Names, carried: Option<&Carried>) -> Vec<String> {
    let mut row = Vec::new();
    match carried {
        Some(c) => row.extend(c.inputs.iter().map(|v| number(*v))),
        None => row.extend(std::iter::repeat_n(String::new(), names.inputs.len())),
    }
    let reactions = carried.and_then(|c| c.reactions.as_ref());
    let (d, dm) = (names.dimension, moment_columns(names).len());
    let mut cells = |values: Option<&[f64]>, n: usize| match values {
        Some(v) => row.extend(v.iter().map(|x| number(*x))),
        None => row.extend(std::iter::repeat_n(String::new(), n)),
    };
    for j in 0..names.joints.len() {
        cells(reactions.map(|r| &r.forces[j][..]), d);
        if names.moments[j] {
            cells(reactions.map(|r| &r.moments[j][..]), dm);
        }
    }
    cells(reactions.map(|r| &r.shaking.0[..]), d);
    cells(reactions.map(|r| &r.shaking.1[..]), dm);
    row
}

/// The text summary: how the sweep ran, each input's peak force or
/// torque and where, the most loaded joint, and what is not unique or
/// not computed.
fn summary(
    names: &Names,
    sweep: &Sweep,
    running: Option<Running>,
    g: &Gathered,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let primary = &names.inputs[sweep.primary().input];
    let how = match running {
        None => "held still at each pose (statics)".to_string(),
        Some(r) => format!("running with {} (kinetostatics)", r.text(primary)),
    };
    writeln!(out, "{}: {} frames, {how}", names.name, sweep.steps)?;
    // An input whose force is round-off at every frame next to the others
    // (and the joints') needs none: its "peak" would name a frame at random.
    let loads = (g.inputs.iter().flatten())
        .map(|(v, _)| v.abs())
        .fold(g.scale, f64::max);
    for (input, peak) in names.inputs.iter().zip(&g.inputs) {
        let what = match input.kind {
            InputKind::Angle => "torque",
            InputKind::Slide => "force",
        };
        match peak {
            Some((v, _)) if v.abs() <= 1e-9 * loads => writeln!(
                out,
                "  input {}: no {what} needed (round-off at every frame)",
                input.name
            )?,
            Some((v, x)) => writeln!(
                out,
                "  input {}: peak {what} {} at {}",
                input.name,
                num(*v),
                at_input(primary, *x)
            )?,
            None => writeln!(out, "  input {}: no frame solved", input.name)?,
        }
    }
    if let Some((j, size, x)) = g.joint {
        writeln!(
            out,
            "  most loaded joint: {}, {} at {}",
            names.joints[j],
            num(size),
            at_input(primary, x)
        )?;
    }
    if let Some(((force, fx), (moment, mx))) = g.ground {
        writeln!(
            out,
            "  on the ground: force up to {} at {}, moment (about the origin) up to {} at {}",
            num(force),
            at_input(primary, fx),
            num(moment),
            at_input(primary, mx)
        )?;
    }
    if !g.indeterminate.is_empty() {
        let joints: Vec<&str> = g.indeterminate.iter().map(|&j| names.joints[j]).collect();
        writeln!(
            out,
            "  the reactions at {} are not unique (the mechanism is over-constrained; the least-norm ones are given)",
            joints.join(", ")
        )?;
    }
    if g.residual > 1e-9 * g.scale.max(1.0) {
        writeln!(
            out,
            "  the joints and inputs cannot hold every body: up to {} is left unbalanced (a freedom no input holds)",
            num(g.residual)
        )?;
    }
    if g.constrained {
        writeln!(
            out,
            "  joint reactions are not computed for files with primitive constraints yet"
        )?;
    }
    if g.unsolved > 0 {
        writeln!(out, "  {} frames not solved (no forces there)", g.unsolved)?;
    }
    if g.singular > 0 {
        writeln!(
            out,
            "  {} frames at a dead point (the input force is not defined there)",
            g.singular
        )?;
    }
    Ok(())
}

/// "2 rad/s", "0.5 length/s".
/// A rate (`power` "") or an acceleration ("²") with its unit.
fn rate_text(kind: InputKind, r: f64, power: &str) -> String {
    match kind {
        InputKind::Angle => format!("{} rad/s{power}", num(r)),
        InputKind::Slide => format!("{} length/s{power}", num(r)),
    }
}

/// The error of a file that gives nothing to compute forces from.
pub(crate) fn no_loads(source: &str) -> String {
    format!(
        "{source}: error: the file gives no masses, gravity or loads, so every force is 0\n  help: add [loads.NAME] entries, [gravity] g = [0, -9.81] (in space [0, 0, -9.81]) with bodies' `mass`, `centre` and `inertia` (see docs/guide/forces.md)"
    )
}
