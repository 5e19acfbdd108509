//! One connection's live state: the pose on screen, the slider values, and
//! the solver that moves the mechanism from there — the plan driven by the
//! inputs, or a drag.
//!
//! Both solvers start from the pose on screen by taking it as a new
//! drawing (MechEdit's constraints added in a solved state): the mechanism
//! is redrawn with every marker where it is now, and planned from there. A
//! plan chooses its branches to reproduce its drawing, so animating after
//! a drag continues on the branch the drag left, never the file's; a drag
//! starts where the last frame ended. Poses found against the redrawn
//! mechanism are composed with the poses it was redrawn at, so everything
//! sent is relative to the file's drawing.

use std::sync::Arc;

use serde::Deserialize;
use serde_json::{json, Value};

use crate::analysis::analyse;
use crate::edit::forces::frame_forces;
use crate::forces::planar::reactions;
use crate::interp::Interpreter;
use crate::model::{InputKind, Marker, MarkerId, Mechanism};
use crate::numeric::planar::drag::Drag;
use crate::numeric::planar::input_drag::drag_inputs;
use crate::plan::Plan;
use crate::simulate::{marker_at, residuals};
use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::{Break, BreakPolicy, Driver, FrameStatus, Options};

use super::document::Document;

/// A pose whose joints are open by more than this, relative to the
/// mechanism's size, is never drawn.
const OPEN_JOINT: f64 = 1e-7;

/// The name of the temporary marker a drag pins: not an identifier, so
/// never a marker of the file.
const GRABBED: &str = "grabbed point";

/// A message from the page.
#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum Request {
    /// Run the plan at these slider values (one per input, file order).
    Inputs {
        /// Echoed in the reply.
        id: u64,
        /// The requested value of every input.
        values: Vec<f64>,
        /// "limit" (the default) or "search".
        #[serde(default)]
        policy: Option<String>,
    },
    /// Grab a moving body at a world point of the pose on screen.
    Grab {
        /// Echoed in the reply.
        id: u64,
        /// The body's name.
        body: String,
        /// The grabbed point, in world coordinates.
        at: [f64; 2],
    },
    /// Move the grabbed point toward a world target.
    Drag {
        /// Echoed in the reply.
        id: u64,
        /// The target.
        to: [f64; 2],
    },
    /// Let go of the grabbed point.
    Release {
        /// Echoed in the reply.
        id: u64,
    },
}

impl Request {
    /// The request's id, for the reply.
    pub fn id(&self) -> u64 {
        match self {
            Request::Inputs { id, .. }
            | Request::Grab { id, .. }
            | Request::Drag { id, .. }
            | Request::Release { id } => *id,
        }
    }
}

/// The plan driven by the inputs, from the pose it was planned at.
struct Animation {
    driver: Driver<Interpreter>,
    /// The poses the mechanism was redrawn at (identity: the file's
    /// drawing, whose plan is the document's).
    base: Vec<Pose>,
    /// The slider values at `base`: the plan's inputs count from them.
    offset: Vec<f64>,
    policy: BreakPolicy,
}

/// A grabbed point being dragged.
struct Grab {
    how: Dragging,
    /// "coupler" — what the status names.
    body: String,
}

/// How a grabbed point is dragged.
enum Dragging {
    /// Through the plan: every freedom is driven by an input, so the
    /// inputs move (in the session's animation) until the point is as
    /// close to the pointer as the mechanism reaches
    /// ([`drag_inputs`]): a few runs of the plan a move.
    Inputs {
        /// The grabbed body's index.
        body: usize,
        /// The grabbed point, in the animation's drawing.
        local: Point,
    },
    /// A freedom no input drives (or no plan): every body's pose is
    /// unknown to a task-priority Newton solve pinning the point.
    Free {
        driver: Box<Driver<Drag>>,
        base: Vec<Pose>,
    },
}

/// One connection's state.
pub struct Session {
    doc: Arc<Document>,
    /// The pose on screen, relative to the file's drawing.
    poses: Vec<Pose>,
    /// The slider values of the pose on screen.
    inputs: Vec<f64>,
    /// `None` after a drag: planned again from the pose on screen when a
    /// slider next moves.
    animation: Option<Animation>,
    grab: Option<Grab>,
}

impl Session {
    /// A session showing the file's drawing.
    pub fn new(doc: Arc<Document>) -> Session {
        let m = &doc.mechanism;
        let animation = doc.plan.as_ref().ok().map(|plan| Animation {
            driver: Driver::new(Interpreter::new(plan.clone()), options(BreakPolicy::Limit)),
            base: vec![Pose::IDENTITY; m.bodies.len()],
            offset: vec![0.0; m.inputs.len()],
            policy: BreakPolicy::Limit,
        });
        Session {
            poses: vec![Pose::IDENTITY; m.bodies.len()],
            inputs: vec![0.0; m.inputs.len()],
            animation,
            grab: None,
            doc,
        }
    }

