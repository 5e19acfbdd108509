//! `dofplan analyze`: the file's sweep with every marker's velocity and
//! acceleration and every body's angular rates — exact, by forward-mode
//! differentiation through the plan — and each four-bar loop's
//! transmission angle; printed as a summary, JSON or CSV (streamed frame by
//! frame), and drawn as plots a designer looks at (plotters' SVG backend).

use std::io::{self, Write};
use std::path::Path;

use crate::analysis::planar::grashof::{four_bars, FourBar};
use crate::format::number;
use crate::interp::{Interpreter, RateError};
use crate::model::{Mechanism, Sweep};
use crate::plan::{num, Plan};
use crate::render::plots::Sample;
use crate::simulate::planar::kinematics::{motion, transmission_angle, Motion};
use crate::simulate::sweep_rates;
use crate::simulate::{sweep_requests, Frame};
use dofplan_runtime::{Driver, FrameStatus, Options};
use serde_json::{json, Value};

use super::frames::{frame_json, sweep_report, Solver};
use crate::report::rates::{
    at_input, extremes, header, rate_keys, rates_json, write_dead_points, write_plots, Series,
};
use crate::report::{Form, FrameProgress, Outcome};

/// Runs `analyze`: the sweep with rates at `rate` (radians or length units
/// per second for the sweep's first input), in `form`, with plots in `svg`.
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
    let report = sweep_report(m, plan, sweep, Solver::Plan);
    let rates = sweep_rates(m, sweep, rate);
    let zero = vec![0.0; m.inputs.len()];
    let loops = four_bars(m);
    let loop_names: Vec<Vec<&str>> = (loops.iter())
        .map(|f| f.bodies.iter().map(|&b| m.bodies[b].name.as_str()).collect())
        .collect();
    let names: Vec<String> = m.all_markers().map(|id| m.marker_name(id)).collect();
    let primary = sweep.primary().input;
    let traced: Vec<usize> = (sweep.trace.iter())
        .filter_map(|t| m.all_markers().position(|id| id == *t))
        .collect();
    let mut gathered = Gathered::new(&names, traced, loops.len());
    let total = sweep.steps;
    match form {
        Form::Json => writeln!(
            out,
            "{{\n  \"mechanism\": {},\n  \"rates\": {},\n  \"frames\": [",
            json!(m.name),
            rates_json(&m.inputs, &rates)
        )?,
        Form::Csv => writeln!(out, "{}", csv_head(m, &names, &loop_names).join(","))?,
        Form::Text => {}
    }
    progress.start(Some(total));
    for (i, requested) in sweep_requests(sweep, m.inputs.len()).enumerate() {
        progress.tick(i);
        let status = driver.frame(&requested);
        let frame = Frame {
            requested,
            inputs: driver.inputs().to_vec(),
            status,
            poses: driver.poses().to_vec(),
            numeric: driver.numeric(),
        };
        let rates_here = interp.rates(driver.state(), &frame.inputs, &rates, &zero);
        let moving: Result<Motion, RateError> = rates_here.map(|j| motion(m, &j));
        let mus: Vec<f64> = loops
            .iter()
            .map(|f| transmission_angle(m, f, &frame.poses))
            .collect();
        gathered.add(m, i, &frame, &moving, &mus, frame.inputs[primary]);
        match form {
            Form::Json => {
                let mut o = frame_json(&report, &frame);
                add_rates(&mut o, m, &names, &moving, &loop_names, &mus);
                let sep = if i + 1 < total { "," } else { "" };
                writeln!(out, "    {o}{sep}")?;
            }
            Form::Csv => writeln!(out, "{}", csv_row(m, i, &frame, &moving, &mus).join(","))?,
            Form::Text => {}
        }
    }
    progress.finish();
    if form == Form::Json {
        writeln!(out, "  ]\n}}")?;
    }
    if form == Form::Text {
        summary(m, sweep, &rates, &gathered, &loops, &loop_names, out)?;
    }
    match svg {
        Some(path) => write_plots(
            path,
            &m.inputs[primary],
            rates[primary],
            form,
            out,
            |axis, rate_label| {
                crate::render::plots::draw(
                    &m.name,
                    axis,
                    rate_label,
                    &series_view(&gathered.series),
                    &loop_views(&loop_names, &gathered.angles),
                )
            },
        ),
        None => Ok(Ok(())),
    }
}

