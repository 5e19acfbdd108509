//! Validating what acts on a planar mechanism: the bodies' `mass`,
//! `centre` and `inertia`, `[gravity]` and `[loads.NAME]`. Every key is
//! checked as the rest of the file is (position, names, a hint); a spatial
//! file that writes any of them is told they are planar for now
//! (`refuse_loads`).

use super::*;
use crate::model::planar::loads::{Load, LoadKind, Loads, Mass};
use crate::model::planar::{Joint, JointKind};

/// The keys a body may have besides `fixed` and `markers`.
pub(super) const MASS_KEYS: [&str; 3] = ["mass", "centre", "inertia"];

/// The kinds of `[loads.NAME]`.
const LOAD_KINDS: [&str; 5] = ["force", "torque", "spring", "damper", "torsion-spring"];

impl Validator {
    /// The loads of a planar file: its bodies' masses (read again from
    /// `bodies_node`, whose keys `bodies` checked), `[gravity]` and
    /// `[loads]`.
    pub(super) fn loads(
        &mut self,
        top: Entries,
        bodies_node: Option<&Node>,
        bodies: &[Body],
        joints: &[(Joint, &Node)],
    ) -> Loads {
        let mut loads = Loads {
            masses: self.masses(bodies_node, bodies),
            ..Loads::default()
        };
        if let Some(g) = Self::get(top, "gravity") {
            loads.gravity = self.gravity(g);
        }
        if let Some(node) = Self::get(top, "loads") {
            loads.applied = self.applied(node, bodies, joints);
        }
        loads
    }

    /// Each body's `mass`, `centre` and `inertia`: all three or none.
    fn masses(&mut self, node: Option<&Node>, bodies: &[Body]) -> Vec<Option<Mass>> {
        let Some(NodeKind::Table(entries)) = node.map(|n| &n.kind) else {
            return Vec::new();
        };
        let mut found = vec![None; bodies.len()];
        let mut any = false;
        for (key, bnode) in entries.iter() {
            let NodeKind::Table(fields) = &bnode.kind else {
                continue;
            };
            let written: Vec<&str> = MASS_KEYS
                .into_iter()
                .filter(|k| Self::get(fields, k).is_some())
                .collect();
            if written.is_empty() {
                continue;
            }
            let path = join("bodies", &key.name);
            if written.len() < MASS_KEYS.len() {
                let missing: Vec<String> = (MASS_KEYS.iter())
                    .filter(|k| !written.contains(k))
                    .map(|k| format!("`{k}`"))
                    .collect();
                let loc = self.loc(bnode, &path);
                self.error(
                    loc,
                    format!(
                        "body `{}` has {} but not {}",
                        key.name,
                        written.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(" and "),
                        missing.join(" or ")
                    ),
                    Some("a body's mass properties are `mass`, `centre` (a point of the drawing) and `inertia` (about the centre; 0 for a point mass), all three".into()),
                );
                continue;
            }
            let mass = self.non_negative(Self::get(fields, "mass").unwrap(), &join(&path, "mass"), false);
            let centre = self.point(Self::get(fields, "centre").unwrap(), &join(&path, "centre"));
            let inertia = self.non_negative(
                Self::get(fields, "inertia").unwrap(),
                &join(&path, "inertia"),
                true,
            );
            let b = bodies.iter().position(|b| b.name == key.name);
            if let (Some(mass), Some(centre), Some(inertia), Some(b)) = (mass, centre, inertia, b) {
                found[b] = Some(Mass {
                    mass,
                    centre,
                    inertia,
                });
                any = true;
            }
        }
        if any {
            found
        } else {
            Vec::new()
        }
    }

    /// A number `> 0` (or `>= 0` when `zero` is allowed).
    fn non_negative(&mut self, node: &Node, path: &str, zero: bool) -> Option<f64> {
        let v = self.number(node, path)?;
        if v < 0.0 || (!zero && v == 0.0) {
            let loc = self.loc(node, path);
            let bound = if zero { "0 or more" } else { "more than 0" };
            self.error(loc, format!("`{path}` is {v}: it must be {bound}"), None);
            return None;
        }
        Some(v)
    }

