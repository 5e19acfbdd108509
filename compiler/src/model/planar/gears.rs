//! Higher pairs of the plane: gear pairs and rack and pinion.
//!
//! Each couples the motions of two bodies that move on one common third
//! body, the *carrier* (the frame, or an arm): two gears that each turn
//! about a revolute joint on it, or a pinion that turns on it and a rack
//! that slides on it. Rolling without slip at the pitch point makes the
//! coupling linear in the relative motions, so one relative angle (or
//! slide) is set from the other: a closed-form plan step, one scalar
//! equation (a higher pair in Grübler's count).

use dofplan_runtime::Point;

/// A gear pair or a rack and pinion, as validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Gear {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// What meshes.
    pub kind: GearKind,
    /// The two bodies in file order (for a rack and pinion: pinion, rack).
    pub bodies: [usize; 2],
    /// The common third body both move on; `None` for the frame (every
    /// fixed body together).
    pub carrier: Option<usize>,
    /// Index into the mechanism's joints of each body's joint with the
    /// carrier (revolute; the rack's is prismatic).
    pub pivots: [usize; 2],
    /// Each body's pivot (the rack's slide marker) as drawn.
    pub centres: [Point; 2],
    /// The line it is written on (1-based), TOML only.
    pub line: Option<usize>,
}

/// The kinds of higher pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GearKind {
    /// Two gears, pitch radii in body order.
    Gear {
        /// Pitch radii.
        radii: [f64; 2],
        /// Internal mesh: the larger gear is a ring with internal teeth.
        internal: bool,
        /// The pressure angle in degrees: the tooth force's line of action
        /// leans this far from the common tangent (20 unless the file
        /// gives `pressure_angle`).
        pressure_angle: f64,
    },
    /// A pinion of pitch radius `radius` and a rack.
    RackPinion {
        /// The pinion's pitch radius.
        radius: f64,
        /// The rack's unit slide direction (the prismatic joint's, in the
        /// carrier's frame, as drawn).
        dir: Point,
        /// +1 when the rack lies to the left of the slide direction through
        /// the pinion's pivot, −1 to the right (from the drawing).
        side: f64,
        /// The pressure angle in degrees (as for gears).
        pressure_angle: f64,
    },
}

impl GearKind {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            GearKind::Gear { .. } => "gear",
            GearKind::RackPinion { .. } => "rack-pinion",
        }
    }
}

/// The pressure angle a gear pair has when its file gives none: the
/// standard involute tooth's.
pub const DEFAULT_PRESSURE_ANGLE: f64 = 20.0;

/// Where the teeth of a pair push, in the carrier's frame as drawn: the
/// pitch point, the common tangent (the tooth force's positive sense on
/// the second body) and the radial direction the pressure angle leans the
/// force toward on the second body (into its teeth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mesh {
    /// The pitch point.
    pub at: Point,
    /// Unit common tangent.
    pub tangent: Point,
    /// Unit radial direction on the second body.
    pub radial: Point,
    /// tan(pressure angle).
    pub lean: f64,
}

/// A gear's pitch circle, for drawing: the body it turns with, its centre
/// in that body's (drawn) coordinates, and its radius.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PitchCircle {
    /// The body.
    pub body: usize,
    /// The centre (the body's pivot as drawn).
    pub centre: Point,
    /// The pitch radius.
    pub radius: f64,
}

/// A rack's pitch line, for drawing, in the rack's drawn coordinates: the
/// pitch point, the slide direction, how far it reaches either side of the
/// pitch point along it (over the rack's markers and a pinion radius,
/// with half a radius to spare) and the unit normal from the pinion
/// toward the rack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PitchLine {
    /// The pitch point.
    pub at: Point,
    /// Unit slide direction.
    pub dir: Point,
    /// The reach along `dir` from `at`, below.
    pub from: f64,
    /// The reach along `dir` from `at`, above.
    pub to: f64,
    /// Unit normal toward the rack.
    pub normal: Point,
}

