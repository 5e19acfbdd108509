//! Validation of spatial files (`dimension = 3`): 3-coordinate markers with
//! axes, the eight joint kinds, Kramer's primitives, and which inputs fit
//! which joints. The tree walk (names, references, sweeps) is the planar
//! validator's, shared.

use dofplan_runtime::spatial::{cross, dot, norm, scale, sub, unit, Vec3};

use super::loads::JointLoad;
use super::{join, parse, source_file, Open, Validator, MAX_COORDINATE};
use crate::model::source::{At, Node, NodeKind};
use crate::model::spatial::equations::{drawn_residual, Frame};
use crate::model::spatial::loads::Spatial;
use crate::model::spatial::{Axes, Constraint, Joint, JointKind, Marker, Mechanism, Primitive};
use crate::model::{Body, InputKind, MarkerId, DRAWN_TOLERANCE};
use crate::model::{Diagnostic, Format, ModelError, SourceFile};

/// Axes closer than this to parallel (or perpendicular), as a sine or a
/// cosine, count as parallel (or perpendicular) as drawn.
const AXIS_TOLERANCE: f64 = 1e-9;

/// A spatial mechanism whose only errors, if any, are joints and
/// constraints that do not hold in the drawn pose: what `dofplan assemble`
/// starts from (the spatial twin of [`crate::model::Drawn`]). With open joints it is not a valid
/// model: only the assembly (`conflict::spatial::assemble`) may
/// use it; everything else takes `conflict::spatial::assembled`.
#[derive(Clone, Debug)]
pub struct Drawn {
    /// The mechanism, every joint and constraint included, open ones too.
    pub mechanism: Mechanism,
    /// The "does not hold in the drawn pose" errors, in file order; empty
    /// when every joint holds.
    pub open: Vec<Diagnostic>,
    /// Which joint or constraint each error is about.
    pub(crate) opened: Vec<Open>,
}

impl Drawn {
    /// How many joints and constraints do not hold in the drawn pose (a
    /// joint may have an error for each of its primitives).
    pub fn open_count(&self) -> usize {
        let mut origins: Vec<&str> = self.opened.iter().map(|o| o.origin.as_str()).collect();
        origins.sort_unstable();
        origins.dedup();
        origins.len()
    }
}

/// Validates a spatial mechanism given as text like `dofplan::load_any_str`, but
/// returns it even when joints or constraints do not hold in the drawn pose
/// (with those errors). Every other error is still an error, and so is a
/// planar file.
pub fn load_str_drawn(file_name: &str, text: &str, format: Format) -> Result<Drawn, ModelError> {
    let file = source_file(file_name, text);
    let root = parse(&file, format)?;
    drawn(file.clone(), &root, format)
}

/// The spatial validation of a parsed file, open joints allowed.
pub(super) fn drawn(file: SourceFile, root: &Node, format: Format) -> Result<Drawn, ModelError> {
    let mut v = Validator::new(file, format);
    match v.mechanism3(root) {
        // Only joints open in the drawn pose (or none): the least-squares
        // assembly says whether the drawing is only off or the joints
        // conflict (`conflict::spatial::assembled`).
        Some(m) if v.diags.len() == v.open.len() => Ok(Drawn {
            mechanism: m,
            open: v.diags,
            opened: v.open,
        }),
        _ => Err(ModelError { diagnostics: v.diags }),
    }
}

