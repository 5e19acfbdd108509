//! The spatial plan interpreter: executes a [`Plan`] step by step through
//! the same `dofplan_runtime::spatial` functions generated code calls —
//! on `f64`s for a frame, on [`Jet2`]s for its rates
//! ([`Interpreter::rates`]).

use dofplan_runtime::planar::Degrees;
use dofplan_runtime::real::Rates;
use dofplan_runtime::real::{Jet2, RateError, Real};
use dofplan_runtime::spatial::rows::WorldFrame;
use dofplan_runtime::spatial::{self, cst, norm, scale, sub, Pose3, Vec3};
use dofplan_runtime::{Branch, BranchPolicy, Break, BreakKind, Ctx, Rot, Solver};

use crate::plan::spatial::{Action, CheckRow, DirRef, HingeTurn, Locus, Plan, PointRef, StepKind};

pub mod cluster;
mod state;

pub use state::InterpState;
pub(crate) use state::{dir_at, point_at};

/// Executes a [`Plan`].
#[derive(Clone, Debug)]
pub struct Interpreter {
    plan: Plan,
    /// The bodies whose rotations are composed frame after frame
    /// ([`Plan::composes`]), corrected once a frame.
    composed: Vec<usize>,
}

impl Interpreter {
    /// An interpreter for `plan`.
    pub fn new(plan: Plan) -> Interpreter {
        let composed = (0..plan.bodies.len()).filter(|&b| plan.composes(b)).collect();
        Interpreter { plan, composed }
    }

    /// The plan.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// Runs every step on `s` (left half-updated on a break: [`Solver::solve`]
    /// works on a copy).
    pub fn run(&self, s: &mut InterpState, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        let mut from = 0;
        loop {
            let mut w = Work {
                poses: &mut s.poses,
                temps: &mut s.temps,
                branches: &mut s.branches,
                angles: &mut s.angles,
            };
            // A numeric cluster needs the whole state: the closed-form
            // steps stop before it, and go on after it.
            let Some(i) = self.steps(&mut w, inputs, inputs, ctx, from)? else {
                break;
            };
            let StepKind::Cluster(c) = &self.plan.steps[i].kind else {
                unreachable!("the steps stop at clusters only");
            };
            cluster::solve(s, c, inputs, ctx, (i + 1) as u32)?;
            from = i + 1;
        }
        // Rotations composed frame after frame drift from orthonormal; one
        // correction a frame keeps every body rigid indefinitely.
        for &b in &self.composed {
            s.poses[b].renormalize();
        }
        Ok(())
    }

    /// The closed-form steps from step `from` on, on `f64`s or on jets
    /// (`inputs`; check rows read their values, `values`), up to the first
    /// numeric cluster: its index, or none when the plan is done.
    fn steps<T: Degrees>(
        &self,
        w: &mut Work<T>,
        inputs: &[T],
        values: &[f64],
        ctx: &mut Ctx,
        from: usize,
    ) -> Result<Option<usize>, Break> {
        for (i, step) in self.plan.steps.iter().enumerate().skip(from) {
            let id = (i + 1) as u32;
            match &step.kind {
                StepKind::Act { body, action } => act(w, *body, action, inputs, ctx, id)?,
                StepKind::Intersect {
                    temp,
                    loci,
                    branch,
                    tol,
                } => {
                    let mut br = branch.map_or(Branch::Plus, |k| w.branches[k]);
                    let mut last = w.temps[*temp];
                    let slot = spatial::Slot::new(&mut br, &mut last);
                    let x = intersect(w, loci, *tol, inputs, ctx, id, slot)?;
                    if let Some(k) = branch {
                        w.branches[*k] = br;
                    }
                    w.temps[*temp] = x;
                }
                StepKind::IntersectDir {
                    temps,
                    cones,
                    sign,
                    branch,
                } => {
                    let [(a1, c1), (a2, c2)] = cones.as_ref();
                    let (w1, w2) = (w.dir(a1, inputs), w.dir(a2, inputs));
                    let mut br = w.branches[*branch];
                    let mut last = w.temps[temps[0]];
                    let (a, b) = (spatial::Cone::new(w1, *c1), spatial::Cone::new(w2, sign * c2));
                    let d = spatial::cone_cone(ctx, id, a, b, spatial::Slot::new(&mut br, &mut last))?;
                    w.branches[*branch] = br;
                    w.temps[temps[0]] = d;
                    w.temps[temps[1]] = scale(d, T::cst(*sign));
                }
                StepKind::Check { rows } => {
                    for r in rows {
                        let gap = check_gap_at(w.poses, r, values);
                        if gap > r.tol {
                            ctx.fail(id, BreakKind::Inconsistent, gap)?;
                        }
                    }
                }
                StepKind::Cluster(_) => return Ok(Some(i)),
            }
        }
        Ok(None)
    }

