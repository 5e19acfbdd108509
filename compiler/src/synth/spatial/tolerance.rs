//! How far tolerances on the dimensions move a marker in space: the exact
//! worst case of the first-order deviation, and its Monte-Carlo
//! counterpart on perturbed candidates (as `synth/planar/tolerance.rs`).

use dofplan_runtime::{Driver, Options};

use super::{Candidate, Design};
use crate::model::MarkerId;
use crate::synth::tolerance::{spread, Paths, Spread};
use crate::synth::SynthError;

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `|Σ t·s_k·d_k|` for the signs `sign(k)` (±1).
fn corner(d: &[[f64; 3]], t: f64, sign: impl Fn(usize) -> f64) -> f64 {
    let mut sum = [0.0; 3];
    for (k, v) in d.iter().enumerate() {
        let s = t * sign(k);
        sum = [sum[0] + s * v[0], sum[1] + s * v[1], sum[2] + s * v[2]];
    }
    dot(sum, sum).sqrt()
}

/// The largest `|Σ δ_k d_k|` over every `δ` with `|δ_k| ≤ t`: the
/// worst-case first-order deviation of a point whose derivatives with
/// respect to the parameters are `d`. Exact: the farthest point of the
/// box's image (a zonotope) is one of its vertices, the corner
/// `δ_k = t·sign(u·d_k)` for a direction `u` inside one cell of the
/// arrangement of the planes perpendicular to the `d_k`. Every cell has a
/// corner where two of those planes meet, along `±(d_i × d_j)`; around
/// it, the signs of the derivatives off the plane of `d_i` and `d_j` are
/// fixed, and those in it take the signs of the sectors around the
/// corner (as in the plane, `synth/planar/tolerance.rs`). So P² corners
/// of the arrangement with at most 2P cells each, not 2^P corners of the
/// box. Derivatives all on one line reduce to `t Σ |d_k|`.
pub fn worst_case(d: &[[f64; 3]], t: f64) -> f64 {
    let d: Vec<[f64; 3]> = d.iter().copied().filter(|v| dot(*v, *v) > 0.0).collect();
    let norm = |v: [f64; 3]| dot(v, v).sqrt();
    // Along the line of every derivative, all signs agree with it.
    let mut best = match d.first() {
        Some(&u) => corner(&d, t, |k| dot(u, d[k]).signum()),
        None => return 0.0,
    };
    for i in 0..d.len() {
        for j in i + 1..d.len() {
            let u = cross(d[i], d[j]);
            // Parallel derivatives meet in no corner of their own.
            if norm(u) <= 1e-12 * norm(d[i]) * norm(d[j]) {
                continue;
            }
            let u = u.map(|x| x / norm(u));
            let e1 = d[i].map(|x| x / norm(d[i]));
            let e2 = cross(u, e1);
            let side: Vec<f64> = d.iter().map(|v| dot(u, *v)).collect();
            let in_plane: Vec<usize> = (0..d.len())
                .filter(|&k| side[k].abs() <= 1e-12 * norm(d[k]))
                .collect();
            // The sectors around the corner, in the plane: cut where a
            // direction turns perpendicular to an in-plane derivative.
            let mut cuts: Vec<f64> = Vec::with_capacity(2 * in_plane.len());
            for &k in &in_plane {
                let a = dot(d[k], e2).atan2(dot(d[k], e1)) + std::f64::consts::FRAC_PI_2;
                cuts.push(a.rem_euclid(std::f64::consts::TAU));
                cuts.push((a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU));
            }
            cuts.sort_by(f64::total_cmp);
            for (c, &a) in cuts.iter().enumerate() {
                let b = cuts
                    .get(c + 1)
                    .copied()
                    .unwrap_or(cuts[0] + std::f64::consts::TAU);
                let mid = 0.5 * (a + b);
                let w = [0, 1, 2].map(|x| mid.cos() * e1[x] + mid.sin() * e2[x]);
                for up in [1.0, -1.0] {
                    let sign = |k: usize| {
                        if in_plane.contains(&k) {
                            dot(w, d[k]).signum()
                        } else {
                            up * side[k].signum()
                        }
                    };
                    best = best.max(corner(&d, t, sign));
                }
            }
        }
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
    nominal: &Paths<3>,
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
) -> Result<Paths<3>, SynthError> {
    let drawn = design.prepare(&design.drawn())?;
    Ok(run(&drawn, requested, markers))
}

/// The paths of `markers` over `requested` of the candidate drawn at `p`,
/// or `None` if it cannot be planned. Positions only: a candidate planned
/// differently from the drawing (its special geometry perturbed away)
/// counts as well.
pub fn paths(design: &Design, requested: &[Vec<f64>], markers: &[MarkerId], p: &[f64]) -> Option<Paths<3>> {
    let c = design.prepare_any(p).ok()?;
    Some(run(&c, requested, markers))
}

/// A candidate driven frame after frame from its drawing.
fn run(c: &Candidate, requested: &[Vec<f64>], markers: &[MarkerId]) -> Paths<3> {
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