/// What the summary and the plots gather over the sweep, frame by frame.
struct Gathered {
    /// The traced markers, as indices into the mechanism's markers.
    traced: Vec<usize>,
    /// Their samples, in the same order.
    series: Vec<Series<Sample>>,
    /// Each four-bar loop's (input, transmission angle).
    angles: Vec<Vec<(f64, f64)>>,
    /// The frames at a dead point.
    singular: Vec<usize>,
}

impl Gathered {
    /// Nothing gathered yet, for the `traced` markers (indices into
    /// `names`) and `loops` four-bar loops.
    fn new(names: &[String], traced: Vec<usize>, loops: usize) -> Gathered {
        Gathered {
            series: Series::traced(names, &traced),
            traced,
            angles: vec![Vec::new(); loops],
            singular: Vec::new(),
        }
    }

    /// Adds frame `i`, at `x` of the swept input, with its motion and its
    /// loops' transmission angles `mus`.
    fn add(
        &mut self,
        m: &Mechanism,
        i: usize,
        frame: &Frame,
        moving: &Result<Motion, RateError>,
        mus: &[f64],
        x: f64,
    ) {
        if let Err(RateError::Singular) = moving {
            self.singular.push(i);
        }
        // A frame held at an earlier pose (the limit policy) repeats a
        // point from elsewhere in the sweep: a gap in the plots, not a line
        // back to it.
        let held = matches!(frame.status, FrameStatus::Limited { .. });
        for (s, &k) in self.series.iter_mut().zip(&self.traced) {
            s.points.push(sample(m, frame, moving, k, x, held));
        }
        for (a, mu) in self.angles.iter_mut().zip(mus) {
            a.push((x, if held { f64::NAN } else { *mu }));
        }
    }
}

/// Where traced marker `k` is at `frame` and how it moves there; a `held`
/// frame is a gap (NaN, no rates), not a point.
fn sample(
    m: &Mechanism,
    frame: &Frame,
    moving: &Result<Motion, RateError>,
    k: usize,
    x: f64,
    held: bool,
) -> Sample {
    if held {
        return Sample {
            input: x,
            at: [f64::NAN; 2],
            rates: None,
        };
    }
    let id = m.all_markers().nth(k).expect("a traced marker");
    Sample {
        input: x,
        at: frame.poses[id.body].world(m.marker(id).at),
        rates: (moving.as_ref().ok()).map(|mo| (mo.velocity[k], mo.acceleration[k])),
    }
}

/// The header of `analyze --csv`: the frame, the inputs and the status,
/// every marker's position, velocity and acceleration, every body's angular
/// rates, every four-bar loop's transmission angle.
fn csv_head(m: &Mechanism, names: &[String], loop_names: &[Vec<&str>]) -> Vec<String> {
    let mut head = vec!["frame".to_string()];
    head.extend(m.inputs.iter().map(|i| i.name.clone()));
    head.push("status".into());
    for n in names {
        for c in ["x", "y", "vx", "vy", "ax", "ay"] {
            head.push(format!("{n}.{c}"));
        }
    }
    for b in &m.bodies {
        head.push(format!("{}.omega", b.name));
        head.push(format!("{}.alpha", b.name));
    }
    for l in loop_names {
        head.push(format!("mu[{}]", l.join("-")));
    }
    head
}

