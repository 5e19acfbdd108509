//! Spatial (3D) mechanisms: markers with a z and an x axis, the eight joint
//! kinds and Kramer's primitive constraints (`dimension = 3` files).
//!
//! The conventions are the planar ones lifted to space: markers are given
//! in world coordinates of the drawn pose, so every body's drawn pose is the
//! identity; the first marker of a joint or constraint owns the axis, line,
//! plane or reference direction, and the second is constrained (Kramer
//! writes in-line and in-plane the other way round; docs/design/spatial.md §6).

use super::{Body, Input, MarkerId, MarkerLike, SourceFile, Sweep};

pub mod equations;
pub mod loads;

pub use dofplan_runtime::spatial::Vec3;

pub use super::load::spatial::{load_str_drawn, Drawn};

/// A validated spatial mechanism.
#[derive(Clone, Debug)]
pub struct Mechanism {
    /// Its name (also the generated module's name).
    pub name: String,
    /// Bodies in file order.
    pub bodies: Vec<Body<Marker>>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// Primitive constraints written directly, in file order.
    pub constraints: Vec<Constraint>,
    /// Driving inputs in file order (angle: degrees about the joint's first
    /// marker's z; slide: length along it).
    pub inputs: Vec<Input>,
    /// The sweep to simulate, if the file has one.
    pub sweep: Option<Sweep>,
    /// Masses, gravity and applied loads (empty if the file gives none).
    pub loads: loads::Loads,
    /// The file it came from.
    pub source: SourceFile,
}

/// A marker's orthonormal axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axes {
    /// Unit z axis (the joint axis, the line's direction, the plane's normal).
    pub z: Vec3,
    /// Unit x axis, perpendicular to z (the reference of angles about z).
    pub x: Vec3,
}

impl Axes {
    /// y = z × x, completing a right-handed frame.
    pub fn y(&self) -> Vec3 {
        dofplan_runtime::spatial::cross(self.z, self.x)
    }

    /// The axes of a z alone: x is the world axis least aligned with z, made
    /// perpendicular to it (ties broken x, then y, then z), so a file that
    /// gives only z always gets the same x.
    pub fn from_z(z: Vec3) -> Axes {
        use dofplan_runtime::spatial::{dot, scale, sub, unit};
        let z = unit(z);
        let mut best = 0;
        for k in 1..3 {
            if z[k].abs() < z[best].abs() {
                best = k;
            }
        }
        let mut e = [0.0; 3];
        e[best] = 1.0;
        let x = unit(sub(e, scale(z, dot(e, z))));
        Axes { z, x }
    }
}

/// A named point on a body, optionally with axes.
#[derive(Clone, Debug)]
pub struct Marker {
    /// Name, unique on its body.
    pub name: String,
    /// World position in the pose as drawn.
    pub at: Vec3,
    /// Its axes, if the file gives a z.
    pub axes: Option<Axes>,
}

impl MarkerLike for Marker {
    fn name(&self) -> &str {
        &self.name
    }
    fn coords(&self) -> &[f64] {
        &self.at
    }
}

/// A joint between markers of two bodies.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// Kind.
    pub kind: JointKind,
    /// The two markers, in file order; the first owns the joint's axis.
    pub markers: [MarkerId; 2],
    /// The helical joint's advance per turn (> 0 right-handed); 0 otherwise.
    pub pitch: f64,
    /// The line it is written on (1-based), for a joint read from a TOML
    /// file; `None` for JSON and for mechanisms built in code.
    pub line: Option<usize>,
}

/// The kinds of spatial joint, each a set of primitive constraints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum JointKind {
    /// Coincident + parallel-z: one rotation about the axis.
    Revolute,
    /// In-line + offset-x as drawn: one slide along the axis.
    Prismatic,
    /// In-line + parallel-z: a slide along and a rotation about the axis.
    Cylindrical,
    /// Coincident: three rotations about the point.
    Spherical,
    /// Coincident + perpendicular-z (the two crosspin axes): two rotations.
    Universal,
    /// In-plane + parallel-z: two slides in the plane and a rotation about
    /// its normal.
    Planar,
    /// Coincident + offset-x as drawn: no relative motion.
    Fixed,
    /// In-line + helical: a screw motion along the axis.
    Helical,
}

