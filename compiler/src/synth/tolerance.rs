//! What tolerances on the dimensions do, in both dimensions: the
//! Monte-Carlo spread of perturbed candidates around the nominal paths.
//! Each dimension has its exact worst case and runs its own candidates
//! (`synth/planar/tolerance.rs`, `synth/spatial/tolerance.rs`).
//!
//! A run is three steps, public so a study can spread the middle one over
//! processes or machines and still give the single run's numbers to the
//! bit: [`draws`] (the candidates a seed gives), [`worst`] (one
//! candidate's largest deviation per marker) and [`Spread::of`] (the
//! summary, candidates in draw order).

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

/// A candidate's markers, frame by frame: `None` where the frame does not
/// solve.
pub type Paths<const N: usize> = Vec<Option<Vec<[f64; N]>>>;

/// The `n` candidates a seed gives: every parameter uniform within `±t`
/// of `drawn`, drawn in order from one generator (the same seed, the same
/// candidates, on any machine).
pub fn draws(drawn: &[f64], (n, t, seed): (usize, f64, u64)) -> Vec<Vec<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    (0..n)
        .map(|_| drawn.iter().map(|v| v + rng.random_range(-t..=t)).collect())
        .collect()
}

/// One candidate's largest deviation from `nominal[frame][marker]` per
/// marker over the frames the drawing reaches (`None` there: not
/// compared), or `None` if the candidate broke at one of them.
pub fn worst<const N: usize>(frames: &Paths<N>, nominal: &Paths<N>) -> Option<Vec<f64>> {
    let markers = nominal.iter().flatten().map(Vec::len).next().unwrap_or(0);
    let mut worst = vec![0.0f64; markers];
    for (frame, nominal) in frames.iter().zip(nominal) {
        let Some(nominal) = nominal else { continue };
        let frame = frame.as_ref()?;
        for (k, (w, at)) in frame.iter().zip(nominal).enumerate() {
            // By hypot, as the plane always measured it (the same last bit).
            let d = (0..N).fold(0.0, |s: f64, a| s.hypot(w[a] - at[a]));
            worst[k] = worst[k].max(d);
        }
    }
    Some(worst)
}

impl Spread {
    /// The summary of candidates' [`worst`] deviations, in draw order
    /// (`None`: a candidate that failed), over `markers` markers.
    pub fn of(markers: usize, candidates: impl IntoIterator<Item = Option<Vec<f64>>>) -> Spread {
        let (mut n, mut failed) = (0, 0);
        let (mut largest, mut sum) = (vec![0.0f64; markers], vec![0.0; markers]);
        for worst in candidates {
            n += 1;
            let Some(worst) = worst else {
                failed += 1;
                continue;
            };
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
}

/// Draws `n` candidates whose parameters are each uniform within `±t` of
/// `drawn` ([`draws`]), runs each with `run` (its markers' paths; `None`
/// for a candidate that cannot be planned) and measures how far the
/// markers stray from `nominal` ([`worst`], [`Spread::of`]).
pub fn spread<const N: usize>(
    drawn: &[f64],
    nominal: &Paths<N>,
    (n, t, seed): (usize, f64, u64),
    mut run: impl FnMut(&[f64]) -> Option<Paths<N>>,
) -> Spread {
    let markers = nominal.iter().flatten().map(Vec::len).next().unwrap_or(0);
    let candidates = draws(drawn, (n, t, seed));
    Spread::of(
        markers,
        (candidates.iter()).map(|p| run(p).and_then(|frames| worst(&frames, nominal))),
    )
}
