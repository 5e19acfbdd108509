//! Synthesis of a spatial mechanism from a request, as
//! `synth/planar/solve.rs` does for planar ones: the target file read, the
//! goal and its parameters resolved by name, the search run, and every
//! solution written into the mechanism's file and verified from that file.
//! Path generation (a marker's position; given or free timing), function
//! generation (a revolute joint's angle) and motion generation (a body's
//! marker and turn), given timing.

use nalgebra::{DMatrix, DVector};

use super::{BodyPose, Constraints, Design, Function, Motion, Path};
use crate::assemble::rewrite_positions;
use crate::model::spatial::Mechanism;
use crate::model::{Format, Model};
use crate::synth::request::{boxes, driving_input, names, varied, Corners};
use crate::synth::search::{Objective, Options, Progress};
use crate::synth::solution::{in_order, search_and_verify, stats, Margin, Solution, Synthesis};
use crate::synth::{target, SynthError};

/// The kind of spatial synthesis and its target file.
#[derive(Clone, Debug)]
pub enum Kind {
    /// Path generation: `marker` ("body.marker") through the file's points
    /// (`input,x,y,z`, given timing, or `x,y,z`, free timing).
    Path {
        /// The marker.
        marker: String,
        /// `Some(true)`: given timing (`input,x,y,z`); `Some(false)`: free
        /// (`x,y,z`); `None`: as the file's columns say.
        given: Option<bool>,
    },
    /// Function generation: the revolute joint's angle at the file's
    /// inputs (`input,output`, degrees from the drawing).
    Function {
        /// The output joint's name.
        output: String,
    },
    /// Motion generation: the body's poses (`input,x,y,z,rx,ry,rz`: where
    /// the marker is, and the body's turn from its drawn pose as a
    /// rotation vector, axis times angle in degrees).
    Motion {
        /// The body's name.
        body: String,
        /// The marker whose position is the body's ("body.marker";
        /// default the body's first marker).
        marker: Option<String>,
    },
}

/// What to synthesise on a spatial mechanism.
#[derive(Clone, Debug)]
pub struct Request {
    /// The goal's kind.
    pub kind: Kind,
    /// The target file's name (for messages) and text.
    pub targets: (String, String),
    /// The driving input's name (default: the sweep's, or the only one).
    pub input: Option<String>,
    /// The parameters varied: names (`D.x`) or points (`D`, all three
    /// coordinates); default all.
    pub vary: Option<Vec<String>>,
    /// A box `[x0, y0, z0, x1, y1, z1]` for every varied point.
    pub bounds: Option<[f64; 6]>,
    /// Boxes for single points, by point name.
    pub point_bounds: Vec<(String, [f64; 6])>,
    /// The constraints the solutions keep.
    pub constraints: Constraints,
}

/// A spatial synthesis problem: one of the two goals.
#[derive(Clone, Debug)]
pub enum Problem {
    /// Path generation.
    Path(Path),
    /// Function generation.
    Function(Function),
    /// Motion generation.
    Motion(Motion),
}

impl Problem {
    fn objective(&self) -> &dyn Objective {
        match self {
            Problem::Path(p) => p,
            Problem::Function(f) => f,
            Problem::Motion(m) => m,
        }
    }

    /// The design the problem varies.
    pub fn design(&self) -> &Design {
        match self {
            Problem::Path(p) => p.design(),
            Problem::Function(f) => f.design(),
            Problem::Motion(m) => m.design(),
        }
    }

    /// The varied parameters' indices.
    pub fn vary(&self) -> &[usize] {
        match self {
            Problem::Path(p) => p.vary(),
            Problem::Function(f) => f.vary(),
            Problem::Motion(m) => m.vary(),
        }
    }

    /// The input range a solution's picture runs over: a whole turn for
    /// `--full-turn`, else the search's range where the file gives one,
    /// else the span of the targets' input values.
    pub fn shown_range(&self) -> [f64; 2] {
        match self {
            Problem::Path(p) => p.shown_range(),
            Problem::Function(f) => f.shown_range(),
            Problem::Motion(m) => m.shown_range(),
        }
    }

    /// The driving input.
    pub fn input(&self) -> usize {
        match self {
            Problem::Path(p) => p.input(),
            Problem::Function(f) => f.input(),
            Problem::Motion(m) => m.input(),
        }
    }