impl JointKind {
    /// Every kind, in the order errors list them.
    pub const ALL: [JointKind; 8] = [
        JointKind::Revolute,
        JointKind::Prismatic,
        JointKind::Cylindrical,
        JointKind::Spherical,
        JointKind::Universal,
        JointKind::Planar,
        JointKind::Fixed,
        JointKind::Helical,
    ];

    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
            JointKind::Cylindrical => "cylindrical",
            JointKind::Spherical => "spherical",
            JointKind::Universal => "universal",
            JointKind::Planar => "planar",
            JointKind::Fixed => "fixed",
            JointKind::Helical => "helical",
        }
    }

    /// The kind named `name` in a file.
    pub fn from_name(name: &str) -> Option<JointKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The primitive constraints the joint is made of, in the order the
    /// planner meets them (position before orientation, as Kramer's
    /// revolute: coincident, then parallel-z).
    pub fn primitives(self) -> &'static [Primitive] {
        use Primitive::*;
        match self {
            JointKind::Revolute => &[Coincident, ParallelZ],
            JointKind::Prismatic => &[InLine, OffsetX],
            JointKind::Cylindrical => &[InLine, ParallelZ],
            JointKind::Spherical => &[Coincident],
            JointKind::Universal => &[Coincident, PerpendicularZ],
            JointKind::Planar => &[InPlane, ParallelZ],
            JointKind::Fixed => &[Coincident, OffsetX],
            JointKind::Helical => &[InLine, Helical],
        }
    }

    /// Scalar equations the joint imposes.
    pub fn equations(self) -> usize {
        self.primitives().iter().map(|p| p.rows()).sum()
    }

    /// Whether the first marker must carry a z axis (the joint's axis).
    pub fn needs_axis(self) -> bool {
        !matches!(self, JointKind::Spherical | JointKind::Fixed)
    }

    /// Whether an angle input can drive it.
    pub fn takes_angle(self) -> bool {
        matches!(self, JointKind::Revolute | JointKind::Cylindrical)
    }

    /// Whether a slide input can drive it.
    pub fn takes_slide(self) -> bool {
        matches!(
            self,
            JointKind::Prismatic | JointKind::Cylindrical | JointKind::Helical
        )
    }
}

/// Kramer's primitive constraints between two markers (m1, m2); m1 owns the
/// line, plane or reference axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Primitive {
    /// p2 = p1 (3 equations).
    Coincident,
    /// p2 on the line (p1, z1) (2 equations).
    InLine,
    /// p2 on the plane (p1, normal z1) (1 equation).
    InPlane,
    /// z2 = ±z1, the sign as drawn (2 equations).
    ParallelZ,
    /// angle(z1, z2) = α (1 equation).
    OffsetZ,
    /// angle(z1, z2) = 90° (1 equation).
    PerpendicularZ,
    /// z2 = z1 and x2 at angle α from x1 about z1 (3 equations).
    OffsetX,
    /// z2 = z1 and the angle of x2 about z1 advances 360° per `pitch` of
    /// axial distance (3 equations).
    Helical,
}

impl Primitive {
    /// Every primitive, in the order errors list them.
    pub const ALL: [Primitive; 8] = [
        Primitive::Coincident,
        Primitive::InLine,
        Primitive::InPlane,
        Primitive::ParallelZ,
        Primitive::OffsetZ,
        Primitive::PerpendicularZ,
        Primitive::OffsetX,
        Primitive::Helical,
    ];

    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            Primitive::Coincident => "coincident",
            Primitive::InLine => "in-line",
            Primitive::InPlane => "in-plane",
            Primitive::ParallelZ => "parallel-z",
            Primitive::OffsetZ => "offset-z",
            Primitive::PerpendicularZ => "perpendicular-z",
            Primitive::OffsetX => "offset-x",
            Primitive::Helical => "helical",
        }
    }

    /// The primitive named `name` in a file.
    pub fn from_name(name: &str) -> Option<Primitive> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Scalar equations.
    pub fn rows(self) -> usize {
        match self {
            Primitive::Coincident | Primitive::OffsetX | Primitive::Helical => 3,
            Primitive::InLine | Primitive::ParallelZ => 2,
            Primitive::InPlane | Primitive::OffsetZ | Primitive::PerpendicularZ => 1,
        }
    }

    /// Whether the first marker needs a z axis.
    pub fn first_needs_axis(self) -> bool {
        self != Primitive::Coincident
    }

    /// Whether the second marker needs a z axis.
    pub fn second_needs_axis(self) -> bool {
        matches!(
            self,
            Primitive::ParallelZ
                | Primitive::OffsetZ
                | Primitive::PerpendicularZ
                | Primitive::OffsetX
                | Primitive::Helical
        )
    }
}

/// A primitive constraint written directly in the file.
#[derive(Clone, Debug)]
pub struct Constraint {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// The primitive.
    pub kind: Primitive,
    /// The two markers.
    pub markers: [MarkerId; 2],
    /// offset-z and offset-x: the angle in degrees (as drawn when the file
    /// gives none, and then equal to the drawn angle).
    pub angle: Option<f64>,
    /// helical: the advance per turn.
    pub pitch: f64,
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
        super::find_marker(&self.bodies, name)
    }

    /// Every marker, body by body, in file order.
    pub fn all_markers(&self) -> impl Iterator<Item = MarkerId> + '_ {
        super::all_markers(&self.bodies)
    }

    /// The size of the mechanism: the diagonal of its markers' bounding box
    /// as drawn (1 if they all coincide). Tolerances are relative to it.
    pub fn size(&self) -> f64 {
        let d = super::extent(self.bodies.iter().flat_map(|b| &b.markers).map(|m| m.coords()));
        if d.is_finite() && d > 0.0 {
            d
        } else {
            1.0
        }
    }

    /// Moving bodies (every body not fixed).
    pub fn moving(&self) -> usize {
        self.bodies.iter().filter(|b| !b.fixed).count()
    }
}
