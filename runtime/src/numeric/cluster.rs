//! What the numeric clusters of both dimensions share: a cluster's Newton
//! options for a mechanism of a given size, and how its solve is reported
//! to the frame. The planar cluster step is `planar::cluster`, the spatial
//! one `spatial::cluster`.

use super::{NewtonOptions, NewtonOutcome, NewtonReport};
use crate::frame::{Break, BreakKind, Ctx, StepId};

/// The Newton options of a cluster of a mechanism of this size: a tolerance
/// relative to the size, and steps of at most a quarter of it (so a frame
/// does not jump to another assembly branch).
pub const fn options(size: f64) -> NewtonOptions {
    NewtonOptions {
        max_iterations: 50,
        tolerance: 1e-12 * size,
        rank_cutoff: 1e-10,
        max_step: 0.25 * size,
    }
}

/// Reports a cluster's solve through `ctx`: its Newton report, and a break
/// (or, under the stretch policy, a relaxation) when it did not converge.
pub fn finish(ctx: &mut Ctx, step: StepId, report: NewtonReport) -> Result<(), Break> {
    ctx.numeric = Some(report);
    match report.outcome {
        NewtonOutcome::Converged => Ok(()),
        NewtonOutcome::NoSolution => ctx.fail(step, BreakKind::NoSolution, report.residual),
        NewtonOutcome::NotConverged => ctx.fail(step, BreakKind::NotConverged, report.residual),
    }
}
