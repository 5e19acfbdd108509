//! Kramer's degrees-of-freedom analysis for spatial mechanisms: equations,
//! the plan-fragment table, the planner, and counting (mobility, rank,
//! redundancy, idle freedoms).

pub mod count;
pub mod equations;
pub mod fragments;
pub mod planner;

use dofplan_runtime::{BranchPolicy, Ctx, Solver};

use crate::interp::spatial::Interpreter3;
use crate::model::spatial::Mechanism3;
use crate::plan::spatial::Plan3;

/// Why a spatial mechanism could not be planned.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanError3 {
    /// Equations no step meets or checks.
    Unplanned(Vec<String>),
    /// The plan does not reproduce the drawing at input 0.
    Drawn(String),
}

impl std::fmt::Display for PlanError3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError3::Unplanned(eqs) => write!(
                f,
                "no plan fragment or cluster meets these equations: {} (please report the file)",
                eqs.join(", ")
            ),
            PlanError3::Drawn(what) => write!(f, "the plan does not reproduce the drawing: {what}"),
        }
    }
}

impl std::error::Error for PlanError3 {}

/// Plans a spatial mechanism: the steps, then each branch chosen so the
/// plan reproduces the drawn pose (run once from the drawing, taking the
/// nearest root everywhere), checked against every equation.
pub fn analyse(m: &Mechanism3) -> Result<Plan3, PlanError3> {
    let eqs = equations::equations(m);
    let planned = planner::plan(m, &eqs);
    if !planned.unused.is_empty() {
        return Err(PlanError3::Unplanned(
            planned
                .unused
                .iter()
                .map(|&i| format!("{} {}", eqs[i].origin, eqs[i].kind.name()))
                .collect(),
        ));
    }
    let mut plan = Plan3 {
        name: m.name.clone(),
        bodies: m.bodies.iter().map(|b| b.name.clone()).collect(),
        fixed: m.bodies.iter().map(|b| b.fixed).collect(),
        inputs: m.inputs.iter().map(|i| i.name.clone()).collect(),
        steps: planned.steps,
        temps: planned.temps,
        branches: planned.branches,
        idle: planned.idle,
    };
    let interp = Interpreter3::new(plan.clone());
    let mut state = interp.initial_state();
    let inputs = vec![0.0; m.inputs.len()];
    let mut ctx = Ctx::new(BranchPolicy::Nearest, false);
    interp.run(&mut state, &inputs, &mut ctx).map_err(|b| {
        PlanError3::Drawn(format!(
            "step {} breaks at input 0 ({})",
            b.step,
            b.kind.describe()
        ))
    })?;
    let size = m.size();
    for e in &eqs {
        let gap = e.gap(&state.poses, &inputs);
        let tol = if e.linear() { 1e-7 * size } else { 1e-7 };
        if gap > tol {
            return Err(PlanError3::Drawn(format!(
                "{} {} is off by {gap:.3e}",
                e.origin,
                e.kind.name()
            )));
        }
    }
    for (slot, b) in plan.branches.iter_mut().zip(&state.branches) {
        slot.initial = *b;
    }
    Ok(plan)
}
