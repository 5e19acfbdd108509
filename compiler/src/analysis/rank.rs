//! Mobility by the rank of the constraint Jacobian at the drawn pose, and
//! what it says that Grübler's count cannot: which equations are redundant
//! (Brunkhart §2.1.3–2.1.4: non-generic mechanisms) and which bodies can
//! move on their own (idle degrees of freedom).

use dofplan_runtime::numeric::rank;
use nalgebra::DMatrix;

use crate::model::Mechanism;
use crate::numeric::PureNewton;

/// Relative singular-value cut-off for ranks at the drawn pose.
const RANK_CUTOFF: f64 = 1e-9;

/// Mobility from the Jacobian.
#[derive(Clone, Debug, PartialEq)]
pub struct RankMobility {
    /// Unknowns: three per mobile body.
    pub unknowns: usize,
    /// Scalar equations of joints and constraints (inputs left out).
    pub equations: usize,
    /// Rank of their Jacobian at the drawn pose.
    pub rank: usize,
    /// Degrees of freedom: unknowns − rank.
    pub dof: i64,
    /// Equations that add no rank, by origin, with how many of their rows
    /// are dependent on the ones before them (file order).
    pub redundant: Vec<(String, usize)>,
    /// Bodies that can move while every other body stays put, with how
    /// many freedoms they have on their own.
    pub idle: Vec<(String, usize)>,
}

fn rows(j: &DMatrix<f64>, n: usize) -> DMatrix<f64> {
    j.rows(0, n).into_owned()
}

/// Mobility of the mechanism with its inputs released, by Jacobian rank.
pub fn rank_mobility(m: &Mechanism) -> RankMobility {
    let mut free = m.clone();
    free.inputs.clear();
    let newton = PureNewton::new(&free);
    let (j, groups) = newton.drawn_jacobian();
    let full = rank(&j, RANK_CUTOFF);
    // Greedy in file order: a group whose rows do not all raise the rank of
    // the rows before it has dependent rows.
    let mut redundant = Vec::new();
    let mut taken = 0;
    let mut rank_so_far = 0;
    for (origin, count) in groups {
        let r = rank(&rows(&j, taken + count), RANK_CUTOFF);
        // More rows can lower a rank taken relative to the largest singular
        // value (a badly scaled row raises the cut-off): such rows add none.
        let gained = r.saturating_sub(rank_so_far);
        if gained < count {
            redundant.push((origin, count - gained));
        }
        rank_so_far = rank_so_far.max(r);
        taken += count;
    }
    let idle = newton
        .unknown_bodies()
        .into_iter()
        .filter_map(|(b, col)| {
            let alone = 3 - rank(&j.columns(col, 3).into_owned(), RANK_CUTOFF);
            (alone > 0).then(|| (m.bodies[b].name.clone(), alone))
        })
        .collect();
    RankMobility {
        unknowns: newton.unknowns(),
        equations: newton.equations(),
        rank: full,
        dof: newton.unknowns() as i64 - full as i64,
        redundant,
        idle,
    }
}
