//! The two rotations of the spatial fragments that set an angle rather
//! than take one direction onto another: the twist about a joint axis
//! (angle inputs, offset-x) and the tilt onto a cone (offset-z on a free
//! rotation).

use super::{cross, dot, norm, perpendicular, scale, unit, Pose3, Rot3, Vec3};
use crate::planar::Rot;
use crate::scalar::Real;

/// The (sin, cos) of the rotation about `axis` that brings the twist of
/// `x2` about `axis` from `x1` to `target`: the body carrying `x2` turns by
/// `sign·(target − current)` (`sign` −1 when the body turned carries `x1`
/// instead, which moves the twist the other way). The target comes as a
/// cos/sin pair ([`Rot::from_degrees`] of the input) and the current twist
/// is read as one from dot products, so a frame needs no trigonometry here.
#[inline]
pub fn twist_correction<T: Real>(
    axis: Vec3<T>,
    x1: Vec3<T>,
    x2: Vec3<T>,
    target: Rot<T>,
    sign: f64,
) -> (T, T) {
    let y1 = cross(axis, x1);
    let (c0, s0) = (dot(x2, x1), dot(x2, y1));
    // Unit vectors: no overflow to guard against, so no `hypot`.
    let n = (c0 * c0 + s0 * s0).sqrt();
    if n.value() == 0.0 {
        // x2 along the axis: no twist to measure, nothing to turn.
        return (T::cst(0.0), T::cst(1.0));
    }
    let (c0, s0) = (c0 / n, s0 / n);
    // target · current⁻¹ as complex numbers.
    let c = target.c * c0 + target.s * s0;
    let s = target.s * c0 - target.c * s0;
    (s.mul_f64(sign), c)
}

/// Rotates `pose` about `pivot`, about the axis `from × to`, until the
/// angle between the body's direction `from` and `to` is acos(`cos`): the
/// smallest rotation that puts `from` on the cone about `to`. Parallel
/// directions tilt about a deterministic perpendicular.
#[inline]
pub fn tilt<T: Real>(pose: &mut Pose3<T>, pivot: Vec3<T>, from: Vec3<T>, to: Vec3<T>, cos: f64) {
    let k = cross(from, to);
    let s = norm(k);
    let axis = if s.value() > 1e-12 {
        scale(k, s.recip())
    } else {
        perpendicular(from)
    };
    let current = s.atan2(dot(from, to));
    let wanted = cos.clamp(-1.0, 1.0).acos();
    let turn = current - T::cst(wanted);
    let (sin, cos) = turn.sin_cos();
    let r = Rot3::about_axis(unit(axis), cos, sin);
    pose.rotate_about(pivot, &r);
}
