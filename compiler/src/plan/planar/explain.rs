//! One-line explanations of steps, as TLA printed them: what is placed,
//! from which loci, on which branch.

use crate::plan::explain::{header, step_line};
use crate::plan::num;

use super::{ClusterParam, DirRef, Line, Plan, PointRef, Rel, StepKind};

fn pair(p: [f64; 2]) -> String {
    format!("({}, {})", num(p[0]), num(p[1]))
}

/// What explaining a step needs from the rest of the plan: which step
/// computes each temp, and whether a body is written again after a step.
/// Either looked up by scanning the steps (one explanation), or indexed
/// once (every explanation: linear in the plan's length).
enum Lookup {
    Scan,
    Index {
        /// Per temp: the step computing it.
        producer: Vec<Option<usize>>,
        /// Per body: the last step writing it.
        last_write: Vec<Option<usize>>,
    },
}

impl Lookup {
    fn index(plan: &Plan) -> Lookup {
        let mut producer = vec![None; plan.temps.len()];
        let mut last_write = vec![None; plan.bodies.len()];
        for (k, step) in plan.steps.iter().enumerate() {
            if let Some(out) = step.kind.computes() {
                producer[out].get_or_insert(k);
            }
            for b in step.kind.writes() {
                last_write[b] = Some(k);
            }
        }
        Lookup::Index { producer, last_write }
    }

    /// The (first) step computing temp `id`.
    fn producer(&self, plan: &Plan, id: usize) -> Option<usize> {
        match self {
            Lookup::Scan => plan.steps.iter().position(|s| s.kind.computes() == Some(id)),
            Lookup::Index { producer, .. } => producer.get(id).copied().flatten(),
        }
    }

    /// Whether a step after step `i` writes body `b`.
    fn written_after(&self, plan: &Plan, i: usize, b: usize) -> bool {
        match self {
            Lookup::Scan => plan.steps[i + 1..].iter().any(|s| s.kind.writes_body(b)),
            Lookup::Index { last_write, .. } => last_write[b].is_some_and(|k| k > i),
        }
    }
}

impl Plan {
    /// The name of a point as a person would say it.
    pub fn point_name(&self, p: &PointRef) -> String {
        self.point_name_in(p, &Lookup::Scan)
    }

    fn point_name_in(&self, p: &PointRef, lookup: &Lookup) -> String {
        match p {
            PointRef::Fixed { name, .. } | PointRef::Marker { name, .. } => name.clone(),
            PointRef::Slid {
                name, input, sign, ..
            } => {
                let op = if *sign > 0.0 { "+" } else { "-" };
                format!("{name} {op} {}", self.inputs[*input].name)
            }
            PointRef::Temp { id } => match lookup.producer(self, *id) {
                Some(k) => format!("{} (step {k})", self.temps[*id].name),
                None => self.temps[*id].name.clone(),
            },
        }
    }

    /// "body.marker" of the marker of `body` at `local` (the first one when
    /// several share the position), or the coordinates if none.
    pub fn local_name(&self, body: usize, local: [f64; 2]) -> String {
        let b = &self.bodies[body];
        b.markers
            .iter()
            .find(|(_, at)| {
                (at[0] - local[0]).abs() <= 1e-12 * (1.0 + at[0].abs())
                    && (at[1] - local[1]).abs() <= 1e-12 * (1.0 + at[1].abs())
            })
            .map_or_else(
                || format!("{} {}", b.name, pair(local)),
                |(n, _)| format!("{}.{n}", b.name),
            )
    }

    fn dir_name(&self, d: &DirRef) -> String {
        match d {
            DirRef::Fixed(v) => pair(*v),
            DirRef::Body { body, local } => format!("{} {}", self.bodies[*body].name, pair(*local)),
        }
    }

    /// The line of a geared step (a turn or a rack's shift).
    fn geared_line(&self, kind: &StepKind) -> String {
        match kind {
            StepKind::Turn { body: b, angle } => {
                format!(
                    "{}: rotation = {} degrees (geared)",
                    self.bodies[*b].name,
                    self.affine_name(angle)
                )
            }
            StepKind::Shift {
                body: b,
                local,
                carrier,
                at,
                dir,
                slide,
                ..
            } => format!(
                "{}: translate {} onto {}'s {} + ({}) along {} (driven by its pinion)",
                self.bodies[*b].name,
                self.local_name(*b, *local),
                self.bodies[*carrier].name,
                pair(*at),
                self.affine_name(slide),
                pair(*dir)
            ),
            _ => unreachable!("only geared steps"),
        }
    }

