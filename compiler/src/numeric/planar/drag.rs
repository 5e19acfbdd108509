//! Dragging (Brunkhart §5.1, fig. 28): a marker pulled toward a target by a
//! temporary coincident constraint to a moving ground point.
//!
//! The mechanism's inputs are released and every mobile body is three
//! unknowns. The joints and constraints are the first task, held exactly;
//! the drag is the second, solved as well as the first allows (task
//! priority, [`dofplan_runtime::numeric::priority`]): an under-constrained
//! chain follows with minimum-norm motion, a well-constrained linkage moves
//! along its own freedom toward the target, and a target out of reach
//! leaves the joints exact and the marker at its **closest approach** — a
//! converged least-squares minimum, singular poses included (a chain pulled
//! straight), reported as a break ("no solution within reach", with the
//! distance left) for the breaking policy to handle: limit keeps the last
//! pose, search finds the boundary, stretch shows the closest approach.
//!
//! When the mechanism has freedom to spare for the drag (two or more DOF
//! once its inputs are released), the drag is first **planned like an
//! input**: the target is a ground point carried by an XY carriage (two
//! slide inputs) and the dragged marker is pinned to it by a revolute. The
//! planner contracts that mechanism like any other — an open chain becomes
//! one cluster of link angles hinged end to end, closed by a single
//! coincident row — and each frame runs the plan. Only a frame the plan
//! cannot solve exactly (the target out of reach) falls back to the task
//! priority above.

use dofplan_runtime::numeric::{priority, Equations, NewtonOptions, NewtonOutcome};
use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::{Break, BreakKind, Ctx, Solver};
use nalgebra::{DMatrix, DVector};

use dofplan_runtime::planar::cluster;

use super::PureNewton;
use crate::analysis::analyse;
use crate::interp::{InterpState, Interpreter};
use crate::model::{Body, InputKind, Joint, JointKind, Marker, MarkerId, Mechanism};

const RANK_CUTOFF: f64 = 1e-10;
const MAX_ITERATIONS: u32 = 50;

/// A marker of a mechanism dragged to targets.
#[derive(Clone, Debug)]
pub struct Drag {
    /// The drag planned like an input, when the mechanism has the freedom.
    planned: Option<Planned>,
    newton: PureNewton,
    body: usize,
    local: Point,
    column: usize,
    size: f64,
}

/// Why a drag cannot be set up.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DragError {
    /// The marker belongs to a fixed body.
    FixedBody(String),
    /// The mechanism has gear pairs (named), which the drag's task-priority
    /// Newton does not model: a gear is planned from its driving input,
    /// and a drag releases the inputs.
    Geared(String),
}

impl std::fmt::Display for DragError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DragError::FixedBody(name) => {
                write!(
                    f,
                    "marker {name} is on a fixed body: drag a marker of a mobile body"
                )
            }
            DragError::Geared(names) => write!(
                f,
                "dragging a marker of a geared mechanism is not supported yet (gear pair {names}): move it by its inputs instead"
            ),
        }
    }
}

impl std::error::Error for DragError {}

/// A drag planned like an input: the plan of the mechanism with its
/// inputs released and the dragged marker pinned to an XY carriage.
#[derive(Clone, Debug)]
struct Planned {
    interpreter: Interpreter,
    /// The dragged marker as drawn: the carriage's slides are measured
    /// from there.
    origin: Point,
}

/// Names of the carriage's bodies, joints and inputs: never a user's (a
/// user's name is an identifier, these are not).
const CARRIAGE_X: &str = "drag carriage x";
const CARRIAGE_Y: &str = "drag carriage y";
const DRAG_PIN: &str = "drag pin";

impl Planned {
    /// `None` when the mechanism cannot spare two DOF for the drag (a
    /// well-constrained linkage follows only the component of the drag its
    /// freedom allows: task priority does that), has no ground, or the
    /// carriage mechanism has no plan.
    fn new(m: &Mechanism, marker: MarkerId) -> Option<Planned> {
        let c = carriage(m, marker)?;
        let origin = m.marker(marker).at;
        let analysis = analyse(&c);
        if analysis.mobility.free() < 0 {
            return None;
        }
        let plan = analysis.plan.ok()?;
        Some(Planned {
            interpreter: Interpreter::new(plan),
            origin,
        })
    }
}

