//! What loads are in the plane (the shared shape is `model/loads.rs`):
//! vectors `[x, y]`, a torque a number (counter-clockwise positive), an
//! inertia a number (about the centre).

use crate::model::loads::Space;

/// The plane, as loads see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Planar;

impl Space for Planar {
    type Vector = [f64; 2];
    type Torque = f64;
    type Inertia = f64;
}

/// The loads of a planar mechanism.
pub type Loads = crate::model::loads::Loads<Planar>;
/// A planar body's mass properties.
pub type Mass = crate::model::loads::Mass<Planar>;
/// One planar `[loads.NAME]` entry.
pub type Load = crate::model::loads::Load<Planar>;
/// The kinds of planar load.
pub type LoadKind = crate::model::loads::LoadKind<Planar>;
