//! `dofplan synth`'s report: the best solution's error (recomputed from
//! the file written), its parameters and constraint margins, and the other
//! distinct solutions; as text or one JSON document.

use std::io::{self, Write};

use crate::format::{length, rounded};
use crate::interp::Interpreter;
use crate::model::{Format, Mechanism, Model, Sweep};
use crate::render::planar::{render, SvgOptions};
use crate::report::synth::{self as shared, short};
use crate::simulate::{run, sweep_requests};
use crate::synth::planar::{Goal, Problem, Solution, Synthesis};

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

/// Prints the synthesis as JSON.
pub fn write_json(m: &Mechanism, problem: &Problem, s: &Synthesis, out: &mut dyn Write) -> io::Result<()> {
    shared::write_json(&m.name, &describe(m, problem.goal()), s, out)
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
    shared::write_order(best, out)?;
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
    shared::write_margins(best, out)?;
    shared::write_tail(s, out)
}

/// The picture of a solution: the mechanism its file holds, run over the
/// search's input range, the goal's marker traced, the targets marked.
pub fn picture(
    m: &Mechanism,
    problem: &Problem,
    solution: &Solution,
    format: Format,
) -> Result<String, String> {
    let Model::Planar(solved) = shared::load_solution(&m.source.name, solution, format)? else {
        return Err("the solution's file reads back as spatial".into());
    };
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
