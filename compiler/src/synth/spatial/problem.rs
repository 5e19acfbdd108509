//! Spatial synthesis problems: function generation (a revolute joint's
//! angle at given input values), motion generation (a body's marker
//! position and the body's turn at given input values) and path
//! generation (a marker's position, at given input values or, free
//! timing, at input values that are unknowns of their own),
//! searched as the planar problems are (`synth/search.rs`), with the exact
//! Jacobians of `synth/spatial/gradient.rs`.

use dofplan_runtime::spatial::rows::WorldFrame;
use dofplan_runtime::spatial::{cross, cst, dot, Pose3, Vec3};
use dofplan_runtime::{Driver, Options};
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};

use super::{sensitivity, Candidate, Design};
use crate::interp::spatial::InterpState;
use crate::model::spatial::{JointKind, Mechanism};
use crate::model::{InputKind, MarkerId};
use crate::synth::search::{penalised, Objective, FAILED};
use crate::synth::solution::Margin;
use crate::synth::{timing, SynthError};

/// A spatial function-generation problem: at each input value, the output
/// revolute joint's angle (degrees, the second marker's x turned about the
/// first marker's z, 0 as drawn) is the target's.
#[derive(Clone, Debug)]
pub struct Function {
    varied: Varied,
    joint: usize,
    pairs: Vec<[f64; 2]>,
}

/// What both problems share: the design, the input the targets are given
/// for (the others at 0), the parameters varied within their box, and the
/// drawn values of the rest.
#[derive(Clone, Debug)]
struct Varied {
    design: Design,
    input: usize,
    vary: Vec<usize>,
    bounds: Vec<[f64; 2]>,
    base: Vec<f64>,
    constraints: Constraints,
}

/// The constraints a spatial solution keeps. (A transmission angle is a
/// planar four-bar loop's: spatial files have no `min_transmission`.)
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Constraints {
    /// The input (an angle) turns through 360° without a break: every
    /// frame of a sampled turn solves, and the driver looks between
    /// samples for a gap narrower than their step.
    pub full_turn: bool,
    /// Longest over shortest link at most this (a link's length: the
    /// largest distance between two joints on it).
    pub max_ratio: Option<f64>,
}

impl Varied {
    /// Checks that the box holds the drawing.
    fn new(
        design: Design,
        input: usize,
        vary: Vec<usize>,
        bounds: Vec<[f64; 2]>,
    ) -> Result<Varied, SynthError> {
        let base = design.drawn();
        for (k, &v) in vary.iter().enumerate() {
            let [lo, hi] = bounds[k];
            if !(lo <= base[v] && base[v] <= hi) {
                return Err(SynthError::Bounds {
                    name: design.names()[v].clone(),
                    value: base[v],
                    bounds: [lo, hi],
                });
            }
        }
        Ok(Varied {
            design,
            input,
            vary,
            bounds,
            base,
            constraints: Constraints::default(),
        })
    }

    /// The same parameters varied within the same box, under the same
    /// constraints, on another drawing of the mechanism (a solution's
    /// written file).
    ///
    /// The box is widened to hold the file's values: a file is written to
    /// within 1e-12 of the mechanism's size, so a solution on the box's
    /// edge may read back a hair outside it.
    fn on(&self, design: Design) -> Result<Varied, SynthError> {
        let drawn = design.drawn();
        let bounds = (self.vary.iter().zip(&self.bounds))
            .map(|(&v, &[lo, hi])| [lo.min(drawn[v]), hi.max(drawn[v])])
            .collect();
        let mut v = Varied::new(design, self.input, self.vary.clone(), bounds)?;
        v.constraints = self.constraints;
        Ok(v)
    }

    /// Sets the constraints, refusing a full turn of a slide.
    fn constrain(&mut self, constraints: Constraints) -> Result<(), SynthError> {
        let input = &self.design.mechanism().inputs[self.input];
        if constraints.full_turn && input.kind != InputKind::Angle {
            return Err(SynthError::Goal {
                reason: format!(
                    "--full-turn asks the input to turn through 360°, and {} is a slide",
                    input.name
                ),
            });
        }
        self.constraints = constraints;
        Ok(())
    }

