//! Planar (2D) geometry: body poses and the steps of a planar plan.
//!
//! Conventions shared with the compiler:
//! - every body's local frame is the world frame of the pose *as drawn*, so
//!   a marker's local coordinates are its drawn world coordinates and every
//!   body's drawn pose is the identity;
//! - a rotation is carried as its cosine/sine pair ([`Rot`]); composing two
//!   rotations is a complex multiplication, never an `atan2` or `sin`.

pub mod cluster;
mod ends;
pub mod forces;
mod locus;
mod place;
mod turn_table;

pub use ends::{past_arc_end, past_line_end, within_arc, within_ends};
pub use locus::{circle_circle, circle_line, line_line, turn_line_through, Circle, Line, Slot};
pub use place::{align, align_consistent, anchor, orient, set_rotation};

use crate::scalar::{Factor, Jet2, Real};

/// A point or a vector in the plane.
pub type Point = [f64; 2];

/// A rotation as its (cos, sin) pair: of `f64`s, or of [`Jet2`]s carrying
/// the rotation's rates.
///
/// `#[repr(C)]`: `c` then `s`, which [`crate::batch::put_body`] stores as
/// a pair.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct Rot<T = f64> {
    /// Cosine of the angle.
    pub c: T,
    /// Sine of the angle.
    pub s: T,
}

/// A number a rotation by an angle in degrees is built of: an angle input
/// of a step generic over [`Real`] (a spatial hinge's, a twist's) turns
/// into its cos/sin pair by the constructor of its own kind, so that every
/// kind gives the numbers of [`Rot::from_degrees`].
pub trait Degrees: Real {
    /// The rotation by `self` degrees as a (cos, sin) pair, its value from
    /// [`Rot::from_degrees`].
    fn degrees_rot(self) -> Rot<Self>;
}

impl Degrees for f64 {
    #[inline(always)]
    fn degrees_rot(self) -> Rot {
        Rot::from_degrees(self)
    }
}

impl Degrees for Jet2 {
    #[inline(always)]
    fn degrees_rot(self) -> Rot<Jet2> {
        Rot::from_degrees_jet(self)
    }
}

impl Rot<Jet2> {
    /// The rotation by `degrees` counter-clockwise, with its rates: the
    /// value from [`Rot::from_degrees`], the derivatives by the chain rule
    /// (c' = −s·ω, c'' = −s·α − c·ω², with ω and α the angle's rates in
    /// radians).
    pub fn from_degrees_jet(degrees: Jet2) -> Rot<Jet2> {
        let r = Rot::from_degrees(degrees.v);
        let k = std::f64::consts::PI / 180.0;
        let (w, a) = (degrees.d * k, degrees.dd * k);
        Rot {
            c: Jet2::new(r.c, -r.s * w, -r.s * a - r.c * w * w),
            s: Jet2::new(r.s, r.c * w, r.c * a - r.s * w * w),
        }
    }
}

impl<T: Real> Rot<T> {
    /// The values alone (of jets or tangents).
    pub fn value(self) -> Rot {
        Rot {
            c: self.c.value(),
            s: self.s.value(),
        }
    }

    /// `self` followed by `other` (angles add).
    #[inline]
    pub fn then(self, other: Rot<T>) -> Rot<T> {
        Rot {
            c: self.c * other.c - self.s * other.s,
            s: self.s * other.c + self.c * other.s,
        }
    }

    /// The inverse rotation.
    #[inline]
    pub fn inverse(self) -> Rot<T> {
        Rot {
            c: self.c,
            s: -self.s,
        }
    }

    /// Rotates a vector.
    #[inline(always)]
    pub fn apply(self, v: [T; 2]) -> [T; 2] {
        [self.c * v[0] - self.s * v[1], self.s * v[0] + self.c * v[1]]
    }

    /// Rotates a vector of constants: [`apply`](Self::apply) with
    /// multiplications by constants, which cost a third of a jet product
    /// (the same numbers: only the constant's zero derivatives are not
    /// multiplied out).
    #[inline(always)]
    pub fn apply_cst(self, v: Point) -> [T; 2] {
        [
            self.c.mul_f64(v[0]) - self.s.mul_f64(v[1]),
            self.s.mul_f64(v[0]) + self.c.mul_f64(v[1]),
        ]
    }