    /// Every body's pose at the frame `state` was solved to (at `inputs`),
    /// with its first and second derivatives along the inputs' `rates` and
    /// `accelerations`: forward-mode differentiation through the plan, the
    /// same steps run on [`Jet2`]s with the branches the frame took (the
    /// spatial counterpart of
    /// [`Interpreter::rates`](crate::interp::Interpreter::rates)). A plan
    /// numeric cluster is solved again on the values, its rates by the
    /// implicit function theorem ([`spatial_cluster::solve_rates`]); a dead
    /// point, where a rate is infinite, gives [`RateError::Singular`]. A
    /// drag's plan (a marker pinned) gives [`RateError::Cluster`].
    ///
    /// [`spatial_cluster::solve_rates`]: cluster::solve_rates
    pub fn rates(
        &self,
        state: &InterpState,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
    ) -> Result<Vec<Pose3<Jet2>>, RateError> {
        let pinned = self.plan.steps.iter().any(|s| match &s.kind {
            StepKind::Cluster(c) => c
                .rows
                .iter()
                .any(|r| matches!(r, crate::plan::spatial::ClusterRow::Pin { .. })),
            _ => false,
        });
        if pinned {
            return Err(RateError::Cluster);
        }
        let mut poses: Vec<Pose3<Jet2>> = state.poses.iter().map(|p| Pose3::cst(*p)).collect();
        let mut temps: Vec<Vec3<Jet2>> = state.temps.iter().map(|t| cst(*t)).collect();
        let (mut branches, mut angles) = (state.branches.clone(), state.angles.clone());
        let jets: Vec<Jet2> = (0..inputs.len())
            .map(|k| Jet2::new(inputs[k], rates[k], accelerations[k]))
            .collect();
        // The frame's branches, kept: the rates are those of the root it took.
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        let mut from = 0;
        loop {
            let mut w = Work {
                poses: &mut poses,
                temps: &mut temps,
                branches: &mut branches,
                angles: &mut angles,
            };
            let Some(i) = self.steps(&mut w, &jets, inputs, &mut ctx, from)? else {
                break;
            };
            let StepKind::Cluster(c) = &self.plan.steps[i].kind else {
                unreachable!("the steps stop at clusters only");
            };
            let id = (i + 1) as u32;
            cluster::solve_rates(&mut poses, &temps, c, &jets, inputs, &mut ctx, id)?;
            from = i + 1;
        }
        for &b in &self.composed {
            poses[b].renormalize();
        }
        spatial::checked3(poses)
    }
}

impl Rates for Interpreter {
    fn rates_into(
        &self,
        state: &InterpState,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
        out: &mut [Pose3<Jet2>],
    ) -> Result<(), RateError> {
        out.copy_from_slice(&self.rates(state, inputs, rates, accelerations)?);
        Ok(())
    }
}

/// One execution's buffers, borrowed apart: of a [`InterpState`] for a frame, of
/// jets for its rates.
struct Work<'a, T> {
    poses: &'a mut [Pose3<T>],
    temps: &'a mut [Vec3<T>],
    branches: &'a mut [Branch],
    angles: &'a mut [f64],
}

