//! Numeric clusters of spatial plans: what no fragment closes is solved by
//! Newton–Raphson ([`crate::numeric::Newton`]) on each cluster body's
//! reduced unknowns, counted from its state (docs/design/spatial.md §2.7): a rotation
//! about a known axis (1), about a known pivot (3), or a free motion (6).
//!
//! A body's pose is its warm start moved by its unknowns `x` ([`moved`]):
//! a rotation by the rotation vector ω (exponential map) about the pivot or
//! the body's own origin, then (free bodies) a translation. The Jacobian
//! column of each unknown is the twist it causes at `x` ([`columns`]),
//! exact at every `x` through the left Jacobian of the rotation group, so
//! Newton keeps its quadratic convergence. The interpreter and generated
//! code both evaluate a cluster's rows with [`RowKind::eval`](crate::spatial::rows::RowKind::eval) and
//! [`RowKind::deriv`](super::rows::RowKind::deriv) at these poses and
//! twists.
//!
//! A solved cluster's rates follow from the implicit function theorem, as
//! a planar cluster's ([`crate::planar::cluster::solve_rates`]): its rows
//! `F(x, upstream) = 0` hold along the motion, so `J·ẋ = −F′` (F's rate
//! with the unknowns held) and `J·ẍ = −F″` (with them moving at ẋ), solved
//! by [`Implicit`](crate::numeric::Implicit). The rows are evaluated on
//! jets at the bodies [`moved_rates`] places.

use super::rows::{FrameRate, WorldFrame};
use super::{add, cross, dot, norm, scale, sub, value, Pose3, Rot3, Vec3};
use crate::scalar::{Jet2, Real};

/// How a cluster body moves with its unknowns (the pivot and axis of
/// `f64`s for a frame, of [`Jet2`]s with their rates for its rates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unknowns<T = f64> {
    /// Rotation vector about its origin, then a translation (6).
    Free,
    /// Rotation vector about the fixed point (3).
    Pivot(Vec3<T>),
    /// Angle about the line (point, unit axis) (1).
    Axis(Vec3<T>, Vec3<T>),
}

impl<T: Real> Unknowns<T> {
    /// How many.
    #[inline]
    pub fn count(&self) -> usize {
        match self {
            Unknowns::Free => 6,
            Unknowns::Pivot(_) => 3,
            Unknowns::Axis(..) => 1,
        }
    }

