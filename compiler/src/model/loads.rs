//! What acts on a mechanism besides its joints, in either dimension: the
//! bodies' masses, gravity, and the file's `[loads.NAME]` (forces, torques,
//! springs, dampers, torsion springs). One shape for both dimensions; each
//! fixes what a vector, a torque and an inertia are (`planar/loads.rs`,
//! `spatial/loads.rs`). Read by the loader (`model/load/loads.rs`), used
//! by force analysis (`forces/`).
//!
//! Units are the file's own: lengths as the drawing's, forces in any
//! force unit, torques in force × length, stiffness in force per length
//! (a torsion spring's per radian), damping in force per (length per
//! second), masses and inertias consistent with them (`g` in length per
//! second squared).

use std::fmt::Debug;

use super::MarkerId;

/// What a dimension's loads are made of.
pub trait Space: Clone + Copy + Debug + PartialEq {
    /// A point or a force: `[x, y]` or `[x, y, z]`.
    type Vector: Clone + Copy + Debug + PartialEq;
    /// A torque: a number (counter-clockwise positive) in the plane, a
    /// vector (right-handed about it) in space.
    type Torque: Clone + Copy + Debug + PartialEq;
    /// A body's inertia about its centre: a number in the plane, a
    /// symmetric 3×3 tensor (in the drawn pose's axes) in space.
    type Inertia: Clone + Copy + Debug + PartialEq;
}

/// The loads of a mechanism: empty for a file that gives none.
#[derive(Clone, Debug, PartialEq)]
pub struct Loads<S: Space> {
    /// The acceleration of gravity, `[gravity] g = [...]`.
    pub gravity: Option<S::Vector>,
    /// Per body (in the mechanism's order), its mass properties if the
    /// file gives them; empty when no body has any.
    pub masses: Vec<Option<Mass<S>>>,
    /// The `[loads.NAME]` entries, in file order.
    pub applied: Vec<Load<S>>,
}

impl<S: Space> Default for Loads<S> {
    fn default() -> Self {
        Loads {
            gravity: None,
            masses: Vec::new(),
            applied: Vec::new(),
        }
    }
}

impl<S: Space> Loads<S> {
    /// Whether the file gives nothing to compute forces from.
    pub fn is_empty(&self) -> bool {
        self.gravity.is_none() && self.masses.iter().all(Option::is_none) && self.applied.is_empty()
    }

    /// Body `b`'s mass properties, if any.
    pub fn mass(&self, b: usize) -> Option<&Mass<S>> {
        self.masses.get(b).and_then(Option::as_ref)
    }
}

/// A body's mass properties.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mass<S: Space> {
    /// Its mass.
    pub mass: f64,
    /// Its centre of mass, a point of the drawing (where it is at the
    /// drawn pose).
    pub centre: S::Vector,
    /// Its inertia about the centre (in the drawn pose's axes).
    pub inertia: S::Inertia,
}

/// One `[loads.NAME]` entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Load<S: Space> {
    /// Its name.
    pub name: String,
    /// What it is.
    pub kind: LoadKind<S>,
}

/// The kinds of load.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadKind<S: Space> {
    /// A force at a marker.
    Force {
        /// Where it acts.
        marker: MarkerId,
        /// Its components: along the world axes, or along the marker's
        /// body's axes (turning with it) when `body_axes`.
        force: S::Vector,
        /// Whether `force` is in the body's axes.
        body_axes: bool,
    },
    /// A torque on a body, in world axes.
    Torque {
        /// The body.
        body: usize,
        /// The torque.
        torque: S::Torque,
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
    /// A torsion spring at a joint that turns about one axis (revolute;
    /// in space also cylindrical): a torque `stiffness × (φ − free_angle)`
    /// resisting φ, the turn of the joint's second body relative to its
    /// first from the drawn pose (about the first marker's z in space).
    TorsionSpring {
        /// Index into the mechanism's joints.
        joint: usize,
        /// Torque per radian.
        stiffness: f64,
        /// The turn at which it pushes nothing, in radians (degrees in the
        /// file).
        free_angle: f64,
    },
}

impl<S: Space> LoadKind<S> {
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
