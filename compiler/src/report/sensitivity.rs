//! `dofplan analyze --sensitivity`, what both dimensions share: the
//! study's options, the sweep's frames gathered into each traced marker's
//! largest derivative per parameter and worst case, the parameters ranked
//! by their largest effect, and the report as text or JSON. Each
//! dimension runs its own frames and derivatives
//! (`report/planar/sensitivity.rs`, `report/spatial/sensitivity.rs`).

use std::io::Write;

use serde_json::{json, Map, Value};

use super::at_input;
use crate::format::{length, number, rounded};
use crate::model::Input;
use crate::report::Form;
use crate::synth::tolerance::Spread;
use crate::synth::SynthError;

/// What `--sensitivity` is asked besides the derivatives.
#[derive(Clone, Copy, Debug, Default)]
pub struct Study {
    /// `--tolerance T`: every parameter may be off by ±T (length units).
    pub tolerance: Option<f64>,
    /// `--monte-carlo N`: perturbed candidates to run (needs a tolerance).
    pub monte_carlo: Option<usize>,
    /// `--seed`: the Monte-Carlo candidates' seed.
    pub seed: u64,
}

/// One traced marker's largest derivative with respect to one parameter.
#[derive(Clone, Copy, Debug, Default)]
struct Peak {
    value: f64,
    frame: usize,
    /// The smallest value over the frames: a peak no larger than it (to
    /// rounding) is the same everywhere, found at no frame in particular.
    least: f64,
}

impl Peak {
    fn add(&mut self, value: f64, frame: usize, first: bool) {
        if value > self.value {
            (self.value, self.frame) = (value, frame);
        }
        self.least = if first { value } else { self.least.min(value) };
    }

    fn constant(&self) -> bool {
        self.value - self.least <= 1e-9 * self.value
    }
}

/// What the sweep gave: per traced marker its peaks and worst case, the
/// nominal paths, and the frames without derivatives.
pub(crate) struct Gathered<const N: usize> {
    pub requested: Vec<Vec<f64>>,
    /// `peaks[traced][parameter]`.
    peaks: Vec<Vec<Peak>>,
    /// Per traced marker, the worst-case deviation under the tolerance.
    worst: Vec<Peak>,
    /// Per frame, the traced markers' nominal positions.
    pub nominal: Vec<Option<Vec<[f64; N]>>>,
    /// Every frame's derivatives (JSON only).
    frames: Vec<Value>,
    /// Frames without derivatives, and why.
    missing: Vec<(usize, String)>,
    frames_with_derivatives: usize,
}

/// What a dimension gives for one frame: `None` where it does not solve;
/// else the traced markers' positions and either their derivatives
/// (`[marker][parameter]`) with the equations' conditioning, or why there
/// are none.
pub(crate) type Frame<const N: usize> =
    Option<(Vec<[f64; N]>, Result<(Vec<Vec<[f64; N]>>, f64), SynthError>)>;

/// The names a report prints: the mechanism, the traced markers, the
/// parameters (with their drawn values) and the swept input.
pub(crate) struct Subject<'a> {
    pub mechanism: &'a str,
    pub traced: Vec<String>,
    pub parameters: &'a [String],
    pub drawn: Vec<f64>,
    pub primary: &'a Input,
    pub primary_index: usize,
}

/// The error for a sweep that traces no marker: there is no path to study.
pub fn untraced(file: &str) -> String {
    format!(
        "{file}: error: the sweep traces no marker, so there is no path to study; add trace = [\"body.marker\"] to [sweep]"
    )
}

/// Runs `frame` at every requested frame and gathers the derivatives;
/// `worst_case` is the dimension's exact worst case under a tolerance. An
/// under-constrained mechanism (its poses depend on the path) is an
/// error; any other frame without derivatives is listed.
pub(crate) fn gather<const N: usize>(
    subject: &Subject,
    requested: Vec<Vec<f64>>,
    study: Study,
    form: Form,
    worst_case: fn(&[[f64; N]], f64) -> f64,
    mut frame: impl FnMut(&[f64]) -> Frame<N>,
) -> Result<Gathered<N>, SynthError> {
    let (names, traced) = (subject.parameters, &subject.traced);
    let mut g = Gathered {
        requested,
        peaks: vec![vec![Peak::default(); names.len()]; traced.len()],
        worst: vec![Peak::default(); traced.len()],
        nominal: Vec::new(),
        frames: Vec::new(),
        missing: Vec::new(),
        frames_with_derivatives: 0,
    };
    for f in 0..g.requested.len() {
        let Some((at, derivatives)) = frame(&g.requested[f]) else {
            g.nominal.push(None);
            g.missing.push((f, "not solved".into()));
            continue;
        };
        g.nominal.push(Some(at));
        let (d, conditioning) = match derivatives {
            Ok(d) => d,
            Err(e @ SynthError::Underconstrained { .. }) => return Err(e),
            Err(e) => {
                g.missing.push((f, e.to_string()));
                continue;
            }
        };
        let mut markers = Map::new();
        let first = g.frames_with_derivatives == 0;
        g.frames_with_derivatives += 1;
        for (t, d) in d.iter().enumerate() {
            for (k, dk) in d.iter().enumerate() {
                // By hypot, as the plane always measured it (the same last bit).
                g.peaks[t][k].add(dk.iter().fold(0.0, |a: f64, &x| a.hypot(x)), f, first);
            }
            if let Some(tol) = study.tolerance {
                g.worst[t].add(worst_case(d, tol), f, first);
            }
            if form == Form::Json {
                let per: Map<String, Value> = names
                    .iter()
                    .zip(d)
                    .map(|(n, v)| (n.clone(), json!(v.as_slice())))
                    .collect();
                markers.insert(traced[t].clone(), Value::Object(per));
            }
        }
        if form == Form::Json {
            let inputs = &g.requested[f];
            g.frames.push(
                json!({ "frame": f, "inputs": inputs, "conditioning": conditioning, "markers": markers }),
            );
        }
    }
    Ok(g)
}

