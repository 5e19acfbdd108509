//! The exact derivatives of a solved spatial frame with respect to the
//! design parameters, as in the plane (`synth/planar/gradient.rs`): the
//! implicit function theorem on the mechanism's primitive equations,
//! whose Jacobians are the runtime's exact directional derivatives of the
//! rows ([`RowKind::deriv`]) under twists of the bodies and moves of the
//! markers.

use dofplan_runtime::spatial::rows::{FrameRate, RowKind, WorldFrame};
use dofplan_runtime::spatial::{add, cross, Pose3, Vec3};
use nalgebra::DMatrix;

use super::{Candidate, Design};
use crate::model::spatial::equations::{equations, row_kind, Equation, Kind};
use crate::model::spatial::Primitive;
use crate::model::MarkerId;
use crate::synth::SynthError;

/// The derivatives of one spatial frame with respect to every parameter.
#[derive(Clone, Debug)]
pub struct Sensitivity {
    /// Six rows per body (rows `6b` to `6b + 2`: the velocity of the
    /// body's origin; `6b + 3` to `6b + 5`: its angular velocity, radians,
    /// in world axes; zero for the ground), one column per parameter.
    pub poses: DMatrix<f64>,
    /// Smallest over largest singular value of the equations' Jacobian
    /// (turns scaled by the mechanism's size).
    pub conditioning: f64,
    /// Per parameter, what the poses cannot follow, relative to the size
    /// (0 unless moving it breaks a redundancy).
    pub misfit: Vec<f64>,
    /// The idle freedoms the equations leave (a spherical–spherical link's
    /// spin about its own axis), as twists of the bodies laid out as
    /// `poses`' rows: the derivatives are the minimum-norm ones, exact for
    /// whatever such a spin does not move ([`Sensitivity::determined`]).
    pub idle: DMatrix<f64>,
    frame: Vec<Pose3>,
    locals: Vec<Vec<Vec3>>,
    node_of: Vec<Vec<usize>>,
}

fn unit(k: usize) -> Vec3 {
    let mut e = [0.0; 3];
    e[k] = 1.0;
    e
}

/// An equation's frames in the world at `poses`.
fn world(eq: &Equation, poses: &[Pose3]) -> [WorldFrame; 2] {
    let f = |i: usize| {
        let fr = &eq.frames[i];
        WorldFrame::of(&poses[eq.bodies[i]], fr.at, fr.axes.z, fr.axes.x)
    };
    [f(0), f(1)]
}

const STILL: FrameRate = FrameRate {
    at: [0.0; 3],
    z: [0.0; 3],
    x: [0.0; 3],
};

