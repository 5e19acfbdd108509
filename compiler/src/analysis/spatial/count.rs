//! Counting in space (docs/design/spatial.md §1.4): Grübler–Kutzbach mobility, mobility
//! from the rank of the joint Jacobian at the drawn pose, the redundant
//! equations named by joint and primitive, and the idle freedoms left with
//! the inputs added.
//!
//! The Jacobian is taken with respect to a twist (ω, v) of every moving
//! body at the drawn pose (6 columns each), by the runtime's exact row
//! derivatives; its rank comes from the planar rank's sparse elimination in
//! file order, so a row is redundant when the rows before it span it, and
//! the work stays linear in a chain's length.

use dofplan_runtime::spatial::rows::{FrameRate, WorldFrame};

use crate::analysis::planar::rank::{Echelon, SparseRow};
use crate::model::spatial::equations::{equations, Equation, Kind};
use crate::model::spatial::Mechanism;

/// Relative cut-off of the elimination (as the planar rank's).
const RANK_CUTOFF: f64 = 1e-9;

/// What `dofplan check` reports of a spatial mechanism.
#[derive(Clone, Debug, PartialEq)]
pub struct Count {
    /// Moving bodies.
    pub moving: usize,
    /// Scalar equations of joints and constraints (inputs left out).
    pub equations: usize,
    /// Grübler–Kutzbach: 6n − Σ equations.
    pub grubler: i64,
    /// Rank of the joints' Jacobian at the drawn pose.
    pub rank: usize,
    /// 6n − rank.
    pub mobility: i64,
    /// Σ equations − rank.
    pub redundant_equations: usize,
    /// The dependent rows by (origin, primitive, rows), in file order.
    pub redundant: Vec<(String, String, usize)>,
    /// Inputs.
    pub inputs: usize,
    /// 6n − rank with the inputs' equations added: freedoms no input
    /// drives (an RSSR coupler's spin).
    pub idle_freedoms: i64,
}

/// Counts a spatial mechanism.
pub fn count(m: &Mechanism) -> Count {
    let eqs = equations(m);
    let mut column = vec![None; m.bodies.len()];
    let mut unknowns = 0;
    for (b, body) in m.bodies.iter().enumerate() {
        if !body.fixed {
            column[b] = Some(unknowns);
            unknowns += 6;
        }
    }
    let size = m.size();
    let groups: Vec<(&Equation, Vec<SparseRow>)> = eqs
        .iter()
        .filter(|e| e.bodies.iter().any(|&b| column[b].is_some()))
        .map(|e| (e, jacobian_rows(e, &column, size, m.inputs.len())))
        .collect();
    let largest = groups
        .iter()
        .flat_map(|(_, rows)| rows.iter().flatten())
        .map(|&(_, v)| v.abs())
        .fold(0.0, f64::max);
    let mut echelon = Echelon::new(unknowns, RANK_CUTOFF * largest);
    let mut redundant = Vec::new();
    let mut equations_n = 0;
    let mut rank_joints: Option<usize> = None;
    // Joints and constraints first (the inputs last, as `equations` lists
    // them): the rank without inputs is read before they are added.
    for (e, rows) in &groups {
        let is_input = matches!(e.kind, Kind::Angle { .. } | Kind::Slide { .. });
        if is_input && rank_joints.is_none() {
            rank_joints = Some(echelon.rank());
        }
        let dependent = rows.iter().filter(|row| !echelon.add(row)).count();
        if !is_input {
            equations_n += e.kind.rows();
            if dependent > 0 {
                redundant.push((e.origin.clone(), e.kind.name().to_string(), dependent));
            }
        }
    }
    let rank = rank_joints.unwrap_or(echelon.rank());
    let with_inputs = echelon.rank();
    let moving = m.moving();
    Count {
        moving,
        equations: equations_n,
        grubler: 6 * moving as i64 - equations_n as i64,
        rank,
        mobility: unknowns as i64 - rank as i64,
        redundant_equations: equations_n - rank,
        redundant,
        inputs: m.inputs.len(),
        idle_freedoms: unknowns as i64 - with_inputs as i64,
    }
}

/// The Jacobian rows of one equation at the drawn pose, against each moving
/// body's twist (ω about the world origin, v).
fn jacobian_rows(e: &Equation, column: &[Option<usize>], size: f64, inputs: usize) -> Vec<SparseRow> {
    let kind = e.row_kind();
    let frame = |k: usize| WorldFrame {
        at: e.frames[k].at,
        z: e.frames[k].axes.z,
        x: e.frames[k].axes.x,
    };
    let (f1, f2) = (frame(0), frame(1));
    let n = kind.rows();
    let inputs = vec![0.0; inputs];
    let mut rows: Vec<SparseRow> = vec![Vec::new(); n];
    for (side, &b) in e.bodies.iter().enumerate() {
        let Some(first) = column[b] else { continue };
        if side == 1 && e.bodies[0] == b {
            continue;
        }
        for j in 0..6 {
            let mut omega = [0.0; 3];
            let mut v = [0.0; 3];
            if j < 3 {
                omega[j] = 1.0;
            } else {
                // Translations scaled by the size, so both kinds of column
                // weigh alike in the elimination's tolerance.
                v[j - 3] = 1.0 / size;
            }
            let zero = FrameRate::default();
            let (d1, d2) = if side == 0 {
                (FrameRate::of(&f1, omega, v, [0.0; 3]), zero)
            } else {
                (zero, FrameRate::of(&f2, omega, v, [0.0; 3]))
            };
            let d = kind.deriv(&f1, &f2, &d1, &d2, &inputs);
            for (r, value) in d.iter().take(n).enumerate() {
                // Rows of lengths against rows of sines: lengths over the size.
                let value = if e.linear() { value / size } else { *value };
                if value.abs() > 1e-14 {
                    rows[r].push((first + j, value));
                }
            }
        }
    }
    rows
}
