//! Pure Newton in space: Figure 30's left column lifted to 3D. Every moving
//! body is six unknowns (a rotation vector and a translation), every joint,
//! constraint and input equation a residual, and Newton–Raphson with the
//! SVD pseudo-inverse solves them all together from the previous frame — no
//! analysis. It is a plan of one numeric cluster, run by the same
//! interpreter and runtime cluster code as a mixed plan's clusters, so the
//! two differ only in what the analysis saves.

use crate::analysis::spatial::empty_plan;
use crate::model::spatial::equations::equations;
use crate::model::spatial::Mechanism3;
use crate::model::MarkerId;
use crate::plan::spatial::{CheckRow, Cluster3, ClusterRow3, Param3, Plan3, Step3, StepKind3};

/// The pure-Newton plan of a spatial mechanism: one cluster of every
/// moving body (6 unknowns each) over every equation.
pub fn pure_newton(m: &Mechanism3) -> Plan3 {
    let size = m.size();
    let params: Vec<Param3> = (0..m.bodies.len())
        .filter(|&b| !m.bodies[b].fixed)
        .map(|body| Param3::Free { body })
        .collect();
    let rows: Vec<ClusterRow3> = equations(m)
        .iter()
        .filter(|e| e.bodies.iter().any(|&b| !m.bodies[b].fixed))
        .map(|e| ClusterRow3::Equation(CheckRow::of(e, 0, size)))
        .collect();
    let cluster = Cluster3 { params, rows, size };
    let text = format!(
        "pure Newton: every moving body free ({} unknowns, {} equations)",
        cluster.unknowns(),
        cluster.equations()
    );
    Plan3 {
        steps: vec![Step3 {
            kind: StepKind3::Cluster(Box::new(cluster)),
            text,
            serves: vec![],
        }],
        ..empty_plan(m)
    }
}

/// Dragging a marker of a spatial mechanism: its inputs released, the
/// marker pinned to a target given as the plan's three inputs (x, y, z),
/// every moving body free, and Newton–Raphson's minimum-norm step — so the
/// mechanism follows the target with the least motion its joints allow
/// (Brunkhart's quasi-physical drag). A target out of reach leaves the
/// joints closed: the frame breaks (no solution within reach) and the
/// breaking policy holds or bisects.
pub fn drag_plan(m: &Mechanism3, marker: MarkerId) -> Plan3 {
    let mut plan = pure_newton(&released(m));
    let StepKind3::Cluster(c) = &mut plan.steps[0].kind else {
        unreachable!("pure Newton is one cluster")
    };
    let name = m.marker_name(marker);
    c.rows.push(ClusterRow3::Pin {
        body: marker.body,
        local: m.marker(marker).at,
        name: name.clone(),
    });
    plan.steps[0].text = format!(
        "drag {name}: every moving body free, {name} pinned to the target ({} unknowns, {} equations)",
        c.unknowns(),
        c.equations()
    );
    plan.inputs = vec!["x".into(), "y".into(), "z".into()];
    plan.input_kinds = vec![crate::model::InputKind::Slide; 3];
    plan
}

/// The mechanism with its inputs released (and so no sweep): what a drag
/// moves, and whose joints its frames are checked against.
pub fn released(m: &Mechanism3) -> Mechanism3 {
    let mut free = m.clone();
    free.inputs.clear();
    free.sweep = None;
    free
}