    /// The `frame` message of the pose on screen (the drawing, at first).
    pub fn current(&self, id: u64) -> Value {
        self.frame(id, &FrameStatus::Solved, None)
    }

    /// Answers one request: a `frame` with the new pose, or an `error`.
    pub fn handle(&mut self, request: Request) -> Value {
        let id = request.id();
        let reply = match request {
            Request::Inputs { values, policy, .. } => self.animate(id, &values, policy.as_deref()),
            Request::Grab { body, at, .. } => self.grab(id, &body, at),
            Request::Drag { to, .. } => self.drag(id, to),
            Request::Release { .. } => {
                self.grab = None;
                Ok(self.current(id))
            }
        };
        reply.unwrap_or_else(|message| error(id, &message))
    }

    fn animate(&mut self, id: u64, values: &[f64], policy: Option<&str>) -> Result<Value, String> {
        let m = &self.doc.mechanism;
        if values.len() != m.inputs.len() {
            return Err(format!(
                "{} input value(s) sent, the mechanism has {} input(s)",
                values.len(),
                m.inputs.len()
            ));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err("input values must be finite numbers".into());
        }
        let policy = match policy {
            None | Some("limit") => BreakPolicy::Limit,
            Some("search") => BreakPolicy::Search,
            Some(other) => {
                return Err(format!(
                    "unknown breaking policy `{other}`: limit or search (stretch would draw open joints)"
                ))
            }
        };
        self.grab = None;
        if self.animation.as_ref().is_none_or(|a| a.policy != policy) {
            self.animation = Some(self.replan(policy)?);
        }
        let a = self.animation.as_mut().expect("planned above");
        let request: Vec<f64> = values.iter().zip(&a.offset).map(|(v, o)| v - o).collect();
        let status = a.driver.frame(&request);
        let poses = compose(a.driver.poses(), &a.base);
        let inputs: Vec<f64> = (a.driver.inputs().iter())
            .zip(&a.offset)
            .map(|(v, o)| v + o)
            .collect();
        let explanation = step_of(&status).map(|step| a.driver.solver().plan().explain(step as usize));
        if let Err(e) = self.show(poses, Some(inputs)) {
            // The driver has moved on to the refused pose: plan again from
            // the one on screen.
            self.animation = None;
            return Err(e);
        }
        Ok(self.frame(id, &status, explanation))
    }

    /// The plan of the mechanism redrawn at the pose on screen, and the
    /// slider values there.
    fn replan(&self, policy: BreakPolicy) -> Result<Animation, String> {
        let m = &self.doc.mechanism;
        let plan: Plan = if self.poses.iter().all(|p| *p == Pose::IDENTITY) {
            // The file's drawing: the document's plan (or why it has none).
            self.doc.plan.clone()?
        } else {
            analyse(&redrawn(m, &self.poses))
                .plan
                .map_err(|e| format!("the mechanism cannot be planned from the pose on screen: {e}"))?
        };
        Ok(Animation {
            driver: Driver::new(Interpreter::new(plan), options(policy)),
            base: self.poses.clone(),
            offset: self.inputs.clone(),
            policy,
        })
    }

    fn grab(&mut self, id: u64, body: &str, at: [f64; 2]) -> Result<Value, String> {
        let m = &self.doc.mechanism;
        if at.iter().any(|v| !v.is_finite()) {
            return Err("the grabbed point must be finite".into());
        }
        let Some(b) = m.bodies.iter().position(|x| x.name == body) else {
            return Err(format!("no body `{body}`"));
        };
        if m.bodies[b].fixed {
            return Err(format!("body {body} is fixed: grab a moving body"));
        }
        // A plan from the pose on screen moves every body from the
        // inputs: drag through it (and the sliders continue from where the
        // drag leaves them, in the same animation).
        if let Ok(animation) = self.replan(BreakPolicy::Limit) {
            self.animation = Some(animation);
            self.grab = Some(Grab {
                how: Dragging::Inputs { body: b, local: at },
                body: body.to_string(),
            });
            return Ok(self.current(id));
        }
        let mut r = redrawn(m, &self.poses);
        r.bodies[b].markers.push(Marker {
            name: GRABBED.into(),
            at,
            dir: None,
        });
        let marker = MarkerId {
            body: b,
            marker: r.bodies[b].markers.len() - 1,
        };
        let drag = Drag::new(&r, marker).map_err(|e| e.to_string())?;
        // Stretch: a target out of reach leaves the point at its closest
        // approach with every joint exact (the drag is relaxed, never the
        // mechanism), so a one-DOF linkage follows its own curve.
        self.grab = Some(Grab {
            how: Dragging::Free {
                driver: Box::new(Driver::new(drag, options(BreakPolicy::Stretch))),
                base: self.poses.clone(),
            },
            body: body.to_string(),
        });
        // Animating after the drag plans from where the drag left it.
        self.animation = None;
        Ok(self.current(id))
    }

