//! Validating planar files: the mechanism, its markers, joints and
//! constraints, each joint and constraint checked to hold as drawn. The
//! tree walk, names, numbers, inputs and sweep are shared (`mod.rs`);
//! `spatial.rs` is the same for `dimension = 3` files.

// The tree walk's types and helpers are the parent module's, as for the
// tests of a module.
use super::loads::JointLoad;
use super::*;
use crate::model::planar::loads::Planar;

impl Validator {
    pub(super) fn mechanism(&mut self, root: &Node) -> Option<Mechanism> {
        let (top, name) = self.top(root)?;
        if let Some(d) = Self::get(top, "dimension") {
            match d.kind {
                NodeKind::Int(2) => {}
                NodeKind::Int(3) => {
                    let loc = self.loc(d, "dimension");
                    self.error(
                        loc,
                        "this is a spatial mechanism (dimension = 3), and this reads planar ones".into(),
                        Some("load it with `dofplan::load_any` (the CLI and build.rs do)".into()),
                    );
                }
                _ => {
                    let loc = self.loc(d, "dimension");
                    self.error(loc, "`dimension` must be 2 or 3".into(), None);
                }
            }
        }
        let bodies_node = self.required(top, "bodies", root, "");
        let bodies = match bodies_node {
            Some(n) => self.bodies(n, Self::marker),
            None => Vec::new(),
        };
        let empty = Node {
            at: At::NONE,
            kind: NodeKind::Table(Vec::new()),
        };
        let joints_node = Self::get(top, "joints").unwrap_or(&empty);
        let constraints_node = Self::get(top, "constraints").unwrap_or(&empty);
        // Gear pairs and racks name bodies, not markers: read apart, after
        // the joints they turn and slide in.
        let split = super::gears::split_joints(joints_node);
        let joints = self.joints(joints_node, &bodies);
        let gears = self.gears(&split.gears, &bodies, &joints);
        let slots = self.slots(&split.slots, &bodies);
        let constraints = self.constraints(constraints_node, &bodies);
        for (what, name, node) in joints
            .iter()
            .map(|(j, n)| ("joint", &j.name, n))
            .chain(constraints.iter().map(|(c, n)| ("constraint", &c.name, n)))
        {
            let place = match node.span() {
                Some(s) => Location::Span(s),
                None => Location::Path(join(&format!("{what}s"), name)),
            };
            self.places.push(place);
        }
        self.cross_duplicates(joints_node, constraints_node);
        let inputs = match Self::get(top, "inputs") {
            Some(n) => {
                self.inputs_on_gears(n, &split.higher());
                self.inputs(n, joints_node, &joints, &bodies)
            }
            None => Vec::new(),
        };
        let written_inputs: Vec<&str> = match Self::get(top, "inputs").map(|n| &n.kind) {
            Some(NodeKind::Table(t)) => t.iter().map(|(k, _)| k.name.as_ref()).collect(),
            _ => vec![],
        };
        let sweep = match Self::get(top, "sweep") {
            Some(n) => self.sweep(n, &inputs, &written_inputs, &bodies),
            None => None,
        };
        let turning: Vec<JointLoad> = (joints.iter())
            .map(|(j, _)| JointLoad {
                name: &j.name,
                kind: j.kind.name(),
                turns: j.kind == JointKind::Revolute,
            })
            .collect();
        let loads = self.loads::<Planar, _>(top, bodies_node, &bodies, &turning);
        let mechanism = Mechanism {
            name: name?,
            dimension: 2,
            bodies,
            joints: self.with_lines(joints, |j, line| j.line = line),
            constraints: constraints.into_iter().map(|(c, _)| c).collect(),
            gears: self.with_lines(gears, |g, line| g.line = line),
            slots: self.with_lines(slots, |s, line| s.line = line),
            inputs,
            sweep,
            loads,
            source: self.file.clone(),
        };
        Some(mechanism)
    }

