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
use crate::model::planar::slots::{Ends, Shape, Slot};
use crate::model::{InputKind, Marker, MarkerId, Mechanism};
use crate::numeric::planar::drag::{Drag, DragError};
use crate::numeric::planar::input_drag::drag_inputs;
use crate::plan::Plan;
use crate::simulate::{marker_at, residuals};
use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::{Break, BreakKind, BreakPolicy, Driver, FrameStatus, Options};

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
        let unplanned = match self.replan(BreakPolicy::Limit) {
            Ok(animation) => {
                self.animation = Some(animation);
                self.grab = Some(Grab {
                    how: Dragging::Inputs { body: b, local: at },
                    body: body.to_string(),
                });
                return Ok(self.current(id));
            }
            Err(why) => why,
        };
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
        let drag = Drag::new(&r, marker).map_err(|e| match e {
            // Neither solver moves it: say what would.
            DragError::Geared(_) if m.inputs.is_empty() => format!(
                "{body} cannot be dragged: {e}\nthe mechanism has no inputs yet: mark a joint as one \
                 (Edit mode: select the joint, then Input)"
            ),
            DragError::Geared(_) => {
                format!("{body} cannot be dragged: {e}\nand no plan moves it from the pose on screen: {unplanned}")
            }
            e => e.to_string(),
        })?;
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
                let (state, before) = (driver.state().clone(), driver.inputs().to_vec());
                let status = driver.frame(&to);
                let poses = compose(driver.poses(), base);
                if let Some((slot, gap)) = past_a_slot_end(m, &poses) {
                    // The drag keeps pins on their slots' lines, not
                    // between the ends: a pin past one is held where it
                    // was, as a plan's check holds it, and the drag goes
                    // on from there.
                    driver.place(&state, &before);
                    let brk = Break {
                        step: 0,
                        kind: BreakKind::PastSlotEnd,
                        gap,
                    };
                    let text = format!(
                        "{}; {} is held at its last pose within the slot",
                        slot_text(m, slot),
                        g.body
                    );
                    (
                        FrameStatus::Limited { brk },
                        self.poses.clone(),
                        self.inputs.clone(),
                        Some(text),
                    )
                } else {
                    let inputs = input_values(m, &poses, &self.inputs);
                    let explanation = step_of(&status).map(|_| held());
                    (status, poses, inputs, explanation)
                }
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
        // The inputs that go with the poses: a gear pair's residual counts
        // its gears' turns from them (unwrapped past whole turns).
        let with = inputs.as_deref().unwrap_or(&self.inputs);
        if let Some(open) = residuals(m, &poses, with)
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
/// pose puts it, so the identity pose of the result is `poses`; its gear
/// pairs' pivots and racks' lines with them. A slot is its marker's line
/// (the marker's position and dir, turned here with the slotted body) and
/// ends measured along it, so it moves with its marker.
fn redrawn(m: &Mechanism, poses: &[Pose]) -> Mechanism {
    let mut r = m.clone();
    for (body, pose) in r.bodies.iter_mut().zip(poses) {
        for marker in &mut body.markers {
            marker.at = pose.world(marker.at);
            marker.dir = marker.dir.map(|d| pose.world_dir(d));
        }
    }
    super::gears::redraw(&mut r.gears, poses);
    r
}

/// The first pin past an end of its slot at `poses` by more than an open
/// joint's tolerance, and how far past.
fn past_a_slot_end<'m>(m: &'m Mechanism, poses: &[Pose]) -> Option<(&'m Slot, f64)> {
    let ends = Ends::of(m);
    let (at, gap) = Ends::first_past(&ends, poses, OPEN_JOINT * m.size())?;
    let slot = m.slots.iter().find(|s| s.name == at.slot().name)?;
    Some((slot, gap))
}

