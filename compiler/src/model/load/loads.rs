//! Validating what acts on a mechanism of either dimension: the bodies'
//! `mass`, `centre` and `inertia`, `[gravity]` and `[loads.NAME]`. Every
//! key is checked as the rest of the file is (position, names, a hint);
//! what differs between the plane and space (a vector's length, a torque,
//! an inertia) is each dimension's [`ReadSpace`].

use super::*;
use crate::model::loads::{Load, LoadKind, Loads, Mass, Space};
use crate::model::planar::loads::Planar;
use crate::model::spatial::loads::Spatial;

/// The keys a body may have besides `fixed` and `markers`.
pub(super) const MASS_KEYS: [&str; 3] = ["mass", "centre", "inertia"];

/// The kinds of `[loads.NAME]`.
const LOAD_KINDS: [&str; 5] = ["force", "torque", "spring", "damper", "torsion-spring"];

/// What a load needs to know of a joint: its name, its kind's name and
/// whether it turns about one axis (where a torsion spring may sit).
pub(super) struct JointLoad<'a> {
    pub(super) name: &'a str,
    pub(super) kind: &'static str,
    pub(super) turns: bool,
}

/// How a dimension's loads are written.
pub(super) trait ReadSpace: Space {
    /// A point, a force or gravity.
    fn vector(v: &mut Validator, node: &Node, path: &str) -> Option<Self::Vector>;
    /// A `torque`.
    fn torque(v: &mut Validator, node: &Node, path: &str) -> Option<Self::Torque>;
    /// A body's `inertia`.
    fn inertia(v: &mut Validator, node: &Node, path: &str) -> Option<Self::Inertia>;
    /// What `inertia` is, for the help of a body missing it.
    const INERTIA: &'static str;
    /// The joints a torsion spring may sit on, for its help.
    const TURNING: &'static str;
}

impl ReadSpace for Planar {
    fn vector(v: &mut Validator, node: &Node, path: &str) -> Option<[f64; 2]> {
        v.coords(node, path)
    }
    fn torque(v: &mut Validator, node: &Node, path: &str) -> Option<f64> {
        v.number(node, path)
    }
    fn inertia(v: &mut Validator, node: &Node, path: &str) -> Option<f64> {
        v.non_negative(node, path, true)
    }
    const INERTIA: &'static str = "`inertia` (about the centre; 0 for a point mass)";
    const TURNING: &'static str = "a revolute joint";
}

impl ReadSpace for Spatial {
    fn vector(v: &mut Validator, node: &Node, path: &str) -> Option<[f64; 3]> {
        v.coords(node, path)
    }
    fn torque(v: &mut Validator, node: &Node, path: &str) -> Option<[f64; 3]> {
        v.coords(node, path)
    }
    fn inertia(v: &mut Validator, node: &Node, path: &str) -> Option<[[f64; 3]; 3]> {
        v.tensor(node, path)
    }
    const INERTIA: &'static str =
        "`inertia` (a symmetric 3×3 tensor about the centre in the drawn axes, [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]]; all 0 for a point mass)";
    const TURNING: &'static str = "a revolute or cylindrical joint";
}

impl Validator {
    /// The loads of a file: its bodies' masses (read again from
    /// `bodies_node`, whose keys `bodies` checked), `[gravity]` and
    /// `[loads]`.
    pub(super) fn loads<S: ReadSpace, M: MarkerLike>(
        &mut self,
        top: Entries,
        bodies_node: Option<&Node>,
        bodies: &[Body<M>],
        joints: &[JointLoad],
    ) -> Loads<S> {
        let mut loads = Loads {
            masses: self.masses(bodies_node, bodies),
            ..Loads::default()
        };
        if let Some(g) = Self::get(top, "gravity") {
            loads.gravity = self.gravity::<S>(g);
        }
        if let Some(node) = Self::get(top, "loads") {
            loads.applied = self.applied(node, bodies, joints);
        }
        loads
    }