    /// Each constraint's margin at the varied parameters `x` (negative:
    /// broken), a full turn sampled at `samples` frames; `None` for a
    /// candidate that cannot be prepared.
    fn margins_at(&self, x: &[f64], samples: usize) -> Option<Vec<Margin>> {
        let k = self.constraints;
        if !k.full_turn && k.max_ratio.is_none() {
            return Some(Vec::new());
        }
        let c = self.design.prepare(&self.values(&x[..self.vary.len()])).ok()?;
        let mut margins = Vec::new();
        if k.full_turn {
            let frames = self.sample(&c, [0.0, 360.0], samples);
            let failed = frames.iter().filter(|f| f.is_none()).count() as f64;
            margins.push(Margin {
                name: "full-turn",
                value: if failed == 0.0 { 1.0 } else { 0.0 },
                // 0, not −0, when every frame solves.
                margin: 0.0 - failed,
            });
        }
        if let Some(r) = k.max_ratio {
            let ratio = link_ratio(&c.mechanism);
            margins.push(Margin {
                name: "max-ratio",
                value: ratio,
                margin: r - ratio,
            });
        }
        Some(margins)
    }

    /// The global search's fitness: `error` (`None`: the candidate fails)
    /// penalised by how far the constraints are broken at `x`.
    fn fitness(&self, x: &[f64], error: Option<f64>) -> f64 {
        let Some(error) = error else { return FAILED };
        match self.margins_at(x, SAMPLES) {
            Some(m) => penalised(error, m.iter().map(|m| (-m.margin).max(0.0)).sum()),
            None => FAILED,
        }
    }

    /// Whether the constraints hold at the polish's unknowns `z`.
    fn feasible(&self, z: &[f64]) -> bool {
        (self.margins_at(z, SAMPLES)).is_some_and(|m| m.iter().all(|m| m.margin >= 0.0))
    }

    /// Every parameter's value for the varied ones at `x`.
    fn values(&self, x: &[f64]) -> Vec<f64> {
        let mut p = self.base.clone();
        for (k, &v) in self.vary.iter().enumerate() {
            p[v] = x[k];
        }
        p
    }

