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

use std::io::{self, Write};
use std::path::Path;

use crate::format::number;
use crate::interp::spatial::Interpreter;
use crate::model::spatial::Mechanism;
use crate::model::{Input, Sweep};
use crate::plan::spatial::Plan;
use crate::render::plots::{draw_spatial, Sample3, Traced3};
use crate::simulate::input_rates;
use crate::simulate::spatial::{marker_positions, motion, residual, Motion};
use crate::simulate::sweep_requests;
use dofplan_runtime::real::RateError;
use dofplan_runtime::spatial::Vec3;
use dofplan_runtime::{Driver, FrameStatus, Options};
use serde_json::{json, Value};

use super::frames::frame_value;
use crate::report::rates::{
    at_input, extremes, header, rate_keys, rates_json, write_dead_points, write_plots, Series,
};
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
    let mut series: Vec<Series<Sample3>> = Series::traced(&names, &traced);
    let mut missed = Missed::default();
    let total = sweep.steps;
    match form {
        Form::Json => writeln!(
            out,
            "{{\"name\": {}, \"dimension\": 3, \"rates\": {}, \"frames\": [",
            json!(m.name),
            rates_json(&m.inputs, &rates)
        )?,
        Form::Csv => writeln!(out, "{}", csv_head(m, &input_names, &names).join(","))?,
        Form::Text => {}
    }
    progress.start(Some(total));
    for (i, requested) in sweep_requests(sweep, m.inputs.len()).enumerate() {
        progress.tick(i);
        let status = driver.frame(&requested);
        let poses = driver.poses();
        let reached = driver.inputs().to_vec();
        let res = residual(m, poses, &reached);
        let markers = marker_positions(m, poses);
        let moving: Result<Motion, RateError> = interp
            .rates(driver.state(), &reached, &rates, &zero)
            .map(|j| motion(m, &j));
        missed.add(i, status, &moving);
        for (s, &k) in series.iter_mut().zip(&traced) {
            s.points.push(Sample3 {
                input: reached[primary],
                at: markers[k],
                rates: (moving.as_ref().ok()).map(|mo| (mo.velocity[k], mo.acceleration[k])),
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
                add_rates(&mut o, m, &names, &moving);
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "  {o}{sep}")?;
            }
            Form::Csv => {
                let row = csv_row(m, i, status, &reached, &markers, &moving, res);
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
        write_extremes(input, &series, out)?;
        missed.write(out)?;
    }
    match svg {
        Some(path) => write_plots(path, input, rates[primary], form, out, |axis, rate_label| {
            let views: Vec<Traced3> = (series.iter())
                .map(|s| Traced3 {
                    name: &s.name,
                    points: &s.points,
                })
                .collect();
            draw_spatial(&m.name, axis, rate_label, &views)
        }),
        None => Ok(Ok(())),
    }
}

/// The frames of the sweep without rates or without a pose, for the
/// summary to say once.
#[derive(Default)]
struct Missed {
    /// The frames at a dead point.
    singular: Vec<usize>,
    /// How many frames did not assemble.
    broken: usize,
    /// Why rates are missing other than at a dead point (said once).
    unavailable: Option<RateError>,
}

impl Missed {
    /// Notes frame `i`, met with `status`, and its motion.
    fn add(&mut self, i: usize, status: FrameStatus, moving: &Result<Motion, RateError>) {
        if !status.is_solved() {
            self.broken += 1;
        }
        match moving {
            Err(RateError::Singular) => self.singular.push(i),
            Err(e) if self.unavailable.is_none() => self.unavailable = Some(e.clone()),
            _ => {}
        }
    }

    /// The summary's lines on what was missed.
    fn write(&self, out: &mut dyn Write) -> io::Result<()> {
        if let Some(e) = &self.unavailable {
            writeln!(
                out,
                "  rates unavailable for this plan ({e}): positions only (`dofplan simulate` gives them too)"
            )?;
        }
        write_dead_points(out, &self.singular)?;
        if self.broken > 0 {
            writeln!(
                out,
                "  {} frame(s) did not assemble (the last pose kept; `dofplan simulate` says where it breaks)",
                self.broken
            )?;
        }
        Ok(())
    }
}

/// The summary's line of each traced marker: its largest speed and
/// acceleration and where on the sweep of `input`.
fn write_extremes(input: &Input, series: &[Series<Sample3>], out: &mut dyn Write) -> io::Result<()> {
    let at = |x: f64| at_input(input, x);
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    for s in series {
        let points: Vec<(f64, f64, f64)> = (s.points.iter())
            .filter_map(|p| p.rates.map(|(v, a)| (p.input, norm(v), norm(a))))
            .collect();
        if let Some(line) = extremes(&s.name, &points, &at) {
            writeln!(out, "{line}")?;
        }
    }
    Ok(())
}

/// The keys `analyze --json` adds to a `simulate` frame.
fn add_rates(o: &mut Value, m: &Mechanism, names: &[String], moving: &Result<Motion, RateError>) {
    rate_keys(
        o,
        m.bodies.iter().map(|b| b.name.as_str()),
        names,
        moving.as_ref().map(|mo| {
            (
                &mo.velocity[..],
                &mo.acceleration[..],
                &mo.omega[..],
                &mo.alpha[..],
            )
        }),
    );
}

/// The header of `analyze --csv`: the frame, its status and the inputs,
/// every marker's position, velocity and acceleration, every body's angular
/// velocity and acceleration, the joint residual.
fn csv_head(m: &Mechanism, input_names: &[String], names: &[String]) -> Vec<String> {
    let mut head: Vec<String> = vec!["frame".into(), "status".into()];
    head.extend(input_names.iter().cloned());
    for n in names {
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
    head
}

/// Frame `i`'s row of `analyze --csv`, in the columns of [`csv_head`].
fn csv_row(
    m: &Mechanism,
    i: usize,
    status: FrameStatus,
    reached: &[f64],
    markers: &[Vec3],
    moving: &Result<Motion, RateError>,
    res: f64,
) -> Vec<String> {
    let mut row = vec![i.to_string(), status.name().to_string()];
    row.extend(reached.iter().map(|v| number(*v)));
    for (k, p) in markers.iter().enumerate() {
        row.extend(p.iter().map(|v| number(*v)));
        match moving {
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
        match moving {
            Ok(mo) => row.extend(mo.omega[b].iter().chain(&mo.alpha[b]).map(|v| number(*v))),
            Err(_) => row.extend(std::iter::repeat_n(String::new(), 6)),
        }
    }
    row.push(format!("{res:e}"));
    row
}
