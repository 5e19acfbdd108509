//! What an expression becomes, before any text is written: bodies with
//! their markers, joints, offset constraints and inputs, each remembering
//! the point it came from so the file's header can say how names map.

use std::collections::{HashMap, HashSet};

use super::{error, error_with, Expression, InputPair, JointType, Point};
use crate::model::source::Span;
use crate::model::ModelError;

/// The fixed frame's name in Pyslvs (`VLink.FRAME`).
pub(super) const GROUND: &str = "ground";

/// Bodies (ground first, then the links in order of first mention, then
/// slider blocks), joints, constraints and inputs.
pub(super) struct Layout {
    pub bodies: Vec<Body>,
    pub joints: Vec<Joint>,
    pub offsets: Vec<Offset>,
    pub inputs: Vec<Input>,
    /// `(body, point)` of the points on one mobile link and no joint.
    pub trace: Vec<(usize, usize)>,
    /// Per point, what it became, for the header.
    pub roles: Vec<String>,
    /// Body by name.
    index: HashMap<String, usize>,
    /// The names of joints and constraints (one namespace in dofplan).
    taken: HashSet<String>,
}

/// A body to write.
pub(super) struct Body {
    pub name: String,
    pub fixed: bool,
    pub markers: Vec<Marker>,
    /// Where the link is first mentioned (`None` for a slider block).
    pub first: Option<Span>,
}

/// A marker, named after its point (`P3`).
pub(super) struct Marker {
    pub point: usize,
    pub at: [f64; 2],
    pub dir: Option<[f64; 2]>,
}

/// A joint between the markers of point `point` on bodies `ends`.
pub(super) struct Joint {
    pub name: String,
    pub prismatic: bool,
    pub ends: [usize; 2],
    pub point: usize,
}

/// An offset constraint (the angle between two markers' directions kept as
/// drawn) between the markers of point `point` on bodies `ends`.
pub(super) struct Offset {
    pub name: String,
    pub ends: [usize; 2],
    pub point: usize,
}

/// An input on joint `joint`.
pub(super) struct Input {
    pub name: String,
    pub joint: usize,
    pub slide: bool,
    /// The pair it came from.
    pub pair: (usize, usize),
    /// What it drives, for the header.
    pub about: String,
}

/// Lays `expr` out, with `pairs` as its inputs.
pub(super) fn build(expr: &Expression, pairs: &[InputPair]) -> Result<Layout, ModelError> {
    let bodies = links(expr)?;
    let index = (bodies.iter().enumerate())
        .map(|(i, b)| (b.name.clone(), i))
        .collect();
    let mut l = Layout {
        bodies,
        joints: Vec::new(),
        offsets: Vec::new(),
        inputs: Vec::new(),
        trace: Vec::new(),
        roles: Vec::new(),
        index,
        taken: HashSet::new(),
    };
    for p in &expr.points {
        let on: Vec<usize> = p.links.iter().map(|(n, _)| l.body(n)).collect();
        let role = match (p.kind, on.len()) {
            (_, 1) => l.single(p, on[0]),
            (JointType::R, _) => l.revolute(p, &on),
            (JointType::P, _) => l.prismatic(p, &on),
            (JointType::RP, _) => l.slot(p, &on),
        };
        l.roles.push(role);
    }
    l.joined(expr)?;
    for pair in pairs {
        let input = l.input(expr, pair)?;
        if let Some(other) = l.inputs.iter().find(|i| i.joint == input.joint) {
            let joint = &l.joints[input.joint].name;
            return Err(pair_error(
                expr,
                pair,
                format!(
                    "input pairs ({}, {}) and ({}, {}) both drive joint {joint}",
                    other.pair.0, other.pair.1, pair.base, pair.drive
                ),
                "a joint takes one input: remove one of the pairs",
            ));
        }
        l.inputs.push(input);
    }
    Ok(l)
}