    /// The input range a solution's picture runs over: a whole turn for
    /// `--full-turn`, else the search's range where the file gives one
    /// (its sweep of the input, or a turn of an angle), else the span of
    /// the targets' input values `given` (and the drawing's 0).
    fn shown(&self, given: impl Iterator<Item = f64>) -> [f64; 2] {
        if self.constraints.full_turn {
            return [0.0, 360.0];
        }
        self.range().unwrap_or_else(|_| {
            let (lo, hi) = given.fold((0.0f64, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
            [lo, hi]
        })
    }

    fn request(&self, value: f64) -> Vec<f64> {
        let mut inputs = vec![0.0; self.design.mechanism().inputs.len()];
        inputs[self.input] = value;
        inputs
    }

    /// The candidate's poses at the inputs `at`, run up from its drawing
    /// in steps of at most 5° (down for negative inputs).
    fn reach(&self, c: &Candidate, at: &[f64]) -> Option<Vec<Vec<Pose3>>> {
        let frames = self.reach_states(c, at)?;
        Some(frames.into_iter().map(|(poses, _)| poses).collect())
    }

    /// [`Varied::reach`] with each frame's state (what its rates are
    /// computed from).
    fn reach_states(&self, c: &Candidate, at: &[f64]) -> Option<Vec<(Vec<Pose3>, InterpState)>> {
        crate::synth::reach::reach(&c.interpreter, at, 5.0, |v| self.request(v))
    }

    /// The candidate's frames at `samples + 1` inputs evenly over `range`,
    /// driven there from its drawing (`None` where a frame is not solved).
    fn sample(&self, c: &Candidate, range: [f64; 2], samples: usize) -> Vec<Option<Vec<Pose3>>> {
        let mut driver = Driver::new(&c.interpreter, Options::default());
        let [a, b] = range;
        if a != 0.0 {
            let n = (a.abs() / 5.0).ceil() as usize;
            for s in 1..=n {
                driver.frame(&self.request(a * s as f64 / n as f64));
            }
        }
        (0..=samples)
            .map(|s| {
                let v = a + (b - a) * s as f64 / samples as f64;
                (driver.frame(&self.request(v)).is_solved()).then(|| driver.poses().to_vec())
            })
            .collect()
    }

    /// The range of the input a curve is sampled over: the sweep's, if it
    /// sweeps this input, else a whole turn of an angle.
    fn range(&self) -> Result<[f64; 2], SynthError> {
        let m = self.design.mechanism();
        match (&m.sweep, m.inputs[self.input].kind) {
            (Some(s), _) if s.primary().input == self.input => Ok([s.primary().from, s.primary().to]),
            (_, InputKind::Angle) => Ok([0.0, 360.0]),
            _ => Err(SynthError::Goal {
                reason: format!(
                    "the slide input {} has no range to search: give the file a [sweep] of it",
                    m.inputs[self.input].name
                ),
            }),
        }
    }
}

/// Samples of the input's range a candidate's curve is read at (free
/// timing).
const SAMPLES: usize = 180;

/// Longest over shortest link of `m`: a link's length is the largest
/// distance between two joints' markers on it; bodies with fewer than two
/// are not links. Infinite if a link has length 0.
pub fn link_ratio(m: &Mechanism) -> f64 {
    let mut in_joint: Vec<Vec<Vec3>> = vec![Vec::new(); m.bodies.len()];
    for j in &m.joints {
        for id in j.markers {
            in_joint[id.body].push(m.marker(id).at);
        }
    }
    let lengths = (in_joint.iter()).filter(|p| p.len() >= 2).map(|p| {
        let mut l = 0.0f64;
        for (i, a) in p.iter().enumerate() {
            for b in &p[i + 1..] {
                l = l.max(dofplan_runtime::spatial::norm(dofplan_runtime::spatial::sub(
                    *a, *b,
                )));
            }
        }
        l
    });
    let (lo, hi) = lengths.fold((f64::INFINITY, 0.0f64), |(lo, hi), l| (lo.min(l), hi.max(l)));
    if lo > 0.0 {
        hi / lo
    } else {
        f64::INFINITY
    }
}

/// The output angle of a revolute joint at `poses`, degrees, 0 as drawn.
pub fn output(m: &Mechanism, joint: usize, poses: &[Pose3]) -> f64 {
    let twist = |poses: Option<&[Pose3]>| {
        let [a, b] = m.joints[joint].markers;
        let frame = |id: crate::model::MarkerId| {
            let mk = m.marker(id);
            let axes = mk
                .axes
                .or(m.marker(a).axes)
                .expect("a revolute joint's first marker has axes");
            let pose = poses.map_or(Pose3::IDENTITY, |p| p[id.body]);
            WorldFrame::of(&pose, mk.at, axes.z, axes.x)
        };
        let (f1, f2) = (frame(a), frame(b));
        dot(f2.x, f1.y()).atan2(dot(f2.x, f1.x))
    };
    let d = twist(Some(poses)) - twist(None);
    let t = std::f64::consts::TAU;
    let w = d.rem_euclid(t);
    (if w > std::f64::consts::PI { w - t } else { w }).to_degrees()
}

/// The derivative of [`output`] along body turns `wa`, `wb` (angular
/// velocities of the joint's two bodies).
fn output_rate(m: &Mechanism, joint: usize, poses: &[Pose3], wa: Vec3, wb: Vec3) -> f64 {
    let [a, b] = m.joints[joint].markers;
    let axes = |id: crate::model::MarkerId| {
        m.marker(id)
            .axes
            .or(m.marker(a).axes)
            .expect("a revolute joint's first marker has axes")
    };
    let f1 = WorldFrame::of(&poses[a.body], m.marker(a).at, axes(a).z, axes(a).x);
    let f2 = WorldFrame::of(&poses[b.body], m.marker(b).at, axes(b).z, axes(b).x);
    let y1 = f1.y();
    let (p, q) = (dot(f2.x, y1), dot(f2.x, f1.x));
    let dx2 = cross(wb, f2.x);
    let (dx1, dy1) = (cross(wa, f1.x), cross(wa, y1));
    let dp = dot(dx2, y1) + dot(f2.x, dy1);
    let dq = dot(dx2, f1.x) + dot(f2.x, dx1);
    ((q * dp - p * dq) / (p * p + q * q)).to_degrees()
}

impl Function {
    /// The problem of making joint `joint` (a revolute joint) follow
    /// `pairs` (input value, output degrees) as input `input` moves,
    /// varying the parameters `vary` within `bounds`.
    pub fn new(
        design: Design,
        joint: usize,
        pairs: Vec<[f64; 2]>,
        input: usize,
        vary: Vec<usize>,
        bounds: Vec<[f64; 2]>,
    ) -> Result<Function, SynthError> {
        let m = design.mechanism();
        if m.joints[joint].kind != JointKind::Revolute {
            return Err(SynthError::Goal {
                reason: format!(
                    "joint {} is not revolute: spatial function generation reads a revolute joint's angle",
                    m.joints[joint].name
                ),
            });
        }
        Ok(Function {
            varied: Varied::new(design, input, vary, bounds)?,
            joint,
            pairs,
        })
    }

    /// Every parameter's value for the varied ones at `x`.
    pub fn values(&self, x: &[f64]) -> Vec<f64> {
        self.varied.values(x)
    }

    /// The design the problem varies.
    pub fn design(&self) -> &Design {
        &self.varied.design
    }

    /// The varied parameters' indices.
    pub fn vary(&self) -> &[usize] {
        &self.varied.vary
    }

    /// The input range a solution's picture runs over (see
    /// `Varied::shown`).
    pub fn shown_range(&self) -> [f64; 2] {
        self.varied.shown(self.pairs.iter().map(|p| p[0]))
    }

    /// The driving input.
    pub fn input(&self) -> usize {
        self.varied.input
    }

    /// The problem with `constraints` kept (a full turn refused for a
    /// slide input).
    pub fn constrained(mut self, constraints: Constraints) -> Result<Self, SynthError> {
        self.varied.constrain(constraints)?;
        Ok(self)
    }

    /// Every constraint's margin at the polish's unknowns `z`, a full turn
    /// measured on eight times the search's samples (a quarter degree
    /// apart), so that what the search kept between its samples is checked
    /// between them too.
    pub fn margins(&self, z: &[f64]) -> Option<Vec<Margin>> {
        self.varied.margins_at(z, 8 * SAMPLES)
    }

    /// The output joint.
    pub fn joint(&self) -> usize {
        self.joint
    }

    /// The targets: (input value, output degrees).
    pub fn pairs(&self) -> &[[f64; 2]] {
        &self.pairs
    }

    /// The same goal on another drawing (a solution's written file).
    pub fn on(&self, design: Design) -> Result<Function, SynthError> {
        Ok(Function {
            varied: self.varied.on(design)?,
            joint: self.joint,
            pairs: self.pairs.clone(),
        })
    }
}

impl Objective for Function {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.varied.bounds
    }

    fn fitness(&self, x: &[f64]) -> f64 {
        let error = self.residuals(x, false).map(|(r, _)| r.norm_squared());
        self.varied.fitness(x, error)
    }

    fn feasible(&self, z: &[f64]) -> bool {
        self.varied.feasible(z)
    }

    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)> {
        let v = &self.varied;
        let c = v.design.prepare(&v.values(z)).ok()?;
        let at: Vec<f64> = self.pairs.iter().map(|p| p[0]).collect();
        let frames = v.reach(&c, &at)?;
        let m = &c.mechanism;
        let r: Vec<f64> = (frames.iter().zip(&self.pairs))
            .map(|(poses, p)| {
                let d = output(m, self.joint, poses) - p[1];
                // The nearer turn: a target of 179° and an output of −179° are 2° apart.
                d - 360.0 * (d / 360.0).round()
            })
            .collect();
        if !jacobian {
            return Some((DVector::from_vec(r), None));
        }
        let [a, b] = m.joints[self.joint].markers;
        let mut j = DMatrix::zeros(r.len(), v.vary.len());
        for (i, poses) in frames.iter().enumerate() {
            let s = sensitivity(&v.design, &c, poses, &v.request(self.pairs[i][0])).ok()?;
            if !(s.turn_determined(a.body) && s.turn_determined(b.body)) {
                return None;
            }
            let (ta, tb) = (s.turn(a.body), s.turn(b.body));
            for (k, &p) in v.vary.iter().enumerate() {
                j[(i, k)] = output_rate(m, self.joint, poses, ta[p], tb[p]);
            }
        }
        Some((DVector::from_vec(r), Some(j)))
    }
}

