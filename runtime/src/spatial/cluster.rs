//! Numeric clusters of spatial plans: what no fragment closes is solved by
//! Newton–Raphson ([`crate::numeric::Newton`]) on each cluster body's
//! reduced unknowns, counted from its state (SPATIAL.md §2.7): a rotation
//! about a known axis (1), about a known pivot (3), or a free motion (6).
//!
//! A body's pose is its warm start moved by its unknowns `x` ([`moved`]):
//! a rotation by the rotation vector ω (exponential map) about the pivot or
//! the body's own origin, then (free bodies) a translation. The Jacobian
//! column of each unknown is the twist it causes at `x` ([`columns`]),
//! exact at every `x` through the left Jacobian of the rotation group, so
//! Newton keeps its quadratic convergence. The interpreter and generated
//! code both evaluate a cluster's rows with [`RowKind::eval`] and
//! [`RowKind::deriv`](super::rows::RowKind::deriv) at these poses and
//! twists.

use super::rows::{FrameRate, WorldFrame};
use super::{add, cross, dot, norm, scale, sub, Pose3, Rot3, Vec3};

/// How a cluster body moves with its unknowns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unknowns {
    /// Rotation vector about its origin, then a translation (6).
    Free,
    /// Rotation vector about the fixed point (3).
    Pivot(Vec3),
    /// Angle about the line (point, unit axis) (1).
    Axis(Vec3, Vec3),
}

impl Unknowns {
    /// How many.
    #[inline]
    pub fn count(&self) -> usize {
        match self {
            Unknowns::Free => 6,
            Unknowns::Pivot(_) => 3,
            Unknowns::Axis(..) => 1,
        }
    }
}

/// The motion one unknown causes: angular velocity `omega` about `origin`
/// and translation velocity `v`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Twist {
    /// Angular velocity.
    pub omega: Vec3,
    /// Velocity of translation.
    pub v: Vec3,
    /// The point `omega` turns about.
    pub origin: Vec3,
}

impl Twist {
    /// The rate of a frame under this twist.
    #[inline]
    pub fn rate(&self, f: &WorldFrame) -> FrameRate {
        FrameRate::of(f, self.omega, self.v, self.origin)
    }

    /// The velocity of a point under this twist.
    #[inline]
    pub fn velocity(&self, p: Vec3) -> Vec3 {
        add(cross(self.omega, sub(p, self.origin)), self.v)
    }
}

/// The rotation by the rotation vector `w` (angle |w| about w/|w|).
#[inline]
fn exp(w: Vec3) -> Rot3 {
    let angle = norm(w);
    if angle == 0.0 {
        return Rot3::IDENTITY;
    }
    Rot3::about_axis(scale(w, 1.0 / angle), angle.cos(), angle.sin())
}

/// `J_l(w)·e`: the left Jacobian of the rotation group applied to `e` —
/// the angular velocity that a change of the rotation vector `w` along
/// `e` causes.
#[inline]
fn left_jacobian(w: Vec3, e: Vec3) -> Vec3 {
    let t2 = dot(w, w);
    let (a, b) = if t2 < 1e-8 {
        // Series: (1 − cos t)/t² and (t − sin t)/t³ near 0.
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let we = cross(w, e);
    add(add(e, scale(we, a)), scale(cross(w, we), b))
}

/// A body's pose moved from its warm start `base` by its unknowns `x`.
#[inline]
pub fn moved(base: &Pose3, u: &Unknowns, x: &[f64]) -> Pose3 {
    let mut p = *base;
    match *u {
        Unknowns::Free => {
            let o = base.pos;
            p.rotate_about(o, &exp([x[0], x[1], x[2]]));
            p.translate([x[3], x[4], x[5]]);
        }
        Unknowns::Pivot(c) => p.rotate_about(c, &exp([x[0], x[1], x[2]])),
        Unknowns::Axis(c, a) => p.rotate_about(c, &Rot3::about_axis(a, x[0].cos(), x[0].sin())),
    }
    p
}

/// The twist of each of a body's unknowns at `x` (the first
/// [`Unknowns::count`] entries of the result).
#[inline]
pub fn columns(base: &Pose3, u: &Unknowns, x: &[f64]) -> [Twist; 6] {
    let mut out = [Twist::default(); 6];
    let unit = |k: usize| {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        e
    };
    match *u {
        Unknowns::Free => {
            let w = [x[0], x[1], x[2]];
            // The rotation turns about the base origin, which the
            // translation then carries: at x the origin is at base + t.
            let origin = add(base.pos, [x[3], x[4], x[5]]);
            for k in 0..3 {
                out[k] = Twist {
                    omega: left_jacobian(w, unit(k)),
                    v: [0.0; 3],
                    origin,
                };
                out[k + 3] = Twist {
                    omega: [0.0; 3],
                    v: unit(k),
                    origin,
                };
            }
        }
        Unknowns::Pivot(c) => {
            let w = [x[0], x[1], x[2]];
            for (k, t) in out.iter_mut().take(3).enumerate() {
                *t = Twist {
                    omega: left_jacobian(w, unit(k)),
                    v: [0.0; 3],
                    origin: c,
                };
            }
        }
        Unknowns::Axis(c, a) => {
            out[0] = Twist {
                omega: a,
                v: [0.0; 3],
                origin: c,
            }
        }
    }
    out
}
