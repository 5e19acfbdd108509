//! The exact derivatives of a solved frame with respect to the design
//! parameters.
//!
//! A frame's poses `q` satisfy the mechanism's primitive equations
//! `Φ(q, p) = 0` (joints, constraints and inputs, Brunkhart §5.1) with the
//! inputs held, where `p` are the drawn positions the markers' local
//! coordinates are (a body's frame is the world at the drawing). Where the
//! frame is not a dead point, `Φ_q` has full column rank and the implicit
//! function theorem gives `dq/dp = −Φ_q⁺ Φ_p` exactly. Both Jacobians are
//! computed exactly, one column at a time, by forward-mode jets through
//! the equations' residuals.

use dofplan_runtime::planar::{cst, Point, Pose, Rot};
use dofplan_runtime::real::{Jet2, Real};
use nalgebra::DMatrix;
use std::sync::Arc;

use super::{Candidate, Design};
use crate::model::planar::equations::{equations, End, Equation};
use crate::model::MarkerId;
use crate::synth::SynthError;

/// The derivatives of one frame with respect to every design parameter.
#[derive(Clone, Debug)]
pub struct Sensitivity {
    /// One row per body coordinate (rows `3b`, `3b + 1`, `3b + 2`: body
    /// `b`'s translation x, y and its angle in radians; zero for the
    /// ground), one column per parameter.
    pub poses: DMatrix<f64>,
    /// Smallest over largest singular value of the equations' Jacobian
    /// (angles scaled by the mechanism's size): how far the frame is from
    /// a dead point, 1 at best.
    pub conditioning: f64,
    /// Per parameter, the part of the equations' change the poses cannot
    /// follow, relative to the mechanism's size: 0 unless the mechanism is
    /// over-constrained and moving that parameter breaks the redundancy
    /// (the candidate then locks away from the drawing).
    pub misfit: Vec<f64>,
    frame: Vec<Pose>,
    locals: Arc<[Vec<Point>]>,
    node_of: Arc<[Vec<usize>]>,
}

/// A primitive equation with the nodes its two markers move with
/// (`usize::MAX` where the equation names no marker).
struct Tied {
    eq: Equation,
    nodes: [usize; 2],
}

/// The derivatives of the frame `poses` (solved at `inputs` by
/// `candidate`'s plan) with respect to `design`'s parameters.
pub fn sensitivity(
    design: &Design,
    candidate: &Candidate,
    poses: &[Pose],
    inputs: &[f64],
) -> Result<Sensitivity, SynthError> {
    Linearised::new(design, candidate).at(poses, inputs)
}

/// What [`sensitivity`] needs of a candidate and not of a frame: its
/// equations with the nodes their markers move with, made once for all the
/// candidate's frames (a polish step differentiates every target's frame
/// of one candidate, and finding the equations' markers by name per frame
/// was a fifth of its time).
pub struct Linearised {
    eqs: Vec<Tied>,
    /// The mobile bodies, one block of three unknowns each.
    columns: Vec<usize>,
    rows: usize,
    params: usize,
    bodies: usize,
    size: f64,
    locals: Arc<[Vec<Point>]>,
    node_of: Arc<[Vec<usize>]>,
}

impl Linearised {
    /// `candidate`'s equations, tied to `design`'s parameters.
    pub fn new(design: &Design, candidate: &Candidate) -> Linearised {
        let m = &candidate.mechanism;
        let node = |e: &End| m.find_marker(&e.name).map_or(usize::MAX, |id| design.node_of(id));
        let eqs: Vec<Tied> = equations(m)
            .into_iter()
            .map(|s| {
                let nodes = match &s.eq {
                    Equation::Coincident { a, b, .. } => [node(a), node(b)],
                    Equation::InLine { line, point, .. } => [node(line), node(point)],
                    Equation::OnCircle { centre, point, .. } => [node(centre), node(point)],
                    Equation::Parallel { .. } => [usize::MAX; 2],
                };
                Tied { eq: s.eq, nodes }
            })
            .collect();
        Linearised {
            rows: eqs.iter().map(|t| t.eq.count()).sum(),
            eqs,
            columns: (0..m.bodies.len()).filter(|&b| !m.bodies[b].fixed).collect(),
            params: design.names().len(),
            bodies: m.bodies.len(),
            size: m.size(),
            locals: (m.bodies.iter())
                .map(|b| b.markers.iter().map(|mk| mk.at).collect())
                .collect(),
            node_of: design.node_table().into(),
        }
    }

