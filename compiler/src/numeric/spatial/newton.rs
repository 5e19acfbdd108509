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
