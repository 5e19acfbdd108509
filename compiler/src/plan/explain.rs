//! One-line explanations of steps, as TLA printed them: what is placed,
//! from which loci, on which branch.

use std::fmt::Write;

use super::{ClusterParam, DirRef, Line, Plan, PointRef, Rel, StepKind};

/// A number for people: at most 4 decimals, trailing zeros dropped.
pub fn num(x: f64) -> String {
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

fn pair(p: [f64; 2]) -> String {
    format!("({}, {})", num(p[0]), num(p[1]))
}

impl Plan {
    /// The name of a point as a person would say it.
    pub fn point_name(&self, p: &PointRef) -> String {
        match p {
            PointRef::Fixed { name, .. } | PointRef::Marker { name, .. } => name.clone(),
            PointRef::Slid {
                name, input, sign, ..
            } => {
                let op = if *sign > 0.0 { "+" } else { "-" };
                format!("{name} {op} {}", self.inputs[*input].name)
            }
            PointRef::Temp { id } => {
                let step = self.steps.iter().position(|s| {
                    matches!(s.kind, StepKind::CircleCircle { out, .. } | StepKind::CircleLine { out, .. } | StepKind::LineLine { out, .. } if out == *id)
                });
                match step {
                    Some(k) => format!("{} (step {k})", self.temps[*id].name),
                    None => self.temps[*id].name.clone(),
                }
            }
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

    fn line_name(&self, l: &Line) -> String {
        format!(
            "line through {} along {}",
            self.point_name(&l.through),
            self.dir_name(&l.dir)
        )
    }

    fn branch_symbol(&self, slot: usize) -> &'static str {
        self.branches[slot].initial.symbol()
    }

    /// The one-line explanation of step `i`.
    pub fn explain(&self, i: usize) -> String {
        let body = |b: &usize| self.bodies[*b].name.as_str();
        match &self.steps[i].kind {
            StepKind::Orient { body: b, from, rel } => match rel {
                Rel::Identity => format!(
                    "{}: rotation of {}",
                    body(b),
                    from.as_ref().map_or("the ground", body)
                ),
                Rel::Input { input, inverse } => format!(
                    "{}: rotation of {} {} input {}",
                    body(b),
                    from.as_ref().map_or("the ground", body),
                    if *inverse { "minus" } else { "plus" },
                    self.inputs[*input].name
                ),
            },
            StepKind::Anchor { body: b, local, at } => {
                // An anchor followed by another write of the same body puts
                // it on its line locus for now (Kramer's 1-TDOF state).
                let provisional = self.steps[i + 1..].iter().any(|s| s.kind.writes().contains(b));
                format!(
                    "{}: translate {} onto {}{}",
                    body(b),
                    self.local_name(*b, *local),
                    self.point_name(at),
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
                self.point_name(p_at),
                self.local_name(*b, *q),
                self.point_name(q_at),
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
                self.point_name(c1),
                num(*r1),
                self.point_name(c2),
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
                self.point_name(c),
                num(*r),
                self.line_name(line),
                self.branch_symbol(*branch)
            ),
            StepKind::LineLine { out, a, b } => format!(
                "{}: {} ∩ {}",
                self.temps[*out].name,
                self.line_name(a),
                self.line_name(b)
            ),
            StepKind::Cluster { params, .. } => {
                let (u, e) = self.steps[i].kind.cluster_size();
                let bodies: Vec<String> = params
                    .iter()
                    .map(|p| match p {
                        ClusterParam::Free { body: b } => format!("{} (free)", body(b)),
                        ClusterParam::Angle { body: b, at, .. } => {
                            format!("{} (angle about {})", body(b), self.point_name(at))
                        }
                        ClusterParam::Hinge { body: b, name, .. } => {
                            format!("{} (angle about {name})", body(b))
                        }
                        ClusterParam::Slide { body: b, dir } => {
                            format!("{} (slide along {})", body(b), self.dir_name(dir))
                        }
                        ClusterParam::Translate { body: b } => format!("{} (translation)", body(b)),
                    })
                    .collect();
                format!(
                    "cluster {}: {} by Newton–Raphson, {u} unknowns, {e} equations",
                    match &self.steps[i].kind {
                        StepKind::Cluster { index, .. } => *index,
                        _ => 0,
                    },
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
                self.point_name(pivot),
                pair(*dir),
                self.point_name(target),
                num(*kappa),
                self.branch_symbol(*branch)
            ),
        }
    }

    /// The whole plan, one numbered line per step, as `dofplan plan` prints
    /// it.
    pub fn explain_all(&self) -> String {
        let mut out = String::new();
        let inputs: Vec<String> = self
            .inputs
            .iter()
            .map(|i| format!("{} ({})", i.name, i.kind.name()))
            .collect();
        let _ = writeln!(
            out,
            "plan for {} ({}): {} steps, {} branch{}, inputs: {}",
            self.mechanism,
            self.source,
            self.steps.len(),
            self.branches.len(),
            if self.branches.len() == 1 { "" } else { "es" },
            if inputs.is_empty() {
                "none".to_string()
            } else {
                inputs.join(", ")
            }
        );
        for (i, step) in self.steps.iter().enumerate() {
            let serves = if step.serves.is_empty() {
                String::new()
            } else {
                format!("  [{}]", step.serves.join(", "))
            };
            let _ = writeln!(out, "{i:>4}  {}{serves}", self.explain(i));
        }
        out
    }
}
