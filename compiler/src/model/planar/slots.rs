//! Pins in slots: a marker of one body runs along a straight or circular
//! slot of another, turning freely, between the slot's two ends.

use dofplan_runtime::planar::Pose;
use dofplan_runtime::Point;

use super::{MarkerId, Mechanism};

/// A slot and the pin in it, as validated.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// The slot's marker (its `dir` is the slot's direction, or for an arc
    /// where its angles count from) and the pin.
    pub markers: [MarkerId; 2],
    /// The slot's shape.
    pub shape: Shape,
    /// The ends, low then high (the pin as drawn lies between them): for a
    /// straight slot, positions along its unit direction from its marker;
    /// for an arc, angles in degrees about its centre, counter-clockwise
    /// from the marker's `dir`, less than a turn apart.
    pub ends: [f64; 2],
    /// The line it is written on (1-based), TOML only.
    pub line: Option<usize>,
}

impl Slot {
    /// The slot's centre line from its low end to its high end, in the
    /// slotted body's drawn coordinates: a straight slot's two ends, or
    /// points along an arc at most 3° apart (both ends included), which
    /// the SVG and the editor draw.
    pub fn centre_line(&self, m: &Mechanism) -> Vec<Point> {
        let marker = m.marker(self.markers[0]);
        let (at, d) = (marker.at, marker.unit_dir().unwrap_or([1.0, 0.0]));
        match self.shape {
            Shape::Straight => self.ends.map(|s| [at[0] + s * d[0], at[1] + s * d[1]]).to_vec(),
            Shape::Arc { radius } => {
                let [lo, hi] = self.ends;
                let n = ((hi - lo) / 3.0).ceil().max(1.0) as usize;
                (0..=n)
                    .map(|k| {
                        let (s, c) = (lo + (hi - lo) * k as f64 / n as f64).to_radians().sin_cos();
                        // `dir` turned by the angle, out to the radius.
                        let u = [c * d[0] - s * d[1], s * d[0] + c * d[1]];
                        [at[0] + radius * u[0], at[1] + radius * u[1]]
                    })
                    .collect()
            }
        }
    }

    /// How far the pin at `pin` is past the nearer end of the slot whose
    /// marker is at `at` with unit direction `dir` (all world; the
    /// runtime's measure, as the plan's check of the ends breaks by it):
    /// positive past an end, along the slot (an arc's length), negative
    /// or zero between the ends.
    pub fn past_end(&self, at: Point, dir: Point, pin: Point) -> f64 {
        use dofplan_runtime::planar::{past_arc_end, past_line_end};
        match self.shape {
            Shape::Straight => past_line_end(at, dir, pin, self.ends),
            Shape::Arc { .. } => past_arc_end(at, dir, pin, self.ends),
        }
    }
}

/// The path a slot guides its pin along.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// The line through the slot's marker along its `dir`.
    Straight,
    /// The circle of this radius about the slot's marker (the drawn
    /// distance from it to the pin).
    Arc {
        /// The radius, in length units.
        radius: f64,
    },
}

/// A slot's ends, checked on poses solved without the plan (pure Newton,
/// drags, the editor's drag): those keep the pin on the slot's line or
/// circle, an equation, but not between the ends, which only the plan's
/// last steps check.
#[derive(Clone, Debug)]
pub struct Ends {
    slot: Slot,
    /// The slot's marker and unit direction, local to its body.
    at: Point,
    dir: Point,
    /// The pin, local to its body.
    pin: Point,
}

impl Ends {
    /// The ends of every slot of `m`.
    pub fn of(m: &Mechanism) -> Vec<Ends> {
        (m.slots.iter())
            .map(|slot| {
                let [a, pin] = slot.markers;
                Ends {
                    slot: slot.clone(),
                    at: m.marker(a).at,
                    dir: m.marker(a).unit_dir().unwrap_or([1.0, 0.0]),
                    pin: m.marker(pin).at,
                }
            })
            .collect()
    }

    /// The slot.
    pub fn slot(&self) -> &Slot {
        &self.slot
    }

    /// How far the pin is past the nearer end at `poses` (the runtime's
    /// measure, [`Slot::past_end`]): positive past an end.
    pub fn past(&self, poses: &[Pose]) -> f64 {
        let [a, pin] = self.slot.markers;
        let pose = &poses[a.body];
        (self.slot).past_end(
            pose.world(self.at),
            pose.world_dir(self.dir),
            poses[pin.body].world(self.pin),
        )
    }

    /// The first of `ends` whose pin is past an end at `poses` by more
    /// than `tolerance`, and by how far.
    pub fn first_past<'e>(ends: &'e [Ends], poses: &[Pose], tolerance: f64) -> Option<(&'e Ends, f64)> {
        ends.iter().find_map(|e| {
            let gap = e.past(poses);
            (gap > tolerance).then_some((e, gap))
        })
    }
}
