//! `dofplan analyze --sensitivity`: how each traced marker's path depends
//! on every design parameter over the sweep (exact derivatives,
//! [`crate::synth::planar::sensitivity`]), the parameters ranked by their
//! largest effect, and with a tolerance the worst-case first-order
//! deviation of each traced marker beside a Monte-Carlo spread.

use std::io::Write;

use dofplan_runtime::{Driver, Options};
use serde_json::{json, Map, Value};

use crate::format::{length, number, rounded};
use crate::model::{Input, InputKind, Mechanism, Sweep};
use crate::plan::num;
use crate::report::{Form, Outcome};
use crate::simulate::sweep_requests;
use crate::synth::planar::{monte_carlo, sensitivity, worst_case, Design, Spread};
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
struct Gathered {
    requested: Vec<Vec<f64>>,
    /// `peaks[traced][parameter]`.
    peaks: Vec<Vec<Peak>>,
    /// Per traced marker, the worst-case deviation under the tolerance.
    worst: Vec<Peak>,
    /// Per frame, the traced markers' nominal positions.
    nominal: Vec<Option<Vec<[f64; 2]>>>,
    /// Every frame's derivatives (JSON only).
    frames: Vec<Value>,
    /// Frames without derivatives, and why.
    missing: Vec<(usize, String)>,
    frames_with_derivatives: usize,
}

/// Runs the study over `sweep` and prints it in `form` (text or JSON).
pub fn run(m: &Mechanism, sweep: &Sweep, study: Study, form: Form, out: &mut dyn Write) -> Outcome {
    if sweep.trace.is_empty() {
        return Ok(Err(format!(
            "{}: error: the sweep traces no marker, so there is no path to study; add trace = [\"body.marker\"] to [sweep]",
            m.source.name
        )));
    }
    let design = match Design::new(m) {
        Ok(d) => d,
        Err(e) => return Ok(Err(format!("{}: error: {e}", m.source.name))),
    };
    let g = match gather(m, &design, sweep, study, form) {
        Ok(g) => g,
        Err(e) => return Ok(Err(format!("{}: error: {e}", m.source.name))),
    };
    let spread = match (study.tolerance, study.monte_carlo) {
        (Some(t), Some(n)) => Some(monte_carlo(
            &design,
            &g.requested,
            &sweep.trace,
            &g.nominal,
            (n, t, study.seed),
        )),
        _ => None,
    };
    match form {
        Form::Json => write_json(m, &design, sweep, study, g, spread.as_ref(), out)?,
        Form::Text | Form::Csv => write_text(m, &design, sweep, study, &g, spread.as_ref(), out)?,
    }
    Ok(Ok(()))
}

/// Runs the sweep and differentiates every solved frame.
fn gather(
    m: &Mechanism,
    design: &Design,
    sweep: &Sweep,
    study: Study,
    form: Form,
) -> Result<Gathered, SynthError> {
    let base = design.prepare(&design.drawn())?;
    let (names, traced) = (design.names(), &sweep.trace);
    let mut g = Gathered {
        requested: sweep_requests(sweep, m.inputs.len()).collect(),
        peaks: vec![vec![Peak::default(); names.len()]; traced.len()],
        worst: vec![Peak::default(); traced.len()],
        nominal: Vec::new(),
        frames: Vec::new(),
        missing: Vec::new(),
        frames_with_derivatives: 0,
    };
    let mut driver = Driver::new(base.interpreter.clone(), Options::default());
    for (f, inputs) in g.requested.iter().enumerate() {
        if !driver.frame(inputs).is_solved() {
            g.nominal.push(None);
            g.missing.push((f, "not solved".into()));
            continue;
        }
        let poses = driver.poses();
        g.nominal.push(Some(
            traced
                .iter()
                .map(|id| poses[id.body].world(m.marker(*id).at))
                .collect(),
        ));
        let s = match sensitivity(design, &base, poses, inputs) {
            Ok(s) => s,
            Err(e @ SynthError::Underconstrained { .. }) => return Err(e),
            Err(e) => {
                g.missing.push((f, e.to_string()));
                continue;
            }
        };
        let mut markers = Map::new();
        let first = g.frames_with_derivatives == 0;
        g.frames_with_derivatives += 1;
        for (t, id) in traced.iter().enumerate() {
            let d = s.marker(*id);
            for (k, dk) in d.iter().enumerate() {
                g.peaks[t][k].add(dk[0].hypot(dk[1]), f, first);
            }
            if let Some(tol) = study.tolerance {
                let w = worst_case(&d, tol);
                g.worst[t].add(w, f, first);
            }
            if form == Form::Json {
                let per: Map<String, Value> =
                    names.iter().zip(&d).map(|(n, v)| (n.clone(), json!(v))).collect();
                markers.insert(m.marker_name(*id), Value::Object(per));
            }
        }
        if form == Form::Json {
            g.frames.push(
                json!({ "frame": f, "inputs": inputs, "conditioning": s.conditioning, "markers": markers }),
            );
        }
    }
    Ok(g)
}