    /// The derivatives of the frame `poses`, solved at `inputs`.
    pub fn at(&self, poses: &[Pose], inputs: &[f64]) -> Result<Sensitivity, SynthError> {
        self.solve(poses, inputs, false)
    }

    /// [`Linearised::at`] for a search's inner loop: the same derivatives,
    /// solved by LU where the frame is clear of a dead point, and the
    /// conditioning only estimated there (see
    /// [`implicit_fast`](crate::synth::nodes::implicit_fast)).
    pub fn at_fast(&self, poses: &[Pose], inputs: &[f64]) -> Result<Sensitivity, SynthError> {
        self.solve(poses, inputs, true)
    }

    fn solve(&self, poses: &[Pose], inputs: &[f64], fast: bool) -> Result<Sensitivity, SynthError> {
        let (eqs, columns, rows, params, size) =
            (&self.eqs, &self.columns, self.rows, self.params, self.size);
        // Φ_q, one jet pass per unknown (x, y, angle × size of each mobile body).
        let mut phi_q = DMatrix::zeros(rows, 3 * columns.len());
        let mut r = Vec::with_capacity(rows);
        for (c, &b) in columns.iter().enumerate() {
            for v in 0..3 {
                let jets = pose_jets(poses, b, v, size);
                residuals(eqs, &jets, |_, _| None, inputs, &mut r);
                for (i, x) in r.iter().enumerate() {
                    phi_q[(i, 3 * c + v)] = x.d;
                }
            }
        }
        // Φ_p, one jet pass per parameter: the markers of its node move.
        let mut phi_p = DMatrix::zeros(rows, params);
        let still: Vec<Pose<Jet2>> = poses.iter().map(|p| Pose::cst(*p)).collect();
        for k in 0..params {
            let moved = |n: usize, _: &End| (n == k / 2).then_some(k % 2);
            residuals(eqs, &still, moved, inputs, &mut r);
            for (i, x) in r.iter().enumerate() {
                phi_p[(i, k)] = x.d;
            }
        }

        let crate::synth::nodes::Implicit {
            dq,
            conditioning,
            misfit,
            ..
        } = if fast {
            crate::synth::nodes::implicit_fast(&phi_q, &phi_p, size)?
        } else {
            crate::synth::nodes::implicit(&phi_q, &phi_p, size, false)?
        };
        let mut out = DMatrix::zeros(3 * self.bodies, params);
        for (c, &b) in columns.iter().enumerate() {
            for k in 0..params {
                out[(3 * b, k)] = dq[(3 * c, k)];
                out[(3 * b + 1, k)] = dq[(3 * c + 1, k)];
                out[(3 * b + 2, k)] = dq[(3 * c + 2, k)] / size;
            }
        }
        Ok(Sensitivity {
            poses: out,
            conditioning,
            misfit,
            frame: poses.to_vec(),
            locals: Arc::clone(&self.locals),
            node_of: Arc::clone(&self.node_of),
        })
    }
}