/// One target pose of a spatial body: at input value `input`, its marker
/// at `at` and the body turned from its drawn pose by the rotation vector
/// `turn` (axis times angle, degrees).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyPose {
    /// The input value.
    pub input: f64,
    /// The marker's world position.
    pub at: [f64; 3],
    /// The body's turn from its drawn pose, as a rotation vector in
    /// degrees.
    pub turn: [f64; 3],
}

/// A spatial motion-generation problem: at each target's input value, the
/// body's marker is at the target's position and the body is turned as
/// the target says. Six residuals a target: the position error, and the
/// turn error (the rotation vector of the target's rotation to the body's,
/// radians) times the drawing's size, so a radian weighs as much as the
/// mechanism's size, as in the plane.
#[derive(Clone, Debug)]
pub struct Motion {
    varied: Varied,
    marker: MarkerId,
    poses: Vec<BodyPose>,
    weight: f64,
}

/// The rotation of the rotation vector `v` (radians).
fn rotation(v: [f64; 3]) -> Matrix3<f64> {
    Rotation3::from_scaled_axis(Vector3::from(v)).into_inner()
}

/// The rotation vector (radians) of the rotation `m`. Near the identity
/// — where a fitted body ends — the angle is taken as the arc tangent of
/// the skew part's length over the trace's cosine, which is exact to
/// round-off there; the arc cosine of the trace (nalgebra's
/// `scaled_axis`) loses half the digits (an error of 1e-8 radians, which
/// would floor a motion fit at 1e-16 in its sum of squares). Past a
/// quarter turn the skew part no longer fixes the axis's sign well, and
/// the arc cosine is accurate: nalgebra's there.
fn rotation_vector(m: &Matrix3<f64>) -> Vector3<f64> {
    let v = 0.5
        * Vector3::new(
            m[(2, 1)] - m[(1, 2)],
            m[(0, 2)] - m[(2, 0)],
            m[(1, 0)] - m[(0, 1)],
        );
    let (sin, cos) = (v.norm(), 0.5 * (m.trace() - 1.0));
    if cos <= 0.0 {
        return Rotation3::from_matrix_unchecked(*m).scaled_axis();
    }
    if sin == 0.0 {
        return Vector3::zeros();
    }
    v * (sin.atan2(cos) / sin)
}

