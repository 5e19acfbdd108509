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
//!
//! Besides the vector helpers, [`Rot3`], [`Pose3`] and [`joint_pose`], the
//! module holds the actions on one body (rotating it about a point or an
//! axis, translating it: [`rotate_about_point`], [`rotate_about_axis_onto`],
//! ...) and the loci intersections (circles, spheres, lines, planes, cones,
//! and the rotation about an axis that meets a condition: [`circle_circle`],
//! [`rotation_to_condition`], ...).

pub mod cluster;
mod locus;
mod place;
pub mod rows;
mod turn;

#[cfg(test)]
mod tests;

pub use locus::{
    circle_about, circle_circle, circle_circle_candidates, circle_distance, cone_cone, line_circle,
    line_plane, line_sphere, plane_circle, rotation_to_condition, sphere_circle, CircleCandidates,
};
pub use place::{
    hinge, hinge_degrees, hinge_dir, hinge_onto, rotate_about_axis_angle, rotate_about_axis_dir,
    rotate_about_axis_onto, rotate_about_point, rotate_about_point_onto, slide_to, translate_along,
    translate_in_plane, translate_onto, translate_to_line, translate_to_plane,
};
pub use turn::{tilt, twist_correction};

/// A point or a vector in space.
pub type Vec3 = [f64; 3];

/// `a + b`.
#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a − b`.
#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a·k`.
#[inline]
pub fn scale(a: Vec3, k: f64) -> Vec3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// The dot product `a·b`.
#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product `a × b` (right-handed).
#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The squared length `|a|²`.
#[inline]
pub fn norm2(a: Vec3) -> f64 {
    dot(a, a)
}

/// The length `|a|`.
#[inline]
pub fn norm(a: Vec3) -> f64 {
    norm2(a).sqrt()
}

/// The distance `|a − b|`.
#[inline]
pub fn dist(a: Vec3, b: Vec3) -> f64 {
    norm(sub(a, b))
}

/// `a` scaled to unit length. The zero vector stays zero (a direction that
/// does not exist is reported as none rather than as NaN).
#[inline]
pub fn unit(a: Vec3) -> Vec3 {
    let n = norm(a);
    if n > 0.0 {
        scale(a, 1.0 / n)
    } else {
        a
    }
}

/// The component of `v` perpendicular to the unit vector `axis`:
/// `v − (v·axis)·axis`.
#[inline]
pub fn reject(v: Vec3, axis: Vec3) -> Vec3 {
    sub(v, scale(axis, dot(v, axis)))
}

