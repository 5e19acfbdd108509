//! A numeric cluster of a mixed plan (Brunkhart §4): the bodies the closed
//! form could not place, each with the fewest unknowns its locus allows,
//! and the equations among them and the bodies already placed, solved by
//! Newton–Raphson. Both back ends call [`solve`]: the interpreter with the
//! cluster read from the plan IR, generated code with it written out as
//! constants.
//!
//! A solved cluster's rates follow from the implicit function theorem: its
//! residuals `F(u, q) = 0` hold along the motion, so `J·q̇ = −∂F/∂u·u̇` and
//! `J·q̈ = −(the rest of F's second derivative)`, both solved with the
//! pseudo-inverse of the cluster's Jacobian `J` at the frame's solution
//! ([`Implicit`]; [`solve_rates`] here, written out by generated code).

use nalgebra::{DMatrix, DVector};

use crate::frame::{Break, Ctx, StepId};
pub use crate::numeric::cluster::{finish, options};
use crate::numeric::{Equations, Implicit, Newton};
use crate::planar::{cst, Point, Pose, Rot};
use crate::scalar::{Jet2, Real};

/// How a cluster body is parametrised (Kramer's DOF states, and the joint
/// coordinates of a body hinged on another cluster body).
///
/// Angles are absolute (the body's rotation from the ground), scaled by the
/// mechanism's size so every unknown is a length.
///
/// Of `f64`s for a frame; of [`Jet2`]s (where a body is pinned and the
/// direction it slides along, with their rates) for its rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Param<T = f64> {
    /// Nothing known: translation and angle (3 unknowns).
    Free {
        /// The body.
        body: usize,
    },
    /// Pinned at a placed point: its angle only (1 unknown).
    Angle {
        /// The body.
        body: usize,
        /// The pinned marker, local.
        pin: Point,
        /// Where it is pinned, world.
        at: [T; 2],
    },
    /// Pinned by a revolute joint to a marker of an earlier cluster body:
    /// its angle only (1 unknown), the joint holding by construction.
    Hinge {
        /// The body.
        body: usize,
        /// The pinned marker, local.
        pin: Point,
        /// The parent body (an earlier param's body).
        parent: usize,
        /// The parent's marker it is pinned to, local to the parent.
        at: Point,
    },
    /// Rotation known and one marker on a known line: the displacement
    /// along the line's unit world direction from where it stands (1
    /// unknown).
    Slide {
        /// The body.
        body: usize,
        /// Unit world direction of the line.
        dir: [T; 2],
    },
    /// Rotation known: translation only (2 unknowns).
    Translate {
        /// The body.
        body: usize,
    },
}

impl<T> Param<T> {
    /// Number of unknowns.
    pub const fn count(&self) -> usize {
        match self {
            Param::Free { .. } => 3,
            Param::Translate { .. } => 2,
            Param::Angle { .. } | Param::Hinge { .. } | Param::Slide { .. } => 1,
        }
    }

    /// The body.
    pub const fn body(&self) -> usize {
        match self {
            Param::Free { body }
            | Param::Angle { body, .. }
            | Param::Hinge { body, .. }
            | Param::Slide { body, .. }
            | Param::Translate { body } => *body,
        }
    }
}

impl Param<Jet2> {
    /// The values alone.
    pub fn value(&self) -> Param {
        let v = |p: [Jet2; 2]| [p[0].v, p[1].v];
        match *self {
            Param::Free { body } => Param::Free { body },
            Param::Angle { body, pin, at } => Param::Angle { body, pin, at: v(at) },
            Param::Hinge {
                body,
                pin,
                parent,
                at,
            } => Param::Hinge {
                body,
                pin,
                parent,
                at,
            },
            Param::Slide { body, dir } => Param::Slide { body, dir: v(dir) },
            Param::Translate { body } => Param::Translate { body },
        }
    }
}

// The geometric primitives of a cluster, shared by the runtime `System`
// below and the straight-line code the compiler writes for each cluster:
// one implementation of each residual, placement and partial derivative.
// The placements and residuals are generic over `Real`: on `f64`s for a
// frame, on jets for its rates (the values then are the frame's exactly).

/// The rotation at an angle unknown `size·angle`.
#[inline]
pub fn angle_rot<T: Real>(scaled_angle: T, size: f64) -> Rot<T> {
    let (s, c) = (scaled_angle / T::cst(size)).sin_cos();
    Rot { c, s }
}