    /// `2·carrier − 1.5·sun`: an affine angle or slide in the inputs'
    /// names.
    fn affine_name(&self, a: &crate::plan::Affine) -> String {
        let mut out = String::new();
        for (k, &(input, c)) in a.terms.iter().enumerate() {
            let name = &self.inputs[input].name;
            let sign = if c < 0.0 {
                "−"
            } else if k > 0 {
                "+"
            } else {
                ""
            };
            let sep = if k > 0 { " " } else { "" };
            let space = if k > 0 { " " } else { "" };
            if c.abs() == 1.0 {
                out.push_str(&format!("{sep}{sign}{space}{name}"));
            } else {
                out.push_str(&format!("{sep}{sign}{space}{}·{name}", num(c.abs())));
            }
        }
        if a.constant != 0.0 || a.terms.is_empty() {
            let sign = if a.terms.is_empty() {
                if a.constant < 0.0 {
                    "−"
                } else {
                    ""
                }
            } else if a.constant < 0.0 {
                " − "
            } else {
                " + "
            };
            out.push_str(&format!("{sign}{}", num(a.constant.abs())));
        }
        out
    }

    fn line_name(&self, l: &Line, lookup: &Lookup) -> String {
        format!(
            "line through {} along {}",
            self.point_name_in(&l.through, lookup),
            self.dir_name(&l.dir)
        )
    }