/// Ground, then every other link in order of first mention. The ground is
/// the one body dofplan must have fixed, so an expression without it has
/// nothing to stand on.
fn links(expr: &Expression) -> Result<Vec<Body>, ModelError> {
    let body = |name: &str, first: &Span| Body {
        name: name.to_string(),
        fixed: name == GROUND,
        markers: Vec::new(),
        first: Some(first.clone()),
    };
    let mut bodies: Vec<Body> = Vec::new();
    let mut seen: HashSet<&str> = HashSet::new();
    let all = expr.points.iter().flat_map(|p| &p.links);
    if let Some((name, first)) = all.clone().find(|(n, _)| n == GROUND) {
        bodies.push(body(name, first));
        seen.insert(GROUND);
    } else {
        return Err(error(
            &expr.file,
            expr.span.clone(),
            "no point is on `ground`: the mechanism has no fixed frame".into(),
            Some("list `ground` among the links of the points fixed to the frame, e.g. `J[R, P[0, 0], L[ground, L1]]`".into()),
        ));
    }
    for (name, first) in all {
        if seen.insert(name) {
            bodies.push(body(name, first));
        }
    }
    Ok(bodies)
}

/// `(x, y)` of `degrees`, exact on the axes (so `A[90]` writes `[0, 1]`).
pub(super) fn direction(degrees: f64) -> [f64; 2] {
    let (s, c) = degrees.to_radians().sin_cos();
    let snap = |v: f64| {
        if v.abs() < 1e-15 {
            0.0
        } else if (v.abs() - 1.0).abs() < 1e-15 {
            v.signum()
        } else {
            v
        }
    };
    [snap(c), snap(s)]
}

impl Layout {
    /// Puts point `p` as a marker on body `body`.
    fn mark(&mut self, body: usize, p: &Point, dir: Option<[f64; 2]>) {
        self.bodies[body].markers.push(Marker {
            point: p.index,
            at: p.at,
            dir,
        });
    }

    /// `want`, or `want_2`, `want_3`, … if a joint or constraint has it
    /// (they share one namespace): derived names may meet link names.
    fn joint_name(&mut self, want: String) -> String {
        let name = unique(want, |n| self.taken.contains(n));
        self.taken.insert(name.clone());
        name
    }

    fn join(&mut self, name: String, prismatic: bool, ends: [usize; 2], point: usize) -> String {
        let name = self.joint_name(name);
        self.joints.push(Joint {
            name: name.clone(),
            prismatic,
            ends,
            point,
        });
        name
    }

    /// A point on one link: a point of it, traced if the link moves.
    fn single(&mut self, p: &Point, body: usize) -> String {
        self.mark(body, p, p.angle.map(direction));
        let name = &self.bodies[body].name;
        if self.bodies[body].fixed {
            format!("a point of {name}")
        } else {
            let role = format!("a point of {name} (traced)");
            self.trace.push((body, p.index));
            role
        }
    }

    /// An R point: one revolute joint from its hub to each other link. The
    /// hub is ground when the point is on it, so an input at a ground
    /// pivot is relative to the ground as Pyslvs's angles are.
    fn revolute(&mut self, p: &Point, on: &[usize]) -> String {
        let hub = if on.contains(&0) { 0 } else { on[0] };
        let mut made = Vec::new();
        for &body in on {
            self.mark(body, p, None);
            if body == hub {
                continue;
            }
            let name = if on.len() == 2 {
                p.name()
            } else {
                format!("{}_{}", p.name(), self.bodies[body].name)
            };
            let name = self.join(name, false, [hub, body], p.index);
            made.push(format!(
                "{name} ({}–{})",
                self.bodies[hub].name, self.bodies[body].name
            ));
        }
        let joints = if made.len() == 1 { "joint" } else { "joints" };
        format!("revolute {joints} {}", made.join(", "))
    }

    /// A P point: the first pinned link slides in the slot; any other
    /// pinned link is held to the first by a revolute joint and an offset
    /// constraint (Pyslvs moves them together without turning).
    fn prismatic(&mut self, p: &Point, on: &[usize]) -> String {
        let dir = direction(p.angle.unwrap_or(0.0));
        let (slot, pins) = (on[0], &on[1..]);
        self.mark(slot, p, Some(dir));
        // The offset constraint compares directions: only then do the
        // pinned markers need one.
        let pin_dir = (pins.len() > 1).then_some(dir);
        for &pin in pins {
            self.mark(pin, p, pin_dir);
        }
        let name = if pins.len() == 1 {
            p.name()
        } else {
            format!("{}_{}", p.name(), self.bodies[pins[0]].name)
        };
        let name = self.join(name, true, [slot, pins[0]], p.index);
        let mut role = format!(
            "prismatic joint {name}: {} slides in {}'s slot",
            self.bodies[pins[0]].name, self.bodies[slot].name
        );
        for &pin in &pins[1..] {
            let link = self.bodies[pin].name.clone();
            let joint = self.join(format!("{}_{link}", p.name()), false, [pins[0], pin], p.index);
            let offset = self.joint_name(format!("{}_{link}_angle", p.name()));
            self.offsets.push(Offset {
                name: offset.clone(),
                ends: [pins[0], pin],
                point: p.index,
            });
            role.push_str(&format!(
                "; {link} moves with {} (revolute joint {joint}, offset constraint {offset})",
                self.bodies[pins[0]].name
            ));
        }
        role
    }