    /// Each body's `mass`, `centre` and `inertia`: all three or none.
    fn masses<S: ReadSpace, M: MarkerLike>(
        &mut self,
        node: Option<&Node>,
        bodies: &[Body<M>],
    ) -> Vec<Option<Mass<S>>> {
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
                    Some(format!("a body's mass properties are `mass`, `centre` (a point of the drawing) and {}, all three", S::INERTIA)),
                );
                continue;
            }
            let mass = self.non_negative(Self::get(fields, "mass").unwrap(), &join(&path, "mass"), false);
            let centre = S::vector(self, Self::get(fields, "centre").unwrap(), &join(&path, "centre"));
            let inertia = S::inertia(
                self,
                Self::get(fields, "inertia").unwrap(),
                &join(&path, "inertia"),
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

    /// `[gravity] g = [gx, gy]` (or `[gx, gy, gz]`).
    fn gravity<S: ReadSpace>(&mut self, node: &Node) -> Option<S::Vector> {
        let fields = self.table(node, "gravity")?;
        self.check_keys(fields, &["g"], "gravity");
        let g = self.required(fields, "g", node, "gravity")?;
        S::vector(self, g, "gravity.g")
    }

    /// A symmetric 3×3 tensor with no negative principal value: an
    /// inertia.
    fn tensor(&mut self, node: &Node, path: &str) -> Option<[[f64; 3]; 3]> {
        let rows = match &node.kind {
            NodeKind::Array(items) if items.len() == 3 => items,
            _ => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!(
                        "`{path}` must be a 3×3 tensor, [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]]"
                    ),
                    Some("for a point mass write [[0, 0, 0], [0, 0, 0], [0, 0, 0]]".into()),
                );
                return None;
            }
        };
        let mut t = [[0.0; 3]; 3];
        let mut ok = true;
        for (k, row) in rows.iter().enumerate() {
            match self.coords::<3>(row, &format!("{path}[{k}]")) {
                Some(r) => t[k] = r,
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        let scale = t.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
        let asymmetry = (t[0][1] - t[1][0])
            .abs()
            .max((t[0][2] - t[2][0]).abs())
            .max((t[1][2] - t[2][1]).abs());
        let loc = || self.loc(node, path);
        if asymmetry > 1e-9 * scale {
            let loc = loc();
            self.error(
                loc,
                format!("`{path}` is not symmetric (differs by {asymmetry} across the diagonal)"),
                Some("an inertia tensor has Ixy = Iyx, Ixz = Izx and Iyz = Izy".into()),
            );
            return None;
        }
        let least = nalgebra::Matrix3::from_fn(|r, c| t[r][c])
            .symmetric_eigenvalues()
            .min();
        if least < -1e-9 * scale {
            let loc = loc();
            self.error(
                loc,
                format!("`{path}` has a negative principal moment ({least}): no body has that inertia"),
                Some("check the signs of the products of inertia (Ixy, Ixz, Iyz)".into()),
            );
            return None;
        }
        Some(t)
    }

    /// `[loads.NAME]`, each by its kind.
    fn applied<S: ReadSpace, M: MarkerLike>(
        &mut self,
        node: &Node,
        bodies: &[Body<M>],
        joints: &[JointLoad],
    ) -> Vec<Load<S>> {
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

    fn force<S: ReadSpace, M: MarkerLike>(
        &mut self,
        fields: Entries,
        entry: &Node,
        path: &str,
        bodies: &[Body<M>],
        owner: &str,
    ) -> Option<LoadKind<S>> {
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
            .and_then(|n| S::vector(self, n, &join(path, "force")));
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
                        Some("\"world\": the force's components are along the world axes; \"body\": along the marker's body's axes (as drawn), turning with it".into()),
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

    fn torque<S: ReadSpace, M: MarkerLike>(
        &mut self,
        fields: Entries,
        entry: &Node,
        path: &str,
        bodies: &[Body<M>],
    ) -> Option<LoadKind<S>> {
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
            .and_then(|n| S::torque(self, n, &join(path, "torque")));
        Some(LoadKind::Torque {
            body: body?,
            torque: torque?,
        })
    }

    /// A spring or a damper: two markers and its constants.
    fn between<S: ReadSpace, M: MarkerLike>(
        &mut self,
        kind: &str,
        fields: Entries,
        entry: &Node,
        path: &str,
        bodies: &[Body<M>],
        owner: &str,
    ) -> Option<LoadKind<S>> {
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

    fn torsion<S: ReadSpace>(
        &mut self,
        fields: Entries,
        entry: &Node,
        path: &str,
        joints: &[JointLoad],
    ) -> Option<LoadKind<S>> {
        let joint = self.required(fields, "joint", entry, path).and_then(|n| {
            let jpath = join(path, "joint");
            let name = self.string(n, &jpath)?;
            let found = joints.iter().position(|j| j.name == name);
            let loc = self.loc(n, &jpath);
            match found {
                None => {
                    let names: Vec<&str> = joints.iter().map(|j| j.name).collect();
                    self.error(
                        loc,
                        format!("`{jpath}`: unknown joint `{name}`"),
                        Some(format!("joints are: {}", names.join(", "))),
                    );
                    None
                }
                Some(j) if !joints[j].turns => {
                    self.error(
                        loc,
                        format!(
                            "`{jpath}`: joint `{name}` is {}; a torsion spring sits on {}",
                            joints[j].kind,
                            S::TURNING
                        ),
                        Some("for a joint that slides, a `spring` between two markers does it".into()),
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
}