    /// `[gravity] g = [gx, gy]`.
    fn gravity(&mut self, node: &Node) -> Option<[f64; 2]> {
        let fields = self.table(node, "gravity")?;
        self.check_keys(fields, &["g"], "gravity");
        let g = self.required(fields, "g", node, "gravity")?;
        self.point(g, "gravity.g")
    }

    /// `[loads.NAME]`, each by its kind.
    fn applied(&mut self, node: &Node, bodies: &[Body], joints: &[(Joint, &Node)]) -> Vec<Load> {
        let Some(entries) = self.table(node, "loads") else {
            return Vec::new();
        };
        self.check_keys(entries, &[], "loads");
        let mut out = Vec::new();
        for (key, entry) in entries {
            let path = join("loads", &key.name);
            let owner = format!("load `{}`", key.name);
            self.check_name(key, &path, "load");
            let Some(fields) = self.table(entry, &path) else {
                continue;
            };
            let Some((kind, _)) = self.kind(fields, entry, &path, &LOAD_KINDS, &owner) else {
                continue;
            };
            let allowed: &[&str] = match kind {
                "force" => &["kind", "marker", "force", "axes"],
                "torque" => &["kind", "body", "torque"],
                "spring" => &["kind", "markers", "stiffness", "free_length"],
                "damper" => &["kind", "markers", "damping"],
                _ => &["kind", "joint", "stiffness", "free_angle"],
            };
            self.check_keys(fields, allowed, &path);
            let read = match kind {
                "force" => self.force(fields, entry, &path, bodies, &owner),
                "torque" => self.torque(fields, entry, &path, bodies),
                "spring" | "damper" => self.between(kind, fields, entry, &path, bodies, &owner),
                _ => self.torsion(fields, entry, &path, joints),
            };
            if let Some(kind) = read {
                out.push(Load {
                    name: key.name.to_string(),
                    kind,
                });
            }
        }
        out
    }

    fn force(
        &mut self,
        fields: Entries,
        entry: &Node,
        path: &str,
        bodies: &[Body],
        owner: &str,
    ) -> Option<LoadKind> {
        let mnode = self.required(fields, "marker", entry, path);
        let marker = mnode.and_then(|n| {
            let mpath = join(path, "marker");
            self.marker_ref(
                &Written {
                    node: n,
                    path: &|| mpath.clone(),
                },
                bodies,
                owner,
            )
        });
        let force = self
            .required(fields, "force", entry, path)
            .and_then(|n| self.point(n, &join(path, "force")));
        let body_axes = match Self::get(fields, "axes") {
            None => Some(false),
            Some(n) => match self.string(n, &join(path, "axes"))? {
                "world" => Some(false),
                "body" => Some(true),
                other => {
                    let loc = self.loc(n, &join(path, "axes"));
                    self.error(
                        loc,
                        format!("{owner}: `axes` is \"world\" or \"body\", not {other:?}"),
                        Some("\"world\": the force's components are along x and y; \"body\": along the marker's body's axes, turning with it".into()),
                    );
                    None
                }
            },
        };
        Some(LoadKind::Force {
            marker: marker?,
            force: force?,
            body_axes: body_axes?,
        })
    }

    fn torque(&mut self, fields: Entries, entry: &Node, path: &str, bodies: &[Body]) -> Option<LoadKind> {
        let body = self.required(fields, "body", entry, path).and_then(|n| {
            let bpath = join(path, "body");
            let name = self.string(n, &bpath)?;
            let found = bodies.iter().position(|b| b.name == name);
            if found.is_none() {
                let loc = self.loc(n, &bpath);
                let names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
                self.error(
                    loc,
                    format!("`{bpath}`: unknown body `{name}`"),
                    Some(format!("bodies are: {}", names.join(", "))),
                );
            }
            found
        });
        let torque = (self.required(fields, "torque", entry, path))
            .and_then(|n| self.number(n, &join(path, "torque")));
        Some(LoadKind::Torque {
            body: body?,
            torque: torque?,
        })
    }