/// The parameters from the largest effect on any traced marker down:
/// (parameter, traced marker, its peak).
fn ranking(g: &Gathered, parameters: usize) -> Vec<(usize, usize, Peak)> {
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

fn write_json(
    m: &Mechanism,
    design: &Design,
    sweep: &Sweep,
    study: Study,
    g: Gathered,
    spread: Option<&Spread>,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let (names, traced) = (design.names(), &sweep.trace);
    let ranked: Vec<Value> = (ranking(&g, names.len()).iter())
        .map(|(k, t, p)| json!({ "parameter": names[*k], "largest": p.value, "marker": m.marker_name(traced[*t]), "frame": p.frame }))
        .collect();
    let parameters: Vec<Value> = (names.iter().zip(design.drawn()))
        .map(|(n, v)| json!({ "name": n, "drawn": v }))
        .collect();
    let mut doc = json!({
        "mechanism": m.name,
        "parameters": parameters,
        "traced": traced.iter().map(|id| m.marker_name(*id)).collect::<Vec<_>>(),
        "ranking": ranked,
        "frames_without_derivatives": g.missing.iter().map(|(f, why)| json!({ "frame": f, "reason": why })).collect::<Vec<_>>(),
        "frames": g.frames,
    });
    if let Some(t) = study.tolerance {
        let per: Map<String, Value> = (traced.iter().zip(&g.worst))
            .map(|(id, w)| {
                (
                    m.marker_name(*id),
                    json!({ "worst_case": w.value, "frame": w.frame }),
                )
            })
            .collect();
        doc["tolerance"] = json!({ "value": t, "markers": per });
    }
    if let Some(s) = spread {
        let per: Map<String, Value> = (traced.iter().enumerate())
            .map(|(k, id)| {
                (
                    m.marker_name(*id),
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

fn write_text(
    m: &Mechanism,
    design: &Design,
    sweep: &Sweep,
    study: Study,
    g: &Gathered,
    spread: Option<&Spread>,
    out: &mut dyn Write,
) -> std::io::Result<()> {
    let (names, traced) = (design.names(), &sweep.trace);
    let primary = &m.inputs[sweep.primary().input];
    let at = |f: usize| at_input(primary, g.requested[f][sweep.primary().input]);
    let traced_names: Vec<String> = traced.iter().map(|id| m.marker_name(*id)).collect();
    writeln!(
        out,
        "{}: sensitivity of {} to {} design parameters over {} frames ({} with derivatives)",
        m.name,
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

/// "theta = 30°": where a frame is, by the swept input's value.
fn at_input(input: &Input, x: f64) -> String {
    let unit = if input.kind == InputKind::Angle { "°" } else { "" };
    format!("{} = {}{unit}", input.name, num(x))
}
