//! `dofplan synth`'s report: the best solution's error (recomputed from
//! the file written), its parameters and constraint margins, and the other
//! distinct solutions; as text or one JSON document.

use std::io::{self, Write};

use serde_json::{json, Map, Value};

use crate::format::{length, rounded};
use crate::interp::Interpreter;
use crate::model::{Format, Mechanism, Sweep};
use crate::render::planar::{render, SvgOptions};
use crate::simulate::{run, sweep_requests};
use crate::synth::planar::{ErrorStats, Goal, Problem, Solution, Synthesis};
use crate::synth::search::Stop;

fn error_json(e: &ErrorStats) -> Value {
    json!({ "sum_sq": e.sum_sq, "rms": e.rms, "max": e.max })
}

fn solution_json(s: &Synthesis, sol: &Solution) -> Value {
    let parameters: Map<String, Value> = (s.names.iter().zip(&sol.values))
        .map(|(n, v)| (n.clone(), json!(v)))
        .collect();
    let constraints: Vec<Value> = (sol.margins.iter())
        .map(|m| json!({ "name": m.name, "value": m.value, "margin": m.margin }))
        .collect();
    let mut v = json!({
        "error": error_json(&sol.error),
        "search_error": error_json(&sol.searched),
        "parameters": parameters,
        "constraints": constraints,
    });
    if let Some(inputs) = &sol.inputs {
        v["inputs"] = json!(inputs);
        v["order_kept"] = json!(sol.order_kept);
    }
    v
}

/// What a goal is, in words: "path generation of coupler.P through 18
/// points (free timing)".
pub fn describe(m: &Mechanism, goal: &Goal) -> String {
    let timing = |given: bool| if given { "given timing" } else { "free timing" };
    match goal {
        Goal::Path {
            marker,
            points,
            inputs,
        } => format!(
            "path generation of {} through {} points ({})",
            m.marker_name(*marker),
            points.len(),
            timing(inputs.is_some())
        ),
        Goal::Function { joint, pairs } => {
            format!(
                "function generation of joint {} at {} input values",
                m.joints[*joint].name,
                pairs.len()
            )
        }
        Goal::Motion {
            body, poses, inputs, ..
        } => format!(
            "motion generation of {} through {} poses ({})",
            m.bodies[*body].name,
            poses.len(),
            timing(inputs.is_some())
        ),
    }
}

fn stop_words(stop: Stop) -> &'static str {
    match stop {
        Stop::Target => "the target error was reached",
        Stop::Time => "the time limit",
        Stop::Stagnation => "no progress",
        Stop::Cancelled => "cancelled",
        Stop::Budget => "the evaluation budget",
    }
}

/// Prints the synthesis as JSON.
pub fn write_json(m: &Mechanism, problem: &Problem, s: &Synthesis, out: &mut dyn Write) -> io::Result<()> {
    let best = &s.solutions[0];
    let mut doc = solution_json(s, best);
    doc["mechanism"] = json!(m.name);
    doc["goal"] = json!(describe(m, problem.goal()));
    doc["varied"] = json!(s.varied.iter().map(|&k| s.names[k].clone()).collect::<Vec<_>>());
    doc["evaluations"] = json!(s.evaluations);
    doc["seconds"] = json!(s.seconds);
    doc["stopped"] = json!(stop_words(s.stop));
    doc["solutions"] = json!(s
        .solutions
        .iter()
        .map(|sol| solution_json(s, sol))
        .collect::<Vec<_>>());
    writeln!(
        out,
        "{}",
        serde_json::to_string_pretty(&doc).expect("JSON of plain values")
    )
}

