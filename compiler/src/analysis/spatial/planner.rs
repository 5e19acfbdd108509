//! Kramer's degrees-of-freedom analysis in space.
//!
//! Each moving body carries a state (its translational and rotational
//! freedoms with their arguments, docs/design/spatial.md §2.1). The planner repeats
//! Kramer's algorithm until nothing is left:
//! 1. **propagation**: an equation whose other side is known is met by the
//!    fragment the table ([`super::fragments`]) gives for the body's state;
//!    an equation between two placed bodies becomes a check of its rows
//!    (redundant);
//! 2. **loop closure**: a coincident equation between two partly placed
//!    bodies intersects their markers' loci into a pseudo-marker, which each
//!    body then meets by propagation;
//! 3. **numeric fallback**: what is still unplaced becomes a cluster, with
//!    bodies hanging on a contracted chain (a leg of fixed length) replaced
//!    by a distance row.
//!
//! Ties are broken by file order, so plans are deterministic.

use std::collections::BTreeSet;

use dofplan_runtime::spatial::{cross, norm, sub, unit, Vec3};
use dofplan_runtime::Branch;

use super::fragments::{lookup, Case, Do, Fragment, Prim, RDof, TDof};
use crate::model::spatial::equations::{Equation, Frame, Kind};
use crate::model::spatial::{JointKind, Mechanism, Primitive};
use crate::plan::spatial::{
    Action, BranchSlot, CheckRow, Cluster, ClusterRow, DirRef, Locus, Param, PointRef, Step, StepKind, Temp,
};

/// Two local points closer than this (relative to the size) are one point;
/// two unit directions whose cross product is smaller are parallel.
const SAME: f64 = 1e-9;

#[derive(Clone, Debug)]
enum T {
    Free,
    Plane { q: Vec3 },
    Line { q: Vec3, dir: DirRef },
    Point { q: Vec3 },
}

#[derive(Clone, Debug)]
enum R {
    Free,
    Cone { u: Vec3, w: DirRef, cos: f64 },
    Axis { al: Vec3 },
    Fixed,
}

#[derive(Clone, Debug)]
struct State {
    t: T,
    r: R,
}

impl State {
    fn tdof(&self) -> TDof {
        match self.t {
            T::Free => TDof::Free,
            T::Plane { .. } => TDof::Plane,
            T::Line { .. } => TDof::Line,
            T::Point { .. } => TDof::Point,
        }
    }
    fn rdof(&self) -> RDof {
        match self.r {
            R::Free => RDof::Free,
            R::Cone { .. } => RDof::Cone,
            R::Axis { .. } => RDof::Axis,
            R::Fixed => RDof::Fixed,
        }
    }
    fn dof(&self) -> usize {
        let t = match self.t {
            T::Free => 3,
            T::Plane { .. } => 2,
            T::Line { .. } => 1,
            T::Point { .. } => 0,
        };
        let r = match self.r {
            R::Free => 3,
            R::Cone { .. } => 2,
            R::Axis { .. } => 1,
            R::Fixed => 0,
        };
        t + r
    }
    /// The body point rotations keep fixed.
    fn pivot(&self) -> Option<Vec3> {
        match self.t {
            T::Point { q } | T::Line { q, .. } | T::Plane { q } => Some(q),
            T::Free => None,
        }
    }
}

/// The outcome of planning.
pub struct Planned {
    /// Steps in order.
    pub steps: Vec<Step>,
    /// Pseudo-markers.
    pub temps: Vec<Temp>,
    /// Branch slots (initial branch still to be chosen).
    pub branches: Vec<BranchSlot>,
    /// Freedoms left at minimum motion.
    pub idle: Vec<(usize, usize, String)>,
    /// Equations no step used.
    pub unused: Vec<usize>,
}

struct Planner<'m> {
    m: &'m Mechanism,
    eqs: &'m [Equation],
    used: Vec<bool>,
    state: Vec<State>,
    steps: Vec<Step>,
    temps: Vec<Temp>,
    branches: Vec<BranchSlot>,
    size: f64,
    /// Per body: slide-input joints (joint, input) whose axis points of the
    /// body move rigidly with the joint's other body.
    slides: Vec<Vec<(usize, usize)>>,
    /// Redundant rows of loops closed through a driven slide: checked at the
    /// end, once the body carrying the point has followed.
    pending: Vec<(usize, usize)>,
    /// Bodies whose state changed since the rules last looked: only
    /// equations on them (or on their slide partners) can have become
    /// applicable, which keeps planning linear in the mechanism's size.
    changed: Vec<usize>,
}

/// Plans a spatial mechanism from its equations.
pub fn plan(m: &Mechanism, eqs: &[Equation]) -> Planned {
    let mut slides = vec![Vec::new(); m.bodies.len()];
    for (ii, input) in m.inputs.iter().enumerate() {
        let j = &m.joints[input.joint];
        if input.kind == crate::model::InputKind::Slide
            && matches!(j.kind, JointKind::Cylindrical | JointKind::Prismatic)
        {
            for id in j.markers {
                slides[id.body].push((input.joint, ii));
            }
        }
    }
    let mut p = Planner {
        m,
        eqs,
        used: vec![false; eqs.len()],
        state: m
            .bodies
            .iter()
            .map(|b| {
                if b.fixed {
                    State {
                        t: T::Point { q: [0.0; 3] },
                        r: R::Fixed,
                    }
                } else {
                    State {
                        t: T::Free,
                        r: R::Free,
                    }
                }
            })
            .collect(),
        steps: Vec::new(),
        temps: Vec::new(),
        branches: Vec::new(),
        size: m.size(),
        slides,
        pending: Vec::new(),
        changed: Vec::new(),
    };
    // Equations by body, and each body's slide partners (a point carried
    // by a slide becomes known when the partner is placed).
    let mut on: Vec<Vec<usize>> = vec![Vec::new(); m.bodies.len()];
    for (i, e) in eqs.iter().enumerate() {
        on[e.bodies[0]].push(i);
        if e.bodies[1] != e.bodies[0] {
            on[e.bodies[1]].push(i);
        }
    }
    let mut partners: Vec<Vec<usize>> = vec![Vec::new(); m.bodies.len()];
    for (b, list) in p.slides.iter().enumerate() {
        for &(ji, _) in list {
            for id in m.joints[ji].markers {
                if id.body != b {
                    partners[id.body].push(b);
                }
            }
        }
    }
    // Each rule takes the lowest-numbered equation it applies to, as a scan
    // in file order would; an equation it found inapplicable comes back
    // only when one of its bodies changes.
    let mut propagate: BTreeSet<usize> = (0..eqs.len()).collect();
    let mut closing: BTreeSet<usize> = (0..eqs.len()).collect();
    let requeue = |p: &mut Planner, propagate: &mut BTreeSet<usize>, closing: &mut BTreeSet<usize>| {
        for b in std::mem::take(&mut p.changed) {
            for &c in std::iter::once(&b).chain(&partners[b]) {
                for &i in &on[c] {
                    if !p.used[i] {
                        propagate.insert(i);
                        closing.insert(i);
                    }
                }
            }
        }
    };
    loop {
        while let Some(i) = propagate.pop_first() {
            if !p.used[i] && p.propagate(i) {
                requeue(&mut p, &mut propagate, &mut closing);
            }
        }
        let mut closed = false;
        while let Some(i) = closing.pop_first() {
            if !p.used[i] && p.close_loop(i) {
                closed = true;
                break;
            }
        }
        if closed || p.cluster() {
            requeue(&mut p, &mut propagate, &mut closing);
            // What a cluster or a closure leaves applicable may be any
            // equation on the bodies it placed; the rest stay queued.
            continue;
        }
        break;
    }
    for (i, redundant) in std::mem::take(&mut p.pending) {
        p.check(i, redundant);
    }
    let mut idle = Vec::new();
    for (b, s) in p.state.iter().enumerate() {
        if !m.bodies[b].fixed && s.dof() > 0 {
            let why = match (&s.t, &s.r) {
                (T::Point { .. }, R::Axis { .. }) => "a spin about its axis no joint restrains".to_string(),
                _ => format!("{} · {} left", s.tdof().name(), s.rdof().name()),
            };
            idle.push((b, s.dof(), why));
        }
    }
    Planned {
        steps: p.steps,
        temps: p.temps,
        branches: p.branches,
        idle,
        unused: (0..eqs.len()).filter(|&i| !p.used[i]).collect(),
    }
}

