//! What tolerances on the dimensions do, in both dimensions: the
//! Monte-Carlo spread of perturbed candidates around the nominal paths.
//! Each dimension has its exact worst case and runs its own candidates
//! (`synth/planar/tolerance.rs`, `synth/spatial/tolerance.rs`).

use rand::{Rng, SeedableRng};

/// What a Monte-Carlo run found.
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

/// Draws `n` candidates whose parameters are each uniform within `±t` of
/// `drawn` (seeded: the same seed gives the same candidates), runs each
/// with `run` (per frame the markers' positions, `None` where the frame
/// does not solve; `None` overall for a candidate that cannot be planned)
/// and measures how far the markers stray from `nominal[frame][marker]`
/// (`None` where the drawing does not reach the frame: not compared).
pub fn spread<const N: usize>(
    drawn: &[f64],
    nominal: &[Option<Vec<[f64; N]>>],
    (n, t, seed): (usize, f64, u64),
    mut run: impl FnMut(&[f64]) -> Option<Vec<Option<Vec<[f64; N]>>>>,
) -> Spread {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let markers = nominal.iter().flatten().map(Vec::len).next().unwrap_or(0);
    let (mut failed, mut largest, mut sum) = (0, vec![0.0f64; markers], vec![0.0; markers]);
    for _ in 0..n {
        let p: Vec<f64> = drawn.iter().map(|v| v + rng.random_range(-t..=t)).collect();
        let Some(frames) = run(&p) else {
            failed += 1;
            continue;
        };
        let mut worst = vec![0.0f64; markers];
        let mut broke = false;
        for (frame, nominal) in frames.iter().zip(nominal) {
            let Some(nominal) = nominal else { continue };
            let Some(frame) = frame else {
                broke = true;
                break;
            };
            for (k, (w, at)) in frame.iter().zip(nominal).enumerate() {
                // By hypot, as the plane always measured it (the same last bit).
                let d = (0..N).fold(0.0, |s: f64, a| s.hypot(w[a] - at[a]));
                worst[k] = worst[k].max(d);
            }
        }
        if broke {
            failed += 1;
            continue;
        }
        for k in 0..markers {
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
