//! Placing a body once its loci are met: rotations about a point or an axis
//! and translations, each applied to the body's current pose.

use super::{cross, cross_by, cst, dot, dot_by, norm2, rate_bits, reject, reject_by, sub, Pose3, Rot3, Vec3};
use crate::planar::Degrees;
use crate::scalar::{Factor, Real};

/// A perpendicular shorter than this fraction of its point's distance from
/// the pivot is rounding, not a direction: the point counts as on the axis.
const ON_AXIS: f64 = 1e-12;

/// Rotates a body about the world point `pivot` by the minimal rotation
/// taking the direction `from` to the direction `to` ([`Rot3::minimal`]).
/// `from` and `to` are directions (of any non-zero length), typically a
/// marker's world position minus the pivot and its target minus the pivot;
/// [`rotate_about_point_onto`] takes the points themselves.
#[inline]
pub fn rotate_about_point<T: Real>(pose: &mut Pose3<T>, pivot: Vec3<T>, from: Vec3<T>, to: Vec3<T>) {
    // Already aligned (to rounding): the common case of a body whose
    // direction a previous frame set, at no cost. On jets the pose keeps
    // its value and takes the rates of the turn (which need not vanish),
    // unless neither direction has rates: then the turn has none either.
    let k = cross(from, to);
    if dot(from, to).value() > 0.0 && norm2(k).value() <= 1e-30 * norm2(from).value() * norm2(to).value() {
        if T::JETS && rate_bits(from) | rate_bits(to) != 0 {
            let before = *pose;
            pose.rotate_about(pivot, &Rot3::minimal(from, to));
            *pose = pose.with_values(&before);
        }
        return;
    }
    pose.rotate_about(pivot, &Rot3::minimal(from, to));
}

/// Rotates a body about the world point `pivot` by the minimal rotation that
/// puts the world point `from` on the ray from `pivot` through the world
/// point `to` (exactly on `to` when both are as far from the pivot).
#[inline]
pub fn rotate_about_point_onto<T: Real>(pose: &mut Pose3<T>, pivot: Vec3<T>, from: Vec3<T>, to: Vec3<T>) {
    rotate_about_point(pose, pivot, sub(from, pivot), sub(to, pivot));
}

/// Rotates a body about the line through `pivot` along the unit vector
/// `axis` by the signed angle (right-handed about `axis`) from the
/// perpendicular dropped from the world point `from` onto the axis to the
/// one dropped from the world point `to`. `from` then lies in the half-plane
/// bounded by the axis that contains `to` (on `to` when both are as far
/// from the axis and at the same height along it).
///
/// If either point is on the axis, the angle is undefined and the body does
/// not move.
#[inline]
pub fn rotate_about_axis_onto<T: Real>(
    pose: &mut Pose3<T>,
    pivot: Vec3<T>,
    axis: Vec3<T>,
    from: Vec3<T>,
    to: Vec3<T>,
) {
    rotate_about_axis_dir(pose, pivot, axis, sub(from, pivot), sub(to, pivot));
}

/// Rotates a body about the line through `pivot` along the unit vector
/// `axis` by the signed angle from the component of the direction
/// `from_dir` perpendicular to the axis to that of `to_dir`.
///
/// If either direction is (to rounding) along the axis, the angle is
/// undefined and the body does not move.
#[inline]
pub fn rotate_about_axis_dir<T: Real>(
    pose: &mut Pose3<T>,
    pivot: Vec3<T>,
    axis: Vec3<T>,
    from_dir: Vec3<T>,
    to_dir: Vec3<T>,
) {
    if let Some((c, s)) = axis_turn(axis, from_dir, to_dir) {
        rotate_about_axis_angle(pose, pivot, axis, c, s);
    }
}

/// The (cos, sin) of the signed angle about the unit `axis` from the
/// component of `from_dir` across the axis to that of `to_dir`; none when
/// either is (to rounding) along the axis.
#[inline(always)]
///
/// The axis and `from_dir` are numbers of the frame's kind, or plain
/// numbers (a fixed hinge's line and a body's direction as drawn): then only
/// the products by `to_dir` carry rates.
fn axis_turn<T: Real, F: Real + Factor<T>>(
    axis: [F; 3],
    from_dir: [F; 3],
    to_dir: Vec3<T>,
) -> Option<(T, T)> {
    let u = reject(from_dir, axis);
    let v = reject_by(to_dir, axis);
    let (u2, v2) = (norm2(u).value(), norm2(v).value());
    if u2 <= ON_AXIS * ON_AXIS * norm2(from_dir).value() || v2 <= ON_AXIS * ON_AXIS * norm2(to_dir).value() {
        return None;
    }
    // cos and sin of the angle scaled by |u||v|: no trigonometry, one square
    // root to normalise (the pair's own length, so it is a unit pair even if
    // `axis` is a little off unit length).
    let c = dot_by(v, u);
    let s = dot_by(cross_by(u, v), axis);
    let n = (c * c + s * s).sqrt();
    (n.value() > 0.0).then(|| (c / n, s / n))
}

