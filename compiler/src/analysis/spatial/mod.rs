//! Kramer's degrees-of-freedom analysis for spatial mechanisms: equations,
//! the plan-fragment table, the planner, and counting (mobility, rank,
//! redundancy, idle freedoms).

pub mod count;
pub mod fragments;
mod invariants;
pub mod planner;

use dofplan_runtime::{BranchPolicy, Ctx, Solver};

use crate::interp::spatial::Interpreter;
use crate::model::spatial::Mechanism;
use crate::plan::spatial::Plan;

/// Why a spatial mechanism could not be planned.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanError {
    /// Equations no step meets or checks.
    Unplanned(Vec<String>),
    /// The plan does not reproduce the drawing at input 0.
    Drawn(String),
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Unplanned(eqs) => write!(
                f,
                "no plan fragment or cluster meets these equations: {} (please report the file)",
                eqs.join(", ")
            ),
            PlanError::Drawn(what) => write!(f, "the plan does not reproduce the drawing: {what}"),
        }
    }
}

impl std::error::Error for PlanError {}

/// A plan of `m` with no steps yet: the names, markers and inputs every
/// spatial plan carries for its back ends.
pub(crate) fn empty_plan(m: &Mechanism) -> Plan {
    Plan {
        name: m.name.clone(),
        bodies: m.bodies.iter().map(|b| b.name.clone()).collect(),
        fixed: m.bodies.iter().map(|b| b.fixed).collect(),
        inputs: m.inputs.iter().map(|i| i.name.clone()).collect(),
        input_kinds: m.inputs.iter().map(|i| i.kind).collect(),
        markers: m
            .bodies
            .iter()
            .map(|b| b.markers.iter().map(|mk| (mk.name.clone(), mk.at)).collect())
            .collect(),
        source: super::file_name(&m.source.name),
        joint_lines: (m.joints.iter())
            .filter_map(|j| Some((format!("joint {}", j.name), j.line?)))
            .collect(),
        steps: vec![],
        temps: vec![],
        branches: vec![],
        idle: vec![],
    }
}

/// Plans a spatial mechanism: the steps, then each branch chosen so the
/// plan reproduces the drawn pose (run once from the drawing, taking the
/// nearest root everywhere), checked against every equation.
///
/// ```
/// use dofplan::model::Model;
/// use dofplan_runtime::{Driver, Options};
///
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../mechanisms/spatial/rssr.toml");
/// let Model::Spatial(m) = dofplan::load_any(std::path::Path::new(path))? else {
///     panic!("rssr.toml is a spatial file");
/// };
/// let plan = dofplan::analysis::spatial::analyse(&m).expect("the RSSR has a plan");
/// let mut driver = Driver::new(dofplan::interp::spatial::Interpreter::new(plan), Options::default());
/// for theta in [0.0, 20.0, 40.0] {
///     assert!(driver.frame(&[theta]).is_solved());
///     // Every joint, constraint and input holds, read from the model's
///     // own equations (relative to the mechanism's size).
///     assert!(dofplan::simulate::spatial::residual(&m, driver.poses(), &[theta]) < 1e-9);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn analyse(m: &Mechanism) -> Result<Plan, PlanError> {
    let eqs = crate::model::spatial::equations::equations(m);
    let planned = planner::plan(m, &eqs);
    if !planned.unused.is_empty() {
        return Err(PlanError::Unplanned(
            planned
                .unused
                .iter()
                .map(|&i| format!("{} {}", eqs[i].origin, eqs[i].kind.name()))
                .collect(),
        ));
    }
    let mut plan = Plan {
        steps: planned.steps,
        temps: planned.temps,
        branches: planned.branches,
        idle: planned.idle,
        ..empty_plan(m)
    };
    invariants::place_hinged(&mut plan, m.size());
    let interp = Interpreter::new(plan.clone());
    let mut state = interp.initial_state();
    let inputs = vec![0.0; m.inputs.len()];
    let mut ctx = Ctx::new(BranchPolicy::Nearest, false);
    interp.run(&mut state, &inputs, &mut ctx).map_err(|b| {
        PlanError::Drawn(format!(
            "step {} breaks at input 0 ({})",
            crate::plan::spatial::step_number(b.step),
            b.kind.describe()
        ))
    })?;
    let size = m.size();
    for e in &eqs {
        let gap = e.gap(&state.poses, &inputs);
        let tol = if e.linear() { 1e-7 * size } else { 1e-7 };
        if gap > tol {
            return Err(PlanError::Drawn(format!(
                "{} {} is off by {gap:.3e}",
                e.origin,
                e.kind.name()
            )));
        }
    }
    for (slot, b) in plan.branches.iter_mut().zip(&state.branches) {
        slot.initial = *b;
    }
    single_roots(&mut plan, &interp);
    Ok(plan)
}

/// Two circles in different planes that do not lie on one sphere meet in
/// at most one of the two candidate points (a Bennett linkage's skew
/// circles): where the drawing has only one valid candidate, the step needs
/// no branch, and its explanation says so with the other's miss.
fn single_roots(plan: &mut Plan, interp: &Interpreter) {
    use crate::plan::spatial::{Locus, StepKind};
    use dofplan_runtime::spatial::{circle_about, circle_circle_candidates, Circle};
    let state = interp.initial_state();
    let inputs = vec![0.0; plan.inputs.len()];
    let p = |q: &crate::plan::spatial::PointRef| crate::interp::spatial::point(&state, q, &inputs);
    let d = |v: &crate::plan::spatial::DirRef| crate::interp::spatial::dir(&state, v, &inputs);
    for step in &mut plan.steps {
        let StepKind::Intersect {
            loci, branch, tol, ..
        } = &mut step.kind
        else {
            continue;
        };
        let [Locus::Circle { pivot, axis, at }, Locus::Circle {
            pivot: p2,
            axis: a2,
            at: x2,
        }] = loci.as_ref()
        else {
            continue;
        };
        let (c1, n1, r1) = circle_about(p(pivot), d(axis), p(at));
        let (c2, n2, r2) = circle_about(p(p2), d(a2), p(x2));
        let cand = circle_circle_candidates(Circle::new(c1, n1, r1), Circle::new(c2, n2, r2), *tol);
        if !cand.coplanar && cand.count() == 1 {
            let other = if cand.passes[0] {
                cand.misses[1]
            } else {
                cand.misses[0]
            };
            *branch = None;
            if let Some(i) = step.text.find(", branch slot") {
                step.text.truncate(i);
            }
            step.text.push_str(&format!(
                ", one valid root (the other misses by {})",
                crate::plan::num(other)
            ));
        }
    }
}