    /// Rotates a body's local vector: [`apply_cst`](Self::apply_cst) for
    /// constants (`f64`), [`apply`](Self::apply) for a candidate's local
    /// points, which move with its design parameters ([`Tangent`]s).
    ///
    /// [`Tangent`]: crate::scalar::Tangent
    #[inline(always)]
    pub fn apply_local<L: Factor<T>>(self, v: [L; 2]) -> [T; 2] {
        [
            v[0].scale(self.c) - v[1].scale(self.s),
            v[0].scale(self.s) + v[1].scale(self.c),
        ]
    }

    /// A rotation of constants.
    #[inline(always)]
    pub fn cst(r: Rot) -> Rot<T> {
        Rot {
            c: T::cst(r.c),
            s: T::cst(r.s),
        }
    }
}

impl Rot {
    /// No rotation.
    pub const IDENTITY: Rot = Rot { c: 1.0, s: 0.0 };

    /// The rotation by `degrees` counter-clockwise. This is the only place a
    /// frame evaluates a trigonometric function: once per angle input.
    ///
    /// The angle is split, exactly, into a multiple of 1.40625° (a table
    /// entry) and a remainder of at most 0.71° (short sine and cosine series,
    /// whose first omitted terms are below 1e-21); the two rotations are then
    /// composed. Multiples of 90° give exactly 0 and ±1. It agrees with the C
    /// library's `sincos` to a few ulps and costs a fraction of the call,
    /// which otherwise dominates a small mechanism's frame.
    #[inline]
    pub fn from_degrees(degrees: f64) -> Rot {
        if !Rot::in_table_range(degrees) {
            return Rot::from_degrees_slow(degrees);
        }
        Rot::from_degrees_in_range(degrees)
    }

    /// Whether [`Rot::from_degrees_in_range`] takes `degrees`.
    #[inline(always)]
    pub(crate) fn in_table_range(degrees: f64) -> bool {
        degrees.is_finite() && degrees.abs() < 1e12
    }

    /// [`Rot::from_degrees`] of a finite angle below 1e12° (no branch: lanes
    /// of angles go through it side by side).
    #[inline(always)]
    pub(crate) fn from_degrees_in_range(degrees: f64) -> Rot {
        const STEP: f64 = 360.0 / 256.0;
        // Round to the nearest step by the 1.5·2⁵² trick: two additions, where
        // `f64::round` is a library call on baseline x86-64.
        const ROUND: f64 = 6_755_399_441_055_744.0;
        let k = (degrees * (1.0 / STEP) + ROUND) - ROUND;
        // Exact: STEP has 6 significant bits and |k| < 2^40, so k·STEP is
        // representable, and it is within a step of `degrees`.
        let x = (degrees - k * STEP).to_radians();
        let x2 = x * x;
        // Multiplications by reciprocals: a division by a constant is not
        // turned into one by the compiler (it would not be exact).
        let sin = x * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0))));
        let cos = 1.0
            - x2 * 0.5 * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0))));
        let [tc, ts] = turn_table::TURN[(k as i64 & 255) as usize];
        Rot {
            c: tc * cos - ts * sin,
            s: ts * cos + tc * sin,
        }
    }

    /// Huge or non-finite angles: reduced modulo 360 first, which is exact
    /// in floating point, since a huge angle in radians has lost the turn it
    /// is at (1e20° is 1.7e18 rad, whose ulp is 256 rad).
    #[cold]
    #[inline(never)]
    fn from_degrees_slow(degrees: f64) -> Rot {
        let (s, c) = (degrees % 360.0).to_radians().sin_cos();
        Rot { c, s }
    }

    /// The angle in degrees (for reports only, never on the per-frame path).
    pub fn degrees(self) -> f64 {
        self.s.atan2(self.c).to_degrees()
    }
}

/// Where a body is: world = `rot` · local + `at` (of `f64`s, or of
/// [`Jet2`]s carrying the body's velocity and acceleration).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pose<T = f64> {
    /// Translation (the world position of the local origin).
    pub at: [T; 2],
    /// Rotation relative to the drawn pose.
    pub rot: Rot<T>,
}

impl Pose {
    /// The drawn pose of every body.
    pub const IDENTITY: Pose = Pose {
        at: [0.0, 0.0],
        rot: Rot::IDENTITY,
    };

    /// World position of a marker and its derivative with respect to the
    /// body's angle (the point turned a quarter turn about the body's
    /// origin): the Jacobian columns of a numeric cluster.
    #[inline(always)]
    pub fn world_and_turn(&self, local: Point) -> (Point, Point) {
        let r = self.rot.apply(local);
        ([self.at[0] + r[0], self.at[1] + r[1]], [-r[1], r[0]])
    }
}

