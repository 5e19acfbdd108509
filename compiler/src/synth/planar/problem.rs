//! A planar synthesis problem: a goal (path, function or motion
//! generation), the parameters varied and their box, the constraints, and
//! the error of a candidate with its exact Jacobian.

use dofplan_runtime::planar::Pose;
use dofplan_runtime::real::Jet2;
use dofplan_runtime::{Driver, Options};
use nalgebra::{DMatrix, DVector};

use super::{Candidate, Design, Linearised};
use crate::analysis::planar::grashof::{four_bars, FourBar};
use crate::interp::InterpState;
use crate::model::{InputKind, JointKind, MarkerId, Mechanism};
use crate::simulate::planar::kinematics::transmission_cos;
use crate::synth::search::{penalised, Objective, FAILED};
use crate::synth::solution::Margin;
use crate::synth::timing::nearest;
use crate::synth::SynthError;

/// What the synthesised mechanism must do.
#[derive(Clone, Debug, PartialEq)]
pub enum Goal {
    /// Path generation: `marker` passes through `points`, at the given
    /// input values (given timing) or at input values of its own, one per
    /// point (free timing, `inputs` `None`).
    Path {
        /// The marker traced.
        marker: MarkerId,
        /// The target points.
        points: Vec<[f64; 2]>,
        /// The input value of each point (given timing).
        inputs: Option<Vec<f64>>,
    },
    /// Function generation: at each input value the joint's angle (degrees,
    /// from its drawn angle) or slide (from its drawn position) is the
    /// target's.
    Function {
        /// The output joint (index into the mechanism's joints).
        joint: usize,
        /// (input value, output value) pairs.
        pairs: Vec<[f64; 2]>,
    },
    /// Motion generation: the body's marker is at (x, y) and the body is
    /// turned by the angle (degrees, from its drawn pose) at each target.
    Motion {
        /// The body moved.
        body: usize,
        /// The marker whose position is the body's.
        marker: MarkerId,
        /// (x, y, angle) targets.
        poses: Vec<[f64; 3]>,
        /// The input value of each pose (given timing).
        inputs: Option<Vec<f64>>,
    },
}

impl Goal {
    /// The targets' input values (given timing), if the goal fixes them.
    pub fn inputs(&self) -> Option<Vec<f64>> {
        match self {
            Goal::Path { inputs, .. } | Goal::Motion { inputs, .. } => inputs.clone(),
            Goal::Function { pairs, .. } => Some(pairs.iter().map(|p| p[0]).collect()),
        }
    }

    /// Number of targets.
    pub fn len(&self) -> usize {
        match self {
            Goal::Path { points, .. } => points.len(),
            Goal::Function { pairs, .. } => pairs.len(),
            Goal::Motion { poses, .. } => poses.len(),
        }
    }

    /// Whether there are no targets.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Residuals per target.
    fn width(&self) -> usize {
        match self {
            Goal::Path { .. } => 2,
            Goal::Function { .. } => 1,
            Goal::Motion { .. } => 3,
        }
    }
}

/// The constraints a solution keeps.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Constraints {
    /// The input turns through 360° without a break (the crank of a
    /// crank-rocker).
    pub full_turn: bool,
    /// Every four-bar loop's transmission angle stays within [DEG, 180° −
    /// DEG] over the input's range.
    pub min_transmission: Option<f64>,
    /// Longest over shortest link at most this (a link's length: the
    /// largest distance between two joints on it).
    pub max_ratio: Option<f64>,
}

/// A synthesis problem on a planar mechanism.
#[derive(Clone, Debug)]
pub struct Problem {
    design: Design,
    goal: Goal,
    input: usize,
    vary: Vec<usize>,
    bounds: Vec<[f64; 2]>,
    constraints: Constraints,
    base: Vec<f64>,
    range: [f64; 2],
    /// The largest input step between frames when running to a target.
    step: f64,
    /// Motion: the length that one radian of turning counts as.
    weight: f64,
    loops: Vec<FourBar>,
    /// The four-bar loop the input drives at its frame, and the driven
    /// link (1 or 3): under `full_turn`, its lengths must let it turn.
    crank: Option<(usize, usize)>,
}

