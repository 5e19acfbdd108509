//! `dofplan analyze --forces` on a planar file: what each input must
//! supply over the sweep (`forces::planar::input_forces`, virtual work)
//! and what each joint carries (`forces::planar::reactions`, every body's
//! equilibrium), as a summary (each input's peak, the most loaded joint),
//! JSON (simulate's frames with `"input_force"`, `"reactions"` and
//! `"reaction_moments"`) or CSV, streamed frame by frame.

use std::io::Write;

use dofplan_runtime::{Driver, FrameStatus, Options};
use serde_json::{json, Map, Value};

use super::frames::{frame_json, sweep_report, Solver};
use crate::forces::planar::{advantage, input_forces, reactions, Advantage, Moving, Reactions};
use crate::format::number;
use crate::interp::{Interpreter, RateError};
use crate::model::{InputKind, JointKind, Mechanism, Sweep};
use crate::plan::{num, Plan};
use crate::report::{at_input, Form, Outcome};
use crate::simulate::{sweep_rates, sweep_requests, Frame};

/// What one solved frame carries.
struct Carried {
    /// Each input's force or torque (virtual work).
    inputs: Vec<f64>,
    /// The mechanical advantage (one input only; `None` at a dead point).
    advantage: Option<Advantage>,
    /// The joints' reactions (`None`: a file with primitive constraints).
    reactions: Option<Reactions>,
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
}

impl Gathered {
    /// A frame with nothing to plot (not solved, a dead point).
    fn gap(&mut self, x: f64) {
        for s in self.input_series.iter_mut().chain(&mut self.joint_series) {
            s.push((x, None));
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
            let size = (c.reactions.as_ref()).map(|r| r.forces[k][0].hypot(r.forces[k][1]));
            s.push((x, size));
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
            let size = f[0].hypot(f[1]);
            self.scale = self.scale.max(size);
            // Joints that carry the same load (to round-off) report the
            // first in the file, on every machine.
            if self.joint.is_none_or(|(_, best, _)| size > best * (1.0 + 1e-9)) {
                self.joint = Some((j, size, x));
            }
        }
        self.indeterminate.extend(r.indeterminate.iter().copied());
        self.residual = self.residual.max(r.residual);
        let (force, moment) = (r.shaking[0].hypot(r.shaking[1]), r.shaking[2].abs());
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

/// Runs the sweep with each frame's input forces and joint reactions:
/// statics when `rate` is None (the mechanism held at each pose: no
/// inertia, dampers idle), kinetostatics at the first swept input's `rate`
/// (radians or length per second, the others in proportion, no
/// acceleration) when given; with `svg`, plots written there.
#[allow(clippy::too_many_arguments)]
pub fn run(
    m: &Mechanism,
    plan: &Plan,
    sweep: &Sweep,
    rate: Option<f64>,
    form: Form,
    svg: Option<&std::path::Path>,
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
    match form {
        Form::Json => writeln!(
            out,
            "{{\n  \"mechanism\": {},\n  \"forces\": {},\n  \"frames\": [",
            json!(m.name),
            json!(if rate.is_some() { "kinetostatic" } else { "static" })
        )?,
        Form::Csv => writeln!(out, "{}", csv_head(m).join(","))?,
        Form::Text => {}
    }
    let primary = sweep.primary().input;
    let mut gathered = Gathered {
        inputs: vec![None; m.inputs.len()],
        input_series: vec![Vec::new(); if svg.is_some() { m.inputs.len() } else { 0 }],
        joint_series: vec![
            Vec::new();
            if svg.is_some() && m.constraints.is_empty() {
                m.joints.len()
            } else {
                0
            }
        ],
        ..Gathered::default()
    };
    let total = sweep.steps;
    for (i, requested) in sweep_requests(sweep, m.inputs.len()).enumerate() {
        let status = driver.frame(&requested);
        let carried = (status == FrameStatus::Solved).then(|| {
            let q = input_forces(m, &interp, driver.state(), driver.inputs(), moving)?;
            let actual = match moving {
                Some(mv) => {
                    Some(interp.rates(driver.state(), driver.inputs(), mv.rates, mv.accelerations)?)
                }
                None => None,
            };
            Ok(Carried {
                inputs: q,
                advantage: advantage(m, &interp, driver.state(), driver.inputs()).and_then(Result::ok),
                reactions: reactions(m, driver.poses(), actual.as_deref()),
            })
        });
        match &carried {
            Some(c) => gathered.add(c, requested[primary]),
            None => {
                gathered.unsolved += 1;
                gathered.gap(requested[primary]);
            }
        }
        let carried = carried.and_then(Result::ok);
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
                add_json(&mut o, m, carried.as_ref());
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "    {o}{sep}")?;
            }
            Form::Csv => {
                let mut row = vec![i.to_string()];
                row.extend(requested.iter().map(|v| number(*v)));
                row.push(status.name().to_string());
                row.extend(csv_values(m, carried.as_ref()));
                writeln!(out, "{}", row.join(","))?;
            }
            Form::Text => {}
        }
    }
    match form {
        Form::Json => writeln!(out, "  ]\n}}")?,
        Form::Csv => {}
        Form::Text => summary(m, sweep, rate, &gathered, out)?,
    }
    match svg {
        Some(path) => plots(m, &m.inputs[primary], rate, &gathered, path, form, out),
        None => Ok(Ok(())),
    }
}

