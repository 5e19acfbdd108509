//! Validating the higher pairs of planar files: `kind = "gear"` and
//! `kind = "rack-pinion"` entries of `[joints]`. They name two bodies, not
//! two markers; the carrier both move on is found from the file's other
//! joints, and the drawing must agree with the radii.

use super::*;
use crate::model::planar::gears::{Gear, GearKind};

/// The joint kinds that are gear pairs (read here, not as marker pairs).
pub(super) const GEAR_KINDS: [&str; 2] = ["gear", "rack-pinion"];

/// A `[joints]` entry's `kind`, if it is a string.
fn kind_of<'a>(entry: &'a Node) -> Option<&'a str> {
    let NodeKind::Table(fields) = &entry.kind else {
        return None;
    };
    match fields
        .iter()
        .find(|(k, _)| k.name == "kind")
        .map(|(_, n)| &n.kind)
    {
        Some(NodeKind::Str(s)) => Some(s.as_ref()),
        _ => None,
    }
}

/// The `[joints]` kinds read apart from the marker pairs: the gear pairs'
/// and the slots'.
pub(super) const HIGHER_KINDS: [&str; 3] = ["gear", "rack-pinion", "slot"];

/// A `[joints]` table's higher pairs, by how they are read (the marker
/// pairs are read in place, skipping these).
pub(super) struct Split<'n> {
    /// The gear pairs and racks.
    pub gears: Vec<&'n (Key<'n>, Node<'n>)>,
    /// The pins in slots.
    pub slots: Vec<&'n (Key<'n>, Node<'n>)>,
}

impl Split<'_> {
    /// The entries read apart from the marker pairs (inputs may not drive
    /// them).
    pub fn higher(&self) -> Vec<&(Key<'_>, Node<'_>)> {
        self.gears.iter().chain(&self.slots).copied().collect()
    }
}

/// The `[joints]` table's higher pairs (nothing is copied: a large file's
/// joints stay where they were read).
pub(super) fn split_joints<'n>(node: &'n Node<'n>) -> Split<'n> {
    let (mut gears, mut slots) = (Vec::new(), Vec::new());
    if let NodeKind::Table(entries) = &node.kind {
        for e in entries {
            match kind_of(&e.1) {
                Some(k) if GEAR_KINDS.contains(&k) => gears.push(e),
                Some("slot") => slots.push(e),
                _ => {}
            }
        }
    }
    Split { gears, slots }
}

/// What a higher pair's entry has given by the time its kind is read.
#[derive(Clone, Copy)]
struct Found {
    pair: [usize; 2],
    pivots: [usize; 2],
    centres: [Point; 2],
    pressure_angle: f64,
}

/// A body and the joints it turns or slides in, with the body at their
/// other end (`None`: a fixed body, the frame).
struct Seat {
    joint: usize,
    other: Option<usize>,
    centre: Point,
}

impl Validator {
    /// The higher pairs among `entries`, validated against the bodies and
    /// the (already validated) marker-pair joints.
    pub(super) fn gears<'n>(
        &mut self,
        entries: &[&'n (Key<'n>, Node<'n>)],
        bodies: &[Body],
        joints: &[(Joint, &Node)],
    ) -> Vec<(Gear, &'n Node<'n>)> {
        let mut out = Vec::new();
        for (key, entry) in entries.iter().map(|e| (&e.0, &e.1)) {
            let path = join("joints", &key.name);
            let owner = format!("joint `{}`", key.name);
            self.check_name(key, &path, "joint");
            let Some(fields) = self.table(entry, &path) else {
                continue;
            };
            let Some((kind, _)) = self.kind(fields, entry, &path, &GEAR_KINDS, &owner) else {
                continue;
            };
            let rack = kind == "rack-pinion";
            let allowed: &[&str] = if rack {
                &["kind", "bodies", "radius", "pressure_angle"]
            } else {
                &["kind", "bodies", "radii", "mesh", "pressure_angle"]
            };
            self.check_keys(fields, allowed, &path);
            let Some(pair) = self.gear_bodies(fields, entry, &path, &owner, bodies) else {
                continue;
            };
            let Some(found) = self.gear_carrier(pair, rack, entry, &path, &owner, bodies, joints) else {
                continue;
            };
            let (carrier, pivots, centres) = found;
            let Some(pressure_angle) = self.pressure_angle(fields, &path) else {
                continue;
            };
            let what = Found {
                pair,
                pivots,
                centres,
                pressure_angle,
            };
            let made = if rack {
                self.rack_pinion(fields, entry, &path, &owner, (bodies, joints), &what)
            } else {
                self.gear_pair(fields, entry, &path, &owner, bodies, &what)
            };
            let Some(kind) = made else {
                continue;
            };
            out.push((
                Gear {
                    name: key.name.to_string(),
                    kind,
                    bodies: pair,
                    carrier,
                    pivots,
                    centres,
                    line: None,
                },
                entry,
            ));
        }
        out
    }