/// Samples of the input's range a candidate's curve is read at (free
/// timing, constraints).
const SAMPLES: usize = 180;

impl Problem {
    /// A problem on `design`, driven by input `input`, varying the
    /// parameters `vary` (indices into [`Design::names`]) within `bounds`.
    pub fn new(
        design: Design,
        goal: Goal,
        input: usize,
        vary: Vec<usize>,
        bounds: Vec<[f64; 2]>,
        constraints: Constraints,
    ) -> Result<Problem, SynthError> {
        let m = design.mechanism();
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
        let kind = m.inputs[input].kind;
        let range = match (&m.sweep, kind) {
            _ if constraints.full_turn => [0.0, 360.0],
            (Some(s), _) if s.primary().input == input => [s.primary().from, s.primary().to],
            (_, InputKind::Angle) => [0.0, 360.0],
            _ => {
                return Err(SynthError::Goal {
                    reason: format!(
                        "the slide input {} has no range to search: give the file a [sweep] of it",
                        m.inputs[input].name
                    ),
                })
            }
        };
        let step = match kind {
            InputKind::Angle => 5.0,
            InputKind::Slide => m.size() / 50.0,
        };
        let loops = four_bars(m);
        let joint = m.inputs[input].joint;
        let crank = (loops.iter().enumerate())
            .filter(|(_, f)| kind == InputKind::Angle && m.bodies[f.bodies[0]].fixed)
            .find_map(|(k, f)| match f.joints.iter().position(|&j| j == joint) {
                Some(0) => Some((k, 1)),
                Some(3) => Some((k, 3)),
                _ => None,
            });
        Ok(Problem {
            loops,
            crank,
            weight: m.size(),
            design,
            goal,
            input,
            vary,
            bounds,
            constraints,
            base,
            range,
            step,
        })
    }

    /// The design.
    pub fn design(&self) -> &Design {
        &self.design
    }

    /// The goal.
    pub fn goal(&self) -> &Goal {
        &self.goal
    }

    /// The varied parameters (indices into the design's names).
    pub fn vary(&self) -> &[usize] {
        &self.vary
    }

    /// The driving input.
    pub fn input(&self) -> usize {
        self.input
    }

    /// The range of the driving input the search reads curves over.
    pub fn range(&self) -> [f64; 2] {
        self.range
    }

    /// The constraints.
    pub fn constraints(&self) -> Constraints {
        self.constraints
    }

    /// Every parameter's value for the varied ones at `x`.
    pub fn values(&self, x: &[f64]) -> Vec<f64> {
        let mut p = self.base.clone();
        for (k, &v) in self.vary.iter().enumerate() {
            p[v] = x[k];
        }
        p
    }

    fn request(&self, value: f64) -> Vec<f64> {
        let mut inputs = vec![0.0; self.design.mechanism().inputs.len()];
        inputs[self.input] = value;
        inputs
    }

    /// Runs `c` from its drawing to every value of `at`, in steps no larger
    /// than `step`, up from 0 to the positive values and down to the
    /// negative ones: the frames (poses and state) in `at`'s order, or
    /// `None` if one is not reached.
    fn reach(&self, c: &Candidate, at: &[f64]) -> Option<Vec<(Vec<Pose>, InterpState)>> {
        crate::synth::reach::reach(&c.interpreter, at, self.step, |v| self.request(v))
    }

    /// The candidate's frames over the input's range, `SAMPLES + 1` of
    /// them (None where a frame is not solved).
    fn sample(&self, c: &Candidate) -> Sampled {
        self.sample_n(c, SAMPLES)
    }

    /// [`Problem::sample`] with `samples` steps.
    fn sample_n(&self, c: &Candidate, samples: usize) -> Sampled {
        let mut driver = Driver::new(&c.interpreter, Options::default());
        let [a, b] = self.range;
        let bodies = c.mechanism.bodies.len();
        let mut out = Sampled {
            bodies,
            poses: Vec::with_capacity((samples + 1) * bodies),
            solved: Vec::with_capacity(samples + 1),
        };
        // One request for every frame: a vector per frame was a tenth of
        // a search's time in the allocator.
        let mut inputs = self.request(0.0);
        // From the drawing (input 0) to the range's start first.
        if a != 0.0 {
            let n = (a.abs() / self.step).ceil() as usize;
            for s in 1..=n {
                inputs[self.input] = a * s as f64 / n as f64;
                driver.frame(&inputs);
            }
        }
        for s in 0..=samples {
            inputs[self.input] = a + (b - a) * s as f64 / samples as f64;
            let solved = driver.frame(&inputs).is_solved();
            out.solved.push(solved);
            if solved {
                out.poses.extend_from_slice(driver.poses());
            } else {
                out.poses.extend(std::iter::repeat_n(Pose::IDENTITY, bodies));
            }
        }
        out
    }