    /// A spring or a damper: two markers and its constants.
    fn between(
        &mut self,
        kind: &str,
        fields: Entries,
        entry: &Node,
        path: &str,
        bodies: &[Body],
        owner: &str,
    ) -> Option<LoadKind> {
        let markers = self.pair(
            fields,
            entry,
            path,
            bodies,
            (owner, "a spring or damper acts between two bodies"),
        );
        if kind == "damper" {
            let c = (self.required(fields, "damping", entry, path))
                .and_then(|n| self.non_negative(n, &join(path, "damping"), true));
            return Some(LoadKind::Damper {
                markers: markers?,
                damping: c?,
            });
        }
        let k = (self.required(fields, "stiffness", entry, path))
            .and_then(|n| self.non_negative(n, &join(path, "stiffness"), true));
        let free = (self.required(fields, "free_length", entry, path))
            .and_then(|n| self.non_negative(n, &join(path, "free_length"), true));
        Some(LoadKind::Spring {
            markers: markers?,
            stiffness: k?,
            free_length: free?,
        })
    }

    fn torsion(
        &mut self,
        fields: Entries,
        entry: &Node,
        path: &str,
        joints: &[(Joint, &Node)],
    ) -> Option<LoadKind> {
        let joint = self.required(fields, "joint", entry, path).and_then(|n| {
            let jpath = join(path, "joint");
            let name = self.string(n, &jpath)?;
            let found = joints.iter().position(|(j, _)| j.name == name);
            let loc = self.loc(n, &jpath);
            match found {
                None => {
                    let names: Vec<&str> = joints.iter().map(|(j, _)| j.name.as_str()).collect();
                    self.error(
                        loc,
                        format!("`{jpath}`: unknown joint `{name}`"),
                        Some(format!("joints are: {}", names.join(", "))),
                    );
                    None
                }
                Some(j) if joints[j].0.kind != JointKind::Revolute => {
                    self.error(
                        loc,
                        format!("`{jpath}`: joint `{name}` is prismatic; a torsion spring sits on a revolute joint"),
                        Some("for a prismatic joint, a `spring` between two markers does it".into()),
                    );
                    None
                }
                Some(j) => Some(j),
            }
        });
        let k = (self.required(fields, "stiffness", entry, path))
            .and_then(|n| self.non_negative(n, &join(path, "stiffness"), true));
        let free = (self.required(fields, "free_angle", entry, path))
            .and_then(|n| self.number(n, &join(path, "free_angle")));
        Some(LoadKind::TorsionSpring {
            joint: joint?,
            stiffness: k?,
            free_angle: free?.to_radians(),
        })
    }

    /// A spatial file's masses, gravity and loads: refused by name, since
    /// force analysis is planar for now.
    pub(super) fn refuse_loads(&mut self, top: Entries) {
        let help = Some(
            "masses, gravity and loads are read from planar files for now; remove them here".to_string(),
        );
        for key in ["loads", "gravity"] {
            if let Some((k, _)) = top.iter().find(|(k, _)| k.name == key) {
                let loc = self.key_loc(k, key);
                self.error(
                    loc,
                    format!("`{key}` is not read from spatial files yet"),
                    help.clone(),
                );
            }
        }
        let Some(NodeKind::Table(bodies)) = Self::get(top, "bodies").map(|n| &n.kind) else {
            return;
        };
        for (b, bnode) in bodies.iter() {
            let NodeKind::Table(fields) = &bnode.kind else {
                continue;
            };
            for (k, _) in fields
                .iter()
                .filter(|(k, _)| MASS_KEYS.contains(&k.name.as_ref()))
            {
                let path = join(&join("bodies", &b.name), &k.name);
                let loc = self.key_loc(k, &path);
                self.error(
                    loc,
                    format!("`{path}`: mass properties are not read from spatial files yet"),
                    help.clone(),
                );
            }
        }
    }
}
