//! `dofplan synth`'s report on a spatial mechanism: the best solution's
//! error (recomputed from the file written), its points, and the other
//! distinct solutions, with free timing's order and the constraints'
//! margins; as text or one JSON document (the planar report's fields);
//! and its picture.

use std::io::{self, Write};

use crate::format::{length, rounded};
use crate::model::spatial::Mechanism;
use crate::model::{Format, Model, Sweep};
use crate::render::spatial::render_spatial_with;
use crate::report::synth::{self as shared, short};
use crate::synth::solution::{Solution, Synthesis};
use crate::synth::spatial::Problem;

/// Prints the synthesis as JSON.
pub fn write_json(m: &Mechanism, problem: &Problem, s: &Synthesis, out: &mut dyn Write) -> io::Result<()> {
    shared::write_json(&m.name, &problem.describe(), s, out)
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
        problem.describe(),
        s.varied.len(),
        s.names.len()
    )?;
    let from = written.map_or("from the solution's file".to_string(), |f| format!("from {f}"));
    let e = &best.error;
    // A function's output is an angle; a path's and a motion's residuals
    // are lengths (a motion's turn weighted by the mechanism's size per
    // radian).
    let unit = match problem {
        Problem::Function(_) => " (degrees)",
        Problem::Path(_) | Problem::Motion(_) => "",
    };
    writeln!(
        out,
        "best: sum of squares {}, rms {}, max {}{unit} ({from})",
        short(e.sum_sq),
        length(e.rms),
        length(e.max)
    )?;
    shared::write_order(best, out)?;
    for (n, node) in problem.design().nodes().iter().enumerate() {
        let at = &best.values[3 * n..3 * n + 3];
        let varied = (3 * n..3 * n + 3).any(|k| s.varied.contains(&k));
        let note = if varied { "" } else { "  (held)" };
        let [x, y, z] = [at[0], at[1], at[2]].map(|v| rounded(v, 6));
        writeln!(out, "  {:<12} ({x}, {y}, {z}){note}", node.name)?;
    }
    shared::write_margins(best, out)?;
    shared::write_tail(s, out)
}

/// The picture of a solution: the mechanism its file holds, run over the
/// input range the problem shows (as `simulate` runs a file), in four
/// views, the goal's marker traced and the targets marked (a function's
/// output has no point to trace: the mechanism alone).
pub fn picture(
    m: &Mechanism,
    problem: &Problem,
    solution: &Solution,
    format: Format,
) -> Result<String, String> {
    let Model::Spatial(mut solved) = shared::load_solution(&m.source.name, solution, format)? else {
        return Err("the solution's file reads back as planar".into());
    };
    let plan = crate::analysis::spatial::analyse(&solved).map_err(|e| e.to_string())?;
    let (trace, targets) = match problem {
        Problem::Path(p) => (vec![p.marker()], p.points().to_vec()),
        Problem::Motion(p) => (vec![p.marker()], p.poses().iter().map(|t| t.at).collect()),
        Problem::Function(_) => (Vec::new(), Vec::new()),
    };
    let [from, to] = problem.shown_range();
    let sweep = Sweep::single(problem.input(), from, to, 361, trace);
    let frames = super::frames::sweep_frames(plan, &sweep, solved.inputs.len());
    solved.sweep = Some(sweep);
    Ok(render_spatial_with(&solved, &frames, &targets))
}
