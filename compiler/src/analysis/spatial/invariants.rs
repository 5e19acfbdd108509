//! Plan rewrites that read what cannot change as constants.
//!
//! **Hinged bodies set outright.** The planner places a body hinged to a
//! fixed body as it places any other: every frame it re-imposes the hinge
//! (translate the body's pivot onto the fixed point, align its axis), then
//! turns the body about the axis from last frame's pose. When every later
//! action on the body is such a turn, the body never leaves its line, so
//! [`place_hinged`] drops the two re-imposing steps and makes each turn an
//! [`Action::Hinge`]: the pose built from the drawn one. A frame then saves
//! the two steps, a matrix composition per turn and the body's rigidity
//! correction (a rotation built afresh does not drift), and later steps read
//! the body's points on the line, its axis and the circles its markers sweep
//! as constants. It is a pass over the finished plan rather than a fragment
//! because only the whole plan tells whether every later action on the
//! body is a turn about its hinge.
//!
//! **Rigid lengths.** A sphere locus's radius is the distance between two
//! points of one body: the same in every pose, so read from the drawing.

use dofplan_runtime::spatial::{cross, dist, norm, reject, sub, twist_correction, Vec3};
use dofplan_runtime::Rot;

use crate::plan::spatial::{
    Action, BodyId, Cluster, ClusterRow, DirRef, HingeTurn, Locus, Param, Plan, PointRef, StepKind,
};

/// Directions parallel to this (the cross product of unit vectors) are one.
const PARALLEL: f64 = 1e-12;

/// A fixed line a body turns about.
#[derive(Clone, Copy, Debug)]
struct Line {
    pivot: Vec3,
    axis: Vec3,
}

impl Line {
    fn holds(&self, p: Vec3, tol: f64) -> bool {
        norm(reject(sub(p, self.pivot), self.axis)) <= tol
    }

    fn along(&self, d: Vec3) -> bool {
        norm(cross(d, self.axis)) <= PARALLEL && norm(d) > 0.0
    }
}

/// Every body hinged on a fixed line whose later actions are all turns
/// about it is set outright ([`Action::Hinge`]); the steps that
/// re-imposed its hinge are dropped (what they served is listed on its
/// first turn); explanations, derived from the steps, number them anew. `size` is the
/// mechanism's size: points within 1e-12 of it are one.
pub(super) fn place_hinged(plan: &mut Plan, size: f64) {
    let tol = 1e-12 * size.max(1.0);
    // Each body's hinge, if it is set outright.
    let mut hinged: Vec<Option<Line>> = vec![None; plan.bodies.len()];
    let mut dropped = vec![false; plan.steps.len()];
    // Each body's actions, and whether a cluster turns it (from last
    // frame's pose, so it is not set outright): one walk over the steps.
    let mut acts_of = vec![Vec::new(); plan.bodies.len()];
    let mut clustered = vec![false; plan.bodies.len()];
    for (i, s) in plan.steps.iter().enumerate() {
        match &s.kind {
            StepKind::Act { body, .. } => acts_of[*body].push(i),
            StepKind::Cluster(c) => c.params.iter().for_each(|p| clustered[p.body()] = true),
            _ => {}
        }
    }
    for b in 0..plan.bodies.len() {
        if plan.fixed[b] || clustered[b] {
            continue;
        }
        let Some((line, acts, turns)) = hinge_of(plan, b, std::mem::take(&mut acts_of[b]), tol) else {
            continue;
        };
        let mut serves: Vec<String> = Vec::new();
        for &i in &acts[..2] {
            dropped[i] = true;
            serves.extend(plan.steps[i].serves.iter().cloned());
        }
        for (k, (i, action)) in acts[2..].iter().zip(turns).enumerate() {
            let step = &mut plan.steps[*i];
            step.kind = StepKind::Act {
                body: b,
                action: Box::new(action),
            };
            if k == 0 {
                for s in std::mem::take(&mut step.serves) {
                    if !serves.contains(&s) {
                        serves.push(s);
                    }
                }
                step.serves = std::mem::take(&mut serves);
            }
        }
        hinged[b] = Some(line);
    }
    if hinged.iter().all(Option::is_none) {
        return;
    }
    let steps = std::mem::take(&mut plan.steps);
    plan.steps = steps
        .into_iter()
        .zip(&dropped)
        .filter(|(_, d)| !**d)
        .map(|(s, _)| s)
        .collect();
    for step in &mut plan.steps {
        read_constants(&mut step.kind, &hinged, tol);
    }
}