    /// An RP point: a slider block, a body of its own, slides in the slot
    /// and every pinned link turns on it (dofplan has no pin-in-slot joint).
    fn slot(&mut self, p: &Point, on: &[usize]) -> String {
        let (slot, pins) = (on[0], &on[1..]);
        self.mark(slot, p, Some(direction(p.angle.unwrap_or(0.0))));
        let block = unique(format!("{}_block", p.name()), |n| self.index.contains_key(n));
        self.index.insert(block.clone(), self.bodies.len());
        self.bodies.push(Body {
            name: block.clone(),
            fixed: false,
            markers: Vec::new(),
            first: None,
        });
        let b = self.bodies.len() - 1;
        self.mark(b, p, None);
        let prismatic = self.join(p.name(), true, [slot, b], p.index);
        let mut turns = Vec::new();
        for &pin in pins {
            self.mark(pin, p, None);
            let link = self.bodies[pin].name.clone();
            let joint = self.join(format!("{}_{link}", p.name()), false, [b, pin], p.index);
            turns.push(format!("{link} (revolute joint {joint})"));
        }
        format!(
            "slider block {block} slides in {}'s slot (prismatic joint {prismatic}); on it turns {}",
            self.bodies[slot].name,
            turns.join(", ")
        )
    }

    /// Every link takes part in a joint: one that does not would float
    /// free, three freedoms no input drives.
    fn joined(&self, expr: &Expression) -> Result<(), ModelError> {
        let joined: HashSet<usize> = self.joints.iter().flat_map(|j| j.ends).collect();
        for (i, body) in self.bodies.iter().enumerate().skip(1) {
            let Some(first) = &body.first else { continue };
            if !joined.contains(&i) {
                let points: Vec<String> = body.markers.iter().map(|m| format!("P{}", m.point)).collect();
                return Err(error(
                    &expr.file,
                    first.clone(),
                    format!(
                        "link {} is joined to nothing: it is only on {}, with no other link",
                        body.name,
                        points.join(", ")
                    ),
                    Some(format!(
                        "a link moves with the mechanism through the points it shares with other links: add {} to one of them, or remove it",
                        body.name
                    )),
                ));
            }
        }
        Ok(())
    }
}

/// `want`, or `want_2`, `want_3`, … the first that is not `taken`.
fn unique(want: String, taken: impl Fn(&str) -> bool) -> String {
    if !taken(&want) {
        return want;
    }
    (2..)
        .map(|k| format!("{want}_{k}"))
        .find(|n| !taken(n))
        .unwrap_or(want)
}

/// An error about an input pair: at the pair where it is written, else at
/// its base point, else at the whole expression.
fn pair_error(expr: &Expression, pair: &InputPair, message: String, help: &str) -> ModelError {
    pair_error_with(expr, pair, message, Vec::new(), help)
}

/// [`pair_error`] with the pair's two points pointed at as well, for an
/// error about the links they are on.
fn points_error(expr: &Expression, pair: &InputPair, message: String, help: &str) -> ModelError {
    let notes = [pair.base, pair.drive].map(|k| {
        let p = &expr.points[k];
        let links: Vec<&str> = p.links.iter().map(|(n, _)| n.as_str()).collect();
        (p.span.clone(), format!("P{k} is on {}", links.join(", ")))
    });
    pair_error_with(expr, pair, message, notes.to_vec(), help)
}