/// The pose of a free body at unknowns `(x, y, size·angle)`.
#[inline]
pub fn free_pose<T: Real>(x: T, y: T, scaled_angle: T, size: f64) -> Pose<T> {
    Pose {
        at: [x, y],
        rot: angle_rot(scaled_angle, size),
    }
}

/// The pose of a body turned to `size·angle` with its local `pin` at the
/// world point `at` (a pinned or hinged body).
#[inline]
pub fn pinned_pose<T: Real>(scaled_angle: T, size: f64, pin: [T; 2], at: [T; 2]) -> Pose<T> {
    let rot = angle_rot(scaled_angle, size);
    let w = rot.apply(pin);
    Pose {
        at: [at[0] - w[0], at[1] - w[1]],
        rot,
    }
}

/// The pose of a body displaced by `u` along the unit world `dir` from
/// `base`.
#[inline]
pub fn slide_pose<T: Real>(base: Pose<T>, dir: [T; 2], u: T) -> Pose<T> {
    Pose {
        at: [base.at[0] + u * dir[0], base.at[1] + u * dir[1]],
        rot: base.rot,
    }
}

/// The pose of a body at translation `(x, y)` with `base`'s rotation.
#[inline]
pub fn translate_pose<T: Real>(base: Pose<T>, x: T, y: T) -> Pose<T> {
    Pose {
        at: [x, y],
        rot: base.rot,
    }
}

/// A body's angle unknown (`size·angle`) read from its pose: the warm
/// start.
#[inline]
pub fn scaled_angle(pose: Pose, size: f64) -> f64 {
    pose.rot.s.atan2(pose.rot.c) * size
}

/// ∂/∂(angle unknown) of the world point `pivot + v` of a body (`v` local,
/// from the point the body turns about): `v` turned a quarter, over `size`.
#[inline]
pub fn turn(pose: Pose, v: Point, size: f64) -> Point {
    let r = pose.rot.apply(v);
    [-r[1] / size, r[0] / size]
}

/// The z component of `a × b`.
#[inline]
pub fn cross<T: Real>(a: [T; 2], b: [T; 2]) -> T {
    a[0] * b[1] - a[1] * b[0]
}

/// `a · b`.
#[inline]
pub fn dot(a: Point, b: Point) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// The in-line residual of world point `pb` on the line through `pa` along
/// the unit world `d`: `d × (pb − pa)`; also `pb − pa`, for the derivative
/// of the line's turn ([`line_turn`]).
#[inline]
pub fn in_line<T: Real>(d: [T; 2], pa: [T; 2], pb: [T; 2]) -> (T, [T; 2]) {
    let v = [pb[0] - pa[0], pb[1] - pa[1]];
    (cross(d, v), v)
}

/// The on-circle residual `|pb − pa| − r` and the unit vector from `pa`
/// to `pb` (its gradient with respect to `pb`; zero where the points
/// coincide, a circle of radius 0 being no slot).
#[inline]
pub fn on_circle<T: Real>(pa: [T; 2], pb: [T; 2], r: f64) -> (T, [f64; 2]) {
    let v = [pb[0] - pa[0], pb[1] - pa[1]];
    let len = (v[0] * v[0] + v[1] * v[1]).sqrt();
    let l = len.value();
    let u = if l > 0.0 {
        [v[0].value() / l, v[1].value() / l]
    } else {
        [0.0, 0.0]
    };
    (len - T::cst(r), u)
}

/// ∂(in-line residual)/∂(angle unknown of the line's body) from the line
/// turning (its point moving is in the point partials).
#[inline]
pub fn line_turn(d: Point, v: Point, size: f64) -> f64 {
    cross([-d[1], d[0]], v) / size
}

/// The parallel residual `size·sin(rot_b − rot_a − rel)` and its
/// derivative with respect to `b`'s angle unknown (minus that for `a`'s).
#[inline]
pub fn parallel<T: Real>(a: Rot<T>, rel: Rot<T>, b: Rot<T>, size: f64) -> (T, T) {
    let delta = a.then(rel).inverse().then(b);
    (T::cst(size) * delta.s, delta.c)
}

