//! Spatial (`dimension = 3`) files in `dofplan edit`: shown, not edited.
//! The page draws them in a view it orbits, pans and zooms itself; the
//! server sends the document (markers in 3D, the panels' texts, the sweep's
//! traces) and runs the plan at the sliders' values. Dragging and editing
//! stay planar-only.

use std::path::Path;
use std::sync::Arc;

use serde_json::{json, Value};

use crate::analysis::spatial::analyse;
use crate::emit::emit_spatial;
use crate::interp::spatial::Interpreter;
use crate::model::spatial::{JointKind, Mechanism};
use crate::plan::spatial::{step_number, Plan};
use crate::simulate::spatial::marker_positions;
use crate::simulate::sweep_requests;
use dofplan_runtime::spatial::Vec3;
use dofplan_runtime::{BreakPolicy, Driver, FrameStatus, Options};

use super::session::{error, Request};

/// Why nothing of a spatial file can be edited or dragged.
pub const READ_ONLY: &str =
    "spatial (dimension = 3) files are shown, not edited: editing and dragging are planar-only";

/// A spatial mechanism open in the editor.
pub struct Document {
    /// The mechanism as drawn in the file.
    pub mechanism: Mechanism,
    /// Its plan, or why it has none.
    plan: Result<Plan, String>,
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
        let mut doc = Document {
            mechanism,
            plan,
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
            super::document::inputs_and_sweep(&m.inputs, &joint_names, m.sweep.as_ref(), size);
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

/// One page's state of a spatial document: the plan driven by the
/// sliders.
pub struct Session {
    doc: Arc<Document>,
    driver: Option<Driver<Interpreter>>,
    policy: BreakPolicy,
}

impl Session {
    /// A session showing the file's drawing.
    pub fn new(doc: Arc<Document>) -> Session {
        let driver = (doc.plan.as_ref().ok())
            .map(|plan| Driver::new(Interpreter::new(plan.clone()), options(BreakPolicy::Limit)));
        Session {
            doc,
            driver,
            policy: BreakPolicy::Limit,
        }
    }

    /// The `frame` of the pose on screen: markers (three coordinates, file
    /// order), slider values, status.
    pub fn current(&self, id: u64) -> Value {
        self.frame(id, &FrameStatus::Solved)
    }

    /// Answers one request: sliders run the plan; a drag is refused.
    pub fn handle(&mut self, request: Request) -> Value {
        let id = request.id();
        match request {
            Request::Inputs { values, policy, .. } => self.animate(id, &values, policy.as_deref()),
            Request::Grab { .. } | Request::Drag { .. } => error(id, READ_ONLY),
            Request::Release { .. } => self.current(id),
        }
    }

    fn animate(&mut self, id: u64, values: &[f64], policy: Option<&str>) -> Value {
        let m = &self.doc.mechanism;
        if values.len() != m.inputs.len() {
            return error(
                id,
                &format!(
                    "{} input value(s) sent, the mechanism has {} input(s)",
                    values.len(),
                    m.inputs.len()
                ),
            );
        }
        if values.iter().any(|v| !v.is_finite()) {
            return error(id, "input values must be finite numbers");
        }
        let policy = match policy {
            None | Some("limit") => BreakPolicy::Limit,
            Some("search") => BreakPolicy::Search,
            Some(other) => return error(id, &format!("unknown breaking policy `{other}`: limit or search")),
        };
        let Ok(plan) = &self.doc.plan else {
            return error(id, self.doc.plan.as_ref().err().map_or("", String::as_str));
        };
        if policy != self.policy {
            // From the drawing, with the new policy, straight to the values.
            self.driver = Some(Driver::new(Interpreter::new(plan.clone()), options(policy)));
            self.policy = policy;
        }
        let Some(driver) = self.driver.as_mut() else {
            return error(id, "no plan to run");
        };
        let status = driver.frame(values);
        self.frame(id, &status)
    }

    /// Each joint's axis in the pose on screen, as the CLI's views draw
    /// it: `[x, y, z]`, the world direction of its first marker's z axis
    /// (`null` for a ball joint, which has none, or a marker without axes).
    fn axes(&self) -> Vec<Value> {
        let m = &self.doc.mechanism;
        (m.joints.iter())
            .map(|j| {
                let id = j.markers[0];
                let z = m.marker(id).axes.map(|a| a.z);
                let dir = match (z, &self.driver) {
                    (Some(_), _) if matches!(j.kind, JointKind::Spherical) => None,
                    (Some(z), Some(d)) => d.poses().get(id.body).map(|p| p.dir(z)),
                    (z, _) => z,
                };
                match dir {
                    Some(d) if d.iter().all(|v| v.is_finite()) => json!(d),
                    _ => Value::Null,
                }
            })
            .collect()
    }

    fn frame(&self, id: u64, status: &FrameStatus) -> Value {
        let m = &self.doc.mechanism;
        let (markers, inputs) = match &self.driver {
            Some(d) => (marker_positions(m, d.poses()), d.inputs().to_vec()),
            None => (
                m.all_markers().map(|k| m.marker(k).at).collect(),
                vec![0.0; m.inputs.len()],
            ),
        };
        let detail = match status {
            FrameStatus::Solved => Value::Null,
            FrameStatus::Limited { brk }
            | FrameStatus::Searched { brk, .. }
            | FrameStatus::Unreached { brk } => json!({
                "step": step_number(brk.step),
                "explanation": format!("step {} of `dofplan plan`", step_number(brk.step)),
                "reason": brk.kind.describe(),
                "gap": brk.gap,
            }),
            FrameStatus::Stretched { step, residual } => json!({
                "step": step_number(*step),
                "explanation": format!("step {} of `dofplan plan`", step_number(*step)),
                "reason": "out of reach",
                "residual": residual,
            }),
        };
        json!({
            "type": "frame",
            "id": id,
            "markers": markers,
            "axes": self.axes(),
            "poses": [],
            "inputs": inputs,
            "status": status.name(),
            "detail": detail,
        })
    }
}

fn options(breaking: BreakPolicy) -> Options {
    Options {
        breaking,
        ..Options::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rssr() -> Session {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/spatial/rssr.toml");
        let Ok(crate::model::Model::Spatial(m)) = crate::load_any(&path) else {
            panic!("rssr is a spatial file");
        };
        Session::new(Arc::new(Document::new(&path, m)))
    }

    fn reply(s: &mut Session, message: &str) -> Value {
        s.handle(serde_json::from_str(message).expect("a well-formed request"))
    }

    #[test]
    fn sliders_run_the_spatial_plan_and_drags_are_refused() {
        let mut s = rssr();
        let drawn = s.current(0)["markers"].clone();
        assert_eq!(
            drawn[0].as_array().map(Vec::len),
            Some(3),
            "points in 3D: {drawn}"
        );
        let frame = reply(&mut s, r#"{"type":"inputs","id":1,"values":[30]}"#);
        assert_eq!(
            (frame["type"].as_str(), frame["status"].as_str()),
            (Some("frame"), Some("solved")),
            "{frame}"
        );
        assert_ne!(frame["markers"], drawn, "the slider moved it");
        for bad in [
            r#"{"type":"grab","id":2,"body":"crank","at":[0,0]}"#,
            r#"{"type":"inputs","id":3,"values":[1,2,3]}"#,
            r#"{"type":"inputs","id":4,"values":[1],"policy":"stretch"}"#,
        ] {
            assert_eq!(reply(&mut s, bad)["type"], "error", "{bad}");
        }
    }
}
