//! Spatial (3D) geometry: body poses and the steps of a spatial plan.
//!
//! Conventions shared with the compiler (the same as [`crate::planar`]):
//! - every body's local frame is the world frame of the pose *as drawn*, so
//!   a marker's local coordinates are its drawn world coordinates and every
//!   body's drawn pose is [`Pose3::IDENTITY`];
//! - a rotation is a row-major 3×3 matrix ([`Rot3`]); a rotated vector is
//!   `m·v`. Rotations are built from (cos, sin) pairs, quaternions of a
//!   half-way vector or Rodrigues' formula, so a frame evaluates no
//!   trigonometric function except once per angle input
//!   ([`Rot3::about_axis_degrees`]);
//! - nothing allocates: points, directions and matrices are fixed-size
//!   arrays;
//! - steps that can fail take the frame's [`Ctx`](crate::frame::Ctx) and a
//!   step id and report through [`Ctx::fail`](crate::frame::Ctx::fail); under
//!   the stretch policy they return the closest reasonable answer instead;
//! - steps with two roots take a [`Branch`](crate::frame::Branch) whose sign
//!   is geometric (documented per function), so a smooth motion away from
//!   singular poses never flips it.
//! - the steps are written once, generic over [`Real`]: on `f64` they
//!   place a frame, on [`Jet2`]s they also carry its velocities and
//!   accelerations (forward mode through the plan, [`Rates`](crate::rates::Rates)). Every
//!   decision (which root, whether loci meet, whether a turn is within
//!   rounding of none) is taken on the values, so a run on jets follows the
//!   run on `f64` and its values are that run's, bit for bit; a shortcut
//!   that drops a dependence on `f64` (a turn within rounding of none taken
//!   as none) keeps its exact value on jets and takes the rates of the
//!   turn it stands for; dead points give infinite rates
//!   ([`Real::sqrt_dead`]), reported as singular.
//!
//! Besides the vector helpers, [`Rot3`], [`Pose3`] and [`joint_pose`], the
//! module holds the actions on one body (rotating it about a point or an
//! axis, translating it: [`rotate_about_point`], [`rotate_about_axis_onto`],
//! ...) and the loci intersections (a [`Circle`], [`Sphere`], [`Line`],
//! [`Plane`] or [`Cone`] with another, and the rotation about an axis that
//! meets a condition: [`circle_circle`], [`rotation_to_condition`], ...),
//! each step with two roots keeping its choice in a [`Slot`].

pub mod cluster;
mod locus;
mod place;
mod rates;
pub mod rows;
mod turn;

#[cfg(test)]
mod tests;

pub use locus::{
    circle_about, circle_circle, circle_circle_candidates, circle_distance, cone_cone, line_circle,
    line_plane, line_sphere, plane_circle, rotation_to_condition, sphere_circle, Circle, CircleCandidates,
    Cone, Line, Plane, Slot, Sphere,
};
pub use place::{
    hinge, hinge_degrees, hinge_dir, hinge_onto, rotate_about_axis_angle, rotate_about_axis_dir,
    rotate_about_axis_onto, rotate_about_point, rotate_about_point_onto, slide_to, translate_along,
    translate_in_plane, translate_onto, translate_to_line, translate_to_plane,
};
pub use rates::checked3;
pub use turn::{tilt, twist_correction};

use crate::scalar::{Factor, Jet2, Real};

/// A point or a vector in space (of `f64`s, or of [`Jet2`]s carrying its
/// rates).
pub type Vec3<T = f64> = [T; 3];

/// `a + b`.
#[inline(always)]
pub fn add<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[0].vadd(b[0]), a[1].vadd(b[1]), a[2].vadd(b[2])]
}

/// `a − b`.
#[inline(always)]
pub fn sub<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [a[0].vsub(b[0]), a[1].vsub(b[1]), a[2].vsub(b[2])]
}

/// `a·k`.
#[inline(always)]
pub fn scale<T: Real>(a: Vec3<T>, k: T) -> Vec3<T> {
    [a[0].vmul(k), a[1].vmul(k), a[2].vmul(k)]
}

/// The dot product `a·b`.
#[inline(always)]
pub fn dot<T: Real>(a: Vec3<T>, b: Vec3<T>) -> T {
    a[0].vmul(b[0]).vadd(a[1].vmul(b[1])).vadd(a[2].vmul(b[2]))
}

