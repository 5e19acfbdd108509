//! Where a plan's constants come from: the table of design parameters a
//! compiled design module is written against.
//!
//! A plan's numbers are the drawing's: a marker's local coordinates are
//! its drawn position (every body is drawn at its identity pose), a
//! circle's radius is the drawn distance between the two points it joins,
//! a turned line's offset the drawn offset of the point it must pass. A
//! design parameter moves markers (every marker of a joint together, each
//! at its drawn offset), so each of those numbers is a function of the
//! parameters, which the back end writes out as `prepare`. This table is
//! the part of that contract the plan itself does not hold: which
//! parameters there are and which of them each marker moves with.

use std::collections::HashMap;

/// A marker as the design parameters place it: at node `node`'s position
/// plus `offset`, or exactly at `drawn` while that node is where it was
/// drawn (so the drawn parameters give the drawn plan to the last bit).
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedMarker<const N: usize> {
    /// The node (parameters `N·node` to `N·node + N − 1`).
    pub node: usize,
    /// Its drawn offset from the node.
    pub offset: [f64; N],
    /// Its drawn position.
    pub drawn: [f64; N],
}

/// The design parameters of a mechanism, as a back end needs them.
#[derive(Clone, Debug, PartialEq)]
pub struct DesignTable<const N: usize> {
    /// The parameters' names (`D.x`, `coupler.P.y`), `N` per node.
    pub names: Vec<String>,
    /// The parameters' drawn values.
    pub drawn: Vec<f64>,
    /// Every marker ("body.marker") and how the parameters place it.
    pub markers: HashMap<String, PlacedMarker<N>>,
}