/// The mechanism of a drag planned like an input: `m` with its inputs
/// released, the dragged marker pinned by a revolute ("drag pin") to an XY
/// carriage on the ground whose two slide inputs ("drag x", "drag y") are
/// the target's offsets from the marker's drawn position. Named `<name>_drag_<body>.<marker>`; `None` without a ground.
///
/// `dofplan::build::Config::drag` compiles it like any mechanism.
pub fn carriage(m: &Mechanism, marker: MarkerId) -> Option<Mechanism> {
    let ground = m.bodies.iter().position(|b| b.fixed)?;
    let origin = m.marker(marker).at;
    let mut c = m.clone();
    c.name = format!("{}_drag_{}", m.name, m.marker_name(marker));
    c.inputs.clear();
    c.sweep = None;
    let slide_marker = |name: &str, dir: Point| Marker {
        name: name.to_string(),
        at: origin,
        dir: Some(dir),
    };
    c.bodies[ground]
        .markers
        .push(slide_marker("drag rail", [1.0, 0.0]));
    let ground_marker = MarkerId {
        body: ground,
        marker: c.bodies[ground].markers.len() - 1,
    };
    let (x, y) = (c.bodies.len(), c.bodies.len() + 1);
    c.bodies.push(Body {
        name: CARRIAGE_X.to_string(),
        fixed: false,
        markers: vec![slide_marker("x", [1.0, 0.0]), slide_marker("y", [0.0, 1.0])],
    });
    c.bodies.push(Body {
        name: CARRIAGE_Y.to_string(),
        fixed: false,
        markers: vec![slide_marker("y", [0.0, 1.0])],
    });
    let id = |body, marker| MarkerId { body, marker };
    c.joints.push(Joint {
        name: CARRIAGE_X.to_string(),
        kind: JointKind::Prismatic,
        markers: [ground_marker, id(x, 0)],
        line: None,
    });
    c.joints.push(Joint {
        name: CARRIAGE_Y.to_string(),
        kind: JointKind::Prismatic,
        markers: [id(x, 1), id(y, 0)],
        line: None,
    });
    c.joints.push(Joint {
        name: DRAG_PIN.to_string(),
        kind: JointKind::Revolute,
        markers: [id(y, 0), marker],
        line: None,
    });
    for (k, name) in ["drag x", "drag y"].into_iter().enumerate() {
        c.inputs.push(crate::model::Input {
            name: name.to_string(),
            kind: InputKind::Slide,
            joint: m.joints.len() + k,
        });
    }
    Some(c)
}

/// What a drag carries from frame to frame.
#[derive(Clone, Debug)]
pub struct DragState {
    /// Body poses, in mechanism order.
    pub poses: Vec<Pose>,
    work: Vec<Pose>,
    /// The planned drag's state (the mechanism's bodies first, then the
    /// carriage).
    planned: Option<InterpState>,
}

impl Drag {
    /// Drags `marker` of `m` (its inputs released).
    pub fn new(m: &Mechanism, marker: MarkerId) -> Result<Drag, DragError> {
        if m.bodies[marker.body].fixed {
            return Err(DragError::FixedBody(m.marker_name(marker)));
        }
        if !m.gears.is_empty() {
            return Err(DragError::Geared(m.gear_names()));
        }
        let mut free = m.clone();
        free.inputs.clear();
        let newton = PureNewton::new(&free);
        let column = newton
            .unknown_bodies()
            .into_iter()
            .find(|&(b, _)| b == marker.body)
            .map(|(_, c)| c)
            .expect("every mobile body is an unknown once inputs are released");
        Ok(Drag {
            planned: Planned::new(m, marker),
            size: m.size(),
            newton,
            body: marker.body,
            local: m.marker(marker).at,
            column,
        })
    }

    /// Drags `marker` by task priority alone, never planned (the pure
    /// Newton baseline of the drag's timing).
    pub fn unplanned(m: &Mechanism, marker: MarkerId) -> Result<Drag, DragError> {
        let mut drag = Drag::new(m, marker)?;
        drag.planned = None;
        Ok(drag)
    }

    /// Whether the drag is planned like an input (see the module's doc):
    /// the unknowns and equations of its numeric clusters, if so.
    pub fn planned(&self) -> Option<(usize, usize)> {
        self.planned.as_ref().map(|p| p.interpreter.plan().numeric_size())
    }

    /// Unknowns of the task-priority solve (three per mobile body).
    pub fn unknowns(&self) -> usize {
        self.newton.unknowns()
    }

    /// Joint and constraint equations, plus the two of the drag.
    pub fn equations(&self) -> usize {
        self.newton.equations() + 2
    }
}

impl Solver for Drag {
    type Pose = Pose;
    type State = DragState;
    type Inputs = [f64; 2];

    fn initial_state(&self) -> DragState {
        let poses = vec![Pose::IDENTITY; self.newton.bodies()];
        DragState {
            work: poses.clone(),
            poses,
            planned: self.planned.as_ref().map(|p| p.interpreter.initial_state()),
        }
    }