/// One primitive equation of a cluster (the residual forms of pure Newton).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Row {
    /// `a.world(la + u·dir) = b.world(lb)` (2 rows), `u` a slide input.
    Coincident {
        /// First body.
        a: usize,
        /// Its marker, local.
        la: Point,
        /// A slide input and its unit direction in `a`'s frame.
        slide: Option<(usize, Point)>,
        /// Second body.
        b: usize,
        /// Its marker, local.
        lb: Point,
    },
    /// `b.world(lb)` on the line through `a.world(la)` along `a`'s `dir`
    /// (1 row).
    InLine {
        /// The body carrying the line.
        a: usize,
        /// The line's marker, local.
        la: Point,
        /// The line's unit direction, local to `a`.
        dir: Point,
        /// The body of the point.
        b: usize,
        /// The point's marker, local.
        lb: Point,
    },
    /// `|b.world(lb) − a.world(la)| = r`: a pin in a circular slot about
    /// `la` (1 row).
    OnCircle {
        /// The body carrying the circle.
        a: usize,
        /// The circle's centre, local.
        la: Point,
        /// The circle's radius.
        r: f64,
        /// The body of the point.
        b: usize,
        /// The point's marker, local.
        lb: Point,
    },
    /// `rot(b) = rot(a)·rel` with `rel` an angle input or the identity
    /// (1 row).
    Parallel {
        /// First body.
        a: usize,
        /// Second body.
        b: usize,
        /// The angle input, if any.
        input: Option<usize>,
    },
}

impl Row {
    /// Number of scalar equations.
    pub const fn count(&self) -> usize {
        match self {
            Row::Coincident { .. } => 2,
            Row::InLine { .. } | Row::OnCircle { .. } | Row::Parallel { .. } => 1,
        }
    }
}

/// Unknown and equation counts of a cluster.
pub fn size_of<T>(params: &[Param<T>], rows: &[Row]) -> (usize, usize) {
    (
        params.iter().map(Param::count).sum(),
        rows.iter().map(Row::count).sum(),
    )
}

/// A cluster as a system of equations over its unknowns: the residuals and
/// analytic Jacobian of primitive equations evaluated from the plan's data
/// at run time (the interpreter, pure Newton and dragging). Generated code
/// writes the same computation out as straight-line code over the same
/// primitives.
pub struct System<'a> {
    poses: &'a mut [Pose],
    /// Pose of every cluster body when the cluster starts (rotation of
    /// oriented and sliding bodies, base of a slide).
    base: Vec<Pose>,
    params: &'a [Param],
    /// Per body: index into `params`, if the body is a cluster body.
    which: Vec<Option<usize>>,
    /// Per param: its first unknown.
    offsets: Vec<usize>,
    rows: &'a [Row],
    inputs: &'a [f64],
    size: f64,
}

impl<'a> System<'a> {
    /// The cluster over `poses` (whose cluster bodies hold where they stand
    /// now), and the unknowns of that standing pose: the warm start. `size`
    /// scales angles to lengths (every unknown is then a length).
    ///
    /// A hinged body's parent must come before it in `params`.
    pub fn new(
        poses: &'a mut [Pose],
        params: &'a [Param],
        rows: &'a [Row],
        inputs: &'a [f64],
        size: f64,
    ) -> (System<'a>, DVector<f64>) {
        let (n, _) = size_of(params, rows);
        let mut which = vec![None; poses.len()];
        let mut offsets = Vec::with_capacity(params.len());
        let mut base = Vec::with_capacity(params.len());
        let mut x = DVector::zeros(n);
        let mut o = 0;
        for (k, p) in params.iter().enumerate() {
            let b = p.body();
            which[b] = Some(k);
            offsets.push(o);
            let pose = poses[b];
            base.push(pose);
            match *p {
                Param::Free { .. } => {
                    x[o] = pose.at[0];
                    x[o + 1] = pose.at[1];
                    x[o + 2] = scaled_angle(pose, size);
                }
                Param::Angle { .. } | Param::Hinge { .. } => x[o] = scaled_angle(pose, size),
                Param::Slide { .. } => x[o] = 0.0,
                Param::Translate { .. } => {
                    x[o] = pose.at[0];
                    x[o + 1] = pose.at[1];
                }
            }
            o += p.count();
        }
        let system = System {
            poses,
            base,
            params,
            which,
            offsets,
            rows,
            inputs,
            size,
        };
        (system, x)
    }

