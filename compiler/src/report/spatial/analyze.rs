//! `dofplan analyze` of a spatial (`dimension = 3`) file: the sweep with
//! every marker's velocity and acceleration and every body's angular
//! velocity and acceleration vectors — exact, by forward-mode
//! differentiation through the plan ([`Interpreter::rates`]) — printed as
//! a summary, JSON or CSV (streamed frame by frame), and drawn as plots.
//! The transmission angle is a planar four-bar notion and is not given.
//!
//! A plan whose rates are not computed (a numeric cluster, for now) still
//! runs: its positions are written with the rates null (JSON) or empty
//! (CSV) and the reason said once, as a dead point's are.

use std::io::Write;
use std::path::Path;

use crate::format::number;
use crate::interp::spatial::Interpreter;
use crate::model::spatial::Mechanism;
use crate::model::{Input, InputKind, Sweep};
use crate::plan::spatial::Plan;
use crate::render::plots::{draw_spatial, Sample3, Traced3};
use crate::simulate::input_rates;
use crate::simulate::spatial::{marker_positions, motion, residual, Motion};
use crate::simulate::sweep_requests;
use dofplan_runtime::real::RateError;
use dofplan_runtime::{Driver, Options};
use serde_json::{json, Map, Value};

use super::frames::frame_value;
use crate::report::rates::{at_input, extremes, header, rate_keys, rate_text};
use crate::report::{Form, FrameProgress, Outcome};