/// The cross product `a × b` (right-handed).
#[inline(always)]
pub fn cross<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    [
        a[1].vmul(b[2]).vsub(a[2].vmul(b[1])),
        a[2].vmul(b[0]).vsub(a[0].vmul(b[2])),
        a[0].vmul(b[1]).vsub(a[1].vmul(b[0])),
    ]
}

/// `a·b` for a constant `a`: [`dot`]'s products on `b`'s side, so the
/// same values.
#[inline(always)]
pub fn dot_cst<T: Real>(a: Vec3, b: Vec3<T>) -> T {
    dot_by(b, a)
}

/// `a × b` for a constant `a`, as [`dot_cst`] is [`dot`].
#[inline(always)]
pub fn cross_cst<T: Real>(a: Vec3, b: Vec3<T>) -> Vec3<T> {
    cross_by(a, b)
}

/// `a·n` for a [`Factor`] `n` (a constant of the plan, such as a fixed
/// circle's normal, or a number of the step's kind): the same products as
/// [`dot`], on `a`'s side.
#[inline(always)]
pub fn dot_by<T: Real>(a: Vec3<T>, n: [impl Factor<T>; 3]) -> T {
    n[0].times(a[0]).vadd(n[1].times(a[1])).vadd(n[2].times(a[2]))
}

/// `n × b` for a [`Factor`] `n`, as [`dot_by`] is [`dot`].
#[inline(always)]
pub fn cross_by<T: Real>(n: [impl Factor<T>; 3], b: Vec3<T>) -> Vec3<T> {
    [
        n[1].times(b[2]).vsub(n[2].times(b[1])),
        n[2].times(b[0]).vsub(n[0].times(b[2])),
        n[0].times(b[1]).vsub(n[1].times(b[0])),
    ]
}

/// `n·k` for a [`Factor`] `n`, as [`dot_by`] is [`dot`].
#[inline(always)]
pub fn scale_by<T: Real>(n: [impl Factor<T>; 3], k: T) -> Vec3<T> {
    [n[0].times(k), n[1].times(k), n[2].times(k)]
}

/// Zero when no entry of `a` has rates ([`Real::rate_bits`]).
#[inline(always)]
pub fn rate_bits<T: Real>(a: Vec3<T>) -> u64 {
    a[0].rate_bits() | a[1].rate_bits() | a[2].rate_bits()
}

/// The squared length `|a|²`.
#[inline(always)]
pub fn norm2<T: Real>(a: Vec3<T>) -> T {
    dot(a, a)
}

/// The length `|a|`.
#[inline(always)]
pub fn norm<T: Real>(a: Vec3<T>) -> T {
    norm2(a).sqrt()
}

/// The distance `|a − b|`.
#[inline(always)]
pub fn dist<T: Real>(a: Vec3<T>, b: Vec3<T>) -> T {
    norm(sub(a, b))
}

/// `a` scaled to unit length. The zero vector stays zero (a direction that
/// does not exist is reported as none rather than as NaN).
#[inline(always)]
pub fn unit<T: Real>(a: Vec3<T>) -> Vec3<T> {
    let n = norm(a);
    if n.value() > 0.0 {
        scale(a, n.recip())
    } else {
        a
    }
}

/// The component of `v` perpendicular to the unit vector `axis`:
/// `v − (v·axis)·axis`.
#[inline(always)]
pub fn reject<T: Real>(v: Vec3<T>, axis: Vec3<T>) -> Vec3<T> {
    sub(v, scale(axis, dot(v, axis)))
}

/// [`reject`] by a [`Factor`] axis (a constant of the plan, or a number of
/// the step's kind): the same products, on `v`'s side.
#[inline(always)]
pub fn reject_by<T: Real>(v: Vec3<T>, axis: [impl Factor<T>; 3]) -> Vec3<T> {
    sub(v, scale_by(axis, dot_by(v, axis)))
}

/// Constants as a point of `T`s.
#[inline(always)]
pub fn cst<T: Real>(v: Vec3) -> Vec3<T> {
    [T::cst(v[0]), T::cst(v[1]), T::cst(v[2])]
}

/// The values of a point of `T`s.
#[inline(always)]
pub fn value<T: Real>(v: Vec3<T>) -> Vec3 {
    [v[0].value(), v[1].value(), v[2].value()]
}