    /// A rack and pinion's kind: its radius, and the rack's side of the
    /// pinion from the drawing.
    fn rack_pinion(
        &mut self,
        fields: &[(Key, Node)],
        entry: &Node,
        path: &str,
        owner: &str,
        (bodies, joints): (&[Body], &[(Joint, &Node)]),
        found: &Found,
    ) -> Option<GearKind> {
        let Found {
            pair,
            pivots,
            centres,
            pressure_angle,
        } = *found;
        let path = path.to_string();
        let radius = self.pitch_radius(fields, entry, &path, "radius")?;
        let prismatic = &joints[pivots[1]].0;
        let line = bodies[prismatic.markers[0].body].markers[prismatic.markers[0].marker].clone();
        let dir = line.unit_dir().expect("validated: prismatic markers carry a dir");
        // The rack's side of the pinion: where the rack's marker of
        // its prismatic joint is drawn.
        let rack_marker = prismatic
            .markers
            .iter()
            .find(|m| m.body == pair[1])
            .expect("the rack's joint");
        let at = bodies[rack_marker.body].markers[rack_marker.marker].at;
        let offset = dir[0] * (at[1] - centres[0][1]) - dir[1] * (at[0] - centres[0][0]);
        if offset.abs() <= DRAWN_TOLERANCE * self.size(bodies) {
            let loc = self.loc(entry, &path);
            self.error(
                loc,
                format!(
                    "{owner}: the rack `{}`'s marker {}.{} lies on the line through the pinion's pivot along the slide, so the side the rack meshes on is not drawn",
                    bodies[pair[1]].name, bodies[pair[1]].name, bodies[rack_marker.body].markers[rack_marker.marker].name
                ),
                Some("draw the rack's prismatic marker on the rack's side of the pinion (its pitch line, say)".into()),
            );
            return None;
        }
        Some(GearKind::RackPinion {
            radius,
            dir,
            side: offset.signum(),
            pressure_angle,
        })
    }

    /// A gear pair's kind: its radii and mesh, which must fit the drawn
    /// distance between the pivots.
    fn gear_pair(
        &mut self,
        fields: &[(Key, Node)],
        entry: &Node,
        path: &str,
        owner: &str,
        bodies: &[Body],
        found: &Found,
    ) -> Option<GearKind> {
        let Found {
            centres,
            pressure_angle,
            ..
        } = *found;
        let path = path.to_string();
        let radii = self.radii(fields, entry, &path)?;
        let internal = self.mesh(fields, entry, &path, owner)?;
        let drawn =
            ((centres[0][0] - centres[1][0]).powi(2) + (centres[0][1] - centres[1][1]).powi(2)).sqrt();
        let (want, how) = if internal {
            (
                (radii[0] - radii[1]).abs(),
                "the difference of the radii (internal mesh)",
            )
        } else {
            (radii[0] + radii[1], "the sum of the radii (external mesh)")
        };
        if internal && radii[0] == radii[1] {
            let loc = self.loc(Self::get(fields, "radii").unwrap_or(entry), &join(&path, "radii"));
            self.error(
                loc,
                format!(
                    "{owner}: an internal mesh needs a ring larger than its pinion, but both radii are {}",
                    radii[0]
                ),
                None,
            );
            return None;
        }
        if (drawn - want).abs() > DRAWN_TOLERANCE * self.size(bodies) {
            let loc = self.loc(Self::get(fields, "radii").unwrap_or(entry), &join(&path, "radii"));
            self.error(
                loc,
                format!(
                    "{owner} does not hold in the drawn pose: its pivots are {drawn} apart, but {how} is {want} (radii {} and {})",
                    radii[0], radii[1]
                ),
                Some("the pitch circles touch: draw the pivots that far apart, or give radii that fit".into()),
            );
            return None;
        }
        Some(GearKind::Gear {
            radii,
            internal,
            pressure_angle,
        })
    }