/// The inverse of SO(3)'s left Jacobian at the rotation vector `r`: how a
/// rotation vector moves when its rotation turns by a small world rotation
/// (`d r = J⁻¹(r) dω`).
fn inverse_left_jacobian(r: Vector3<f64>) -> Matrix3<f64> {
    let theta = r.norm();
    let k = r.cross_matrix();
    // (1/θ² − (1 + cos θ)/(2θ sin θ)), 1/12 + θ²/720 near 0.
    let c = if theta < 1e-4 {
        1.0 / 12.0 + theta * theta / 720.0
    } else {
        1.0 / (theta * theta) - (1.0 + theta.cos()) / (2.0 * theta * theta.sin())
    };
    Matrix3::identity() - 0.5 * k + c * k * k
}

impl Motion {
    /// The problem of moving the body of `marker` through `poses` as input
    /// `input` moves, varying the parameters `vary` within `bounds`.
    pub fn new(
        design: Design,
        marker: MarkerId,
        poses: Vec<BodyPose>,
        input: usize,
        vary: Vec<usize>,
        bounds: Vec<[f64; 2]>,
    ) -> Result<Motion, SynthError> {
        let m = design.mechanism();
        if m.bodies[marker.body].fixed {
            return Err(SynthError::Goal {
                reason: format!(
                    "body {} is fixed: it has no motion to generate",
                    m.bodies[marker.body].name
                ),
            });
        }
        let weight = m.size();
        Ok(Motion {
            varied: Varied::new(design, input, vary, bounds)?,
            marker,
            poses,
            weight,
        })
    }

    /// Every parameter's value for the varied ones at `x`.
    pub fn values(&self, x: &[f64]) -> Vec<f64> {
        self.varied.values(x)
    }

    /// The design the problem varies.
    pub fn design(&self) -> &Design {
        &self.varied.design
    }

    /// The varied parameters' indices.
    pub fn vary(&self) -> &[usize] {
        &self.varied.vary
    }

    /// The input range a solution's picture runs over (see
    /// `Varied::shown`).
    pub fn shown_range(&self) -> [f64; 2] {
        self.varied.shown(self.poses.iter().map(|p| p.input))
    }