    fn drag(&mut self, id: u64, to: [f64; 2]) -> Result<Value, String> {
        if to.iter().any(|v| !v.is_finite()) {
            return Err("the drag target must be finite".into());
        }
        let Some(g) = self.grab.as_mut() else {
            return Err("nothing is grabbed: send `grab` first".into());
        };
        let m = &self.doc.mechanism;
        let held = || {
            format!(
                "{} is held at the closest approach to the pointer that its joints allow",
                g.body
            )
        };
        let (status, poses, inputs, explanation) = match &mut g.how {
            Dragging::Inputs { body, local } => {
                let a = self
                    .animation
                    .as_mut()
                    .ok_or("the drag lost its plan: grab again")?;
                let kinds: Vec<InputKind> = m.inputs.iter().map(|i| i.kind).collect();
                let report = drag_inputs(&mut a.driver, *body, *local, to, &kinds, m.size());
                let poses = compose(a.driver.poses(), &a.base);
                let inputs: Vec<f64> = (a.driver.inputs().iter())
                    .zip(&a.offset)
                    .map(|(v, o)| v + o)
                    .collect();
                // Within a thousandth of the size counts as reached (the
                // pointer's own precision is coarser).
                let (status, explanation) = match report.status {
                    FrameStatus::Limited { brk } => {
                        let text = a.driver.solver().plan().explain(brk.step as usize);
                        (FrameStatus::Limited { brk }, Some(text))
                    }
                    _ if report.distance > 1e-3 * m.size() => (
                        FrameStatus::Stretched {
                            step: 0,
                            residual: report.distance,
                        },
                        Some(held()),
                    ),
                    status => (status, None),
                };
                (status, poses, inputs, explanation)
            }
            Dragging::Free { driver, base } => {
                let status = driver.frame(&to);
                let poses = compose(driver.poses(), base);
                let inputs = input_values(m, &poses, &self.inputs);
                let explanation = step_of(&status).map(|_| held());
                (status, poses, inputs, explanation)
            }
        };
        if let Err(e) = self.show(poses, Some(inputs)) {
            // The animation has moved on to the refused pose: plan again
            // from the one on screen.
            self.animation = None;
            return Err(e);
        }
        Ok(self.frame(id, &status, explanation))
    }

    /// Makes `poses` the pose on screen, unless a joint is open there.
    fn show(&mut self, poses: Vec<Pose>, inputs: Option<Vec<f64>>) -> Result<(), String> {
        let m = &self.doc.mechanism;
        let size = m.size();
        let zero = vec![0.0; m.inputs.len()];
        if let Some(open) = residuals(m, &poses, &zero)
            .into_iter()
            .filter(|r| !r.name.starts_with("input "))
            // A NaN gap is open too.
            .find(|r| r.value.is_nan() || r.value > OPEN_JOINT * size)
        {
            return Err(format!(
                "{} would be open by {:.3e}: the pose is not drawn",
                open.name, open.value
            ));
        }
        self.poses = poses;
        if let Some(inputs) = inputs {
            self.inputs = inputs;
        }
        Ok(())
    }

    /// The `frame` message: every marker's world position (file order),
    /// every body's pose, the slider values, and the status with the
    /// breaking step's `explanation`.
    fn frame(&self, id: u64, status: &FrameStatus, explanation: Option<String>) -> Value {
        let m = &self.doc.mechanism;
        // In file order, as the document lists them (names are not resent).
        let markers: Vec<Point> = m.all_markers().map(|id| marker_at(m, &self.poses, id)).collect();
        let poses: Vec<[f64; 4]> = (self.poses.iter())
            .map(|p| [p.rot.c, p.rot.s, p.at[0], p.at[1]])
            .collect();
        let brk = |b: &Break| {
            json!({
                "step": b.step,
                "explanation": explanation,
                "reason": b.kind.describe(),
                "gap": b.gap,
            })
        };
        let detail = match status {
            FrameStatus::Solved => Value::Null,
            FrameStatus::Limited { brk: b } | FrameStatus::Unreached { brk: b } => brk(b),
            FrameStatus::Searched { brk: b, reached } => {
                let mut v = brk(b);
                v["reached"] = json!(reached);
                v
            }
            FrameStatus::Stretched { step, residual } => json!({
                "step": step,
                "explanation": explanation,
                "reason": "out of reach",
                "residual": residual,
            }),
        };
        let mut frame = json!({
            "type": "frame",
            "id": id,
            "markers": markers,
            "poses": poses,
            "inputs": self.inputs,
            "status": status.name(),
            "detail": detail,
        });
        if let Some(forces) = self.forces() {
            frame["forces"] = forces;
        }
        frame
    }

