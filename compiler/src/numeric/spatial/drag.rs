//! Dragging a marker of a spatial mechanism: the pure-Newton plan with the
//! marker pinned to a target.

use super::pure_newton;
use crate::model::spatial::Mechanism;
use crate::model::MarkerId;
use crate::plan::spatial::{ClusterRow, Plan, StepKind};

/// Dragging a marker of a spatial mechanism: its inputs released, the
/// marker pinned to a target given as the plan's three inputs (x, y, z),
/// every moving body free, and Newton–Raphson's minimum-norm step — so the
/// mechanism follows the target with the least motion its joints allow
/// (Brunkhart's quasi-physical drag). A target out of reach leaves the
/// joints closed: the frame breaks (no solution within reach) and the
/// breaking policy holds or bisects.
pub fn drag_plan(m: &Mechanism, marker: MarkerId) -> Plan {
    let mut plan = pure_newton(&released(m));
    let StepKind::Cluster(c) = &mut plan.steps[0].kind else {
        unreachable!("pure Newton is one cluster")
    };
    let name = m.marker_name(marker);
    c.rows.push(ClusterRow::Pin {
        body: marker.body,
        local: m.marker(marker).at,
        name: name.clone(),
    });
    plan.inputs = vec!["x".into(), "y".into(), "z".into()];
    plan.input_kinds = vec![crate::model::InputKind::Slide; 3];
    plan
}

/// The mechanism with its inputs released (and so no sweep): what a drag
/// moves, and whose joints its frames are checked against.
pub fn released(m: &Mechanism) -> Mechanism {
    let mut free = m.clone();
    free.inputs.clear();
    free.sweep = None;
    free
}
