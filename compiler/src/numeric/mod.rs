//! Pure Newton mode: Brunkhart's baseline (Figure 30's left column). Every
//! mobile body not driven directly by an input is three unknowns, every
//! primitive equation is a residual, and Newton–Raphson with an SVD
//! pseudo-inverse step solves them all together — no analysis.
//!
//! A body driven by an input at a joint to the ground is placed from the
//! input, as the table counts it (its unknowns and its driving joint are
//! not in the Newton columns). Rotations are unknown as arc lengths
//! (θ times the mechanism's size) so that every unknown is a length: the
//! minimum-norm step then weighs turning and sliding alike, and one step
//! limit fits all.

pub mod drag;

use dofplan_runtime::numeric::{Equations, Newton, NewtonOptions, NewtonOutcome, NewtonReport};
use dofplan_runtime::planar::{Point, Pose, Rot};
use dofplan_runtime::{Break, BreakKind, Ctx, Solver};
use nalgebra::{DMatrix, DVector};

use crate::analysis::equations::{equations, Equation};
use crate::model::{InputKind, JointKind, Mechanism};

/// How pure Newton treats a body.
#[derive(Clone, Debug)]
enum Role {
    /// Ground: the identity pose.
    Fixed,
    /// Placed directly from an input at a joint to the ground.
    Driven(Drive),
    /// Three unknowns starting at this offset.
    Unknown(usize),
}

#[derive(Clone, Debug)]
struct Drive {
    input: usize,
    kind: InputKind,
    /// The ground marker of the driving joint (world = drawn).
    ground: Point,
    /// The driven body's marker of the driving joint (local = drawn).
    local: Point,
    /// Unit slide direction (slide inputs).
    dir: Point,
    /// The driven body is the joint's first: its motion is the inverse.
    inverse: bool,
}

/// A mechanism solved by Newton–Raphson alone.
#[derive(Clone, Debug)]
pub struct PureNewton {
    roles: Vec<Role>,
    rows: Vec<Equation>,
    /// The joint, constraint or input each of `rows` comes from.
    origins: Vec<String>,
    unknowns: usize,
    equations: usize,
    size: f64,
    options: NewtonOptions,
    input_kinds: Vec<InputKind>,
}

/// What pure Newton carries from frame to frame (buffers sized once).
#[derive(Clone, Debug)]
pub struct NewtonState {
    /// Body poses, in mechanism order.
    pub poses: Vec<Pose>,
    work: Vec<Pose>,
    x: DVector<f64>,
    newton: Newton,
}

impl PureNewton {
    /// Sets up pure Newton for a mechanism.
    pub fn new(m: &Mechanism) -> PureNewton {
        let mut roles: Vec<Role> = m
            .bodies
            .iter()
            .map(|b| if b.fixed { Role::Fixed } else { Role::Unknown(0) })
            .collect();
        for (i, input) in m.inputs.iter().enumerate() {
            let joint = &m.joints[input.joint];
            let [a, b] = joint.markers;
            let (ground, driven, inverse) = match (m.bodies[a.body].fixed, m.bodies[b.body].fixed) {
                (true, false) => (a, b, false),
                (false, true) => (b, a, true),
                _ => continue,
            };
            if !matches!(roles[driven.body], Role::Unknown(_)) {
                continue;
            }
            let dir = match joint.kind {
                JointKind::Prismatic => m.marker(a).unit_dir().expect("validated"),
                JointKind::Revolute => [0.0, 0.0],
            };
            roles[driven.body] = Role::Driven(Drive {
                input: i,
                kind: input.kind,
                ground: m.marker(ground).at,
                local: m.marker(driven).at,
                dir,
                inverse,
            });
        }
        let mut unknowns = 0;
        for role in &mut roles {
            if let Role::Unknown(offset) = role {
                *offset = unknowns;
                unknowns += 3;
            }
        }
        let (rows, origins): (Vec<Equation>, Vec<String>) = equations(m)
            .into_iter()
            .filter(|s| {
                s.eq.bodies()
                    .iter()
                    .any(|&b| matches!(roles[b], Role::Unknown(_)))
            })
            .map(|s| (s.eq, s.origin))
            .unzip();
        let equations = rows.iter().map(Equation::count).sum();
        let size = m.size();
        PureNewton {
            roles,
            rows,
            origins,
            unknowns,
            equations,
            size,
            options: NewtonOptions {
                max_iterations: 50,
                tolerance: 1e-12 * size,
                rank_cutoff: 1e-10,
                max_step: 0.25 * size,
            },
            input_kinds: m.inputs.iter().map(|i| i.kind).collect(),
        }
    }

