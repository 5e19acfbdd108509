//! Planar (2D) geometry: body poses and the steps of a planar plan.
//!
//! Conventions shared with the compiler:
//! - every body's local frame is the world frame of the pose *as drawn*, so
//!   a marker's local coordinates are its drawn world coordinates and every
//!   body's drawn pose is the identity;
//! - a rotation is carried as its cosine/sine pair ([`Rot`]); composing two
//!   rotations is a complex multiplication, never an `atan2` or `sin`.

mod locus;
mod place;

pub use locus::{circle_circle, circle_line, line_line, turn_line_through};
pub use place::{align, anchor, orient};

/// A point or a vector in the plane.
pub type Point = [f64; 2];

/// A rotation as its (cos, sin) pair.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rot {
    /// Cosine of the angle.
    pub c: f64,
    /// Sine of the angle.
    pub s: f64,
}

impl Rot {
    /// No rotation.
    pub const IDENTITY: Rot = Rot { c: 1.0, s: 0.0 };

    /// The rotation by `degrees` counter-clockwise. This is the only place a
    /// frame calls a trigonometric function: once per angle input.
    #[inline]
    pub fn from_degrees(degrees: f64) -> Rot {
        let (s, c) = degrees.to_radians().sin_cos();
        Rot { c, s }
    }

    /// `self` followed by `other` (angles add).
    #[inline]
    pub fn then(self, other: Rot) -> Rot {
        Rot {
            c: self.c * other.c - self.s * other.s,
            s: self.s * other.c + self.c * other.s,
        }
    }

    /// The inverse rotation.
    #[inline]
    pub fn inverse(self) -> Rot {
        Rot {
            c: self.c,
            s: -self.s,
        }
    }

    /// Rotates a vector.
    #[inline(always)]
    pub fn apply(self, v: Point) -> Point {
        [self.c * v[0] - self.s * v[1], self.s * v[0] + self.c * v[1]]
    }

    /// The angle in degrees (for reports only, never on the per-frame path).
    pub fn degrees(self) -> f64 {
        self.s.atan2(self.c).to_degrees()
    }
}

/// Where a body is: world = `rot` · local + `at`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pose {
    /// Translation (the world position of the local origin).
    pub at: Point,
    /// Rotation relative to the drawn pose.
    pub rot: Rot,
}

impl Pose {
    /// The drawn pose of every body.
    pub const IDENTITY: Pose = Pose {
        at: [0.0, 0.0],
        rot: Rot::IDENTITY,
    };

    /// World position of a marker given in local (= drawn) coordinates.
    #[inline(always)]
    pub fn world(&self, local: Point) -> Point {
        let r = self.rot.apply(local);
        [self.at[0] + r[0], self.at[1] + r[1]]
    }

    /// World direction of a local direction.
    #[inline]
    pub fn world_dir(&self, local: Point) -> Point {
        self.rot.apply(local)
    }
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

#[inline]
pub(crate) fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline]
pub(crate) fn add(a: Point, b: Point) -> Point {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline]
pub(crate) fn scale(a: Point, k: f64) -> Point {
    [a[0] * k, a[1] * k]
}

#[inline]
pub(crate) fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

#[inline]
pub(crate) fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `a` turned a quarter counter-clockwise.
#[inline]
pub(crate) fn perp(a: Point) -> Point {
    [-a[1], a[0]]
}

#[inline]
pub(crate) fn dist2(a: Point, b: Point) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_composition_matches_angle_sum() {
        let r = Rot::from_degrees(30.0).then(Rot::from_degrees(60.0));
        assert!((r.c - 0.0).abs() < 1e-15 && (r.s - 1.0).abs() < 1e-15);
        let back = r.then(r.inverse());
        assert!((back.c - 1.0).abs() < 1e-15 && back.s.abs() < 1e-15);
    }

    #[test]
    fn pose_maps_local_to_world() {
        let p = Pose {
            at: [1.0, 2.0],
            rot: Rot::from_degrees(90.0),
        };
        let w = p.world([1.0, 0.0]);
        assert!((w[0] - 1.0).abs() < 1e-15 && (w[1] - 3.0).abs() < 1e-15);
    }
}

/// The kind of a driving input, as generated plans describe their inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum InputKind {
    /// A joint angle in degrees.
    Angle,
    /// A slide in length units.
    Slide,
}

impl InputKind {
    /// The name used in mechanism files.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Angle => "angle",
            InputKind::Slide => "slide",
        }
    }
}
