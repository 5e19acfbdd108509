//! The document the editor serves: the mechanism as loaded, its plan, and
//! what the side panels show (the texts of `dofplan plan`, `check` and
//! `emit`), computed once when the server starts.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use crate::analysis::analyse;
use crate::emit::emit;
use crate::forces::plan::ForcePlan;
use crate::forces::planar::force_plan;
use crate::interp::Interpreter;
use crate::model::{InputKind, JointKind, Mechanism};
use crate::plan::Plan;
use crate::report::planar::check::Check;
use crate::simulate::{frames, marker_at, sweep_requests};
use dofplan_runtime::planar::Pose;
use dofplan_runtime::{BreakPolicy, Driver, Options};

use crate::analysis::Progress;

/// Makes the display of an analysis's progress on a document's file (the
/// CLI's bar, shown on a terminal for a large file): it is told how far
/// the analysis is, and removed when dropped.
pub type Watch = fn(&Path) -> Box<dyn FnMut(Progress)>;

/// What a new document is called until it is saved.
pub const UNTITLED: &str = "untitled.toml";

/// A mechanism open in the editor.
pub struct Document {
    /// The file it was read from (`None`: a new document).
    pub path: Option<PathBuf>,
    /// The mechanism as drawn in the file.
    pub mechanism: Mechanism,
    /// Its plan, or why it has none (no inputs, or the analysis failed).
    pub plan: Result<Plan, String>,
    /// The plan of its reaction unknowns, for a file with loads (and no
    /// primitive constraints): every frame then carries the forces that
    /// hold the pose on screen.
    pub forces: Option<ForcePlan>,
    /// What the page is sent first, the `document` message: bodies and
    /// markers as drawn, joints, gear pairs, slots, inputs with their
    /// slider ranges, the sweep, its traces, and the texts of `dofplan
    /// plan`, `check` and `emit`.
    pub description: Value,
}

impl Document {
    /// Reads `path`, or starts an empty document. An error is the text to
    /// print: the file's diagnostics, as `dofplan check` prints them. (The
    /// server opens files through its workspace, which also opens a file
    /// that does not load; the tests start sessions from files directly.)
    #[cfg(test)]
    pub fn open(path: Option<&Path>) -> Result<Document, String> {
        use crate::conflict::{load_any, load_str};
        use crate::edit::EMPTY;
        use crate::model::{Format, Model};
        let mechanism = match path {
            None => load_str(UNTITLED, EMPTY, Format::Toml).map_err(|e| e.render(false))?,
            Some(path) => match load_any(path) {
                Ok(Model::Planar(m)) => m,
                Ok(Model::Spatial(_)) => {
                    return Err(format!(
                        "{}: error: the editor does not open spatial (dimension = 3) files yet\n  \
                         help: `dofplan simulate {0} --svg OUT.svg` draws one",
                        path.display()
                    ))
                }
                Err(e) => return Err(e.render(false)),
            },
        };
        Ok(Document::new(path, mechanism))
    }

    /// The document of `mechanism`, read from (or to be saved to) `path`:
    /// its plan and panels computed from it.
    pub fn new(path: Option<&Path>, mechanism: Mechanism) -> Document {
        Document::watched(path, mechanism, None)
    }

    /// [`Document::new`], the analysis of its check report showing its
    /// progress through `watch`.
    pub fn watched(path: Option<&Path>, mechanism: Mechanism, watch: Option<Watch>) -> Document {
        let plan = if mechanism.inputs.is_empty() && mechanism.gears.is_empty() {
            Err("the mechanism has no inputs, so there is no plan to run: drag a body to move it".to_string())
        } else if mechanism.inputs.is_empty() {
            // A drag does not model gears: a geared mechanism moves only
            // through a plan.
            Err(format!(
                "the mechanism has no inputs, so there is no plan to run: mark a joint as an input to move it \
                 (gear pair {}: a geared mechanism is dragged only through its plan)",
                mechanism.gear_names()
            ))
        } else {
            analyse(&mechanism).plan.map_err(|e| e.to_string())
        };
        let forces = if mechanism.loads.is_empty() {
            None
        } else {
            force_plan(&mechanism)
        };
        let mut doc = Document {
            path: path.map(Path::to_path_buf),
            mechanism,
            plan,
            forces,
            description: Value::Null,
        };
        doc.description = doc.describe(watch);
        doc
    }

    /// The file's name as the reports write it.
    fn place(&self) -> String {
        self.path
            .as_ref()
            .map_or_else(|| self.mechanism.source.name.clone(), |p| p.display().to_string())
    }