/// Prints the synthesis as text.
pub fn write_text(
    m: &Mechanism,
    problem: &Problem,
    s: &Synthesis,
    written: Option<&str>,
    out: &mut dyn Write,
) -> io::Result<()> {
    let best = &s.solutions[0];
    writeln!(
        out,
        "{}: {}, {} of {} parameters varied",
        m.name,
        describe(m, problem.goal()),
        s.varied.len(),
        s.names.len()
    )?;
    let from = written.map_or("from the solution's file".to_string(), |f| format!("from {f}"));
    let e = &best.error;
    // A revolute joint's output is compared in degrees; the rest in lengths.
    let unit = match problem.goal() {
        Goal::Function { joint, .. } if m.joints[*joint].kind == crate::model::JointKind::Revolute => {
            " (degrees)"
        }
        _ => "",
    };
    writeln!(
        out,
        "best: sum of squares {}, rms {}, max {}{unit} ({from})",
        short(e.sum_sq),
        length(e.rms),
        length(e.max)
    )?;
    match best.order_kept {
        Some(true) => writeln!(out, "  the inputs found pass the targets in their order")?,
        Some(false) => writeln!(out, "  the inputs found do not pass the targets in their order")?,
        None => {}
    }
    let design = problem.design();
    for (n, node) in design.nodes().iter().enumerate() {
        let (x, y) = (best.values[2 * n], best.values[2 * n + 1]);
        let varied = s.varied.contains(&(2 * n)) || s.varied.contains(&(2 * n + 1));
        let note = if varied { "" } else { "  (held)" };
        writeln!(
            out,
            "  {:<12} ({}, {}){note}",
            node.name,
            rounded(x, 6),
            rounded(y, 6)
        )?;
    }
    for c in &best.margins {
        let state = if c.margin >= 0.0 { "kept" } else { "BROKEN" };
        writeln!(
            out,
            "  {}: {} ({state}, margin {})",
            c.name,
            rounded(c.value, 4),
            rounded(c.margin, 4)
        )?;
    }
    if s.solutions.len() > 1 {
        let others: Vec<String> = s.solutions[1..].iter().map(|o| short(o.error.sum_sq)).collect();
        writeln!(
            out,
            "other distinct solutions: sum of squares {}",
            others.join(", ")
        )?;
    }
    for r in &s.rejected {
        writeln!(out, "left out: {r}")?;
    }
    writeln!(
        out,
        "{} evaluations in {} s (stopped: {})",
        s.evaluations,
        rounded(s.seconds, 2),
        stop_words(s.stop)
    )
}

/// A sum of squares for people: four significant digits.
fn short(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e6).contains(&x.abs()) {
        rounded(x, (3 - x.abs().log10().floor() as i64).max(0) as usize)
    } else {
        format!("{x:.3e}")
    }
}

/// The picture of a solution: the mechanism its file holds, run over the
/// search's input range, the goal's marker traced, the targets marked.
pub fn picture(
    m: &Mechanism,
    problem: &Problem,
    solution: &Solution,
    format: Format,
) -> Result<String, String> {
    let solved = crate::load_str(&m.source.name, &solution.text, format).map_err(|e| {
        e.diagnostics
            .first()
            .map_or_else(String::new, |d| d.message.clone())
    })?;
    let plan = crate::analysis::analyse(&solved)
        .plan
        .map_err(|e| e.to_string())?;
    let [from, to] = problem.range();
    let (marker, points) = match problem.goal() {
        Goal::Path { marker, points, .. } => (Some(*marker), points.clone()),
        Goal::Motion { marker, poses, .. } => (Some(*marker), poses.iter().map(|p| [p[0], p[1]]).collect()),
        Goal::Function { .. } => (None, Vec::new()),
    };
    let trace: Vec<_> = marker.into_iter().collect();
    let sweep = Sweep::single(problem.input(), from, to, 361, trace.clone());
    let requests: Vec<Vec<f64>> = sweep_requests(&sweep, solved.inputs.len()).collect();
    let frames = run(Interpreter::new(plan), Default::default(), &requests);
    let options = SvgOptions {
        points,
        ..SvgOptions::default()
    };
    Ok(render(&solved, &frames, &trace, &options))
}