/// Runs `analyze` on a spatial plan: the sweep with rates at `rate`
/// (radians or length units per second for the sweep's first input), in
/// `form`, with plots in `svg`.
#[allow(clippy::too_many_arguments)]
pub fn analyze(
    m: &Mechanism,
    plan: &Plan,
    sweep: &Sweep,
    rate: f64,
    form: Form,
    svg: Option<&Path>,
    progress: &mut dyn FrameProgress,
    out: &mut dyn Write,
) -> Outcome {
    let interp = Interpreter::new(plan.clone());
    let mut driver = Driver::new(interp.clone(), Options::default());
    let rates = input_rates(&m.inputs, sweep, rate);
    let zero = vec![0.0; m.inputs.len()];
    let names: Vec<String> = m.all_markers().map(|id| m.marker_name(id)).collect();
    let input_names: Vec<String> = m.inputs.iter().map(|i| i.name.clone()).collect();
    let primary = sweep.primary().input;
    let traced: Vec<usize> = (sweep.trace.iter())
        .filter_map(|t| m.all_markers().position(|id| id == *t))
        .collect();
    let mut samples: Vec<Vec<Sample3>> = vec![Vec::new(); traced.len()];
    let (mut singular, mut broken) = (Vec::new(), 0usize);
    // Why rates are missing other than at a dead point (said once).
    let mut unavailable: Option<RateError> = None;
    let total = sweep.steps;
    match form {
        Form::Json => {
            let rates_json: Map<String, Value> = (input_names.iter().zip(&rates))
                .map(|(n, r)| (n.clone(), json!(r)))
                .collect();
            writeln!(
                out,
                "{{\"name\": {}, \"dimension\": 3, \"rates\": {}, \"frames\": [",
                json!(m.name),
                Value::Object(rates_json)
            )?;
        }
        Form::Csv => {
            let mut head: Vec<String> = vec!["frame".into(), "status".into()];
            head.extend(input_names.iter().cloned());
            for n in &names {
                for c in ["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"] {
                    head.push(format!("{n}.{c}"));
                }
            }
            for b in &m.bodies {
                for c in ["omega", "alpha"] {
                    for k in ["x", "y", "z"] {
                        head.push(format!("{}.{c}.{k}", b.name));
                    }
                }
            }
            head.push("residual".into());
            writeln!(out, "{}", head.join(","))?;
        }
        Form::Text => {}
    }
    progress.start(Some(total));
    for (i, requested) in sweep_requests(sweep, m.inputs.len()).enumerate() {
        progress.tick(i);
        let status = driver.frame(&requested);
        if !status.is_solved() {
            broken += 1;
        }
        let poses = driver.poses();
        let reached = driver.inputs().to_vec();
        let res = residual(m, poses, &reached);
        let markers = marker_positions(m, poses);
        let moving: Result<Motion, RateError> = interp
            .rates(driver.state(), &reached, &rates, &zero)
            .map(|j| motion(m, &j));
        match &moving {
            Err(RateError::Singular) => singular.push(i),
            Err(e) if unavailable.is_none() => unavailable = Some(e.clone()),
            _ => {}
        }
        for (s, &k) in samples.iter_mut().zip(&traced) {
            s.push(Sample3 {
                input: reached[primary],
                at: markers[k],
                rates: moving
                    .as_ref()
                    .ok()
                    .map(|mo| (mo.velocity[k], mo.acceleration[k])),
            });
        }
        match form {
            Form::Json => {
                let mut o = frame_value(
                    m,
                    &names,
                    &input_names,
                    i,
                    status,
                    &requested,
                    &reached,
                    poses,
                    &markers,
                    res,
                );
                rate_keys(
                    &mut o,
                    m.bodies.iter().map(|b| b.name.as_str()),
                    &names,
                    moving.as_ref().map(|mo| {
                        (
                            &mo.velocity[..],
                            &mo.acceleration[..],
                            &mo.omega[..],
                            &mo.alpha[..],
                        )
                    }),
                );
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "  {o}{sep}")?;
            }
            Form::Csv => {
                let mut row = vec![i.to_string(), status.name().to_string()];
                row.extend(reached.iter().map(|v| number(*v)));
                for (k, p) in markers.iter().enumerate() {
                    row.extend(p.iter().map(|v| number(*v)));
                    match &moving {
                        Ok(mo) => row.extend(
                            (mo.velocity[k].iter())
                                .chain(&mo.acceleration[k])
                                .map(|v| number(*v)),
                        ),
                        // No rate here: no number, not a huge one.
                        Err(_) => row.extend(std::iter::repeat_n(String::new(), 6)),
                    }
                }
                for b in 0..m.bodies.len() {
                    match &moving {
                        Ok(mo) => row.extend(mo.omega[b].iter().chain(&mo.alpha[b]).map(|v| number(*v))),
                        Err(_) => row.extend(std::iter::repeat_n(String::new(), 6)),
                    }
                }
                row.push(format!("{res:e}"));
                writeln!(out, "{}", row.join(","))?;
            }
            Form::Text => {}
        }
    }
    progress.finish();
    if form == Form::Json {
        writeln!(out, "]}}")?;
    }
    let input = &m.inputs[primary];
    if form == Form::Text {
        writeln!(out, "{}", header(&m.name, total, &m.inputs, &rates))?;
        let at = |x: f64| at_input(input, x);
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        for (s, &k) in samples.iter().zip(&traced) {
            let points: Vec<(f64, f64, f64)> = (s.iter())
                .filter_map(|p| p.rates.map(|(v, a)| (p.input, norm(v), norm(a))))
                .collect();
            if let Some(line) = extremes(&names[k], &points, &at) {
                writeln!(out, "{line}")?;
            }
        }
        if let Some(e) = &unavailable {
            writeln!(
                out,
                "  rates unavailable for this plan ({e}): positions only (`dofplan simulate` gives them too)"
            )?;
        }
        if !singular.is_empty() {
            writeln!(
                out,
                "  {} frame(s) at a dead point (rates singular), the first frame {}",
                singular.len(),
                singular[0]
            )?;
        }
        if broken > 0 {
            writeln!(
                out,
                "  {broken} frame(s) did not assemble (the last pose kept; `dofplan simulate` says where it breaks)"
            )?;
        }
    }
    if let Some(path) = svg {
        let views: Vec<Traced3> = (traced.iter().zip(&samples))
            .map(|(&k, s)| Traced3 {
                name: &names[k],
                points: s,
            })
            .collect();
        return plots(&m.name, input, rates[primary], &views, path, form, out);
    }
    Ok(Ok(()))
}

/// Draws the traced markers' plots to `path` (and says so in a text
/// report), or the error why they could not be drawn or written.
fn plots(
    name: &str,
    input: &Input,
    rate: f64,
    views: &[Traced3],
    path: &Path,
    form: Form,
    out: &mut dyn Write,
) -> Outcome {
    let axis = match input.kind {
        InputKind::Angle => format!("{} (degrees)", input.name),
        InputKind::Slide => format!("{} (length)", input.name),
    };
    let rate_text = rate_text(input.kind, rate);
    match draw_spatial(name, &axis, &rate_text, views) {
        Ok(text) => {
            if let Err(e) = std::fs::write(path, text) {
                return Ok(Err(format!(
                    "{}: error: cannot write the plots: {e}",
                    path.display()
                )));
            }
        }
        Err(e) => {
            return Ok(Err(format!(
                "{}: error: cannot draw the plots: {e}",
                path.display()
            )));
        }
    }
    if form == Form::Text {
        writeln!(out, "wrote {}", path.display())?;
    }
    Ok(Ok(()))
}