    /// What holds the pose on screen still under the file's loads (a file
    /// with loads only; see [`frame_forces`]).
    fn forces(&self) -> Option<Value> {
        let m = &self.doc.mechanism;
        let r = reactions(m, self.doc.forces.as_ref()?, &self.poses, None)?;
        Some(frame_forces(
            &r.inputs,
            &r.forces,
            &r.moments,
            r.forces.iter().map(|f| f[0].hypot(f[1])),
            r.residual,
            r.indeterminate
                .iter()
                .map(|&j| m.joints[j].name.as_str())
                .collect(),
        ))
    }
}

/// The step a frame broke or stretched at, if it did.
fn step_of(status: &FrameStatus) -> Option<u32> {
    match status {
        FrameStatus::Solved => None,
        FrameStatus::Limited { brk } | FrameStatus::Searched { brk, .. } | FrameStatus::Unreached { brk } => {
            Some(brk.step)
        }
        FrameStatus::Stretched { step, .. } => Some(*step),
    }
}

/// An `error` reply.
pub fn error(id: u64, message: &str) -> Value {
    json!({"type": "error", "id": id, "message": message})
}

fn options(breaking: BreakPolicy) -> Options {
    Options {
        breaking,
        ..Options::default()
    }
}

/// `m` drawn at `poses`: every marker (and its direction) where the body's
/// pose puts it, so the identity pose of the result is `poses`.
fn redrawn(m: &Mechanism, poses: &[Pose]) -> Mechanism {
    let mut r = m.clone();
    for (body, pose) in r.bodies.iter_mut().zip(poses) {
        for marker in &mut body.markers {
            marker.at = pose.world(marker.at);
            marker.dir = marker.dir.map(|d| pose.world_dir(d));
        }
    }
    r
}

/// Poses found against a mechanism redrawn at `base`, relative to the
/// original drawing: first `base`, then the pose.
fn compose(poses: &[Pose], base: &[Pose]) -> Vec<Pose> {
    poses
        .iter()
        .zip(base)
        .map(|(q, p)| Pose {
            rot: p.rot.then(q.rot),
            at: q.world(p.at),
        })
        .collect()
}