impl<T: Real> Work<'_, T> {
    fn point(&self, p: &PointRef, inputs: &[T]) -> Vec3<T> {
        point_at(self.poses, self.temps, p, inputs)
    }

    fn dir(&self, d: &DirRef, inputs: &[T]) -> Vec3<T> {
        dir_at(self.poses, self.temps, d, inputs)
    }
}

/// A check row's largest residual at the values of `poses`.
fn check_gap_at<T: Real>(poses: &[Pose3<T>], r: &CheckRow, inputs: &[f64]) -> f64 {
    let value = |b: usize| {
        let p = &poses[b];
        Pose3 {
            rot: dofplan_runtime::spatial::Rot3 {
                m: p.rot.m.map(spatial::value),
            },
            pos: spatial::value(p.pos),
        }
    };
    let f1 = WorldFrame::of(&value(r.bodies[0]), r.at[0], r.z[0], r.x[0]);
    let f2 = WorldFrame::of(&value(r.bodies[1]), r.at[1], r.z[1], r.x[1]);
    r.kind.gap(&f1, &f2, inputs)
}

/// Moves body `body` by one action of step `id`: a translation, a
/// rotation, or a hinged body's pose set outright.
fn act<T: Degrees>(
    s: &mut Work<T>,
    body: usize,
    a: &Action,
    inputs: &[T],
    ctx: &mut Ctx,
    id: u32,
) -> Result<(), Break> {
    match a {
        Action::TranslateOnto { .. }
        | Action::TranslateAlong { .. }
        | Action::TranslateInPlane { .. }
        | Action::TranslateToLine { .. }
        | Action::TranslateToPlane { .. }
        | Action::SlideTo { .. } => translate(s, body, a, inputs),
        Action::Hinge { .. } => hinge(s, body, a, inputs),
        _ => rotate(s, body, a, inputs, ctx, id)?,
    }
    Ok(())
}

/// The translations: the body keeps its rotation.
fn translate<T: Degrees>(s: &mut Work<T>, body: usize, a: &Action, inputs: &[T]) {
    let p = |s: &Work<T>, q: &PointRef| s.point(q, inputs);
    let d = |s: &Work<T>, v: &DirRef| s.dir(v, inputs);
    match a {
        Action::TranslateOnto { from, to } => {
            let (f, t) = (p(s, from), p(s, to));
            spatial::translate_onto(&mut s.poses[body], f, t);
        }
        Action::TranslateAlong { from, to, dir: l } => {
            let (f, t, u) = (p(s, from), p(s, to), d(s, l));
            spatial::translate_along(&mut s.poses[body], f, t, u);
        }
        Action::TranslateInPlane { from, to, normal } => {
            let (f, t, n) = (p(s, from), p(s, to), d(s, normal));
            spatial::translate_in_plane(&mut s.poses[body], f, t, n);
        }
        Action::TranslateToLine {
            from,
            through,
            dir: l,
        } => {
            let (f, q, u) = (p(s, from), p(s, through), d(s, l));
            spatial::translate_to_line(&mut s.poses[body], f, q, u);
        }
        Action::TranslateToPlane {
            from,
            through,
            normal,
        } => {
            let (f, q, n) = (p(s, from), p(s, through), d(s, normal));
            spatial::translate_to_plane(&mut s.poses[body], f, q, n);
        }
        Action::SlideTo {
            from,
            origin,
            dir: l,
            axial0,
            input,
            sign,
        } => {
            let (f, o, u) = (p(s, from), p(s, origin), d(s, l));
            spatial::slide_to(
                &mut s.poses[body],
                o,
                f,
                u,
                T::cst(*axial0) + inputs[*input],
                *sign,
            );
        }
        _ => unreachable!("not a translation"),
    }
}