    /// The `document` message: bodies and markers as drawn, joints, gear
    /// pairs and racks (see [`super::gears::describe`]), pins in slots (see
    /// [`super::slots::describe`]), inputs with their slider ranges, the
    /// sweep, the traces of its traced markers, and the texts of `dofplan
    /// plan`, `check` and `emit`.
    fn describe(&self, watch: Option<Watch>) -> Value {
        let m = &self.mechanism;
        let bodies: Vec<Value> = m
            .bodies
            .iter()
            .map(|b| {
                json!({
                    "name": b.name,
                    "fixed": b.fixed,
                    "markers": b.markers.iter().map(|k| json!({
                        "name": k.name,
                        "at": k.at,
                        "dir": k.unit_dir(),
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        let joints: Vec<Value> = m
            .joints
            .iter()
            .map(|j| {
                json!({
                    "name": j.name,
                    "kind": match j.kind {
                        JointKind::Revolute => "revolute",
                        JointKind::Prismatic => "prismatic",
                    },
                    "markers": [m.marker_name(j.markers[0]), m.marker_name(j.markers[1])],
                })
            })
            .collect();
        let size = m.size();
        let joint_names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
        let (inputs, mut sweep) = inputs_and_sweep(&m.inputs, &joint_names, m.sweep.as_ref(), size);
        // The traced markers by name, for the page's sweep editor (the
        // traces themselves need a plan; the list does not).
        if let (Some(sweep), Some(s)) = (sweep.as_mut(), m.sweep.as_ref()) {
            sweep["trace"] = json!(s.trace.iter().map(|&id| m.marker_name(id)).collect::<Vec<_>>());
        }
        let plan_text = self.plan.as_ref().map(|p| p.explain_all()).map_err(Clone::clone);
        let (traces, bounds) = self.traces();
        json!({
            "type": "document",
            "name": m.name,
            "file": self.place(),
            "size": size,
            "bodies": bodies,
            "joints": joints,
            "gears": super::gears::describe(m),
            "slots": super::slots::describe(m),
            "inputs": inputs,
            "sweep": sweep,
            "traces": traces,
            "bounds": bounds,
            "plan": plan_text.as_ref().ok(),
            "plan_error": plan_text.as_ref().err(),
            "check": self.check_text(watch),
            "rust": self.plan.as_ref().ok().map(emit),
        })
    }

    /// The report of `dofplan check`, as it prints it.
    fn check_text(&self, watch: Option<Watch>) -> String {
        let mut out = Vec::new();
        // A path that is no file (a new document) shows no progress, as a
        // small file does not.
        let check = match watch {
            Some(watch) => {
                let mut progress = watch(self.path.as_deref().unwrap_or(Path::new("")));
                Check::of(&self.mechanism, &mut *progress)
            }
            None => Check::of(&self.mechanism, &mut |_| {}),
        };
        let written = check.write(&self.mechanism, &self.place(), false, &mut out);
        match written {
            Ok(_) => String::from_utf8_lossy(&out).into_owned(),
            Err(e) => format!("cannot write the check report: {e}"),
        }
    }

    /// The paths of the sweep's traced markers over the file's sweep, run
    /// as `dofplan simulate` runs it (limit policy), by "body.marker".
    /// Also the box every marker stays in over the sweep (without one, a
    /// square twice the drawing's extent), `[x0, y0, x1, y1]`, so the page
    /// can frame the whole motion.
    fn traces(&self) -> (Value, [f64; 4]) {
        let m = &self.mechanism;
        let mut bounds = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
        let mut grow = |p: [f64; 2]| {
            if p.iter().all(|v| v.is_finite()) {
                bounds = [
                    bounds[0].min(p[0]),
                    bounds[1].min(p[1]),
                    bounds[2].max(p[0]),
                    bounds[3].max(p[1]),
                ];
            }
        };
        for id in m.all_markers() {
            grow(m.marker(id).at);
        }
        // Pitch circles, racks and slots reach past their markers.
        let drawn = vec![Pose::IDENTITY; m.bodies.len()];
        for p in super::gears::reach(m, &drawn)
            .into_iter()
            .chain(super::slots::reach(m, &drawn))
        {
            grow(p);
        }
        let (Ok(plan), Some(sweep)) = (&self.plan, &m.sweep) else {
            // No sweep to say how far the bodies go: a dragged chain can
            // swing about anywhere within its own extent of the drawing.
            let [x0, y0, x1, y1] = bounds;
            let (cx, cy, r) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0, (x1 - x0).max(y1 - y0));
            return (json!({}), [cx - r, cy - r, cx + r, cy + r]);
        };
        let options = Options {
            breaking: BreakPolicy::Limit,
            ..Options::default()
        };
        let mut driver = Driver::new(Interpreter::new(plan.clone()), options);
        let mut paths = vec![Vec::new(); sweep.trace.len()];
        for f in frames(&mut driver, sweep_requests(sweep, m.inputs.len())) {
            for (path, &id) in paths.iter_mut().zip(&sweep.trace) {
                path.push(marker_at(m, &f.poses, id));
            }
            for id in m.all_markers() {
                grow(marker_at(m, &f.poses, id));
            }
            for p in super::gears::reach(m, &f.poses)
                .into_iter()
                .chain(super::slots::reach(m, &f.poses))
            {
                grow(p);
            }
        }
        let traces = Value::Object(
            (sweep.trace.iter())
                .zip(paths)
                .map(|(&id, path)| (m.marker_name(id), json!(path)))
                .collect(),
        );
        (traces, bounds)
    }
}

/// The `inputs` of a `document` message — each with its slider's range:
/// the sweep's when it is swept, otherwise a full turn (angles) or the
/// mechanism's size either way (slides) — and its `sweep`. Both dimensions
/// share it (`joint_names` by joint index).
pub(crate) fn inputs_and_sweep(
    inputs: &[crate::model::Input],
    joint_names: &[&str],
    sweep: Option<&crate::model::Sweep>,
    size: f64,
) -> (Vec<Value>, Option<Value>) {
    let described = (inputs.iter().enumerate())
        .map(|(k, input)| {
            let swept = sweep.and_then(|s| s.inputs.iter().find(|w| w.input == k));
            let (lo, hi) = match (swept, input.kind) {
                (Some(s), _) => (s.from.min(s.to), s.from.max(s.to)),
                (None, InputKind::Angle) => (-180.0, 180.0),
                (None, InputKind::Slide) => (-size, size),
            };
            json!({
                "name": input.name,
                "kind": input.kind.name(),
                "joint": joint_names[input.joint],
                "min": lo,
                "max": hi,
            })
        })
        .collect();
    let sweep = sweep.map(|s| {
        json!({
            "steps": s.steps,
            "inputs": s.inputs.iter().map(|w| json!({"input": w.input, "from": w.from, "to": w.to})).collect::<Vec<_>>(),
        })
    });
    (described, sweep)
}