impl Gear {
    /// The pitch circles: both gears', or a rack and pinion's pinion's.
    pub fn pitch_circles(&self) -> Vec<PitchCircle> {
        let circle = |k: usize, radius: f64| PitchCircle {
            body: self.bodies[k],
            centre: self.centres[k],
            radius,
        };
        match self.kind {
            GearKind::Gear { radii, .. } => vec![circle(0, radii[0]), circle(1, radii[1])],
            GearKind::RackPinion { radius, .. } => vec![circle(0, radius)],
        }
    }

    /// A rack's pitch line (`None` for a gear pair); `rack_markers` are the
    /// rack's markers as drawn, which it reaches over.
    pub fn pitch_line(&self, rack_markers: impl Iterator<Item = Point>) -> Option<PitchLine> {
        let GearKind::RackPinion {
            radius, dir, side, ..
        } = self.kind
        else {
            return None;
        };
        let at = self.mesh().at;
        let s = |p: Point| (p[0] - at[0]) * dir[0] + (p[1] - at[1]) * dir[1];
        let (lo, hi) = rack_markers
            .map(s)
            .fold((-radius, radius), |(lo, hi), v| (lo.min(v), hi.max(v)));
        Some(PitchLine {
            at,
            dir,
            from: lo - 0.5 * radius,
            to: hi + 0.5 * radius,
            normal: [-side * dir[1], side * dir[0]],
        })
    }

    /// The pitch point and the tooth force's directions (see [`Mesh`]).
    pub fn mesh(&self) -> Mesh {
        let [ca, cb] = self.centres;
        let unit = |v: Point| {
            let n = v[0].hypot(v[1]);
            [v[0] / n, v[1] / n]
        };
        match self.kind {
            GearKind::Gear {
                radii,
                internal,
                pressure_angle,
            } => {
                let nu = unit([cb[0] - ca[0], cb[1] - ca[1]]);
                let at = if !internal {
                    [ca[0] + radii[0] * nu[0], ca[1] + radii[0] * nu[1]]
                } else if radii[0] < radii[1] {
                    // A pinion inside ring B: the pitch point lies beyond
                    // the pinion's centre, away from the ring's.
                    [ca[0] - radii[0] * nu[0], ca[1] - radii[0] * nu[1]]
                } else {
                    // Ring A, pinion B: beyond the pinion's centre too.
                    [cb[0] + radii[1] * nu[0], cb[1] + radii[1] * nu[1]]
                };
                // Teeth push into each other: on a pinion or an external
                // gear toward its centre, on a ring away from its own.
                let to_b = unit([cb[0] - at[0], cb[1] - at[1]]);
                let ring_b = internal && radii[1] > radii[0];
                let radial = if ring_b { [-to_b[0], -to_b[1]] } else { to_b };
                Mesh {
                    at,
                    tangent: [-nu[1], nu[0]],
                    radial,
                    lean: pressure_angle.to_radians().tan(),
                }
            }
            GearKind::RackPinion {
                radius,
                dir,
                side,
                pressure_angle,
            } => {
                let n = [-side * dir[1], side * dir[0]];
                Mesh {
                    at: [ca[0] + radius * n[0], ca[1] + radius * n[1]],
                    tangent: dir,
                    radial: n,
                    lean: pressure_angle.to_radians().tan(),
                }
            }
        }
    }

    /// The coupling as `d second = ratio · d first`, both relative to the
    /// carrier: for gears, radians per radian (−rA/rB external, +rA/rB
    /// internal); for a rack and pinion, the rack's slide along
    /// [`GearKind::RackPinion::dir`] in length units per radian of the
    /// pinion.
    pub fn ratio(&self) -> f64 {
        match self.kind {
            GearKind::Gear { radii, internal, .. } => {
                let r = radii[0] / radii[1];
                if internal {
                    r
                } else {
                    -r
                }
            }
            // The pinion's pitch point, on the rack's side, moves at
            // r·ω along the slide direction's opposite when the rack lies
            // to the left (turning counter-clockwise, a point to the left
            // of the centre moves backward).
            GearKind::RackPinion { radius, side, .. } => -side * radius,
        }
    }
}