    /// The driving input.
    pub fn input(&self) -> usize {
        self.varied.input
    }

    /// The problem with `constraints` kept (a full turn refused for a
    /// slide input).
    pub fn constrained(mut self, constraints: Constraints) -> Result<Self, SynthError> {
        self.varied.constrain(constraints)?;
        Ok(self)
    }

    /// Every constraint's margin at the polish's unknowns `z`, a full turn
    /// measured on eight times the search's samples (a quarter degree
    /// apart), so that what the search kept between its samples is checked
    /// between them too.
    pub fn margins(&self, z: &[f64]) -> Option<Vec<Margin>> {
        self.varied.margins_at(z, 8 * SAMPLES)
    }

    /// The marker whose position is the body's.
    pub fn marker(&self) -> MarkerId {
        self.marker
    }

    /// The target poses.
    pub fn poses(&self) -> &[BodyPose] {
        &self.poses
    }

    /// The same goal on another drawing (a solution's written file).
    pub fn on(&self, design: Design) -> Result<Motion, SynthError> {
        Ok(Motion {
            varied: self.varied.on(design)?,
            marker: self.marker,
            poses: self.poses.clone(),
            weight: self.weight,
        })
    }
}

impl Objective for Motion {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.varied.bounds
    }

    fn fitness(&self, x: &[f64]) -> f64 {
        let error = self.residuals(x, false).map(|(r, _)| r.norm_squared());
        self.varied.fitness(x, error)
    }

    fn feasible(&self, z: &[f64]) -> bool {
        self.varied.feasible(z)
    }

    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)> {
        let v = &self.varied;
        let c = v.design.prepare(&v.values(z)).ok()?;
        let at: Vec<f64> = self.poses.iter().map(|p| p.input).collect();
        let frames = v.reach(&c, &at)?;
        let (body, local) = (self.marker.body, c.mechanism.marker(self.marker).at);
        let n = self.poses.len();
        let mut r = DVector::zeros(6 * n);
        let mut j = jacobian.then(|| DMatrix::zeros(6 * n, v.vary.len()));
        for (i, (poses, target)) in frames.iter().zip(&self.poses).enumerate() {
            let pose = poses[body];
            let w = pose.world(local);
            let rt = rotation(target.turn.map(f64::to_radians));
            let turned = Matrix3::from_fn(|a, b| pose.rot.m[a][b]);
            let e = rotation_vector(&(rt.transpose() * turned));
            for k in 0..3 {
                r[6 * i + k] = w[k] - target.at[k];
                r[6 * i + 3 + k] = self.weight * e[k];
            }
            let Some(j) = j.as_mut() else { continue };
            let s = sensitivity(&v.design, &c, poses, &v.request(target.input)).ok()?;
            if !(s.determined(self.marker) && s.turn_determined(body)) {
                return None;
            }
            let (dm, dt) = (s.marker(self.marker), s.turn(body));
            let turn_rate = self.weight * inverse_left_jacobian(e) * rt.transpose();
            for (k, &p) in v.vary.iter().enumerate() {
                let de = turn_rate * Vector3::from(dt[p]);
                for a in 0..3 {
                    j[(6 * i + a, k)] = dm[p][a];
                    j[(6 * i + 3 + a, k)] = de[a];
                }
            }
        }
        Some((r, j))
    }
}

/// A spatial path-generation problem: the marker passes through the
/// target points, at the input values given with them (given timing) or
/// at input values of its own, one unknown a point (free timing). Three
/// residuals a target: the position error.
#[derive(Clone, Debug)]
pub struct Path {
    varied: Varied,
    marker: MarkerId,
    points: Vec<[f64; 3]>,
    /// Each point's input value (given timing), or `None` (free timing).
    inputs: Option<Vec<f64>>,
    /// Free timing: the input's range the candidates' curves are sampled
    /// over.
    range: [f64; 2],
}

