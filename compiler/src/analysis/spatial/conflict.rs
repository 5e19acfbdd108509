//! The least-squares help for spatial drawings whose joints do not hold:
//! from the drawn pose, every moving body free and Newton–Raphson's
//! minimum-norm steps on every joint and constraint (no inputs), as the
//! planar `conflict` does. Either the joints all close near the drawing —
//! only the drawing is off, and by how much — or they cannot, and the
//! joints still open at the least-squares pose are the ones in conflict.

use dofplan_runtime::spatial::{norm, sub};
use dofplan_runtime::{BranchPolicy, Ctx, Solver};

use super::equations::equations;
use crate::analysis::conflict::Open;
use crate::interp::spatial::Interpreter3;
use crate::model::spatial::Mechanism3;
use crate::model::Diagnostic;
use crate::numeric::spatial::{pure_newton, released};

/// Above this many moving bodies the dense assembly is not run (its SVD
/// grows with the cube of the unknowns); the errors say so.
const MAX_REVIEWED_BODIES: usize = 80;

/// Adds to each "does not hold in the drawn pose" error what the
/// least-squares assembly says.
pub(crate) fn review(m: &Mechanism3, open: &[Open], diags: &mut [Diagnostic]) {
    let mut add = |i: usize, hint: &str| {
        let d = &mut diags[i];
        d.help = Some(match d.help.take() {
            Some(h) => format!("{h}; {hint}"),
            None => hint.to_string(),
        });
    };
    let moving = m.moving();
    if moving > MAX_REVIEWED_BODIES {
        for o in open {
            add(
                o.diagnostic,
                &format!(
                    "whether the rest of the mechanism lets it close was not checked: the least-squares assembly \
                     runs on at most {MAX_REVIEWED_BODIES} moving bodies, and this mechanism has {moving}"
                ),
            );
        }
        return;
    }
    let free = released(m);
    let interp = Interpreter3::new(pure_newton(&free));
    let mut state = interp.initial_state();
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    // The least-squares pose is left in `state` whether or not it closes.
    let closed = interp.run(&mut state, &[], &mut ctx).is_ok();
    let size = m.size();
    let open_at: Vec<(String, f64)> = equations(&free)
        .iter()
        .map(|e| {
            let gap = e.gap(&state.poses, &[]);
            (e.origin.clone(), if e.linear() { gap } else { gap * size })
        })
        .filter(|(_, gap)| *gap > 1e-9 * size)
        .collect();
    if closed && open_at.is_empty() {
        let moved = m
            .all_markers()
            .map(|id| {
                let p = m.marker(id).at;
                norm(sub(state.poses[id.body].world(p), p))
            })
            .fold(0.0, f64::max);
        for o in open {
            add(
                o.diagnostic,
                &format!(
                    "the mechanism does assemble with {} closed, no marker moving more than {moved:.2e} from the \
                     drawing: only the drawing is off",
                    o.origin
                ),
            );
        }
    } else {
        let mut names: Vec<String> = Vec::new();
        for (origin, gap) in &open_at {
            let named = format!("{origin} (open by {gap:.1e})");
            if !names.iter().any(|n| n.starts_with(&format!("{origin} "))) {
                names.push(named);
            }
        }
        for o in open {
            add(
                o.diagnostic,
                &format!(
                    "the joints cannot all close near the drawing: at the least-squares pose these stay open, \
                     in conflict with each other: {}",
                    names.join(", ")
                ),
            );
        }
    }
}
