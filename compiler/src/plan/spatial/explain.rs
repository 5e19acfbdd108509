//! One-line explanations of spatial steps, derived from the plan IR as the
//! planar ones are (`plan/planar/explain.rs`): what a step moves, by which
//! action or from which loci, on which branch. The planner writes none of
//! them, so an explanation can never disagree with the step it explains.
//!
//! Points and directions are named the way the file names them: a body's
//! point by its marker (`coupler.B`), a body's direction by the marker axis
//! it is (`rocker.D z`), a pseudo-marker by the step that computes it
//! (`step 2 (rocker.C)`); what no marker names is given by coordinates.

use dofplan_runtime::spatial::{circle_about, circle_circle_candidates, norm, sub, unit, Circle, Vec3};

use super::{Action, Cluster, ClusterRow, DirRef, HingeTurn, Locus, Plan, PointRef, StepKind};
use crate::plan::explain::{header, step_line};
use crate::plan::num;

/// Coordinates for people: `[0, 0.5, 2]`.
fn coords(v: Vec3) -> String {
    format!("[{}, {}, {}]", num(v[0]), num(v[1]), num(v[2]))
}

/// Whether two drawn vectors are the same (relative 1e-12).
fn same(a: Vec3, b: Vec3) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-12 * (1.0 + a[k].abs().max(b[k].abs())))
}

/// Degrees for people from a cosine.
fn degrees(cos: f64) -> String {
    num(cos.clamp(-1.0, 1.0).acos().to_degrees())
}

impl Plan {
    /// The one-line explanation of step `i` (numbered from 0).
    pub fn explain(&self, i: usize) -> String {
        match &self.steps[i].kind {
            StepKind::Act { body, action } => {
                format!("{}: {}", self.bodies[*body], self.action_text(*body, action))
            }
            StepKind::Intersect {
                temp, loci, branch, ..
            } => {
                let [a, b] = loci.as_ref();
                let root = match branch {
                    Some(slot) => format!(", branch slot {slot}"),
                    None => match self.single_root_miss(i) {
                        Some(miss) => format!(", one valid root (the other misses by {})", num(miss)),
                        None => String::new(),
                    },
                };
                format!(
                    "{}: {} ∩ {}{root}",
                    self.temps[*temp].name,
                    self.locus_name(a),
                    self.locus_name(b)
                )
            }
            StepKind::IntersectDir {
                temps, cones, branch, ..
            } => {
                let [(w1, cos1), (w2, cos2)] = cones.as_ref();
                format!(
                    "{}, {}: cone of {}° about {} ∩ cone of {}° about {}, branch slot {branch}",
                    self.temps[temps[0]].name,
                    self.temps[temps[1]].name,
                    degrees(*cos1),
                    self.dir_name(w1),
                    degrees(*cos2),
                    self.dir_name(w2)
                )
            }
            StepKind::Check { rows } => {
                let names: Vec<&str> = rows.iter().map(|r| r.name.as_str()).collect();
                let redundant: usize = rows.iter().map(|r| r.redundant).sum();
                if redundant > 0 {
                    format!(
                        "check {} ({redundant} row{}) [redundant]",
                        names.join(", "),
                        if redundant == 1 { "" } else { "s" }
                    )
                } else {
                    format!("check {}", names.join(", "))
                }
            }
            StepKind::Cluster(c) => self.cluster_text(c),
        }
    }

    /// Every step's line of `dofplan plan`.
    pub fn explanations(&self) -> Vec<String> {
        (0..self.steps.len()).map(|i| self.explain(i)).collect()
    }

    /// The plan as `dofplan plan` prints it, in the planar plan's layout:
    /// a header, then one line a step numbered from 0 (the number its
    /// explanations cite; a break's runtime id is one more, see
    /// [`super::step_number`]), then the idle freedoms.
    pub fn explain_all(&self) -> String {
        let mut out = header(
            &self.name,
            &self.source,
            self.steps.len(),
            self.branches.len(),
            self.inputs
                .iter()
                .map(String::as_str)
                .zip(self.input_kinds.iter().copied()),
        );
        for (i, s) in self.steps.iter().enumerate() {
            out.push_str(&step_line(i, &self.explain(i), &s.serves));
        }
        for (b, dof, why) in &self.idle {
            out.push_str(&format!(
                "      idle: {} keeps {dof} freedom{} at minimum motion ({why})\n",
                self.bodies[*b],
                if *dof == 1 { "" } else { "s" }
            ));
        }
        out
    }