impl Validator {
    pub(super) fn mechanism3(&mut self, root: &Node) -> Option<Mechanism> {
        let (top, name) = self.top(root)?;
        let bodies = match self.required(top, "bodies", root, "") {
            Some(n) => self.bodies(n, Self::marker3),
            None => Vec::new(),
        };
        let size = {
            let d = crate::model::extent(bodies.iter().flat_map(|b| &b.markers).map(|m| &m.at[..]));
            if d.is_finite() && d > 0.0 {
                d
            } else {
                1.0
            }
        };
        let empty = Node {
            at: At::NONE,
            kind: NodeKind::Table(Vec::new()),
        };
        let joints_node = Self::get(top, "joints").unwrap_or(&empty);
        let constraints_node = Self::get(top, "constraints").unwrap_or(&empty);
        let joints = self.joints3(joints_node, &bodies, size);
        let constraints = self.constraints3(constraints_node, &bodies, size);
        self.cross_duplicates(joints_node, constraints_node);
        let inputs = match Self::get(top, "inputs") {
            Some(n) => self.inputs(n, joints_node, &joints, &bodies),
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
                turns: matches!(j.kind, JointKind::Revolute | JointKind::Cylindrical),
            })
            .collect();
        let loads = self.loads::<Spatial, _>(top, Self::get(top, "bodies"), &bodies, &turning);
        Some(Mechanism {
            name: name?,
            bodies,
            joints: self.with_lines(joints, |j, line| j.line = line),
            constraints,
            inputs,
            sweep,
            loads,
            source: self.file.clone(),
        })
    }

    /// `[x, y, z]`.
    fn vec3(&mut self, node: &Node, path: &str) -> Option<Vec3> {
        self.coords(node, path)
    }

    /// A direction: non-zero, normalisable.
    fn axis(&mut self, marker: &str, node: &Node, path: &str, which: &str) -> Option<Vec3> {
        let v = self.vec3(node, path)?;
        let n = norm(v);
        if !(n * n).is_normal() {
            let loc = self.loc(node, path);
            let what = if n == 0.0 {
                "a zero"
            } else {
                "a too short or too long"
            };
            self.error(
                loc,
                format!("marker `{marker}` has {what} {which} axis"),
                Some(format!(
                    "an axis needs a non-zero length, e.g. {which} = [0, 0, 1]"
                )),
            );
            return None;
        }
        Some(scale(v, 1.0 / n))
    }

    fn marker3(&mut self, body: &str, short: &str, node: &Node, path: &str) -> Option<Marker> {
        let name = format!("{body}.{short}");
        let position = |v: &mut Self, n: &Node, p: &str| -> Option<Vec3> {
            let at = v.vec3(n, p)?;
            if let Some(c) = at.iter().find(|c| c.abs() > MAX_COORDINATE) {
                let loc = v.loc(n, p);
                v.error(
                    loc,
                    format!(
                        "marker `{name}` has a coordinate {c:e}, too far from the origin to compute with"
                    ),
                    Some(format!(
                        "rescale the drawing (units are free): coordinates up to {MAX_COORDINATE:e} work"
                    )),
                );
                return None;
            }
            Some(at)
        };
        match &node.kind {
            NodeKind::Array(_) => Some(Marker {
                name: short.to_string(),
                at: position(self, node, path)?,
                axes: None,
            }),
            NodeKind::Table(fields) => {
                if let Some((k, _)) = fields.iter().find(|(k, _)| k.name == "dir") {
                    let loc = self.key_loc(k, &join(path, "dir"));
                    self.error(
                        loc,
                        format!("marker `{name}`: in 3D a marker has `z` (and `x`) instead of `dir`"),
                        Some(format!("write {short} = {{ at = [x, y, z], z = [zx, zy, zz] }}")),
                    );
                    return None;
                }
                self.check_keys(fields, &["at", "z", "x"], path);
                let at = self
                    .required(fields, "at", node, path)
                    .and_then(|n| position(self, n, &join(path, "at")));
                let z = match Self::get(fields, "z") {
                    Some(n) => Some(self.axis(&name, n, &join(path, "z"), "z")?),
                    None => None,
                };
                let x = match Self::get(fields, "x") {
                    Some(n) => Some((self.axis(&name, n, &join(path, "x"), "x")?, n)),
                    None => None,
                };
                let axes = match (z, x) {
                    (None, None) => None,
                    (None, Some((_, n))) => {
                        let loc = self.loc(n, &join(path, "x"));
                        self.error(
                            loc,
                            format!("marker `{name}` has an x axis but no z"),
                            Some("x is the reference of angles about z: give z too".into()),
                        );
                        return None;
                    }
                    (Some(z), None) => Some(Axes::from_z(z)),
                    (Some(z), Some((x, n))) => {
                        let c = dot(z, x);
                        if c.abs() > AXIS_TOLERANCE {
                            let loc = self.loc(n, &join(path, "x"));
                            let near = unit(sub(x, scale(z, c)));
                            self.error(
                                loc,
                                format!(
                                    "marker `{name}`: x is not perpendicular to z (angle {:.4}°)",
                                    c.clamp(-1.0, 1.0).acos().to_degrees()
                                ),
                                Some(format!(
                                    "the nearest perpendicular x is [{}, {}, {}]",
                                    short_num(near[0]),
                                    short_num(near[1]),
                                    short_num(near[2])
                                )),
                            );
                            return None;
                        }
                        Some(Axes { z, x })
                    }
                };
                Some(Marker {
                    name: short.to_string(),
                    at: at?,
                    axes,
                })
            }
            other => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!(
                        "marker `{name}` must be [x, y, z] or {{ at = [x, y, z], z = [..], x = [..] }}, found {}",
                        other.type_name()
                    ),
                    None,
                );
                None
            }
        }
    }

    /// `pitch = p` of a helical joint or constraint: required, finite,
    /// non-zero.
    fn pitch(&mut self, entry: &Node, path: &str, owner: &str) -> Option<f64> {
        let NodeKind::Table(fields) = &entry.kind else {
            return None;
        };
        let n = self.required(fields, "pitch", entry, path)?;
        let p = self.number(n, &join(path, "pitch"))?;
        if p == 0.0 {
            let loc = self.loc(n, &join(path, "pitch"));
            self.error(
                loc,
                format!("{owner}: `pitch` must not be 0"),
                Some("pitch is the advance per turn: > 0 right-handed, < 0 left-handed".into()),
            );
            return None;
        }
        Some(p)
    }

    fn joints3<'n>(
        &mut self,
        node: &'n Node<'n>,
        bodies: &[Body<Marker>],
        size: f64,
    ) -> Vec<(Joint, &'n Node<'n>)> {
        let kinds: Vec<&str> = JointKind::ALL.iter().map(|k| k.name()).collect();
        let found = self.connections(
            node,
            bodies,
            "joints",
            "joint",
            (&kinds, &["pitch"], &[]),
            |v, kind, markers, entry, path, owner| {
                let kind = JointKind::from_name(kind)?;
                let pitch = match kind {
                    JointKind::Helical => v.pitch(entry, path, owner)?,
                    _ => {
                        if let NodeKind::Table(f) = &entry.kind {
                            if let Some(n) = Self::get(f, "pitch") {
                                let loc = v.loc(n, &join(path, "pitch"));
                                v.error(
                                    loc,
                                    format!("{owner}: only a helical joint has a `pitch`"),
                                    Some(format!(
                                        "remove it, or make the joint kind = \"helical\" (it is {})",
                                        kind.name()
                                    )),
                                );
                                return None;
                            }
                        }
                        0.0
                    }
                };
                v.check_joint_axes(kind, markers, bodies, entry, path, owner)?;
                let joint = Joint {
                    name: String::new(),
                    kind,
                    markers,
                    pitch,
                    line: None,
                };
                let frames = joint_frames(&joint, bodies);
                for &p in kind.primitives() {
                    v.check_drawn(p, &frames, 0.0, pitch, bodies, markers, entry, path, owner, size);
                }
                Some((kind, pitch))
            },
        );
        found
            .into_iter()
            .map(|(name, (kind, pitch), markers, entry)| {
                (
                    Joint {
                        name,
                        kind,
                        markers,
                        pitch,
                        line: None,
                    },
                    entry,
                )
            })
            .collect()
    }

    /// The axes a joint needs: the first marker's z for axial joints (the
    /// second's, if written, parallel to it); both z for a universal joint,
    /// perpendicular.
    fn check_joint_axes(
        &mut self,
        kind: JointKind,
        markers: [MarkerId; 2],
        bodies: &[Body<Marker>],
        entry: &Node,
        path: &str,
        owner: &str,
    ) -> Option<()> {
        let name = |id: MarkerId| {
            format!(
                "{}.{}",
                bodies[id.body].name, bodies[id.body].markers[id.marker].name
            )
        };
        let axes = |id: MarkerId| bodies[id.body].markers[id.marker].axes;
        let loc = self.loc(entry, path);
        if kind == JointKind::Universal {
            let mut ok = true;
            for id in markers {
                if axes(id).is_none() {
                    ok = false;
                    self.error(
                        loc.clone(),
                        format!(
                            "{owner}: a universal joint's markers carry its two crosspin axes, but `{}` has no z",
                            name(id)
                        ),
                        Some("give both markers a z: { at = [x, y, z], z = [..] }".into()),
                    );
                }
            }
            if !ok {
                return None;
            }
            let (a, b) = (axes(markers[0]).unwrap().z, axes(markers[1]).unwrap().z);
            if dot(a, b).abs() > AXIS_TOLERANCE {
                self.error(
                    loc,
                    format!(
                        "{owner}: the crosspin axes of `{}` and `{}` are at {:.4}°, not perpendicular as drawn",
                        name(markers[0]),
                        name(markers[1]),
                        dot(a, b).clamp(-1.0, 1.0).acos().to_degrees()
                    ),
                    Some("a universal joint's two z axes must be perpendicular in the drawing".into()),
                );
                return None;
            }
            return Some(());
        }
        if !kind.needs_axis() {
            return Some(());
        }
        let Some(first) = axes(markers[0]) else {
            self.error(
                loc,
                format!(
                    "{owner}: the first marker of a {} joint carries its axis, but `{}` has no z",
                    kind.name(),
                    name(markers[0])
                ),
                Some("give it a z: { at = [x, y, z], z = [..] }".into()),
            );
            return None;
        };
        if let Some(second) = axes(markers[1]) {
            let s = norm(cross(first.z, second.z));
            if s > AXIS_TOLERANCE {
                self.error_notes(
                    loc,
                    format!(
                        "{owner}: the axes of `{}` and `{}` are {:.4}° apart, not parallel as drawn",
                        name(markers[0]),
                        name(markers[1]),
                        s.clamp(-1.0, 1.0).asin().to_degrees()
                    ),
                    vec![],
                    Some(format!(
                        "the joint's axis is the first marker's z; give `{}` the same z (or ±) or none",
                        name(markers[1])
                    )),
                );
                return None;
            }
        }
        Some(())
    }

    /// Whether primitive `p` holds in the drawn pose (an error if not).
    #[allow(clippy::too_many_arguments)]
    fn check_drawn(
        &mut self,
        p: Primitive,
        frames: &[Frame; 2],
        angle: f64,
        pitch: f64,
        bodies: &[Body<Marker>],
        markers: [MarkerId; 2],
        entry: &Node,
        path: &str,
        owner: &str,
        size: f64,
    ) {
        let (gap, linear) = drawn_residual(p, frames, angle, pitch);
        let tol = if linear {
            DRAWN_TOLERANCE * size
        } else {
            AXIS_TOLERANCE
        };
        if gap > tol {
            let name = |id: MarkerId| {
                format!(
                    "{}.{}",
                    bodies[id.body].name, bodies[id.body].markers[id.marker].name
                )
            };
            let what = match p {
                Primitive::Coincident => format!(
                    "{} and {} are {gap:.3e} apart",
                    name(markers[0]),
                    name(markers[1])
                ),
                Primitive::InLine => format!(
                    "{} is {gap:.3e} off the line of {}",
                    name(markers[1]),
                    name(markers[0])
                ),
                Primitive::InPlane => format!(
                    "{} is {gap:.3e} off the plane of {}",
                    name(markers[1]),
                    name(markers[0])
                ),
                _ => format!(
                    "the {} rows of {} and {} miss by {gap:.3e} (a sine of the angle)",
                    p.name(),
                    name(markers[0]),
                    name(markers[1])
                ),
            };
            let loc = self.loc(entry, path);
            self.error(
                loc,
                format!("{owner} does not hold in the drawn pose ({}): {what}", p.name()),
                Some(
                    "markers are world coordinates of the pose as drawn: the joined markers must satisfy the joint there"
                        .into(),
                ),
            );
            self.opened(owner);
        }
    }

    fn constraints3(&mut self, node: &Node, bodies: &[Body<Marker>], size: f64) -> Vec<Constraint> {
        let kinds: Vec<&str> = Primitive::ALL.iter().map(|k| k.name()).collect();
        let found = self.connections(
            node,
            bodies,
            "constraints",
            "constraint",
            (&kinds, &["angle", "pitch"], &[]),
            |v, kind, markers, entry, path, owner| {
                let kind = Primitive::from_name(kind)?;
                let NodeKind::Table(fields) = &entry.kind else {
                    return None;
                };
                let name = |id: MarkerId| format!("{}.{}", bodies[id.body].name, bodies[id.body].markers[id.marker].name);
                let mut ok = true;
                for (i, id) in markers.into_iter().enumerate() {
                    let needs = if i == 0 {
                        kind.first_needs_axis()
                    } else {
                        kind.second_needs_axis()
                    };
                    if needs && bodies[id.body].markers[id.marker].axes.is_none() {
                        ok = false;
                        let loc = v.loc(entry, path);
                        v.error(
                            loc,
                            format!(
                                "{owner}: {} needs the {} marker's z, but `{}` has none",
                                kind.name(),
                                if i == 0 { "first" } else { "second" },
                                name(id)
                            ),
                            Some("give it a z: { at = [x, y, z], z = [..] }".into()),
                        );
                    }
                }
                let angle = match Self::get(fields, "angle") {
                    None => None,
                    Some(n) => {
                        let a = v.number(n, &join(path, "angle"));
                        if !matches!(kind, Primitive::OffsetZ | Primitive::OffsetX) {
                            let loc = v.loc(n, &join(path, "angle"));
                            v.error(
                                loc,
                                format!("{owner}: only offset-z and offset-x take an `angle`"),
                                Some(format!("remove it ({} has none)", kind.name())),
                            );
                            ok = false;
                        } else if kind == Primitive::OffsetZ {
                            if let Some(a) = a {
                                if a <= 0.0 || a >= 180.0 {
                                    let loc = v.loc(n, &join(path, "angle"));
                                    v.error(
                                        loc,
                                        format!("{owner}: offset-z takes an angle strictly between 0° and 180°, not {a}"),
                                        Some("for z axes kept parallel (0°) or opposed (180°) use parallel-z".into()),
                                    );
                                    ok = false;
                                }
                            }
                        }
                        a
                    }
                };
                let pitch = match kind {
                    Primitive::Helical => v.pitch(entry, path, owner),
                    _ => {
                        if let Some(n) = Self::get(fields, "pitch") {
                            let loc = v.loc(n, &join(path, "pitch"));
                            v.error(loc, format!("{owner}: only a helical constraint has a `pitch`"), None);
                            ok = false;
                        }
                        Some(0.0)
                    }
                };
                if !ok {
                    return None;
                }
                let pitch = pitch?;
                let frames = [frame_of(bodies, markers[0], None), frame_of(bodies, markers[1], None)];
                let drawn = crate::model::spatial::equations::drawn_angle(kind, &frames);
                v.check_drawn(
                    kind,
                    &frames,
                    angle.map_or(drawn, f64::to_radians),
                    pitch,
                    bodies,
                    markers,
                    entry,
                    path,
                    owner,
                    size,
                );
                Some((kind, angle, pitch))
            },
        );
        found
            .into_iter()
            .map(|(name, (kind, angle, pitch), markers, _)| Constraint {
                name,
                kind,
                markers,
                angle,
                pitch,
            })
            .collect()
    }
}