fn pair_error_with(
    expr: &Expression,
    pair: &InputPair,
    message: String,
    notes: Vec<(Span, String)>,
    help: &str,
) -> ModelError {
    let span = (pair.span.clone())
        .or_else(|| expr.points.get(pair.base).map(|p| p.span.clone()))
        .unwrap_or_else(|| expr.span.clone());
    error_with(&expr.file, span, message, notes, Some(help.into()))
}

impl Layout {
    /// The input of `pair`, or why dofplan cannot drive it.
    fn input(&mut self, expr: &Expression, pair: &InputPair) -> Result<Input, ModelError> {
        let n = expr.points.len();
        for k in [pair.base, pair.drive] {
            if k >= n {
                let have = match n {
                    0 => "no points".to_string(),
                    1 => "one point, P0".to_string(),
                    _ => format!("{n} points, P0 to P{}", n - 1),
                };
                return Err(pair_error(
                    expr,
                    pair,
                    format!(
                        "input pair ({}, {}): there is no point P{k} (the expression has {have})",
                        pair.base, pair.drive
                    ),
                    "points are numbered from 0 in the order they are written",
                ));
            }
        }
        if pair.base == pair.drive {
            self.slide_input(expr, pair)
        } else {
            self.turn_input(expr, pair)
        }
    }

    /// `(b, b)`: the slide of the P or RP point `b`.
    fn slide_input(&self, expr: &Expression, pair: &InputPair) -> Result<Input, ModelError> {
        let b = &expr.points[pair.base];
        let what = format!("input pair ({0}, {0})", b.index);
        if b.kind == JointType::R {
            return Err(pair_error(
                expr,
                pair,
                format!("{what} slides point P{} along its slot, but P{} is revolute (R)", b.index, b.index),
                "a pair of one point twice drives a P or RP point's slide; to turn a link about an R point, pair it with another point of that link, (base, drive)",
            ));
        }
        let Some(joint) = self.joints.iter().position(|j| j.point == b.index && j.prismatic) else {
            return Err(pair_error(
                expr,
                pair,
                format!(
                    "{what}: nothing slides in the slot of P{}, which is on {} only",
                    b.index, b.links[0].0
                ),
                "list the link that slides after the slot's link, e.g. `L[ground, L2]`",
            ));
        };
        let j = &self.joints[joint];
        Ok(Input {
            name: format!("{}_slide", b.name()),
            joint,
            slide: true,
            pair: (pair.base, pair.drive),
            about: format!(
                "slide of joint {}: {} moves along {}'s slot (A = {}°), from the drawn position (Pyslvs's offset)",
                j.name,
                self.bodies[j.ends[1]].name,
                self.bodies[j.ends[0]].name,
                crate::format::rounded(b.angle.unwrap_or(0.0), 6)
            ),
        })
    }