/// The derivatives of the frame `poses` (solved at `inputs` by
/// `candidate`'s plan) with respect to `design`'s parameters.
pub fn sensitivity(
    design: &Design,
    candidate: &Candidate,
    poses: &[Pose3],
    inputs: &[f64],
) -> Result<Sensitivity, SynthError> {
    let m = &candidate.mechanism;
    let eqs = equations(m);
    let size = m.size();
    let mobile: Vec<usize> = (0..m.bodies.len()).filter(|&b| !m.bodies[b].fixed).collect();
    let rows: usize = eqs.iter().map(|e| e.kind.rows()).sum();
    let params = design.names().len();
    let frames: Vec<[WorldFrame; 2]> = eqs.iter().map(|e| world(e, poses)).collect();
    let fill =
        |matrix: &mut DMatrix<f64>, col: usize, rate: &dyn Fn(&Equation, usize, &WorldFrame) -> FrameRate| {
            let mut row = 0;
            for (eq, f) in eqs.iter().zip(&frames) {
                let rk = eq.row_kind();
                let d = rk.deriv(&f[0], &f[1], &rate(eq, 0, &f[0]), &rate(eq, 1, &f[1]), inputs);
                for (k, v) in d.iter().take(eq.kind.rows()).enumerate() {
                    matrix[(row + k, col)] = *v;
                }
                row += eq.kind.rows();
            }
        };
    // Φ_q: a twist of each mobile body, its turns scaled by the size.
    let mut phi_q = DMatrix::zeros(rows, 6 * mobile.len());
    for (c, &b) in mobile.iter().enumerate() {
        for k in 0..6 {
            let (omega, v) = if k < 3 {
                ([0.0; 3], unit(k))
            } else {
                (scaled(unit(k - 3), 1.0 / size), [0.0; 3])
            };
            let origin = poses[b].pos;
            fill(&mut phi_q, 6 * c + k, &|eq, i, f| {
                if eq.bodies[i] == b {
                    FrameRate::of(f, omega, v, origin)
                } else {
                    STILL
                }
            });
        }
    }
    // Φ_p: the markers of a parameter's node move along its axis.
    let mut phi_p = DMatrix::zeros(rows, params);
    for k in 0..params {
        let (node, axis) = (k / 3, k % 3);
        fill(&mut phi_p, k, &|eq, i, _| {
            if design.node_of(eq.markers[i]) == node {
                FrameRate {
                    at: poses[eq.bodies[i]].dir(unit(axis)),
                    ..STILL
                }
            } else {
                STILL
            }
        });
        add_drawn_axial(&mut phi_p, k, &eqs, &frames, design, inputs);
    }
    solve(phi_q, phi_p, size, &mobile, m.bodies.len(), poses, design, m)
}

/// A helical joint's or a slide input's axial distance as drawn is a
/// constant of the equation that moves with the drawing when its two
/// markers are in different nodes: its share of column `k` (the rows are
/// linear in it, so a unit step gives the exact slope).
fn add_drawn_axial(
    phi_p: &mut DMatrix<f64>,
    k: usize,
    eqs: &[Equation],
    frames: &[[WorldFrame; 2]],
    design: &Design,
    inputs: &[f64],
) {
    let (node, axis) = (k / 3, k % 3);
    let mut row = 0;
    for (eq, f) in eqs.iter().zip(frames) {
        let rows = eq.kind.rows();
        if matches!(eq.kind, Kind::Slide { .. } | Kind::Prim(Primitive::Helical)) {
            let moved = |i: usize| {
                if design.node_of(eq.markers[i]) == node {
                    1.0
                } else {
                    0.0
                }
            };
            // axial0 = z₁·(b₀ − a₀) in the drawing, whose frames are the world's.
            let slope = eq.frames[0].axes.z[axis] * (moved(1) - moved(0));
            if slope != 0.0 {
                let rk = |a: f64| -> RowKind { row_kind(eq.kind, eq.angle, eq.pitch, a) };
                let (r0, r1) = (
                    rk(eq.axial0).eval(&f[0], &f[1], inputs),
                    rk(eq.axial0 + 1.0).eval(&f[0], &f[1], inputs),
                );
                for j in 0..rows {
                    phi_p[(row + j, k)] += slope * (r1[j] - r0[j]);
                }
            }
        }
        row += rows;
    }
}

fn scaled(v: Vec3, k: f64) -> Vec3 {
    [v[0] * k, v[1] * k, v[2] * k]
}