/// A deterministic unit vector perpendicular to `v`: `v` crossed with the
/// world axis least aligned with it (the smallest `|v[i]|`, ties broken
/// x before y before z), normalised. The zero vector gives zero.
///
/// The choice is not continuous in `v` (no choice can be, on the sphere);
/// it is only used where any perpendicular will do, such as the axis of a
/// half turn between opposite directions.
#[inline]
pub fn perpendicular<T: Real>(v: Vec3<T>) -> Vec3<T> {
    let a = [v[0].value().abs(), v[1].value().abs(), v[2].value().abs()];
    let e = if a[0] <= a[1] && a[0] <= a[2] {
        [1.0, 0.0, 0.0]
    } else if a[1] <= a[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    unit(cross(v, cst(e)))
}

/// `1 − cos` computed without cancellation for small angles: `sin²/(1 + cos)`
/// when `cos > 0` (equal when `cos² + sin² = 1`). At the zero angle it is
/// exactly 0, so a rotation by (1, 0) is exactly the identity.
///
/// On jets the rates are `1 − cos`'s whatever the value's form: exactly
/// minus the cosine's, so `cos + vers` has none and a turn about an axis
/// along a coordinate axis leaves that axis's direction with rates of
/// exactly zero, as it should — a later step can then tell that nothing
/// turns it (for other axes the products leave rounding's worth).
#[inline(always)]
fn versine<T: Real>(cos: T, sin: T) -> T {
    let vers = T::cst(1.0) - cos;
    if cos.value() > 0.0 {
        vers.with_value((sin * sin / (T::cst(1.0) + cos)).value())
    } else {
        vers
    }
}

/// A rotation as a row-major 3×3 matrix: the rotated `v` is `m·v` (of
/// `f64`s, or of [`Jet2`]s carrying the rotation's rates).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rot3<T = f64> {
    /// The rows of the matrix.
    pub m: [[T; 3]; 3],
}

impl Default for Rot3 {
    fn default() -> Self {
        Rot3::IDENTITY
    }
}

impl Rot3 {
    /// No rotation.
    pub const IDENTITY: Rot3 = Rot3 {
        m: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    /// The rotation about the unit vector `axis` by `degrees`
    /// (right-handed). The cosine and sine come from
    /// [`Rot::from_degrees`](crate::planar::Rot::from_degrees), so multiples
    /// of 90° are exact and planar and spatial plans agree on every angle.
    #[inline]
    pub fn about_axis_degrees(axis: Vec3, degrees: f64) -> Rot3 {
        let r = crate::planar::Rot::from_degrees(degrees);
        Rot3::about_axis(axis, r.c, r.s)
    }

    /// The nearest orthonormal, right-handed matrix by Gram–Schmidt on the
    /// rows: row 0 is normalised, row 1 is made perpendicular to it and
    /// normalised, row 2 is their cross product. Use it to clean up a
    /// rotation that was composed many times. Degenerate rows are replaced
    /// deterministically (x axis, then [`perpendicular`]).
    pub fn orthonormalize(&self) -> Rot3 {
        let mut r0 = unit(self.m[0]);
        if norm2(r0) == 0.0 {
            r0 = [1.0, 0.0, 0.0];
        }
        let mut r1 = unit(reject(self.m[1], r0));
        if norm2(r1) == 0.0 {
            r1 = perpendicular(r0);
        }
        // A second pass removes what rounding left of row 0 in row 1.
        r1 = unit(reject(r1, r0));
        Rot3 {
            m: [r0, r1, cross(r0, r1)],
        }
    }
}

impl Rot3<Jet2> {
    /// The values alone.
    #[inline(always)]
    pub fn value(&self) -> Rot3 {
        // Indexed, not `map`: plans call this for every body every frame,
        // and the generated code inlines it only as plain reads.
        let m = &self.m;
        Rot3 {
            m: [value(m[0]), value(m[1]), value(m[2])],
        }
    }
}

impl<T: Real> Rot3<T> {
    /// A rotation of constants.
    #[inline(always)]
    pub fn cst(r: Rot3) -> Rot3<T> {
        Rot3 { m: r.m.map(cst) }
    }