/// Body `b`'s hinge, the indices of its actions `acts` (the two
/// re-imposing the hinge first) and its turns rewritten, if `b` is hinged
/// and only turned about its hinge after that.
fn hinge_of(plan: &Plan, b: BodyId, acts: Vec<usize>, tol: f64) -> Option<(Line, Vec<usize>, Vec<Action>)> {
    if acts.len() < 3 {
        return None;
    }
    let action = |i: usize| match &plan.steps[i].kind {
        StepKind::Act { action, .. } => &**action,
        _ => unreachable!("acts are Act steps"),
    };
    // The hinge as the planner imposes it: the body's pivot onto a fixed
    // point where it is drawn, then its axis onto a fixed axis it is drawn
    // along (so both steps only undo rounding).
    let Action::TranslateOnto {
        from: PointRef::Body { body, local: p },
        to: PointRef::Fixed(q),
    } = action(acts[0])
    else {
        return None;
    };
    if *body != b || dist(*p, *q) > tol {
        return None;
    }
    let Action::AlignDir {
        pivot,
        from: DirRef::Body { body, local: z },
        to: DirRef::Fixed(z2),
    } = action(acts[1])
    else {
        return None;
    };
    let on_pivot = match pivot {
        PointRef::Fixed(v) => dist(*v, *q) <= tol,
        PointRef::Body { body, local } => *body == b && dist(*local, *p) <= tol,
        _ => false,
    };
    if *body != b || !on_pivot || dist(*z, *z2) > PARALLEL || (norm(*z2) - 1.0).abs() > PARALLEL {
        return None;
    }
    let line = Line { pivot: *q, axis: *z2 };
    let turns = acts[2..]
        .iter()
        .map(|&i| turn(action(i), b, line, tol))
        .collect::<Option<Vec<_>>>()?;
    Some((line, acts, turns))
}

/// A point of the line, constant: a fixed point, or one of `b`'s on it.
fn on_line(p: &PointRef, b: BodyId, line: Line, tol: f64) -> Option<Vec3> {
    match p {
        PointRef::Fixed(v) => Some(*v),
        PointRef::Body { body, local } if *body == b => Some(*local),
        _ => None,
    }
    .filter(|v| line.holds(*v, tol))
}

/// A direction fixed or of `b`, as drawn.
fn drawn_dir(d: &DirRef, b: BodyId) -> Option<Vec3> {
    match d {
        DirRef::Fixed(v) => Some(*v),
        DirRef::Body { body, local } if *body == b => Some(*local),
        _ => None,
    }
}

