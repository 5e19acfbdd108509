//! Degrees-of-freedom analysis for planar bodies: the plan-fragment table.
//!
//! Each body's remaining freedom is tracked as a [`Know`] state (Kramer's
//! TDOF/RDOF bookkeeping in 2D). Rules consume primitive equations whose
//! other end is already known and either narrow a body's state or place it
//! by a closed-form step:
//!
//! | state     | + equation to something known    | fragment                   |
//! |-----------|----------------------------------|----------------------------|
//! | any       | parallel (rotation known)        | orient (propagation)       |
//! | free      | coincident                       | pinned (1 RDOF left)       |
//! | oriented  | coincident                       | anchor → placed            |
//! | oriented  | in-line                          | sliding (1 TDOF left)      |
//! | sliding   | in-line                          | line ∩ line → placed       |
//! | pinned    | in-line (its point on a line)    | circle ∩ line → placed     |
//! | pinned    | in-line (its line through point) | turn line → placed         |
//! | pinned    | coincident (another marker)      | two points → placed        |
//!
//! and dyads — two bodies, each with one freedom left, joined to each
//! other (contraction of a three-node loop, Brunkhart §3.3):
//!
//! | pair                | joined by            | fragment                  |
//! |---------------------|----------------------|---------------------------|
//! | pinned + pinned     | coincident (RRR)     | circle ∩ circle           |
//! | pinned + sliding    | coincident (RRP)     | circle ∩ line             |
//! | sliding + sliding   | coincident (PRP)     | line ∩ line               |
//! | pinned + pinned     | prismatic (RPR)      | turn line through pivot   |
//!
//! Sliding bodies are translated provisionally onto their line so that any
//! of their markers, read at that pose, is a point of its own line locus.

mod arcs;

use std::collections::BTreeSet;

use dofplan_runtime::{Branch, Point};

use super::Progress;
use crate::model::planar::equations::{End, Equation, Sourced};
use crate::model::planar::gears::GearKind;
use crate::model::Mechanism;
use crate::plan::{
    Affine, BodyId, BranchSlot, ClusterParam, DirRef, Line, PointRef, Rel, Step, StepKind, Temp,
};

/// Two local points closer than this (relative to the mechanism's size) are
/// the same point.
const SAME_POINT: f64 = 1e-9;

/// What is known about a body's pose.
#[derive(Clone, Debug)]
enum Know {
    /// Nothing: 3 DOF.
    Free,
    /// Its marker `local` is at the known point `at`: 1 RDOF.
    Pinned { local: Point, at: PointRef },
    /// Its rotation is known: 2 TDOF.
    Oriented,
    /// Rotation known and translation on a line of direction `dir`; the
    /// body sits provisionally on that line: 1 TDOF.
    Sliding { dir: DirRef },
    /// Fully known.
    Placed,
}

impl Know {
    fn rot_known(&self) -> bool {
        matches!(self, Know::Oriented | Know::Sliding { .. } | Know::Placed)
    }
}

/// The outcome of planning.
pub struct Planned {
    /// Steps in order.
    pub steps: Vec<Step>,
    /// Computed points.
    pub temps: Vec<Temp>,
    /// Branch slots (initial branch still to be chosen).
    pub branches: Vec<BranchSlot>,
    /// Equations no rule used (redundant ones, or ones on unplaced bodies).
    pub unused: Vec<usize>,
    /// Gear pairs no step serves (indices into the mechanism's gears).
    pub ungeared: Vec<usize>,
    /// Candidate equations the rules examined: the planner's work, linear
    /// in the mechanism's size.
    pub checks: usize,
}

struct Planner<'m> {
    m: &'m Mechanism,
    eqs: &'m [Sourced],
    used: Vec<bool>,
    know: Vec<Know>,
    /// Origins consumed for a body that no step has reported yet (a pin
    /// records no step; the step that finally places the body serves it).
    pending: Vec<Vec<String>>,
    steps: Vec<Step>,
    temps: Vec<Temp>,
    branches: Vec<BranchSlot>,
    tol: f64,
    clusters: usize,
    /// Per body: the equations on it, in file order.
    on: Vec<Vec<usize>>,
    /// Per closed-form rule: the equations it may apply to — every one at
    /// first, then each whose bodies' states changed since the rule last
    /// found it inapplicable (nothing else changes whether a rule applies).
    /// Each rule takes the lowest-numbered equation it applies to, exactly
    /// as a scan of all equations in file order would, at a cost linear in
    /// the mechanism's size.
    queues: [BTreeSet<usize>; RULES],
    /// Bodies not placed yet.
    unplaced: usize,
    /// Candidate equations examined by the rules (the planner's work).
    checks: usize,
    /// Equations used so far.
    consumed: usize,
    /// Per body: its rotation in degrees as an affine function of the
    /// inputs, where every step that set it was a rotation by an input or
    /// a gear pair (the ground's is 0); what gear pairs are planned from.
    angle: Vec<Option<Affine>>,
    /// Per gear pair of the mechanism: whether a step serves it.
    geared: Vec<bool>,
}

