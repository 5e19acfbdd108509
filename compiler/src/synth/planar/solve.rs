//! Synthesis of a planar mechanism from a request as the CLI (or any front
//! end) makes it: the target file read, the goal and its parameters
//! resolved by name, the search run, and every solution written into the
//! mechanism's file and verified from that file.

use std::time::Instant;

use super::{Constraints, Design, Goal, Problem};
use crate::assemble::rewrite_positions;
use crate::model::{Format, Mechanism};
use crate::synth::search::{self, Objective, Options, Progress, Stop};
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
    pub margins: Vec<super::Margin>,
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

/// The problem a request asks on `m`.
pub fn problem(m: &Mechanism, request: &Request) -> Result<Problem, String> {
    let design = Design::new(m).map_err(|e| e.to_string())?;
    let input = driving_input(m, request.input.as_deref())?;
    let (name, text) = &request.targets;
    let marker_of = |n: &str| {
        m.find_marker(n).ok_or_else(|| {
            format!(
                "no marker '{n}': name it as body.marker, one of {}",
                names(m.all_markers().map(|id| m.marker_name(id)))
            )
        })
    };
    let given = |g: Option<bool>, cols: usize| {
        match (g, cols) {
        (Some(true), 2) | (Some(false), 3) => Err(format!(
            "{name}: {cols} columns do not fit --timing {}: given timing reads the input first (input,x,y), free timing does not",
            if g == Some(true) { "given" } else { "free" }
        )),
        _ => Ok(cols == 3 || cols == 4),
    }
    };
    let goal = match &request.kind {
        Kind::Path { marker, given: g } => {
            let rows = target::read(
                name,
                text,
                &[2, 3],
                "x,y (free timing) or input,x,y (given timing)",
            )?;
            let timed = given(*g, rows[0].values.len())?;
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
            let timed = given(*g, cols - 1)?;
            let v = |r: &target::Row, k: usize| r.values[k + usize::from(timed)];
            Goal::Motion {
                body: b,
                marker,
                poses: rows.iter().map(|r| [v(r, 0), v(r, 1), v(r, 2)]).collect(),
                inputs: timed.then(|| rows.iter().map(|r| r.values[0]).collect()),
            }
        }
    };
    let vary = varied(&design, request.vary.as_deref())?;
    let bounds = boxes(&design, &goal, &vary, request)?;
    Problem::new(design, goal, input, vary, bounds, request.constraints).map_err(|e| e.to_string())
}

fn names(it: impl Iterator<Item = String>) -> String {
    let v: Vec<String> = it.collect();
    v.join(", ")
}

/// The input that drives the synthesis.
fn driving_input(m: &Mechanism, name: Option<&str>) -> Result<usize, String> {
    match name {
        Some(n) => (m.inputs.iter().position(|i| i.name == n)).ok_or_else(|| {
            format!(
                "no input '{n}': one of {}",
                names(m.inputs.iter().map(|i| i.name.clone()))
            )
        }),
        None => match (&m.sweep, m.inputs.len()) {
            (Some(s), _) => Ok(s.primary().input),
            (None, 1) => Ok(0),
            (None, 0) => Err("the mechanism has no input to drive".into()),
            _ => Err(format!(
                "the mechanism has several inputs: choose one with --input ({})",
                names(m.inputs.iter().map(|i| i.name.clone()))
            )),
        },
    }
}

/// The indices of the parameters `vary` names (all when `None`).
fn varied(design: &Design, vary: Option<&[String]>) -> Result<Vec<usize>, String> {
    let Some(vary) = vary else {
        return Ok((0..design.names().len()).collect());
    };
    let mut out = Vec::new();
    for v in vary {
        let found: Vec<usize> = match design.index(v) {
            Ok(k) => vec![k],
            Err(e) => match design.nodes().iter().position(|n| &n.name == v) {
                Some(n) => vec![2 * n, 2 * n + 1],
                None => return Err(e.to_string()),
            },
        };
        for k in found {
            if !out.contains(&k) {
                out.push(k);
            }
        }
    }
    if out.is_empty() {
        return Err("--vary names no parameter".into());
    }
    Ok(out)
}

/// The box of every varied parameter: a point's own `--bounds NAME=…`, or
/// the common `--bounds`, or by default the box around the drawing and the
/// targets, widened by half its larger side on every side.
fn boxes(design: &Design, goal: &Goal, vary: &[usize], request: &Request) -> Result<Vec<[f64; 2]>, String> {
    for (n, _) in &request.point_bounds {
        if !design.nodes().iter().any(|x| &x.name == n) {
            return Err(format!(
                "--bounds {n}=…: no point '{n}': one of {}",
                names(design.nodes().iter().map(|x| x.name.clone()))
            ));
        }
    }
    let default = request.bounds.unwrap_or_else(|| {
        let mut pts: Vec<[f64; 2]> = design.nodes().iter().map(|n| n.at).collect();
        match goal {
            Goal::Path { points, .. } => pts.extend(points),
            Goal::Motion { poses, .. } => pts.extend(poses.iter().map(|p| [p[0], p[1]])),
            Goal::Function { .. } => {}
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &pts {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let pad = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]).max(1e-9);
        [lo[0] - pad, lo[1] - pad, hi[0] + pad, hi[1] + pad]
    });
    Ok(vary
        .iter()
        .map(|&k| {
            let node = &design.nodes()[k / 2].name;
            let b = (request.point_bounds.iter().find(|(n, _)| n == node)).map_or(default, |(_, b)| *b);
            [b[k % 2], b[2 + k % 2]]
        })
        .collect())
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
    let start = Instant::now();
    let outcome = search::run(problem, options, progress);
    let (mut solutions, mut rejected) = (Vec::new(), Vec::new());
    for found in &outcome.found {
        match verify(m, text, format, problem, &found.z) {
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
        names: problem.design().names().to_vec(),
        varied: problem.vary().to_vec(),
        solutions,
        evaluations: outcome.evaluations,
        seconds: start.elapsed().as_secs_f64(),
        stop: outcome.stop,
        rejected,
    })
}

/// The residuals' size per target.
pub fn stats(problem: &Problem, residuals: &[f64]) -> ErrorStats {
    let n = problem.goal().len().max(1);
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
        .map(|(r, _)| stats(problem, r.as_slice()));
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
    let from_file = Problem::new(
        again,
        problem.goal().clone(),
        problem.input(),
        problem.vary().to_vec(),
        problem.bounds().to_vec(),
        problem.constraints(),
    )
    .map_err(|e| e.to_string())?;
    let (r, _) = from_file
        .residuals(&z2, false)
        .ok_or("a solution whose written file does not reach every target where the search's candidate did (a frame at the edge of its reach)")?;
    let error = stats(problem, r.as_slice());
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