/// The input values of `poses` (what the sliders show after a drag), each
/// angle taken within half a turn of `near`, so a slider does not jump by
/// a turn. Measured as [`residuals`] measures an input.
fn input_values(m: &Mechanism, poses: &[Pose], near: &[f64]) -> Vec<f64> {
    m.inputs
        .iter()
        .zip(near)
        .map(|(input, &near)| {
            let [a, b] = m.joints[input.joint].markers;
            match input.kind {
                InputKind::Angle => {
                    let r = poses[a.body].rot.inverse().then(poses[b.body].rot);
                    let turn = r.s.atan2(r.c).to_degrees();
                    near + (turn - near + 180.0).rem_euclid(360.0) - 180.0
                }
                InputKind::Slide => {
                    // The distance along the first marker's line, from where
                    // it was drawn.
                    let along = |poses: Option<&[Pose]>| {
                        let at = |id: MarkerId| {
                            poses.map_or(m.marker(id).at, |p| p[id.body].world(m.marker(id).at))
                        };
                        let d = m.marker(a).unit_dir().unwrap_or([1.0, 0.0]);
                        let d = poses.map_or(d, |p| p[a.body].world_dir(d));
                        let (pa, pb) = (at(a), at(b));
                        (pb[0] - pa[0]) * d[0] + (pb[1] - pa[1]) * d[1]
                    };
                    along(Some(poses)) - along(None)
                }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fourbar() -> Session {
        session("fourbar")
    }

    fn session(name: &str) -> Session {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../mechanisms/{name}.toml"));
        Session::new(Arc::new(Document::open(Some(&path)).expect("the file opens")))
    }

    #[test]
    fn a_file_with_loads_sends_the_forces_that_hold_each_pose() {
        // The input torque from the bodies' equilibrium against virtual
        // work's (the plan's rates, another path), at a few crank angles;
        // a file without loads sends none.
        use crate::forces::planar::input_forces;
        let mut s = session("loads/fourbar_weights");
        let m = s.doc.mechanism.clone();
        let mut d = Driver::new(Interpreter::new(s.doc.plan.clone().unwrap()), Options::default());
        for theta in [0.0, 40.0, 135.0, 250.0] {
            let frame = reply(
                &mut s,
                &format!(r#"{{"type":"inputs","id":1,"values":[{theta}]}}"#),
            );
            let forces = &frame["forces"];
            assert_eq!(forces["held"], true, "{frame}");
            assert_eq!(forces["reactions"].as_array().unwrap().len(), m.joints.len());
            assert!(d.frame(&[theta]).is_solved());
            let q = input_forces(&m, d.solver(), d.state(), d.inputs(), None).unwrap()[0];
            let shown = forces["inputs"][0].as_f64().unwrap();
            assert!(
                (shown - q).abs() < 1e-9 * q.abs().max(1.0),
                "{theta}: {shown} against {q}"
            );
        }
        assert!(reply(&mut fourbar(), r#"{"type":"inputs","id":1,"values":[30]}"#)
            .get("forces")
            .is_none());
    }

    fn reply(s: &mut Session, message: &str) -> Value {
        match serde_json::from_str::<Request>(message) {
            Ok(r) => s.handle(r),
            Err(e) => error(0, &e.to_string()),
        }
    }

    #[test]
    fn bad_requests_get_errors_and_leave_the_pose_alone() {
        let mut s = fourbar();
        for bad in [
            r#"{"type":"inputs","id":1,"values":[1,2]}"#,
            r#"{"type":"inputs","id":2,"values":[1],"policy":"stretch"}"#,
            r#"{"type":"grab","id":3,"body":"ground","at":[0,0]}"#,
            r#"{"type":"grab","id":4,"body":"nobody","at":[0,0]}"#,
            r#"{"type":"drag","id":5,"to":[1,1]}"#,
            r#"{"type":"inputs","id":6,"values":[1e999]}"#,
            r#"{"type":"inputs","id":7,"values":[1],"extra":true}"#,
        ] {
            assert_eq!(reply(&mut s, bad)["type"], "error", "{bad}");
        }
        assert!(s.poses.iter().all(|p| *p == Pose::IDENTITY));
        let frame = reply(&mut s, r#"{"type":"inputs","id":8,"values":[90]}"#);
        assert_eq!(
            (frame["type"].as_str(), frame["status"].as_str()),
            (Some("frame"), Some("solved"))
        );
    }

    #[test]
    fn a_slider_after_a_drag_continues_from_the_dragged_pose() {
        let mut s = fourbar();
        reply(&mut s, r#"{"type":"grab","id":1,"body":"coupler","at":[3,3.5]}"#);
        let dragged = reply(&mut s, r#"{"type":"drag","id":2,"to":[2.9,3.6]}"#);
        assert_eq!(dragged["type"], "frame", "{dragged}");
        reply(&mut s, r#"{"type":"release","id":3}"#);
        let theta = s.inputs[0];
        assert!(theta.abs() > 0.1, "the drag turned the crank ({theta}°)");
        // The same value again: the mechanism stays where the drag left it.
        let held = s.poses.clone();
        let again = reply(
            &mut s,
            &format!(r#"{{"type":"inputs","id":4,"values":[{theta}]}}"#),
        );
        assert_eq!(again["status"], "solved", "{again}");
        for (a, b) in held.iter().zip(&s.poses) {
            assert!((a.at[0] - b.at[0]).abs() < 1e-9 && (a.at[1] - b.at[1]).abs() < 1e-9);
            assert!((a.rot.s - b.rot.s).abs() < 1e-9 && (a.rot.c - b.rot.c).abs() < 1e-9);
        }
    }

    #[test]
    fn composing_with_the_base_pose_keeps_world_points() {
        let base = Pose {
            at: [1.0, 2.0],
            rot: dofplan_runtime::planar::Rot::from_degrees(30.0),
        };
        let q = Pose {
            at: [-0.5, 0.25],
            rot: dofplan_runtime::planar::Rot::from_degrees(-75.0),
        };
        let p = [0.3, -1.2];
        let two_steps = q.world(base.world(p));
        let composed = compose(&[q], &[base])[0].world(p);
        assert!((two_steps[0] - composed[0]).abs() < 1e-12);
        assert!((two_steps[1] - composed[1]).abs() < 1e-12);
    }
}
