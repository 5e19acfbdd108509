//! Plan rewrites that read what cannot change as constants.
//!
//! **Hinged bodies set outright.** The planner places a body hinged to a
//! fixed body as it places any other: every frame it re-imposes the hinge
//! (translate the body's pivot onto the fixed point, align its axis), then
//! turns the body about the axis from last frame's pose. When every later
//! action on the body is such a turn, the body never leaves its line, so
//! [`place_hinged`] drops the two re-imposing steps and makes each turn an
//! [`Action3::Hinge`]: the pose built from the drawn one. A frame then saves
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
    Action3, BodyId, ClusterRow3, HingeTurn, Locus3, Param3, Plan3, StepKind3, D3, P3,
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
/// about it is set outright ([`Action3::Hinge`]); the steps that
/// re-imposed its hinge are dropped (what they served is listed on its
/// first turn) and the steps after them renumbered. `size` is the
/// mechanism's size: points within 1e-12 of it are one.
pub(super) fn place_hinged(plan: &mut Plan3, size: f64) {
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
            StepKind3::Act { body, .. } => acts_of[*body].push(i),
            StepKind3::Cluster(c) => c.params.iter().for_each(|p| clustered[p.body()] = true),
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
            step.kind = StepKind3::Act {
                body: b,
                action: Box::new(action),
            };
            step.text.push_str(&format!(
                ", set outright on its fixed hinge ({} along {})",
                point(line.pivot),
                point(line.axis)
            ));
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
    // Each kept step's new number (from 0, as explanations cite them).
    let mut new_id = vec![None; plan.steps.len()];
    let mut next = 0;
    for (i, d) in dropped.iter().enumerate() {
        if !d {
            new_id[i] = Some(next);
            next += 1;
        }
    }
    let steps = std::mem::take(&mut plan.steps);
    plan.steps = steps
        .into_iter()
        .zip(&dropped)
        .filter(|(_, d)| !**d)
        .map(|(mut s, _)| {
            s.text = renumber(&s.text, &new_id);
            s
        })
        .collect();
    for step in &mut plan.steps {
        read_constants(&mut step.kind, &hinged, tol);
    }
}