/// The closed-form rules, in the order they are tried.
#[derive(Clone, Copy)]
enum Rule {
    Rotation,
    Coincident,
    InLine,
    OnCircle,
    Dyad,
}

const RULES: usize = 5;

/// The closed-form rules that can apply to an equation.
fn rules_for(eq: &Equation) -> &'static [Rule] {
    match eq {
        Equation::Parallel { .. } => &[Rule::Rotation],
        Equation::Coincident { .. } => &[Rule::Coincident, Rule::Dyad],
        Equation::InLine { .. } => &[Rule::InLine, Rule::Dyad],
        Equation::OnCircle { .. } => &[Rule::OnCircle],
    }
}

/// Plans a mechanism from its equations: closed form as far as it goes, then
/// a numeric cluster for what is left, then closed form again for what the
/// cluster determines, and so on.
///
/// `progress` hears how many equations the steps use so far, out of all.
pub fn plan(m: &Mechanism, eqs: &[Sourced], progress: &mut dyn FnMut(Progress)) -> Planned {
    let mut p = Planner {
        m,
        eqs,
        used: vec![false; eqs.len()],
        know: m
            .bodies
            .iter()
            .map(|b| if b.fixed { Know::Placed } else { Know::Free })
            .collect(),
        pending: vec![Vec::new(); m.bodies.len()],
        steps: Vec::new(),
        temps: Vec::new(),
        branches: Vec::new(),
        tol: SAME_POINT * m.size(),
        clusters: 0,
        on: vec![Vec::new(); m.bodies.len()],
        queues: Default::default(),
        unplaced: m.bodies.iter().filter(|b| !b.fixed).count(),
        checks: 0,
        consumed: 0,
        angle: m.bodies.iter().map(|b| b.fixed.then(Affine::default)).collect(),
        geared: vec![false; m.gears.len()],
    };
    for (i, e) in eqs.iter().enumerate() {
        let [a, b] = e.eq.bodies();
        p.on[a].push(i);
        if b != a {
            p.on[b].push(i);
        }
        for &rule in rules_for(&e.eq) {
            p.queues[rule as usize].insert(i);
        }
    }
    while p.unplaced > 0 {
        let progressed = p.drain(Rule::Rotation, Planner::try_rotation)
            || p.gear_rule()
            || p.drain(Rule::Coincident, Planner::try_coincident)
            || p.drain(Rule::InLine, Planner::try_in_line)
            || p.drain(Rule::OnCircle, Planner::try_on_circle)
            || p.drain(Rule::Dyad, Planner::try_dyad)
            || p.cluster_rule();
        if !progressed {
            break;
        }
        progress(Progress {
            stage: "plan",
            done: p.consumed,
            total: eqs.len(),
        });
    }
    Planned {
        unused: (0..eqs.len()).filter(|&i| !p.used[i]).collect(),
        ungeared: (0..m.gears.len()).filter(|&g| !p.geared[g]).collect(),
        steps: p.steps,
        temps: p.temps,
        branches: p.branches,
        checks: p.checks,
    }
}

fn dist(a: Point, b: Point) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

/// A marker of a body not yet placed, read at its provisional pose (a
/// sliding body's marker is a point of its own line locus there).
fn moving_marker(end: &End) -> PointRef {
    PointRef::Marker {
        body: end.body,
        local: end.local,
        name: end.name.clone(),
    }
}