impl Sensitivity {
    /// The derivative of a marker's world position with respect to each
    /// parameter, `[dx, dy]` per parameter.
    pub fn marker(&self, id: MarkerId) -> Vec<[f64; 2]> {
        let (b, pose) = (id.body, self.frame[id.body]);
        let turned = pose.rot.apply(self.locals[b][id.marker]);
        let node = self.node_of[b][id.marker];
        (0..self.poses.ncols())
            .map(|k| {
                let (dx, dy, da) = (
                    self.poses[(3 * b, k)],
                    self.poses[(3 * b + 1, k)],
                    self.poses[(3 * b + 2, k)],
                );
                let mut d = [dx - da * turned[1], dy + da * turned[0]];
                if k / 2 == node {
                    let e = if k % 2 == 0 { [1.0, 0.0] } else { [0.0, 1.0] };
                    let r = pose.rot.apply(e);
                    d = [d[0] + r[0], d[1] + r[1]];
                }
                d
            })
            .collect()
    }
}

/// The frame's poses as jets, body `b`'s coordinate `v` (0: x, 1: y, 2:
/// angle × `size`) the one with derivative 1.
fn pose_jets(poses: &[Pose], b: usize, v: usize, size: f64) -> Vec<Pose<Jet2>> {
    let mut out: Vec<Pose<Jet2>> = poses.iter().map(|p| Pose::cst(*p)).collect();
    let p = poses[b];
    match v {
        0 => out[b].at[0] = Jet2::new(p.at[0], 1.0, 0.0),
        1 => out[b].at[1] = Jet2::new(p.at[1], 1.0, 0.0),
        _ => {
            out[b].rot = Rot {
                c: Jet2::new(p.rot.c, -p.rot.s / size, 0.0),
                s: Jet2::new(p.rot.s, p.rot.c / size, 0.0),
            }
        }
    }
    out
}

/// Every equation's residual on jets. `moved(node, end)` says which
/// coordinate of a marker's local position carries derivative 1 (the
/// parameter being differentiated), if any.
fn residuals(
    eqs: &[Tied],
    poses: &[Pose<Jet2>],
    moved: impl Fn(usize, &End) -> Option<usize>,
    inputs: &[f64],
    out: &mut Vec<Jet2>,
) {
    out.clear();
    let local = |e: &End, n: usize| {
        let mut l: [Jet2; 2] = cst(e.local);
        if let Some(axis) = moved(n, e) {
            l[axis].d = 1.0;
        }
        l
    };
    for t in eqs {
        match &t.eq {
            Equation::Coincident { a, b, slide } => {
                let mut la = local(a, t.nodes[0]);
                if let Some((input, dir)) = slide {
                    let u = inputs[*input];
                    la = [la[0] + Jet2::cst(u * dir[0]), la[1] + Jet2::cst(u * dir[1])];
                }
                let pa = poses[a.body].world_carried(la);
                let pb = poses[b.body].world_carried(local(b, t.nodes[1]));
                out.extend([pa[0] - pb[0], pa[1] - pb[1]]);
            }
            Equation::InLine { line, dir, point } => {
                let pa = poses[line.body].world_carried(local(line, t.nodes[0]));
                let pb = poses[point.body].world_carried(local(point, t.nodes[1]));
                let d = poses[line.body].rot.apply(cst(*dir));
                out.push(d[0] * (pb[1] - pa[1]) - d[1] * (pb[0] - pa[0]));
            }
            Equation::OnCircle { centre, point, .. } => {
                // The radius is the drawn distance, which moves with the
                // parameters as the markers do.
                let (la, lb) = (local(centre, t.nodes[0]), local(point, t.nodes[1]));
                let pa = poses[centre.body].world_carried(la);
                let pb = poses[point.body].world_carried(lb);
                let length = |v: [Jet2; 2]| (v[0] * v[0] + v[1] * v[1]).sqrt();
                out.push(length([pb[0] - pa[0], pb[1] - pa[1]]) - length([lb[0] - la[0], lb[1] - la[1]]));
            }
            Equation::Parallel { a, b, input } => {
                let rel = match input {
                    Some(k) => Rot::cst(Rot::from_degrees(inputs[*k])),
                    None => Rot::cst(Rot::IDENTITY),
                };
                let want = poses[*a].rot.then(rel);
                let got = poses[*b].rot;
                out.push(got.s * want.c - got.c * want.s);
            }
        }
    }
}