impl Path {
    /// The problem of moving `marker` through `points` (world points) as
    /// input `input` moves, at the input values `inputs` (given timing) or
    /// at any (free timing, `None`), varying the parameters `vary` within
    /// `bounds`.
    pub fn new(
        design: Design,
        marker: MarkerId,
        points: Vec<[f64; 3]>,
        inputs: Option<Vec<f64>>,
        input: usize,
        vary: Vec<usize>,
        bounds: Vec<[f64; 2]>,
    ) -> Result<Path, SynthError> {
        let m = design.mechanism();
        if m.bodies[marker.body].fixed {
            return Err(SynthError::Goal {
                reason: format!(
                    "marker {} is on the fixed body: it has no path to generate",
                    m.marker_name(marker)
                ),
            });
        }
        let varied = Varied::new(design, input, vary, bounds)?;
        // A point an idle spin turns (off the axis of an RSSR's coupler)
        // has no path the input decides: refused here, where it can be
        // said, rather than failing every candidate's derivatives.
        let drawn = varied.design.prepare(&varied.base)?;
        let frames = varied.reach(&drawn, &[0.0]).ok_or_else(|| SynthError::Goal {
            reason: "the drawing does not run at input 0".into(),
        })?;
        let s = sensitivity(&varied.design, &drawn, &frames[0], &varied.request(0.0))?;
        if !s.determined(marker) {
            return Err(SynthError::Goal {
                reason: format!(
                    "marker {} moves with an idle spin of its body (a spin no input drives), so its path is not determined: trace a point on the spin's axis, or on another body",
                    varied.design.mechanism().marker_name(marker)
                ),
            });
        }
        let range = match inputs {
            Some(_) => [0.0, 0.0],
            None => varied.range()?,
        };
        Ok(Path {
            varied,
            marker,
            points,
            inputs,
            range,
        })
    }

    /// Every parameter's value for the varied ones at `x`.
    pub fn values(&self, x: &[f64]) -> Vec<f64> {
        self.varied.values(x)
    }

    /// The design the problem varies.
    pub fn design(&self) -> &Design {
        &self.varied.design
    }

    /// The varied parameters' indices.
    pub fn vary(&self) -> &[usize] {
        &self.varied.vary
    }

    /// The input range a solution's picture runs over (see
    /// `Varied::shown`).
    pub fn shown_range(&self) -> [f64; 2] {
        match &self.inputs {
            Some(inputs) => self.varied.shown(inputs.iter().copied()),
            None => self.range,
        }
    }

    /// The driving input.
    pub fn input(&self) -> usize {
        self.varied.input
    }

    /// The problem with `constraints` kept (a full turn refused for a
    /// slide input).
    pub fn constrained(mut self, constraints: Constraints) -> Result<Self, SynthError> {
        self.varied.constrain(constraints)?;
        Ok(self)
    }

    /// Every constraint's margin at the polish's unknowns `z`, a full turn
    /// measured on eight times the search's samples (a quarter degree
    /// apart), so that what the search kept between its samples is checked
    /// between them too.
    pub fn margins(&self, z: &[f64]) -> Option<Vec<Margin>> {
        self.varied.margins_at(z, 8 * SAMPLES)
    }

    /// The marker that passes the points.
    pub fn marker(&self) -> MarkerId {
        self.marker
    }

    /// The target points.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }

    /// Each point's input value (given timing), or `None` (free timing).
    pub fn inputs(&self) -> Option<&[f64]> {
        self.inputs.as_deref()
    }

    /// The same goal on another drawing (a solution's written file).
    pub fn on(&self, design: Design) -> Result<Path, SynthError> {
        Ok(Path {
            varied: self.varied.on(design)?,
            marker: self.marker,
            points: self.points.clone(),
            inputs: self.inputs.clone(),
            range: self.range,
        })
    }

    /// Free timing: the candidate at `x` (the varied parameters), the sum
    /// over targets of the squared distance to its sampled curve, and
    /// each target's input at the nearest point.
    fn nearest(&self, x: &[f64]) -> Option<(f64, Vec<f64>)> {
        let v = &self.varied;
        let c = v.design.prepare(&v.values(x)).ok()?;
        let local = c.mechanism.marker(self.marker).at;
        // A full turn is searched whole, whatever the sweep's range.
        let range = match v.constraints.full_turn {
            true => [0.0, 360.0],
            false => self.range,
        };
        let curve: Vec<Option<[f64; 3]>> = (v.sample(&c, range, SAMPLES).iter())
            .map(|f| f.as_ref().map(|poses| poses[self.marker.body].world(local)))
            .collect();
        let [a, b] = range;
        let input_of = |s: usize| a + (b - a) * s as f64 / SAMPLES as f64;
        timing::nearest(&curve, input_of, self.points.iter().copied())
    }

