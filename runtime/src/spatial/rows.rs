//! Kramer's primitive constraints as residual rows, evaluated on world
//! frames: what a plan's check steps, its numeric clusters and the
//! compiler's drawn-pose and residual checks all compute, written once.
//!
//! A marker frame is its point and unit axes (z, x, y = z × x). Rows are
//! zero when the primitive holds; the first marker owns the line, plane or
//! reference axis.

use super::{dot, sub, Vec3};
use crate::scalar::Real;

/// coincident: p2 − p1 (3 rows).
#[inline]
pub fn coincident<T: Real>(p1: Vec3<T>, p2: Vec3<T>) -> [T; 3] {
    sub(p2, p1)
}

/// in-line: the offset of p2 from the line (p1, z1) along x1 and y1 (2 rows).
#[inline]
pub fn in_line<T: Real>(p1: Vec3<T>, x1: Vec3<T>, y1: Vec3<T>, p2: Vec3<T>) -> [T; 2] {
    let d = sub(p2, p1);
    [dot(d, x1), dot(d, y1)]
}

/// in-plane: the height of p2 over the plane (p1, z1) (1 row).
#[inline]
pub fn in_plane<T: Real>(p1: Vec3<T>, z1: Vec3<T>, p2: Vec3<T>) -> T {
    dot(sub(p2, p1), z1)
}

/// parallel-z: the components of z2 across z1 (2 rows). They vanish for z2 =
/// ±z1; which sign holds is kept by the plan (the drawn one).
#[inline]
pub fn parallel_z<T: Real>(x1: Vec3<T>, y1: Vec3<T>, z2: Vec3<T>) -> [T; 2] {
    [dot(z2, x1), dot(z2, y1)]
}

/// offset-z: cos∠(z1, z2) − cos α (1 row).
#[inline]
pub fn offset_z<T: Real>(z1: Vec3<T>, z2: Vec3<T>, cos: T) -> T {
    dot(z1, z2) - cos
}

/// The angle-about-z1 row of offset-x, helical and angle inputs:
/// sin(∠(x1 → x2 about z1) − α), with α given by its cosine and sine.
#[inline]
pub fn twist<T: Real>(x1: Vec3<T>, y1: Vec3<T>, x2: Vec3<T>, cos: T, sin: T) -> T {
    dot(x2, y1) * cos - dot(x2, x1) * sin
}

/// The angle of x2 about z1 from x1, in radians (−π, π].
#[inline]
pub fn angle_about(x1: Vec3, y1: Vec3, x2: Vec3) -> f64 {
    dot(x2, y1).atan2(dot(x2, x1))
}

/// The axial distance (p2 − p1)·z1 of slide inputs and helical joints.
#[inline]
pub fn axial<T: Real>(p1: Vec3<T>, z1: Vec3<T>, p2: Vec3<T>) -> T {
    dot(sub(p2, p1), z1)
}

/// A primitive's rows with every constant they need: what a plan's check
/// steps and numeric clusters carry, so both back ends evaluate a
/// primitive by the same [`RowKind::eval`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RowKind {
    /// p2 = p1 (3 rows).
    Coincident,
    /// p2 on the line (p1, z1) (2 rows).
    InLine,
    /// p2 on the plane (p1, z1) (1 row).
    InPlane,
    /// z2 ∥ z1 (2 rows).
    ParallelZ,
    /// cos∠(z1, z2) = `cos` (1 row).
    OffsetZ {
        /// cos α.
        cos: f64,
    },
    /// z2 ∥ z1 and x2 at `angle` (radians) from x1 about z1 (3 rows).
    OffsetX {
        /// α.
        angle: f64,
    },
    /// z2 ∥ z1 and x2 at `angle + 2π (axial − axial0)/pitch` about z1 (3 rows).
    Helical {
        /// The twist as drawn.
        angle: f64,
        /// Advance per turn.
        pitch: f64,
        /// The axial distance as drawn.
        axial0: f64,
    },
    /// x2 at `angle` + the input (degrees) about z1 (1 row).
    Angle {
        /// The twist as drawn.
        angle: f64,
        /// The input.
        input: usize,
    },
    /// The axial distance is `axial0` + the input (1 row).
    Slide {
        /// The axial distance as drawn.
        axial0: f64,
        /// The input.
        input: usize,
    },
}

