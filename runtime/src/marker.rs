//! A marker of a compiled mechanism by name: the body it is on and its
//! local coordinates, so a program reads a coupler point without copying
//! coordinates out of the mechanism file or looking a body up by string.
//! Generated modules hold one constant per marker (`fourbar::marker::COUPLER_P`):
//! a [`Marker`] in a planar module, a [`Marker3`] in a spatial one.

use crate::planar::{Point, Pose};
use crate::spatial::{Pose3, Vec3};

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

/// A marker of a spatial mechanism: a point fixed on a body.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Marker3 {
    /// Its name as the mechanism file writes it ("coupler.M").
    pub name: &'static str,
    /// Its body's index in the mechanism's body order (the index of its
    /// pose).
    pub body: usize,
    /// Its local coordinates, which are its drawn world coordinates.
    pub local: Vec3,
}

impl Marker3 {
    /// The marker `name` on body `body` at `local`.
    pub const fn new(name: &'static str, body: usize, local: Vec3) -> Marker3 {
        Marker3 { name, body, local }
    }

    /// Its world position when the bodies are at `poses` (in the
    /// mechanism's body order, as a state or a driver holds them).
    ///
    /// # Panics
    /// If `poses` has no pose for the marker's body (poses of another
    /// mechanism).
    #[inline]
    pub fn world(&self, poses: &[Pose3]) -> Vec3 {
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

    #[test]
    fn a_spatial_marker_moves_with_its_body() {
        use crate::spatial::Rot3;
        let m = Marker3::new("coupler.M", 1, [2.0, 1.0, 3.0]);
        // A quarter turn about z takes (2, 1, 3) to (−1, 2, 3), then the
        // translation.
        let poses = [
            Pose3::IDENTITY,
            Pose3 {
                rot: Rot3::about_axis([0.0, 0.0, 1.0], 0.0, 1.0),
                pos: [10.0, 20.0, 30.0],
            },
        ];
        assert_eq!(m.world(&poses), [9.0, 22.0, 33.0]);
        assert_eq!(m.world(&[Pose3::IDENTITY; 2]), [2.0, 1.0, 3.0]);
    }
}