    /// The input value of sample `s`.
    fn sample_input(&self, s: usize) -> f64 {
        let [a, b] = self.range;
        a + (b - a) * s as f64 / SAMPLES as f64
    }

    /// The residuals of target `i` at the frame `poses` of candidate `c`.
    fn target_residuals(&self, c: &Candidate, i: usize, poses: &[Pose], out: &mut Vec<f64>) {
        let m = &c.mechanism;
        match &self.goal {
            Goal::Path { marker, points, .. } => {
                let w = poses[marker.body].world(m.marker(*marker).at);
                out.extend([w[0] - points[i][0], w[1] - points[i][1]]);
            }
            Goal::Function { joint, pairs } => out.push(output(m, *joint, poses) - pairs[i][1]),
            Goal::Motion {
                body,
                marker,
                poses: targets,
                ..
            } => {
                let w = poses[marker.body].world(m.marker(*marker).at);
                let angle = poses[*body].rot.s.atan2(poses[*body].rot.c);
                let turn = wrap(angle - targets[i][2].to_radians());
                out.extend([w[0] - targets[i][0], w[1] - targets[i][1], self.weight * turn]);
            }
        }
        if let Goal::Function { joint, .. } = &self.goal {
            if m.joints[*joint].kind == JointKind::Revolute {
                let last = out.len() - 1;
                out[last] = wrap(out[last].to_radians()).to_degrees();
            }
        }
    }

    /// How far the constraints are broken at candidate `c` with its
    /// sampled frames (0: all kept), and each one's margin.
    fn check(&self, c: &Candidate, frames: &Sampled) -> (f64, Vec<Margin>) {
        let mut margins = Vec::new();
        if self.constraints.full_turn {
            // Minus the frames that fail; and where the input drives a
            // four-bar at its frame, the lengths' margin (a length), as
            // sampled frames miss the stops of a four-bar just past its
            // change point.
            let failed = frames.iter().filter(|f| f.is_none()).count() as f64;
            let lengths = self
                .crank
                .map(|(k, link)| match self.loops[k].in_drawing(&c.mechanism) {
                    Some(f) => f.turning_margin(link),
                    None => -1.0,
                });
            let margin = match lengths {
                Some(l) if failed == 0.0 => l,
                Some(l) => l.min(-failed),
                None => -failed,
            };
            margins.push(Margin {
                name: "full-turn",
                value: if margin >= 0.0 { 1.0 } else { 0.0 },
                margin,
            });
        }
        if let Some(deg) = self.constraints.min_transmission {
            // min(μ, 180° − μ) is acos |cos μ|: the worst frame is the
            // one with the largest |cos μ|, and one arc cosine says how
            // bad it is.
            let worst = (frames.iter().flatten())
                .flat_map(|poses| {
                    self.loops
                        .iter()
                        .map(|f| transmission_cos(&c.mechanism, f, poses).abs())
                })
                .fold(0.0f64, f64::max)
                .acos()
                .to_degrees();
            // The search's frames are 2° apart: it keeps a quarter
            // degree in hand so the angle between them holds too (the
            // reported margin is measured on denser frames).
            let hand = if frames.len() <= SAMPLES + 1 { 0.25 } else { 0.0 };
            margins.push(Margin {
                name: "min-transmission",
                value: worst,
                margin: worst - deg - hand,
            });
        }
        if let Some(r) = self.constraints.max_ratio {
            let ratio = link_ratio(&c.mechanism);
            margins.push(Margin {
                name: "max-ratio",
                value: ratio,
                margin: r - ratio,
            });
        }
        let violation = margins.iter().map(|m| (-m.margin).max(0.0)).sum();
        (violation, margins)
    }

