//! Planar plan-time analysis: Grübler's mobility, the DOF-driven planner
//! (propagation, then contraction by dyads), the branch choice that makes a
//! plan reproduce the drawn pose, the rank test and Grashof's classes.

pub mod grashof;
pub mod mobility;
mod planner;
pub mod rank;

use std::fmt;

use dofplan_runtime::{BranchPolicy, Ctx, Solver};

use super::{file_name, Progress};
use crate::interp::Interpreter;
pub use crate::model::planar::equations::{Equation, Sourced};
use crate::model::Mechanism;
use crate::plan::{Plan, PlanBody, PlanInput};
pub use mobility::{Class, Mobility};

/// Everything plan time learns about a mechanism.
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Grübler's count.
    pub mobility: Mobility,
    /// The primitive equations of joints, constraints and inputs.
    pub equations: Vec<Sourced>,
    /// The closed-form plan, or why there is none.
    pub plan: Result<Plan, PlanError>,
    /// Equations no step used (redundant, or on bodies left over), by origin.
    pub unused: Vec<String>,
    /// Candidate equations the planner's rules examined: its work, linear
    /// in the mechanism's size.
    pub planner_checks: usize,
}

/// Why a mechanism has no plan.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanError {
    /// The plan does not reproduce the pose as drawn (an analysis bug,
    /// reported rather than hidden).
    DrawnPoseMismatch {
        /// The body that lands elsewhere.
        body: String,
        /// How far off.
        gap: f64,
    },
    /// Equations no step enforces nor checks: frames would break them
    /// unnoticed (a degenerate drawing, e.g. two joints of a body at one
    /// point, makes the rules take one joint for another).
    Unchecked {
        /// Their origins ("joint TY").
        equations: Vec<String>,
    },
    /// Gear pairs (or racks) no closed-form step sets: the angle each is set
    /// from does not come from inputs through revolute joints and gears.
    Ungeared {
        /// Their names.
        gears: Vec<String>,
    },
    /// A step cannot be met even at the drawn pose.
    BrokenAtDrawnPose {
        /// The step.
        step: usize,
        /// Its explanation.
        explanation: String,
    },
}

impl fmt::Display for PlanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlanError::DrawnPoseMismatch { body, gap } => write!(
                f,
                "internal error: the plan does not reproduce the drawn pose (body {body} is {gap:.3e} off); please report it with the file"
            ),
            PlanError::Unchecked { equations } => write!(
                f,
                "no step enforces or checks {}, so a frame could break it unnoticed; the drawing is \
                 degenerate there (e.g. two joints of a body at one point): draw those joints apart",
                equations.join(", ")
            ),
            PlanError::Ungeared { gears } => write!(
                f,
                "no closed-form step sets gear pair {}: a gear is planned from the angle of a body an input \
                 turns (directly, or through revolute joints and other gears), a rack from its pinion's angle \
                 or its own slide input, and here the driving angle comes from a loop closure instead; drive \
                 one of the pair's bodies (or its carrier) with an input",
                gears.join(", ")
            ),
            PlanError::BrokenAtDrawnPose { step, explanation } => {
                write!(f, "step {step} cannot be met at the drawn pose: {explanation}")
            }
        }
    }
}

impl std::error::Error for PlanError {}

/// Analyses a mechanism and plans it.
pub fn analyse(m: &Mechanism) -> Analysis {
    analyse_with(m, &mut |_| {})
}