/// A marker frame in world coordinates (of `f64`s, or of
/// [`Jet2`](crate::scalar::Jet2)s carrying its rates).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldFrame<T = f64> {
    /// Its point.
    pub at: Vec3<T>,
    /// Unit z.
    pub z: Vec3<T>,
    /// Unit x.
    pub x: Vec3<T>,
}

impl<T: Real> WorldFrame<T> {
    /// The frame with local point and axes `at`, `z`, `x` carried by `pose`.
    #[inline]
    pub fn of(pose: &super::Pose3<T>, at: Vec3, z: Vec3, x: Vec3) -> WorldFrame<T> {
        WorldFrame {
            at: pose.world(at),
            z: pose.dir(z),
            x: pose.dir(x),
        }
    }

    /// y = z × x.
    #[inline]
    pub fn y(&self) -> Vec3<T> {
        super::cross(self.z, self.x)
    }
}

impl RowKind {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        match self {
            RowKind::Coincident | RowKind::OffsetX { .. } | RowKind::Helical { .. } => 3,
            RowKind::InLine | RowKind::ParallelZ => 2,
            _ => 1,
        }
    }

    /// Whether the rows are lengths (else sines and cosines).
    pub fn linear(&self) -> bool {
        matches!(
            self,
            RowKind::Coincident | RowKind::InLine | RowKind::InPlane | RowKind::Slide { .. }
        )
    }

    /// The rows on two world frames (the first `rows()` entries are used),
    /// on `f64`s or, for a cluster's rates, on jets.
    #[inline]
    pub fn eval<T: Real>(&self, f1: &WorldFrame<T>, f2: &WorldFrame<T>, inputs: &[T]) -> [T; 3] {
        let y1 = f1.y();
        let zero = T::cst(0.0);
        match *self {
            RowKind::Coincident => coincident(f1.at, f2.at),
            RowKind::InLine => {
                let [a, b] = in_line(f1.at, f1.x, y1, f2.at);
                [a, b, zero]
            }
            RowKind::InPlane => [in_plane(f1.at, f1.z, f2.at), zero, zero],
            RowKind::ParallelZ => {
                let [a, b] = parallel_z(f1.x, y1, f2.z);
                [a, b, zero]
            }
            RowKind::OffsetZ { cos } => [offset_z(f1.z, f2.z, T::cst(cos)), zero, zero],
            RowKind::OffsetX { angle } => {
                let [a, b] = parallel_z(f1.x, y1, f2.z);
                let (s, c) = angle.sin_cos();
                [a, b, twist(f1.x, y1, f2.x, T::cst(c), T::cst(s))]
            }
            RowKind::Helical { angle, pitch, axial0 } => {
                let [a, b] = parallel_z(f1.x, y1, f2.z);
                // τ·(axial − axial0)/pitch, as `TAU * (..) / pitch`.
                let t = T::cst(angle)
                    + (axial(f1.at, f1.z, f2.at) - T::cst(axial0)).mul_f64(core::f64::consts::TAU)
                        / T::cst(pitch);
                let (s, c) = t.sin_cos();
                [a, b, twist(f1.x, y1, f2.x, c, s)]
            }
            RowKind::Angle { angle, input } => {
                // `to_radians` is the product by π/180.
                let (s, c) = (T::cst(angle) + inputs[input].mul_f64(core::f64::consts::PI / 180.0)).sin_cos();
                [twist(f1.x, y1, f2.x, c, s), zero, zero]
            }
            RowKind::Slide { axial0, input } => [
                axial(f1.at, f1.z, f2.at) - T::cst(axial0) - inputs[input],
                zero,
                zero,
            ],
        }
    }

    /// The largest absolute row.
    #[inline]
    pub fn gap(&self, f1: &WorldFrame, f2: &WorldFrame, inputs: &[f64]) -> f64 {
        let r = self.eval(f1, f2, inputs);
        r[..self.rows()].iter().fold(0.0_f64, |m, v| m.max(v.abs()))
    }
}

