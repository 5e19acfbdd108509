//! The planar plan interpreter: each step of a planar plan IR executed by
//! the runtime function the generated code calls for it.

use dofplan_runtime::numeric::Newton;
use dofplan_runtime::planar::cluster;
use dofplan_runtime::planar::{self, cst, Point, Pose, Rot};
use dofplan_runtime::real::{Jet2, RateError, Real};
use dofplan_runtime::{Branch, BranchPolicy, Break, Ctx, FrameStatus, Solver, StepId};

use crate::model::InputKind;
use crate::plan::{ClusterParam, DirRef, Plan, PointRef, Rel, StepKind};

/// Executes a [`Plan`].
#[derive(Clone, Debug)]
pub struct Interpreter {
    plan: Plan,
}

/// What the interpreter carries from frame to frame. Its buffers are sized
/// once, so a frame reuses them without allocating.
#[derive(Debug)]
pub struct InterpState {
    /// Body poses, in the plan's body order.
    pub poses: Vec<Pose>,
    /// Each branching step's last root (point, or rotation as cos/sin).
    pub last: Vec<Point>,
    /// Each branching step's current branch.
    pub branches: Vec<Branch>,
    /// The frame being computed; swapped in when every step succeeded, so a
    /// break leaves the state above untouched.
    work: Work,
}

/// One execution's buffers, of `f64`s for a frame, of [`Jet2`]s for its
/// rates ([`Interpreter::rates`]).
#[derive(Debug)]
struct Work<T = f64> {
    poses: Vec<Pose<T>>,
    last: Vec<[T; 2]>,
    branches: Vec<Branch>,
    temps: Vec<[T; 2]>,
    rots: Vec<Rot<T>>,
    /// Newton work buffers, one per cluster (frames only).
    newtons: Vec<Newton>,
}

// Written out so that `clone_from` reuses the buffers: the driver's search
// policy copies states on the per-frame path.
impl Clone for InterpState {
    fn clone(&self) -> Self {
        InterpState {
            poses: self.poses.clone(),
            last: self.last.clone(),
            branches: self.branches.clone(),
            work: self.work.clone(),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.poses.clone_from(&source.poses);
        self.last.clone_from(&source.last);
        self.branches.clone_from(&source.branches);
        self.work.clone_from(&source.work);
    }
}

impl Clone for Work {
    fn clone(&self) -> Self {
        Work {
            poses: self.poses.clone(),
            last: self.last.clone(),
            branches: self.branches.clone(),
            temps: self.temps.clone(),
            rots: self.rots.clone(),
            newtons: self.newtons.clone(),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.poses.clone_from(&source.poses);
        self.last.clone_from(&source.last);
        self.branches.clone_from(&source.branches);
        self.temps.clone_from(&source.temps);
        self.rots.clone_from(&source.rots);
        self.newtons.clone_from(&source.newtons);
    }
}

impl Interpreter {
    /// An interpreter for `plan`.
    pub fn new(plan: Plan) -> Interpreter {
        Interpreter { plan }
    }

    /// The plan it executes.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    fn point<T: Scalar>(&self, s: &Work<T>, inputs: &[T], p: &PointRef) -> [T; 2] {
        match p {
            PointRef::Fixed { at, .. } => cst(*at),
            PointRef::Marker { body, local, .. } => s.poses[*body].world(*local),
            PointRef::Slid {
                body,
                local,
                dir,
                input,
                sign,
                ..
            } => {
                let u = T::cst(*sign) * inputs[*input];
                let (l, d) = (cst::<T>(*local), cst::<T>(*dir));
                let carried = [l[0] + u * d[0], l[1] + u * d[1]];
                // A fixed body is at its drawn pose (as `PointRef::Fixed`
                // takes it): the carried point is the world point.
                if self.plan.bodies[*body].fixed {
                    carried
                } else {
                    s.poses[*body].world_carried(carried)
                }
            }
            PointRef::Temp { id } => s.temps[*id],
        }
    }

    fn dir<T: Scalar>(&self, s: &Work<T>, d: &DirRef) -> [T; 2] {
        match d {
            DirRef::Fixed(v) => cst(*v),
            DirRef::Body { body, local } => s.poses[*body].world_dir(*local),
        }
    }