    /// An input written on a higher pair: an error (the pair's motion is
    /// set by its bodies' joints, which inputs drive).
    pub(super) fn inputs_on_gears(&mut self, inputs: &Node, gears: &[&(Key, Node)]) {
        let NodeKind::Table(entries) = &inputs.kind else {
            return;
        };
        for (key, node) in entries {
            let NodeKind::Table(fields) = &node.kind else {
                continue;
            };
            let Some(jnode) = Self::get(fields, "joint") else {
                continue;
            };
            let NodeKind::Str(joint) = &jnode.kind else {
                continue;
            };
            if let Some((gkey, _)) = gears.iter().map(|e| (&e.0, &e.1)).find(|(k, _)| k.name == *joint) {
                let path = join(&join("inputs", &key.name), "joint");
                let loc = self.loc(jnode, &path);
                let first = self.key_loc(gkey, &join("joints", &gkey.name));
                self.error_notes(
                    loc,
                    format!("input `{}` drives joint `{joint}`, a gear pair or slot, which has no motion of its own to drive", key.name),
                    vec![Note {
                        location: first,
                        message: format!("joint `{joint}` is defined here"),
                    }],
                    Some("drive a revolute or prismatic joint of one of its bodies".into()),
                );
            }
        }
    }

    /// `bodies = ["A", "B"]`: two different mobile bodies.
    fn gear_bodies(
        &mut self,
        fields: &[(Key, Node)],
        entry: &Node,
        path: &str,
        owner: &str,
        bodies: &[Body],
    ) -> Option<[usize; 2]> {
        let node = self.required(fields, "bodies", entry, path)?;
        let bpath = join(path, "bodies");
        let names: Vec<&str> = match &node.kind {
            NodeKind::Array(items) if items.len() == 2 => {
                let a = self.string(&items[0], &bpath);
                let b = self.string(&items[1], &bpath);
                vec![a?, b?]
            }
            _ => {
                let loc = self.loc(node, &bpath);
                self.error(
                    loc,
                    format!("{owner}: `bodies` must name two bodies, e.g. [\"sun\", \"planet\"]"),
                    None,
                );
                return None;
            }
        };
        let mut ids = [0; 2];
        for (k, name) in names.iter().enumerate() {
            let Some(b) = bodies.iter().position(|b| b.name == *name) else {
                let loc = self.loc(node, &bpath);
                self.error(
                    loc,
                    format!("{owner}: unknown body `{name}`"),
                    Some(format!(
                        "bodies are: {}",
                        bodies
                            .iter()
                            .map(|b| b.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                );
                return None;
            };
            if bodies[b].fixed {
                let loc = self.loc(node, &bpath);
                self.error(
                    loc,
                    format!("{owner}: body `{name}` is fixed, and a gear pair meshes two bodies that move on a third"),
                    Some("a fixed gear (a sun held still) is a gear on a body joined to the frame and held by an input, or the pair's carrier".into()),
                );
                return None;
            }
            ids[k] = b;
        }
        if ids[0] == ids[1] {
            let loc = self.loc(node, &bpath);
            self.error(
                loc,
                format!("{owner} meshes body `{}` with itself", names[0]),
                None,
            );
            return None;
        }
        Some(ids)
    }

    /// The common body both move on: each body's revolute joints (the
    /// rack's prismatic ones), and the one body at their other ends that
    /// both share. Fixed bodies are one body, the frame.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn gear_carrier(
        &mut self,
        pair: [usize; 2],
        rack: bool,
        entry: &Node,
        path: &str,
        owner: &str,
        bodies: &[Body],
        joints: &[(Joint, &Node)],
    ) -> Option<(Option<usize>, [usize; 2], [Point; 2])> {
        let seats = |body: usize, kind: JointKind| -> Vec<Seat> {
            (joints.iter().enumerate())
                .filter(|(_, (j, _))| j.kind == kind)
                .filter_map(|(ji, (j, _))| {
                    let k = j.markers.iter().position(|m| m.body == body)?;
                    let other = j.markers[1 - k].body;
                    Some(Seat {
                        joint: ji,
                        other: (!bodies[other].fixed).then_some(other),
                        centre: bodies[body].markers[j.markers[k].marker].at,
                    })
                })
                .collect()
        };
        let first = seats(pair[0], JointKind::Revolute);
        let second_kind = if rack {
            JointKind::Prismatic
        } else {
            JointKind::Revolute
        };
        let second = seats(pair[1], second_kind);
        let common: Vec<(&Seat, &Seat)> = (first.iter())
            .flat_map(|a| {
                second
                    .iter()
                    .filter(move |b| b.other == a.other)
                    .map(move |b| (a, b))
            })
            .filter(|(a, _)| a.other != Some(pair[1]) && a.other != Some(pair[0]))
            .collect();
        let name = |b: Option<usize>| b.map_or("the frame".to_string(), |b| format!("`{}`", bodies[b].name));
        let list = |s: &[Seat]| {
            if s.is_empty() {
                "nothing".to_string()
            } else {
                s.iter().map(|s| name(s.other)).collect::<Vec<_>>().join(", ")
            }
        };
        let (how1, how2) = if rack {
            ("turns", "slides")
        } else {
            ("turns", "turns")
        };
        match common.as_slice() {
            [(a, b)] => Some((a.other, [a.joint, b.joint], [a.centre, b.centre])),
            [] => {
                let loc = self.loc(entry, path);
                let second_joint = if rack { "a prismatic" } else { "a revolute" };
                let second_joints = if rack { "prismatic" } else { "revolute" };
                self.error(
                    loc,
                    format!(
                        "{owner}: `{}` and `{}` move on no common body: `{}` {how1} on {} (revolute joints), `{}` {how2} on {} ({second_joints} joints)",
                        bodies[pair[0]].name,
                        bodies[pair[1]].name,
                        bodies[pair[0]].name,
                        list(&first),
                        bodies[pair[1]].name,
                        list(&second),
                    ),
                    Some(format!(
                        "join each to the frame or to one carrier (an arm): `{}` by a revolute joint, `{}` by {second_joint} joint",
                        bodies[pair[0]].name, bodies[pair[1]].name
                    )),
                );
                None
            }
            several => {
                let loc = self.loc(entry, path);
                let names: Vec<String> = several.iter().map(|(a, _)| name(a.other)).collect();
                self.error(
                    loc,
                    format!(
                        "{owner}: `{}` and `{}` both move on {}, so which one carries the pair is not clear",
                        bodies[pair[0]].name,
                        bodies[pair[1]].name,
                        names.join(" and ")
                    ),
                    Some("a gear pair's bodies share exactly one carrier; remove the extra joint".into()),
                );
                None
            }
        }
    }

    /// A positive pitch radius under `key`.
    fn pitch_radius(&mut self, fields: &[(Key, Node)], entry: &Node, path: &str, key: &str) -> Option<f64> {
        let node = self.required(fields, key, entry, path)?;
        let kpath = join(path, key);
        let r = self.number(node, &kpath)?;
        if r <= 0.0 {
            let loc = self.loc(node, &kpath);
            self.error(loc, format!("`{kpath}` is {r}: a pitch radius is positive"), None);
            return None;
        }
        Some(r)
    }

    /// `pressure_angle` in degrees, from 0 up to 45 (the standard 20 when
    /// the file gives none).
    fn pressure_angle(&mut self, fields: &[(Key, Node)], path: &str) -> Option<f64> {
        let Some(node) = Self::get(fields, "pressure_angle") else {
            return Some(crate::model::planar::gears::DEFAULT_PRESSURE_ANGLE);
        };
        let ppath = join(path, "pressure_angle");
        let a = self.number(node, &ppath)?;
        if !(0.0..=45.0).contains(&a) {
            let loc = self.loc(node, &ppath);
            self.error(
                loc,
                format!("`{ppath}` is {a}: a pressure angle is from 0 to 45 degrees"),
                Some("involute gears have 14.5, 20 or 25".into()),
            );
            return None;
        }
        Some(a)
    }

    /// `radii = [rA, rB]`, both positive.
    fn radii(&mut self, fields: &[(Key, Node)], entry: &Node, path: &str) -> Option<[f64; 2]> {
        let node = self.required(fields, "radii", entry, path)?;
        let rpath = join(path, "radii");
        let r = self.point(node, &rpath)?;
        if r[0] <= 0.0 || r[1] <= 0.0 {
            let loc = self.loc(node, &rpath);
            self.error(
                loc,
                format!("`{rpath}` is [{}, {}]: pitch radii are positive", r[0], r[1]),
                None,
            );
            return None;
        }
        Some(r)
    }

    /// `mesh = "external" | "internal"`: true for internal.
    fn mesh(&mut self, fields: &[(Key, Node)], entry: &Node, path: &str, owner: &str) -> Option<bool> {
        let node = self.required(fields, "mesh", entry, path)?;
        let mpath = join(path, "mesh");
        match self.string(node, &mpath)? {
            "external" => Some(false),
            "internal" => Some(true),
            other => {
                let loc = self.loc(node, &mpath);
                self.error(
                    loc,
                    format!("{owner}: unknown mesh `{other}`"),
                    Some("expected \"external\" (two gears side by side) or \"internal\" (a pinion inside a ring)".into()),
                );
                None
            }
        }
    }
}