fn parallel(a: Vec3, b: Vec3) -> bool {
    norm(cross(a, b)) <= SAME * norm(a).max(1e-300) * norm(b).max(1e-300)
}

fn neg(v: Vec3) -> Vec3 {
    [-v[0], -v[1], -v[2]]
}

impl Planner<'_> {
    fn fixed(&self, b: usize) -> bool {
        self.m.bodies[b].fixed
    }

    fn placed(&self, b: usize) -> bool {
        matches!(
            self.state[b],
            State {
                t: T::Point { .. },
                r: R::Fixed
            }
        )
    }

    fn same_point(&self, a: Vec3, b: Vec3) -> bool {
        norm(sub(a, b)) <= SAME * self.size
    }

    /// Whether `local` lies on the line (`q`, `al`) of the body.
    fn on_line(&self, local: Vec3, q: Vec3, al: Vec3) -> bool {
        norm(cross(sub(local, q), al)) <= SAME * self.size
    }

    /// A body point as the plan reads it.
    fn body_point(&self, b: usize, local: Vec3) -> PointRef {
        if self.fixed(b) {
            PointRef::Fixed(local)
        } else {
            PointRef::Body { body: b, local }
        }
    }

    fn body_dir(&self, b: usize, local: Vec3) -> DirRef {
        if self.fixed(b) {
            DirRef::Fixed(local)
        } else {
            DirRef::Body { body: b, local }
        }
    }

    /// The body point `local`, if its world position is known already.
    fn known_point(&self, b: usize, local: Vec3) -> Option<PointRef> {
        if self.placed(b) {
            return Some(self.body_point(b, local));
        }
        let s = &self.state[b];
        if let T::Point { q } = s.t {
            if self.same_point(local, q) {
                return Some(self.body_point(b, local));
            }
            if let R::Axis { al } = s.r {
                if self.on_line(local, q, al) {
                    return Some(self.body_point(b, local));
                }
            }
        }
        // A point on a driven slide's axis moves with the slide's other body.
        let (a, slid) = self.slid(b, local)?;
        self.placed(a).then_some(slid)
    }

    /// The point `local` of `b` as a point of the other body of a slide
    /// input's joint, when it lies on the joint's axis.
    fn slid(&self, b: usize, local: Vec3) -> Option<(usize, PointRef)> {
        for &(ji, input) in &self.slides[b] {
            let j = &self.m.joints[ji];
            let first = self.m.marker(j.markers[0]);
            let z = first.axes?.z;
            if !self.on_line(local, first.at, z) {
                continue;
            }
            let (other, sign) = if j.markers[1].body == b {
                (j.markers[0].body, 1.0)
            } else {
                (j.markers[1].body, -1.0)
            };
            let p = if self.fixed(other) {
                continue;
            } else {
                PointRef::Slid {
                    body: other,
                    local,
                    dir: z,
                    input,
                    sign,
                }
            };
            return Some((other, p));
        }
        None
    }

    /// The body direction `local`, if its world value is known already.
    fn known_dir(&self, b: usize, local: Vec3) -> Option<DirRef> {
        match self.state[b].r {
            R::Fixed => Some(self.body_dir(b, local)),
            R::Axis { al } if parallel(local, al) => Some(self.body_dir(b, local)),
            _ => None,
        }
    }

    fn temp(&mut self, name: String, drawn: Vec3) -> usize {
        self.temps.push(Temp { name, drawn });
        self.temps.len() - 1
    }

    fn slot(&mut self) -> usize {
        self.branches.push(BranchSlot {
            initial: Branch::Plus,
            angle: 0.0,
        });
        self.branches.len() - 1
    }

    fn push(&mut self, kind: StepKind, serves: Vec<String>) {
        self.steps.push(Step { kind, serves });
    }

    fn act(&mut self, body: usize, action: Action, serves: &[String]) {
        self.push(
            StepKind::Act {
                body,
                action: Box::new(action),
            },
            serves.to_vec(),
        );
    }

    fn serves(&self, i: usize) -> String {
        format!("{} {}", self.eqs[i].origin, self.eqs[i].kind.name())
    }

    fn check_row(&self, i: usize, redundant: usize) -> CheckRow {
        CheckRow::of(&self.eqs[i], redundant, self.size)
    }

    /// A check step of `redundant` rows of equation `i`.
    fn check(&mut self, i: usize, redundant: usize) {
        let row = self.check_row(i, redundant);
        self.push(StepKind::Check { rows: vec![row] }, vec![]);
    }

    fn name(&self, b: usize) -> &str {
        &self.m.bodies[b].name
    }

    /// Tries to meet equation `i` with one side known.
    fn propagate(&mut self, i: usize) -> bool {
        let e = &self.eqs[i];
        let [b1, b2] = e.bodies;
        if self.placed(b1) && self.placed(b2) {
            self.used[i] = true;
            let rows = e.kind.rows();
            self.check(i, rows);
            return true;
        }
        for mover in [1usize, 0] {
            let (b, o) = (e.bodies[mover], e.bodies[1 - mover]);
            if self.placed(b) || self.fixed(b) {
                continue;
            }
            if let Some(done) = self.try_side(i, mover, b, o) {
                if done {
                    self.used[i] = true;
                    return true;
                }
            }
        }
        false
    }

    /// The fragment for body `b` (marker `mover` of equation `i`) against
    /// the other body `o`, applied if the other side is known. `None` when
    /// not applicable.
    fn try_side(&mut self, i: usize, mover: usize, b: usize, o: usize) -> Option<bool> {
        let e = self.eqs[i].clone();
        let fm = e.frames[mover];
        let fo = e.frames[1 - mover];
        let st = self.state[b].clone();
        let serves = vec![self.serves(i)];
        let (prim, target): (Prim, Target) = match e.kind {
            Kind::Prim(Primitive::Coincident) => {
                (Prim::Coincident, Target::Point(self.known_point(o, fo.at)?))
            }
            Kind::Prim(Primitive::InLine) if mover == 1 => {
                let k = self.known_point(o, fo.at)?;
                let d = self.known_dir(o, fo.axes.z)?;
                (Prim::InLine, Target::Line(k, d))
            }
            Kind::Prim(Primitive::InLine) => {
                let k = self.known_point(o, fo.at)?;
                (Prim::InLineOwner, Target::Point(k))
            }
            Kind::Prim(Primitive::InPlane) if mover == 1 => {
                let k = self.known_point(o, fo.at)?;
                let d = self.known_dir(o, fo.axes.z)?;
                (Prim::InPlane, Target::Line(k, d))
            }
            Kind::Prim(Primitive::InPlane) => {
                let k = self.known_point(o, fo.at)?;
                (Prim::InPlaneOwner, Target::Point(k))
            }
            Kind::Prim(Primitive::ParallelZ) => {
                let z = if e.sign < 0.0 { neg(fo.axes.z) } else { fo.axes.z };
                (Prim::ParallelZ, Target::Dir(self.known_dir(o, z)?))
            }
            Kind::Prim(Primitive::OffsetZ | Primitive::PerpendicularZ) => {
                (Prim::OffsetZ, Target::Dir(self.known_dir(o, fo.axes.z)?))
            }
            Kind::Prim(Primitive::OffsetX) => {
                let z = if e.sign < 0.0 { neg(fo.axes.z) } else { fo.axes.z };
                let t = self.known_dir(o, z)?;
                self.known_dir(o, fo.axes.x)?;
                (Prim::OffsetX, Target::Dir(t))
            }
            Kind::Angle { .. } => {
                self.known_dir(o, fo.axes.z)?;
                self.known_dir(o, fo.axes.x)?;
                (Prim::Angle, Target::None)
            }
            Kind::Slide { .. } => {
                self.known_point(o, fo.at)?;
                self.known_dir(o, fo.axes.z)?;
                (Prim::Slide, Target::None)
            }
            Kind::Prim(Primitive::Helical) => return None,
        };
        let case = self.case(&st, prim, &fm, &e);
        let frag = *lookup(st.tdof(), st.rdof(), prim, case)?;
        self.apply(i, mover, b, &frag, target, &serves, false)
    }

    /// The geometric case of the marker `fm` of a body in state `st`.
    fn case(
        &self,
        st: &State,
        prim: Prim,
        fm: &crate::model::spatial::equations::Frame,
        e: &Equation,
    ) -> Case {
        match prim {
            Prim::Coincident | Prim::InLine | Prim::InPlane => {
                if let Some(q) = st.pivot() {
                    if matches!(st.t, T::Point { .. }) && self.same_point(fm.at, q) {
                        return Case::AtPivot;
                    }
                    if let R::Axis { al } = st.r {
                        return if self.on_line(fm.at, q, al) {
                            Case::OnAxis
                        } else {
                            Case::OffAxis
                        };
                    }
                    return Case::OffPivot;
                }
                Case::Any
            }
            _ => {
                // The joint axis is the first marker's z; an angle input or
                // a slide moves about or along it.
                let z = match prim {
                    Prim::Angle | Prim::Slide => e.frames[0].axes.z,
                    _ => fm.axes.z,
                };
                match (&st.r, &st.t) {
                    (_, T::Line { .. }) if prim == Prim::Slide => Case::Along,
                    (R::Axis { al }, _) => {
                        if parallel(z, *al) {
                            Case::Along
                        } else {
                            Case::Across
                        }
                    }
                    (R::Cone { u, .. }, _) => {
                        if parallel(z, *u) {
                            Case::Along
                        } else {
                            Case::Across
                        }
                    }
                    _ => Case::Any,
                }
            }
        }
    }

    /// The pivot of a body as a point (its T-part's point, or the marker
    /// itself for a free body).
    fn pivot_point(&self, b: usize, st: &State, fallback: Vec3) -> PointRef {
        self.body_point(b, st.pivot().unwrap_or(fallback))
    }

    /// Carries out a fragment. `by_construction`: the target is a
    /// pseudo-marker that already meets the rows the fragment would check.
    #[allow(clippy::too_many_arguments)]
    fn apply(
        &mut self,
        i: usize,
        mover: usize,
        b: usize,
        frag: &Fragment,
        target: Target,
        serves: &[String],
        by_construction: bool,
    ) -> Option<bool> {
        let e = self.eqs[i].clone();
        let fm = e.frames[mover];
        let st = self.state[b].clone();
        let mut new = st.clone();
        let a = Applied {
            mover,
            b,
            name: self.name(b).to_string(),
            mname: self.m.marker_name(e.markers[mover]),
            m_pt: self.body_point(b, fm.at),
            pivot: self.pivot_point(b, &st, fm.at),
            sign: if mover == 1 { 1.0 } else { -1.0 },
            e,
            fm,
            st,
            serves,
        };
        match (frag.action, &target) {
            (Do::Check, _) => {
                self.check(i, a.e.kind.rows());
                return Some(true);
            }
            (Do::TranslateOnto, Target::Point(k)) => self.do_translate_onto(&a, k, &mut new)?,
            (Do::TranslateAlong, Target::Point(k)) => self.do_translate_along(&a, k, &mut new)?,
            (Do::SlideTurn, Target::Point(k)) => self.do_slide_turn(&a, k, &mut new)?,
            (Do::TranslateInPlane, Target::Point(k)) => self.do_translate_in_plane(&a, k, &mut new)?,
            (Do::TranslateToLine, Target::Line(k, d)) => self.do_translate_to_line(&a, k, d, &mut new)?,
            (Do::TranslateToPlane, Target::Line(k, n)) => self.do_translate_to_plane(&a, k, n, &mut new)?,
            (Do::OwnerLineThrough, Target::Point(k)) => self.do_owner_line_through(&a, k, &mut new)?,
            (Do::OwnerPlaneThrough, Target::Point(k)) => self.do_owner_plane_through(&a, k, &mut new)?,
            (Do::RotateOnto, Target::Point(k)) => self.do_rotate_onto(&a, k, &mut new)?,
            (Do::AxisOnto, Target::Point(k)) => self.do_axis_onto(&a, k, &mut new)?,
            (Do::RotateOntoCone, Target::Point(k)) => self.do_rotate_onto_cone(&a, k, &mut new)?,
            (Do::LineSphere, Target::Point(k)) => self.do_line_sphere(&a, k, &mut new)?,
            (Do::CircleLine | Do::SphereLine, Target::Line(k, d)) => {
                self.do_circle_or_sphere_line(&a, k, d, &mut new)?
            }
            (Do::AlignDir, Target::Dir(t)) => self.do_align_dir(&a, t, &mut new)?,
            (Do::AxisDir, Target::Dir(t)) => self.do_axis_dir(&a, t, &mut new)?,
            (Do::AlignOntoCone, Target::Dir(t)) => self.do_align_onto_cone(&a, t, &mut new)?,
            (Do::AxisCondition, Target::Dir(t)) => self.do_axis_condition(&a, t, &mut new)?,
            (Do::Tilt, Target::Dir(t)) => self.do_tilt(&a, t, &mut new)?,
            (Do::AlignTwist | Do::Twist, Target::Dir(_) | Target::None) => {
                self.do_twist(&a, frag, &target, &mut new)?
            }
            (Do::SlideTo, Target::None) => self.do_slide_to(&a, &mut new)?,
            _ => return None,
        }
        self.state[b] = new;
        self.changed.push(b);
        if frag.checks > 0 && !by_construction {
            self.check(i, frag.checks);
        }
        Some(true)
    }

    /// `TranslateOnto`: Translate the marker onto the point.
    fn do_translate_onto(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves) = (a.b, a.fm, a.serves);
        let m_pt = a.m_pt.clone();
        self.act(
            b,
            Action::TranslateOnto {
                from: m_pt,
                to: k.clone(),
            },
            serves,
        );
        new.t = T::Point { q: fm.at };
        Some(())
    }

    /// `TranslateAlong`: Translate along the body's line so the marker reaches the point.
    fn do_translate_along(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st) = (a.b, a.fm, a.serves, &a.st);
        let m_pt = a.m_pt.clone();
        let T::Line { q, dir } = st.t.clone() else {
            return None;
        };
        self.act(
            b,
            Action::TranslateAlong {
                from: m_pt,
                to: k.clone(),
                dir,
            },
            serves,
        );
        new.t = T::Point {
            q: if matches!(st.r, R::Fixed) { q } else { fm.at },
        };
        Some(())
    }

    /// `SlideTurn`: Translate along the line, then rotate about it onto the point.
    fn do_slide_turn(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, serves, st) = (a.b, a.serves, &a.st);
        let m_pt = a.m_pt.clone();
        let (T::Line { q, dir }, R::Axis { al }) = (st.t.clone(), st.r.clone()) else {
            return None;
        };
        self.act(
            b,
            Action::TranslateAlong {
                from: m_pt.clone(),
                to: k.clone(),
                dir,
            },
            serves,
        );
        self.act(
            b,
            Action::AxisOnto {
                pivot: self.body_point(b, q),
                axis: self.body_dir(b, al),
                from: m_pt,
                to: k.clone(),
            },
            serves,
        );
        *new = State {
            t: T::Point { q },
            r: R::Fixed,
        };
        Some(())
    }

    /// `TranslateInPlane`: Translate in the body's plane so the marker reaches the point.
    fn do_translate_in_plane(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st) = (a.b, a.fm, a.serves, &a.st);
        let m_pt = a.m_pt.clone();
        let normal = match st.r {
            R::Axis { al } => self.body_dir(b, al),
            _ => return None,
        };
        self.act(
            b,
            Action::TranslateInPlane {
                from: m_pt,
                to: k.clone(),
                normal,
            },
            serves,
        );
        new.t = T::Point { q: fm.at };
        Some(())
    }

    /// `TranslateToLine`: Translate the marker to its foot on the line.
    fn do_translate_to_line(&mut self, a: &Applied, k: &PointRef, d: &DirRef, new: &mut State) -> Option<()> {
        let (b, fm, serves) = (a.b, a.fm, a.serves);
        let m_pt = a.m_pt.clone();
        self.act(
            b,
            Action::TranslateToLine {
                from: m_pt,
                through: k.clone(),
                dir: d.clone(),
            },
            serves,
        );
        new.t = T::Line {
            q: fm.at,
            dir: d.clone(),
        };
        Some(())
    }

    /// `TranslateToPlane`: Translate the marker onto the plane.
    fn do_translate_to_plane(
        &mut self,
        a: &Applied,
        k: &PointRef,
        n: &DirRef,
        new: &mut State,
    ) -> Option<()> {
        let (b, fm, serves) = (a.b, a.fm, a.serves);
        let m_pt = a.m_pt.clone();
        self.act(
            b,
            Action::TranslateToPlane {
                from: m_pt,
                through: k.clone(),
                normal: n.clone(),
            },
            serves,
        );
        new.t = T::Plane { q: fm.at };
        Some(())
    }

    /// `OwnerLineThrough`: Translate the body's line (its z known) through the point.
    fn do_owner_line_through(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves) = (a.b, a.fm, a.serves);
        let m_pt = a.m_pt.clone();
        let d = self.body_dir(b, fm.axes.z);
        self.act(
            b,
            Action::TranslateToLine {
                from: m_pt,
                through: k.clone(),
                dir: d.clone(),
            },
            serves,
        );
        new.t = T::Line { q: fm.at, dir: d };
        Some(())
    }

    /// `OwnerPlaneThrough`: Translate the body's plane (its z known) through the point.
    fn do_owner_plane_through(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves) = (a.b, a.fm, a.serves);
        let m_pt = a.m_pt.clone();
        let n = self.body_dir(b, fm.axes.z);
        self.act(
            b,
            Action::TranslateToPlane {
                from: m_pt,
                through: k.clone(),
                normal: n,
            },
            serves,
        );
        new.t = T::Plane { q: fm.at };
        Some(())
    }

    /// `RotateOnto`: Minimal rotation about the pivot taking the marker toward the point.
    fn do_rotate_onto(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st) = (a.b, a.fm, a.serves, &a.st);
        let m_pt = a.m_pt.clone();
        let pivot = a.pivot.clone();
        let q = st.pivot()?;
        self.rotate_onto(b, &pivot, m_pt, k, serves);
        new.r = R::Axis {
            al: unit(sub(fm.at, q)),
        };
        Some(())
    }

    /// `AxisOnto`: Rotation about the axis taking the marker onto the point.
    fn do_axis_onto(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, serves, st) = (a.b, a.serves, &a.st);
        let m_pt = a.m_pt.clone();
        let pivot = a.pivot.clone();
        let R::Axis { al } = st.r else { return None };
        self.act(
            b,
            Action::AxisOnto {
                pivot: pivot.clone(),
                axis: self.body_dir(b, al),
                from: m_pt,
                to: k.clone(),
            },
            serves,
        );
        new.r = R::Fixed;
        Some(())
    }

    /// `RotateOntoCone`: Rotate onto the point, then about the new axis onto the cone (a branch).
    fn do_rotate_onto_cone(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st) = (a.b, a.fm, a.serves, &a.st);
        let m_pt = a.m_pt.clone();
        let pivot = a.pivot.clone();
        let R::Cone { u, w, cos } = st.r.clone() else {
            return None;
        };
        let q = st.pivot()?;
        if parallel(sub(fm.at, q), u) {
            return None;
        }
        self.rotate_onto(b, &pivot, m_pt, k, serves);
        let slot = self.slot();
        self.act(
            b,
            Action::AxisCondition {
                pivot: pivot.clone(),
                axis: DirRef::Between(Box::new(pivot.clone()), Box::new(k.clone())),
                v: self.body_dir(b, u),
                w,
                cos,
                branch: slot,
            },
            serves,
        );
        new.r = R::Fixed;
        Some(())
    }

    /// `LineSphere`: Pivot onto line ∩ sphere (a branch), then rotate onto the point.
    fn do_line_sphere(&mut self, a: &Applied, k: &PointRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st, name) = (a.b, a.fm, a.serves, &a.st, &a.name);
        let m_pt = a.m_pt.clone();
        let T::Line { q, dir } = st.t.clone() else {
            return None;
        };
        let qp = self.body_point(b, q);
        let t = self.temp(format!("{name} pivot"), q);
        let slot = self.slot();
        self.push(
            StepKind::Intersect {
                temp: t,
                loci: Box::new([
                    Locus::Line { at: qp.clone(), dir },
                    Locus::Sphere {
                        centre: k.clone(),
                        a: qp.clone(),
                        b: m_pt.clone(),
                    },
                ]),
                branch: Some(slot),
                tol: 1e-9 * self.size,
            },
            serves.to_vec(),
        );
        self.act(
            b,
            Action::TranslateOnto {
                from: qp.clone(),
                to: PointRef::Temp(t),
            },
            serves,
        );
        self.act(
            b,
            Action::RotateOnto {
                pivot: qp,
                from: m_pt,
                to: k.clone(),
            },
            serves,
        );
        *new = State {
            t: T::Point { q },
            r: R::Axis {
                al: unit(sub(fm.at, q)),
            },
        };
        Some(())
    }

    /// `CircleLine`, `SphereLine`: Marker onto circle ∩ line (a branch). / Marker onto sphere ∩ line (a branch).
    fn do_circle_or_sphere_line(
        &mut self,
        a: &Applied,
        k: &PointRef,
        d: &DirRef,
        new: &mut State,
    ) -> Option<()> {
        let (b, fm, serves, st, mname) = (a.b, a.fm, a.serves, &a.st, &a.mname);
        let m_pt = a.m_pt.clone();
        let pivot = a.pivot.clone();
        let q = st.pivot()?;
        let locus = match st.r {
            R::Axis { al } => Locus::Circle {
                pivot: pivot.clone(),
                axis: self.body_dir(b, al),
                at: m_pt.clone(),
            },
            _ => Locus::Sphere {
                centre: pivot.clone(),
                a: pivot.clone(),
                b: m_pt.clone(),
            },
        };
        let t = self.temp(mname.clone(), fm.at);
        let slot = self.slot();
        self.push(
            StepKind::Intersect {
                temp: t,
                loci: Box::new([
                    locus,
                    Locus::Line {
                        at: k.clone(),
                        dir: d.clone(),
                    },
                ]),
                branch: Some(slot),
                tol: 1e-9 * self.size,
            },
            serves.to_vec(),
        );
        let to = PointRef::Temp(t);
        if let R::Axis { al } = st.r {
            self.act(
                b,
                Action::AxisOnto {
                    pivot: pivot.clone(),
                    axis: self.body_dir(b, al),
                    from: m_pt,
                    to,
                },
                serves,
            );
            new.r = R::Fixed;
        } else {
            self.act(
                b,
                Action::RotateOnto {
                    pivot: pivot.clone(),
                    from: m_pt,
                    to,
                },
                serves,
            );
            new.r = R::Axis {
                al: unit(sub(fm.at, q)),
            };
        }
        Some(())
    }

    /// `AlignDir`: Minimal rotation taking z_m to the direction.
    fn do_align_dir(&mut self, a: &Applied, t: &DirRef, new: &mut State) -> Option<()> {
        let (b, fm, serves) = (a.b, a.fm, a.serves);
        let pivot = a.pivot.clone();
        self.align_z(b, &pivot, fm.axes.z, t, serves);
        new.r = R::Axis { al: fm.axes.z };
        Some(())
    }

    /// `AxisDir`: Rotation about the axis taking z_m to the direction.
    fn do_axis_dir(&mut self, a: &Applied, t: &DirRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st) = (a.b, a.fm, a.serves, &a.st);
        let pivot = a.pivot.clone();
        let R::Axis { al } = st.r else { return None };
        self.act(
            b,
            Action::AxisDir {
                pivot: pivot.clone(),
                axis: self.body_dir(b, al),
                from: self.body_dir(b, fm.axes.z),
                to: t.clone(),
            },
            serves,
        );
        new.r = R::Fixed;
        Some(())
    }

    /// `AlignOntoCone`: Align z_m, then turn about it until the cone's direction is on its cone (a branch).
    fn do_align_onto_cone(&mut self, a: &Applied, t: &DirRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, st) = (a.b, a.fm, a.serves, &a.st);
        let pivot = a.pivot.clone();
        let R::Cone { u, w, cos } = st.r.clone() else {
            return None;
        };
        self.align_z(b, &pivot, fm.axes.z, t, serves);
        let slot = self.slot();
        self.act(
            b,
            Action::AxisCondition {
                pivot: pivot.clone(),
                axis: self.body_dir(b, fm.axes.z),
                v: self.body_dir(b, u),
                w,
                cos,
                branch: slot,
            },
            serves,
        );
        new.r = R::Fixed;
        Some(())
    }

    /// `AxisCondition`: Rotation about the axis making the angle to the direction (a branch).
    fn do_axis_condition(&mut self, a: &Applied, t: &DirRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, e, st) = (a.b, a.fm, a.serves, &a.e, &a.st);
        let pivot = a.pivot.clone();
        let R::Axis { al } = st.r else { return None };
        let cos = match e.kind {
            Kind::Prim(Primitive::PerpendicularZ) => 0.0,
            _ => e.angle.cos(),
        };
        let slot = self.slot();
        self.act(
            b,
            Action::AxisCondition {
                pivot: pivot.clone(),
                axis: self.body_dir(b, al),
                v: self.body_dir(b, fm.axes.z),
                w: t.clone(),
                cos,
                branch: slot,
            },
            serves,
        );
        new.r = R::Fixed;
        Some(())
    }

    /// `Tilt`: Tilt z_m to the angle: the cone state.
    fn do_tilt(&mut self, a: &Applied, t: &DirRef, new: &mut State) -> Option<()> {
        let (b, fm, serves, e) = (a.b, a.fm, a.serves, &a.e);
        let pivot = a.pivot.clone();
        let cos = match e.kind {
            Kind::Prim(Primitive::PerpendicularZ) => 0.0,
            _ => e.angle.cos(),
        };
        self.act(
            b,
            Action::Tilt {
                pivot: pivot.clone(),
                from: self.body_dir(b, fm.axes.z),
                to: t.clone(),
                cos,
            },
            serves,
        );
        new.r = R::Cone {
            u: fm.axes.z,
            w: t.clone(),
            cos,
        };
        Some(())
    }

    /// `AlignTwist`, `Twist`: Align z, then twist x: orientation known. / Twist about the axis (the input's angle, or offset-x's).
    fn do_twist(&mut self, a: &Applied, frag: &Fragment, target: &Target, new: &mut State) -> Option<()> {
        let (mover, b, fm, sign, serves, e) = (a.mover, a.b, a.fm, a.sign, a.serves, &a.e);
        let pivot = a.pivot.clone();
        // The twist is measured about the first marker's z from its x
        // to the second's.
        let (b1, b2) = (e.bodies[0], e.bodies[1]);
        let [f1, f2] = e.frames;
        if frag.action == Do::AlignTwist {
            let Target::Dir(t) = target else { return None };
            self.align_z(b, &pivot, fm.axes.z, t, serves);
        }
        let input = match e.kind {
            Kind::Angle { input } => Some(input),
            _ => None,
        };
        let z1 = if mover == 0 {
            self.body_dir(b1, f1.axes.z)
        } else {
            self.known_dir(b1, f1.axes.z)
                .unwrap_or(self.body_dir(b1, f1.axes.z))
        };
        self.act(
            b,
            Action::Twist {
                pivot: pivot.clone(),
                axis: z1,
                x1: self.body_dir(b1, f1.axes.x),
                x2: self.body_dir(b2, f2.axes.x),
                angle: e.angle,
                input,
                sign,
            },
            serves,
        );
        new.r = R::Fixed;
        Some(())
    }

    /// `SlideTo`: Slide along the line to the input's distance.
    fn do_slide_to(&mut self, a: &Applied, new: &mut State) -> Option<()> {
        let (b, sign, serves, e, st) = (a.b, a.sign, a.serves, &a.e, &a.st);
        let Kind::Slide { input } = e.kind else {
            return None;
        };
        let T::Line { q, dir } = st.t.clone() else {
            return None;
        };
        let (b1, b2) = (e.bodies[0], e.bodies[1]);
        self.act(
            b,
            Action::SlideTo {
                from: self.body_point(b2, e.frames[1].at),
                origin: self.body_point(b1, e.frames[0].at),
                dir,
                axial0: e.axial0,
                input,
                sign,
            },
            serves,
        );
        new.t = T::Point { q };
        Some(())
    }

    /// Rotates body `b` about `pivot` so its marker `mname`'s z (local `z`)
    /// points along `to`.
    fn align_z(&mut self, b: usize, pivot: &PointRef, z: Vec3, to: &DirRef, serves: &[String]) {
        self.act(
            b,
            Action::AlignDir {
                pivot: pivot.clone(),
                from: self.body_dir(b, z),
                to: to.clone(),
            },
            serves,
        );
    }

    /// Rotates body `b` about `pivot` taking its point `from` (the marker
    /// `mname`) onto `to`.
    fn rotate_onto(&mut self, b: usize, pivot: &PointRef, from: PointRef, to: &PointRef, serves: &[String]) {
        self.act(
            b,
            Action::RotateOnto {
                pivot: pivot.clone(),
                from,
                to: to.clone(),
            },
            serves,
        );
    }

    /// The locus of body point `local` of `b` (or of the point it is on a
    /// driven slide's other body), with the body that moves on it.
    fn locus(&self, b: usize, local: Vec3) -> Option<(usize, Locus, PointRef)> {
        self.locus_of(b, local, false)
    }

    /// [`Self::locus`]; `cone_ok`: a point of a body whose direction is on
    /// a cone (a leg on a universal joint) counts as on a sphere, which
    /// holds for distances (contraction) though not for placing it.
    fn locus_of(&self, b: usize, local: Vec3, cone_ok: bool) -> Option<(usize, Locus, PointRef)> {
        let s = &self.state[b];
        let here = |p: PointRef| -> Option<Locus> {
            match (&s.t, &s.r) {
                (T::Point { q }, R::Axis { al }) if !self.on_line(local, *q, *al) => Some(Locus::Circle {
                    pivot: self.body_point(b, *q),
                    axis: self.body_dir(b, *al),
                    at: p,
                }),
                (T::Point { q }, R::Free) if !self.same_point(local, *q) => Some(Locus::Sphere {
                    centre: self.body_point(b, *q),
                    a: self.body_point(b, *q),
                    b: p,
                }),
                (T::Line { dir, .. }, R::Fixed) => Some(Locus::Line {
                    at: p,
                    dir: dir.clone(),
                }),
                _ => None,
            }
        };
        if let Some(l) = here(self.body_point(b, local)) {
            return Some((b, l, self.body_point(b, local)));
        }
        let (a, slid) = self.slid(b, local)?;
        let sa = &self.state[a];
        let l = match (&sa.t, &sa.r) {
            (T::Point { q }, R::Axis { al }) => Locus::Circle {
                pivot: self.body_point(a, *q),
                axis: self.body_dir(a, *al),
                at: slid.clone(),
            },
            (T::Point { q }, R::Free) => Locus::Sphere {
                centre: self.body_point(a, *q),
                a: self.body_point(a, *q),
                b: slid.clone(),
            },
            (T::Point { q }, R::Cone { .. }) if cone_ok => Locus::Sphere {
                centre: self.body_point(a, *q),
                a: self.body_point(a, *q),
                b: slid.clone(),
            },
            _ => return None,
        };
        Some((a, l, slid))
    }

    /// Loop closure: a coincident equation between two partly placed
    /// bodies, by intersecting its markers' loci.
    fn close_loop(&mut self, i: usize) -> bool {
        let e = self.eqs[i].clone();
        if e.kind == Kind::Prim(Primitive::ParallelZ) {
            return self.close_directions(i);
        }
        if e.kind != Kind::Prim(Primitive::Coincident) {
            return false;
        }
        let Some((ba, la, pa)) = self.locus(e.bodies[0], e.frames[0].at) else {
            return false;
        };
        let Some((bb, lb, pb)) = self.locus(e.bodies[1], e.frames[1].at) else {
            return false;
        };
        if ba == bb || la.dim() + lb.dim() > 3 {
            return false;
        }
        let pair_ok = matches!(
            (&la, &lb),
            (Locus::Circle { .. }, Locus::Circle { .. })
                | (Locus::Sphere { .. }, Locus::Circle { .. })
                | (Locus::Circle { .. }, Locus::Sphere { .. })
                | (Locus::Line { .. }, Locus::Sphere { .. })
                | (Locus::Sphere { .. }, Locus::Line { .. })
                | (Locus::Line { .. }, Locus::Circle { .. })
                | (Locus::Circle { .. }, Locus::Line { .. })
        );
        if !pair_ok {
            return false;
        }
        let redundant = 3 - (la.dim() + lb.dim()).min(3);
        let mname = self.m.marker_name(e.markers[1]);
        let t = self.temp(mname.clone(), e.frames[1].at);
        let slot = self.slot();
        let serves = vec![self.serves(i)];
        self.push(
            StepKind::Intersect {
                temp: t,
                loci: Box::new([la, lb]),
                branch: Some(slot),
                tol: 1e-7 * self.size,
            },
            serves.clone(),
        );
        for (body, pt) in [(ba, pa), (bb, pb)] {
            self.meet(body, pt, PointRef::Temp(t), &serves);
        }
        self.used[i] = true;
        if redundant > 0 {
            if ba == e.bodies[0] && bb == e.bodies[1] {
                self.check(i, redundant);
            } else {
                self.pending.push((i, redundant));
            }
        }
        true
    }

    /// Loop closure on directions: a parallel-z between two bodies that each
    /// turn about an axis across their marker's z. Each z sweeps a cone
    /// about its body's axis; the cones meet in (at most) two directions,
    /// and each body turns about its axis onto its own (Kramer's
    /// pseudo-direction and two parallel-z).
    fn close_directions(&mut self, i: usize) -> bool {
        let e = self.eqs[i].clone();
        let [b1, b2] = e.bodies;
        let (R::Axis { al: al1 }, R::Axis { al: al2 }) = (self.state[b1].r.clone(), self.state[b2].r.clone())
        else {
            return false;
        };
        let (z1, z2) = (e.frames[0].axes.z, e.frames[1].axes.z);
        // Parallel axes (a planar loop) make the two cones one: a curve of
        // solutions, not two; that loop closes on points instead.
        if b1 == b2
            || self.fixed(b1)
            || self.fixed(b2)
            || parallel(z1, al1)
            || parallel(z2, al2)
            || parallel(al1, al2)
        {
            return false;
        }
        let cos = |u: Vec3, a: Vec3| {
            let n = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
                * (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            (u[0] * a[0] + u[1] * a[1] + u[2] * a[2]) / n
        };
        let name1 = self.m.marker_name(e.markers[0]);
        let name2 = self.m.marker_name(e.markers[1]);
        let t1 = self.temp(format!("{name1} z"), z1);
        let t2 = self.temp(format!("{name2} z"), z2);
        let slot = self.slot();
        let serves = vec![self.serves(i)];
        self.push(
            StepKind::IntersectDir {
                temps: [t1, t2],
                cones: Box::new([
                    (self.body_dir(b1, al1), cos(z1, al1)),
                    (self.body_dir(b2, al2), cos(z2, al2)),
                ]),
                sign: e.sign,
                branch: slot,
            },
            serves.clone(),
        );
        for (b, al, z, t) in [(b1, al1, z1, t1), (b2, al2, z2, t2)] {
            let pivot = self.pivot_point(b, &self.state[b].clone(), e.frames[0].at);
            self.act(
                b,
                Action::AxisDir {
                    pivot,
                    axis: self.body_dir(b, al),
                    from: self.body_dir(b, z),
                    to: DirRef::Temp(t),
                },
                &serves,
            );
            self.state[b].r = R::Fixed;
            self.changed.push(b);
        }
        self.used[i] = true;
        true
    }

    /// Moves a partly placed body so its point `pt` meets a known point.
    fn meet(&mut self, b: usize, pt: PointRef, to: PointRef, serves: &[String]) {
        let st = self.state[b].clone();
        match (&st.t, &st.r) {
            (T::Point { q }, R::Axis { al }) => {
                self.act(
                    b,
                    Action::AxisOnto {
                        pivot: self.body_point(b, *q),
                        axis: self.body_dir(b, *al),
                        from: pt,
                        to,
                    },
                    serves,
                );
                self.state[b].r = R::Fixed;
                self.changed.push(b);
            }
            (T::Point { q }, R::Free) => {
                let local = match &pt {
                    PointRef::Body { local, .. } | PointRef::Slid { local, .. } => *local,
                    _ => *q,
                };
                self.act(
                    b,
                    Action::RotateOnto {
                        pivot: self.body_point(b, *q),
                        from: pt,
                        to,
                    },
                    serves,
                );
                self.state[b].r = R::Axis {
                    al: unit(sub(local, *q)),
                };
                self.changed.push(b);
            }
            (T::Line { .. }, R::Fixed) => {
                let T::Line { q, dir } = st.t.clone() else {
                    unreachable!()
                };
                self.act(b, Action::TranslateAlong { from: pt, to, dir }, serves);
                self.state[b].t = T::Point { q };
                self.changed.push(b);
            }
            (T::Point { q }, R::Cone { u, w, cos }) => {
                let (u, w, cos) = (*u, w.clone(), *cos);
                let pivot = self.body_point(b, *q);
                self.act(
                    b,
                    Action::RotateOnto {
                        pivot: pivot.clone(),
                        from: pt,
                        to: to.clone(),
                    },
                    serves,
                );
                let slot = self.slot();
                self.act(
                    b,
                    Action::AxisCondition {
                        pivot: pivot.clone(),
                        axis: DirRef::Between(Box::new(pivot), Box::new(to)),
                        v: self.body_dir(b, u),
                        w,
                        cos,
                        branch: slot,
                    },
                    serves,
                );
                self.state[b].r = R::Fixed;
                self.changed.push(b);
            }
            _ => {}
        }
    }

    /// Numeric fallback: the unplaced bodies that still have equations,
    /// with bodies hanging on a contracted leg replaced by distance rows.
    fn cluster(&mut self) -> bool {
        let unplaced: Vec<usize> = (0..self.m.bodies.len())
            .filter(|&b| !self.fixed(b) && !self.placed(b))
            .collect();
        if unplaced.is_empty() {
            return false;
        }
        let open: Vec<usize> = (0..self.eqs.len()).filter(|&i| !self.used[i]).collect();
        if open.is_empty() {
            return false;
        }
        let (contracted, mut gathered) = self.contract(&open);
        let hanging = self.hanging(&open, &contracted, &gathered.used);
        let mut members: Vec<usize> = unplaced.iter().copied().filter(|&b| !hanging[b]).collect();
        if members.is_empty() || gathered.rows.is_empty() {
            // No contraction: every unplaced body with open equations.
            members = unplaced
                .iter()
                .copied()
                .filter(|&b| open.iter().any(|&i| self.eqs[i].bodies.contains(&b)))
                .collect();
            gathered = Gathered::default();
        }
        if members.is_empty() {
            return false;
        }
        self.gather_inside(&open, &members, &mut gathered);
        let params = self.cluster_params(&members, &mut gathered);
        self.place_cluster(members, params, gathered);
        true
    }

    /// Contraction: a coincident equation between a point on a body
    /// turning about a pivot (directly, or through a driven slide) and a
    /// point of another body is the distance from the pivot. Returns which
    /// bodies were contracted, and the distance rows with the legs to swing
    /// into place afterwards.
    fn contract(&self, open: &[usize]) -> (Vec<bool>, Gathered) {
        let mut contracted = vec![false; self.m.bodies.len()];
        let mut gathered = Gathered::default();
        for &i in open {
            let e = &self.eqs[i];
            if e.kind != Kind::Prim(Primitive::Coincident) {
                continue;
            }
            for side in [0usize, 1] {
                let (b, o) = (e.bodies[side], e.bodies[1 - side]);
                let Some((a, Locus::Sphere { centre, a: pa, b: pb }, _)) =
                    self.locus_of(b, e.frames[side].at, true)
                else {
                    continue;
                };
                if a == o || self.placed(o) {
                    continue;
                }
                let _ = centre;
                contracted[a] = true;
                if a != b {
                    contracted[b] = true;
                }
                let (_, _, carried) = self.locus_of(b, e.frames[side].at, true).expect("found above");
                gathered.meets.push(Meet {
                    body: a,
                    carried,
                    target: self.body_point(o, e.frames[1 - side].at),
                    serves: self.serves(i),
                });
                gathered.rows.push(ClusterRow::Distance {
                    a: self.body_point(o, e.frames[1 - side].at),
                    b: pa.clone(),
                    c: pa,
                    d: pb,
                    name: self.serves(i),
                });
                gathered.used.push(i);
                break;
            }
        }
        (contracted, gathered)
    }

    /// The contracted bodies and the bodies joined to one by an equation
    /// not contracted (`used`): these are placed after the cluster, not
    /// solved in it.
    fn hanging(&self, open: &[usize], contracted: &[bool], used: &[usize]) -> Vec<bool> {
        let mut hanging = contracted.to_vec();
        for &i in open {
            let [b1, b2] = self.eqs[i].bodies;
            if used.contains(&i) {
                continue;
            }
            if contracted[b1] && !self.fixed(b2) {
                hanging[b2] = true;
            }
            if contracted[b2] && !self.fixed(b1) {
                hanging[b1] = true;
            }
        }
        hanging
    }

    /// Adds as rows the open equations on a member whose bodies are all
    /// members, placed or fixed.
    fn gather_inside(&self, open: &[usize], members: &[usize], gathered: &mut Gathered) {
        let member = |b: usize| members.contains(&b);
        for &i in open {
            if gathered.used.contains(&i) {
                continue;
            }
            let [b1, b2] = self.eqs[i].bodies;
            let inside = |b: usize| member(b) || self.placed(b) || self.fixed(b);
            if (member(b1) || member(b2)) && inside(b1) && inside(b2) {
                gathered.rows.push(ClusterRow::Equation(self.check_row(i, 0)));
                gathered.used.push(i);
            }
        }
    }

    /// Unknowns from each member's state. A state that no parameter keeps
    /// by construction gives the equations that narrowed it back as rows.
    fn cluster_params(&self, members: &[usize], gathered: &mut Gathered) -> Vec<Param> {
        let mut params = Vec::new();
        for &b in members {
            let st = &self.state[b];
            params.push(match (&st.t, &st.r) {
                (T::Point { q }, R::Axis { al }) => Param::Axis {
                    body: b,
                    pivot: self.body_point(b, *q),
                    axis: self.body_dir(b, *al),
                },
                (T::Point { q }, R::Free) => Param::Pivot {
                    body: b,
                    pivot: self.body_point(b, *q),
                },
                _ => Param::Free { body: b },
            });
            if !matches!(
                (&st.t, &st.r),
                (T::Point { .. }, R::Axis { .. } | R::Free) | (T::Free, R::Free)
            ) {
                // The state's own constraints become rows again.
                for (i, e) in self.eqs.iter().enumerate() {
                    if self.used[i] && e.bodies.contains(&b) && !gathered.used.contains(&i) {
                        gathered.rows.push(ClusterRow::Equation(self.check_row(i, 0)));
                        gathered.used.push(i);
                    }
                }
            }
        }
        params
    }

    /// Records the cluster's step, marks its equations used and its members
    /// placed, then swings each contracted leg onto the point it holds.
    fn place_cluster(&mut self, members: Vec<usize>, params: Vec<Param>, gathered: Gathered) {
        let Gathered { rows, used, meets } = gathered;
        let cluster = Cluster {
            params,
            rows,
            size: self.size,
        };
        let serves: Vec<String> = used.iter().map(|&i| self.serves(i)).collect();
        self.push(StepKind::Cluster(Box::new(cluster)), serves);
        for &i in &used {
            self.used[i] = true;
        }
        for &b in &members {
            self.state[b] = State {
                t: T::Point { q: [0.0; 3] },
                r: R::Fixed,
            };
            self.changed.push(b);
        }
        for Meet {
            body,
            carried,
            target,
            serves,
        } in meets
        {
            self.meet(body, carried, target, &[serves]);
        }
    }
}