/// A deterministic unit vector perpendicular to `v`: `v` crossed with the
/// world axis least aligned with it (the smallest `|v[i]|`, ties broken
/// x before y before z), normalised. The zero vector gives zero.
///
/// The choice is not continuous in `v` (no choice can be, on the sphere);
/// it is only used where any perpendicular will do, such as the axis of a
/// half turn between opposite directions.
#[inline]
pub fn perpendicular(v: Vec3) -> Vec3 {
    let a = [v[0].abs(), v[1].abs(), v[2].abs()];
    let e = if a[0] <= a[1] && a[0] <= a[2] {
        [1.0, 0.0, 0.0]
    } else if a[1] <= a[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    unit(cross(v, e))
}

/// `1 − cos` computed without cancellation for small angles: `sin²/(1 + cos)`
/// when `cos > 0` (equal when `cos² + sin² = 1`). At the zero angle it is
/// exactly 0, so a rotation by (1, 0) is exactly the identity.
#[inline]
fn versine(cos: f64, sin: f64) -> f64 {
    if cos > 0.0 {
        sin * sin / (1.0 + cos)
    } else {
        1.0 - cos
    }
}

/// A rotation as a row-major 3×3 matrix: the rotated `v` is `m·v`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Rot3 {
    /// The rows of the matrix.
    pub m: [[f64; 3]; 3],
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

    /// Rotates a vector: `m·v`.
    #[inline]
    pub fn apply(&self, v: Vec3) -> Vec3 {
        let m = &self.m;
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }

    /// Rotates a vector by the inverse rotation: `mᵀ·v`.
    #[inline]
    pub fn apply_inverse(&self, v: Vec3) -> Vec3 {
        let m = &self.m;
        [
            m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
            m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
            m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
        ]
    }

    /// The transpose, which is the inverse of a rotation.
    #[inline]
    pub fn transpose(&self) -> Rot3 {
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
    #[inline]
    pub fn mul(&self, other: &Rot3) -> Rot3 {
        let (a, b) = (&self.m, &other.m);
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j];
            }
        }
        Rot3 { m }
    }

    /// `self` followed by `other`: the product `other.m · self.m`.
    #[inline]
    pub fn then(&self, other: &Rot3) -> Rot3 {
        other.mul(self)
    }

    /// The right-handed rotation about the unit vector `axis` by the angle
    /// whose cosine and sine are `cos` and `sin` (a unit pair), by Rodrigues'
    /// formula `R = cos·I + sin·[axis]× + (1 − cos)·axis·axisᵀ`.
    ///
    /// `(1, 0)` gives exactly the identity.
    #[inline]
    pub fn about_axis(axis: Vec3, cos: f64, sin: f64) -> Rot3 {
        let [x, y, z] = axis;
        let v = versine(cos, sin);
        let (vx, vy, vz) = (v * x, v * y, v * z);
        let (sx, sy, sz) = (sin * x, sin * y, sin * z);
        Rot3 {
            m: [
                [cos + vx * x, vx * y - sz, vx * z + sy],
                [vx * y + sz, cos + vy * y, vy * z - sx],
                [vx * z - sy, vy * z + sx, cos + vz * z],
            ],
        }
    }

    /// The rotation about the unit vector `axis` by `degrees`
    /// (right-handed). The cosine and sine come from
    /// [`Rot::from_degrees`](crate::planar::Rot::from_degrees), so multiples
    /// of 90° are exact and planar and spatial plans agree on every angle.
    #[inline]
    pub fn about_axis_degrees(axis: Vec3, degrees: f64) -> Rot3 {
        let r = crate::planar::Rot::from_degrees(degrees);
        Rot3::about_axis(axis, r.c, r.s)
    }

    /// The rotation of the unit quaternion proportional to `(w, x, y, z)`.
    /// Every entry is divided by the squared norm instead of normalising the
    /// quaternion first, and the diagonal is written `(w² + x² − y² − z²)/n²`
    /// rather than `1 − 2(y² + z²)/n²`: of the usual forms this one came out
    /// most nearly orthonormal (worst entry of `R·Rᵀ − I` about 5 ulps over
    /// 200,000 random rotations, typically 1 or 2). The caller guarantees a
    /// non-zero quaternion.
    #[inline]
    fn from_quaternion(w: f64, x: f64, y: f64, z: f64) -> Rot3 {
        let (ww, xx, yy, zz) = (w * w, x * x, y * y, z * z);
        let k = 1.0 / (ww + xx + yy + zz);
        let t = 2.0 * k;
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
    /// - parallel directions give exactly the identity;
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
    pub fn minimal(from: Vec3, to: Vec3) -> Rot3 {
        let (fa, fb) = (norm2(from), norm2(to));
        if fa == 0.0 || fb == 0.0 {
            return Rot3::IDENTITY;
        }
        // Away from opposite directions, Rodrigues' form straight from the
        // unnormalised vectors: with k = (a × b)/(|a||b|) and c = cos θ,
        // R = c·I + [k]× + k kᵀ/(1 + c) — one square root, one division.
        let ab = (fa * fb).sqrt();
        let c = dot(from, to) / ab;
        if c > -0.5 {
            let k = scale(cross(from, to), 1.0 / ab);
            // Within rounding of parallel: exactly the identity, rather
            // than a turn by rounding noise.
            if norm2(k) <= 64e-32 {
                return Rot3::IDENTITY;
            }
            let f = 1.0 / (1.0 + c);
            let [x, y, z] = k;
            let (fx, fy, fz) = (f * x, f * y, f * z);
            return Rot3 {
                m: [
                    [c + fx * x, fx * y - z, fx * z + y],
                    [fx * y + z, c + fy * y, fy * z - x],
                    [fx * z - y, fy * z + x, c + fz * z],
                ],
            };
        }
        let a = unit(from);
        let b = unit(to);
        let h = add(a, b);
        // The quaternion is (|â||b̂| + â·b̂, â × b̂). Its scalar part equals
        // (|h|² − (|â| − |b̂|)²)/2: |h|²/2 is that to O(ε²) without the
        // cancellation of 1 + â·b̂ near opposite directions (where an error
        // of ε in |â| would be an error of ε/|h|² in the angle).
        let w = 0.5 * norm2(h);
        let v = cross(a, h);
        // |h| ≈ 2 cos(θ/2): below 1e-15 h is the rounding of normalising two
        // opposite directions and carries no axis.
        if w < 0.5e-30 {
            let p = perpendicular(a);
            return Rot3::from_quaternion(0.0, p[0], p[1], p[2]);
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
    pub fn renormalized(&self) -> Rot3 {
        let m = &self.m;
        // E = RᵀR (symmetric).
        let mut e = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in i..3 {
                let v = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
                e[i][j] = v;
                e[j][i] = v;
            }
        }
        let mut out = [[0.0; 3]; 3];
        for (r, row) in out.iter_mut().enumerate() {
            for (c, entry) in row.iter_mut().enumerate() {
                let mut v = 0.0;
                for k in 0..3 {
                    let f = if k == c { 3.0 - e[k][c] } else { -e[k][c] };
                    v += m[r][k] * f;
                }
                *entry = 0.5 * v;
            }
        }
        Rot3 { m: out }
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

/// Where a body is: world(q) = `rot`·q + `pos` for a point q in local (=
/// drawn) coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pose3 {
    /// Rotation relative to the drawn pose.
    pub rot: Rot3,
    /// Translation (the world position of the local origin).
    pub pos: Vec3,
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

    /// World position of a marker given in local (= drawn) coordinates.
    #[inline]
    pub fn world(&self, q: Vec3) -> Vec3 {
        add(self.rot.apply(q), self.pos)
    }

    /// World direction of a local direction (`rot·v`).
    #[inline]
    pub fn dir(&self, v: Vec3) -> Vec3 {
        self.rot.apply(v)
    }

    /// Applies the world rotation `r` about the world point `pivot`: every
    /// point moves to `pivot + r·(old world − pivot)`.
    #[inline]
    pub fn rotate_about(&mut self, pivot: Vec3, r: &Rot3) {
        self.rot = self.rot.then(r);
        self.pos = add(pivot, r.apply(sub(self.pos, pivot)));
    }

    /// Moves the body by `v`.
    #[inline]
    pub fn translate(&mut self, v: Vec3) {
        self.pos = add(self.pos, v);
    }

    /// `self ∘ local`: world(q) = `self.world(local.world(q))`. With
    /// `local` a joint's relative pose this places a child on its parent.
    #[inline]
    pub fn compose(&self, local: &Pose3) -> Pose3 {
        Pose3 {
            rot: self.rot.mul(&local.rot),
            pos: self.world(local.pos),
        }
    }

    /// Keeps the rotation rigid after many compositions: when RᵀR is off
    /// the identity by more than 1e-14 (thousands of frames of rounding),
    /// one [`Rot3::renormalized`] step; otherwise nothing, so the check is
    /// all a frame pays. Plans call it on every moving body once a frame.
    #[inline]
    pub fn renormalize(&mut self) {
        let m = &self.rot.m;
        let col = |i: usize, j: usize| m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
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
#[inline(always)]
pub fn joint_pose(axis: Vec3, at: Vec3, cos: f64, sin: f64, slide: f64) -> Pose3 {
    let rot = Rot3::about_axis(axis, cos, sin);
    let vers = versine(cos, sin);
    let pos = add(
        sub(scale(reject(at, axis), vers), scale(cross(axis, at), sin)),
        scale(axis, slide),
    );
    Pose3 { rot, pos }
}