    /// Every constraint's margin at the polish's unknowns `z`, measured
    /// on eight times the search's samples (a tenth of a degree apart
    /// over a turn), so that what the search kept between its samples is
    /// checked between them too.
    pub fn margins(&self, z: &[f64]) -> Option<Vec<Margin>> {
        let c = self.design.prepare(&self.values(&z[..self.vary.len()])).ok()?;
        let frames = self.sample_n(&c, 8 * SAMPLES);
        Some(self.check(&c, &frames).1)
    }

    fn constrained(&self) -> bool {
        let k = self.constraints;
        k.full_turn || k.min_transmission.is_some() || k.max_ratio.is_some()
    }

    /// The sum over targets of the squared distance to the nearest point
    /// of the sampled curve (each point projected on the two sample
    /// segments beside its nearest sample), and each target's input there.
    fn nearest(&self, c: &Candidate, frames: &Sampled) -> Option<(f64, Vec<f64>)> {
        let curve: Vec<Option<[f64; 3]>> = (frames.iter())
            .map(|f| f.as_ref().map(|poses| self.curve_point(c, poses)))
            .collect();
        nearest(
            &curve,
            |s| self.sample_input(s),
            (0..self.goal.len()).map(|i| self.target_point(i)),
        )
    }

    /// A frame as the point the goal compares with its targets: the
    /// marker (path), the marker and the weighted angle (motion), the
    /// output (function); unused coordinates 0.
    fn curve_point(&self, c: &Candidate, poses: &[Pose]) -> [f64; 3] {
        match &self.goal {
            Goal::Path { marker, .. } => {
                let w = poses[marker.body].world(c.mechanism.marker(*marker).at);
                [w[0], w[1], 0.0]
            }
            Goal::Motion { body, marker, .. } => {
                let w = poses[marker.body].world(c.mechanism.marker(*marker).at);
                let angle = poses[*body].rot.s.atan2(poses[*body].rot.c);
                [w[0], w[1], self.weight * angle]
            }
            Goal::Function { joint, .. } => [output(&c.mechanism, *joint, poses), 0.0, 0.0],
        }
    }

    /// Target `i` as a point of [`Problem::curve_point`]'s space.
    fn target_point(&self, i: usize) -> [f64; 3] {
        match &self.goal {
            Goal::Path { points, .. } => [points[i][0], points[i][1], 0.0],
            Goal::Motion { poses, .. } => [poses[i][0], poses[i][1], self.weight * poses[i][2].to_radians()],
            Goal::Function { pairs, .. } => [pairs[i][1], 0.0, 0.0],
        }
    }

    /// The error of the varied parameters `x` as the global search ranks
    /// it, and for free timing each target's input.
    fn evaluate(&self, x: &[f64]) -> Option<(f64, Option<Vec<f64>>)> {
        let c = self.design.prepare(&self.values(x)).ok()?;
        let given = self.goal.inputs();
        let sampled = (given.is_none() || self.constrained()).then(|| self.sample(&c));
        let violation = match &sampled {
            Some(frames) => self.check(&c, frames).0,
            None => 0.0,
        };
        match given {
            Some(at) => {
                let frames = self.reach(&c, &at)?;
                let mut r = Vec::new();
                for (i, (poses, _)) in frames.iter().enumerate() {
                    self.target_residuals(&c, i, poses, &mut r);
                }
                Some((penalised(r.iter().map(|v| v * v).sum(), violation), None))
            }
            None => {
                let (error, inputs) = self.nearest(&c, sampled.as_ref()?)?;
                Some((penalised(error, violation), Some(inputs)))
            }
        }
    }
}

/// A candidate's frames sampled over the input's range: every frame's
/// poses in one vector (a search samples 181 frames per candidate, and a
/// vector per frame was a tenth of its time in the allocator).
struct Sampled {
    bodies: usize,
    /// `bodies` poses per frame; an unsolved frame's are placeholders.
    poses: Vec<Pose>,
    solved: Vec<bool>,
}

impl Sampled {
    fn len(&self) -> usize {
        self.solved.len()
    }