    /// `(b, d)`: the link both points are on turns about `b`.
    fn turn_input(&mut self, expr: &Expression, pair: &InputPair) -> Result<Input, ModelError> {
        let (b, d) = (&expr.points[pair.base], &expr.points[pair.drive]);
        let what = format!("input pair ({}, {})", b.index, d.index);
        if b.on(GROUND) && d.on(GROUND) {
            return Err(points_error(
                expr,
                pair,
                format!(
                    "{what}: P{} and P{} are both on ground, which never turns",
                    b.index, d.index
                ),
                "pair the base point with a point of the link to turn, e.g. the crank's other end",
            ));
        }
        let common: Vec<&str> = (b.links.iter())
            .map(|(n, _)| n.as_str())
            .filter(|n| d.on(n))
            .collect();
        let names = |p: &Point| {
            p.links
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let turned = match common.as_slice() {
            [one] => *one,
            [] => {
                return Err(points_error(
                    expr,
                    pair,
                    format!(
                        "{what}: P{} (on {}) and P{} (on {}) share no link, so the pair turns nothing",
                        b.index,
                        names(b),
                        d.index,
                        names(d)
                    ),
                    "an input pair turns the link that carries both of its points: pick a driving point on the link to turn",
                ))
            }
            several => {
                return Err(points_error(
                    expr,
                    pair,
                    format!("{what}: P{} and P{} are both on links {}, so which one turns is ambiguous", b.index, d.index, several.join(" and ")),
                    "links that share two points are one rigid link: merge them into one",
                ))
            }
        };
        let turned = self.body(turned);
        let (joint, base) = self.turn_joint(expr, pair, turned)?;
        // The driven link second: a positive angle turns it
        // counter-clockwise relative to the base, as Pyslvs's angle grows.
        if self.joints[joint].ends[1] == base {
            self.joints[joint].ends.swap(0, 1);
        }
        Ok(self.angle_input(b, d, joint, base, turned))
    }

    /// The revolute joint at the pair's base point that turns body
    /// `turned`, and the body it turns relative to.
    fn turn_joint(
        &self,
        expr: &Expression,
        pair: &InputPair,
        turned: usize,
    ) -> Result<(usize, usize), ModelError> {
        let b = &expr.points[pair.base];
        let at_b = |x: usize, y: usize| {
            self.joints.iter().position(|j| {
                j.point == b.index && !j.prismatic && j.ends.contains(&x) && j.ends.contains(&y)
            })
        };
        let name = &self.bodies[turned].name;
        let what = format!("input pair ({}, {})", pair.base, pair.drive);
        let found = match b.kind {
            JointType::P => None,
            JointType::R => {
                // Relative to the hub, or (when the turned link is the hub)
                // to the point's first other link.
                let other = (b.links.iter()).find_map(|(n, _)| (n != name).then(|| self.body(n)));
                let hub = if b.on(GROUND) { 0 } else { self.body(&b.links[0].0) };
                let base = if hub != turned { Some(hub) } else { other };
                base.and_then(|base| Some((at_b(base, turned)?, base)))
            }
            JointType::RP => {
                let block = self
                    .joints
                    .iter()
                    .find(|j| j.point == b.index && j.prismatic)
                    .map(|j| j.ends[1]);
                let pins: Vec<usize> = b.links[1..].iter().map(|(n, _)| self.body(n)).collect();
                block.and_then(|block| {
                    if pins.contains(&turned) {
                        Some((at_b(block, turned)?, block))
                    } else {
                        // The slot's link turns with its block, about a
                        // pinned link (ground if the slot is on it).
                        let base = if pins.contains(&0) { 0 } else { *pins.first()? };
                        Some((at_b(block, base)?, base))
                    }
                })
            }
        };
        found.ok_or_else(|| {
            let why = match b.kind {
                JointType::P => format!("P{} is a prismatic (P) joint, where no link turns", b.index),
                _ => format!("P{} joins {name} to no other link, so nothing turns it there", b.index),
            };
            pair_error(
                expr,
                pair,
                format!("{what} turns {name} about P{}, but {why}", b.index),
                "the base point of an input pair is a revolute (R) or RP point joining the turned link to another one (usually ground); a P or RP point's slide is the pair (b, b)",
            )
        })
    }

    /// The body of link `name` (the layout has every link).
    fn body(&self, name: &str) -> usize {
        self.index.get(name).copied().unwrap_or(0)
    }

    /// An angle input on `joint`, turning `turned` relative to `base`.
    fn angle_input(&self, b: &Point, d: &Point, joint: usize, base: usize, turned: usize) -> Input {
        let name = format!("{}_{}", b.name(), d.name());
        let drawn = (d.at[1] - b.at[1]).atan2(d.at[0] - b.at[0]).to_degrees();
        let drawn = crate::format::rounded(drawn, 6);
        let (base_name, turned_name) = (&self.bodies[base].name, &self.bodies[turned].name);
        let joint_name = &self.joints[joint].name;
        let moved = if self.joints[joint].ends[1] == turned {
            turned_name.clone()
        } else {
            format!(
                "{} (and {turned_name} with it)",
                self.bodies[self.joints[joint].ends[1]].name
            )
        };
        let pyslvs = if self.bodies[base].fixed {
            format!("Pyslvs's angle of {}→{} is {drawn}° + {name}", b.name(), d.name())
        } else {
            format!(
                "Pyslvs measures {}→{} from the x axis ({drawn}° as drawn): the two agree while {base_name} does not turn",
                b.name(),
                d.name()
            )
        };
        Input {
            name,
            joint,
            slide: false,
            pair: (b.index, d.index),
            about: format!(
                "angle of joint {joint_name}: {moved} turns counter-clockwise relative to {base_name}, from the drawn pose; {pyslvs}"
            ),
        }
    }
}
