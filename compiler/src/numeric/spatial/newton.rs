//! Pure Newton in space: Figure 30's left column lifted to 3D. Every moving
//! body is six unknowns (a rotation vector and a translation), every joint,
//! constraint and input equation a residual, and Newton–Raphson with the
//! SVD pseudo-inverse solves them all together from the previous frame — no
//! analysis. It is a plan of one numeric cluster, run by the same
//! interpreter and runtime cluster code as a mixed plan's clusters, so the
//! two differ only in what the analysis saves.

use crate::analysis::spatial::empty_plan;
use crate::model::spatial::equations::equations;
use crate::model::spatial::Mechanism;
use crate::plan::spatial::{CheckRow, Cluster, ClusterRow, Param, Plan, Step, StepKind};

/// The pure-Newton plan of a spatial mechanism: one cluster of every
/// moving body (6 unknowns each) over every equation.
pub fn pure_newton(m: &Mechanism) -> Plan {
    let size = m.size();
    let params: Vec<Param> = (0..m.bodies.len())
        .filter(|&b| !m.bodies[b].fixed)
        .map(|body| Param::Free { body })
        .collect();
    let rows: Vec<ClusterRow> = equations(m)
        .iter()
        .filter(|e| e.bodies.iter().any(|&b| !m.bodies[b].fixed))
        .map(|e| ClusterRow::Equation(CheckRow::of(e, 0, size)))
        .collect();
    let cluster = Cluster { params, rows, size };
    Plan {
        steps: vec![Step {
            kind: StepKind::Cluster(Box::new(cluster)),
            serves: vec![],
        }],
        ..empty_plan(m)
    }
}
