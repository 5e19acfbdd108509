//! Spatial (`dimension = 3`) files in `dofplan edit`: shown, not edited.
//! The page draws them in a view it orbits, pans and zooms itself; the
//! server sends the document (markers in 3D, the panels' texts, the sweep's
//! traces) and runs the plan at the sliders' values. Dragging and editing
//! stay planar-only.

use std::path::Path;

use serde_json::{json, Value};

use crate::analysis::spatial::analyse;
use crate::emit::emit_spatial;
use crate::forces::plan::ForcePlan;
use crate::forces::spatial::force_plan;
use crate::interp::spatial::Interpreter;
use crate::model::spatial::Mechanism;
use crate::plan::spatial::Plan;
use crate::simulate::spatial::marker_positions;
use crate::simulate::sweep_requests;
use dofplan_runtime::spatial::Vec3;
use dofplan_runtime::{BreakPolicy, Driver, Options};

/// Why nothing of a spatial file can be edited or dragged.
pub const READ_ONLY: &str =
    "spatial (dimension = 3) files are shown, not edited: editing and dragging are planar-only";

/// A spatial mechanism open in the editor.
pub struct Document {
    /// The mechanism as drawn in the file.
    pub mechanism: Mechanism,
    /// Its plan, or why it has none.
    pub(super) plan: Result<Plan, String>,
    /// The plan of its reaction unknowns, for a file with loads: every
    /// frame then carries the forces that hold the pose on screen.
    pub(super) forces: Option<ForcePlan>,
    /// The `document` message, as the planar document's with
    /// `dimension: 3`, points of three coordinates and `bounds` a box
    /// `[x0, y0, z0, x1, y1, z1]`.
    pub description: Value,
}

impl Document {
    /// The document of `mechanism`, read from `path`.
    pub fn new(path: &Path, mechanism: Mechanism) -> Document {
        let plan = if mechanism.inputs.is_empty() {
            Err("the mechanism has no inputs, so there is no plan to run".to_string())
        } else {
            analyse(&mechanism).map_err(|e| e.to_string())
        };
        let forces = if mechanism.loads.is_empty() {
            None
        } else {
            force_plan(&mechanism)
        };
        let mut doc = Document {
            mechanism,
            plan,
            forces,
            description: Value::Null,
        };
        doc.description = doc.describe(path);
        doc
    }

    /// The `document` message, as the planar one with `dimension: 3`,
    /// points of three coordinates and `bounds` a box
    /// `[x0, y0, z0, x1, y1, z1]`.
    fn describe(&self, path: &Path) -> Value {
        let m = &self.mechanism;
        let bodies: Vec<Value> = (m.bodies.iter())
            .map(|b| {
                json!({
                    "name": b.name,
                    "fixed": b.fixed,
                    "markers": b.markers.iter().map(|k| json!({"name": k.name, "at": k.at})).collect::<Vec<_>>(),
                })
            })
            .collect();
        let joints: Vec<Value> = (m.joints.iter())
            .map(|j| {
                json!({
                    "name": j.name,
                    "kind": j.kind.name(),
                    "markers": [m.marker_name(j.markers[0]), m.marker_name(j.markers[1])],
                })
            })
            .collect();
        let size = m.size();
        let joint_names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
        let (inputs, sweep) =
            crate::edit::planar::document::inputs_and_sweep(&m.inputs, &joint_names, m.sweep.as_ref(), size);
        let mut check = Vec::new();
        let check = match crate::report::spatial::check(m, false, &mut check) {
            Ok(_) => String::from_utf8_lossy(&check).into_owned(),
            Err(e) => format!("cannot write the check report: {e}"),
        };
        let (traces, bounds) = self.traces();
        json!({
            "type": "document",
            "dimension": 3,
            "name": m.name,
            "file": path.display().to_string(),
            "size": size,
            "bodies": bodies,
            "joints": joints,
            "inputs": inputs,
            "sweep": sweep,
            "traces": traces,
            "bounds": bounds,
            "plan": self.plan.as_ref().ok().map(Plan::explain_all),
            "plan_error": self.plan.as_ref().err(),
            "check": check,
            "rust": self.plan.as_ref().ok().map(emit_spatial),
        })
    }

    /// The sweep's traced markers' paths (run as `dofplan simulate` runs
    /// it) and the box every marker stays in over the sweep.
    fn traces(&self) -> (Value, [f64; 6]) {
        let m = &self.mechanism;
        let mut bounds = [
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        let mut grow = |p: Vec3| {
            if p.iter().all(|v| v.is_finite()) {
                for k in 0..3 {
                    bounds[k] = bounds[k].min(p[k]);
                    bounds[k + 3] = bounds[k + 3].max(p[k]);
                }
            }
        };
        for id in m.all_markers() {
            grow(m.marker(id).at);
        }
        let (Ok(plan), Some(sweep)) = (&self.plan, &m.sweep) else {
            return (json!({}), bounds);
        };
        let mut driver = Driver::new(Interpreter::new(plan.clone()), options(BreakPolicy::Limit));
        let mut paths = vec![Vec::new(); sweep.trace.len()];
        for request in sweep_requests(sweep, m.inputs.len()) {
            driver.frame(&request);
            let at = marker_positions(m, driver.poses());
            for (path, &id) in paths.iter_mut().zip(&sweep.trace) {
                path.push(driver.poses()[id.body].world(m.marker(id).at));
            }
            at.into_iter().for_each(&mut grow);
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

pub(super) fn options(breaking: BreakPolicy) -> Options {
    Options {
        breaking,
        ..Options::default()
    }
}
