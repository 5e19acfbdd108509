//! Synthesis of a planar mechanism from a request as the CLI (or any front
//! end) makes it: the target file read, the goal and its parameters
//! resolved by name, the search run, and every solution written into the
//! mechanism's file and verified from that file.

use super::{Constraints, Design, Goal, Problem};
use crate::assemble::rewrite_positions;
use crate::model::{Format, Mechanism};
use crate::synth::request::{boxes, driving_input, names, varied, Corners};
use crate::synth::search::{Objective, Options, Progress};
use crate::synth::solution::{in_order, search_and_verify, stats, Solution, Synthesis};
use crate::synth::target;

/// The kind of synthesis and its target file.
#[derive(Clone, Debug)]
pub enum Kind {
    /// Path generation: `marker` ("body.marker") through the file's points.
    Path {
        /// The marker.
        marker: String,
        /// `Some(true)`: given timing (`input,x,y`); `Some(false)`: free
        /// (`x,y`); `None`: as the file's columns say.
        given: Option<bool>,
    },
    /// Function generation: the joint's output at the file's inputs.
    Function {
        /// The output joint's name.
        output: String,
    },
    /// Motion generation: the body's poses.
    Motion {
        /// The body's name.
        body: String,
        /// The marker whose position is the body's ("body.marker";
        /// default the body's first marker).
        marker: Option<String>,
        /// As for paths.
        given: Option<bool>,
    },
}

/// What to synthesise.
#[derive(Clone, Debug)]
pub struct Request {
    /// The goal's kind.
    pub kind: Kind,
    /// The target file's name (for messages) and text.
    pub targets: (String, String),
    /// The driving input's name (default: the sweep's, or the only one).
    pub input: Option<String>,
    /// The parameters varied: names (`D.x`) or points (`D`, both
    /// coordinates); default all.
    pub vary: Option<Vec<String>>,
    /// A box `[x0, y0, x1, y1]` for every varied point.
    pub bounds: Option<[f64; 4]>,
    /// Boxes for single points, by point name.
    pub point_bounds: Vec<(String, [f64; 4])>,
    /// The constraints.
    pub constraints: Constraints,
}

/// The problem a request asks on `m`.
pub fn problem(m: &Mechanism, request: &Request) -> Result<Problem, String> {
    let design = Design::new(m).map_err(|e| e.to_string())?;
    let input = driving_input(&m.inputs, m.sweep.as_ref(), request.input.as_deref())?;
    let (name, text) = &request.targets;
    let marker_of = |n: &str| {
        m.find_marker(n).ok_or_else(|| {
            format!(
                "no marker '{n}': name it as body.marker, one of {}",
                names(m.all_markers().map(|id| m.marker_name(id)))
            )
        })
    };
    let goal = match &request.kind {
        Kind::Path { marker, given: g } => {
            let rows = target::read(
                name,
                text,
                &[2, 3],
                "x,y (free timing) or input,x,y (given timing)",
            )?;
            let timed = target::timed(name, *g, rows[0].values.len(), 2)?;
            let v = |r: &target::Row, k: usize| r.values[k + usize::from(timed)];
            Goal::Path {
                marker: marker_of(marker)?,
                points: rows.iter().map(|r| [v(r, 0), v(r, 1)]).collect(),
                inputs: timed.then(|| rows.iter().map(|r| r.values[0]).collect()),
            }
        }
        Kind::Function { output } => {
            let joint = (m.joints.iter().position(|j| &j.name == output)).ok_or_else(|| {
                format!(
                    "no joint '{output}': one of {}",
                    names(m.joints.iter().map(|j| j.name.clone()))
                )
            })?;
            let rows = target::read(name, text, &[2], "input,output")?;
            Goal::Function {
                joint,
                pairs: rows.iter().map(|r| [r.values[0], r.values[1]]).collect(),
            }
        }
        Kind::Motion {
            body,
            marker,
            given: g,
        } => {
            let b = (m.bodies.iter().position(|x| &x.name == body)).ok_or_else(|| {
                format!(
                    "no body '{body}': one of {}",
                    names(m.bodies.iter().map(|b| b.name.clone()))
                )
            })?;
            let marker = match marker {
                Some(n) => marker_of(n)?,
                None => marker_of(&format!("{body}.{}", m.bodies[b].markers[0].name))?,
            };
            if marker.body != b {
                return Err(format!("marker {} is not on body {body}", m.marker_name(marker)));
            }
            let rows = target::read(
                name,
                text,
                &[3, 4],
                "x,y,angle (free timing) or input,x,y,angle (given timing)",
            )?;
            let cols = rows[0].values.len();
            let timed = target::timed(name, *g, cols, 3)?;
            let v = |r: &target::Row, k: usize| r.values[k + usize::from(timed)];
            Goal::Motion {
                body: b,
                marker,
                poses: rows.iter().map(|r| [v(r, 0), v(r, 1), v(r, 2)]).collect(),
                inputs: timed.then(|| rows.iter().map(|r| r.values[0]).collect()),
            }
        }
    };
    let vary = varied(design.parameters(), request.vary.as_deref())?;
    let targets: Vec<[f64; 2]> = match &goal {
        Goal::Path { points, .. } => points.clone(),
        Goal::Motion { poses, .. } => poses.iter().map(|p| [p[0], p[1]]).collect(),
        Goal::Function { .. } => Vec::new(),
    };
    let corners = |b: [f64; 4]| ([b[0], b[1]], [b[2], b[3]]);
    let point_bounds: Vec<(String, Corners<2>)> = (request.point_bounds.iter())
        .map(|(n, b)| (n.clone(), corners(*b)))
        .collect();
    let bounds = boxes(
        design.parameters(),
        targets.into_iter(),
        &vary,
        request.bounds.map(corners),
        &point_bounds,
    )?;
    Problem::new(design, goal, input, vary, bounds, request.constraints).map_err(|e| e.to_string())
}