/// Body `b`'s hinge, the indices of its actions `acts` (the two
/// re-imposing the hinge first) and its turns rewritten, if `b` is hinged
/// and only turned about its hinge after that.
fn hinge_of(plan: &Plan3, b: BodyId, acts: Vec<usize>, tol: f64) -> Option<(Line, Vec<usize>, Vec<Action3>)> {
    if acts.len() < 3 {
        return None;
    }
    let action = |i: usize| match &plan.steps[i].kind {
        StepKind3::Act { action, .. } => &**action,
        _ => unreachable!("acts are Act steps"),
    };
    // The hinge as the planner imposes it: the body's pivot onto a fixed
    // point where it is drawn, then its axis onto a fixed axis it is drawn
    // along (so both steps only undo rounding).
    let Action3::TranslateOnto {
        from: P3::Body { body, local: p },
        to: P3::Fixed(q),
    } = action(acts[0])
    else {
        return None;
    };
    if *body != b || dist(*p, *q) > tol {
        return None;
    }
    let Action3::AlignDir {
        pivot,
        from: D3::Body { body, local: z },
        to: D3::Fixed(z2),
    } = action(acts[1])
    else {
        return None;
    };
    let on_pivot = match pivot {
        P3::Fixed(v) => dist(*v, *q) <= tol,
        P3::Body { body, local } => *body == b && dist(*local, *p) <= tol,
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
fn on_line(p: &P3, b: BodyId, line: Line, tol: f64) -> Option<Vec3> {
    match p {
        P3::Fixed(v) => Some(*v),
        P3::Body { body, local } if *body == b => Some(*local),
        _ => None,
    }
    .filter(|v| line.holds(*v, tol))
}

/// A direction fixed or of `b`, as drawn.
fn drawn_dir(d: &D3, b: BodyId) -> Option<Vec3> {
    match d {
        D3::Fixed(v) => Some(*v),
        D3::Body { body, local } if *body == b => Some(*local),
        _ => None,
    }
}

/// A turn of `b` about its hinge, set outright.
fn turn(a: &Action3, b: BodyId, line: Line, tol: f64) -> Option<Action3> {
    let about = |pivot: &P3, axis: &D3| {
        let c = on_line(pivot, b, line, tol)?;
        let a = drawn_dir(axis, b).filter(|a| line.along(*a) && (norm(*a) - 1.0).abs() <= PARALLEL)?;
        Some((c, a))
    };
    let not_b = |p: &P3| !matches!(p, P3::Body { body, .. } | P3::Slid { body, .. } if *body == b);
    let (pivot, axis, turn) = match a {
        Action3::Twist {
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
        Action3::AxisOnto {
            pivot,
            axis,
            from: P3::Body { body, local },
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
        Action3::AxisDir {
            pivot,
            axis,
            from: D3::Body { body, local },
            to,
        } if *body == b
            && !matches!(to, D3::Body { body, .. } if *body == b)
            && !matches!(to, D3::Between(..)) =>
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
    Some(Action3::Hinge { pivot, axis, turn })
}

/// `[x, y, z]` as plans print numbers.
fn point(v: Vec3) -> String {
    format!(
        "[{}, {}, {}]",
        crate::plan::num(v[0]),
        crate::plan::num(v[1]),
        crate::plan::num(v[2])
    )
}

/// `text` with every "step N" citing its new number.
fn renumber(text: &str, new_id: &[Option<usize>]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find("step ") {
        let (head, tail) = rest.split_at(i + "step ".len());
        out.push_str(head);
        let digits = tail.bytes().take_while(u8::is_ascii_digit).count();
        let boundary = i == 0 || !rest.as_bytes()[i - 1].is_ascii_alphanumeric();
        match tail[..digits].parse::<usize>() {
            Ok(n) if boundary && new_id.get(n).copied().flatten().is_some() => {
                out.push_str(&new_id[n].expect("kept").to_string());
            }
            _ => out.push_str(&tail[..digits]),
        }
        rest = &tail[digits..];
    }
    out.push_str(rest);
    out
}

/// Reads as constants what the hinged bodies keep fixed (their points on
/// the line, their directions along it, the circles their points sweep
/// about it) and every sphere's radius.
fn read_constants(kind: &mut StepKind3, hinged: &[Option<Line>], tol: f64) {
    let fixed_point = |p: &mut P3| {
        if let P3::Body { body, local } = p {
            if hinged[*body].is_some_and(|l| l.holds(*local, tol)) {
                *p = P3::Fixed(*local);
            }
        }
    };
    let fixed_dir = |d: &mut D3| {
        if let D3::Body { body, local } = d {
            if hinged[*body].is_some_and(|l| l.along(*local)) {
                *d = D3::Fixed(*local);
            }
        }
    };
    each_ref(kind, &mut |r| match r {
        Ref::P(p) => fixed_point(p),
        Ref::D(d) => fixed_dir(d),
    });
    if let StepKind3::Intersect { loci, .. } = kind {
        for locus in loci.iter_mut() {
            match locus {
                Locus3::Circle {
                    pivot: P3::Fixed(c),
                    axis: D3::Fixed(a),
                    at,
                } => {
                    if let P3::Body { body, local } = at {
                        let swept = hinged[*body].is_some_and(|l| l.holds(*c, tol) && l.along(*a));
                        if swept {
                            *at = P3::Fixed(*local);
                        }
                    }
                }
                Locus3::Sphere { a, b, .. } => {
                    if let (P3::Body { body: b1, local: l1 }, P3::Body { body: b2, local: l2 }) = (&*a, &*b) {
                        if b1 == b2 {
                            let (l1, l2) = (*l1, *l2);
                            *a = P3::Fixed(l1);
                            *b = P3::Fixed(l2);
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
    P(&'a mut P3),
    D(&'a mut D3),
}

/// Calls `f` on every point and direction a step reads (inside a
/// [`D3::Between`] too).
fn each_ref(kind: &mut StepKind3, f: &mut dyn FnMut(Ref<'_>)) {
    fn p(q: &mut P3, f: &mut dyn FnMut(Ref<'_>)) {
        f(Ref::P(q));
    }
    fn d(v: &mut D3, f: &mut dyn FnMut(Ref<'_>)) {
        if let D3::Between(a, b) = v {
            f(Ref::P(a));
            f(Ref::P(b));
        } else {
            f(Ref::D(v));
        }
    }
    match kind {
        StepKind3::Act { action, .. } => match &mut **action {
            Action3::TranslateOnto { from, to } => {
                p(from, f);
                p(to, f);
            }
            Action3::TranslateAlong { from, to, dir: n }
            | Action3::TranslateInPlane { from, to, normal: n } => {
                p(from, f);
                p(to, f);
                d(n, f);
            }
            Action3::TranslateToLine {
                from,
                through,
                dir: n,
            }
            | Action3::TranslateToPlane {
                from,
                through,
                normal: n,
            } => {
                p(from, f);
                p(through, f);
                d(n, f);
            }
            Action3::SlideTo {
                from, origin, dir, ..
            } => {
                p(from, f);
                p(origin, f);
                d(dir, f);
            }
            Action3::RotateOnto { pivot, from, to } => {
                p(pivot, f);
                p(from, f);
                p(to, f);
            }
            Action3::AlignDir { pivot, from, to } | Action3::Tilt { pivot, from, to, .. } => {
                p(pivot, f);
                d(from, f);
                d(to, f);
            }
            Action3::AxisOnto {
                pivot,
                axis,
                from,
                to,
            } => {
                p(pivot, f);
                d(axis, f);
                p(from, f);
                p(to, f);
            }
            Action3::AxisDir {
                pivot,
                axis,
                from,
                to,
            } => {
                p(pivot, f);
                d(axis, f);
                d(from, f);
                d(to, f);
            }
            Action3::Twist {
                pivot, axis, x1, x2, ..
            } => {
                p(pivot, f);
                d(axis, f);
                d(x1, f);
                d(x2, f);
            }
            Action3::AxisCondition {
                pivot, axis, v, w, ..
            } => {
                p(pivot, f);
                d(axis, f);
                d(v, f);
                d(w, f);
            }
            Action3::Hinge { turn, .. } => match turn {
                HingeTurn::Degrees { .. } => {}
                HingeTurn::Onto { to, .. } => p(to, f),
                HingeTurn::Dir { to, .. } => d(to, f),
            },
        },
        StepKind3::Intersect { loci, .. } => {
            for locus in loci.iter_mut() {
                match locus {
                    Locus3::Circle { pivot, axis, at } => {
                        p(pivot, f);
                        d(axis, f);
                        p(at, f);
                    }
                    Locus3::Sphere { centre, a, b } => {
                        p(centre, f);
                        p(a, f);
                        p(b, f);
                    }
                    Locus3::Line { at, dir } => {
                        p(at, f);
                        d(dir, f);
                    }
                }
            }
        }
        StepKind3::IntersectDir { cones, .. } => {
            for (axis, _) in cones.iter_mut() {
                d(axis, f);
            }
        }
        StepKind3::Check { .. } => {}
        StepKind3::Cluster(c) => {
            for param in &mut c.params {
                match param {
                    Param3::Free { .. } => {}
                    Param3::Pivot { pivot, .. } => p(pivot, f),
                    Param3::Axis { pivot, axis, .. } => {
                        p(pivot, f);
                        d(axis, f);
                    }
                }
            }
            for row in &mut c.rows {
                if let ClusterRow3::Distance { a, b, c, d: e, .. } = row {
                    p(a, f);
                    p(b, f);
                    p(c, f);
                    p(e, f);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::renumber;

    #[test]
    fn renumber_cites_the_new_step_numbers() {
        // Steps 1 and 2 dropped: 3 → 1, 4 → 2.
        let ids = [Some(0), None, None, Some(1), Some(2)];
        assert_eq!(
            renumber(
                "rocker: turn onto step 4 (rocker.C), not step 2x or mystep 3",
                &ids
            ),
            "rocker: turn onto step 2 (rocker.C), not step 2x or mystep 3"
        );
        assert_eq!(renumber("step 3", &ids), "step 1");
    }
}