    /// `self`'s rates with `values`'s values, entry by entry
    /// ([`Real::with_value`]).
    #[inline(always)]
    fn with_values(&self, values: &Rot3) -> Rot3<T> {
        let mut m = self.m;
        for (row, vals) in m.iter_mut().zip(&values.m) {
            for (x, v) in row.iter_mut().zip(vals) {
                *x = x.with_value(*v);
            }
        }
        Rot3 { m }
    }

    /// Rotates a vector: `m·v`.
    #[inline(always)]
    pub fn apply(&self, v: Vec3<T>) -> Vec3<T> {
        let m = &self.m;
        [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
    }

    /// Rotates a constant vector: `m·v` (the same products as
    /// [`Rot3::apply`], without lifting `v` to `T`).
    #[inline(always)]
    pub fn apply_cst(&self, v: Vec3) -> Vec3<T> {
        let m = &self.m;
        [dot_by(m[0], v), dot_by(m[1], v), dot_by(m[2], v)]
    }

    /// Rotates a vector by the inverse rotation: `mᵀ·v`.
    #[inline(always)]
    pub fn apply_inverse(&self, v: Vec3<T>) -> Vec3<T> {
        let m = &self.transpose().m;
        [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
    }

    /// The transpose, which is the inverse of a rotation.
    #[inline(always)]
    pub fn transpose(&self) -> Rot3<T> {
        let m = &self.m;
        Rot3 {
            m: [
                [m[0][0], m[1][0], m[2][0]],
                [m[0][1], m[1][1], m[2][1]],
                [m[0][2], m[1][2], m[2][2]],
            ],
        }
    }

    /// The matrix product `self.m · other.m`: `other` first, then `self`.
    #[inline(always)]
    pub fn mul(&self, other: &Rot3<T>) -> Rot3<T> {
        let (a, b) = (&self.m, &other.m);
        let mut m = [[T::cst(0.0); 3]; 3];
        // On jets, a body's rotation that no step of the frame has turned
        // yet has no rates: the product by its values alone is the same
        // jets (to the sign of a zero) at half the multiplications. Its
        // first turn in a frame is the common case of every body placed
        // by turning.
        if T::JETS && rate_bits(b[0]) | rate_bits(b[1]) | rate_bits(b[2]) == 0 {
            for (i, row) in m.iter_mut().enumerate() {
                for (j, x) in row.iter_mut().enumerate() {
                    *x = dot_cst([0, 1, 2].map(|k| b[k][j].value()), a[i]);
                }
            }
            return Rot3 { m };
        }
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = dot(a[i], [b[0][j], b[1][j], b[2][j]]);
            }
        }
        Rot3 { m }
    }

    /// `self` followed by `other`: the product `other.m · self.m`.
    #[inline(always)]
    pub fn then(&self, other: &Rot3<T>) -> Rot3<T> {
        other.mul(self)
    }

    /// The right-handed rotation about the unit vector `axis` by the angle
    /// whose cosine and sine are `cos` and `sin` (a unit pair), by Rodrigues'
    /// formula `R = cos·I + sin·[axis]× + (1 − cos)·axis·axisᵀ`.
    ///
    /// `(1, 0)` gives exactly the identity. The axis is a [`Factor`]: a
    /// fixed hinge's is plain numbers, which jets multiply by at a third of
    /// a product's cost (the same values).
    #[inline(always)]
    pub fn about_axis(axis: [impl Factor<T>; 3], cos: T, sin: T) -> Rot3<T> {
        let [x, y, z] = axis;
        let v = versine(cos, sin);
        let (vx, vy, vz) = (x.times(v), y.times(v), z.times(v));
        let (sx, sy, sz) = (x.times(sin), y.times(sin), z.times(sin));
        Rot3 {
            m: [
                [cos + x.times(vx), y.times(vx) - sz, z.times(vx) + sy],
                [y.times(vx) + sz, cos + y.times(vy), z.times(vy) - sx],
                [z.times(vx) - sy, z.times(vy) + sx, cos + z.times(vz)],
            ],
        }
    }

