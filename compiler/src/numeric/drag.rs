//! Dragging (Brunkhart §5.1, fig. 28): a marker pulled toward a target by a
//! temporary coincident constraint to a moving ground point.
//!
//! The mechanism's inputs are released and every mobile body is three
//! unknowns. The joints and constraints are the first task, held exactly;
//! the drag is the second, solved in the null space of the first (task
//! priority): each Newton step is
//!
//! ```text
//! δ₁ = −J_c⁺ r_c          meet the joints (minimum-norm)
//! N  = I − J_c⁺ J_c       the motions the joints allow
//! δ  = δ₁ + N (J_d N)⁺ (−r_d − J_d δ₁)
//! ```
//!
//! so an under-constrained chain follows with minimum-norm motion, a
//! well-constrained linkage moves along its own freedom toward the target,
//! and a target out of reach leaves the joints exact and the marker as
//! close as the mechanism allows — reported as a break ("no solution within
//! reach") for the breaking policy to handle: limit keeps the last pose,
//! search finds the boundary, stretch accepts the closest approach.
//!
//! When the mechanism has freedom to spare for the drag (two or more DOF
//! once its inputs are released), the drag is first **planned like an
//! input**: the target is a ground point carried by an XY carriage (two
//! slide inputs) and the dragged marker is pinned to it by a revolute. The
//! planner contracts that mechanism like any other — an open chain becomes
//! one cluster of link angles hinged end to end, closed by a single
//! coincident row — and each frame runs the plan. Only a frame the plan
//! cannot solve exactly (the target out of reach) falls back to the task
//! priority above, which finds the closest approach with every joint
//! exact.

use dofplan_runtime::numeric::{pseudo_inverse, rank, Equations, NewtonOutcome, NewtonReport};
use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::{Break, BreakKind, Ctx, Solver};
use nalgebra::{DMatrix, DVector};

use dofplan_runtime::numeric::cluster;

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
    });
    c.joints.push(Joint {
        name: CARRIAGE_Y.to_string(),
        kind: JointKind::Prismatic,
        markers: [id(x, 1), id(y, 0)],
    });
    c.joints.push(Joint {
        name: DRAG_PIN.to_string(),
        kind: JointKind::Revolute,
        markers: [id(y, 0), marker],
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
    /// One frame by task priority (see the module's doc).
    fn task_priority(&self, state: &mut DragState, target: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        let DragState { poses, work, .. } = state;
        work.copy_from_slice(poses);
        let (n, m) = (self.newton.unknowns(), self.newton.equations());
        // The joints: the runtime's cluster system over every mobile body
        // (free), warm-started from the last frame.
        let (mut joints_system, mut x) =
            cluster::System::new(work, self.newton.params(), self.newton.rows(), &[], self.size);
        let mut rc = DVector::zeros(m);
        let mut jc = DMatrix::zeros(m, n);
        let mut jd = DMatrix::zeros(2, n);
        let tolerance = 1e-12 * self.size;
        let max_step = 0.1 * self.size;
        let mut report = NewtonReport {
            outcome: NewtonOutcome::NotConverged,
            iterations: 0,
            residual: f64::INFINITY,
            rank: 0,
        };
        let mut previous_drag = f64::INFINITY;
        for iteration in 0..=MAX_ITERATIONS {
            joints_system.eval(&x, &mut rc, Some(&mut jc));
            let (at, turn) = joints_system.poses()[self.body].world_and_turn(self.local);
            let rd = DVector::from_row_slice(&[at[0] - target[0], at[1] - target[1]]);
            let (joints, drag) = (rc.norm(), rd.norm());
            report.iterations = iteration;
            report.residual = drag.max(joints);
            if joints <= tolerance && drag <= tolerance {
                report.outcome = NewtonOutcome::Converged;
                break;
            }
            // The drag has (all but) stopped improving with the joints met:
            // the closest reachable point — no solution within reach of
            // this pose. Near a singular pose (a chain pulled straight) the
            // approach is slow, hence a relative threshold rather than
            // waiting for a zero step.
            if joints <= tolerance && drag > (1.0 - 1e-6) * previous_drag {
                report.outcome = NewtonOutcome::NoSolution;
                report.residual = drag;
                break;
            }
            if iteration == MAX_ITERATIONS || !joints.is_finite() || !drag.is_finite() {
                break;
            }
            previous_drag = if joints <= tolerance { drag } else { f64::INFINITY };
            jd.fill(0.0);
            jd[(0, self.column)] = 1.0;
            jd[(1, self.column + 1)] = 1.0;
            jd[(0, self.column + 2)] = turn[0] / self.size;
            jd[(1, self.column + 2)] = turn[1] / self.size;
            let jc_pinv = pseudo_inverse(&jc, RANK_CUTOFF);
            report.rank = rank(&jc, RANK_CUTOFF);
            let step_joints = -(&jc_pinv * &rc);
            let null = DMatrix::identity(n, n) - &jc_pinv * &jc;
            let along = &jd * &null;
            let wanted = -(&rd) - &jd * &step_joints;
            let mut step = step_joints + &null * (pseudo_inverse(&along, RANK_CUTOFF) * wanted);
            let largest = step.amax();
            if largest > max_step {
                step *= max_step / largest;
            }
            // Keep the joints: near a singular pose (a chain pulled
            // straight) the linearised null space lets a full step open
            // them. Halve the step until the joints stay within what they
            // were (or a share of the step); failing that, only restore
            // them.
            let allowed = (2.0 * joints).max(0.05 * step.norm()).max(tolerance);
            let mut accepted = false;
            for _ in 0..30 {
                let trial = &x + &step;
                joints_system.eval(&trial, &mut rc, None);
                if rc.norm() <= allowed {
                    x = trial;
                    accepted = true;
                    break;
                }
                step *= 0.5;
            }
            if !accepted {
                joints_system.eval(&x, &mut rc, None);
                x -= &jc_pinv * &rc;
            }
        }
        // The pose of the last iterate (the closest approach when out of
        // reach), and its joints.
        joints_system.eval(&x, &mut rc, None);
        drop(joints_system);
        ctx.numeric = Some(report);
        // A pose whose joints are open is never shown, whatever the policy:
        // stretching relaxes the drag, not the mechanism. (Pulling a chain
        // straight is singular; Newton may fail to hold the joints there.)
        let joints = rc.norm();
        if joints > 1e-9 * self.size {
            return Err(Break {
                step: 0,
                kind: BreakKind::NotConverged,
                gap: joints,
            });
        }
        match report.outcome {
            NewtonOutcome::Converged => {}
            NewtonOutcome::NoSolution => ctx.fail(0, BreakKind::NoSolution, report.residual)?,
            NewtonOutcome::NotConverged => ctx.fail(0, BreakKind::NotConverged, report.residual)?,
        }
        std::mem::swap(poses, work);
        Ok(())
    }
}