    /// Unknowns handed to Newton–Raphson.
    pub fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// Scalar equations handed to Newton–Raphson.
    pub fn equations(&self) -> usize {
        self.equations
    }

    /// The Jacobian of every equation at the drawn pose (all inputs at 0),
    /// with each equation's origin and number of rows, in row order.
    pub fn drawn_jacobian(&self) -> (DMatrix<f64>, Vec<(String, usize)>) {
        let mut poses = vec![Pose::IDENTITY; self.roles.len()];
        let inputs = vec![0.0; self.input_kinds.len()];
        self.place_driven(&mut poses, &inputs);
        let mut system = System {
            solver: self,
            poses: &mut poses,
            inputs: &inputs,
        };
        let x = DVector::zeros(self.unknowns);
        let mut r = DVector::zeros(self.equations);
        let mut j = DMatrix::zeros(self.equations, self.unknowns);
        system.eval(&x, &mut r, Some(&mut j));
        let groups = self
            .rows
            .iter()
            .zip(&self.origins)
            .map(|(eq, o)| (o.clone(), eq.count()))
            .collect();
        (j, groups)
    }

    /// Number of bodies.
    pub fn bodies(&self) -> usize {
        self.roles.len()
    }

    /// The unknown columns of each body that has them: (body, first column).
    pub fn unknown_bodies(&self) -> Vec<(usize, usize)> {
        self.roles
            .iter()
            .enumerate()
            .filter_map(|(b, r)| match r {
                Role::Unknown(o) => Some((b, *o)),
                _ => None,
            })
            .collect()
    }

    fn place_driven(&self, poses: &mut [Pose], inputs: &[f64]) {
        for (b, role) in self.roles.iter().enumerate() {
            let Role::Driven(d) = role else { continue };
            let v = inputs[d.input];
            let pose = &mut poses[b];
            match d.kind {
                InputKind::Angle => {
                    let r = Rot::from_degrees(v);
                    pose.rot = if d.inverse { r.inverse() } else { r };
                    let w = pose.rot.apply(d.local);
                    pose.at = [d.ground[0] - w[0], d.ground[1] - w[1]];
                }
                InputKind::Slide => {
                    let u = if d.inverse { -v } else { v };
                    pose.rot = Rot::IDENTITY;
                    pose.at = [u * d.dir[0], u * d.dir[1]];
                }
            }
        }
    }
}

/// The residuals of pure Newton at one frame.
pub(crate) struct System<'a> {
    pub(crate) solver: &'a PureNewton,
    pub(crate) poses: &'a mut [Pose],
    pub(crate) inputs: &'a [f64],
}

impl System<'_> {
    /// Writes the unknowns `x` into the poses of the unknown bodies.
    pub(crate) fn apply(&mut self, x: &DVector<f64>) {
        let size = self.solver.size;
        for (b, role) in self.solver.roles.iter().enumerate() {
            if let Role::Unknown(o) = role {
                let (s, c) = (x[o + 2] / size).sin_cos();
                self.poses[b] = Pose {
                    at: [x[*o], x[o + 1]],
                    rot: Rot { c, s },
                };
            }
        }
    }
}

fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