    /// What an action does to its body, after "body: ".
    fn action_text(&self, body: usize, action: &Action) -> String {
        let p = |q: &PointRef| self.point_name(q);
        let d = |v: &DirRef| self.dir_name(v);
        match action {
            Action::TranslateOnto { from, to } => format!("translate {} onto {}", p(from), p(to)),
            Action::TranslateAlong { from, to, dir } => {
                format!("slide along {} until {} meets {}", d(dir), p(from), p(to))
            }
            Action::TranslateInPlane { from, to, normal } => {
                format!("translate across {}, {} onto {}", d(normal), p(from), p(to))
            }
            Action::TranslateToLine { from, through, dir } => format!(
                "translate {} onto the line through {} along {}",
                p(from),
                p(through),
                d(dir)
            ),
            Action::TranslateToPlane {
                from,
                through,
                normal,
            } => format!(
                "translate {} onto the plane through {} across {}",
                p(from),
                p(through),
                d(normal)
            ),
            Action::SlideTo { dir, input, .. } => {
                format!("slide along {} by input {}", d(dir), self.inputs[*input])
            }
            Action::RotateOnto { pivot, from, to } => {
                format!("rotate about {} taking {} onto {}", p(pivot), p(from), p(to))
            }
            Action::AlignDir { pivot, from, to } => {
                format!("rotate about {} aligning {} with {}", p(pivot), d(from), d(to))
            }
            Action::AxisOnto {
                pivot,
                axis,
                from,
                to,
            } => format!(
                "turn about {} through {} taking {} onto {}",
                d(axis),
                p(pivot),
                p(from),
                p(to)
            ),
            Action::AxisDir {
                pivot,
                axis,
                from,
                to,
            } => format!(
                "turn about {} through {} aligning {} with {}",
                d(axis),
                p(pivot),
                d(from),
                d(to)
            ),
            Action::Twist {
                axis, input, angle, ..
            } => match input {
                Some(k) => format!("turn about {} by input {}", d(axis), self.inputs[*k]),
                None => format!(
                    "turn about {} to the twist of {}°",
                    d(axis),
                    num(angle.to_degrees())
                ),
            },
            Action::AxisCondition {
                pivot,
                axis,
                v,
                w,
                cos,
                branch,
            } => format!(
                "turn about {} through {} until {} is at {}° to {}, branch slot {branch}",
                d(axis),
                p(pivot),
                d(v),
                degrees(*cos),
                d(w)
            ),
            Action::Hinge { pivot, axis, turn } => {
                let how = match turn {
                    HingeTurn::Degrees { input: Some(k), .. } => format!("by input {}", self.inputs[*k]),
                    HingeTurn::Degrees {
                        input: None, offset, ..
                    } => format!("by {}°", num(*offset)),
                    HingeTurn::Onto { from, to } => format!(
                        "taking {} onto {}",
                        self.point_name(&PointRef::Body { body, local: *from }),
                        p(to)
                    ),
                    HingeTurn::Dir { from, to } => format!(
                        "aligning {} with {}",
                        self.dir_name(&DirRef::Body { body, local: *from }),
                        d(to)
                    ),
                };
                format!(
                    "turn on its fixed hinge {how}, set outright ({} along {})",
                    coords(*pivot),
                    coords(*axis)
                )
            }
            Action::Tilt { pivot, from, to, cos } => format!(
                "tilt {} about {} to {}° from {} (a cone)",
                d(from),
                p(pivot),
                degrees(*cos),
                d(to)
            ),
        }
    }

    /// A numeric cluster: its bodies and size; a drag's names the pinned
    /// marker.
    fn cluster_text(&self, c: &Cluster) -> String {
        let names: Vec<&str> = c.params.iter().map(|p| self.bodies[p.body()].as_str()).collect();
        let pinned = c.rows.iter().find_map(|r| match r {
            ClusterRow::Pin { name, .. } => Some(name.as_str()),
            _ => None,
        });
        match pinned {
            Some(name) => format!(
                "drag {name}: {} free, {name} pinned to the target ({} unknowns, {} equations)",
                names.join(", "),
                c.unknowns(),
                c.equations()
            ),
            None => format!(
                "numeric cluster: {} ({} unknowns, {} equations), Newton-Raphson",
                names.join(", "),
                c.unknowns(),
                c.equations()
            ),
        }
    }

    /// A locus as a person says it, with its radius as drawn (the plan
    /// may carry a radius as two constant points).
    fn locus_name(&self, l: &Locus) -> String {
        match l {
            Locus::Circle { pivot, axis, at } => {
                let (_, _, r) = circle_about(
                    self.drawn_point(pivot),
                    self.drawn_dir(axis),
                    self.drawn_point(at),
                );
                format!(
                    "circle of radius {} about {} through {}",
                    num(r),
                    self.dir_name(axis),
                    self.point_name(pivot)
                )
            }
            Locus::Sphere { centre, a, b } => format!(
                "sphere of radius {} about {}",
                num(norm(sub(self.drawn_point(a), self.drawn_point(b)))),
                self.point_name(centre)
            ),
            Locus::Line { at, dir } => {
                format!(
                    "line through {} along {}",
                    self.point_name(at),
                    self.dir_name(dir)
                )
            }
        }
    }

    /// The name of a point as the file names it.
    pub fn point_name(&self, p: &PointRef) -> String {
        match p {
            PointRef::Fixed(v) => self.fixed_marker(*v).unwrap_or_else(|| coords(*v)),
            PointRef::Body { body, local } => self.marker_at(*body, *local),
            PointRef::Slid {
                body,
                local,
                input,
                sign,
                ..
            } => format!(
                "{} {} {}",
                self.marker_at(*body, *local),
                if *sign > 0.0 { "+" } else { "-" },
                self.inputs[*input]
            ),
            PointRef::Temp(t) => self.temp_name(*t),
        }
    }

