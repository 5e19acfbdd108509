//! A spatial synthesis problem: for now function generation — a revolute
//! joint's angle at given input values — searched as the planar problems
//! are (`synth/search.rs`), with the exact Jacobian of
//! `synth/spatial/gradient.rs`.

use dofplan_runtime::spatial::rows::WorldFrame;
use dofplan_runtime::spatial::{cross, dot, Pose3, Vec3};
use nalgebra::{DMatrix, DVector};

use super::{sensitivity, Candidate, Design};
use crate::model::spatial::{JointKind, Mechanism};
use crate::synth::search::{Objective, FAILED};
use crate::synth::SynthError;

/// A spatial function-generation problem: at each input value, the output
/// revolute joint's angle (degrees, the second marker's x turned about the
/// first marker's z, 0 as drawn) is the target's.
#[derive(Clone, Debug)]
pub struct Function {
    design: Design,
    joint: usize,
    pairs: Vec<[f64; 2]>,
    input: usize,
    vary: Vec<usize>,
    bounds: Vec<[f64; 2]>,
    base: Vec<f64>,
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
        Ok(Function {
            design,
            joint,
            pairs,
            input,
            vary,
            bounds,
            base,
        })
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

    /// The candidate's poses at every target's input, run up from its
    /// drawing in steps of at most 5° (down for negative inputs).
    fn reach(&self, c: &Candidate) -> Option<Vec<Vec<Pose3>>> {
        let at: Vec<f64> = self.pairs.iter().map(|p| p[0]).collect();
        let frames = crate::synth::reach::reach(&c.interpreter, &at, 5.0, |v| self.request(v))?;
        Some(frames.into_iter().map(|(poses, _)| poses).collect())
    }
}

impl Objective for Function {
    fn bounds(&self) -> &[[f64; 2]] {
        &self.bounds
    }

    fn fitness(&self, x: &[f64]) -> f64 {
        self.residuals(x, false).map_or(FAILED, |(r, _)| r.norm_squared())
    }

    fn start(&self, x: &[f64]) -> Option<Vec<f64>> {
        Some(x.to_vec())
    }

    fn residuals(&self, z: &[f64], jacobian: bool) -> Option<(DVector<f64>, Option<DMatrix<f64>>)> {
        let c = self.design.prepare(&self.values(z)).ok()?;
        let frames = self.reach(&c)?;
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
        let mut j = DMatrix::zeros(r.len(), self.vary.len());
        for (i, poses) in frames.iter().enumerate() {
            let s = sensitivity(&self.design, &c, poses, &self.request(self.pairs[i][0])).ok()?;
            if !(s.turn_determined(a.body) && s.turn_determined(b.body)) {
                return None;
            }
            let (ta, tb) = (s.turn(a.body), s.turn(b.body));
            for (k, &v) in self.vary.iter().enumerate() {
                j[(i, k)] = output_rate(m, self.joint, poses, ta[v], tb[v]);
            }
        }
        Some((DVector::from_vec(r), Some(j)))
    }

    fn feasible(&self, _: &[f64]) -> bool {
        true
    }
}
