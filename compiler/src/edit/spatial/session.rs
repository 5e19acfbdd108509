//! One page's state of a spatial document: the plan driven by the
//! sliders.

use std::sync::Arc;

use serde_json::{json, Value};

use crate::edit::forces::frame_forces;
use crate::forces::spatial::reactions;
use crate::interp::spatial::Interpreter;
use crate::model::spatial::JointKind;
use crate::plan::spatial::step_number;
use crate::simulate::spatial::marker_positions;
use dofplan_runtime::{BreakPolicy, Driver, FrameStatus};

use super::document::options;
use super::{Document, READ_ONLY};
use crate::edit::planar::session::{error, Request};

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
        let mut frame = json!({
            "type": "frame",
            "id": id,
            "markers": markers,
            "axes": self.axes(),
            "poses": [],
            "inputs": inputs,
            "status": status.name(),
            "detail": detail,
        });
        if let Some(forces) = self.forces() {
            frame["forces"] = forces;
        }
        frame
    }

    /// What holds the pose on screen still under the file's loads (a file
    /// with loads only; see [`frame_forces`]): reactions and moments as
    /// 3-vectors.
    fn forces(&self) -> Option<Value> {
        let m = &self.doc.mechanism;
        let poses = self.driver.as_ref()?.poses();
        let r = reactions(m, self.doc.forces.as_ref()?, poses, None)?;
        Some(frame_forces(
            &r.inputs,
            &r.forces,
            &r.moments,
            r.forces.iter().map(|f| dofplan_runtime::spatial::norm(*f)),
            r.residual,
            r.indeterminate
                .iter()
                .map(|&j| m.joints[j].name.as_str())
                .collect(),
        ))
    }
}