    /// The name of a direction as the file names it: a marker's axis.
    pub fn dir_name(&self, d: &DirRef) -> String {
        match d {
            // By coordinates: several fixed markers often share an axis.
            DirRef::Fixed(v) => coords(*v),
            DirRef::Body { body, local } => self
                .axis_of(*body, *local)
                .unwrap_or_else(|| format!("{} {}", self.bodies[*body], coords(*local))),
            DirRef::Between(a, b) => format!("{}–{}", self.point_name(a), self.point_name(b)),
            DirRef::Temp(t) => self.temp_name(*t),
        }
    }

    /// "step 2 (rocker.C)": a pseudo-marker by the step computing it.
    fn temp_name(&self, t: usize) -> String {
        let producer = self.steps.iter().position(|s| match &s.kind {
            StepKind::Intersect { temp, .. } => *temp == t,
            StepKind::IntersectDir { temps, .. } => temps.contains(&t),
            _ => false,
        });
        match producer {
            Some(k) => format!("step {k} ({})", self.temps[t].name),
            None => self.temps[t].name.clone(),
        }
    }

    /// "body.marker" of the marker of `body` at `local` (the first when
    /// several share it), or "a point of body".
    fn marker_at(&self, body: usize, local: Vec3) -> String {
        match self.markers[body].iter().find(|(_, at)| same(*at, local)) {
            Some((m, _)) => format!("{}.{m}", self.bodies[body]),
            None => format!("a point of {}", self.bodies[body]),
        }
    }

    /// The marker at world `v` of a fixed body (fixed bodies stay as
    /// drawn). A constant point of a moving body (a hinged body's point on
    /// its line) is given by its coordinates: several bodies' markers may
    /// be drawn there.
    fn fixed_marker(&self, v: Vec3) -> Option<String> {
        self.fixed_bodies().find_map(|b| {
            (self.markers[b].iter())
                .find(|(_, at)| same(*at, v))
                .map(|(m, _)| format!("{}.{m}", self.bodies[b]))
        })
    }

    /// "body.marker z" (or x) of the marker axis of `body` along `local`.
    fn axis_of(&self, body: usize, local: Vec3) -> Option<String> {
        let axes = self.axes.get(body)?;
        (self.markers[body].iter().zip(axes)).find_map(|((m, _), axes)| {
            let [z, x] = (*axes)?;
            if same(z, local) {
                Some(format!("{}.{m} z", self.bodies[body]))
            } else if same(x, local) {
                Some(format!("{}.{m} x", self.bodies[body]))
            } else {
                None
            }
        })
    }

    /// The fixed bodies' indices.
    fn fixed_bodies(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.bodies.len()).filter(|&b| self.fixed[b])
    }

    /// Where step `i` intersects two circles in different planes and only
    /// one candidate is valid in the drawn pose (a Bennett linkage's skew
    /// circles; analysis then keeps no branch): the other candidate's miss,
    /// evaluated on the drawing (every body as drawn, inputs 0).
    pub(crate) fn single_root_miss(&self, i: usize) -> Option<f64> {
        let StepKind::Intersect { loci, tol, .. } = &self.steps[i].kind else {
            return None;
        };
        let [Locus::Circle { pivot, axis, at }, Locus::Circle {
            pivot: p2,
            axis: a2,
            at: x2,
        }] = loci.as_ref()
        else {
            return None;
        };
        let (c1, n1, r1) = circle_about(
            self.drawn_point(pivot),
            self.drawn_dir(axis),
            self.drawn_point(at),
        );
        let (c2, n2, r2) = circle_about(self.drawn_point(p2), self.drawn_dir(a2), self.drawn_point(x2));
        let cand = circle_circle_candidates(Circle::new(c1, n1, r1), Circle::new(c2, n2, r2), *tol);
        (!cand.coplanar && cand.count() == 1).then(|| {
            if cand.passes[0] {
                cand.misses[1]
            } else {
                cand.misses[0]
            }
        })
    }

    /// A point as drawn: bodies at their drawn poses (local = drawn), slides
    /// at 0, pseudo-markers where they are drawn.
    fn drawn_point(&self, p: &PointRef) -> Vec3 {
        match p {
            PointRef::Fixed(v) => *v,
            PointRef::Body { local, .. } | PointRef::Slid { local, .. } => *local,
            PointRef::Temp(t) => self.temps[*t].drawn,
        }
    }

    /// A direction as drawn.
    fn drawn_dir(&self, d: &DirRef) -> Vec3 {
        match d {
            DirRef::Fixed(v) | DirRef::Body { local: v, .. } => *v,
            DirRef::Between(a, b) => unit(sub(self.drawn_point(b), self.drawn_point(a))),
            DirRef::Temp(t) => self.temps[*t].drawn,
        }
    }
}