/// A numeric cluster as it is gathered: its rows, the equations they take,
/// and the contracted legs to swing into place once it is solved.
#[derive(Default)]
struct Gathered {
    /// The cluster's rows, in the order they are taken.
    rows: Vec<ClusterRow>,
    /// The equations the rows take.
    used: Vec<usize>,
    /// The contracted legs.
    meets: Vec<Meet>,
}

/// A contracted leg: once the cluster is solved, `body` swings so that the
/// point it carries meets `target`.
struct Meet {
    /// The body that swings.
    body: usize,
    /// The point it carries.
    carried: PointRef,
    /// The point that point must reach.
    target: PointRef,
    /// The equation it serves.
    serves: String,
}

/// What a fragment acts on, worked out once by `apply` and read by the
/// method of its action: the equation, the moving marker's frame, the
/// body's state before the action, and the names its explanation uses.
struct Applied<'s> {
    /// Which of the equation's two markers moves (0 or 1).
    mover: usize,
    /// The body that moves.
    b: usize,
    e: Equation,
    /// The moving marker's frame, in its body.
    fm: Frame,
    /// The body's state before the action.
    st: State,
    name: String,
    mname: String,
    /// The moving marker, as a point of its body.
    m_pt: PointRef,
    /// The body's pivot (its T-part's point, or the marker).
    pivot: PointRef,
    /// +1 when the second marker moves, −1 when the first does.
    sign: f64,
    /// The joints the action serves (for the explanation).
    serves: &'s [String],
}

/// What the other side of an equation offers.
#[derive(Clone, Debug)]
enum Target {
    /// A known point.
    Point(PointRef),
    /// A known line (or plane: point and normal).
    Line(PointRef, DirRef),
    /// A known direction.
    Dir(DirRef),
    /// Nothing beyond the known axes (inputs).
    None,
}