    /// The marker's velocity along the input at a frame (per degree or
    /// per length), from the plan's exact rates.
    fn input_rate(&self, c: &Candidate, state: &InterpState, inputs: &[f64]) -> Option<Vec3> {
        let mut rates = vec![0.0; inputs.len()];
        rates[self.varied.input] = 1.0;
        let zero = vec![0.0; inputs.len()];
        let jets = c.interpreter.rates(state, inputs, &rates, &zero).ok()?;
        let local = c.mechanism.marker(self.marker).at;
        let w = jets[self.marker.body].world(cst(local));
        Some([w[0].d, w[1].d, w[2].d])
    }
}

impl Objective for Path {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.varied.bounds
    }

    fn fitness(&self, x: &[f64]) -> f64 {
        let error = match self.inputs {
            Some(_) => self.residuals(x, false).map(|(r, _)| r.norm_squared()),
            None => self.nearest(x).map(|(e, _)| e),
        };
        self.varied.fitness(x, error)
    }

    fn feasible(&self, z: &[f64]) -> bool {
        self.varied.feasible(z)
    }

    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        match self.inputs {
            Some(_) => Some(x.to_vec()),
            None => Some(x.iter().copied().chain(self.nearest(x)?.1).collect()),
        }
    }

    /// The unknowns `z`: the varied parameters, then (free timing) each
    /// target's input value.
    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)> {
        let v = &self.varied;
        let nv = v.vary.len();
        let c = v.design.prepare(&v.values(&z[..nv])).ok()?;
        let at: Vec<f64> = self.inputs.clone().unwrap_or_else(|| z[nv..].to_vec());
        let frames = v.reach_states(&c, &at)?;
        let (body, local) = (self.marker.body, c.mechanism.marker(self.marker).at);
        let n = self.points.len();
        let cols = nv + if self.inputs.is_some() { 0 } else { n };
        let mut r = DVector::zeros(3 * n);
        let mut j = jacobian.then(|| DMatrix::zeros(3 * n, cols));
        for (i, ((poses, state), target)) in frames.iter().zip(&self.points).enumerate() {
            let w = poses[body].world(local);
            for k in 0..3 {
                r[3 * i + k] = w[k] - target[k];
            }
            let Some(j) = j.as_mut() else { continue };
            let inputs = v.request(at[i]);
            let s = sensitivity(&v.design, &c, poses, &inputs).ok()?;
            if !s.determined(self.marker) {
                return None;
            }
            let dm = s.marker(self.marker);
            for (k, &p) in v.vary.iter().enumerate() {
                for a in 0..3 {
                    j[(3 * i + a, k)] = dm[p][a];
                }
            }
            if self.inputs.is_none() {
                let rate = self.input_rate(&c, state, &inputs)?;
                for a in 0..3 {
                    j[(3 * i + a, nv + i)] = rate[a];
                }
            }
        }
        Some((r, j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load_any_str;
    use crate::model::{Format, Model};

    fn design(text: &str) -> Design {
        match load_any_str("rssr.toml", text, Format::Toml) {
            Ok(Model::Spatial(m)) => Design::new(&m).unwrap(),
            _ => panic!("the RSSR does not load"),
        }
    }

    /// A solution on the box's edge, written to the file's digits, reads
    /// back a hair outside the box: checking it from the file must not
    /// refuse it as out of bounds.
    #[test]
    fn a_file_read_back_just_outside_the_box_is_still_checked() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../mechanisms/spatial/rssr.toml"
        ))
        .unwrap();
        let d = design(&text);
        let dx = (d.names().iter()).position(|n| n == "D.x").unwrap();
        let at = d.drawn()[dx];
        let varied = Varied::new(d, 0, vec![dx], vec![[at - 1.0, at]]).unwrap();
        let outside = text.replace("[-0.5, 3.2, 2.0]", "[-0.4999999999999, 3.2, 2.0]");
        assert_ne!(outside, text);
        let again = design(&outside);
        assert!(again.drawn()[dx] > at);
        let checked = varied
            .on(again)
            .expect("the file's value is inside the widened box");
        assert_eq!(checked.bounds[0], [at - 1.0, -0.4999999999999]);
    }
}
