//! What a synthesis returns, in both dimensions: the distinct solutions,
//! each written into the mechanism's file and its error recomputed from
//! that file, and how the search went.

use std::time::Instant;

use crate::synth::search::{self, Objective, Options, Progress, Stop};

/// An error's size over the targets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// The sum of squared residuals (lengths, or degrees for function
    /// generation).
    pub sum_sq: f64,
    /// The root of the mean over targets of the squared residual norm.
    pub rms: f64,
    /// The largest residual norm of one target.
    pub max: f64,
}

/// One solution.
#[derive(Clone, Debug)]
pub struct Solution {
    /// Every parameter's value.
    pub values: Vec<f64>,
    /// Free timing: each target's input value.
    pub inputs: Option<Vec<f64>>,
    /// The error, recomputed from the written file.
    pub error: ErrorStats,
    /// The error in the search's own state (before writing).
    pub searched: ErrorStats,
    /// Free timing: whether the inputs found pass the targets in the
    /// file's order (for an angle input, once around in one sense; for a
    /// slide, monotonically).
    pub order_kept: Option<bool>,
    /// Each constraint's margin, from the written file.
    pub margins: Vec<Margin>,
    /// The mechanism file with the solution's coordinates.
    pub text: String,
}

/// What a synthesis found.
#[derive(Clone, Debug)]
pub struct Synthesis {
    /// The parameters' names (all of them, varied or not).
    pub names: Vec<String>,
    /// Which are varied.
    pub varied: Vec<usize>,
    /// The distinct solutions, best first.
    pub solutions: Vec<Solution>,
    /// Evaluations of candidates.
    pub evaluations: usize,
    /// Wall time.
    pub seconds: f64,
    /// Why the search stopped.
    pub stop: Stop,
    /// Solutions the search found whose written file did not reproduce
    /// them (left out of `solutions`), and why.
    pub rejected: Vec<String>,
}

/// A constraint's value at a solution and how far it is kept.
#[derive(Clone, Debug, PartialEq)]
pub struct Margin {
    /// "full-turn", "min-transmission", "max-ratio".
    pub name: &'static str,
    /// The measured value (full-turn: 1 when the input turns fully, else 0).
    pub value: f64,
    /// How far inside the constraint (negative: broken). Full-turn:
    /// minus the sampled frames that fail; where the input drives a
    /// four-bar at its frame, its lengths' slack (see
    /// `FourBar::turning_margin`) when every frame solves.
    pub margin: f64,
}

/// The residuals' size per target: `residuals` holds the same number of
/// residuals for each of `targets` targets.
pub fn stats(targets: usize, residuals: &[f64]) -> ErrorStats {
    let n = targets.max(1);
    let w = residuals.len() / n;
    let per: Vec<f64> = residuals
        .chunks(w.max(1))
        .map(|c| c.iter().map(|v| v * v).sum::<f64>())
        .collect();
    let sum_sq: f64 = per.iter().sum();
    ErrorStats {
        sum_sq,
        rms: (sum_sq / n as f64).sqrt(),
        max: per.iter().fold(0.0f64, |a, b| a.max(b.sqrt())),
    }
}

/// Whether `inputs` pass their targets in order: for an angle, each step
/// to the next (and from the last back to the first) turns the same way
/// and the steps add up to one turn; otherwise they only increase or only
/// decrease.
pub fn in_order(inputs: &[f64], angle: bool) -> bool {
    if inputs.len() < 2 {
        return true;
    }
    if angle {
        let around = |sign: f64| {
            let n = inputs.len();
            let total: f64 = (0..n)
                .map(|i| (sign * (inputs[(i + 1) % n] - inputs[i])).rem_euclid(360.0))
                .sum();
            (total - 360.0).abs() < 1e-6
        };
        around(1.0) || around(-1.0)
    } else {
        inputs.windows(2).all(|w| w[1] >= w[0]) || inputs.windows(2).all(|w| w[1] <= w[0])
    }
}

/// Runs the search on `problem` (whose parameters are `names`, `vary`
/// the varied ones) and keeps every solution `verify` writes into the
/// file and confirms from it, best first; the others are listed with why
/// (and if none is kept, the first reason is the error).
pub(crate) fn search_and_verify<O: Objective + ?Sized>(
    problem: &O,
    names: &[String],
    vary: &[usize],
    options: &Options,
    progress: &mut (dyn FnMut(Progress) + Send),
    verify: impl Fn(&[f64]) -> Result<Solution, String>,
) -> Result<Synthesis, String> {
    let start = Instant::now();
    let outcome = search::run(problem, options, progress);
    let (mut solutions, mut rejected) = (Vec::new(), Vec::new());
    for found in &outcome.found {
        match verify(&found.z) {
            Ok(s) => solutions.push(s),
            Err(e) => rejected.push(e),
        }
    }
    if solutions.is_empty() {
        if let Some(e) = rejected.first() {
            return Err(e.clone());
        }
    }
    solutions.sort_by(|a, b| a.error.sum_sq.total_cmp(&b.error.sum_sq));
    Ok(Synthesis {
        names: names.to_vec(),
        varied: vary.to_vec(),
        solutions,
        evaluations: outcome.evaluations,
        seconds: start.elapsed().as_secs_f64(),
        stop: outcome.stop,
        rejected,
    })
}

#[cfg(test)]
mod tests {
    use super::in_order;

    #[test]
    fn order_once_around_either_way() {
        assert!(in_order(&[10.0, 100.0, 200.0, 350.0], true));
        assert!(in_order(&[350.0, 10.0, 100.0, 200.0], true));
        assert!(in_order(&[200.0, 100.0, -10.0], true));
        assert!(!in_order(&[10.0, 200.0, 100.0, 300.0], true));
        assert!(in_order(&[1.0, 2.0, 3.0], false));
        assert!(!in_order(&[1.0, 3.0, 2.0], false));
    }
}