/// The rotations about a point or an axis (a branch for a rotation to a
/// condition, whose sine the slot keeps).
fn rotate<T: Degrees>(
    s: &mut Work<T>,
    body: usize,
    a: &Action,
    inputs: &[T],
    ctx: &mut Ctx,
    id: u32,
) -> Result<(), Break> {
    let p = |s: &Work<T>, q: &PointRef| s.point(q, inputs);
    let d = |s: &Work<T>, v: &DirRef| s.dir(v, inputs);
    match a {
        Action::RotateOnto { pivot, from, to } => {
            let (c, f, t) = (p(s, pivot), p(s, from), p(s, to));
            spatial::rotate_about_point(&mut s.poses[body], c, sub(f, c), sub(t, c));
        }
        Action::AlignDir { pivot, from, to } => {
            let (c, f, t) = (p(s, pivot), d(s, from), d(s, to));
            spatial::rotate_about_point(&mut s.poses[body], c, f, t);
        }
        Action::AxisOnto {
            pivot,
            axis,
            from,
            to,
        } => {
            let (c, a, f, t) = (p(s, pivot), d(s, axis), p(s, from), p(s, to));
            spatial::rotate_about_axis_onto(&mut s.poses[body], c, a, f, t);
        }
        Action::AxisDir {
            pivot,
            axis,
            from,
            to,
        } => {
            let (c, a, f, t) = (p(s, pivot), d(s, axis), d(s, from), d(s, to));
            spatial::rotate_about_axis_dir(&mut s.poses[body], c, a, f, t);
        }
        Action::Twist {
            pivot,
            axis,
            x1,
            x2,
            angle,
            input,
            sign,
        } => {
            let (c, a, u1, u2) = (p(s, pivot), d(s, axis), d(s, x1), d(s, x2));
            let degrees = T::cst(angle.to_degrees()) + input.map_or(T::cst(0.0), |i| inputs[i]);
            let target: Rot<T> = degrees.degrees_rot();
            let (sin, cos) = spatial::twist_correction(a, u1, u2, target, *sign);
            spatial::rotate_about_axis_angle(&mut s.poses[body], c, a, cos, sin);
        }
        Action::AxisCondition {
            pivot,
            axis,
            v,
            w,
            cos,
            branch,
        } => {
            let (c, a, vv, ww) = (p(s, pivot), d(s, axis), d(s, v), d(s, w));
            let mut br = s.branches[*branch];
            let mut last = s.angles[*branch];
            let slot = spatial::Slot::new(&mut br, &mut last);
            let (co, si) = spatial::rotation_to_condition(ctx, id, a, vv, ww, *cos, slot)?;
            s.branches[*branch] = br;
            s.angles[*branch] = last;
            spatial::rotate_about_axis_angle(&mut s.poses[body], c, a, co, si);
        }
        Action::Tilt { pivot, from, to, cos } => {
            let (c, f, t) = (p(s, pivot), d(s, from), d(s, to));
            spatial::tilt(&mut s.poses[body], c, f, t, *cos);
        }
        _ => unreachable!("not a rotation"),
    }
    Ok(())
}

/// A body hinged on a fixed line, its pose set outright from the drawn one.
fn hinge<T: Degrees>(s: &mut Work<T>, body: usize, a: &Action, inputs: &[T]) {
    let p = |s: &Work<T>, q: &PointRef| s.point(q, inputs);
    let d = |s: &Work<T>, v: &DirRef| s.dir(v, inputs);
    let Action::Hinge { pivot, axis, turn } = a else {
        unreachable!("a hinge")
    };
    match turn {
        HingeTurn::Degrees { offset, input, sign } => {
            // `(offset + input)·sign`, the same product as the
            // generated `sign * (offset + input)`.
            let degrees = (T::cst(*offset) + input.map_or(T::cst(0.0), |i| inputs[i])).mul_f64(*sign);
            spatial::hinge_degrees(&mut s.poses[body], *pivot, *axis, degrees);
        }
        HingeTurn::Onto { from, to } => {
            let t = p(s, to);
            spatial::hinge_onto(&mut s.poses[body], *pivot, *axis, *from, t);
        }
        HingeTurn::Dir { from, to } => {
            let t = d(s, to);
            spatial::hinge_dir(&mut s.poses[body], *pivot, *axis, *from, t);
        }
    }
}

