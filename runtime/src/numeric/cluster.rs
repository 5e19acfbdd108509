//! A numeric cluster of a mixed plan (Brunkhart §4): the bodies the closed
//! form could not place, each with the fewest unknowns its locus allows,
//! and the equations among them and the bodies already placed, solved by
//! Newton–Raphson. Both back ends call [`solve`]: the interpreter with the
//! cluster read from the plan IR, generated code with it written out as
//! constants.

use nalgebra::{DMatrix, DVector};

use super::{Equations, Newton, NewtonOptions, NewtonOutcome};
use crate::frame::{Break, BreakKind, Ctx, StepId};
use crate::planar::{Point, Pose, Rot};

/// How a cluster body is parametrised (Kramer's DOF states).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Param {
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
        at: Point,
    },
    /// Rotation known and one marker on a known line: the displacement
    /// along the line's unit world direction from where it stands (1
    /// unknown).
    Slide {
        /// The body.
        body: usize,
        /// Unit world direction of the line.
        dir: Point,
    },
    /// Rotation known: translation only (2 unknowns).
    Translate {
        /// The body.
        body: usize,
    },
}

impl Param {
    /// Number of unknowns.
    pub const fn count(&self) -> usize {
        match self {
            Param::Free { .. } => 3,
            Param::Translate { .. } => 2,
            Param::Angle { .. } | Param::Slide { .. } => 1,
        }
    }

    /// The body.
    pub const fn body(&self) -> usize {
        match self {
            Param::Free { body }
            | Param::Angle { body, .. }
            | Param::Slide { body, .. }
            | Param::Translate { body } => *body,
        }
    }
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
            Row::InLine { .. } | Row::Parallel { .. } => 1,
        }
    }
}

/// Unknown and equation counts of a cluster.
pub fn size_of(params: &[Param], rows: &[Row]) -> (usize, usize) {
    (
        params.iter().map(Param::count).sum(),
        rows.iter().map(Row::count).sum(),
    )
}

/// A cluster as a system of equations over its unknowns: the one
/// implementation of the residuals and analytic Jacobian of primitive
/// equations, used by mixed plans, pure Newton and dragging alike.
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

/// Partial derivatives of a world point, a direction and an angle of one
/// body with respect to its unknowns (at most three).
struct Partials {
    first: usize,
    count: usize,
    point: [Point; 3],
}

impl<'a> System<'a> {
    /// The cluster over `poses` (whose cluster bodies hold where they stand
    /// now), and the unknowns of that standing pose: the warm start. `size`
    /// scales angles to lengths (every unknown is then a length).
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
                    x[o + 2] = pose.rot.s.atan2(pose.rot.c) * size;
                }
                Param::Angle { .. } => x[o] = pose.rot.s.atan2(pose.rot.c) * size,
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

    /// Places the cluster bodies at the unknowns `x`.
    pub fn apply(&mut self, x: &DVector<f64>) {
        for (k, p) in self.params.iter().enumerate() {
            let o = self.offsets[k];
            let b = p.body();
            let base = self.base[k];
            self.poses[b] = match *p {
                Param::Free { .. } => {
                    let (s, c) = (x[o + 2] / self.size).sin_cos();
                    Pose {
                        at: [x[o], x[o + 1]],
                        rot: Rot { c, s },
                    }
                }
                Param::Angle { pin, at, .. } => {
                    let (s, c) = (x[o] / self.size).sin_cos();
                    let rot = Rot { c, s };
                    let w = rot.apply(pin);
                    Pose {
                        at: [at[0] - w[0], at[1] - w[1]],
                        rot,
                    }
                }
                Param::Slide { dir, .. } => Pose {
                    at: [base.at[0] + x[o] * dir[0], base.at[1] + x[o] * dir[1]],
                    rot: base.rot,
                },
                Param::Translate { .. } => Pose {
                    at: [x[o], x[o + 1]],
                    rot: base.rot,
                },
            };
        }
    }

    /// Partials of the world point of local `q` on body `b` (None when the
    /// body is not in the cluster).
    fn partials(&self, b: usize, q: Point) -> Option<Partials> {
        let k = self.which[b]?;
        let pose = self.poses[b];
        let o = self.offsets[k];
        let turn = |v: Point| {
            let r = pose.rot.apply(v);
            [-r[1] / self.size, r[0] / self.size]
        };
        Some(match self.params[k] {
            Param::Free { .. } => Partials {
                first: o,
                count: 3,
                point: [[1.0, 0.0], [0.0, 1.0], turn(q)],
            },
            Param::Angle { pin, .. } => Partials {
                first: o,
                count: 1,
                point: [turn([q[0] - pin[0], q[1] - pin[1]]), [0.0; 2], [0.0; 2]],
            },
            Param::Slide { dir, .. } => Partials {
                first: o,
                count: 1,
                point: [dir, [0.0; 2], [0.0; 2]],
            },
            Param::Translate { .. } => Partials {
                first: o,
                count: 2,
                point: [[1.0, 0.0], [0.0, 1.0], [0.0; 2]],
            },
        })
    }

    /// The unknown whose derivative turns body `b` (its angle), with d angle
    /// / d unknown.
    fn angle_unknown(&self, b: usize) -> Option<(usize, f64)> {
        let k = self.which[b]?;
        let o = self.offsets[k];
        match self.params[k] {
            Param::Free { .. } => Some((o + 2, 1.0 / self.size)),
            Param::Angle { .. } => Some((o, 1.0 / self.size)),
            _ => None,
        }
    }
}

