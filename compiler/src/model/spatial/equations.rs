//! Spatial joints, constraints and inputs as Kramer's primitive equations
//! on body poses (docs/design/spatial.md §1.2–1.3).
//!
//! Every equation holds two marker frames in their bodies' local (= drawn)
//! coordinates. A joint's second marker without axes of its own takes the
//! first marker's as drawn (a prismatic, fixed or helical joint needs
//! "no relative rotation", and a bare point has no x to measure it by).

use dofplan_runtime::spatial::rows::{self, RowKind, WorldFrame};
use dofplan_runtime::spatial::{dot, Pose3, Vec3};

use crate::model::spatial::{Axes, Joint, JointKind, Mechanism, Primitive};
use crate::model::{InputKind, MarkerId};

/// A marker's point and axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The point.
    pub at: Vec3,
    /// The axes.
    pub axes: Axes,
}

impl Frame {
    /// The frame carried by a pose.
    pub fn moved(&self, pose: &Pose3) -> Frame {
        Frame {
            at: pose.world(self.at),
            axes: Axes {
                z: pose.dir(self.axes.z),
                x: pose.dir(self.axes.x),
            },
        }
    }
}

/// What an equation constrains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// A primitive of a joint or of a constraint written in the file.
    Prim(Primitive),
    /// An angle input: the twist of the second marker's x about the first's z.
    Angle {
        /// The input.
        input: usize,
    },
    /// A slide input: the axial distance along the first marker's z.
    Slide {
        /// The input.
        input: usize,
    },
}

impl Kind {
    /// Scalar rows.
    pub fn rows(self) -> usize {
        match self {
            Kind::Prim(p) => p.rows(),
            Kind::Angle { .. } | Kind::Slide { .. } => 1,
        }
    }

    /// The name used in explanations.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Prim(p) => p.name(),
            Kind::Angle { .. } => "angle",
            Kind::Slide { .. } => "slide",
        }
    }
}

/// One primitive equation between two bodies.
#[derive(Clone, Debug)]
pub struct Equation {
    /// What it constrains.
    pub kind: Kind,
    /// The first marker's body (owner of the line, plane or axis), then the
    /// second's.
    pub bodies: [usize; 2],
    /// The two markers.
    pub markers: [MarkerId; 2],
    /// Their frames, local (= drawn).
    pub frames: [Frame; 2],
    /// offset-z: the angle α between the z axes (radians). offset-x,
    /// helical and angle inputs: the twist angle as drawn (or as written).
    pub angle: f64,
    /// helical: the advance per turn.
    pub pitch: f64,
    /// helical and slide inputs: the axial distance as drawn.
    pub axial0: f64,
    /// parallel-z: +1 when z2 runs along z1 as drawn, −1 against it.
    pub sign: f64,
    /// Who it comes from: "joint B", "constraint K", "input theta".
    pub origin: String,
    /// Index of the joint, if it comes from one.
    pub joint: Option<usize>,
}

impl Equation {
    /// The runtime's description of its rows.
    pub fn row_kind(&self) -> RowKind {
        row_kind(self.kind, self.angle, self.pitch, self.axial0)
    }

    /// The residual rows at the given body poses and input values (the
    /// first `kind.rows()` entries of the result).
    pub fn residual(&self, poses: &[Pose3], inputs: &[f64]) -> [f64; 3] {
        let f1 = self.frames[0].moved(&poses[self.bodies[0]]);
        let f2 = self.frames[1].moved(&poses[self.bodies[1]]);
        residual_rows(self.kind, &f1, &f2, self.angle, self.pitch, self.axial0, inputs)
    }

    /// The largest absolute residual row.
    pub fn gap(&self, poses: &[Pose3], inputs: &[f64]) -> f64 {
        let r = self.residual(poses, inputs);
        r[..self.kind.rows()].iter().fold(0.0_f64, |m, v| m.max(v.abs()))
    }

    /// Whether its rows are lengths (compared with the size) rather than
    /// sines of angles.
    pub fn linear(&self) -> bool {
        matches!(
            self.kind,
            Kind::Prim(Primitive::Coincident | Primitive::InLine | Primitive::InPlane) | Kind::Slide { .. }
        )
    }
}

/// The rows of a primitive on world frames: the runtime's
/// [`RowKind::eval`], so plan checks, clusters and these residuals agree.
pub fn residual_rows(
    kind: Kind,
    f1: &Frame,
    f2: &Frame,
    angle: f64,
    pitch: f64,
    axial0: f64,
    inputs: &[f64],
) -> [f64; 3] {
    let w = |f: &Frame| WorldFrame {
        at: f.at,
        z: f.axes.z,
        x: f.axes.x,
    };
    row_kind(kind, angle, pitch, axial0).eval(&w(f1), &w(f2), inputs)
}

/// The runtime's description of an equation's rows.
pub fn row_kind(kind: Kind, angle: f64, pitch: f64, axial0: f64) -> RowKind {
    match kind {
        Kind::Prim(Primitive::Coincident) => RowKind::Coincident,
        Kind::Prim(Primitive::InLine) => RowKind::InLine,
        Kind::Prim(Primitive::InPlane) => RowKind::InPlane,
        Kind::Prim(Primitive::ParallelZ) => RowKind::ParallelZ,
        Kind::Prim(Primitive::OffsetZ) => RowKind::OffsetZ { cos: angle.cos() },
        Kind::Prim(Primitive::PerpendicularZ) => RowKind::OffsetZ { cos: 0.0 },
        Kind::Prim(Primitive::OffsetX) => RowKind::OffsetX { angle },
        Kind::Prim(Primitive::Helical) => RowKind::Helical { angle, pitch, axial0 },
        Kind::Angle { input } => RowKind::Angle { angle, input },
        Kind::Slide { input } => RowKind::Slide { axial0, input },
    }
}

