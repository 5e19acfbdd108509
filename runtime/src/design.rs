//! What a compiled design module's `prepare` calls: a candidate drawing's
//! markers placed from the design parameters, the numbers of the plan
//! taken from them, and the error when the candidate cannot follow the
//! plan.
//!
//! A design parameter is a coordinate of a node: a joint's drawn position
//! (all its markers move with it, each at its drawn offset) or a free
//! marker's. A plan's numbers are the drawing's, so a candidate's are the
//! same functions of its own drawing: a radius is the drawn distance
//! between the two points it joins, a turned line's offset the drawn
//! offset of the point it passes ([`crate::planar::turn_line_through`]).

use std::fmt;

use crate::planar::Point;
use crate::scalar::{Real, Tangent};

/// A marker coordinate for parameter value `v` of its node, drawn at `at`:
/// the drawn coordinate itself while the node is where it was drawn (so
/// the drawn parameters give the drawn plan to the last bit), `v + offset`
/// otherwise.
#[inline(always)]
pub fn place(v: f64, at: f64, drawn: f64, offset: f64) -> f64 {
    if v == at {
        drawn
    } else {
        v + offset
    }
}

/// A circle's radius: the drawn distance between its centre and the point
/// on it (on `f64`, or on [`Tangent`]s for its derivatives with respect
/// to the design parameters).
#[inline(always)]
pub fn radius<T: Real>(centre: [T; 2], on: [T; 2]) -> T {
    let (dx, dy) = (on[0] - centre[0], on[1] - centre[1]);
    (dx * dx + dy * dy).sqrt()
}

/// The signed distance at which a line (unit direction `dir`, turned about
/// `pivot`) passes `target` in the drawing, where the body is unturned:
/// `cross(target − pivot, dir)`.
#[inline(always)]
pub fn line_offset<T: Real>(pivot: [T; 2], target: [T; 2], dir: Point) -> T {
    (target[0] - pivot[0]).mul_f64(dir[1]) - (target[1] - pivot[1]).mul_f64(dir[0])
}

/// A candidate's marker drawn at `at` as [`Tangent`]s: its coordinates
/// are its node's parameters `2·node` and `2·node + 1` plus constant
/// offsets ([`place`]), so each has derivative 1 with respect to its own.
#[inline(always)]
pub fn seeded<const N: usize>(at: Point, node: usize) -> [Tangent<N>; 2] {
    [Tangent::var(at[0], 2 * node), Tangent::var(at[1], 2 * node + 1)]
}

/// The size of a drawing, as the compiler measures a mechanism's (the
/// diagonal of its markers' bounding box; 1 when that is zero): the scale
/// of the tolerance a candidate's drawing is reproduced to.
pub fn size(markers: &[Point]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in markers {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

/// Why a candidate cannot be prepared: it is not a drawing the plan can
/// run from.
#[derive(Clone, Debug, PartialEq)]
pub enum PrepareError {
    /// A parameter is not a finite number.
    NotFinite {
        /// Its name (`D.x`).
        parameter: &'static str,
    },
    /// The plan breaks at the candidate's drawing (every input at 0): a
    /// radius of zero, lines that no longer cross, …
    Broken {
        /// The step, numbered as in the plan.
        step: u32,
        /// What went wrong there ([`crate::BreakKind::describe`]).
        why: &'static str,
    },
    /// The plan places a body elsewhere than the candidate draws it: the
    /// candidate needs another plan (a step relies on a geometry the
    /// candidate does not have).
    NotReproduced {
        /// The body.
        body: &'static str,
        /// How far its furthest marker lands from its drawn position.
        gap: f64,
    },
}

impl fmt::Display for PrepareError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PrepareError::NotFinite { parameter } => write!(f, "parameter {parameter} is not a finite number"),
            PrepareError::Broken { step, why } => write!(
                f,
                "the plan breaks at step {step} at the candidate's drawing ({why}): no mechanism to run"
            ),
            PrepareError::NotReproduced { body, gap } => write!(
                f,
                "the plan places body {body} {gap:e} from where the candidate draws it: this candidate needs another plan (prepare it through the interpreter's Design instead)"
            ),
        }
    }
}

impl std::error::Error for PrepareError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_node_left_as_drawn_keeps_the_drawn_coordinate() {
        // 0.1 + 0.2 is not 0.3: the drawn coordinate is kept, not rebuilt.
        assert_eq!(place(0.1, 0.1, 0.3, 0.2), 0.3);
        assert_eq!(place(0.5, 0.1, 0.3, 0.2), 0.7);
    }

    #[test]
    fn radius_and_line_offset_are_the_drawn_ones() {
        assert_eq!(radius([1.0, 1.0], [4.0, 5.0]), 5.0);
        // The target 2 to the left of a line along +x through the pivot.
        assert_eq!(line_offset([0.0, 0.0], [3.0, 2.0], [1.0, 0.0]), -2.0);
        assert_eq!(size(&[[0.0, 0.0], [3.0, 4.0]]), 5.0);
        assert_eq!(size(&[[1.0, 1.0]]), 1.0);
    }
}
