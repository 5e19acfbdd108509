//! Planar mechanisms: markers at a point with a direction, revolute and
//! prismatic joints, and the primitive constraints of the plane.

pub mod equations;
pub mod gears;
pub mod loads;
pub mod slots;

use dofplan_runtime::Point;

use super::{all_markers, find_marker, Body, Input, MarkerId, MarkerLike, SourceFile, Sweep};

/// A validated mechanism.
#[derive(Clone, Debug)]
pub struct Mechanism {
    /// Its name (also the generated module's name).
    pub name: String,
    /// 2: a planar mechanism ([`spatial::Mechanism`](crate::model::spatial::Mechanism) holds 3D ones).
    pub dimension: u8,
    /// Bodies in file order.
    pub bodies: Vec<Body>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// Primitive constraints written directly, in file order.
    pub constraints: Vec<Constraint>,
    /// Gear pairs and racks and pinions (`[joints]` entries that mesh two
    /// bodies rather than join two markers), in file order.
    pub gears: Vec<gears::Gear>,
    /// Pins in straight slots (`[joints]` entries of kind `slot`), in file
    /// order.
    pub slots: Vec<slots::Slot>,
    /// Driving inputs in file order.
    pub inputs: Vec<Input>,
    /// The sweep to simulate, if the file has one.
    pub sweep: Option<Sweep>,
    /// Masses, gravity and applied loads (empty if the file gives none).
    pub loads: loads::Loads,
    /// The file it came from.
    pub source: SourceFile,
}

impl MarkerLike for Marker {
    fn name(&self) -> &str {
        &self.name
    }
    fn coords(&self) -> &[f64] {
        &self.at
    }
}

/// A named point on a body, optionally with a direction.
#[derive(Clone, Debug)]
pub struct Marker {
    /// Name, unique on its body.
    pub name: String,
    /// World position in the pose as drawn.
    pub at: Point,
    /// Direction as written (not normalised), if any.
    pub dir: Option<Point>,
}

impl Marker {
    /// The direction scaled to unit length.
    pub fn unit_dir(&self) -> Option<Point> {
        self.dir.map(|d| {
            let n = (d[0] * d[0] + d[1] * d[1]).sqrt();
            [d[0] / n, d[1] / n]
        })
    }
}

/// A joint between markers of two bodies.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// Kind.
    pub kind: JointKind,
    /// The two markers, in file order.
    pub markers: [MarkerId; 2],
    /// The line it is written on (1-based), for a joint read from a TOML
    /// file; `None` for JSON and for mechanisms built in code.
    pub line: Option<usize>,
}

/// The kinds of joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// The two markers coincide (one relative rotation left).
    Revolute,
    /// The second marker slides along the first marker's direction and the
    /// bodies never turn relative to each other (one relative slide left).
    Prismatic,
}

impl JointKind {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        }
    }
}

/// A primitive constraint between two markers (Kramer's, as Brunkhart §5.1
/// uses them).
#[derive(Clone, Debug)]
pub struct Constraint {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// Kind.
    pub kind: ConstraintKind,
    /// The two markers.
    pub markers: [MarkerId; 2],
}

/// Primitive constraint kinds in 2D.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintKind {
    /// The markers coincide (2 equations).
    Coincident,
    /// The second marker lies on the line of the first marker's direction
    /// (1 equation).
    InLine,
    /// The angle between the markers' directions stays as drawn (1 equation).
    Offset,
}

impl ConstraintKind {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            ConstraintKind::Coincident => "coincident",
            ConstraintKind::InLine => "in-line",
            ConstraintKind::Offset => "offset",
        }
    }
}

impl Mechanism {
    /// A marker by id.
    pub fn marker(&self, id: MarkerId) -> &Marker {
        &self.bodies[id.body].markers[id.marker]
    }

    /// "body.marker".
    pub fn marker_name(&self, id: MarkerId) -> String {
        format!(
            "{}.{}",
            self.bodies[id.body].name, self.bodies[id.body].markers[id.marker].name
        )
    }

    /// Looks a marker up by "body.marker".
    pub fn find_marker(&self, name: &str) -> Option<MarkerId> {
        find_marker(&self.bodies, name)
    }

    /// Every marker, body by body, in file order.
    pub fn all_markers(&self) -> impl Iterator<Item = MarkerId> + '_ {
        all_markers(&self.bodies)
    }

    /// The pairs of markers held on one point: those of every revolute
    /// joint and every coincident constraint, in file order.
    pub fn coincident_pairs(&self) -> impl Iterator<Item = [MarkerId; 2]> + '_ {
        let joints = self.joints.iter().filter(|j| j.kind == JointKind::Revolute);
        let constraints = (self.constraints.iter()).filter(|c| c.kind == ConstraintKind::Coincident);
        joints.map(|j| j.markers).chain(constraints.map(|c| c.markers))
    }

    /// The size of the mechanism: the diagonal of its markers' bounding box
    /// as drawn (1 if they all coincide). Tolerances are relative to it.
    pub fn size(&self) -> f64 {
        size_of(&self.bodies)
    }

    /// The gear pairs' names, `sp, pr`: for the messages of what does not
    /// handle them.
    pub fn gear_names(&self) -> String {
        self.gears
            .iter()
            .map(|g| g.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The gear pair (or rack and pinion) named `name`.
    pub fn gear(&self, name: &str) -> Option<&gears::Gear> {
        self.gears.iter().find(|g| g.name == name)
    }

    /// Number of links in Grübler's sense: every mobile body plus one for
    /// the ground (all fixed bodies together).
    pub fn links(&self) -> usize {
        self.bodies.iter().filter(|b| !b.fixed).count() + 1
    }
}

/// [`Mechanism::size`] of a mechanism with these bodies.
pub(crate) fn size_of(bodies: &[Body]) -> f64 {
    // The runtime measures a compiled candidate's drawing the same way.
    let points: Vec<[f64; 2]> = bodies.iter().flat_map(|b| &b.markers).map(|m| m.at).collect();
    dofplan_runtime::design::size(&points)
}
