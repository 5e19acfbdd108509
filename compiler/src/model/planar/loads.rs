//! What acts on a planar mechanism besides its joints: the bodies' masses,
//! gravity, and the file's `[loads.NAME]` (forces, torques, springs,
//! dampers, torsion springs). Read by the loader (`model/load/loads.rs`),
//! used by force analysis (`forces/planar.rs`).
//!
//! Units are the file's own: lengths as the drawing's, forces in any
//! force unit, torques in force × length, stiffness in force per length
//! (a torsion spring's per radian), damping in force per (length per
//! second), masses and inertias consistent with them (`g` in length per
//! second squared).

use super::super::MarkerId;

/// The loads of a mechanism: empty for a file that gives none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loads {
    /// The acceleration of gravity, `[gravity] g = [gx, gy]`.
    pub gravity: Option<[f64; 2]>,
    /// Per body (in the mechanism's order), its mass properties if the
    /// file gives them; empty when no body has any.
    pub masses: Vec<Option<Mass>>,
    /// The `[loads.NAME]` entries, in file order.
    pub applied: Vec<Load>,
}

impl Loads {
    /// Whether the file gives nothing to compute forces from.
    pub fn is_empty(&self) -> bool {
        self.gravity.is_none() && self.masses.iter().all(Option::is_none) && self.applied.is_empty()
    }

    /// Body `b`'s mass properties, if any.
    pub fn mass(&self, b: usize) -> Option<&Mass> {
        self.masses.get(b).and_then(Option::as_ref)
    }
}

/// A body's mass properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mass {
    /// Its mass.
    pub mass: f64,
    /// Its centre of mass, a point of the drawing (where it is at the
    /// drawn pose).
    pub centre: [f64; 2],
    /// Its moment of inertia about the centre.
    pub inertia: f64,
}

/// One `[loads.NAME]` entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Load {
    /// Its name.
    pub name: String,
    /// What it is.
    pub kind: LoadKind,
}

/// The kinds of load.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadKind {
    /// A force at a marker.
    Force {
        /// Where it acts.
        marker: MarkerId,
        /// Its components: along x and y, or along the marker's body's
        /// axes (turning with it) when `body_axes`.
        force: [f64; 2],
        /// Whether `force` is in the body's axes.
        body_axes: bool,
    },
    /// A torque on a body (counter-clockwise positive).
    Torque {
        /// The body.
        body: usize,
        /// The torque.
        torque: f64,
    },
    /// A linear spring between two markers: a tension `stiffness × (length
    /// − free_length)` pulling them together.
    Spring {
        /// Its ends.
        markers: [MarkerId; 2],
        /// Force per length.
        stiffness: f64,
        /// The length at which it pulls nothing.
        free_length: f64,
    },
    /// A linear damper between two markers: a tension `damping ×
    /// d(length)/dt`, from the exact velocities.
    Damper {
        /// Its ends.
        markers: [MarkerId; 2],
        /// Force per (length per second).
        damping: f64,
    },
    /// A torsion spring at a revolute joint: a torque `stiffness × (φ −
    /// free_angle)` resisting φ, the turn of the joint's second body
    /// relative to its first from the drawn pose.
    TorsionSpring {
        /// Index into the mechanism's joints (a revolute one).
        joint: usize,
        /// Torque per radian.
        stiffness: f64,
        /// The turn at which it pushes nothing, in radians (degrees in the
        /// file).
        free_angle: f64,
    },
}

impl LoadKind {
    /// The kind's name as the file writes it.
    pub fn name(&self) -> &'static str {
        match self {
            LoadKind::Force { .. } => "force",
            LoadKind::Torque { .. } => "torque",
            LoadKind::Spring { .. } => "spring",
            LoadKind::Damper { .. } => "damper",
            LoadKind::TorsionSpring { .. } => "torsion-spring",
        }
    }
}