fn cross(a: Point, b: Point) -> f64 {
    a[0] * b[1] - a[1] * b[0]
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
                            if let Some(p) = self.partials(body, q) {
                                for c in 0..p.count {
                                    j[(row, p.first + c)] += sign * p.point[c][0];
                                    j[(row + 1, p.first + c)] += sign * p.point[c][1];
                                }
                            }
                        }
                    }
                    row += 2;
                }
                Row::InLine { a, la, dir, b, lb } => {
                    let d = self.poses[a].world_dir(dir);
                    let pa = self.poses[a].world(la);
                    let pb = self.poses[b].world(lb);
                    let v = [pb[0] - pa[0], pb[1] - pa[1]];
                    r[row] = cross(d, v);
                    if let Some(j) = jacobian.as_deref_mut() {
                        if let Some(p) = self.partials(b, lb) {
                            for c in 0..p.count {
                                j[(row, p.first + c)] += cross(d, p.point[c]);
                            }
                        }
                        if let Some(p) = self.partials(a, la) {
                            for c in 0..p.count {
                                j[(row, p.first + c)] -= cross(d, p.point[c]);
                            }
                        }
                        // The line itself turns with `a`.
                        if let Some((col, k)) = self.angle_unknown(a) {
                            j[(row, col)] += k * cross([-d[1], d[0]], v);
                        }
                    }
                    row += 1;
                }
                Row::Parallel { a, b, input } => {
                    let rel = match input {
                        Some(i) => Rot::from_degrees(self.inputs[i]),
                        None => Rot::IDENTITY,
                    };
                    let delta = self.poses[a].rot.then(rel).inverse().then(self.poses[b].rot);
                    r[row] = self.size * delta.s;
                    if let Some(j) = jacobian.as_deref_mut() {
                        if let Some((col, k)) = self.angle_unknown(b) {
                            j[(row, col)] += self.size * delta.c * k;
                        }
                        if let Some((col, k)) = self.angle_unknown(a) {
                            j[(row, col)] -= self.size * delta.c * k;
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
    let options = NewtonOptions {
        max_iterations: 50,
        tolerance: 1e-12 * size,
        rank_cutoff: 1e-10,
        max_step: 0.25 * size,
    };
    let report = newton.solve(&mut system, &mut x, &options);
    system.apply(&x);
    ctx.numeric = Some(report);
    match report.outcome {
        NewtonOutcome::Converged => Ok(()),
        NewtonOutcome::NoSolution => ctx.fail(step, BreakKind::NoSolution, report.residual),
        NewtonOutcome::NotConverged => ctx.fail(step, BreakKind::NotConverged, report.residual),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::BranchPolicy;

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
}