    /// The drawn position of the dragged marker (the first "previous
    /// target").
    fn initial_inputs(&self) -> [f64; 2] {
        self.local
    }

    fn poses(state: &DragState) -> &[Pose] {
        &state.poses
    }

    fn solve(&self, state: &mut DragState, target: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        if let (Some(p), Some(st)) = (&self.planned, state.planned.as_mut()) {
            // Exactly or not at all: a frame the plan cannot solve goes to
            // the task priority below, whatever the policy.
            let mut exact = Ctx::new(ctx.branch, false);
            let slides = [target[0] - p.origin[0], target[1] - p.origin[1]];
            if p.interpreter.solve(st, &slides, &mut exact).is_ok() {
                let n = state.poses.len();
                state.poses.copy_from_slice(&st.poses[..n]);
                ctx.numeric = exact.numeric;
                return Ok(());
            }
        }
        self.task_priority(state, target, ctx)?;
        if let Some(st) = state.planned.as_mut() {
            // The next planned frame starts from the pose shown.
            let n = state.poses.len();
            st.poses[..n].copy_from_slice(&state.poses);
        }
        Ok(())
    }
}

impl Drag {
    /// One frame by task priority (see the module's doc): the runtime's
    /// [`priority::solve`] over the joints (first task) and the drag
    /// (second), warm-started from the last frame.
    fn task_priority(&self, state: &mut DragState, target: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        let DragState { poses, work, .. } = state;
        work.copy_from_slice(poses);
        let joints = self.newton.equations();
        let (system, mut x) =
            cluster::System::new(work, self.newton.params(), self.newton.rows(), &[], self.size);
        let mut dragged = Dragged {
            joints: system,
            rows: joints,
            body: self.body,
            local: self.local,
            column: self.column,
            target: [target[0], target[1]],
            size: self.size,
        };
        let options = NewtonOptions {
            max_iterations: MAX_ITERATIONS,
            tolerance: 1e-12 * self.size,
            rank_cutoff: RANK_CUTOFF,
            max_step: 0.1 * self.size,
        };
        let report = priority::solve(&mut dragged, joints, &mut x, &options);
        dragged.joints.apply(&x);
        drop(dragged);
        ctx.numeric = Some(report.newton);
        // A pose whose joints are open is never shown, whatever the policy:
        // stretching relaxes the drag, not the mechanism.
        if report.first > 1e-9 * self.size {
            return Err(Break {
                step: 0,
                kind: BreakKind::NotConverged,
                gap: report.first,
            });
        }
        let residual = report.newton.residual;
        match report.newton.outcome {
            NewtonOutcome::Converged => {}
            // The closest approach, with the distance left to the target.
            NewtonOutcome::NoSolution => ctx.fail(0, BreakKind::NoSolution, residual)?,
            NewtonOutcome::NotConverged => ctx.fail(0, BreakKind::NotConverged, residual)?,
        }
        // The joints keep a pin on its slot's line or circle; past an end
        // the frame breaks, as the plan's check of the ends breaks it.
        if let Some(gap) = self.newton.past_an_end(work) {
            ctx.fail(0, BreakKind::PastSlotEnd, gap)?;
        }
        std::mem::swap(poses, work);
        Ok(())
    }
}

/// The joints of the released mechanism (rows first) and the drag: the
/// dragged marker minus the target (two rows), over the same unknowns.
struct Dragged<'a> {
    joints: cluster::System<'a>,
    rows: usize,
    body: usize,
    local: Point,
    /// The dragged body's first unknown (it is free: x, y, size·angle).
    column: usize,
    target: Point,
    size: f64,
}

impl Equations for Dragged<'_> {
    fn unknowns(&self) -> usize {
        self.joints.unknowns()
    }

    fn equations(&self) -> usize {
        self.rows + 2
    }

    fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, mut jacobian: Option<&mut DMatrix<f64>>) {
        // The cluster system writes its rows (and zeroes the whole
        // Jacobian); the drag's two rows follow.
        self.joints.eval(x, r, jacobian.as_deref_mut());
        let (at, turn) = self.joints.poses()[self.body].world_and_turn(self.local);
        let k = self.rows;
        r[k] = at[0] - self.target[0];
        r[k + 1] = at[1] - self.target[1];
        if let Some(j) = jacobian {
            let c = self.column;
            j[(k, c)] = 1.0;
            j[(k + 1, c + 1)] = 1.0;
            j[(k, c + 2)] = turn[0] / self.size;
            j[(k + 1, c + 2)] = turn[1] / self.size;
        }
    }
}