/// A slot as a plan's check of its ends names it: `crank.P within the slot
/// of yoke.S, from -0.8 to 0.8 along it (joint S)`, or `… within the arc
/// slot about lever.C, from -40° to 20° round it …`.
fn slot_text(m: &Mechanism, slot: &Slot) -> String {
    let [a, pin] = slot.markers;
    let [lo, hi] = slot.ends.map(crate::plan::num);
    let (pin, a) = (m.marker_name(pin), m.marker_name(a));
    match slot.shape {
        Shape::Straight => format!(
            "{pin} within the slot of {a}, from {lo} to {hi} along it (joint {})",
            slot.name
        ),
        Shape::Arc { .. } => format!(
            "{pin} within the arc slot about {a}, from {lo}° to {hi}° round it (joint {})",
            slot.name
        ),
    }
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

    /// The world position of marker `name` ("body.marker") on screen.
    fn marker(s: &Session, name: &str) -> Point {
        let m = &s.doc.mechanism;
        let id = m
            .all_markers()
            .find(|&id| m.marker_name(id) == name)
            .expect("the marker");
        marker_at(m, &s.poses, id)
    }

    #[test]
    fn a_geared_mechanism_is_dragged_through_its_plan_and_meshes_after() {
        // rack_pinion: the rack slides r·θ (r = 1, θ in radians) along x.
        // Turned to 60°, dragged (through the plan, from the pose on screen:
        // the pairs redrawn there), released: the slider continues on the
        // same law.
        let mut s = session("gears/rack_pinion");
        let frame = reply(&mut s, r#"{"type":"inputs","id":1,"values":[60]}"#);
        assert_eq!(frame["status"], "solved", "{frame}");
        let t = marker(&s, "rack.T");
        let grabbed = reply(
            &mut s,
            &format!(
                r#"{{"type":"grab","id":2,"body":"rack","at":[{},{}]}}"#,
                t[0], t[1]
            ),
        );
        assert_eq!(grabbed["type"], "frame", "{grabbed}");
        let dragged = reply(
            &mut s,
            &format!(r#"{{"type":"drag","id":3,"to":[{},{}]}}"#, t[0] - 0.5, t[1]),
        );
        assert_eq!(dragged["type"], "frame", "{dragged}");
        let theta = s.inputs[0];
        assert!(
            (marker(&s, "rack.T")[0] - theta.to_radians()).abs() < 1e-9,
            "{theta}°"
        );
        assert!(
            (theta - (60.0 - 0.5f64.to_degrees())).abs() < 1e-2,
            "the drag turned the pinion back ({theta}°)"
        );
        reply(&mut s, r#"{"type":"release","id":4}"#);
        for theta in [-45.0, 10.0, 80.0] {
            let frame = reply(
                &mut s,
                &format!(r#"{{"type":"inputs","id":5,"values":[{theta}]}}"#),
            );
            assert_eq!(frame["status"], "solved", "{frame}");
            let [x, y] = marker(&s, "rack.T");
            let want = f64::to_radians(theta);
            assert!(
                (x - want).abs() < 1e-9 && (y + 1.0).abs() < 1e-12,
                "{theta}°: rack.T at ({x}, {y})"
            );
            // The pinion's Q, drawn at (1, 0), turned θ about O.
            let q = marker(&s, "pinion.Q");
            assert!((q[0] - want.cos()).abs() < 1e-9 && (q[1] - want.sin()).abs() < 1e-9);
        }
    }

    #[test]
    fn an_epicyclic_train_turned_dragged_and_turned_again_keeps_willis() {
        // The planet's absolute angle is c − (rS/rP)·s = c − 2s whatever
        // the route to the inputs (c, s): slider, drag, slider.
        let mut s = session("gears/epicyclic");
        reply(&mut s, r#"{"type":"inputs","id":1,"values":[30,-30]}"#);
        let p = marker(&s, "planet.P");
        reply(
            &mut s,
            &format!(
                r#"{{"type":"grab","id":2,"body":"planet","at":[{},{}]}}"#,
                p[0], p[1]
            ),
        );
        let dragged = reply(&mut s, r#"{"type":"drag","id":3,"to":[0,3]}"#);
        assert_eq!(dragged["type"], "frame", "{dragged}");
        reply(&mut s, r#"{"type":"release","id":4}"#);
        let (c, sun) = (120.0, 75.0);
        let frame = reply(
            &mut s,
            &format!(r#"{{"type":"inputs","id":5,"values":[{c},{sun}]}}"#),
        );
        assert_eq!(frame["status"], "solved", "{frame}");
        let planet = s
            .doc
            .mechanism
            .bodies
            .iter()
            .position(|b| b.name == "planet")
            .unwrap();
        let turn = s.poses[planet].rot.s.atan2(s.poses[planet].rot.c).to_degrees();
        let want = c - 2.0 * sun;
        assert!(
            ((turn - want + 180.0).rem_euclid(360.0) - 180.0).abs() < 1e-9,
            "planet at {turn}°, {want}° wanted"
        );
        let q = marker(&s, "planet.P");
        let (cr, sr) = (f64::to_radians(c).cos(), f64::to_radians(c).sin());
        assert!(
            (q[0] - 3.0 * cr).abs() < 1e-9 && (q[1] - 3.0 * sr).abs() < 1e-9,
            "{q:?}"
        );
    }

    /// A pinion on an arm (which turns on the frame, input c) driving a
    /// rack that slides on the arm below it (input theta turns the pinion
    /// on the arm): the rack's carrier turns.
    const ARM_RACK: &str = r#"name = "arm_rack"
[bodies.frame]
fixed = true
markers = { O = [0.0, 0.0] }
[bodies.arm]
markers = { O = [0.0, 0.0], P = [2.0, 0.0], T = { at = [2.0, -1.0], dir = [1.0, 0.0] } }
[bodies.pinion]
markers = { P = [2.0, 0.0], Q = [3.0, 0.0] }
[bodies.rack]
markers = { T = [2.0, -1.0], E = [4.0, -1.0] }
[joints.A]
kind = "revolute"
markers = ["frame.O", "arm.O"]
[joints.B]
kind = "revolute"
markers = ["arm.P", "pinion.P"]
[joints.S]
kind = "prismatic"
markers = ["arm.T", "rack.T"]
[joints.R]
kind = "rack-pinion"
bodies = ["pinion", "rack"]
radius = 1.0
[inputs.c]
kind = "angle"
joint = "A"
[inputs.theta]
kind = "angle"
joint = "B"
"#;

    #[test]
    fn a_rack_on_a_turned_carrier_slides_along_it_after_a_replan() {
        // The arm turned a quarter, then a grab plans again from the pose
        // on screen (the rack's line redrawn with the arm): turning the
        // pinion then slides the rack along the arm as turned, as the
        // file's own plan does.
        use crate::conflict::load_str;
        use crate::model::Format;
        let m = load_str("arm_rack.toml", ARM_RACK, Format::Toml).expect("the file loads");
        let doc = Arc::new(Document::new(None, m));
        let mut s = Session::new(doc.clone());
        reply(&mut s, r#"{"type":"inputs","id":1,"values":[90,0]}"#);
        let grabbed = reply(&mut s, r#"{"type":"grab","id":2,"body":"pinion","at":[0,3]}"#);
        assert_eq!(grabbed["type"], "frame", "{grabbed}");
        reply(&mut s, r#"{"type":"release","id":3}"#);
        let frame = reply(&mut s, r#"{"type":"inputs","id":4,"values":[90,40]}"#);
        assert_eq!(frame["status"], "solved", "{frame}");
        let mut d = Driver::new(Interpreter::new(doc.plan.clone().unwrap()), Options::default());
        assert!(d.frame(&[90.0, 40.0]).is_solved());
        let m = &doc.mechanism;
        for id in m.all_markers() {
            let (a, b) = (marker_at(m, &s.poses, id), marker_at(m, d.poses(), id));
            assert!(
                (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9,
                "{}: {a:?} against {b:?}",
                m.marker_name(id)
            );
        }
        // The rack slid r·40° along the arm, now along +y: T up from (1, 2).
        let t = marker(&s, "rack.T");
        assert!(
            (t[0] - 1.0).abs() < 1e-9 && (t[1] - (2.0 + f64::to_radians(40.0))).abs() < 1e-9,
            "{t:?}"
        );
    }

    #[test]
    fn a_geared_mechanism_without_inputs_says_why_it_is_not_dragged() {
        // Neither solver moves it: the drag does not model gears and there
        // is no plan. The grab's error says both; nothing moves.
        use crate::conflict::load_str;
        use crate::model::Format;
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/gears/rack_pinion.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let text = &text[..text.find("[inputs.theta]").expect("the file's input")];
        let m = load_str("still.toml", text, Format::Toml).expect("the file loads without its input");
        let mut s = Session::new(Arc::new(Document::new(None, m)));
        let refused = reply(&mut s, r#"{"type":"grab","id":1,"body":"rack","at":[0,-1]}"#);
        assert_eq!(refused["type"], "error", "{refused}");
        let message = refused["message"].as_str().unwrap();
        assert!(
            message.contains("geared") && message.contains("gear pair R") && message.contains("no inputs"),
            "{message}"
        );
        assert_eq!(
            reply(&mut s, r#"{"type":"drag","id":2,"to":[1,-1]}"#)["type"],
            "error"
        );
        assert!(s.poses.iter().all(|p| *p == Pose::IDENTITY));
    }

    /// How far along slot `name` its pin is on screen (from the slot's
    /// marker, along its direction turned with its body), and how far off
    /// its line.
    fn along_slot(s: &Session, name: &str) -> (f64, f64) {
        let m = &s.doc.mechanism;
        let slot = m.slots.iter().find(|x| x.name == name).expect("the slot");
        let [a, pin] = slot.markers;
        let (at, p) = (marker_at(m, &s.poses, a), marker_at(m, &s.poses, pin));
        let d = s.poses[a.body].world_dir(m.marker(a).unit_dir().unwrap());
        let v = [p[0] - at[0], p[1] - at[1]];
        (v[0] * d[0] + v[1] * d[1], v[0] * d[1] - v[1] * d[0])
    }

    #[test]
    fn a_slotted_lever_turned_and_grabbed_plans_again_with_its_slot_turned() {
        // quick_return: the crank's pin A in the rocker's slot through O4.
        // At 90° the rocker has turned; a grab plans from the pose on
        // screen, the mechanism redrawn there (the slot's marker and its
        // dir turned with the rocker); the sliders then move it as the
        // file's own plan does, the pin on the slot's line.
        let mut s = session("slots/quick_return");
        let frame = reply(&mut s, r#"{"type":"inputs","id":1,"values":[90]}"#);
        assert_eq!(frame["status"], "solved", "{frame}");
        let m = s.doc.mechanism.clone();
        let rocker = m.bodies.iter().position(|b| b.name == "rocker").unwrap();
        assert!(s.poses[rocker].rot.s.abs() > 0.1, "the rocker turned");
        // Redrawn there, the slot's dir is the rocker's line to the pin.
        let r = redrawn(&m, &s.poses);
        let slot = r.marker(r.slots[0].markers[0]);
        let d = slot.unit_dir().unwrap();
        let a = marker(&s, "crank.A");
        let to_pin = [a[0] - slot.at[0], a[1] - slot.at[1]];
        assert!(
            (to_pin[0] * d[1] - to_pin[1] * d[0]).abs() < 1e-12,
            "{d:?} against {to_pin:?}"
        );
        let b = marker(&s, "rocker.B");
        let grabbed = reply(
            &mut s,
            &format!(
                r#"{{"type":"grab","id":2,"body":"rocker","at":[{},{}]}}"#,
                b[0], b[1]
            ),
        );
        assert_eq!(grabbed["type"], "frame", "{grabbed}");
        let dragged = reply(
            &mut s,
            &format!(r#"{{"type":"drag","id":3,"to":[{},{}]}}"#, b[0] - 0.3, b[1]),
        );
        assert_eq!(dragged["type"], "frame", "{dragged}");
        assert!(
            (s.inputs[0] - 90.0).abs() > 1.0,
            "the drag turned the crank ({})",
            s.inputs[0]
        );
        reply(&mut s, r#"{"type":"release","id":4}"#);
        let plan = s.doc.plan.clone().unwrap();
        let mut d = Driver::new(Interpreter::new(plan), Options::default());
        for theta in [120.0, 200.0, 300.0, 400.0] {
            let frame = reply(
                &mut s,
                &format!(r#"{{"type":"inputs","id":5,"values":[{theta}]}}"#),
            );
            assert_eq!(frame["status"], "solved", "{theta}: {frame}");
            assert!(d.frame(&[theta]).is_solved());
            for id in m.all_markers() {
                let (a, b) = (marker_at(&m, &s.poses, id), marker_at(&m, d.poses(), id));
                assert!(
                    (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9,
                    "{theta}: {}: {a:?} against {b:?}",
                    m.marker_name(id)
                );
            }
            // The pin on the slot's line, between its ends (0.9, 3.1): its
            // distance from O4, between d - r = 1 and d + r = 3.
            let (along, off) = along_slot(&s, "S");
            assert!(
                off.abs() < 1e-9 && (1.0 - 1e-9..=3.0 + 1e-9).contains(&along),
                "{theta}: {along}, {off}"
            );
        }
    }

    /// The scotch yoke with its slot's ends at ±0.8: the pin, r sin(30° +
    /// θ) up the slot, reaches the upper end at θ = asin(0.8) − 30°.
    fn short_yoke(inputs: bool) -> Session {
        use crate::conflict::load_str;
        use crate::model::Format;
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/slots/scotch_yoke.toml");
        let text = std::fs::read_to_string(path).unwrap();
        let mut text = text.replace("ends = [-1.25, 1.25]", "ends = [-0.8, 0.8]");
        if !inputs {
            text.truncate(text.find("[inputs.theta]").expect("the file's input"));
        }
        let m = load_str("short.toml", &text, Format::Toml).expect("the file loads");
        Session::new(Arc::new(Document::new(None, m)))
    }

    #[test]
    fn a_pin_driven_past_its_slots_end_is_held_there_and_says_so() {
        let reached = 0.8f64.asin().to_degrees() - 30.0;
        for policy in ["limit", "search"] {
            let mut s = short_yoke(true);
            // Once from the drawing, once after a grab has planned again
            // from a pose short of the end.
            for replanned in [false, true] {
                if replanned {
                    reply(&mut s, r#"{"type":"inputs","id":1,"values":[10]}"#);
                    let p = marker(&s, "crank.P");
                    let grab = format!(
                        r#"{{"type":"grab","id":2,"body":"crank","at":[{},{}]}}"#,
                        p[0], p[1]
                    );
                    assert_eq!(reply(&mut s, &grab)["type"], "frame");
                    reply(&mut s, r#"{"type":"release","id":3}"#);
                }
                let frame = reply(
                    &mut s,
                    &format!(r#"{{"type":"inputs","id":4,"values":[60],"policy":"{policy}"}}"#),
                );
                let want = if policy == "limit" { "limited" } else { "searched" };
                assert_eq!(frame["status"], want, "{frame}");
                let detail = &frame["detail"];
                assert_eq!(
                    detail["reason"], "the pin would run past an end of its slot",
                    "{frame}"
                );
                let text = detail["explanation"].as_str().unwrap();
                assert!(
                    text.contains("crank.P within the slot of yoke.S, from -0.8 to 0.8"),
                    "{text}"
                );
                // Held at the last pose within the ends (the limit policy) or
                // stopped at the end (search), never past it.
                let (along, off) = along_slot(&s, "S");
                let before = if replanned { 40f64.to_radians().sin() } else { 0.5 };
                let want = if policy == "limit" { before } else { 0.8 };
                assert!(
                    off.abs() < 1e-9 && (along - want).abs() < 1e-6,
                    "{policy}: {along}"
                );
                assert!(s.inputs[0] <= reached + 1e-6, "{} past {reached}", s.inputs[0]);
                // Back within the ends, it is solved again.
                let back = reply(&mut s, r#"{"type":"inputs","id":5,"values":[0]}"#);
                assert_eq!(back["status"], "solved", "{back}");
            }
        }
    }

    #[test]
    fn a_free_drag_holds_a_pin_at_its_slots_end() {
        // No inputs, so no plan: the drag itself moves the yoke, and keeps
        // the pin on the slot's line but knows nothing of its ends. Dragged
        // up past the end (0.8), the pin is held within it, the status says
        // which slot; dragged back, it follows again.
        let mut s = short_yoke(false);
        let grab = r#"{"type":"grab","id":1,"body":"crank","at":[0.8660254037844387,0.5]}"#;
        assert_eq!(reply(&mut s, grab)["type"], "frame");
        let mut held = 0;
        for k in 0..=12 {
            let y = 0.5 + 0.1 * f64::from(k);
            let frame = reply(&mut s, &format!(r#"{{"type":"drag","id":2,"to":[0.5,{y}]}}"#));
            assert_eq!(frame["type"], "frame", "{frame}");
            let (along, off) = along_slot(&s, "S");
            assert!(off.abs() < 1e-9 && along <= 0.8 + 1e-6, "{y}: {along}");
            if frame["status"] == "limited" {
                held += 1;
                assert_eq!(
                    frame["detail"]["reason"],
                    "the pin would run past an end of its slot"
                );
                let text = frame["detail"]["explanation"].as_str().unwrap();
                assert!(
                    text.starts_with(
                        "crank.P within the slot of yoke.S, from -0.8 to 0.8 along it (joint S)"
                    ),
                    "{text}"
                );
            }
        }
        assert!(held > 0, "the drag reached past the end");
        // Back down: the pin follows the pointer again.
        let frame = reply(&mut s, r#"{"type":"drag","id":3,"to":[0.5,0.3]}"#);
        assert_ne!(frame["status"], "limited", "{frame}");
        let (along, _) = along_slot(&s, "S");
        assert!(along < 0.7, "{along}");
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