    /// The poses (cluster bodies at the last unknowns applied or evaluated).
    pub fn poses(&self) -> &[Pose] {
        self.poses
    }

    /// The first unknown of each cluster body, by body.
    pub fn offset_of(&self, body: usize) -> Option<usize> {
        self.which[body].map(|k| self.offsets[k])
    }

    /// Places the cluster bodies at the unknowns `x` (in param order, so a
    /// hinge's parent is placed first).
    pub fn apply(&mut self, x: &DVector<f64>) {
        place(self.poses, &self.base, self.params, self.size, x.as_slice());
    }

    /// Calls `f(unknown, ∂p/∂unknown)` for every unknown the world point of
    /// local `q` on body `b` depends on (none when the body is not in the
    /// cluster). A hinged body's point also moves with its parent's
    /// unknowns, recursively.
    fn partials(&self, b: usize, q: Point, f: &mut impl FnMut(usize, Point)) {
        let Some(k) = self.which[b] else { return };
        let pose = self.poses[b];
        let o = self.offsets[k];
        match self.params[k] {
            Param::Free { .. } => {
                f(o, [1.0, 0.0]);
                f(o + 1, [0.0, 1.0]);
                f(o + 2, turn(pose, q, self.size));
            }
            Param::Angle { pin, .. } => f(o, turn(pose, [q[0] - pin[0], q[1] - pin[1]], self.size)),
            Param::Hinge { pin, parent, at, .. } => {
                f(o, turn(pose, [q[0] - pin[0], q[1] - pin[1]], self.size));
                self.partials(parent, at, f);
            }
            Param::Slide { dir, .. } => f(o, dir),
            Param::Translate { .. } => {
                f(o, [1.0, 0.0]);
                f(o + 1, [0.0, 1.0]);
            }
        }
    }

    /// The unknown that turns body `b` (its angle), if any.
    fn angle_unknown(&self, b: usize) -> Option<usize> {
        let k = self.which[b]?;
        let o = self.offsets[k];
        match self.params[k] {
            Param::Free { .. } => Some(o + 2),
            Param::Angle { .. } | Param::Hinge { .. } => Some(o),
            Param::Slide { .. } | Param::Translate { .. } => None,
        }
    }
}

impl Equations for System<'_> {
    fn unknowns(&self) -> usize {
        self.params.iter().map(Param::count).sum()
    }

    fn equations(&self) -> usize {
        self.rows.iter().map(Row::count).sum()
    }

    fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, mut jacobian: Option<&mut DMatrix<f64>>) {
        self.apply(x);
        if let Some(j) = jacobian.as_deref_mut() {
            j.fill(0.0);
        }
        let mut row = 0;
        for eq in self.rows {
            match *eq {
                Row::Coincident { a, la, slide, b, lb } => {
                    let la = match slide {
                        Some((input, d)) => {
                            let u = self.inputs[input];
                            [la[0] + u * d[0], la[1] + u * d[1]]
                        }
                        None => la,
                    };
                    let pa = self.poses[a].world(la);
                    let pb = self.poses[b].world(lb);
                    r[row] = pa[0] - pb[0];
                    r[row + 1] = pa[1] - pb[1];
                    if let Some(j) = jacobian.as_deref_mut() {
                        for (body, q, sign) in [(a, la, 1.0), (b, lb, -1.0)] {
                            self.partials(body, q, &mut |col, d| {
                                j[(row, col)] += sign * d[0];
                                j[(row + 1, col)] += sign * d[1];
                            });
                        }
                    }
                    row += 2;
                }
                Row::InLine { a, la, dir, b, lb } => {
                    let d = self.poses[a].world_dir(dir);
                    let (residual, v) = in_line(d, self.poses[a].world(la), self.poses[b].world(lb));
                    r[row] = residual;
                    if let Some(j) = jacobian.as_deref_mut() {
                        self.partials(b, lb, &mut |col, p| j[(row, col)] += cross(d, p));
                        self.partials(a, la, &mut |col, p| j[(row, col)] -= cross(d, p));
                        if let Some(col) = self.angle_unknown(a) {
                            j[(row, col)] += line_turn(d, v, self.size);
                        }
                    }
                    row += 1;
                }
                Row::OnCircle {
                    a,
                    la,
                    r: radius,
                    b,
                    lb,
                } => {
                    let (residual, u) = on_circle(self.poses[a].world(la), self.poses[b].world(lb), radius);
                    r[row] = residual;
                    if let Some(j) = jacobian.as_deref_mut() {
                        self.partials(b, lb, &mut |col, p| j[(row, col)] += dot(u, p));
                        self.partials(a, la, &mut |col, p| j[(row, col)] -= dot(u, p));
                    }
                    row += 1;
                }
                Row::Parallel { a, b, input } => {
                    let rel = match input {
                        Some(i) => Rot::from_degrees(self.inputs[i]),
                        None => Rot::IDENTITY,
                    };
                    let (residual, slope) = parallel(self.poses[a].rot, rel, self.poses[b].rot, self.size);
                    r[row] = residual;
                    if let Some(j) = jacobian.as_deref_mut() {
                        if let Some(col) = self.angle_unknown(b) {
                            j[(row, col)] += slope;
                        }
                        if let Some(col) = self.angle_unknown(a) {
                            j[(row, col)] -= slope;
                        }
                    }
                    row += 1;
                }
            }
        }
    }
}