    /// The rotation of the unit quaternion proportional to `(w, x, y, z)`.
    /// Every entry is divided by the squared norm instead of normalising the
    /// quaternion first, and the diagonal is written `(w² + x² − y² − z²)/n²`
    /// rather than `1 − 2(y² + z²)/n²`: of the usual forms this one came out
    /// most nearly orthonormal (worst entry of `R·Rᵀ − I` about 5 ulps over
    /// 200,000 random rotations, typically 1 or 2). The caller guarantees a
    /// non-zero quaternion.
    #[inline(always)]
    fn from_quaternion(w: T, x: T, y: T, z: T) -> Rot3<T> {
        let (ww, xx, yy, zz) = (w * w, x * x, y * y, z * z);
        let k = (ww + xx + yy + zz).recip();
        let t = k.mul_f64(2.0);
        let (xy, xz, yz) = (x * y, x * z, y * z);
        let (wx, wy, wz) = (w * x, w * y, w * z);
        Rot3 {
            m: [
                [(ww + xx - yy - zz) * k, (xy - wz) * t, (xz + wy) * t],
                [(xy + wz) * t, (ww - xx + yy - zz) * k, (yz - wx) * t],
                [(xz - wy) * t, (yz + wx) * t, (ww - xx - yy + zz) * k],
            ],
        }
    }

    /// The minimal rotation taking the direction `from` to the direction
    /// `to` (both of any non-zero length): the rotation about `from × to` by
    /// the angle between them.
    ///
    /// - parallel directions give exactly the identity (on jets: with the
    ///   rates of the turn, which need not vanish there);
    /// - opposite directions give the half turn about
    ///   [`perpendicular`]`(from)` (any half turn would do; this one is
    ///   deterministic);
    /// - a zero direction gives the identity.
    ///
    /// Built as the quaternion `(|h|²/2, â × h)` of the half-way vector
    /// `h = â + b̂`: near opposite directions `h` is small but exact, so the
    /// angle stays accurate where `1 + â·b̂` would cancel. The matrix is
    /// orthonormal to a few ulps.
    #[inline]
    pub fn minimal(from: Vec3<T>, to: Vec3<T>) -> Rot3<T> {
        // On jets, `from` is often without rates (a direction of a body no
        // step has turned yet this frame): its products with `to` then
        // multiply by its values, for a third of a jet product's cost.
        // The same numbers either way (the products' values are the same
        // roundings).
        if T::JETS && rate_bits(from) == 0 {
            let f = from.map(Real::value);
            let (dot, cross) = (dot_cst(f, to), cross_cst(f, to));
            return Self::minimal_of(from, to, T::cst(norm2(f)), dot, cross);
        }
        Self::minimal_of(from, to, norm2(from), dot(from, to), cross(from, to))
    }

    /// [`Rot3::minimal`] given `|from|²`, `from·to` and `from × to`.
    #[inline(always)]
    fn minimal_of(from: Vec3<T>, to: Vec3<T>, fa: T, from_dot_to: T, from_cross_to: Vec3<T>) -> Rot3<T> {
        let fb = norm2(to);
        if fa.value() == 0.0 || fb.value() == 0.0 {
            return Rot3::cst(Rot3::IDENTITY);
        }
        // Away from opposite directions, Rodrigues' form straight from the
        // unnormalised vectors: with k = (a × b)/(|a||b|) and c = cos θ,
        // R = c·I + [k]× + k kᵀ/(1 + c) — one square root, one division.
        let ab = (fa * fb).sqrt();
        let c = from_dot_to / ab;
        if c.value() > -0.5 {
            let k = scale(from_cross_to, ab.recip());
            // Within rounding of parallel: exactly the identity, rather
            // than a turn by rounding noise.
            let parallel = norm2(k).value() <= 64e-32;
            if parallel && !T::JETS {
                return Rot3::cst(Rot3::IDENTITY);
            }
            let f = (T::cst(1.0) + c).recip();
            let [x, y, z] = k;
            let (fx, fy, fz) = (f * x, f * y, f * z);
            let r = Rot3 {
                m: [
                    [c + fx * x, fx * y - z, fx * z + y],
                    [fx * y + z, c + fy * y, fy * z - x],
                    [fx * z - y, fy * z + x, c + fz * z],
                ],
            };
            // On jets: the identity's value, the turn's rates.
            return if parallel {
                r.with_values(&Rot3::IDENTITY)
            } else {
                r
            };
        }
        let a = unit(from);
        let b = unit(to);
        let h = add(a, b);
        // The quaternion is (|â||b̂| + â·b̂, â × b̂). Its scalar part equals
        // (|h|² − (|â| − |b̂|)²)/2: |h|²/2 is that to O(ε²) without the
        // cancellation of 1 + â·b̂ near opposite directions (where an error
        // of ε in |â| would be an error of ε/|h|² in the angle).
        let w = norm2(h).mul_f64(0.5);
        let v = cross(a, h);
        // |h| ≈ 2 cos(θ/2): below 1e-15 h is the rounding of normalising two
        // opposite directions and carries no axis.
        if w.value() < 0.5e-30 {
            let p = perpendicular(a);
            return Rot3::from_quaternion(T::cst(0.0), p[0], p[1], p[2]);
        }
        Rot3::from_quaternion(w, v[0], v[1], v[2])
    }