    /// Each frame's poses, `None` where it is not solved.
    fn iter(&self) -> impl Iterator<Item = Option<&[Pose]>> {
        (self.solved.iter())
            .zip(self.poses.chunks_exact(self.bodies.max(1)))
            .map(|(&ok, poses)| ok.then_some(poses))
    }
}

impl Objective for Problem {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.bounds
    }

    fn fitness(&self, x: &[f64]) -> f64 {
        self.evaluate(x).map_or(FAILED, |(e, _)| e)
    }

    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        let (_, inputs) = self.evaluate(x)?;
        Some(x.iter().copied().chain(inputs.unwrap_or_default()).collect())
    }

    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)> {
        let nv = self.vary.len();
        let c = self.design.prepare(&self.values(&z[..nv])).ok()?;
        let given = self.goal.inputs();
        let at: Vec<f64> = given.clone().unwrap_or_else(|| z[nv..].to_vec());
        let frames = self.reach(&c, &at)?;
        let w = self.goal.width();
        let rows = w * self.goal.len();
        let mut r = Vec::with_capacity(rows);
        for (i, (poses, _)) in frames.iter().enumerate() {
            self.target_residuals(&c, i, poses, &mut r);
        }
        if !jacobian {
            return Some((DVector::from_vec(r), None));
        }
        let cols = nv + if given.is_some() { 0 } else { self.goal.len() };
        let mut j = DMatrix::zeros(rows, cols);
        let linearised = Linearised::new(&self.design, &c);
        for (i, (poses, state)) in frames.iter().enumerate() {
            let inputs = self.request(at[i]);
            let s = linearised.at_fast(poses, &inputs).ok()?;
            let d = self.target_derivatives(
                &c,
                poses,
                |id| s.marker(id),
                |b| s.poses.row(3 * b + 2).iter().copied().collect(),
            );
            for row in 0..w {
                for (k, &v) in self.vary.iter().enumerate() {
                    j[(w * i + row, k)] = d[row][v];
                }
            }
            if given.is_none() {
                let rates = self.input_rates(&c, state, &inputs)?;
                for row in 0..w {
                    j[(w * i + row, nv + i)] = rates[row];
                }
            }
        }
        Some((DVector::from_vec(r), Some(j)))
    }

    fn feasible(&self, z: &[f64]) -> bool {
        if !self.constrained() {
            return true;
        }
        let Ok(c) = self.design.prepare(&self.values(&z[..self.vary.len()])) else {
            return false;
        };
        let frames = self.sample(&c);
        self.check(&c, &frames).0 == 0.0
    }
}

impl Problem {
    /// The derivatives of a target's residuals with respect to every
    /// parameter, from the markers' (`marker`) and the bodies' angles'
    /// (`angle`, radians).
    fn target_derivatives(
        &self,
        c: &Candidate,
        poses: &[Pose],
        marker: impl Fn(MarkerId) -> Vec<[f64; 2]>,
        angle: impl Fn(usize) -> Vec<f64>,
    ) -> Vec<Vec<f64>> {
        let m = &c.mechanism;
        match &self.goal {
            Goal::Path { marker: id, .. } => {
                let d = marker(*id);
                vec![d.iter().map(|v| v[0]).collect(), d.iter().map(|v| v[1]).collect()]
            }
            Goal::Motion { body, marker: id, .. } => {
                let d = marker(*id);
                let a = angle(*body);
                vec![
                    d.iter().map(|v| v[0]).collect(),
                    d.iter().map(|v| v[1]).collect(),
                    a.iter().map(|v| self.weight * v).collect(),
                ]
            }
            Goal::Function { joint, .. } => {
                let [a, b] = m.joints[*joint].markers;
                match m.joints[*joint].kind {
                    JointKind::Revolute => {
                        let (da, db) = (angle(a.body), angle(b.body));
                        vec![da.iter().zip(&db).map(|(x, y)| (y - x).to_degrees()).collect()]
                    }
                    JointKind::Prismatic => {
                        // s = d·(pb − pa) − d₀·(b₀ − a₀): the joint's markers
                        // move together with its parameters, so only the
                        // frame's terms change.
                        let dir = poses[a.body].world_dir(m.marker(a).unit_dir().unwrap_or([1.0, 0.0]));
                        let (pa, pb) = (
                            poses[a.body].world(m.marker(a).at),
                            poses[b.body].world(m.marker(b).at),
                        );
                        let gap = [pb[0] - pa[0], pb[1] - pa[1]];
                        let (ma, mb, ta) = (marker(a), marker(b), angle(a.body));
                        let row = (0..ma.len())
                            .map(|k| {
                                let dd = [-dir[1] * ta[k], dir[0] * ta[k]];
                                dir[0] * (mb[k][0] - ma[k][0])
                                    + dir[1] * (mb[k][1] - ma[k][1])
                                    + dd[0] * gap[0]
                                    + dd[1] * gap[1]
                            })
                            .collect();
                        vec![row]
                    }
                }
            }
        }
    }