/// Frame `i`'s row of `analyze --csv`, in the columns of [`csv_head`].
fn csv_row(
    m: &Mechanism,
    i: usize,
    frame: &Frame,
    moving: &Result<Motion, RateError>,
    mus: &[f64],
) -> Vec<String> {
    let mut row = vec![i.to_string()];
    row.extend(frame.requested.iter().map(|v| number(*v)));
    row.push(frame.status.name().to_string());
    for (k, id) in m.all_markers().enumerate() {
        let p = frame.poses[id.body].world(m.marker(id).at);
        row.extend(p.iter().map(|v| number(*v)));
        match moving {
            Ok(mo) => {
                let (v, a) = (mo.velocity[k], mo.acceleration[k]);
                row.extend([v[0], v[1], a[0], a[1]].iter().map(|v| number(*v)));
            }
            // A dead point: no number, not a huge one.
            Err(_) => row.extend(std::iter::repeat_n(String::new(), 4)),
        }
    }
    for b in 0..m.bodies.len() {
        match moving {
            Ok(mo) => row.extend([number(mo.omega[b]), number(mo.alpha[b])]),
            Err(_) => row.extend([String::new(), String::new()]),
        }
    }
    row.extend(mus.iter().map(|v| number(*v)));
    row
}

/// The keys `analyze --json` adds to a `simulate` frame.
fn add_rates(
    o: &mut Value,
    m: &Mechanism,
    names: &[String],
    moving: &Result<Motion, RateError>,
    loops: &[Vec<&str>],
    mus: &[f64],
) {
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
    if !loops.is_empty() {
        o["transmission"] = json!(loops
            .iter()
            .zip(mus)
            .map(|(l, mu)| json!({"loop": l, "angle": mu}))
            .collect::<Vec<_>>());
    }
}

/// The text summary: the rates used, each traced marker's largest speed
/// and acceleration and where, each loop's transmission angle range (the
/// first [`LISTED_LOOPS`], as `check` lists them).
fn summary(
    m: &Mechanism,
    sweep: &Sweep,
    rates: &[f64],
    gathered: &Gathered,
    loops: &[FourBar],
    loop_names: &[Vec<&str>],
    out: &mut dyn Write,
) -> io::Result<()> {
    let primary = &m.inputs[sweep.primary().input];
    writeln!(out, "{}", header(&m.name, sweep.steps, &m.inputs, rates))?;
    let at = |x: f64| at_input(primary, x);
    for s in &gathered.series {
        let points: Vec<(f64, f64, f64)> = (s.points.iter())
            .filter_map(|p| {
                p.rates
                    .map(|(v, a)| (p.input, v[0].hypot(v[1]), a[0].hypot(a[1])))
            })
            .collect();
        if let Some(line) = extremes(&s.name, &points, &at) {
            writeln!(out, "{line}")?;
        }
    }
    for ((_, name), a) in (loops.iter().zip(loop_names).zip(&gathered.angles)).take(LISTED_LOOPS) {
        let finite = || a.iter().filter(|p| p.1.is_finite());
        let lo = finite().min_by(|p, q| p.1.total_cmp(&q.1));
        let hi = finite().max_by(|p, q| p.1.total_cmp(&q.1));
        if let (Some(lo), Some(hi)) = (lo, hi) {
            writeln!(
                out,
                "  transmission angle of {}: from {}° (at {}) to {}° (at {})",
                name.join("–"),
                num(lo.1),
                at(lo.0),
                num(hi.1),
                at(hi.0)
            )?;
        }
    }
    if loops.len() > LISTED_LOOPS {
        writeln!(
            out,
            "  … and {} more four-bar loops (`dofplan analyze --json` or `--csv` gives them all)",
            loops.len() - LISTED_LOOPS
        )?;
    }
    write_dead_points(out, &gathered.singular)
}

/// The summary lists this many four-bar loops at most, as `check` does.
const LISTED_LOOPS: usize = 12;

/// The traced markers' series as the plots take them.
fn series_view(series: &[Series<Sample>]) -> Vec<crate::render::plots::Traced<'_>> {
    series
        .iter()
        .map(|s| crate::render::plots::Traced {
            name: &s.name,
            points: &s.points,
        })
        .collect()
}

/// The four-bar loops' transmission angles as the plots take them.
fn loop_views<'a>(
    names: &'a [Vec<&'a str>],
    angles: &'a [Vec<(f64, f64)>],
) -> Vec<crate::render::plots::Loop<'a>> {
    names
        .iter()
        .zip(angles)
        .map(|(n, a)| crate::render::plots::Loop {
            name: n.join("–"),
            angles: a,
        })
        .collect()
}