    /// One Newton–Schulz step toward the nearest rotation,
    /// R·(3I − RᵀR)/2: it squares the orthonormality error, so applied once
    /// a frame it keeps rotations composed millions of times rigid (without
    /// it their error grows with every composition, and a mechanism's
    /// redundant checks eventually fail on bodies that are no longer rigid).
    /// No square root; an exact rotation comes back unchanged to rounding.
    #[inline]
    pub fn renormalized(&self) -> Rot3<T> {
        let m = &self.m;
        // E = RᵀR (symmetric).
        let mut e = [[T::cst(0.0); 3]; 3];
        for i in 0..3 {
            for j in i..3 {
                let v = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
                e[i][j] = v;
                e[j][i] = v;
            }
        }
        let mut out = [[T::cst(0.0); 3]; 3];
        for (r, row) in out.iter_mut().enumerate() {
            for (c, entry) in row.iter_mut().enumerate() {
                let mut v = T::cst(0.0);
                for k in 0..3 {
                    let f = if k == c { T::cst(3.0) - e[k][c] } else { -e[k][c] };
                    v = v + m[r][k] * f;
                }
                *entry = v.mul_f64(0.5);
            }
        }
        Rot3 { m: out }
    }
}

/// Where a body is: world(q) = `rot`·q + `pos` for a point q in local (=
/// drawn) coordinates (of `f64`s, or of [`Jet2`]s carrying the body's
/// velocity and acceleration).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pose3<T = f64> {
    /// Rotation relative to the drawn pose.
    pub rot: Rot3<T>,
    /// Translation (the world position of the local origin).
    pub pos: Vec3<T>,
}

impl Default for Pose3 {
    fn default() -> Self {
        Pose3::IDENTITY
    }
}

impl Pose3 {
    /// The drawn pose of every body.
    pub const IDENTITY: Pose3 = Pose3 {
        rot: Rot3::IDENTITY,
        pos: [0.0, 0.0, 0.0],
    };
}

impl Pose3<Jet2> {
    /// The values alone.
    #[inline(always)]
    pub fn value(&self) -> Pose3 {
        Pose3 {
            rot: self.rot.value(),
            pos: value(self.pos),
        }
    }

    /// Whether every rate is finite (not at a dead point).
    pub fn finite(&self) -> bool {
        self.nonfinite_bits() == 0
    }

    /// Zero when every rate is finite ([`Jet2::nonfinite_bits`] of every
    /// entry, ORed).
    #[inline(always)]
    pub fn nonfinite_bits(&self) -> u64 {
        let m = &self.rot.m;
        let rows =
            [0, 1, 2].map(|i| m[i][0].nonfinite_bits() | m[i][1].nonfinite_bits() | m[i][2].nonfinite_bits());
        let pos = self.pos[0].nonfinite_bits() | self.pos[1].nonfinite_bits() | self.pos[2].nonfinite_bits();
        rows[0] | rows[1] | rows[2] | pos
    }
}

impl<T: Real> Pose3<T> {
    /// A pose of constants.
    #[inline(always)]
    pub fn cst(p: Pose3) -> Pose3<T> {
        Pose3 {
            rot: Rot3::cst(p.rot),
            pos: cst(p.pos),
        }
    }

    /// `self`'s rates with `values`'s values ([`Real::with_value`]): a
    /// shortcut's exact pose with the rates of the motion it stands for.
    #[inline(always)]
    fn with_values(&self, values: &Pose3<T>) -> Pose3<T> {
        let mut pos = self.pos;
        for (x, v) in pos.iter_mut().zip(&values.pos) {
            *x = x.with_value(v.value());
        }
        let vals = Rot3 {
            m: values.rot.m.map(value),
        };
        Pose3 {
            rot: self.rot.with_values(&vals),
            pos,
        }
    }