/// Places a body hinged on a fixed line outright: its pose becomes the turn
/// by the angle whose cosine and sine are `cos` and `sin` about the line
/// through `pivot` along the unit `axis`, from the drawn pose.
///
/// A body whose only joint to the fixed bodies is a hinge never leaves that
/// line, so setting the pose (rather than turning last frame's) needs no
/// step re-imposing the hinge, and a rotation built afresh every frame
/// never drifts from orthonormal.
#[inline(always)]
pub fn hinge<T: Real>(pose: &mut Pose3<T>, pivot: Vec3, axis: Vec3, cos: T, sin: T) {
    *pose = super::joint_pose(axis, pivot, cos, sin, T::cst(0.0));
}

/// [`hinge`] by `degrees` (right-handed about `axis`), the cosine and sine
/// from [`Rot::from_degrees`](crate::planar::Rot::from_degrees) as every
/// angle input's.
#[inline(always)]
pub fn hinge_degrees<T: Degrees>(pose: &mut Pose3<T>, pivot: Vec3, axis: Vec3, degrees: T) {
    let r = degrees.degrees_rot();
    hinge(pose, pivot, axis, r.c, r.s);
}

/// [`hinge`] by the angle that takes the body's point `from` *as drawn* onto
/// the half-plane of the world point `to` bounded by the line (the
/// outright form of [`rotate_about_axis_onto`]). If either point is on the
/// line the angle is undefined and the body keeps its pose.
#[inline(always)]
pub fn hinge_onto<T: Real>(pose: &mut Pose3<T>, pivot: Vec3, axis: Vec3, from: Vec3, to: Vec3<T>) {
    hinge_dir(pose, pivot, axis, sub(from, pivot), sub(to, cst(pivot)));
}

/// [`hinge`] by the angle that takes the body's direction `from_dir` *as
/// drawn* to the world direction `to_dir` (their components across the
/// line; the outright form of [`rotate_about_axis_dir`]). If either is
/// along the line the body keeps its pose.
#[inline(always)]
pub fn hinge_dir<T: Real>(pose: &mut Pose3<T>, pivot: Vec3, axis: Vec3, from_dir: Vec3, to_dir: Vec3<T>) {
    if let Some((c, s)) = axis_turn(axis, from_dir, to_dir) {
        hinge(pose, pivot, axis, c, s);
    }
}

/// Rotates a body about the line through `pivot` along the unit vector
/// `axis` by the angle whose cosine and sine are `cos` and `sin`.
#[inline]
pub fn rotate_about_axis_angle<T: Real>(pose: &mut Pose3<T>, pivot: Vec3<T>, axis: Vec3<T>, cos: T, sin: T) {
    pose.rotate_about(pivot, &Rot3::about_axis(axis, cos, sin));
}

/// Translates a body by `to − from`, so that the world point `from` (a
/// marker's current world position) lands on `to`.
#[inline]
pub fn translate_onto<T: Real>(pose: &mut Pose3<T>, from: Vec3<T>, to: Vec3<T>) {
    pose.translate(sub(to, from));
}

/// Translates a body along the unit `dir` by the component of `to − from`
/// along it (a body sliding on a line: `from` reaches `to`'s height).
#[inline]
pub fn translate_along<T: Real>(pose: &mut Pose3<T>, from: Vec3<T>, to: Vec3<T>, dir: Vec3<T>) {
    pose.translate(super::scale(dir, dot(sub(to, from), dir)));
}

/// Translates a body across the unit `normal` by the component of
/// `to − from` across it (a body sliding in a plane).
#[inline]
pub fn translate_in_plane<T: Real>(pose: &mut Pose3<T>, from: Vec3<T>, to: Vec3<T>, normal: Vec3<T>) {
    let v = sub(to, from);
    pose.translate(sub(v, super::scale(normal, dot(v, normal))));
}

/// Translates a body so its point `from` lands on its foot on the line
/// (`through`, unit `dir`).
#[inline]
pub fn translate_to_line<T: Real>(pose: &mut Pose3<T>, from: Vec3<T>, through: Vec3<T>, dir: Vec3<T>) {
    let foot = super::add(through, super::scale(dir, dot(sub(from, through), dir)));
    translate_onto(pose, from, foot);
}

/// Translates a body along the unit `normal` so its point `from` lands on
/// the plane (`through`, `normal`).
#[inline]
pub fn translate_to_plane<T: Real>(pose: &mut Pose3<T>, from: Vec3<T>, through: Vec3<T>, normal: Vec3<T>) {
    pose.translate(super::scale(normal, -dot(sub(from, through), normal)));
}

/// A slide input: translates a body along the unit `dir` so that the axial
/// distance `(second − first)·dir` becomes `axial`; `sign` is +1 when the
/// body carries the second marker and −1 when it carries the first.
#[inline]
pub fn slide_to<T: Real>(
    pose: &mut Pose3<T>,
    first: Vec3<T>,
    second: Vec3<T>,
    dir: Vec3<T>,
    axial: T,
    sign: f64,
) {
    let err = axial - dot(sub(second, first), dir);
    pose.translate(super::scale(dir, err.mul_f64(sign)));
}