/// The point on both `loci` at the working poses: the runtime step for the
/// pair, called on the loci as the generated code calls it.
fn intersect<T: Real>(
    s: &Work<T>,
    loci: &[Locus; 2],
    tol: f64,
    inputs: &[T],
    ctx: &mut Ctx,
    id: u32,
    slot: spatial::Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let p = |q: &PointRef| s.point(q, inputs);
    let d = |v: &DirRef| s.dir(v, inputs);
    let circle = |pivot: &PointRef, axis: &DirRef, at: &PointRef| {
        let (c, n, r) = spatial::circle_about(p(pivot), d(axis), p(at));
        spatial::Circle::new(c, n, r)
    };
    let sphere = |centre: &PointRef, a: &PointRef, b: &PointRef| {
        spatial::Sphere::new(p(centre), norm(sub(p(b), p(a))))
    };
    let line = |at: &PointRef, l: &DirRef| spatial::Line::new(p(at), d(l));
    match loci {
        [Locus::Circle { pivot, axis, at }, Locus::Circle {
            pivot: p2,
            axis: a2,
            at: x2,
        }] => {
            let (a, b) = (circle(pivot, axis, at), circle(p2, a2, x2));
            spatial::circle_circle(ctx, id, a, b, tol, slot)
        }
        [Locus::Sphere { centre, a, b }, Locus::Circle { pivot, axis, at: x }]
        | [Locus::Circle { pivot, axis, at: x }, Locus::Sphere { centre, a, b }] => {
            spatial::sphere_circle(ctx, id, sphere(centre, a, b), circle(pivot, axis, x), slot)
        }
        [Locus::Line { at, dir: l }, Locus::Sphere { centre, a, b }]
        | [Locus::Sphere { centre, a, b }, Locus::Line { at, dir: l }] => {
            spatial::line_sphere(ctx, id, line(at, l), sphere(centre, a, b), slot)
        }
        [Locus::Line { at, dir: l }, Locus::Circle { pivot, axis, at: x }]
        | [Locus::Circle { pivot, axis, at: x }, Locus::Line { at, dir: l }] => {
            spatial::line_circle(ctx, id, line(at, l), circle(pivot, axis, x), tol, slot)
        }
        _ => unreachable!("the planner intersects only the pairs above"),
    }
}

impl Solver for Interpreter {
    type Pose = Pose3;
    type State = InterpState;
    type Inputs = Vec<f64>;

    fn initial_state(&self) -> InterpState {
        InterpState {
            poses: vec![Pose3::IDENTITY; self.plan.bodies.len()],
            temps: self.plan.temps.iter().map(|t| t.drawn).collect(),
            branches: self.plan.branches.iter().map(|b| b.initial).collect(),
            angles: self.plan.branches.iter().map(|b| b.angle).collect(),
            undo: Box::default(),
        }
    }

    fn initial_inputs(&self) -> Vec<f64> {
        vec![0.0; self.plan.inputs.len()]
    }

    fn poses(state: &InterpState) -> &[Pose3] {
        &state.poses
    }

    fn solve(&self, state: &mut InterpState, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        // A break must leave the state as it was.
        let u = &mut state.undo;
        u.poses.clone_from(&state.poses);
        u.temps.clone_from(&state.temps);
        u.branches.clone_from(&state.branches);
        u.angles.clone_from(&state.angles);
        let result = self.run(state, inputs, ctx);
        if result.is_err() {
            let u = &state.undo;
            state.poses.clone_from(&u.poses);
            state.temps.clone_from(&u.temps);
            state.branches.clone_from(&u.branches);
            state.angles.clone_from(&u.angles);
        }
        result
    }
}

/// A spatial plan's frames depend on each other (each action moves a body
/// from its last pose), so a batch runs them in order, as the driver
/// would: the `Batch` defaults.
impl dofplan_runtime::Batch for Interpreter {}