impl Planner<'_> {
    fn placed(&self, body: BodyId) -> bool {
        matches!(self.know[body], Know::Placed)
    }

    /// A marker of a placed body as a point reference.
    fn marker_point(&self, body: BodyId, local: Point, name: &str) -> PointRef {
        if self.m.bodies[body].fixed {
            PointRef::Fixed {
                at: local,
                name: name.to_string(),
            }
        } else {
            PointRef::Marker {
                body,
                local,
                name: name.to_string(),
            }
        }
    }

    /// The world point of a marker, if known: a marker of a placed body, or
    /// the pin point of a pinned body.
    fn known_point(&self, body: BodyId, local: Point, name: &str) -> Option<PointRef> {
        match &self.know[body] {
            Know::Placed => Some(self.marker_point(body, local, name)),
            Know::Pinned { local: l, at } if dist(*l, local) <= self.tol => Some(at.clone()),
            _ => None,
        }
    }

    fn dir_ref(&self, body: BodyId, local: Point) -> DirRef {
        if self.m.bodies[body].fixed {
            DirRef::Fixed(local)
        } else {
            DirRef::Body { body, local }
        }
    }

    /// Changes what is known about a body, and hands the equations on it
    /// back to every rule (they may apply now).
    fn set(&mut self, body: BodyId, know: Know) {
        let was_placed = self.placed(body);
        self.know[body] = know;
        match (was_placed, self.placed(body)) {
            (false, true) => self.unplaced -= 1,
            (true, false) => self.unplaced += 1,
            _ => {}
        }
        for k in 0..self.on[body].len() {
            let i = self.on[body][k];
            if !self.used[i] {
                for &rule in rules_for(&self.eqs[i].eq) {
                    self.queues[rule as usize].insert(i);
                }
            }
        }
    }

    fn consume(&mut self, i: usize) -> String {
        self.used[i] = true;
        self.consumed += 1;
        self.eqs[i].origin.clone()
    }

    fn push(&mut self, kind: StepKind, mut serves: Vec<String>) {
        for b in kind.writes() {
            serves.append(&mut self.pending[b]);
        }
        serves.dedup();
        self.steps.push(Step { kind, serves });
    }

    fn temp(&mut self, name: &str) -> usize {
        self.temps.push(Temp {
            name: name.to_string(),
        });
        self.temps.len() - 1
    }

    fn branch_slot(&mut self, drawn: Point) -> usize {
        self.branches.push(BranchSlot {
            step: self.steps.len(),
            initial: Branch::Plus,
            drawn,
        });
        self.branches.len() - 1
    }

    /// Applies `rule` to the equations on its worklist, lowest-numbered
    /// first, until one yields a step (true) or the list is empty (false).
    /// An equation is back on the list only when one of its bodies changes
    /// state, so the planner's work stays linear in the mechanism's size.
    fn drain(&mut self, rule: Rule, apply: fn(&mut Self, usize) -> bool) -> bool {
        while let Some(i) = self.queues[rule as usize].pop_first() {
            self.checks += 1;
            if apply(self, i) {
                return true;
            }
        }
        false
    }

    /// Propagation of rotation through parallel equations.
    fn try_rotation(&mut self, i: usize) -> bool {
        if self.used[i] {
            return false;
        }
        let Equation::Parallel { a, b, input } = self.eqs[i].eq else {
            return false;
        };
        let (target, from, rel) = match (self.know[a].rot_known(), self.know[b].rot_known()) {
            (true, false) => (
                b,
                a,
                input.map_or(Rel::Identity, |i| Rel::Input {
                    input: i,
                    inverse: false,
                }),
            ),
            (false, true) => (
                a,
                b,
                input.map_or(Rel::Identity, |i| Rel::Input {
                    input: i,
                    inverse: true,
                }),
            ),
            _ => return false,
        };
        let origin = self.consume(i);
        self.angle[target] = self.angle[from].as_ref().map(|a| match rel {
            Rel::Identity => a.clone(),
            Rel::Input { input, inverse } => {
                a.combine(1.0, &Affine::input(input, if inverse { -1.0 } else { 1.0 }), 1.0)
            }
        });
        let from = (!self.m.bodies[from].fixed).then_some(from);
        self.push(
            StepKind::Orient {
                body: target,
                from,
                rel,
            },
            vec![origin],
        );
        let next = match &self.know[target] {
            Know::Pinned { local, at } => {
                let (local, at) = (*local, at.clone());
                self.push(
                    StepKind::Anchor {
                        body: target,
                        local,
                        at,
                    },
                    vec![],
                );
                Know::Placed
            }
            _ => Know::Oriented,
        };
        self.set(target, next);
        true
    }

    /// A marker meets a known point.
    fn try_coincident(&mut self, i: usize) -> bool {
        if self.used[i] {
            return false;
        }
        let Equation::Coincident { a, b, slide } = &self.eqs[i].eq else {
            return false;
        };
        // The point each side's marker must reach, when the other side
        // knows it.
        let for_b = match slide {
            Some((input, dir)) if self.placed(a.body) => Some(PointRef::Slid {
                body: a.body,
                local: a.local,
                dir: *dir,
                input: *input,
                sign: 1.0,
                name: a.name.clone(),
            }),
            Some(_) => None,
            None => self.known_point(a.body, a.local, &a.name),
        };
        let for_a = match slide {
            Some((input, dir)) if self.placed(b.body) => Some(PointRef::Slid {
                body: b.body,
                local: b.local,
                dir: *dir,
                input: *input,
                sign: -1.0,
                name: b.name.clone(),
            }),
            Some(_) => None,
            None => self.known_point(b.body, b.local, &b.name),
        };
        let candidates = [(b.body, b.local, for_b), (a.body, a.local, for_a)];
        for (body, local, at) in candidates {
            let Some(at) = at else { continue };
            let next = match &self.know[body] {
                Know::Free => Some(None),
                Know::Oriented => Some(Some(StepKind::Anchor {
                    body,
                    local,
                    at: at.clone(),
                })),
                Know::Pinned { local: l0, at: at0 } if dist(*l0, local) > self.tol => {
                    Some(Some(StepKind::Align {
                        body,
                        p: *l0,
                        p_at: at0.clone(),
                        q: local,
                        q_at: at.clone(),
                        redundant: true,
                    }))
                }
                _ => None,
            };
            let Some(step) = next else { continue };
            let origin = self.consume(i);
            match step {
                None => {
                    self.pending[body].push(origin);
                    self.set(body, Know::Pinned { local, at });
                }
                Some(kind) => {
                    self.push(kind, vec![origin]);
                    self.set(body, Know::Placed);
                }
            }
            return true;
        }
        false
    }

    /// A marker on a known line, or a body's line through a known point.
    fn try_in_line(&mut self, i: usize) -> bool {
        if self.used[i] {
            return false;
        }
        let Equation::InLine { line, dir, point } = &self.eqs[i].eq else {
            return false;
        };
        let (line, dir, point) = (line.clone(), *dir, point.clone());
        if self.placed(line.body) && !self.placed(point.body) {
            return self.point_onto_line(i, &line, dir, &point);
        }
        if !self.placed(line.body) {
            return self.line_through_point(i, &line, dir, &point);
        }
        false
    }

    /// In-line whose line is known (its body placed): the point's body
    /// slides along it, or is placed where its own locus meets it.
    fn point_onto_line(&mut self, i: usize, line: &End, dir: Point, point: &End) -> bool {
        let known = Line {
            through: self.marker_point(line.body, line.local, &line.name),
            dir: self.dir_ref(line.body, dir),
        };
        let body = point.body;
        match self.know[body].clone() {
            Know::Oriented => self.start_sliding(i, body, point.local, known.through, known.dir),
            Know::Sliding { dir: own } => self.slide_to_crossing(i, point, own, known),
            Know::Pinned { local: l0, at: at0 } if dist(l0, point.local) > self.tol => {
                self.circle_line_place(i, l0, at0, point, known);
                self.set(body, Know::Placed);
            }
            _ => return false,
        }
        true
    }

    /// In-line whose point is known (a marker of a placed body): the line's
    /// body slides through it, or is placed by crossing or turning its line
    /// onto it.
    fn line_through_point(&mut self, i: usize, line: &End, dir: Point, point: &End) -> bool {
        let Some(q) = self.known_point(point.body, point.local, &point.name) else {
            return false;
        };
        if !self.placed(point.body) {
            return false; // the point is known but its body still turns
        }
        let body = line.body;
        let along = DirRef::Body { body, local: dir };
        match self.know[body].clone() {
            Know::Oriented => self.start_sliding(i, body, line.local, q, along),
            Know::Sliding { dir: own } => self.slide_to_crossing(
                i,
                line,
                own,
                Line {
                    through: q,
                    dir: along,
                },
            ),
            Know::Pinned { local: l0, at: at0 } => {
                let origin = self.consume(i);
                let branch = self.branch_slot([1.0, 0.0]);
                self.push(
                    StepKind::TurnLine {
                        body,
                        pivot: at0.clone(),
                        target: q,
                        dir,
                        kappa: cross(sub(line.local, l0), dir),
                        branch,
                    },
                    vec![origin],
                );
                self.push(
                    StepKind::Anchor {
                        body,
                        local: l0,
                        at: at0,
                    },
                    vec![],
                );
                self.set(body, Know::Placed);
            }
            _ => return false,
        }
        true
    }

    /// An oriented body's marker `local` put on the known point `at`: the
    /// body is left sliding along `dir` (1 TDOF).
    fn start_sliding(&mut self, i: usize, body: BodyId, local: Point, at: PointRef, dir: DirRef) {
        let origin = self.consume(i);
        self.push(StepKind::Anchor { body, local, at }, vec![origin]);
        self.set(body, Know::Sliding { dir });
    }

    /// A sliding body placed where its own line (through its marker `end`,
    /// along `along`) crosses the line `other`.
    fn slide_to_crossing(&mut self, i: usize, end: &End, along: DirRef, other: Line) {
        let origin = self.consume(i);
        let out = self.temp(&end.name);
        let own = Line {
            through: moving_marker(end),
            dir: along,
        };
        self.push(
            StepKind::LineLine {
                out,
                a: own,
                b: other,
            },
            vec![origin],
        );
        self.push(
            StepKind::Anchor {
                body: end.body,
                local: end.local,
                at: PointRef::Temp { id: out },
            },
            vec![],
        );
        self.set(end.body, Know::Placed);
    }

    /// Turns a pinned body (its marker `pin` at `at`) so that its marker
    /// `end` lies where the circle it draws about the pin meets `line`;
    /// returns that point. The caller records the body's new state.
    fn circle_line_place(&mut self, i: usize, pin: Point, at: PointRef, end: &End, line: Line) -> PointRef {
        let origin = self.consume(i);
        let out = self.temp(&end.name);
        let branch = self.branch_slot(end.local);
        self.push(
            StepKind::CircleLine {
                out,
                c: at.clone(),
                r: dist(pin, end.local),
                line,
                branch,
            },
            vec![origin],
        );
        let x = PointRef::Temp { id: out };
        self.push(
            StepKind::Align {
                body: end.body,
                p: pin,
                p_at: at,
                q: end.local,
                q_at: x.clone(),
                redundant: false,
            },
            vec![],
        );
        x
    }

    /// Contraction of a three-node loop: two bodies with one freedom each,
    /// joined to each other.
    fn try_dyad(&mut self, i: usize) -> bool {
        if self.used[i] {
            return false;
        }
        match &self.eqs[i].eq {
            Equation::Coincident { a, b, slide: None } if !self.placed(a.body) && !self.placed(b.body) => {
                let (a, b) = (a.clone(), b.clone());
                self.coincident_dyad(i, &a, &b)
            }
            Equation::InLine { line, dir, point } => {
                let (line, dir, point) = (line.clone(), *dir, point.clone());
                self.rpr_dyad(i, &line, dir, &point)
            }
            _ => false,
        }
    }

    /// RRR, RRP or PRP: the markers `a` and `b` of two bodies with one
    /// freedom each meet; both bodies are placed.
    fn coincident_dyad(&mut self, i: usize, a: &End, b: &End) -> bool {
        let (la, lb) = (a.local, b.local);
        match (self.know[a.body].clone(), self.know[b.body].clone()) {
            (Know::Pinned { local: l1, at: p1 }, Know::Pinned { local: l2, at: p2 })
                if dist(l1, la) > self.tol && dist(l2, lb) > self.tol =>
            {
                self.circle_circle_dyad(i, a, (l1, p1), b, (l2, p2));
            }
            (Know::Pinned { local: l1, at: p1 }, Know::Sliding { dir }) if dist(l1, la) > self.tol => {
                self.pinned_sliding(i, l1, p1, a, b, dir);
            }
            (Know::Sliding { dir }, Know::Pinned { local: l2, at: p2 }) if dist(l2, lb) > self.tol => {
                self.pinned_sliding(i, l2, p2, b, a, dir);
            }
            (Know::Sliding { dir: d1 }, Know::Sliding { dir: d2 }) => {
                self.line_line_dyad(i, a, d1, b, d2);
            }
            _ => return false,
        }
        self.set(a.body, Know::Placed);
        self.set(b.body, Know::Placed);
        true
    }

    /// RRR: two pinned bodies (each pin given as its marker and the known
    /// point it sits at) whose markers `a` and `b` meet where the circles
    /// they draw about their pins cross.
    fn circle_circle_dyad(
        &mut self,
        i: usize,
        a: &End,
        (l1, p1): (Point, PointRef),
        b: &End,
        (l2, p2): (Point, PointRef),
    ) {
        let (la, lb) = (a.local, b.local);
        let origin = self.consume(i);
        let out = self.temp(&a.name);
        let branch = self.branch_slot(la);
        self.push(
            StepKind::CircleCircle {
                out,
                c1: p1.clone(),
                r1: dist(l1, la),
                c2: p2.clone(),
                r2: dist(l2, lb),
                branch,
            },
            vec![origin],
        );
        let x = PointRef::Temp { id: out };
        self.push(
            StepKind::Align {
                body: a.body,
                p: l1,
                p_at: p1,
                q: la,
                q_at: x.clone(),
                redundant: false,
            },
            vec![],
        );
        self.push(
            StepKind::Align {
                body: b.body,
                p: l2,
                p_at: p2,
                q: lb,
                q_at: x,
                redundant: false,
            },
            vec![],
        );
    }

    /// PRP: two sliding bodies whose markers `a` and `b` meet where their
    /// lines (along `d1` and `d2`) cross.
    fn line_line_dyad(&mut self, i: usize, a: &End, d1: DirRef, b: &End, d2: DirRef) {
        let origin = self.consume(i);
        let out = self.temp(&a.name);
        self.push(
            StepKind::LineLine {
                out,
                a: Line {
                    through: moving_marker(a),
                    dir: d1,
                },
                b: Line {
                    through: moving_marker(b),
                    dir: d2,
                },
            },
            vec![origin],
        );
        let x = PointRef::Temp { id: out };
        self.push(
            StepKind::Anchor {
                body: a.body,
                local: a.local,
                at: x.clone(),
            },
            vec![],
        );
        self.push(
            StepKind::Anchor {
                body: b.body,
                local: b.local,
                at: x,
            },
            vec![],
        );
    }

    /// RPR: two pinned bodies joined by a prismatic (this in-line with its
    /// parallel equation): the line's body turns until its line passes
    /// through the other's pin, and the other takes its rotation.
    fn rpr_dyad(&mut self, i: usize, line: &End, dir: Point, point: &End) -> bool {
        let (Know::Pinned { local: l1, at: p1 }, Know::Pinned { local: l2, at: p2 }) =
            (self.know[line.body].clone(), self.know[point.body].clone())
        else {
            return false;
        };
        // An RPR dyad also needs the prismatic's parallel
        // equation between the same two bodies.
        let Some(par) = self.on[line.body].iter().copied().find(|&j| {
            !self.used[j]
                && matches!(self.eqs[j].eq, Equation::Parallel { a, b, input: None }
                    if (a == line.body && b == point.body) || (a == point.body && b == line.body))
        }) else {
            return false;
        };
        let o1 = self.consume(i);
        let o2 = self.consume(par);
        let branch = self.branch_slot([1.0, 0.0]);
        let kappa = cross(sub(sub(line.local, l1), sub(point.local, l2)), dir);
        self.push(
            StepKind::TurnLine {
                body: line.body,
                pivot: p1.clone(),
                target: p2.clone(),
                dir,
                kappa,
                branch,
            },
            vec![o1, o2],
        );
        self.push(
            StepKind::Orient {
                body: point.body,
                from: Some(line.body),
                rel: Rel::Identity,
            },
            vec![],
        );
        self.push(
            StepKind::Anchor {
                body: line.body,
                local: l1,
                at: p1,
            },
            vec![],
        );
        self.push(
            StepKind::Anchor {
                body: point.body,
                local: l2,
                at: p2,
            },
            vec![],
        );
        self.set(line.body, Know::Placed);
        self.set(point.body, Know::Placed);
        true
    }

    /// Unknowns of a body in a cluster: the fewest its locus allows.
    fn unknowns_of(&self, body: BodyId) -> usize {
        match self.know[body] {
            Know::Free => 3,
            Know::Oriented => 2,
            Know::Pinned { .. } | Know::Sliding { .. } => 1,
            Know::Placed => 0,
        }
    }

    /// Unused equations that a cluster `s` would take: every body of the
    /// equation placed or in `s`, at least one in `s`; in file order.
    fn cluster_equations(&self, s: &[BodyId]) -> Vec<usize> {
        let mut in_s = vec![false; self.know.len()];
        for &b in s {
            in_s[b] = true;
        }
        let mut eqs: Vec<usize> = s
            .iter()
            .flat_map(|&b| self.on[b].iter().copied())
            .filter(|&i| !self.used[i] && self.eqs[i].eq.bodies().iter().all(|&b| in_s[b] || self.placed(b)))
            .collect();
        eqs.sort_unstable();
        eqs.dedup();
        eqs
    }

    /// How adding `b` to a cluster (`in_s`: its bodies) changes the
    /// cluster's freedom: `b`'s unknowns less its unused equations to the
    /// cluster, to placed bodies or to itself (the ones the cluster takes
    /// with it).
    fn freedom_added(&self, b: BodyId, in_s: &[bool]) -> i64 {
        let taken: usize = self.on[b]
            .iter()
            .filter(|&&i| !self.used[i])
            .filter(|&&i| {
                self.eqs[i]
                    .eq
                    .bodies()
                    .iter()
                    .all(|&x| x == b || in_s[x] || self.placed(x))
            })
            .map(|&i| self.eqs[i].eq.count())
            .sum();
        self.unknowns_of(b) as i64 - taken as i64
    }

    /// The unknowns of cluster `s` over its equations `eqs`, parents before
    /// children, and which of `eqs` (by position) the params satisfy by
    /// construction.
    ///
    /// Each body keeps the fewest unknowns its locus allows (pinned: its
    /// angle; sliding: its displacement; oriented: its translation). A free
    /// body joined by a plain revolute to a body already parametrised is
    /// then hinged on it — joint coordinates: its angle alone, the joint
    /// holding by construction — so a chain of free links costs one unknown
    /// per link and no equation per joint instead of three and two. A free
    /// body no hinge reaches is a free root (3 unknowns) and may carry
    /// hinges itself. Among the hinges possible, the first of `eqs` is
    /// taken; among free roots, the first body of `s`.
    fn cluster_params(&self, s: &[BodyId], eqs: &[usize]) -> (Vec<ClusterParam>, Vec<bool>) {
        let n = self.know.len();
        let (mut done, mut free) = (vec![false; n], vec![false; n]);
        // Per body: the positions in `eqs` of the plain revolutes on it.
        let mut hinges_on: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (k, &i) in eqs.iter().enumerate() {
            if let Equation::Coincident { a, b, slide: None } = &self.eqs[i].eq {
                hinges_on[a.body].push(k);
                if b.body != a.body {
                    hinges_on[b.body].push(k);
                }
            }
        }
        // Positions in `eqs` that may hinge a free body on a done one
        // (checked again when taken: their free end may be done by then).
        let mut candidates = BTreeSet::new();
        let mut params = Vec::new();
        for &b in s {
            let p = match &self.know[b] {
                Know::Free | Know::Placed => {
                    free[b] = true;
                    continue;
                }
                Know::Pinned { local, at } => ClusterParam::Angle {
                    body: b,
                    pin: *local,
                    at: at.clone(),
                },
                Know::Sliding { dir } => ClusterParam::Slide {
                    body: b,
                    dir: dir.clone(),
                },
                Know::Oriented => ClusterParam::Translate { body: b },
            };
            params.push(p);
            done[b] = true;
            candidates.extend(hinges_on[b].iter().copied());
        }
        let mut hinged = vec![false; eqs.len()];
        let mut left = s.iter().filter(|&&b| free[b]).count();
        let mut first_free = 0;
        while left > 0 {
            let mut hinge = None;
            while let Some(k) = candidates.pop_first() {
                let Equation::Coincident { a, b, .. } = &self.eqs[eqs[k]].eq else {
                    continue;
                };
                if done[a.body] && free[b.body] {
                    hinge = Some((k, b, a));
                } else if done[b.body] && free[a.body] {
                    hinge = Some((k, a, b));
                }
                if hinge.is_some() {
                    break;
                }
            }
            let body = match hinge {
                Some((k, child, parent)) => {
                    hinged[k] = true;
                    params.push(ClusterParam::Hinge {
                        body: child.body,
                        pin: child.local,
                        parent: parent.body,
                        at: parent.local,
                        name: parent.name.clone(),
                    });
                    child.body
                }
                None => {
                    while !free[s[first_free]] {
                        first_free += 1;
                    }
                    params.push(ClusterParam::Free { body: s[first_free] });
                    s[first_free]
                }
            };
            free[body] = false;
            done[body] = true;
            left -= 1;
            candidates.extend(hinges_on[body].iter().copied().filter(|&k| !hinged[k]));
        }
        (params, hinged)
    }

    /// Gear pairs and racks: the driven body's rotation (or the rack's
    /// slide) from the other's, when the angles it is set from are known
    /// affine in the inputs. Gears are few: each pass looks at all of
    /// them.
    fn gear_rule(&mut self) -> bool {
        for g in 0..self.m.gears.len() {
            self.checks += 1;
            if !self.geared[g] && self.try_gear(g) {
                return true;
            }
        }
        false
    }

    /// One gear pair or rack (see [`Planner::gear_rule`]).
    fn try_gear(&mut self, g: usize) -> bool {
        let gear = &self.m.gears[g];
        let [a, b] = gear.bodies;
        let ratio = gear.ratio();
        let zero = Affine::default();
        let carrier = match gear.carrier {
            Some(c) => self.angle[c].clone(),
            None => Some(zero.clone()),
        };
        let origin = format!("joint {}", gear.name);
        let rot = |p: &Self, body: usize| p.know[body].rot_known();
        match gear.kind {
            GearKind::Gear { .. } => {
                let (ta, tb) = (self.angle[a].clone(), self.angle[b].clone());
                // θb − θc = ratio·(θa − θc), all from the drawn pose.
                let (body, angle) = match (ta, tb, carrier) {
                    (Some(ta), None, Some(tc)) if !rot(self, b) => (b, ta.combine(ratio, &tc, 1.0 - ratio)),
                    (None, Some(tb), Some(tc)) if !rot(self, a) => {
                        (a, tb.combine(1.0 / ratio, &tc, 1.0 - 1.0 / ratio))
                    }
                    (Some(ta), Some(tb), None) => match gear.carrier {
                        Some(c) if !rot(self, c) => {
                            (c, tb.combine(1.0 / (1.0 - ratio), &ta, -ratio / (1.0 - ratio)))
                        }
                        _ => return false,
                    },
                    _ => return false,
                };
                self.turn(body, angle, origin);
                self.geared[g] = true;
                true
            }
            GearKind::RackPinion { dir, .. } => {
                let Some(tc) = carrier else { return false };
                let joint = &self.m.joints[gear.pivots[1]];
                let rack_marker = if joint.markers[0].body == b {
                    joint.markers[0]
                } else {
                    joint.markers[1]
                };
                let local = self.m.marker(rack_marker).at;
                let carrier_body = joint
                    .markers
                    .iter()
                    .find(|m| m.body != b)
                    .expect("a joint of two bodies")
                    .body;
                // The slide per degree of the pinion relative to the carrier.
                let per_degree = ratio * std::f64::consts::PI / 180.0;
                if let Some(tp) = self.angle[a].clone() {
                    // The pinion is set: the rack's slide follows, once the
                    // rack is oriented (by its prismatic joint) and the
                    // carrier placed.
                    if self.placed(b) || !rot(self, b) || !self.placed(carrier_body) {
                        return false;
                    }
                    let slide = tp.combine(per_degree, &tc, -per_degree);
                    // The prismatic joint's line is implied by the slide.
                    for i in self.on[b].clone() {
                        if !self.used[i] && self.eqs[i].origin == format!("joint {}", joint.name) {
                            if let Equation::InLine { .. } = self.eqs[i].eq {
                                self.consume(i);
                            }
                        }
                    }
                    self.push(
                        StepKind::Shift {
                            body: b,
                            local,
                            carrier: carrier_body,
                            at: local,
                            dir,
                            slide,
                            name: self.m.marker_name(rack_marker),
                        },
                        vec![origin, format!("joint {}", joint.name)],
                    );
                    self.set(b, Know::Placed);
                    self.geared[g] = true;
                    return true;
                }
                // The rack's slide is an input: the pinion turns with it.
                let input = self.m.inputs.iter().position(|i| i.joint == gear.pivots[1]);
                let (Some(input), false) = (input, rot(self, a)) else {
                    return false;
                };
                // The input slides the joint's second marker along the
                // first's direction (the rack's `dir`); seen from the rack
                // as first, backward.
                let sign = if joint.markers[1].body == b { 1.0 } else { -1.0 };
                let slide = Affine::input(input, sign);
                let angle = slide.combine(1.0 / per_degree, &tc, 1.0);
                self.turn(a, angle, origin);
                self.geared[g] = true;
                true
            }
        }
    }

    /// A geared body turned to `angle`, then placed by its pin if it has
    /// one.
    fn turn(&mut self, body: BodyId, angle: Affine, origin: String) {
        self.angle[body] = Some(angle.clone());
        self.push(StepKind::Turn { body, angle }, vec![origin]);
        let next = match &self.know[body] {
            Know::Pinned { local, at } => {
                let (local, at) = (*local, at.clone());
                self.push(StepKind::Anchor { body, local, at }, vec![]);
                Know::Placed
            }
            _ => Know::Oriented,
        };
        self.set(body, next);
    }

    /// When no closed-form fragment applies: the smallest set of unplaced
    /// bodies that is rigid against the placed ones (grown from each seed,
    /// adding the neighbour that removes the most freedom), or all of them
    /// when none is (an under-constrained mechanism, solved by minimum-norm
    /// steps), placed together by Newton–Raphson.
    fn cluster_rule(&mut self) -> bool {
        let unplaced: Vec<BodyId> = (0..self.m.bodies.len()).filter(|&b| !self.placed(b)).collect();
        if unplaced.is_empty() {
            return false;
        }
        // A cluster knows no gear pair: with one still unplanned, its bodies
        // would be placed as if it were not there. The plan stops instead,
        // and says which pair it could not set in closed form.
        if self.geared.iter().any(|&g| !g) {
            return false;
        }
        let mut best: Option<Vec<BodyId>> = None;
        let mut in_s = vec![false; self.know.len()];
        for &seed in &unplaced {
            let mut s = vec![seed];
            in_s[seed] = true;
            let mut freedom = self.freedom_added(seed, &in_s);
            // Unplaced bodies sharing an unused equation with `s`, in body
            // order (the first of equally good ones is taken).
            let mut neighbours = BTreeSet::new();
            self.add_neighbours(seed, &in_s, &mut neighbours);
            while freedom > 0 {
                // Growing on cannot give a smaller rigid set than the best.
                if best.as_ref().is_some_and(|b| s.len() >= b.len()) {
                    break;
                }
                let mut next: Option<(BodyId, i64)> = None;
                for &b in &neighbours {
                    let f = self.freedom_added(b, &in_s);
                    if next.is_none_or(|(_, g)| f < g) {
                        next = Some((b, f));
                    }
                }
                let Some((b, f)) = next else { break };
                neighbours.remove(&b);
                s.push(b);
                in_s[b] = true;
                freedom += f;
                self.add_neighbours(b, &in_s, &mut neighbours);
            }
            for &b in &s {
                in_s[b] = false;
            }
            if freedom <= 0 && best.as_ref().is_none_or(|b| s.len() < b.len()) {
                best = Some(s);
            }
        }
        let mut s = best.unwrap_or(unplaced);
        s.sort_unstable();
        let eqs = self.cluster_equations(&s);
        let mut serves = Vec::new();
        for b in &s {
            serves.append(&mut self.pending[*b]);
        }
        let (params, hinged) = self.cluster_params(&s, &eqs);
        let rows = eqs
            .iter()
            .zip(&hinged)
            .filter(|(_, &h)| !h)
            .map(|(&i, _)| self.eqs[i].eq.row())
            .collect();
        for &i in &eqs {
            serves.push(self.consume(i));
        }
        let index = self.clusters;
        self.clusters += 1;
        serves.dedup();
        self.steps.push(Step {
            kind: StepKind::Cluster { index, params, rows },
            serves,
        });
        for b in s {
            self.set(b, Know::Placed);
        }
        true
    }

    /// Adds to `neighbours` the unplaced bodies outside the cluster (`in_s`)
    /// that share an unused equation with its body `b`.
    fn add_neighbours(&self, b: BodyId, in_s: &[bool], neighbours: &mut BTreeSet<BodyId>) {
        for &i in &self.on[b] {
            if !self.used[i] {
                for x in self.eqs[i].eq.bodies() {
                    if !in_s[x] && !self.placed(x) {
                        neighbours.insert(x);
                    }
                }
            }
        }
    }

    /// RRP: a pinned body (its marker `pin` at `at`) and a sliding body
    /// whose markers meet where the circle the pinned one's draws crosses
    /// the sliding one's line (along `dir`).
    fn pinned_sliding(
        &mut self,
        i: usize,
        pin: Point,
        at: PointRef,
        pinned: &End,
        sliding: &End,
        dir: DirRef,
    ) {
        let line = Line {
            through: moving_marker(sliding),
            dir,
        };
        let x = self.circle_line_place(i, pin, at, pinned, line);
        self.push(
            StepKind::Anchor {
                body: sliding.body,
                local: sliding.local,
                at: x,
            },
            vec![],
        );
    }
}