    fn branch_symbol(&self, slot: usize) -> &'static str {
        self.branches[slot].initial.symbol()
    }

    /// The one-line explanation of step `i`.
    pub fn explain(&self, i: usize) -> String {
        self.explain_in(i, &Lookup::Scan)
    }

    /// The one-line explanations of every step, in order (linear in the
    /// plan's length, where calling [`Plan::explain`] for each step is not).
    pub fn explanations(&self) -> Vec<String> {
        let lookup = Lookup::index(self);
        (0..self.steps.len())
            .map(|i| self.explain_in(i, &lookup))
            .collect()
    }

    /// A slot's check: `crank.P within the slot of yoke.S, from -1 to 1
    /// along it`, or `… within the arc slot about lever.C, from -40° to
    /// 20° round it`.
    fn within_line(&self, kind: &StepKind, lookup: &Lookup) -> String {
        let StepKind::Within {
            at, pin, ends, arc, ..
        } = kind
        else {
            unreachable!("a slot's check")
        };
        let (pin, at) = (self.point_name_in(pin, lookup), self.point_name_in(at, lookup));
        let [lo, hi] = ends.map(num);
        match arc {
            false => format!("{pin} within the slot of {at}, from {lo} to {hi} along it"),
            true => format!("{pin} within the arc slot about {at}, from {lo}° to {hi}° round it"),
        }
    }

    fn explain_in(&self, i: usize, lookup: &Lookup) -> String {
        let body = |b: &usize| self.bodies[*b].name.as_str();
        match &self.steps[i].kind {
            StepKind::Orient { body: b, from, rel } => self.orient_line(*b, *from, rel),
            StepKind::Turn { .. } | StepKind::Shift { .. } => self.geared_line(&self.steps[i].kind),
            StepKind::Anchor { body: b, local, at } => {
                // An anchor followed by another write of the same body puts
                // it on its line locus for now (Kramer's 1-TDOF state).
                let provisional = lookup.written_after(self, i, *b);
                format!(
                    "{}: translate {} onto {}{}",
                    body(b),
                    self.local_name(*b, *local),
                    self.point_name_in(at, lookup),
                    if provisional {
                        " (for now: it slides along its line from there)"
                    } else {
                        ""
                    }
                )
            }
            StepKind::Align {
                body: b,
                p,
                p_at,
                q,
                q_at,
                redundant,
            } => format!(
                "{}: {} onto {}, {} toward {}{}",
                body(b),
                self.local_name(*b, *p),
                self.point_name_in(p_at, lookup),
                self.local_name(*b, *q),
                self.point_name_in(q_at, lookup),
                if *redundant {
                    " (redundant: the distance is checked)"
                } else {
                    ""
                }
            ),
            StepKind::CircleCircle {
                out,
                c1,
                r1,
                c2,
                r2,
                branch,
            } => format!(
                "{}: circle about {} r={} ∩ circle about {} r={}, branch {}",
                self.temps[*out].name,
                self.point_name_in(c1, lookup),
                num(*r1),
                self.point_name_in(c2, lookup),
                num(*r2),
                self.branch_symbol(*branch)
            ),
            StepKind::CircleLine {
                out,
                c,
                r,
                line,
                branch,
            } => format!(
                "{}: circle about {} r={} ∩ {}, branch {}",
                self.temps[*out].name,
                self.point_name_in(c, lookup),
                num(*r),
                self.line_name(line, lookup),
                self.branch_symbol(*branch)
            ),
            StepKind::Within { .. } => self.within_line(&self.steps[i].kind, lookup),
            StepKind::LineLine { out, a, b } => format!(
                "{}: {} ∩ {}",
                self.temps[*out].name,
                self.line_name(a, lookup),
                self.line_name(b, lookup)
            ),
            StepKind::Cluster { index, params, .. } => {
                let (u, e) = self.steps[i].kind.cluster_size();
                let bodies: Vec<String> = params.iter().map(|p| self.param_name(p, lookup)).collect();
                format!(
                    "cluster {index}: {} by Newton–Raphson, {u} unknowns, {e} equations",
                    bodies.join(", ")
                )
            }
            StepKind::TurnLine {
                body: b,
                pivot,
                target,
                dir,
                kappa,
                branch,
            } => format!(
                "{}: turn about {} until its line along {} passes {} at offset {}, branch {}",
                body(b),
                self.point_name_in(pivot, lookup),
                pair(*dir),
                self.point_name_in(target, lookup),
                num(*kappa),
                self.branch_symbol(*branch)
            ),
        }
    }

    /// The explanation of an orient step: whose rotation body `b` takes,
    /// and the input that turns it from there, if any.
    fn orient_line(&self, b: usize, from: Option<usize>, rel: &Rel) -> String {
        let body = |b: &usize| self.bodies[*b].name.as_str();
        match rel {
            Rel::Identity => format!(
                "{}: rotation of {}",
                body(&b),
                from.as_ref().map_or("the ground", body)
            ),
            Rel::Input { input, inverse } => format!(
                "{}: rotation of {} {} input {}",
                body(&b),
                from.as_ref().map_or("the ground", body),
                if *inverse { "minus" } else { "plus" },
                self.inputs[*input].name
            ),
        }
    }

    /// A cluster's unknown as its explanation names it: the body, and what
    /// of its pose the unknown is.
    fn param_name(&self, p: &ClusterParam, lookup: &Lookup) -> String {
        let body = |b: &usize| self.bodies[*b].name.as_str();
        match p {
            ClusterParam::Free { body: b } => format!("{} (free)", body(b)),
            ClusterParam::Angle { body: b, at, .. } => {
                format!("{} (angle about {})", body(b), self.point_name_in(at, lookup))
            }
            ClusterParam::Hinge { body: b, name, .. } => {
                format!("{} (angle about {name})", body(b))
            }
            ClusterParam::Slide { body: b, dir } => {
                format!("{} (slide along {})", body(b), self.dir_name(dir))
            }
            ClusterParam::Translate { body: b } => format!("{} (translation)", body(b)),
        }
    }

    /// The whole plan, one numbered line per step, as `dofplan plan` prints
    /// it.
    pub fn explain_all(&self) -> String {
        let mut out = header(
            &self.mechanism,
            &self.source,
            self.steps.len(),
            self.branches.len(),
            self.inputs.iter().map(|i| (i.name.as_str(), i.kind)),
        );
        for (i, (step, line)) in self.steps.iter().zip(self.explanations()).enumerate() {
            out.push_str(&step_line(i, &line, &step.serves));
        }
        out
    }
}
