//! What loads are in space (the shared shape is `model/loads.rs`):
//! vectors `[x, y, z]`, a torque a vector (right-handed about it), an
//! inertia a symmetric 3×3 tensor about the centre, in the drawn pose's
//! axes (which the body's rotation carries).

use crate::model::loads::Space;

/// Space, as loads see it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spatial;

impl Space for Spatial {
    type Vector = [f64; 3];
    type Torque = [f64; 3];
    type Inertia = [[f64; 3]; 3];
}

/// The loads of a spatial mechanism.
pub type Loads = crate::model::loads::Loads<Spatial>;
/// A spatial body's mass properties.
pub type Mass = crate::model::loads::Mass<Spatial>;
/// One spatial `[loads.NAME]` entry.
pub type Load = crate::model::loads::Load<Spatial>;
/// The kinds of spatial load.
pub type LoadKind = crate::model::loads::LoadKind<Spatial>;