impl Equations for System<'_> {
    fn unknowns(&self) -> usize {
        self.solver.unknowns
    }

    fn equations(&self) -> usize {
        self.solver.equations
    }

    fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, mut jacobian: Option<&mut DMatrix<f64>>) {
        self.apply(x);
        let size = self.solver.size;
        if let Some(j) = jacobian.as_deref_mut() {
            j.fill(0.0);
        }
        let offset = |b: usize| match self.solver.roles[b] {
            Role::Unknown(o) => Some(o),
            _ => None,
        };
        let mut row = 0;
        for eq in &self.solver.rows {
            match eq {
                Equation::Coincident { a, b, slide } => {
                    let la = match slide {
                        Some((input, d)) => {
                            let u = self.inputs[*input];
                            [a.local[0] + u * d[0], a.local[1] + u * d[1]]
                        }
                        None => a.local,
                    };
                    let (pa, ta) = self.poses[a.body].world_and_turn(la);
                    let (pb, tb) = self.poses[b.body].world_and_turn(b.local);
                    r[row] = pa[0] - pb[0];
                    r[row + 1] = pa[1] - pb[1];
                    if let Some(j) = jacobian.as_deref_mut() {
                        for (body, sign, t) in [(a.body, 1.0, ta), (b.body, -1.0, tb)] {
                            if let Some(o) = offset(body) {
                                j[(row, o)] += sign;
                                j[(row + 1, o + 1)] += sign;
                                j[(row, o + 2)] += sign * t[0] / size;
                                j[(row + 1, o + 2)] += sign * t[1] / size;
                            }
                        }
                    }
                    row += 2;
                }
                Equation::InLine { line, dir, point } => {
                    let pose_a = self.poses[line.body];
                    let d = pose_a.world_dir(*dir);
                    let (pa, ta) = pose_a.world_and_turn(line.local);
                    let (pb, tb) = self.poses[point.body].world_and_turn(point.local);
                    let v = [pb[0] - pa[0], pb[1] - pa[1]];
                    r[row] = cross(d, v);
                    if let Some(j) = jacobian.as_deref_mut() {
                        if let Some(o) = offset(line.body) {
                            j[(row, o)] += d[1];
                            j[(row, o + 1)] -= d[0];
                            // The line turns (d → perp d) and its point moves.
                            let turn = cross([-d[1], d[0]], v) - cross(d, ta);
                            j[(row, o + 2)] += turn / size;
                        }
                        if let Some(o) = offset(point.body) {
                            j[(row, o)] -= d[1];
                            j[(row, o + 1)] += d[0];
                            j[(row, o + 2)] += cross(d, tb) / size;
                        }
                    }
                    row += 1;
                }
                Equation::Parallel { a, b, input } => {
                    let rel = match input {
                        Some(i) => Rot::from_degrees(self.inputs[*i]),
                        None => Rot::IDENTITY,
                    };
                    // (R_a · rel)⁻¹ · R_b: the angle error, as a rotation.
                    let delta = self.poses[*a].rot.then(rel).inverse().then(self.poses[*b].rot);
                    r[row] = size * delta.s;
                    if let Some(j) = jacobian.as_deref_mut() {
                        if let Some(o) = offset(*b) {
                            j[(row, o + 2)] += delta.c;
                        }
                        if let Some(o) = offset(*a) {
                            j[(row, o + 2)] -= delta.c;
                        }
                    }
                    row += 1;
                }
            }
        }
    }
}

impl Solver for PureNewton {
    type State = NewtonState;
    type Inputs = Vec<f64>;

    fn initial_state(&self) -> NewtonState {
        let poses = vec![Pose::IDENTITY; self.roles.len()];
        NewtonState {
            work: poses.clone(),
            poses,
            x: DVector::zeros(self.unknowns),
            newton: Newton::new(self.unknowns, self.equations),
        }
    }

    fn initial_inputs(&self) -> Vec<f64> {
        vec![0.0; self.input_kinds.len()]
    }

    fn poses(state: &NewtonState) -> &[Pose] {
        &state.poses
    }

    fn solve(&self, state: &mut NewtonState, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        let NewtonState {
            poses,
            work,
            x,
            newton,
        } = state;
        work.copy_from_slice(poses);
        self.place_driven(work, inputs);
        // Warm start: the unknowns of the last valid frame.
        for (b, role) in self.roles.iter().enumerate() {
            if let Role::Unknown(o) = role {
                let p = work[b];
                x[*o] = p.at[0];
                x[o + 1] = p.at[1];
                x[o + 2] = p.rot.s.atan2(p.rot.c) * self.size;
            }
        }
        let mut system = System {
            solver: self,
            poses: work,
            inputs,
        };
        let report: NewtonReport = newton.solve(&mut system, x, &self.options);
        system.apply(x);
        ctx.numeric = Some(report);
        match report.outcome {
            NewtonOutcome::Converged => {}
            NewtonOutcome::NoSolution => ctx.fail(0, BreakKind::NoSolution, report.residual)?,
            NewtonOutcome::NotConverged => ctx.fail(0, BreakKind::NotConverged, report.residual)?,
        }
        std::mem::swap(poses, work);
        Ok(())
    }
}