    /// A cluster's params for the runtime, where it is pinned and the
    /// lines it slides on read from the frame.
    fn cluster_params<T: Scalar>(
        &self,
        s: &Work<T>,
        inputs: &[T],
        params: &[ClusterParam],
    ) -> Vec<cluster::Param<T>> {
        params
            .iter()
            .map(|p| match p {
                ClusterParam::Free { body } => cluster::Param::Free { body: *body },
                ClusterParam::Angle { body, pin, at } => cluster::Param::Angle {
                    body: *body,
                    pin: *pin,
                    at: self.point(s, inputs, at),
                },
                ClusterParam::Hinge {
                    body,
                    pin,
                    parent,
                    at,
                    ..
                } => cluster::Param::Hinge {
                    body: *body,
                    pin: *pin,
                    parent: *parent,
                    at: *at,
                },
                ClusterParam::Slide { body, dir } => cluster::Param::Slide {
                    body: *body,
                    dir: self.dir(s, dir),
                },
                ClusterParam::Translate { body } => cluster::Param::Translate { body: *body },
            })
            .collect()
    }
}

impl Solver for Interpreter {
    type Pose = Pose;
    type State = InterpState;
    type Inputs = Vec<f64>;

    fn initial_state(&self) -> InterpState {
        let work = Work {
            poses: vec![Pose::IDENTITY; self.plan.bodies.len()],
            last: self.plan.branches.iter().map(|b| b.drawn).collect(),
            branches: self.plan.branches.iter().map(|b| b.initial).collect(),
            temps: vec![[0.0; 2]; self.plan.temps.len()],
            rots: vec![Rot::IDENTITY; self.plan.inputs.len()],
            newtons: self
                .plan
                .steps
                .iter()
                .filter(|s| matches!(s.kind, StepKind::Cluster { .. }))
                .map(|s| {
                    let (n, m) = s.kind.cluster_size();
                    Newton::new(n, m)
                })
                .collect(),
        };
        InterpState {
            poses: work.poses.clone(),
            last: work.last.clone(),
            branches: work.branches.clone(),
            work,
        }
    }

    fn initial_inputs(&self) -> Vec<f64> {
        vec![0.0; self.plan.inputs.len()]
    }

    fn poses(state: &InterpState) -> &[Pose] {
        &state.poses
    }

    fn solve(&self, state: &mut InterpState, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        let w = &mut state.work;
        w.poses.copy_from_slice(&state.poses);
        w.last.copy_from_slice(&state.last);
        w.branches.copy_from_slice(&state.branches);
        self.run(w, inputs, ctx)?;
        std::mem::swap(&mut state.poses, &mut w.poses);
        std::mem::swap(&mut state.last, &mut w.last);
        std::mem::swap(&mut state.branches, &mut w.branches);
        Ok(())
    }
}

impl Interpreter {
    /// A check of a slot's ends: the pin between them, along the line or
    /// round the arc.
    fn within<T: Scalar>(
        &self,
        s: &mut Work<T>,
        inputs: &[T],
        ctx: &mut Ctx,
        id: StepId,
        kind: &StepKind,
    ) -> Result<(), Break> {
        let StepKind::Within {
            at,
            dir,
            pin,
            ends,
            arc,
        } = kind
        else {
            unreachable!("a slot's check")
        };
        let (a, d, p) = (
            self.point(s, inputs, at),
            self.dir(s, dir),
            self.point(s, inputs, pin),
        );
        match arc {
            false => planar::within_ends(ctx, id, a, d, p, *ends),
            true => planar::within_arc(ctx, id, a, d, p, *ends),
        }
    }

    /// A geared step: a body turned to an angle, or a rack moved along its
    /// slide, affine in the inputs.
    fn geared<T: Scalar>(&self, s: &mut Work<T>, inputs: &[T], kind: &StepKind) {
        match kind {
            StepKind::Turn { body, angle } => {
                planar::set_rotation(&mut s.poses[*body], T::rot_from_degrees(angle.eval(inputs)));
            }
            StepKind::Shift {
                body,
                local,
                carrier,
                at,
                dir,
                slide,
                ..
            } => {
                let u = slide.eval(inputs);
                let (l, d) = (cst::<T>(*at), cst::<T>(*dir));
                let carried = [l[0] + u * d[0], l[1] + u * d[1]];
                // A fixed carrier is at its drawn pose (as for
                // `PointRef::Slid`): the carried point is the world point.
                let at = if self.plan.bodies[*carrier].fixed {
                    carried
                } else {
                    s.poses[*carrier].world_carried(carried)
                };
                planar::anchor(&mut s.poses[*body], *local, at);
            }
            _ => unreachable!("only geared steps"),
        }
    }