    fn marker(&mut self, body: &str, short: &str, node: &Node, path: &str) -> Option<Marker> {
        // The marker's full name, for errors only.
        let name = || format!("{body}.{short}");
        match &node.kind {
            NodeKind::Array(_) => Some(Marker {
                name: short.to_string(),
                at: self.position(&name, node, path)?,
                dir: None,
            }),
            NodeKind::Table(fields) => {
                self.check_keys(fields, &["at", "dir"], path);
                let at = self
                    .required(fields, "at", node, path)
                    .and_then(|n| self.position(&name, n, &join(path, "at")));
                let dir = match Self::get(fields, "dir") {
                    None => None,
                    Some(d) => {
                        let dpath = join(path, "dir");
                        let v = self.point(d, &dpath)?;
                        if !(v[0] * v[0] + v[1] * v[1]).is_normal() {
                            let loc = self.loc(d, &dpath);
                            let what = if v[0] == 0.0 && v[1] == 0.0 {
                                "a zero direction".to_string()
                            } else {
                                "a direction too short or too long to normalise".to_string()
                            };
                            self.error(
                                loc,
                                format!("marker `{}` has {what}", name()),
                                Some("a direction needs a non-zero length, e.g. dir = [1, 0]".into()),
                            );
                            return None;
                        }
                        Some(v)
                    }
                };
                Some(Marker {
                    name: short.to_string(),
                    at: at?,
                    dir,
                })
            }
            other => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!(
                        "marker `{}` must be [x, y] or {{ at = [x, y], dir = [dx, dy] }}, found {}",
                        name(),
                        other.type_name()
                    ),
                    None,
                );
                None
            }
        }
    }

    fn joints<'n>(&mut self, node: &'n Node<'n>, bodies: &[Body]) -> Vec<(Joint, &'n Node<'n>)> {
        let found = self.connections(
            node,
            bodies,
            "joints",
            "joint",
            (
                &["revolute", "prismatic", "gear", "rack-pinion", "slot"],
                &[],
                &super::gears::HIGHER_KINDS,
            ),
            |v, kind, markers, entry, path, owner| match kind {
                "revolute" => v
                    .check_coincident(markers, bodies, entry, path, owner)
                    .then_some(JointKind::Revolute),
                _ => v
                    .check_in_line(markers, bodies, entry, path, owner, "prismatic joint")
                    .then_some(JointKind::Prismatic),
            },
        );
        found
            .into_iter()
            .map(|(name, kind, markers, entry)| {
                (
                    Joint {
                        name,
                        kind,
                        markers,
                        line: None,
                    },
                    entry,
                )
            })
            .collect()
    }

    fn constraints<'n>(&mut self, node: &'n Node<'n>, bodies: &[Body]) -> Vec<(Constraint, &'n Node<'n>)> {
        let found = self.connections(
            node,
            bodies,
            "constraints",
            "constraint",
            (&["coincident", "in-line", "offset"], &[], &[]),
            |v, kind, markers, entry, path, owner| match kind {
                "coincident" => v
                    .check_coincident(markers, bodies, entry, path, owner)
                    .then_some(ConstraintKind::Coincident),
                "in-line" => v
                    .check_in_line(markers, bodies, entry, path, owner, "in-line constraint")
                    .then_some(ConstraintKind::InLine),
                _ => v
                    .check_directions(markers, bodies, entry, path, owner)
                    .then_some(ConstraintKind::Offset),
            },
        );
        found
            .into_iter()
            .map(|(name, kind, markers, entry)| (Constraint { name, kind, markers }, entry))
            .collect()
    }

    /// An offset constraint relates the two markers' directions: both need one.
    fn check_directions(
        &mut self,
        ids: [MarkerId; 2],
        bodies: &[Body],
        node: &Node,
        path: &str,
        owner: &str,
    ) -> bool {
        let mut ok = true;
        for id in ids {
            let m = &bodies[id.body].markers[id.marker];
            if m.dir.is_none() {
                ok = false;
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!(
                        "{owner}: an offset constraint relates directions, but marker `{}.{}` has none",
                        bodies[id.body].name, m.name
                    ),
                    Some(format!(
                        "write the marker as {} = {{ at = [{}, {}], dir = [1, 0] }}",
                        m.name, m.at[0], m.at[1]
                    )),
                );
            }
        }
        ok
    }

    pub(super) fn size(&mut self, bodies: &[Body]) -> f64 {
        *self
            .size
            .get_or_insert_with(|| crate::model::planar::size_of(bodies))
    }

    fn check_coincident(
        &mut self,
        ids: [MarkerId; 2],
        bodies: &[Body],
        node: &Node,
        path: &str,
        owner: &str,
    ) -> bool {
        let a = &bodies[ids[0].body].markers[ids[0].marker];
        let b = &bodies[ids[1].body].markers[ids[1].marker];
        let gap = ((a.at[0] - b.at[0]).powi(2) + (a.at[1] - b.at[1]).powi(2)).sqrt();
        let size = self.size(bodies);
        if gap > DRAWN_TOLERANCE * size {
            let loc = self.loc(node, path);
            self.error(
                loc,
                format!(
                    "{owner} does not hold in the drawn pose: {}.{} at [{}, {}] and {}.{} at [{}, {}] are {:.3e} apart (tolerance {:.1e})",
                    bodies[ids[0].body].name, a.name, a.at[0], a.at[1], bodies[ids[1].body].name, b.name, b.at[0], b.at[1], gap, DRAWN_TOLERANCE * size
                ),
                Some("markers are world coordinates of the pose as drawn: give the joined markers the same coordinates".into()),
            );
            self.opened(owner);
        }
        true
    }

    /// Reports that marker `id` has no `dir` where `needs` says why it
    /// must (a slot's line, an arc's angles), with the marker written
    /// with one as the fix.
    pub(super) fn no_direction(
        &mut self,
        id: MarkerId,
        bodies: &[Body],
        node: &Node,
        path: &str,
        owner: &str,
        needs: &str,
    ) {
        let m = &bodies[id.body].markers[id.marker];
        let loc = self.loc(node, path);
        self.error(
            loc,
            format!(
                "{owner}: {needs}, but `{}.{}` has no direction",
                bodies[id.body].name, m.name
            ),
            Some(format!(
                "write it as {} = {{ at = [{}, {}], dir = [dx, dy] }}",
                m.name, m.at[0], m.at[1]
            )),
        );
    }

    pub(super) fn check_in_line(
        &mut self,
        ids: [MarkerId; 2],
        bodies: &[Body],
        node: &Node,
        path: &str,
        owner: &str,
        what: &str,
    ) -> bool {
        let a = &bodies[ids[0].body].markers[ids[0].marker];
        let b = &bodies[ids[1].body].markers[ids[1].marker];
        let Some(d) = a.unit_dir() else {
            let needs = format!("the first marker of a {what} carries the line");
            self.no_direction(ids[0], bodies, node, path, owner, &needs);
            return false;
        };
        let off = (b.at[0] - a.at[0]) * d[1] - (b.at[1] - a.at[1]) * d[0];
        let size = self.size(bodies);
        if off.abs() > DRAWN_TOLERANCE * size {
            let loc = self.loc(node, path);
            self.error(
                loc,
                format!(
                    "{owner} does not hold in the drawn pose: {}.{} is {:.3e} off the line of {}.{}",
                    bodies[ids[1].body].name,
                    b.name,
                    off.abs(),
                    bodies[ids[0].body].name,
                    a.name
                ),
                Some("the second marker must lie on the line through the first along its dir".into()),
            );
            self.opened(owner);
        }
        true
    }
}

impl JointLike for Joint {
    fn name(&self) -> &str {
        &self.name
    }
    fn kind_name(&self) -> &'static str {
        self.kind.name()
    }
    fn markers(&self) -> [MarkerId; 2] {
        self.markers
    }
    fn refuses(&self, kind: InputKind) -> Option<String> {
        let fits = match (kind, self.kind) {
            (InputKind::Angle, JointKind::Revolute) | (InputKind::Slide, JointKind::Prismatic) => {
                return None
            }
            (_, JointKind::Revolute) => "angle",
            (_, JointKind::Prismatic) => "slide",
        };
        Some(format!(
            "an angle input drives a revolute joint and a slide input a prismatic one; use kind = \"{fits}\""
        ))
    }
}
