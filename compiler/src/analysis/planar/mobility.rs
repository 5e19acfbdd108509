//! Mobility by Grübler's count and the resulting classification.

use crate::model::Mechanism;

/// Degrees of freedom by counting.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mobility {
    /// Links (mobile bodies + 1 for the ground).
    pub links: usize,
    /// One-DOF joints (revolute and prismatic).
    pub joints: usize,
    /// Scalar equations of the primitive constraints written directly.
    pub constraint_equations: usize,
    /// Gear pairs, racks and pinions and pins in slots: higher pairs, one
    /// equation each.
    pub gears: usize,
    /// D = 3(L − 1) − 2J − H − (constraint equations), H the higher pairs.
    pub dof: i64,
    /// Number of inputs.
    pub inputs: usize,
}

/// How the inputs relate to the mobility.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// As many inputs as degrees of freedom.
    Well,
    /// Fewer inputs than degrees of freedom.
    Under,
    /// More equations than freedoms (redundant or inconsistent).
    Over,
}

impl Mobility {
    /// Counts a mechanism.
    pub fn of(m: &Mechanism) -> Mobility {
        let constraint_equations: usize = m
            .constraints
            .iter()
            .map(|c| match c.kind {
                crate::model::ConstraintKind::Coincident => 2,
                _ => 1,
            })
            .sum();
        let links = m.links();
        let joints = m.joints.len();
        let gears = m.gears.len() + m.slots.len();
        let dof = 3 * (links as i64 - 1) - 2 * joints as i64 - gears as i64 - constraint_equations as i64;
        Mobility {
            links,
            joints,
            constraint_equations,
            gears,
            dof,
            inputs: m.inputs.len(),
        }
    }

    /// Degrees of freedom left once every input is given.
    pub fn free(&self) -> i64 {
        self.dof - self.inputs as i64
    }

    /// Well-, under- or over-constrained once the inputs are given.
    pub fn class(&self) -> Class {
        match self.free() {
            0 => Class::Well,
            f if f > 0 => Class::Under,
            _ => Class::Over,
        }
    }
}

impl Class {
    /// "well-constrained", …
    pub fn name(self) -> &'static str {
        match self {
            Class::Well => "well-constrained",
            Class::Under => "under-constrained",
            Class::Over => "over-constrained",
        }
    }
}
