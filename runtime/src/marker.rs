//! A marker of a compiled mechanism by name: the body it is on and its
//! local coordinates, so a program reads a coupler point without copying
//! coordinates out of the mechanism file or looking a body up by string.
//! Generated modules hold one constant per marker (`fourbar::marker::COUPLER_P`).

use crate::planar::{Point, Pose};

/// A marker: a point fixed on a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    /// Its name as the mechanism file writes it ("coupler.P").
    pub name: &'static str,
    /// Its body's index in the mechanism's body order (the index of its
    /// pose).
    pub body: usize,
    /// Its local coordinates, which are its drawn world coordinates.
    pub local: Point,
}

impl Marker {
    /// The marker `name` on body `body` at `local`.
    pub const fn new(name: &'static str, body: usize, local: Point) -> Marker {
        Marker { name, body, local }
    }

    /// Its world position when the bodies are at `poses` (in the
    /// mechanism's body order, as a state or a driver holds them).
    ///
    /// # Panics
    /// If `poses` has no pose for the marker's body (poses of another
    /// mechanism).
    #[inline]
    pub fn world(&self, poses: &[Pose]) -> Point {
        poses[self.body].world(self.local)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar::Rot;

    #[test]
    fn a_marker_moves_with_its_body() {
        let m = Marker::new("coupler.P", 1, [2.0, 1.0]);
        let poses = [
            Pose::IDENTITY,
            Pose {
                at: [10.0, 20.0],
                rot: Rot::from_degrees(90.0),
            },
        ];
        // A quarter turn takes (2, 1) to (−1, 2), then the translation.
        assert_eq!(m.world(&poses), [9.0, 22.0]);
        assert_eq!(m.world(&[Pose::IDENTITY; 2]), [2.0, 1.0]);
    }
}
