//! How far tolerances on the dimensions move a marker: the exact
//! worst case of the first-order deviation, and its Monte-Carlo
//! counterpart on perturbed candidates.

use dofplan_runtime::{Driver, Options};

use super::{Candidate, Design};
use crate::model::MarkerId;
use crate::synth::tolerance::{spread, Paths, Spread};
use crate::synth::SynthError;

/// The largest `|Σ δ_k d_k|` over every `δ` with `|δ_k| ≤ t`: the
/// worst-case first-order deviation of a point whose derivatives with
/// respect to the parameters are `d`. Exact: the maximum of a convex
/// function over the box is at a corner, and the corner for the direction
/// `u` is `δ_k = t·sign(u·d_k)`, which changes only where `u` crosses a
/// perpendicular of some `d_k` — so one corner per sector between those
/// crossings is enough (2P of them, not 2^P).
pub fn worst_case(d: &[[f64; 2]], t: f64) -> f64 {
    let mut cuts: Vec<f64> = Vec::with_capacity(2 * d.len());
    for v in d.iter().filter(|v| v[0] != 0.0 || v[1] != 0.0) {
        let a = v[1].atan2(v[0]) + std::f64::consts::FRAC_PI_2;
        cuts.push(a.rem_euclid(std::f64::consts::TAU));
        cuts.push((a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU));
    }
    if cuts.is_empty() {
        return 0.0;
    }
    cuts.sort_by(f64::total_cmp);
    let mut best = 0.0f64;
    for (i, &a) in cuts.iter().enumerate() {
        let b = cuts
            .get(i + 1)
            .copied()
            .unwrap_or(cuts[0] + std::f64::consts::TAU);
        let mid = 0.5 * (a + b);
        let u = [mid.cos(), mid.sin()];
        let mut sum = [0.0; 2];
        for v in d {
            let s = if u[0] * v[0] + u[1] * v[1] >= 0.0 { t } else { -t };
            sum = [sum[0] + s * v[0], sum[1] + s * v[1]];
        }
        best = best.max(sum[0].hypot(sum[1]));
    }
    best
}

/// Runs `n` candidates whose parameters are each drawn uniformly within
/// `±t` of the drawing (seeded: the same seed gives the same candidates)
/// over `requested`, and measures how far `markers` stray from their
/// nominal paths `nominal[frame][marker]` (`None` where the drawing does
/// not reach the frame).
pub fn monte_carlo(
    design: &Design,
    requested: &[Vec<f64>],
    markers: &[MarkerId],
    nominal: &Paths<2>,
    (n, t, seed): (usize, f64, u64),
) -> Spread {
    spread(&design.drawn(), nominal, (n, t, seed), |p| {
        paths(design, requested, markers, p)
    })
}

/// The drawing's own paths of `markers` over `requested`: what candidates
/// are measured against (`None` where the drawing does not reach a frame).
pub fn nominal(
    design: &Design,
    requested: &[Vec<f64>],
    markers: &[MarkerId],
) -> Result<Paths<2>, SynthError> {
    let drawn = design.prepare(&design.drawn())?;
    Ok(run(&drawn, requested, markers))
}

/// The paths of `markers` over `requested` of the candidate drawn at `p`,
/// or `None` if it cannot be planned. Positions only: a candidate planned
/// differently from the drawing (its special geometry perturbed away)
/// counts as well.
pub fn paths(design: &Design, requested: &[Vec<f64>], markers: &[MarkerId], p: &[f64]) -> Option<Paths<2>> {
    let c = design.prepare_any(p).ok()?;
    Some(run(&c, requested, markers))
}

/// A candidate driven frame after frame from its drawing.
fn run(c: &Candidate, requested: &[Vec<f64>], markers: &[MarkerId]) -> Paths<2> {
    let mut driver = Driver::new(&c.interpreter, Options::default());
    (requested.iter())
        .map(|inputs| {
            let solved = driver.frame(inputs).is_solved();
            solved.then(|| {
                let at = |id: &MarkerId| driver.poses()[id.body].world(c.mechanism.marker(*id).at);
                markers.iter().map(at).collect()
            })
        })
        .collect()
}