    /// Every parameter's value for the varied ones at `x`.
    pub fn values(&self, x: &[f64]) -> Vec<f64> {
        match self {
            Problem::Path(p) => p.values(x),
            Problem::Function(f) => f.values(x),
            Problem::Motion(m) => m.values(x),
        }
    }

    /// Every constraint's margin at the polish's unknowns `z` (see
    /// [`Path::margins`]).
    pub fn margins(&self, z: &[f64]) -> Option<Vec<Margin>> {
        match self {
            Problem::Path(p) => p.margins(z),
            Problem::Function(f) => f.margins(z),
            Problem::Motion(m) => m.margins(z),
        }
    }

    /// The number of targets.
    pub fn targets(&self) -> usize {
        match self {
            Problem::Path(p) => p.points().len(),
            Problem::Function(f) => f.pairs().len(),
            Problem::Motion(m) => m.poses().len(),
        }
    }

    /// The same goal on another drawing (a solution's written file).
    pub fn on(&self, design: Design) -> Result<Problem, SynthError> {
        Ok(match self {
            Problem::Path(p) => Problem::Path(p.on(design)?),
            Problem::Function(f) => Problem::Function(f.on(design)?),
            Problem::Motion(m) => Problem::Motion(m.on(design)?),
        })
    }

    /// What the goal is, in words: "function generation of joint D at 12
    /// input values".
    pub fn describe(&self) -> String {
        let m = self.design().mechanism();
        match self {
            Problem::Path(p) => format!(
                "path generation of {} through {} points ({} timing)",
                m.marker_name(p.marker()),
                p.points().len(),
                if p.inputs().is_some() { "given" } else { "free" }
            ),
            Problem::Function(f) => format!(
                "function generation of joint {} at {} input values",
                m.joints[f.joint()].name,
                f.pairs().len()
            ),
            Problem::Motion(p) => format!(
                "motion generation of {} through {} poses (given timing)",
                m.bodies[p.marker().body].name,
                p.poses().len()
            ),
        }
    }
}

impl Objective for Problem {
    fn bounds(&self) -> &[[f64; 2]] {
        self.objective().bounds()
    }

    fn fitness(&self, x: &[f64]) -> f64 {
        self.objective().fitness(x)
    }

    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        self.objective().start(x)
    }

    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)> {
        self.objective().residuals(z, jacobian)
    }

    fn feasible(&self, z: &[f64]) -> bool {
        self.objective().feasible(z)
    }
}