/// Solves a cluster in place: the cluster bodies of `poses` are the warm
/// start (the previous frame's poses, with this frame's rotation for
/// oriented and sliding bodies) and receive the solution. Reports through
/// `ctx` (its Newton report, and a break or — under the stretch policy — a
/// relaxation when it does not converge). `size` scales angles to lengths
/// and the tolerance.
#[allow(clippy::too_many_arguments)]
pub fn solve(
    ctx: &mut Ctx,
    step: StepId,
    poses: &mut [Pose],
    params: &[Param],
    rows: &[Row],
    inputs: &[f64],
    size: f64,
    newton: &mut Newton,
) -> Result<(), Break> {
    let (mut system, mut x) = System::new(poses, params, rows, inputs, size);
    let report = newton.solve(&mut system, &mut x, &options(size));
    system.apply(&x);
    finish(ctx, step, report)
}

/// Places the cluster bodies of `poses` at the unknowns `x`, in param
/// order (a hinge's parent first); `base` holds each param's body as it
/// stood when the cluster started (the rotation of a sliding or translated
/// body, the start of a slide).
pub fn place<T: Real>(poses: &mut [Pose<T>], base: &[Pose<T>], params: &[Param<T>], size: f64, x: &[T]) {
    let mut o = 0;
    for (k, p) in params.iter().enumerate() {
        poses[p.body()] = match *p {
            Param::Free { .. } => free_pose(x[o], x[o + 1], x[o + 2], size),
            Param::Angle { pin, at, .. } => pinned_pose(x[o], size, cst(pin), at),
            Param::Hinge { pin, parent, at, .. } => {
                pinned_pose(x[o], size, cst(pin), poses[parent].world(at))
            }
            Param::Slide { dir, .. } => slide_pose(base[k], dir, x[o]),
            Param::Translate { .. } => translate_pose(base[k], x[o], x[o + 1]),
        };
        o += p.count();
    }
}

/// The residuals of `rows` over `poses` (the cluster bodies placed), on
/// jets: the rows of [`System`]'s residual, with the inputs' rates.
pub fn jet_residuals(poses: &[Pose<Jet2>], rows: &[Row], inputs: &[Jet2], size: f64, r: &mut [Jet2]) {
    let mut row = 0;
    for eq in rows {
        match *eq {
            Row::Coincident { a, la, slide, b, lb } => {
                let la = match slide {
                    Some((input, d)) => {
                        let u = inputs[input];
                        [
                            Jet2::cst(la[0]) + u * Jet2::cst(d[0]),
                            Jet2::cst(la[1]) + u * Jet2::cst(d[1]),
                        ]
                    }
                    None => cst(la),
                };
                let pa = poses[a].world_carried(la);
                let pb = poses[b].world(lb);
                r[row] = pa[0] - pb[0];
                r[row + 1] = pa[1] - pb[1];
                row += 2;
            }
            Row::InLine { a, la, dir, b, lb } => {
                let d = poses[a].world_dir(dir);
                r[row] = in_line(d, poses[a].world(la), poses[b].world(lb)).0;
                row += 1;
            }
            Row::OnCircle {
                a,
                la,
                r: radius,
                b,
                lb,
            } => {
                r[row] = on_circle(poses[a].world(la), poses[b].world(lb), radius).0;
                row += 1;
            }
            Row::Parallel { a, b, input } => {
                let rel = match input {
                    Some(i) => Rot::from_degrees_jet(inputs[i]),
                    None => Rot::cst(Rot::IDENTITY),
                };
                r[row] = parallel(poses[a].rot, rel, poses[b].rot, size).0;
                row += 1;
            }
        }
    }
}