impl<T: Real> Pose<T> {
    /// The values alone (of jets or tangents).
    pub fn value(&self) -> Pose {
        Pose {
            at: [self.at[0].value(), self.at[1].value()],
            rot: self.rot.value(),
        }
    }

    /// A pose of constants.
    #[inline(always)]
    pub fn cst(p: Pose) -> Pose<T> {
        Pose {
            at: [T::cst(p.at[0]), T::cst(p.at[1])],
            rot: Rot::cst(p.rot),
        }
    }

    /// World position of a marker given in local (= drawn) coordinates:
    /// a body's markers are constants of its geometry (`f64`), or of a
    /// candidate's, with their derivatives with respect to its design
    /// parameters.
    #[inline(always)]
    pub fn world<L: Factor<T>>(&self, local: [L; 2]) -> [T; 2] {
        let r = self.rot.apply_local(local);
        [self.at[0] + r[0], self.at[1] + r[1]]
    }

    /// World position of a local point that is not a constant: a marker
    /// carried along a slide input, whose local position moves with it.
    #[inline(always)]
    pub fn world_carried(&self, local: [T; 2]) -> [T; 2] {
        let r = self.rot.apply(local);
        [self.at[0] + r[0], self.at[1] + r[1]]
    }

    /// World direction of a local direction (a constant of the body).
    #[inline]
    pub fn world_dir(&self, local: Point) -> [T; 2] {
        self.rot.apply_cst(local)
    }
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

#[inline(always)]
pub(crate) fn sub<T: Real>(a: [T; 2], b: [T; 2]) -> [T; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

#[inline(always)]
pub(crate) fn add<T: Real>(a: [T; 2], b: [T; 2]) -> [T; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

#[inline(always)]
pub(crate) fn scale<T: Real>(a: [T; 2], k: T) -> [T; 2] {
    [a[0] * k, a[1] * k]
}

#[inline(always)]
pub(crate) fn dot<T: Real>(a: [T; 2], b: [T; 2]) -> T {
    a[0] * b[0] + a[1] * b[1]
}

#[inline(always)]
pub(crate) fn cross<T: Real>(a: [T; 2], b: [T; 2]) -> T {
    a[0] * b[1] - a[1] * b[0]
}

/// `a` turned a quarter counter-clockwise.
#[inline(always)]
pub(crate) fn perp<T: Real>(a: [T; 2]) -> [T; 2] {
    [-a[1], a[0]]
}

#[inline(always)]
pub(crate) fn dist2<T: Real>(a: [T; 2], b: [T; 2]) -> T {
    let d = sub(a, b);
    dot(d, d)
}

/// Constants as a point of `T`s.
#[inline(always)]
pub fn cst<T: Real>(p: Point) -> [T; 2] {
    [T::cst(p[0]), T::cst(p[1])]
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
    fn degrees_match_the_c_library_and_quadrants_are_exact() {
        let mut worst = 0.0_f64;
        let mut d = -3000.0;
        while d <= 3000.0 {
            let r = Rot::from_degrees(d);
            // Reduced exactly first, so the reference is not off by the
            // rounding of a large angle in radians.
            let (s, c) = (d % 360.0).to_radians().sin_cos();
            worst = worst.max((r.c - c).abs()).max((r.s - s).abs());
            d += 0.0137;
        }
        // The reference's own rounding of the angle to radians (up to half
        // an ulp of 2π ≈ 4.4e-16) dominates this bound.
        assert!(worst < 1e-15, "worst difference from libm {worst:e}");
        for (deg, c, s) in [
            (0.0, 1.0, 0.0),
            (90.0, 0.0, 1.0),
            (180.0, -1.0, 0.0),
            (-90.0, 0.0, -1.0),
            (720.0, 1.0, 0.0),
        ] {
            let r = Rot::from_degrees(deg);
            assert!(r.c == c && r.s == s, "{deg}: {r:?}");
        }
        assert!(Rot::from_degrees(f64::NAN).c.is_nan());
        let big = Rot::from_degrees(1e13);
        assert!((big.c * big.c + big.s * big.s - 1.0).abs() < 1e-15);
        // Huge angles keep their turn: 1e20° and 9e306° are whole turns
        // plus 280° and 56° (fmod is exact; the remainders computed apart).
        for (deg, rest) in [(1e20, 280.0), (9e306, 56.0), (-1e20, -280.0)] {
            let (r, e) = (Rot::from_degrees(deg), Rot::from_degrees(rest));
            assert!(
                (r.c - e.c).abs() < 1e-15 && (r.s - e.s).abs() < 1e-15,
                "{deg}: {r:?}"
            );
        }
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