    /// World position of a marker given in local (= drawn) coordinates.
    #[inline(always)]
    pub fn world(&self, q: Vec3) -> Vec3<T> {
        add(self.rot.apply_cst(q), self.pos)
    }

    /// World direction of a local direction (`rot·v`).
    #[inline(always)]
    pub fn dir(&self, v: Vec3) -> Vec3<T> {
        self.rot.apply_cst(v)
    }

    /// [`Pose3::world`] of a local point that moves itself (a marker
    /// carried along a slide input).
    #[inline(always)]
    pub fn world_of(&self, q: Vec3<T>) -> Vec3<T> {
        add(self.rot.apply(q), self.pos)
    }

    /// Applies the world rotation `r` about the world point `pivot`: every
    /// point moves to `pivot + r·(old world − pivot)`.
    #[inline(always)]
    pub fn rotate_about(&mut self, pivot: Vec3<T>, r: &Rot3<T>) {
        self.rot = self.rot.then(r);
        self.pos = add(pivot, r.apply(sub(self.pos, pivot)));
    }

    /// Moves the body by `v`.
    #[inline(always)]
    pub fn translate(&mut self, v: Vec3<T>) {
        self.pos = add(self.pos, v);
    }

    /// Keeps the rotation rigid after many compositions: when RᵀR is off
    /// the identity by more than 1e-14 (thousands of frames of rounding),
    /// one [`Rot3::renormalized`] step; otherwise nothing, so the check is
    /// all a frame pays. Plans call it on every moving body once a frame.
    #[inline]
    pub fn renormalize(&mut self) {
        let m = &self.rot.m;
        let col = |i: usize, j: usize| {
            m[0][i].value() * m[0][j].value()
                + m[1][i].value() * m[1][j].value()
                + m[2][i].value() * m[2][j].value()
        };
        let off = (col(0, 0) - 1.0)
            .abs()
            .max((col(1, 1) - 1.0).abs())
            .max((col(2, 2) - 1.0).abs())
            .max(col(0, 1).abs())
            .max(col(0, 2).abs())
            .max(col(1, 2).abs());
        // `!(off <= ..)`: a NaN rotation is left for the steps to report.
        if off > 1e-14 {
            self.rot = self.rot.renormalized();
        }
    }
}

impl Pose3 {
    /// `self ∘ local`: world(q) = `self.world(local.world(q))`. With
    /// `local` a joint's relative pose this places a child on its parent.
    #[inline]
    pub fn compose(&self, local: &Pose3) -> Pose3 {
        Pose3 {
            rot: self.rot.mul(&local.rot),
            pos: self.world(local.pos),
        }
    }

    /// The inverse pose: `inverse().world(world(q)) = q`.
    #[inline]
    pub fn inverse(&self) -> Pose3 {
        Pose3 {
            rot: self.rot.transpose(),
            pos: scale(self.rot.apply_inverse(self.pos), -1.0),
        }
    }
}

/// The relative pose of a joint with a rotation and a slide along one axis
/// (revolute, prismatic or cylindrical): the rotation by `(cos, sin)` about
/// the line through `at` along the unit vector `axis`, followed by the
/// translation `slide·axis`. Used for angle and slide inputs as
/// `child = parent.compose(&joint_pose(..))`.
///
/// `(1, 0, 0)` gives exactly [`Pose3::IDENTITY`]. The translation part is
/// written as `vers·(at⊥) − sin·(axis × at) + slide·axis` (with `at⊥` the
/// part of `at` perpendicular to the axis) rather than `at − R·at`, which
/// would lose digits for small angles far from the origin.
///
/// The line (`axis`, `at`) is numbers of the frame's kind, or plain numbers
/// (a fixed hinge's): then only the products by the turn carry rates.
#[inline(always)]
pub fn joint_pose<T: Real, F: Real + Factor<T>>(
    axis: [F; 3],
    at: [F; 3],
    cos: T,
    sin: T,
    slide: T,
) -> Pose3<T> {
    let rot = Rot3::about_axis(axis, cos, sin);
    let vers = versine(cos, sin);
    let pos = add(
        sub(scale_by(reject(at, axis), vers), scale_by(cross(axis, at), sin)),
        scale_by(axis, slide),
    );
    Pose3 { rot, pos }
}