    /// Executes every step on the work buffers: a frame with `f64`s, its
    /// rates with [`Jet2`]s — the same steps, the same runtime functions.
    fn run<T: Scalar>(&self, s: &mut Work<T>, inputs: &[T], ctx: &mut Ctx) -> Result<(), Break> {
        for (k, input) in self.plan.inputs.iter().enumerate() {
            if input.kind == InputKind::Angle {
                s.rots[k] = T::rot_from_degrees(inputs[k]);
            }
        }
        for (i, step) in self.plan.steps.iter().enumerate() {
            let id = i as u32;
            match &step.kind {
                StepKind::Orient { body, from, rel } => orient(s, *body, *from, rel),
                StepKind::Turn { .. } | StepKind::Shift { .. } => self.geared(s, inputs, &step.kind),
                StepKind::Anchor { body, local, at } => {
                    let at = self.point(s, inputs, at);
                    planar::anchor(&mut s.poses[*body], *local, at);
                }
                StepKind::Align {
                    body,
                    p,
                    p_at,
                    q,
                    q_at,
                    redundant,
                } => {
                    let p_at = self.point(s, inputs, p_at);
                    let q_at = self.point(s, inputs, q_at);
                    let (p, q) = (*p, *q);
                    if *redundant {
                        planar::align_consistent(ctx, id, &mut s.poses[*body], p, p_at, q, q_at)?;
                    } else {
                        planar::align(&mut s.poses[*body], p, p_at, q, q_at);
                    }
                }
                StepKind::CircleCircle {
                    out,
                    c1,
                    r1,
                    c2,
                    r2,
                    branch,
                } => {
                    let c1 = self.point(s, inputs, c1);
                    let c2 = self.point(s, inputs, c2);
                    let (a, b) = (
                        planar::Circle::new(c1, T::cst(*r1)),
                        planar::Circle::new(c2, T::cst(*r2)),
                    );
                    let slot = planar::Slot::new(&mut s.branches[*branch], &mut s.last[*branch]);
                    s.temps[*out] = planar::circle_circle(ctx, id, a, b, slot)?;
                }
                StepKind::CircleLine {
                    out,
                    c,
                    r,
                    line,
                    branch,
                } => {
                    let c = self.point(s, inputs, c);
                    let p = self.point(s, inputs, &line.through);
                    let (circle, k) = (planar::Circle::new(c, T::cst(*r)), *branch);
                    let slot = planar::Slot::new(&mut s.branches[k], &mut s.last[k]);
                    // As the emitted code: a fixed direction as plain numbers.
                    s.temps[*out] = match &line.dir {
                        DirRef::Fixed(d) => {
                            planar::circle_line(ctx, id, circle, planar::Line::new(p, *d), slot)
                        }
                        DirRef::Body { body, local } => {
                            let d = s.poses[*body].world_dir(*local);
                            planar::circle_line(ctx, id, circle, planar::Line::new(p, d), slot)
                        }
                    }?;
                }
                StepKind::LineLine { out, a, b } => {
                    let p1 = self.point(s, inputs, &a.through);
                    let d1 = self.dir(s, &a.dir);
                    let p2 = self.point(s, inputs, &b.through);
                    let d2 = self.dir(s, &b.dir);
                    s.temps[*out] = planar::line_line(ctx, id, p1, d1, p2, d2)?;
                }
                StepKind::Cluster { index, params, rows } => {
                    T::cluster(self, s, inputs, ctx, id, *index, params, rows)?;
                }
                StepKind::Within { .. } => self.within(s, inputs, ctx, id, &step.kind)?,
                StepKind::TurnLine {
                    body,
                    pivot,
                    target,
                    dir,
                    kappa,
                    branch,
                } => {
                    let pivot = self.point(s, inputs, pivot);
                    let target = self.point(s, inputs, target);
                    s.poses[*body].rot = planar::turn_line_through(
                        ctx,
                        id,
                        pivot,
                        target,
                        cst(*dir),
                        T::cst(*kappa),
                        planar::Slot::new(&mut s.branches[*branch], &mut s.last[*branch]),
                    )?;
                }
            }
        }
        Ok(())
    }
}

/// What the interpreter computes with: `f64` for frames, [`Jet2`] for
/// their rates. Two steps differ: an angle input's rotation (with its
/// rates), and a numeric cluster (solved by Newton for a frame; for its
/// rates solved the same way on the values, then differentiated by the
/// implicit function theorem).
trait Scalar: Real {
    fn rot_from_degrees(degrees: Self) -> Rot<Self>;
    #[allow(clippy::too_many_arguments)]
    fn cluster(
        interp: &Interpreter,
        s: &mut Work<Self>,
        inputs: &[Self],
        ctx: &mut Ctx,
        id: u32,
        index: usize,
        params: &[ClusterParam],
        rows: &[crate::plan::ClusterRow],
    ) -> Result<(), Break>;
}

impl Scalar for f64 {
    fn rot_from_degrees(degrees: f64) -> Rot {
        Rot::from_degrees(degrees)
    }

