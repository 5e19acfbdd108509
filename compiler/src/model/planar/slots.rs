//! Pins in slots: a marker of one body runs along a straight slot of
//! another, turning freely, between the slot's two ends.

use super::MarkerId;

/// A straight slot and the pin in it, as validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// The slot's marker (its `dir` is the slot's direction) and the pin.
    pub markers: [MarkerId; 2],
    /// The ends: positions along the slot's unit direction from its
    /// marker, low then high (the pin as drawn lies between them).
    pub ends: [f64; 2],
    /// The line it is written on (1-based), TOML only.
    pub line: Option<usize>,
}