/// [`solve`] with the rates: the cluster solved on the values exactly as
/// [`solve`] solves it (the same Newton on the same numbers, so the
/// positions are `solve`'s), then its unknowns' rates by the implicit
/// function theorem ([`Implicit`]) from the rates of what it hangs on
/// (`poses` before the step, `params`, `inputs`), and the cluster bodies
/// placed on jets. A singular Jacobian at the solution gives infinite rates
/// (reported singular by [`crate::rates::checked`]), not huge numbers.
#[allow(clippy::too_many_arguments)]
pub fn solve_rates(
    ctx: &mut Ctx,
    step: StepId,
    poses: &mut [Pose<Jet2>],
    params: &[Param<Jet2>],
    rows: &[Row],
    inputs: &[Jet2],
    size: f64,
    newton: &mut Newton,
) -> Result<(), Break> {
    let (n, m) = size_of(params, rows);
    let values: Vec<Param> = params.iter().map(Param::value).collect();
    let input_values: Vec<f64> = inputs.iter().map(|u| u.v).collect();
    let mut at: Vec<Pose> = poses.iter().map(Pose::value).collect();
    let (x, jacobian) = {
        let (mut system, mut x) = System::new(&mut at, &values, rows, &input_values, size);
        let report = newton.solve(&mut system, &mut x, &options(size));
        finish(ctx, step, report)?;
        let (mut r, mut j) = (DVector::zeros(m), DMatrix::zeros(m, n));
        system.eval(&x, &mut r, Some(&mut j));
        (x, j)
    };
    let base: Vec<Pose<Jet2>> = params.iter().map(|p| poses[p.body()]).collect();
    let implicit = Implicit::new(&jacobian);
    let mut q: Vec<Jet2> = x.iter().map(|&v| Jet2::cst(v)).collect();
    let mut f = vec![Jet2::cst(0.0); m];
    // F with the unknowns held: its rate is ∂F/∂(upstream)·rates.
    place(poses, &base, params, size, &q);
    jet_residuals(poses, rows, inputs, size, &mut f);
    let q_dot = implicit.solve(&DVector::from_iterator(m, f.iter().map(|r| r.d)));
    // F with the unknowns moving at q̇: its second derivative is all but J·q̈.
    for (q, d) in q.iter_mut().zip(q_dot.iter()) {
        q.d = *d;
    }
    place(poses, &base, params, size, &q);
    jet_residuals(poses, rows, inputs, size, &mut f);
    let q_ddot = implicit.solve(&DVector::from_iterator(m, f.iter().map(|r| r.dd)));
    for (q, dd) in q.iter_mut().zip(q_ddot.iter()) {
        q.dd = *dd;
    }
    place(poses, &base, params, size, &q);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::BranchPolicy;
    use crate::numeric::NewtonOutcome;

    /// A four-bar's coupler and rocker as a cluster: the coupler pinned at
    /// the crank pin (its angle), the rocker pinned at the ground (its
    /// angle), joined at C: 2 unknowns, 2 equations. The solution is the
    /// circle intersection, computed here by formula.
    #[test]
    fn a_dyad_as_a_cluster_meets_the_circle_intersection() {
        let b = [0.5, 1.2];
        let d = [4.0, 0.0];
        let (c0, r1, r2) = (
            [4.5, 2.5],
            (3.5f64.powi(2) + 1.5f64.powi(2)).sqrt(),
            (0.25f64 + 6.25).sqrt(),
        );
        // Drawn: coupler B = (1, 1), C = (4.5, 2.5); rocker D = (4, 0), C.
        let params = [
            Param::Angle {
                body: 1,
                pin: [1.0, 1.0],
                at: b,
            },
            Param::Angle {
                body: 2,
                pin: d,
                at: d,
            },
        ];
        let rows = [Row::Coincident {
            a: 1,
            la: c0,
            slide: None,
            b: 2,
            lb: c0,
        }];
        let mut poses = [Pose::IDENTITY; 3];
        let mut newton = Newton::new(2, 2);
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        solve(&mut ctx, 0, &mut poses, &params, &rows, &[], 5.0, &mut newton).unwrap();
        let c = poses[1].world(c0);
        // Closed form: intersection of circles about B (r1) and D (r2), the
        // root on the drawn side (left of B → D).
        let dx = [d[0] - b[0], d[1] - b[1]];
        let dd = (dx[0] * dx[0] + dx[1] * dx[1]).sqrt();
        let a = (r1 * r1 - r2 * r2 + dd * dd) / (2.0 * dd);
        let h = (r1 * r1 - a * a).sqrt();
        let u = [dx[0] / dd, dx[1] / dd];
        let expect = [b[0] + a * u[0] - h * u[1], b[1] + a * u[1] + h * u[0]];
        assert!(
            (c[0] - expect[0]).abs() < 1e-10 && (c[1] - expect[1]).abs() < 1e-10,
            "{c:?} vs {expect:?}"
        );
        let c2 = poses[2].world(c0);
        assert!((c2[0] - c[0]).abs() < 1e-10 && (c2[1] - c[1]).abs() < 1e-10);
        assert_eq!(ctx.numeric.unwrap().outcome, NewtonOutcome::Converged);
    }

    #[test]
    fn an_unreachable_cluster_breaks_or_stretches() {
        let params = [
            Param::Angle {
                body: 1,
                pin: [0.0, 0.0],
                at: [0.0, 0.0],
            },
            Param::Angle {
                body: 2,
                pin: [10.0, 0.0],
                at: [10.0, 0.0],
            },
        ];
        // Two unit links 10 apart cannot meet.
        let rows = [Row::Coincident {
            a: 1,
            la: [1.0, 0.0],
            slide: None,
            b: 2,
            lb: [9.0, 0.0],
        }];
        let mut poses = [Pose::IDENTITY; 3];
        let mut newton = Newton::new(2, 2);
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        let brk = solve(&mut ctx, 4, &mut poses, &params, &rows, &[], 10.0, &mut newton).unwrap_err();
        assert_eq!(brk.step, 4);
        assert!((brk.gap - 8.0).abs() < 1e-6, "{brk:?}");
        let mut ctx = Ctx::new(BranchPolicy::Keep, true);
        solve(&mut ctx, 4, &mut poses, &params, &rows, &[], 10.0, &mut newton).unwrap();
        assert_eq!(ctx.stretched.map(|s| s.0), Some(4));
    }

    /// The analytic Jacobian against central differences, for every kind
    /// of param (a hinge on a hinge included) and every kind of row.
    #[test]
    fn the_jacobian_is_the_derivative_of_the_residuals() {
        let params = [
            Param::Angle {
                body: 1,
                pin: [0.3, -0.2],
                at: [1.0, 2.0],
            },
            Param::Hinge {
                body: 2,
                pin: [0.5, 0.1],
                parent: 1,
                at: [2.0, 0.7],
            },
            Param::Hinge {
                body: 3,
                pin: [-0.4, 0.9],
                parent: 2,
                at: [1.1, -0.6],
            },
            Param::Free { body: 4 },
            Param::Slide {
                body: 5,
                dir: [0.6, 0.8],
            },
            Param::Translate { body: 6 },
        ];
        let rows = [
            Row::Coincident {
                a: 3,
                la: [0.2, 0.3],
                slide: Some((0, [0.0, 1.0])),
                b: 4,
                lb: [-1.0, 0.5],
            },
            Row::Coincident {
                a: 0,
                la: [3.0, 1.0],
                slide: None,
                b: 5,
                lb: [0.7, 0.2],
            },
            Row::InLine {
                a: 2,
                la: [0.1, 0.2],
                dir: [0.8, -0.6],
                b: 6,
                lb: [0.4, 0.4],
            },
            Row::InLine {
                a: 4,
                la: [0.0, 1.0],
                dir: [1.0, 0.0],
                b: 3,
                lb: [1.0, 1.0],
            },
            Row::Parallel {
                a: 3,
                b: 4,
                input: Some(1),
            },
            Row::Parallel {
                a: 6,
                b: 2,
                input: None,
            },
        ];
        let inputs = [0.7, 25.0];
        let mut poses = [Pose::IDENTITY; 7];
        poses[5].rot = Rot { c: 0.8, s: 0.6 };
        poses[6].rot = Rot { c: 0.6, s: -0.8 };
        let size = 3.0;
        let (mut system, _) = System::new(&mut poses, &params, &rows, &inputs, size);
        let (n, m) = (system.unknowns(), system.equations());
        assert_eq!((n, m), (9, 8));
        let x = DVector::from_fn(n, |i, _| 0.3 + 0.17 * i as f64 - 0.05 * (i * i) as f64);
        let mut r = DVector::zeros(m);
        let mut j = DMatrix::zeros(m, n);
        system.eval(&x, &mut r, Some(&mut j));
        let h = 1e-6;
        for col in 0..n {
            let (mut plus, mut minus) = (x.clone(), x.clone());
            plus[col] += h;
            minus[col] -= h;
            let (mut rp, mut rm) = (DVector::zeros(m), DVector::zeros(m));
            system.eval(&plus, &mut rp, None);
            system.eval(&minus, &mut rm, None);
            for row in 0..m {
                let numeric = (rp[row] - rm[row]) / (2.0 * h);
                assert!(
                    (numeric - j[(row, col)]).abs() < 1e-7,
                    "∂r{row}/∂x{col}: analytic {} numeric {numeric}",
                    j[(row, col)]
                );
            }
        }
    }

    /// A free body held to a moving one by two coincident points and a
    /// parallel row, and a translated body (turning with the moving one)
    /// held by one point and an in-line row: an over-constrained consistent
    /// cluster whose solution is the moving body's pose, so its rates must
    /// be the moving body's, velocity and acceleration.
    #[test]
    fn free_and_translated_bodies_move_with_what_holds_them() {
        let mover = Pose {
            at: [Jet2::new(0.3, 0.2, -0.1), Jet2::new(-0.2, 0.05, 0.4)],
            rot: Rot::from_degrees_jet(Jet2::new(30.0, 10.0, -3.0)),
        };
        let mut poses = [Pose::<Jet2>::cst(Pose::IDENTITY); 4];
        poses[1] = mover;
        // Warm starts near the solution; the translated body's rotation is
        // known (the mover's, with its rates).
        let v = mover.value();
        poses[2] = Pose::cst(Pose {
            at: [v.at[0] + 0.01, v.at[1] - 0.02],
            rot: Rot::from_degrees(31.0),
        });
        poses[3] = Pose {
            at: [Jet2::cst(v.at[0] - 0.03), Jet2::cst(v.at[1] + 0.01)],
            rot: mover.rot,
        };
        let params = [Param::Free { body: 2 }, Param::Translate { body: 3 }];
        let rows = [
            Row::Coincident {
                a: 1,
                la: [1.0, 0.0],
                slide: None,
                b: 2,
                lb: [1.0, 0.0],
            },
            Row::Coincident {
                a: 1,
                la: [0.0, 1.0],
                slide: None,
                b: 2,
                lb: [0.0, 1.0],
            },
            Row::Parallel {
                a: 1,
                b: 2,
                input: None,
            },
            Row::Coincident {
                a: 2,
                la: [0.5, 0.5],
                slide: None,
                b: 3,
                lb: [0.5, 0.5],
            },
            Row::InLine {
                a: 1,
                la: [0.0, 0.0],
                dir: [1.0, 0.0],
                b: 3,
                lb: [2.0, 0.0],
            },
        ];
        let mut newton = Newton::new(5, 8);
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        solve_rates(&mut ctx, 0, &mut poses, &params, &rows, &[], 2.0, &mut newton).unwrap();
        for b in [2, 3] {
            let (p, q) = (poses[b], mover);
            for (x, y) in [
                (p.at[0], q.at[0]),
                (p.at[1], q.at[1]),
                (p.rot.c, q.rot.c),
                (p.rot.s, q.rot.s),
            ] {
                assert!((x.v - y.v).abs() < 1e-10, "body {b}: {x:?} vs {y:?}");
                assert!((x.d - y.d).abs() < 1e-9, "body {b}: {x:?} vs {y:?}");
                assert!((x.dd - y.dd).abs() < 1e-9, "body {b}: {x:?} vs {y:?}");
            }
        }
    }
}