/// A turn of `b` about its hinge, set outright.
fn turn(a: &Action, b: BodyId, line: Line, tol: f64) -> Option<Action> {
    let about = |pivot: &PointRef, axis: &DirRef| {
        let c = on_line(pivot, b, line, tol)?;
        let a = drawn_dir(axis, b).filter(|a| line.along(*a) && (norm(*a) - 1.0).abs() <= PARALLEL)?;
        Some((c, a))
    };
    let not_b =
        |p: &PointRef| !matches!(p, PointRef::Body { body, .. } | PointRef::Slid { body, .. } if *body == b);
    let (pivot, axis, turn) = match a {
        Action::Twist {
            pivot,
            axis,
            x1,
            x2,
            angle,
            input,
            sign,
        } => {
            let (c, ax) = about(pivot, axis)?;
            let (u1, u2) = (drawn_dir(x1, b)?, drawn_dir(x2, b)?);
            // The twist as drawn: the relative turn from the drawn pose to
            // twist 0 is minus it.
            let (s0, c0) = twist_correction(ax, u1, u2, Rot::from_degrees(0.0), 1.0);
            let drawn = (-s0).atan2(c0);
            let offset = if drawn == 0.0 {
                angle.to_degrees()
            } else {
                angle.to_degrees() - drawn.to_degrees()
            };
            let turn = HingeTurn::Degrees {
                offset,
                input: *input,
                sign: *sign,
            };
            (c, ax, turn)
        }
        Action::AxisOnto {
            pivot,
            axis,
            from: PointRef::Body { body, local },
            to,
        } if *body == b && not_b(to) => {
            let (c, ax) = about(pivot, axis)?;
            (
                c,
                ax,
                HingeTurn::Onto {
                    from: *local,
                    to: to.clone(),
                },
            )
        }
        Action::AxisDir {
            pivot,
            axis,
            from: DirRef::Body { body, local },
            to,
        } if *body == b
            && !matches!(to, DirRef::Body { body, .. } if *body == b)
            && !matches!(to, DirRef::Between(..)) =>
        {
            let (c, ax) = about(pivot, axis)?;
            (
                c,
                ax,
                HingeTurn::Dir {
                    from: *local,
                    to: to.clone(),
                },
            )
        }
        _ => return None,
    };
    Some(Action::Hinge { pivot, axis, turn })
}

/// Reads as constants what the hinged bodies keep fixed (their points on
/// the line, their directions along it, the circles their points sweep
/// about it) and every sphere's radius.
fn read_constants(kind: &mut StepKind, hinged: &[Option<Line>], tol: f64) {
    let fixed_point = |p: &mut PointRef| {
        if let PointRef::Body { body, local } = p {
            if hinged[*body].is_some_and(|l| l.holds(*local, tol)) {
                *p = PointRef::Fixed(*local);
            }
        }
    };
    let fixed_dir = |d: &mut DirRef| {
        if let DirRef::Body { body, local } = d {
            if hinged[*body].is_some_and(|l| l.along(*local)) {
                *d = DirRef::Fixed(*local);
            }
        }
    };
    each_ref(kind, &mut |r| match r {
        Ref::P(p) => fixed_point(p),
        Ref::D(d) => fixed_dir(d),
    });
    if let StepKind::Intersect { loci, .. } = kind {
        for locus in loci.iter_mut() {
            match locus {
                Locus::Circle {
                    pivot: PointRef::Fixed(c),
                    axis: DirRef::Fixed(a),
                    at,
                } => {
                    if let PointRef::Body { body, local } = at {
                        let swept = hinged[*body].is_some_and(|l| l.holds(*c, tol) && l.along(*a));
                        if swept {
                            *at = PointRef::Fixed(*local);
                        }
                    }
                }
                Locus::Sphere { a, b, .. } => {
                    if let (PointRef::Body { body: b1, local: l1 }, PointRef::Body { body: b2, local: l2 }) =
                        (&*a, &*b)
                    {
                        if b1 == b2 {
                            let (l1, l2) = (*l1, *l2);
                            *a = PointRef::Fixed(l1);
                            *b = PointRef::Fixed(l2);
                        }
                    }
                }
                _ => {}
            }
        }
    }
}