/// The world frame of a marker as drawn; `borrow` stands in for missing
/// axes (a joint's second marker takes the first's).
fn frame_of(bodies: &[Body<Marker>], id: MarkerId, borrow: Option<Axes>) -> Frame {
    let m = &bodies[id.body].markers[id.marker];
    let axes = m.axes.or(borrow).unwrap_or(Axes {
        z: [0.0, 0.0, 1.0],
        x: [1.0, 0.0, 0.0],
    });
    Frame { at: m.at, axes }
}

/// The drawn frames of a joint's two markers, as its equations use them.
pub(crate) fn joint_frames(joint: &Joint, bodies: &[Body<Marker>]) -> [Frame; 2] {
    crate::model::spatial::equations::joint_frames(
        joint,
        |id| frame_of(bodies, id, None).at,
        |id| bodies[id.body].markers[id.marker].axes,
    )
}

/// A number for a help text: short, and 0 for round-off.
fn short_num(v: f64) -> String {
    if v.abs() < 1e-12 {
        "0".into()
    } else {
        format!("{}", (v * 1e6).round() / 1e6)
    }
}

impl super::JointLike for Joint {
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
        let fits = match kind {
            InputKind::Angle => self.kind.takes_angle(),
            InputKind::Slide => self.kind.takes_slide(),
        };
        if fits {
            return None;
        }
        let help = match self.kind {
            JointKind::Spherical | JointKind::Universal | JointKind::Planar => format!(
                "joint `{}` has {} freedoms; an input needs a 1-DOF joint or a cylindrical joint",
                self.name,
                6 - self.kind.equations()
            ),
            JointKind::Fixed => format!("joint `{}` is fixed: nothing to drive", self.name),
            k if k.takes_angle() => "use kind = \"angle\"".into(),
            _ => "use kind = \"slide\"".into(),
        };
        Some(format!(
            "{help} (angle: revolute, cylindrical; slide: prismatic, cylindrical, helical)"
        ))
    }
    fn takes_both(&self) -> bool {
        self.kind == JointKind::Cylindrical
    }
}