/// The rate of change of a world frame under a motion: its point's
/// velocity and its axes' angular rates applied (ω × z, ω × x).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameRate {
    /// d(point).
    pub at: Vec3,
    /// d(z).
    pub z: Vec3,
    /// d(x).
    pub x: Vec3,
}

impl FrameRate {
    /// The rate of `f` under the twist (ω, v) taken about `origin`:
    /// d(point) = ω × (point − origin) + v, d(axis) = ω × axis.
    #[inline]
    pub fn of(f: &WorldFrame, omega: Vec3, v: Vec3, origin: Vec3) -> FrameRate {
        use super::{add, cross};
        FrameRate {
            at: add(cross(omega, sub(f.at, origin)), v),
            z: cross(omega, f.z),
            x: cross(omega, f.x),
        }
    }
}

impl RowKind {
    /// The directional derivative of [`RowKind::eval`] when the frames move
    /// at the rates `d1`, `d2` (forward-mode, exact): a column of a
    /// Jacobian.
    pub fn deriv(
        &self,
        f1: &WorldFrame,
        f2: &WorldFrame,
        d1: &FrameRate,
        d2: &FrameRate,
        inputs: &[f64],
    ) -> [f64; 3] {
        use super::{add, cross};
        let y1 = f1.y();
        let dy1 = add(cross(d1.z, f1.x), cross(f1.z, d1.x));
        let dp = sub(d2.at, d1.at);
        let p = sub(f2.at, f1.at);
        let par = || [dot(d2.z, f1.x) + dot(f2.z, d1.x), dot(d2.z, y1) + dot(f2.z, dy1)];
        let twist_d = |c: f64, s: f64, dt: f64| {
            let (a, b) = (dot(f2.x, y1), dot(f2.x, f1.x));
            let da = dot(d2.x, y1) + dot(f2.x, dy1);
            let db = dot(d2.x, f1.x) + dot(f2.x, d1.x);
            da * c - db * s + (-a * s - b * c) * dt
        };
        let daxial = dot(dp, f1.z) + dot(p, d1.z);
        match *self {
            RowKind::Coincident => dp,
            RowKind::InLine => [dot(dp, f1.x) + dot(p, d1.x), dot(dp, y1) + dot(p, dy1), 0.0],
            RowKind::InPlane => [daxial, 0.0, 0.0],
            RowKind::ParallelZ => {
                let [a, b] = par();
                [a, b, 0.0]
            }
            RowKind::OffsetZ { .. } => [dot(d1.z, f2.z) + dot(f1.z, d2.z), 0.0, 0.0],
            RowKind::OffsetX { angle } => {
                let [a, b] = par();
                let (s, c) = angle.sin_cos();
                [a, b, twist_d(c, s, 0.0)]
            }
            RowKind::Helical { angle, pitch, axial0 } => {
                let [a, b] = par();
                let k = core::f64::consts::TAU / pitch;
                let t = angle + k * (axial(f1.at, f1.z, f2.at) - axial0);
                let (s, c) = t.sin_cos();
                [a, b, twist_d(c, s, k * daxial)]
            }
            RowKind::Angle { angle, input } => {
                let (s, c) = (angle + inputs[input].to_radians()).sin_cos();
                [twist_d(c, s, 0.0), 0.0, 0.0]
            }
            RowKind::Slide { .. } => [daxial, 0.0, 0.0],
        }
    }
}