/// Writes the plots to `path`: each input's force against the swept
/// input, then the joints' reactions, the most loaded first.
#[cfg(feature = "plots")]
fn plots(
    m: &Mechanism,
    swept: &crate::model::Input,
    rate: Option<f64>,
    g: &Gathered,
    path: &std::path::Path,
    form: Form,
    out: &mut dyn Write,
) -> Outcome {
    let axis = match swept.kind {
        InputKind::Angle => format!("{} (degrees)", swept.name),
        InputKind::Slide => format!("{} (length)", swept.name),
    };
    let how = match rate {
        None => "held still".to_string(),
        Some(r) => format!("{} at {}", swept.name, rate_text(swept.kind, r)),
    };
    let inputs: Vec<crate::render::plots::Series> = (m.inputs.iter().zip(&g.input_series))
        .map(|(i, s)| (i.name.as_str(), s.clone()))
        .collect();
    let peak = |s: &[(f64, Option<f64>)]| s.iter().filter_map(|p| p.1).fold(0.0f64, f64::max);
    let mut joints: Vec<crate::render::plots::Series> = (m.joints.iter().zip(&g.joint_series))
        .map(|(j, s)| (j.name.as_str(), s.clone()))
        .collect();
    joints.sort_by(|a, b| peak(&b.1).total_cmp(&peak(&a.1)));
    let drawn = crate::render::plots::draw_forces(&m.name, (&axis, &how), &inputs, &joints);
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
fn plots(
    _: &Mechanism,
    _: &crate::model::Input,
    _: Option<f64>,
    _: &Gathered,
    path: &std::path::Path,
    _: Form,
    _: &mut dyn Write,
) -> Outcome {
    Ok(Err(format!(
        "{}: error: this build has no plots (the `plots` feature is off)",
        path.display()
    )))
}

/// The keys `--forces --json` adds to a frame: `"input_force"` (input ->
/// force or torque), `"reactions"` (joint -> the force its first body
/// exerts on its second), `"reaction_moments"` (prismatic joints' moments)
/// `"shaking"` (the force and moment the mechanism exerts on the ground),
/// `"mechanical_advantage"` (one input: per joint and marker)
/// and `"indeterminate"` (joints whose reactions are not unique there);
/// null where the frame has none.
fn add_json(o: &mut Value, m: &Mechanism, carried: Option<&Carried>) {
    let Some(c) = carried else {
        o["input_force"] = Value::Null;
        o["reactions"] = Value::Null;
        return;
    };
    let named = |pairs: Vec<(String, Value)>| Value::Object(pairs.into_iter().collect::<Map<_, _>>());
    o["input_force"] = named(
        m.inputs
            .iter()
            .map(|i| i.name.clone())
            .zip(c.inputs.iter().map(|v| json!(v)))
            .collect(),
    );
    let Some(r) = &c.reactions else {
        o["reactions"] = Value::Null;
        return;
    };
    o["reactions"] = named(
        m.joints
            .iter()
            .map(|j| j.name.clone())
            .zip(r.forces.iter().map(|f| json!(f)))
            .collect(),
    );
    let prismatic: Vec<(String, Value)> = (m.joints.iter().zip(&r.moments))
        .filter(|(j, _)| j.kind == JointKind::Prismatic)
        .map(|(j, v)| (j.name.clone(), json!(v)))
        .collect();
    if !prismatic.is_empty() {
        o["reaction_moments"] = named(prismatic);
    }
    o["shaking"] = json!({"force": [r.shaking[0], r.shaking[1]], "moment": r.shaking[2]});
    if let Some(a) = &c.advantage {
        let joints = (m.joints.iter().zip(&a.joints))
            .filter(|(j, _)| !m.inputs.iter().any(|i| m.joints[i.joint].name == j.name))
            .map(|(j, v)| (j.name.clone(), json!(v)))
            .collect();
        let markers = m
            .all_markers()
            .map(|id| m.marker_name(id))
            .zip(a.markers.iter().map(|v| json!(v)))
            .collect();
        o["mechanical_advantage"] = json!({"joints": named(joints), "markers": named(markers)});
    }
    if !r.indeterminate.is_empty() {
        o["indeterminate"] = json!(r
            .indeterminate
            .iter()
            .map(|&j| &m.joints[j].name)
            .collect::<Vec<_>>());
    }
}

/// The header of `--forces --csv`: frame, inputs, status, each input's
/// force, each joint's reaction (and a prismatic joint's moment), the
/// force and moment on the ground.
fn csv_head(m: &Mechanism) -> Vec<String> {
    let mut head = vec!["frame".to_string()];
    head.extend(m.inputs.iter().map(|i| i.name.clone()));
    head.push("status".into());
    head.extend(m.inputs.iter().map(|i| format!("{}.force", i.name)));
    for j in &m.joints {
        head.push(format!("{}.fx", j.name));
        head.push(format!("{}.fy", j.name));
        if j.kind == JointKind::Prismatic {
            head.push(format!("{}.m", j.name));
        }
    }
    head.extend(["shaking.fx", "shaking.fy", "shaking.m"].map(String::from));
    head
}

/// A frame's numbers in [`csv_head`]'s columns (empty where there are none:
/// not solved, a dead point, primitive constraints).
fn csv_values(m: &Mechanism, carried: Option<&Carried>) -> Vec<String> {
    let mut row = Vec::new();
    match carried {
        Some(c) => row.extend(c.inputs.iter().map(|v| number(*v))),
        None => row.extend(std::iter::repeat_n(String::new(), m.inputs.len())),
    }
    let reactions = carried.and_then(|c| c.reactions.as_ref());
    for (j, joint) in m.joints.iter().enumerate() {
        let mut cell = |v: Option<f64>| row.push(v.map(number).unwrap_or_default());
        cell(reactions.map(|r| r.forces[j][0]));
        cell(reactions.map(|r| r.forces[j][1]));
        if joint.kind == JointKind::Prismatic {
            cell(reactions.map(|r| r.moments[j]));
        }
    }
    for k in 0..3 {
        row.push(reactions.map(|r| number(r.shaking[k])).unwrap_or_default());
    }
    row
}

/// The text summary: how the sweep ran, each input's peak force or
/// torque and where, the most loaded joint, and what is not unique or
/// not computed.
fn summary(
    m: &Mechanism,
    sweep: &Sweep,
    rate: Option<f64>,
    g: &Gathered,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let primary = &m.inputs[sweep.primary().input];
    let how = match rate {
        None => "held still at each pose (statics)".to_string(),
        Some(r) => format!(
            "running with {} at {} (kinetostatics)",
            primary.name,
            rate_text(primary.kind, r)
        ),
    };
    writeln!(out, "{}: {} frames, {how}", m.name, sweep.steps)?;
    for (input, peak) in m.inputs.iter().zip(&g.inputs) {
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
                at_input(primary, *x)
            )?,
            None => writeln!(out, "  input {}: no frame solved", input.name)?,
        }
    }
    if let Some((j, size, x)) = g.joint {
        writeln!(
            out,
            "  most loaded joint: {}, {} at {}",
            m.joints[j].name,
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
        let names: Vec<&str> = g
            .indeterminate
            .iter()
            .map(|&j| m.joints[j].name.as_str())
            .collect();
        writeln!(
            out,
            "  the reactions at {} are not unique (the mechanism is over-constrained; the least-norm ones are given)",
            names.join(", ")
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
fn rate_text(kind: InputKind, r: f64) -> String {
    match kind {
        InputKind::Angle => format!("{} rad/s", num(r)),
        InputKind::Slide => format!("{} length/s", num(r)),
    }
}