    /// The derivatives of a target's residuals with respect to its input
    /// value (per degree or per length), from the plan's exact rates.
    fn input_rates(&self, c: &Candidate, state: &InterpState, inputs: &[f64]) -> Option<Vec<f64>> {
        let mut rates = vec![0.0; inputs.len()];
        rates[self.input] = 1.0;
        let zero = vec![0.0; inputs.len()];
        let jets: Vec<Pose<Jet2>> = c.interpreter.rates(state, inputs, &rates, &zero).ok()?;
        let poses: Vec<Pose> = jets.iter().map(Pose::value).collect();
        let marker = |id: MarkerId| {
            let w = jets[id.body].world(c.mechanism.marker(id).at);
            vec![[w[0].d, w[1].d]]
        };
        let angle = |b: usize| {
            let r = jets[b].rot;
            vec![r.c.v * r.s.d - r.s.v * r.c.d]
        };
        // One "parameter" here, the input: the same formulas as for the
        // dimensions, every marker's drawn position held.
        let d = self.target_derivatives(c, &poses, marker, angle);
        Some(d.iter().map(|row| row[0]).collect())
    }
}

/// A joint's output: a revolute joint's angle (degrees, the second body
/// from the first, 0 as drawn), a prismatic joint's slide (the second
/// marker along the first's direction, 0 as drawn).
pub fn output(m: &Mechanism, joint: usize, poses: &[Pose]) -> f64 {
    let [a, b] = m.joints[joint].markers;
    match m.joints[joint].kind {
        JointKind::Revolute => {
            let (ra, rb) = (poses[a.body].rot, poses[b.body].rot);
            (rb.s * ra.c - rb.c * ra.s)
                .atan2(rb.c * ra.c + rb.s * ra.s)
                .to_degrees()
        }
        JointKind::Prismatic => {
            let d0 = m.marker(a).unit_dir().unwrap_or([1.0, 0.0]);
            let dir = poses[a.body].world_dir(d0);
            let (pa, pb) = (
                poses[a.body].world(m.marker(a).at),
                poses[b.body].world(m.marker(b).at),
            );
            let (a0, b0) = (m.marker(a).at, m.marker(b).at);
            dir[0] * (pb[0] - pa[0]) + dir[1] * (pb[1] - pa[1])
                - (d0[0] * (b0[0] - a0[0]) + d0[1] * (b0[1] - a0[1]))
        }
    }
}

/// Longest over shortest link: a body's length is the largest distance
/// between two of its markers that are in joints (the ground's too).
pub fn link_ratio(m: &Mechanism) -> f64 {
    let mut in_joint: Vec<Vec<[f64; 2]>> = vec![Vec::new(); m.bodies.len()];
    for j in &m.joints {
        for id in j.markers {
            in_joint[id.body].push(m.marker(id).at);
        }
    }
    let lengths: Vec<f64> = (in_joint.iter())
        .filter(|p| p.len() >= 2)
        .map(|p| {
            let mut l = 0.0f64;
            for (i, a) in p.iter().enumerate() {
                for b in &p[i + 1..] {
                    l = l.max((a[0] - b[0]).hypot(a[1] - b[1]));
                }
            }
            l
        })
        .collect();
    let (lo, hi) = lengths
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), &l| (lo.min(l), hi.max(l)));
    if lo > 0.0 {
        hi / lo
    } else {
        f64::INFINITY
    }
}

/// An angle in radians brought into (−π, π].
fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let w = a.rem_euclid(t);
    if w > std::f64::consts::PI {
        w - t
    } else {
        w
    }
}