#[allow(clippy::too_many_arguments)]
fn solve(
    phi_q: DMatrix<f64>,
    phi_p: DMatrix<f64>,
    size: f64,
    mobile: &[usize],
    bodies: usize,
    poses: &[Pose3],
    design: &Design,
    m: &crate::model::spatial::Mechanism,
) -> Result<Sensitivity, SynthError> {
    let params = phi_p.ncols();
    let found = crate::synth::nodes::implicit(&phi_q, &phi_p, size, true)?;
    let (dq, conditioning, misfit) = (found.dq, found.conditioning, found.misfit);
    // The idle spins, as twists of the bodies (turns unscaled).
    let mut idle = DMatrix::zeros(6 * bodies, found.idle.ncols());
    for (c, &b) in mobile.iter().enumerate() {
        for k in 0..found.idle.ncols() {
            for j in 0..3 {
                idle[(6 * b + j, k)] = found.idle[(6 * c + j, k)];
                idle[(6 * b + 3 + j, k)] = found.idle[(6 * c + 3 + j, k)] / size;
            }
        }
    }
    let mut out = DMatrix::zeros(6 * bodies, params);
    for (c, &b) in mobile.iter().enumerate() {
        for k in 0..params {
            for j in 0..3 {
                out[(6 * b + j, k)] = dq[(6 * c + j, k)];
                out[(6 * b + 3 + j, k)] = dq[(6 * c + 3 + j, k)] / size;
            }
        }
    }
    Ok(Sensitivity {
        poses: out,
        conditioning,
        misfit,
        idle,
        frame: poses.to_vec(),
        locals: m
            .bodies
            .iter()
            .map(|b| b.markers.iter().map(|mk| mk.at).collect())
            .collect(),
        node_of: design.node_table().to_vec(),
    })
}

impl Sensitivity {
    /// The derivative of a marker's world position with respect to each
    /// parameter, `[dx, dy, dz]` per parameter.
    pub fn marker(&self, id: MarkerId) -> Vec<[f64; 3]> {
        let (b, pose) = (id.body, self.frame[id.body]);
        let w = pose.world(self.locals[b][id.marker]);
        let arm = [w[0] - pose.pos[0], w[1] - pose.pos[1], w[2] - pose.pos[2]];
        let node = self.node_of[b][id.marker];
        (0..self.poses.ncols())
            .map(|k| {
                let v = [
                    self.poses[(6 * b, k)],
                    self.poses[(6 * b + 1, k)],
                    self.poses[(6 * b + 2, k)],
                ];
                let omega = [
                    self.poses[(6 * b + 3, k)],
                    self.poses[(6 * b + 4, k)],
                    self.poses[(6 * b + 5, k)],
                ];
                let mut d = add(v, cross(omega, arm));
                if k / 3 == node {
                    d = add(d, pose.dir(unit(k % 3)));
                }
                d
            })
            .collect()
    }

    /// Whether the marker's position is fixed by the equations: no idle
    /// spin moves it (then its derivatives are exact; otherwise they are
    /// those of one choice of the spin).
    pub fn determined(&self, id: MarkerId) -> bool {
        let (b, pose) = (id.body, self.frame[id.body]);
        let w = pose.world(self.locals[b][id.marker]);
        let arm = [w[0] - pose.pos[0], w[1] - pose.pos[1], w[2] - pose.pos[2]];
        (0..self.idle.ncols()).all(|k| {
            let v = [
                self.idle[(6 * b, k)],
                self.idle[(6 * b + 1, k)],
                self.idle[(6 * b + 2, k)],
            ];
            let omega = [
                self.idle[(6 * b + 3, k)],
                self.idle[(6 * b + 4, k)],
                self.idle[(6 * b + 5, k)],
            ];
            let d = add(v, cross(omega, arm));
            d.iter().map(|x| x * x).sum::<f64>().sqrt()
                <= 1e-9 * (1.0 + arm.iter().map(|x| x * x).sum::<f64>().sqrt())
        })
    }

    /// Whether a body's rotation is fixed by the equations (no idle spin
    /// turns it).
    pub fn turn_determined(&self, body: usize) -> bool {
        (0..self.idle.ncols()).all(|k| (3..6).all(|j| self.idle[(6 * body + j, k)].abs() <= 1e-9))
    }

    /// The derivative of a body's rotation (angular velocity, radians, in
    /// world axes) with respect to each parameter.
    pub fn turn(&self, body: usize) -> Vec<[f64; 3]> {
        (0..self.poses.ncols())
            .map(|k| {
                [
                    self.poses[(6 * body + 3, k)],
                    self.poses[(6 * body + 4, k)],
                    self.poses[(6 * body + 5, k)],
                ]
            })
            .collect()
    }
}
