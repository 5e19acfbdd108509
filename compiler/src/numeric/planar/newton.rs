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

use dofplan_runtime::numeric::{Equations, Newton, NewtonOptions, NewtonOutcome, NewtonReport};
use dofplan_runtime::planar::cluster::{self, Param};
use dofplan_runtime::planar::{Point, Pose, Rot};
use dofplan_runtime::{Break, BreakKind, Ctx, Solver};
use nalgebra::{DMatrix, DVector};

use crate::model::planar::equations::equations;
use crate::model::planar::slots::Ends;
use crate::model::{InputKind, JointKind, Mechanism};
use crate::plan::ClusterRow;

/// How pure Newton treats a body.
#[derive(Clone, Debug)]
enum Role {
    /// Ground: the identity pose.
    Fixed,
    /// Placed directly from an input at a joint to the ground.
    Driven(Drive),
    /// Three unknowns (free).
    Unknown,
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

/// A mechanism solved by Newton–Raphson alone: one numeric cluster of every
/// mobile body not driven directly, each free (three unknowns), over every
/// equation — evaluated by the runtime's cluster system, the same residuals
/// and Jacobian as a mixed plan's clusters.
#[derive(Clone, Debug)]
pub struct PureNewton {
    roles: Vec<Role>,
    params: Vec<Param>,
    rows: Vec<ClusterRow>,
    /// The joint, constraint or input each of `rows` comes from.
    origins: Vec<String>,
    unknowns: usize,
    equations: usize,
    size: f64,
    options: NewtonOptions,
    input_kinds: Vec<InputKind>,
    /// The slots' ends, checked on every converged frame (the equations
    /// keep a pin on its slot's line or circle, not between the ends).
    ends: Vec<Ends>,
}

/// What pure Newton carries from frame to frame (buffers sized once).
#[derive(Clone, Debug)]
pub struct NewtonState {
    /// Body poses, in mechanism order.
    pub poses: Vec<Pose>,
    work: Vec<Pose>,
    newton: Newton,
}

impl PureNewton {
    /// Sets up pure Newton for a mechanism.
    pub fn new(m: &Mechanism) -> PureNewton {
        let mut roles: Vec<Role> = m
            .bodies
            .iter()
            .map(|b| if b.fixed { Role::Fixed } else { Role::Unknown })
            .collect();
        for (i, input) in m.inputs.iter().enumerate() {
            let joint = &m.joints[input.joint];
            let [a, b] = joint.markers;
            let (ground, driven, inverse) = match (m.bodies[a.body].fixed, m.bodies[b.body].fixed) {
                (true, false) => (a, b, false),
                (false, true) => (b, a, true),
                _ => continue,
            };
            if !matches!(roles[driven.body], Role::Unknown) {
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
        let params: Vec<Param> = (0..roles.len())
            .filter(|&b| matches!(roles[b], Role::Unknown))
            .map(|body| Param::Free { body })
            .collect();
        let (rows, origins): (Vec<ClusterRow>, Vec<String>) = equations(m)
            .into_iter()
            .filter(|s| s.eq.bodies().iter().any(|&b| matches!(roles[b], Role::Unknown)))
            .map(|s| (s.eq.row(), s.origin))
            .unzip();
        let (unknowns, equations) = cluster::size_of(&params, &rows);
        let size = m.size();
        PureNewton {
            roles,
            params,
            rows,
            origins,
            unknowns,
            equations,
            size,
            options: cluster::options(size),
            input_kinds: m.inputs.iter().map(|i| i.kind).collect(),
            ends: Ends::of(m),
        }
    }

    /// The first slot whose pin is past an end at `poses` (beyond 1e-9 of
    /// the size: a pin at its end is within it), and by how far.
    pub(super) fn past_an_end(&self, poses: &[Pose]) -> Option<f64> {
        Ends::first_past(&self.ends, poses, 1e-9 * self.size).map(|(_, gap)| gap)
    }

    /// Unknowns handed to Newton–Raphson.
    pub fn unknowns(&self) -> usize {
        self.unknowns
    }

    /// Scalar equations handed to Newton–Raphson.
    pub fn equations(&self) -> usize {
        self.equations
    }

    /// Number of bodies.
    pub fn bodies(&self) -> usize {
        self.roles.len()
    }

    /// The cluster's bodies and unknowns (every one free).
    pub fn params(&self) -> &[Param] {
        &self.params
    }

    /// The cluster's equations.
    pub fn rows(&self) -> &[ClusterRow] {
        &self.rows
    }

    /// The mechanism's size (angles are unknown as arc lengths at it).
    pub fn size(&self) -> f64 {
        self.size
    }

    /// The Jacobian of every equation at the drawn pose (all inputs at 0),
    /// with each equation's origin and number of rows, in row order.
    pub fn drawn_jacobian(&self) -> (DMatrix<f64>, Vec<(String, usize)>) {
        let mut poses = vec![Pose::IDENTITY; self.roles.len()];
        let inputs = vec![0.0; self.input_kinds.len()];
        self.place_driven(&mut poses, &inputs);
        let (mut system, x) = cluster::System::new(&mut poses, &self.params, &self.rows, &inputs, self.size);
        let mut r = DVector::zeros(self.equations);
        let mut j = DMatrix::zeros(self.equations, self.unknowns);
        system.eval(&x, &mut r, Some(&mut j));
        let groups = self
            .rows
            .iter()
            .zip(&self.origins)
            .map(|(row, o)| (o.clone(), row.count()))
            .collect();
        (j, groups)
    }

    /// The unknown columns of each body that has them: (body, first column).
    pub fn unknown_bodies(&self) -> Vec<(usize, usize)> {
        self.params
            .iter()
            .enumerate()
            .map(|(k, p)| (p.body(), 3 * k))
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

impl Solver for PureNewton {
    type Pose = Pose;
    type State = NewtonState;
    type Inputs = Vec<f64>;

    fn initial_state(&self) -> NewtonState {
        let poses = vec![Pose::IDENTITY; self.roles.len()];
        NewtonState {
            work: poses.clone(),
            poses,
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
        let NewtonState { poses, work, newton } = state;
        work.copy_from_slice(poses);
        self.place_driven(work, inputs);
        // Warm start: the unknowns of the last valid frame.
        let (mut system, mut x) = cluster::System::new(work, &self.params, &self.rows, inputs, self.size);
        let report: NewtonReport = newton.solve(&mut system, &mut x, &self.options);
        system.apply(&x);
        ctx.numeric = Some(report);
        match report.outcome {
            NewtonOutcome::Converged => {}
            NewtonOutcome::NoSolution => ctx.fail(0, BreakKind::NoSolution, report.residual)?,
            NewtonOutcome::NotConverged => ctx.fail(0, BreakKind::NotConverged, report.residual)?,
        }
        // Past a slot's end the frame breaks as the plan's check breaks it.
        if let Some(gap) = self.past_an_end(work) {
            ctx.fail(0, BreakKind::PastSlotEnd, gap)?;
        }
        std::mem::swap(poses, work);
        Ok(())
    }
}