/// [`analyse`], reporting how far it is to `progress`.
pub fn analyse_with(m: &Mechanism, progress: &mut dyn FnMut(Progress)) -> Analysis {
    let mobility = Mobility::of(m);
    let eqs = crate::model::planar::equations::equations(m);
    let planned = planner::plan(m, &eqs, progress);
    let unused: Vec<String> = planned.unused.iter().map(|&i| eqs[i].origin.clone()).collect();
    let plan = if !planned.ungeared.is_empty() {
        let gears = planned
            .ungeared
            .iter()
            .map(|&g| m.gears[g].name.clone())
            .collect();
        Err(PlanError::Ungeared { gears })
    } else if !unused.is_empty() {
        let mut equations = unused.clone();
        equations.dedup();
        Err(PlanError::Unchecked { equations })
    } else {
        let plan = Plan {
            mechanism: m.name.clone(),
            source: file_name(&m.source.name),
            joint_lines: (m.joints.iter())
                .filter_map(|j| Some((format!("joint {}", j.name), j.line?)))
                .chain(
                    m.gears
                        .iter()
                        .filter_map(|g| Some((format!("joint {}", g.name), g.line?))),
                )
                .collect(),
            bodies: m
                .bodies
                .iter()
                .map(|b| PlanBody {
                    name: b.name.clone(),
                    fixed: b.fixed,
                    markers: b.markers.iter().map(|mk| (mk.name.clone(), mk.at)).collect(),
                })
                .collect(),
            inputs: m
                .inputs
                .iter()
                .map(|i| PlanInput {
                    name: i.name.clone(),
                    kind: i.kind,
                })
                .collect(),
            temps: planned.temps,
            branches: planned.branches,
            steps: with_slot_ends(m, planned.steps),
            size: m.size(),
        };
        let branches = |done| Progress {
            stage: "branches",
            done,
            total: 1,
        };
        progress(branches(0));
        let chosen = choose_branches(m, plan);
        progress(branches(1));
        chosen
    };
    Analysis {
        mobility,
        equations: eqs,
        plan,
        unused,
        planner_checks: planned.checks,
    }
}

/// The plan's steps and, last, a check of each slot's ends (the pin on
/// the slot's line is an equation the steps meet; how far along it is
/// only checked, once every body is placed).
fn with_slot_ends(m: &Mechanism, mut steps: Vec<crate::plan::Step>) -> Vec<crate::plan::Step> {
    use crate::plan::{DirRef, PointRef, Step, StepKind};
    let point = |id: crate::model::MarkerId| {
        let (at, name) = (m.marker(id).at, m.marker_name(id));
        if m.bodies[id.body].fixed {
            PointRef::Fixed { at, name }
        } else {
            PointRef::Marker {
                body: id.body,
                local: at,
                name,
            }
        }
    };
    for slot in &m.slots {
        let [a, b] = slot.markers;
        let local = m
            .marker(a)
            .unit_dir()
            .expect("validated: a slot's marker carries a dir");
        let dir = if m.bodies[a.body].fixed {
            DirRef::Fixed(local)
        } else {
            DirRef::Body { body: a.body, local }
        };
        steps.push(Step {
            kind: StepKind::Within {
                at: point(a),
                dir,
                pin: point(b),
                ends: slot.ends,
                arc: matches!(slot.shape, crate::model::planar::slots::Shape::Arc { .. }),
            },
            serves: vec![format!("joint {}", slot.name)],
        });
    }
    steps
}

/// Chooses every branch so the plan reproduces the drawn pose, then checks
/// that it does.
///
/// Running the plan once at zero input with the nearest-root policy, with
/// every slot's "previous" value set to its drawn value, picks at each step
/// the root nearest the drawing — the same code path move time uses.
fn choose_branches(m: &Mechanism, mut plan: Plan) -> Result<Plan, PlanError> {
    let interp = Interpreter::new(plan.clone());
    let mut state = interp.initial_state();
    let zeros = interp.initial_inputs();
    let mut ctx = Ctx::new(BranchPolicy::Nearest, false);
    if let Err(brk) = interp.solve(&mut state, &zeros, &mut ctx) {
        return Err(PlanError::BrokenAtDrawnPose {
            step: brk.step as usize,
            explanation: plan.explain(brk.step as usize),
        });
    }
    for (slot, chosen) in plan.branches.iter_mut().zip(&state.branches) {
        slot.initial = *chosen;
    }
    let tol = 1e-9 * m.size();
    for (b, body) in m.bodies.iter().enumerate() {
        for marker in &body.markers {
            let w = state.poses[b].world(marker.at);
            let gap = ((w[0] - marker.at[0]).powi(2) + (w[1] - marker.at[1]).powi(2)).sqrt();
            if gap > tol {
                return Err(PlanError::DrawnPoseMismatch {
                    body: body.name.clone(),
                    gap,
                });
            }
        }
    }
    Ok(plan)
}