    fn cluster(
        interp: &Interpreter,
        s: &mut Work,
        inputs: &[f64],
        ctx: &mut Ctx,
        id: u32,
        index: usize,
        params: &[ClusterParam],
        rows: &[crate::plan::ClusterRow],
    ) -> Result<(), Break> {
        let params = interp.cluster_params(s, inputs, params);
        cluster::solve(
            ctx,
            id,
            &mut s.poses,
            &params,
            rows,
            inputs,
            interp.plan.size,
            &mut s.newtons[index],
        )
    }
}

impl Scalar for Jet2 {
    fn rot_from_degrees(degrees: Jet2) -> Rot<Jet2> {
        Rot::from_degrees_jet(degrees)
    }

    fn cluster(
        interp: &Interpreter,
        s: &mut Work<Jet2>,
        inputs: &[Jet2],
        ctx: &mut Ctx,
        id: u32,
        _: usize,
        params: &[ClusterParam],
        rows: &[crate::plan::ClusterRow],
    ) -> Result<(), Break> {
        let params = interp.cluster_params(s, inputs, params);
        let (n, m) = cluster::size_of(&params, rows);
        let mut newton = Newton::new(n, m);
        cluster::solve_rates(
            ctx,
            id,
            &mut s.poses,
            &params,
            rows,
            inputs,
            interp.plan.size,
            &mut newton,
        )
    }
}

/// A closed-form plan's frames are independent under keep-branch (a step
/// places a body from its inputs and the constants, never from its last
/// pose), as the generated module's are: solved each on its own (no lanes
/// here), and on several cores by
/// `dofplan_runtime::batch::solve_batch_parallel`, whose `settle` then makes
/// them the driver's. A plan with a numeric cluster warm-starts Newton from
/// the last frame: its frames are solved in order.
impl dofplan_runtime::Batch for Interpreter {
    fn independent(&self) -> bool {
        self.plan.clusters() == 0
    }

    fn solve_frames(&self, inputs: &[f64], out: &mut [Pose], status: &mut [FrameStatus]) {
        if self.independent() {
            dofplan_runtime::batch::one_at_a_time(self, 0..status.len(), inputs, out, status);
        } else {
            dofplan_runtime::batch::in_order(self, inputs, out, status);
        }
    }
}

impl dofplan_runtime::real::Rates for Interpreter {
    fn rates_into(
        &self,
        state: &InterpState,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
        out: &mut [Pose<Jet2>],
    ) -> Result<(), RateError> {
        out.copy_from_slice(&self.rates(state, inputs, rates, accelerations)?);
        Ok(())
    }
}

impl Interpreter {
    /// Every body's pose at the frame `state` was solved to (at `inputs`),
    /// with its first and second derivatives along the inputs' `rates` and
    /// `accelerations`: forward-mode differentiation through the plan, the
    /// same steps run on [`Jet2`]s with the branches the frame took (a
    /// numeric cluster solved again on the values, its rates by the
    /// implicit function theorem: [`cluster::solve_rates`]). With
    /// one input at rate 1 and acceleration 0 the derivatives are d/dθ and
    /// d²/dθ² (per degree for an angle); with real rates, velocities and
    /// accelerations.
    pub fn rates(
        &self,
        state: &InterpState,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
    ) -> Result<Vec<Pose<Jet2>>, RateError> {
        let mut w: Work<Jet2> = Work {
            poses: state.poses.iter().map(|p| Pose::cst(*p)).collect(),
            last: state.last.iter().map(|p| cst(*p)).collect(),
            branches: state.branches.clone(),
            temps: vec![cst([0.0; 2]); self.plan.temps.len()],
            rots: vec![Rot::cst(Rot::IDENTITY); self.plan.inputs.len()],
            newtons: Vec::new(),
        };
        let jets: Vec<Jet2> = (0..inputs.len())
            .map(|k| Jet2::new(inputs[k], rates[k], accelerations[k]))
            .collect();
        // The frame's branches, kept: the rates are those of the root it took.
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        self.run(&mut w, &jets, &mut ctx).map_err(RateError::Break)?;
        let finite = w
            .poses
            .iter()
            .all(|p| p.at.iter().all(|x| x.finite()) && p.rot.c.finite() && p.rot.s.finite());
        if finite {
            Ok(w.poses)
        } else {
            Err(RateError::Singular)
        }
    }
}

/// Sets a body's rotation from another's (or the ground's) and a relative
/// rotation: an input's or none.
fn orient<T: Scalar>(s: &mut Work<T>, body: usize, from: Option<usize>, rel: &Rel) {
    let r = match rel {
        Rel::Identity => Rot::cst(Rot::IDENTITY),
        Rel::Input {
            input,
            inverse: false,
        } => s.rots[*input],
        Rel::Input { input, inverse: true } => s.rots[*input].inverse(),
    };
    match from {
        Some(from) => {
            let from = s.poses[from].rot;
            planar::orient(&mut s.poses[body], from, r);
        }
        None => planar::set_rotation(&mut s.poses[body], r),
    }
}
