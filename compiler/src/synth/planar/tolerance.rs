//! How far tolerances on the dimensions move a marker: the exact
//! worst case of the first-order deviation, and its Monte-Carlo
//! counterpart on perturbed candidates.

use dofplan_runtime::{Driver, Options};
use rand::{Rng, SeedableRng};

use super::Design;
use crate::model::MarkerId;

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

/// What [`monte_carlo`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Spread {
    /// Candidates drawn.
    pub candidates: usize,
    /// Candidates that could not be planned, or broke at a frame the
    /// drawing reaches.
    pub failed: usize,
    /// Per marker: the largest deviation from the nominal path over every
    /// frame and every candidate that ran.
    pub largest: Vec<f64>,
    /// Per marker: the mean over candidates of each one's largest deviation.
    pub mean: Vec<f64>,
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
    nominal: &[Option<Vec<[f64; 2]>>],
    (n, t, seed): (usize, f64, u64),
) -> Spread {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let drawn = design.drawn();
    let (mut failed, mut largest, mut sum) = (0, vec![0.0f64; markers.len()], vec![0.0; markers.len()]);
    for _ in 0..n {
        let p: Vec<f64> = drawn.iter().map(|v| v + rng.random_range(-t..=t)).collect();
        let Ok(c) = design.prepare(&p) else {
            failed += 1;
            continue;
        };
        let mut driver = Driver::new(c.interpreter.clone(), Options::default());
        let mut worst = vec![0.0f64; markers.len()];
        let mut broke = false;
        for (inputs, nominal) in requested.iter().zip(nominal) {
            let solved = driver.frame(inputs).is_solved();
            let Some(nominal) = nominal else { continue };
            if !solved {
                broke = true;
                break;
            }
            for (k, id) in markers.iter().enumerate() {
                let w = driver.poses()[id.body].world(c.mechanism.marker(*id).at);
                worst[k] = worst[k].max((w[0] - nominal[k][0]).hypot(w[1] - nominal[k][1]));
            }
        }
        if broke {
            failed += 1;
            continue;
        }
        for k in 0..markers.len() {
            largest[k] = largest[k].max(worst[k]);
            sum[k] += worst[k];
        }
    }
    let ran = (n - failed).max(1) as f64;
    Spread {
        candidates: n,
        failed,
        largest,
        mean: sum.iter().map(|s| s / ran).collect(),
    }
}