/// Runs the search on `problem` (made from `m`, whose file is `text` in
/// `format`) and writes and verifies each solution.
pub fn synthesize(
    m: &Mechanism,
    text: &str,
    format: Format,
    problem: &Problem,
    options: &Options,
    progress: &mut (dyn FnMut(Progress) + Send),
) -> Result<Synthesis, String> {
    let (names, vary) = (problem.design().names(), problem.vary());
    search_and_verify(problem, names, vary, options, progress, |z| {
        verify(m, text, format, problem, z)
    })
}

/// Writes the solution `z` into the file and computes its error and
/// margins again from what was written (loaded, planned and run as any
/// file is).
fn verify(
    m: &Mechanism,
    text: &str,
    format: Format,
    problem: &Problem,
    z: &[f64],
) -> Result<Solution, String> {
    let nv = problem.vary().len();
    let values = problem.values(&z[..nv]);
    let design = problem.design();
    let moved = design.drawing(&values).map_err(|e| e.to_string())?;
    let changes: Vec<(String, String, Vec<f64>)> = (moved.all_markers())
        .filter(|&id| moved.marker(id).at != m.marker(id).at)
        .map(|id| {
            (
                m.bodies[id.body].name.clone(),
                moved.marker(id).name.clone(),
                moved.marker(id).at.to_vec(),
            )
        })
        .collect();
    let written = rewrite_positions(text, format, m.size(), &changes)?;
    let searched = problem
        .residuals(z, false)
        .map(|(r, _)| stats(problem.goal().len(), r.as_slice()));
    let reloaded = crate::load_str(&m.source.name, &written, format).map_err(|e| {
        format!(
            "the solution's file does not load back (please report it): {}",
            e.diagnostics.first().map_or(String::new(), |d| d.message.clone())
        )
    })?;
    let again = Design::new(&reloaded).map_err(|e| format!("the solution's file has no plan: {e}"))?;
    let file_values = again.drawn();
    let mut z2: Vec<f64> = problem.vary().iter().map(|&k| file_values[k]).collect();
    z2.extend_from_slice(&z[nv..]);
    // The box widened to hold the file's values: a file is written to
    // within 1e-12 of the mechanism's size, so a solution on the box's edge
    // may read back a hair outside it.
    let bounds: Vec<[f64; 2]> = (z2.iter().zip(problem.bounds()))
        .map(|(&v, &[lo, hi])| [lo.min(v), hi.max(v)])
        .collect();
    let from_file = Problem::new(
        again,
        problem.goal().clone(),
        problem.input(),
        problem.vary().to_vec(),
        bounds,
        problem.constraints(),
    )
    .map_err(|e| e.to_string())?;
    let (r, _) = from_file
        .residuals(&z2, false)
        .ok_or("a solution whose written file does not reach every target where the search's candidate did (a frame at the edge of its reach)")?;
    let error = stats(problem.goal().len(), r.as_slice());
    Ok(Solution {
        values: file_values,
        inputs: (z.len() > nv).then(|| z[nv..].to_vec()),
        order_kept: (z.len() > nv).then(|| {
            let angle = m.inputs[problem.input()].kind == crate::model::InputKind::Angle;
            in_order(&z[nv..], angle)
        }),
        error,
        searched: searched.unwrap_or(error),
        margins: from_file.margins(&z2).unwrap_or_default(),
        text: written,
    })
}