/// A point or a direction a step reads.
enum Ref<'a> {
    P(&'a mut PointRef),
    D(&'a mut DirRef),
}

/// Calls `f` on every point and direction a step reads (inside a
/// [`DirRef::Between`] too).
fn each_ref(kind: &mut StepKind, f: &mut dyn FnMut(Ref<'_>)) {
    match kind {
        StepKind::Act { action, .. } => action_refs(action, f),
        StepKind::Intersect { loci, .. } => {
            for locus in loci.iter_mut() {
                locus_refs(locus, f);
            }
        }
        StepKind::IntersectDir { cones, .. } => {
            for (axis, _) in cones.iter_mut() {
                read_dir(axis, f);
            }
        }
        StepKind::Check { .. } => {}
        StepKind::Cluster(c) => cluster_refs(c, f),
    }
}

/// Calls `f` on a point a step reads.
fn read_point(q: &mut PointRef, f: &mut dyn FnMut(Ref<'_>)) {
    f(Ref::P(q));
}

/// Calls `f` on a direction a step reads, or on its two points when it is
/// the direction between them.
fn read_dir(v: &mut DirRef, f: &mut dyn FnMut(Ref<'_>)) {
    if let DirRef::Between(a, b) = v {
        f(Ref::P(a));
        f(Ref::P(b));
    } else {
        f(Ref::D(v));
    }
}

/// [`each_ref`] for the action of an act step.
fn action_refs(action: &mut Action, f: &mut dyn FnMut(Ref<'_>)) {
    match action {
        Action::TranslateOnto { from, to } => {
            read_point(from, f);
            read_point(to, f);
        }
        Action::TranslateAlong { from, to, dir: n } | Action::TranslateInPlane { from, to, normal: n } => {
            read_point(from, f);
            read_point(to, f);
            read_dir(n, f);
        }
        Action::TranslateToLine {
            from,
            through,
            dir: n,
        }
        | Action::TranslateToPlane {
            from,
            through,
            normal: n,
        } => {
            read_point(from, f);
            read_point(through, f);
            read_dir(n, f);
        }
        Action::SlideTo {
            from, origin, dir, ..
        } => {
            read_point(from, f);
            read_point(origin, f);
            read_dir(dir, f);
        }
        Action::RotateOnto { pivot, from, to } => {
            read_point(pivot, f);
            read_point(from, f);
            read_point(to, f);
        }
        Action::AlignDir { pivot, from, to } | Action::Tilt { pivot, from, to, .. } => {
            read_point(pivot, f);
            read_dir(from, f);
            read_dir(to, f);
        }
        Action::AxisOnto {
            pivot,
            axis,
            from,
            to,
        } => {
            read_point(pivot, f);
            read_dir(axis, f);
            read_point(from, f);
            read_point(to, f);
        }
        Action::AxisDir {
            pivot,
            axis,
            from,
            to,
        } => {
            read_point(pivot, f);
            read_dir(axis, f);
            read_dir(from, f);
            read_dir(to, f);
        }
        Action::Twist {
            pivot, axis, x1, x2, ..
        } => {
            read_point(pivot, f);
            read_dir(axis, f);
            read_dir(x1, f);
            read_dir(x2, f);
        }
        Action::AxisCondition {
            pivot, axis, v, w, ..
        } => {
            read_point(pivot, f);
            read_dir(axis, f);
            read_dir(v, f);
            read_dir(w, f);
        }
        Action::Hinge { turn, .. } => match turn {
            HingeTurn::Degrees { .. } => {}
            HingeTurn::Onto { to, .. } => read_point(to, f),
            HingeTurn::Dir { to, .. } => read_dir(to, f),
        },
    }
}

/// [`each_ref`] for one locus of an intersect step.
fn locus_refs(locus: &mut Locus, f: &mut dyn FnMut(Ref<'_>)) {
    match locus {
        Locus::Circle { pivot, axis, at } => {
            read_point(pivot, f);
            read_dir(axis, f);
            read_point(at, f);
        }
        Locus::Sphere { centre, a, b } => {
            read_point(centre, f);
            read_point(a, f);
            read_point(b, f);
        }
        Locus::Line { at, dir } => {
            read_point(at, f);
            read_dir(dir, f);
        }
    }
}

/// [`each_ref`] for a cluster step: its parameters' pivots and axes and its
/// distance rows' points.
fn cluster_refs(c: &mut Cluster, f: &mut dyn FnMut(Ref<'_>)) {
    for param in &mut c.params {
        match param {
            Param::Free { .. } => {}
            Param::Pivot { pivot, .. } => read_point(pivot, f),
            Param::Axis { pivot, axis, .. } => {
                read_point(pivot, f);
                read_dir(axis, f);
            }
        }
    }
    for row in &mut c.rows {
        if let ClusterRow::Distance { a, b, c, d: e, .. } = row {
            read_point(a, f);
            read_point(b, f);
            read_point(c, f);
            read_point(e, f);
        }
    }
}