/// Prints the study in `form` (text or JSON).
pub(crate) fn write<const N: usize>(
    subject: &Subject,
    study: Study,
    g: Gathered<N>,
    spread: Option<&Spread>,
    form: Form,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    match form {
        Form::Json => write_json(subject, study, g, spread, out),
        Form::Text | Form::Csv => write_text(subject, study, &g, spread, out),
    }
}

/// The parameters from the largest effect on any traced marker down:
/// (parameter, traced marker, its peak).
fn ranking<const N: usize>(g: &Gathered<N>, parameters: usize) -> Vec<(usize, usize, Peak)> {
    let mut ranked: Vec<(usize, usize, Peak)> = (0..parameters)
        .map(|k| {
            let (t, p) = (0..g.peaks.len())
                .map(|t| (t, g.peaks[t][k]))
                .fold(
                    (0, Peak::default()),
                    |a, b| {
                        if b.1.value > a.1.value {
                            b
                        } else {
                            a
                        }
                    },
                );
            (k, t, p)
        })
        .collect();
    ranked.sort_by(|a, b| b.2.value.total_cmp(&a.2.value).then(a.0.cmp(&b.0)));
    ranked
}

fn write_json<const N: usize>(
    subject: &Subject,
    study: Study,
    g: Gathered<N>,
    spread: Option<&Spread>,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let (names, traced) = (subject.parameters, &subject.traced);
    let ranked: Vec<Value> = (ranking(&g, names.len()).iter())
        .map(|(k, t, p)| json!({ "parameter": names[*k], "largest": p.value, "marker": traced[*t], "frame": p.frame }))
        .collect();
    let parameters: Vec<Value> = (names.iter().zip(&subject.drawn))
        .map(|(n, v)| json!({ "name": n, "drawn": v }))
        .collect();
    let mut doc = json!({
        "mechanism": subject.mechanism,
        "parameters": parameters,
        "traced": traced,
        "ranking": ranked,
        "frames_without_derivatives": g.missing.iter().map(|(f, why)| json!({ "frame": f, "reason": why })).collect::<Vec<_>>(),
        "frames": g.frames,
    });
    if let Some(t) = study.tolerance {
        let per: Map<String, Value> = (traced.iter().zip(&g.worst))
            .map(|(name, w)| (name.clone(), json!({ "worst_case": w.value, "frame": w.frame })))
            .collect();
        doc["tolerance"] = json!({ "value": t, "markers": per });
    }
    if let Some(s) = spread {
        let per: Map<String, Value> = (traced.iter().enumerate())
            .map(|(k, name)| {
                (
                    name.clone(),
                    json!({ "largest": s.largest[k], "mean": s.mean[k] }),
                )
            })
            .collect();
        doc["monte_carlo"] =
            json!({ "candidates": s.candidates, "failed": s.failed, "seed": study.seed, "markers": per });
    }
    writeln!(
        out,
        "{}",
        serde_json::to_string_pretty(&doc).expect("JSON of plain values")
    )
}

fn write_text<const N: usize>(
    subject: &Subject,
    study: Study,
    g: &Gathered<N>,
    spread: Option<&Spread>,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let names = subject.parameters;
    let at = |f: usize| at_input(subject.primary, g.requested[f][subject.primary_index]);
    let traced_names = &subject.traced;
    writeln!(
        out,
        "{}: sensitivity of {} to {} design parameters over {} frames ({} with derivatives)",
        subject.mechanism,
        traced_names.join(", "),
        names.len(),
        g.requested.len(),
        g.requested.len() - g.missing.len()
    )?;
    writeln!(
        out,
        "parameters by largest effect |d marker / d parameter| (length per length):"
    )?;
    let width = names.iter().map(String::len).max().unwrap_or(0);
    for (k, t, p) in ranking(g, names.len()) {
        let place = if p.value == 0.0 {
            "  (no effect on a traced marker)".to_string()
        } else if p.constant() {
            format!("  {} (the same at every frame)", traced_names[t])
        } else {
            format!("  {} at {}", traced_names[t], at(p.frame))
        };
        writeln!(out, "  {:<width$}  {:>7}{place}", names[k], rounded(p.value, 4))?;
    }
    if let Some(t) = study.tolerance {
        writeln!(
            out,
            "every parameter within ±{}: worst-case first-order deviation",
            number(t)
        )?;
        for (k, w) in g.worst.iter().enumerate() {
            let mc = spread.map_or(String::new(), |s| {
                let ran = s.candidates - s.failed;
                let (largest, mean) = (length(s.largest[k]), length(s.mean[k]));
                format!(
                    "; Monte-Carlo ({ran} candidates, seed {}): largest {largest}, mean {mean}",
                    study.seed
                )
            });
            writeln!(
                out,
                "  {}  {} at {}{mc}",
                traced_names[k],
                length(w.value),
                at(w.frame)
            )?;
        }
        if let Some(s) = spread.filter(|s| s.failed > 0) {
            writeln!(
                out,
                "  {} of {} perturbed candidates did not run the sweep (not planned, or broke where the drawing does not)",
                s.failed, s.candidates
            )?;
        }
    }
    for (f, why) in g.missing.iter().take(5) {
        writeln!(out, "no derivatives at {}: {why}", at(*f))?;
    }
    if g.missing.len() > 5 {
        writeln!(
            out,
            "… and {} more frames without derivatives",
            g.missing.len() - 5
        )?;
    }
    Ok(())
}