    /// The values alone.
    #[inline]
    pub fn value(&self) -> Unknowns {
        match *self {
            Unknowns::Free => Unknowns::Free,
            Unknowns::Pivot(c) => Unknowns::Pivot(value(c)),
            Unknowns::Axis(c, a) => Unknowns::Axis(value(c), value(a)),
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

/// The rotation by the rotation vector `w` as `I + a·[w]× + b·[w]×²` with
/// `a = sin t/t` and `b = (1 − cos t)/t²` (t = |w|), both smooth in t²
/// (series near 0): what [`exp`] computes, written so its rates exist at
/// `w = 0` too (|w| has none there).
#[inline]
fn exp_smooth<T: Real>(w: Vec3<T>) -> Rot3<T> {
    let t2 = dot(w, w);
    let (a, b) = if t2.value() < 1e-4 {
        // sin t/t and (1 − cos t)/t² to t⁸: the next terms are below 1e-27.
        let a = T::cst(1.0)
            - t2 * (T::cst(1.0 / 6.0)
                - t2 * (T::cst(1.0 / 120.0) - t2 * (T::cst(1.0 / 5040.0) - t2.mul_f64(1.0 / 362_880.0))));
        let b = T::cst(0.5)
            - t2 * (T::cst(1.0 / 24.0)
                - t2 * (T::cst(1.0 / 720.0) - t2 * (T::cst(1.0 / 40_320.0) - t2.mul_f64(1.0 / 3_628_800.0))));
        (a, b)
    } else {
        let t = t2.sqrt();
        let (s, c) = t.sin_cos();
        // 1 − cos t = sin²t/(1 + cos t) without cancellation when cos t > 0.
        let versine = if c.value() > 0.0 {
            s * s / (T::cst(1.0) + c)
        } else {
            T::cst(1.0) - c
        };
        (s / t, versine / t2)
    };
    let k = [
        [T::cst(0.0), -w[2], w[1]],
        [w[2], T::cst(0.0), -w[0]],
        [-w[1], w[0], T::cst(0.0)],
    ];
    let mut m = [[T::cst(0.0); 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, e) in row.iter_mut().enumerate() {
            let k2 = k[i][0] * k[0][j] + k[i][1] * k[1][j] + k[i][2] * k[2][j];
            let id = if i == j { T::cst(1.0) } else { T::cst(0.0) };
            *e = id + a * k[i][j] + b * k2;
        }
    }
    Rot3 { m }
}

/// [`moved`] on jets, for a cluster's rates: the pose's values are
/// [`moved`]'s on the values, bit for bit (so a frame's rates carry
/// exactly its positions), its rates those of the same motion written
/// smoothly in the unknowns (`base`, the pivot and the axis with their
/// rates; `x` the unknowns with theirs).
#[inline]
pub fn moved_rates(base: &Pose3<Jet2>, u: &Unknowns<Jet2>, x: &[Jet2]) -> Pose3<Jet2> {
    let mut values = [0.0; 6];
    for (v, x) in values.iter_mut().zip(&x[..u.count()]) {
        *v = x.v;
    }
    let exact = moved(&base.value(), &u.value(), &values);
    let mut p = *base;
    match *u {
        Unknowns::Free => {
            let o = base.pos;
            p.rotate_about(o, &exp_smooth([x[0], x[1], x[2]]));
            p.translate([x[3], x[4], x[5]]);
        }
        Unknowns::Pivot(c) => p.rotate_about(c, &exp_smooth([x[0], x[1], x[2]])),
        Unknowns::Axis(c, a) => {
            let (s, cos) = x[0].sin_cos();
            p.rotate_about(c, &Rot3::about_axis(a, cos, s));
        }
    }
    p.with_values(&Pose3::cst(exact))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The jets [`moved_rates`] gives are [`moved`]'s values and the
    /// central differences of [`moved`] along a motion of the unknowns,
    /// the pivot and the axis, near and away from the warm start.
    #[test]
    fn moved_rates_are_the_derivatives_of_moved() {
        let base = Pose3 {
            rot: Rot3::about_axis([0.0, 0.6, 0.8], 0.8, 0.6),
            pos: [0.1, -0.2, 0.3],
        };
        let (dbase, dx) = ([0.2, 0.1, -0.3], [0.3, -0.1, 0.2, 0.5, -0.4, 0.1]);
        for x0 in [
            [0.0; 6],
            [1e-5, -2e-5, 1e-5, 0.1, 0.2, 0.3],
            [0.4, -0.3, 0.9, 0.1, 0.2, 0.3],
        ] {
            for kind in 0..3 {
                let at = |t: f64| {
                    let pivot = [0.5 + 0.1 * t, 0.2, -0.1 * t];
                    let axis = super::super::unit([0.1 * t, 0.6, 0.8]);
                    let u = match kind {
                        0 => Unknowns::Free,
                        1 => Unknowns::Pivot(pivot),
                        _ => Unknowns::Axis(pivot, axis),
                    };
                    let mut b = base;
                    b.translate(scale(dbase, t));
                    let x: Vec<f64> = (0..6).map(|k| x0[k] + dx[k] * t + 0.3 * dx[k] * t * t).collect();
                    (b, u, x)
                };
                let jet = |t: Jet2| {
                    let pivot = [Jet2::cst(0.5) + t.mul_f64(0.1), Jet2::cst(0.2), t.mul_f64(-0.1)];
                    let axis = super::super::unit([t.mul_f64(0.1), Jet2::cst(0.6), Jet2::cst(0.8)]);
                    let u = match kind {
                        0 => Unknowns::Free,
                        1 => Unknowns::Pivot(pivot),
                        _ => Unknowns::Axis(pivot, axis),
                    };
                    let mut b = Pose3::<Jet2>::cst(base);
                    b.translate([0, 1, 2].map(|k| t.mul_f64(dbase[k])));
                    let x: Vec<Jet2> = (0..6)
                        .map(|k| Jet2::cst(x0[k]) + t.mul_f64(dx[k]) + (t * t).mul_f64(0.3 * dx[k]))
                        .collect();
                    moved_rates(&b, &u, &x)
                };
                let entries =
                    |p: &Pose3| -> Vec<f64> { p.rot.m.iter().flatten().chain(&p.pos).copied().collect() };
                let h = 1e-4;
                let f = |t: f64| {
                    let (b, u, x) = at(t);
                    entries(&moved(&b, &u, &x))
                };
                let (p, m, z) = (f(h), f(-h), f(0.0));
                let j = jet(Jet2::new(0.0, 1.0, 0.0));
                let js: Vec<Jet2> = j.rot.m.iter().flatten().chain(&j.pos).copied().collect();
                assert_eq!(js.len(), 12);
                for (k, jet) in js.iter().enumerate() {
                    assert_eq!(jet.v.to_bits(), z[k].to_bits(), "kind {kind} [{k}]: value");
                    let first = (p[k] - m[k]) / (2.0 * h);
                    let second = (p[k] - 2.0 * z[k] + m[k]) / (h * h);
                    assert!(
                        (jet.d - first).abs() < 1e-8,
                        "kind {kind} x0 {x0:?} [{k}]: {} vs {first}",
                        jet.d
                    );
                    assert!(
                        (jet.dd - second).abs() < 1e-5,
                        "kind {kind} x0 {x0:?} [{k}]: {} vs {second}",
                        jet.dd
                    );
                }
            }
        }
    }
}