/// The problem a request asks on `m`.
pub fn problem(m: &Mechanism, request: &Request) -> Result<Problem, String> {
    let design = Design::new(m).map_err(|e| e.to_string())?;
    let input = driving_input(&m.inputs, m.sweep.as_ref(), request.input.as_deref())?;
    let (name, text) = &request.targets;
    let vary = varied(design.parameters(), request.vary.as_deref())?;
    let corners = |b: [f64; 6]| ([b[0], b[1], b[2]], [b[3], b[4], b[5]]);
    let point_bounds: Vec<(String, Corners<3>)> = (request.point_bounds.iter())
        .map(|(n, b)| (n.clone(), corners(*b)))
        .collect();
    let bounds = |targets: Vec<[f64; 3]>| {
        boxes(
            design.parameters(),
            targets.into_iter(),
            &vary,
            request.bounds.map(corners),
            &point_bounds,
        )
    };
    let marker_of = |n: &str| {
        m.find_marker(n).ok_or_else(|| {
            format!(
                "no marker '{n}': name it as body.marker, one of {}",
                names(m.all_markers().map(|id| m.marker_name(id)))
            )
        })
    };
    match &request.kind {
        Kind::Path { marker, given } => {
            let id = marker_of(marker)?;
            let rows = target::read(
                name,
                text,
                &[3, 4],
                "x,y,z (free timing) or input,x,y,z (given timing)",
            )?;
            let timed = target::timed(name, *given, rows[0].values.len(), 3)?;
            let v = |r: &target::Row, k: usize| r.values[k + usize::from(timed)];
            let points: Vec<[f64; 3]> = rows.iter().map(|r| [v(r, 0), v(r, 1), v(r, 2)]).collect();
            let inputs = timed.then(|| rows.iter().map(|r| r.values[0]).collect());
            let bounds = bounds(points.clone())?;
            let p = Path::new(design, id, points, inputs, input, vary, bounds);
            let p = p.and_then(|p| p.constrained(request.constraints));
            p.map(Problem::Path).map_err(|e| e.to_string())
        }
        Kind::Function { output } => {
            let joint = (m.joints.iter().position(|j| &j.name == output)).ok_or_else(|| {
                format!(
                    "no joint '{output}': one of {}",
                    names(m.joints.iter().map(|j| j.name.clone()))
                )
            })?;
            let rows = target::read(name, text, &[2], "input,output")?;
            let pairs = rows.iter().map(|r| [r.values[0], r.values[1]]).collect();
            let bounds = bounds(Vec::new())?;
            let f = Function::new(design, joint, pairs, input, vary, bounds);
            let f = f.and_then(|f| f.constrained(request.constraints));
            f.map(Problem::Function).map_err(|e| e.to_string())
        }
        Kind::Motion { body, marker } => {
            let b = (m.bodies.iter().position(|x| &x.name == body)).ok_or_else(|| {
                format!(
                    "no body '{body}': one of {}",
                    names(m.bodies.iter().map(|b| b.name.clone()))
                )
            })?;
            let first = || m.bodies[b].markers.first().map(|k| format!("{body}.{}", k.name));
            let marker_name = marker
                .clone()
                .or_else(first)
                .ok_or(format!("body {body} has no marker"))?;
            let id = marker_of(&marker_name)?;
            if id.body != b {
                return Err(format!("marker {marker_name} is not on body {body}"));
            }
            let rows = target::read(
                name,
                text,
                &[7],
                "input,x,y,z,rx,ry,rz (the marker's position; the body's turn from the drawing as a rotation vector, degrees)",
            )?;
            let poses: Vec<BodyPose> = (rows.iter())
                .map(|r| BodyPose {
                    input: r.values[0],
                    at: [r.values[1], r.values[2], r.values[3]],
                    turn: [r.values[4], r.values[5], r.values[6]],
                })
                .collect();
            let bounds = bounds(poses.iter().map(|p| p.at).collect())?;
            let p = Motion::new(design, id, poses, input, vary, bounds);
            let p = p.and_then(|p| p.constrained(request.constraints));
            p.map(Problem::Motion).map_err(|e| e.to_string())
        }
    }
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

/// Writes the solution `z` into the file and computes its error again
/// from what was written (loaded, planned and run as any file is).
fn verify(
    m: &Mechanism,
    text: &str,
    format: Format,
    problem: &Problem,
    z: &[f64],
) -> Result<Solution, String> {
    let values = problem.values(z);
    let moved = problem.design().drawing(&values).map_err(|e| e.to_string())?;
    let changes: Vec<(String, String, Vec<f64>)> = (moved.all_markers())
        .filter(|&id| moved.marker(id).at != m.marker(id).at)
        .map(|id| {
            let name = moved.marker(id).name.clone();
            (m.bodies[id.body].name.clone(), name, moved.marker(id).at.to_vec())
        })
        .collect();
    let written = rewrite_positions(text, format, m.size(), &changes)?;
    let searched = problem
        .residuals(z, false)
        .map(|(r, _)| stats(problem.targets(), r.as_slice()));
    let reloaded = match crate::load_any_str(&m.source.name, &written, format) {
        Ok(Model::Spatial(m)) => m,
        Ok(Model::Planar(_)) => {
            return Err("the solution's file reads back as planar (please report it)".into())
        }
        Err(e) => {
            return Err(format!(
                "the solution's file does not load back (please report it): {}",
                e.diagnostics.first().map_or(String::new(), |d| d.message.clone())
            ))
        }
    };
    let again = Design::new(&reloaded).map_err(|e| format!("the solution's file has no plan: {e}"))?;
    let file_values = again.drawn();
    let nv = problem.vary().len();
    let mut z2: Vec<f64> = problem.vary().iter().map(|&k| file_values[k]).collect();
    // Free timing: each target's input, as the search left it.
    z2.extend_from_slice(&z[nv..]);
    let from_file = problem.on(again).map_err(|e| e.to_string())?;
    let (r, _) = from_file
        .residuals(&z2, false)
        .ok_or("a solution whose written file does not reach every target where the search's candidate did (a frame at the edge of its reach)")?;
    let error = stats(problem.targets(), r.as_slice());
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