/// The drawn angle a primitive keeps when the file gives none (radians):
/// offset-z the angle between the z axes, offset-x and helical the twist of
/// x2 about z1.
pub fn drawn_angle(p: Primitive, f: &[Frame; 2]) -> f64 {
    match p {
        Primitive::OffsetZ => dot(f[0].axes.z, f[1].axes.z).clamp(-1.0, 1.0).acos(),
        Primitive::OffsetX | Primitive::Helical => rows::angle_about(f[0].axes.x, f[0].axes.y(), f[1].axes.x),
        _ => 0.0,
    }
}

/// How far a primitive is from holding on drawn frames (the largest row),
/// and whether that is a length.
pub fn drawn_residual(p: Primitive, f: &[Frame; 2], angle: f64, pitch: f64) -> (f64, bool) {
    let axial0 = rows::axial(f[0].at, f[0].axes.z, f[1].at);
    let r = residual_rows(Kind::Prim(p), &f[0], &f[1], angle, pitch, axial0, &[]);
    let gap = r[..p.rows()].iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let linear = matches!(p, Primitive::Coincident | Primitive::InLine | Primitive::InPlane);
    (gap, linear)
}

/// The frames a joint's equations use, from each marker's position and
/// written axes: the second marker takes the first's axes where it has
/// none, or where the joint relates the x axes (prismatic, fixed, helical:
/// "no relative rotation as drawn", whatever x the files gave).
pub fn joint_frames(
    joint: &Joint,
    at: impl Fn(MarkerId) -> Vec3,
    axes: impl Fn(MarkerId) -> Option<Axes>,
) -> [Frame; 2] {
    let default = Axes {
        z: [0.0, 0.0, 1.0],
        x: [1.0, 0.0, 0.0],
    };
    let [a, b] = joint.markers;
    let first = axes(a).unwrap_or(default);
    let second = match joint.kind {
        JointKind::Prismatic | JointKind::Fixed | JointKind::Helical => first,
        JointKind::Universal => axes(b).unwrap_or(default),
        _ => match axes(b) {
            // The same axis, pointing as the file drew it.
            Some(s) if dot(s.z, first.z) < 0.0 => {
                let z = [-first.z[0], -first.z[1], -first.z[2]];
                // Keep x; if it is not across z (a default x may not be), take
                // the first's x, which is.
                let x = if dot(s.x, first.z).abs() < 1e-9 {
                    s.x
                } else {
                    first.x
                };
                Axes { z, x }
            }
            Some(_) | None => first,
        },
    };
    [
        Frame {
            at: at(a),
            axes: first,
        },
        Frame {
            at: at(b),
            axes: second,
        },
    ]
}

/// Every equation of a mechanism: joints' primitives in file order, then
/// constraints, then inputs.
pub fn equations(m: &Mechanism) -> Vec<Equation> {
    let mut out = Vec::new();
    let frame = |id: MarkerId| {
        let mk = m.marker(id);
        Frame {
            at: mk.at,
            axes: mk.axes.unwrap_or(Axes {
                z: [0.0, 0.0, 1.0],
                x: [1.0, 0.0, 0.0],
            }),
        }
    };
    for (ji, j) in m.joints.iter().enumerate() {
        let frames = joint_frames(j, |id| m.marker(id).at, |id| m.marker(id).axes);
        for &p in j.kind.primitives() {
            out.push(equation(
                Kind::Prim(p),
                j.markers,
                frames,
                None,
                j.pitch,
                format!("joint {}", j.name),
                Some(ji),
            ));
        }
    }
    for c in &m.constraints {
        let frames = [frame(c.markers[0]), frame(c.markers[1])];
        out.push(equation(
            Kind::Prim(c.kind),
            c.markers,
            frames,
            c.angle.map(f64::to_radians),
            c.pitch,
            format!("constraint {}", c.name),
            None,
        ));
    }
    for (ii, input) in m.inputs.iter().enumerate() {
        let j = &m.joints[input.joint];
        let frames = joint_frames(j, |id| m.marker(id).at, |id| m.marker(id).axes);
        let kind = match input.kind {
            InputKind::Angle => Kind::Angle { input: ii },
            InputKind::Slide => Kind::Slide { input: ii },
        };
        out.push(equation(
            kind,
            j.markers,
            frames,
            None,
            j.pitch,
            format!("input {}", input.name),
            Some(input.joint),
        ));
    }
    out
}

fn equation(
    kind: Kind,
    markers: [MarkerId; 2],
    frames: [Frame; 2],
    angle: Option<f64>,
    pitch: f64,
    origin: String,
    joint: Option<usize>,
) -> Equation {
    let drawn = match kind {
        Kind::Prim(p) => drawn_angle(p, &frames),
        Kind::Angle { .. } => rows::angle_about(frames[0].axes.x, frames[0].axes.y(), frames[1].axes.x),
        Kind::Slide { .. } => 0.0,
    };
    Equation {
        kind,
        bodies: [markers[0].body, markers[1].body],
        markers,
        frames,
        angle: angle.unwrap_or(drawn),
        pitch,
        axial0: rows::axial(frames[0].at, frames[0].axes.z, frames[1].at),
        sign: if dot(frames[0].axes.z, frames[1].axes.z) < 0.0 {
            -1.0
        } else {
            1.0
        },
        origin,
        joint,
    }
}
