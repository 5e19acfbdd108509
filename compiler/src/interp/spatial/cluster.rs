//! Numeric clusters of spatial plans in the interpreter: the cluster's rows
//! as [`Equations`] over the bodies' reduced unknowns, evaluated by the
//! runtime's [`cluster::moved`], [`cluster::columns`] and row functions and
//! solved by the runtime's [`Newton`] — what generated code does with
//! fixed sizes. Its rates ([`solve_rates`]) follow by the implicit
//! function theorem from the Jacobian at the solution.

use dofplan_runtime::numeric::cluster::{finish, options};
use dofplan_runtime::numeric::{Equations, Implicit, Newton};
use dofplan_runtime::real::{Jet2, Real};
use dofplan_runtime::spatial::cluster::{self, Twist, Unknowns};
use dofplan_runtime::spatial::rows::{FrameRate, WorldFrame};
use dofplan_runtime::spatial::{dot, norm, sub, unit, value, Pose3, Vec3};
use dofplan_runtime::{Break, Ctx};
use nalgebra::{DMatrix, DVector};

use super::state::{dir_at, point_at, InterpState};
use crate::plan::spatial::{Cluster, ClusterRow, Param, PointRef};

/// A row ready to evaluate: an equation's, or a distance from a constant
/// point.
enum Row<'c> {
    Frames(&'c crate::plan::spatial::CheckRow),
    Distance { a: &'c PointRef, b: Vec3, len: f64 },
    Pin { body: usize, local: Vec3 },
}

/// A cluster's rows as Newton's [`Equations`] over its bodies' unknowns,
/// warm-started from the poses it was made at. The loader's least-squares
/// assembly of a spatial drawing solves one too
/// (`conflict::spatial`), so its residuals are a plan's.
pub(crate) struct System<'a> {
    /// The state's poses: every body not in the cluster stays as it is.
    pub(crate) poses: Vec<Pose3>,
    base: Vec<Pose3>,
    /// Per cluster body: (body, unknowns, first column).
    members: Vec<(usize, Unknowns, usize)>,
    /// Per body: its member index.
    member_of: Vec<Option<usize>>,
    rows: Vec<Row<'a>>,
    inputs: &'a [f64],
    n: usize,
    m: usize,
}

impl System<'_> {
    /// Moves the cluster bodies of `poses` to the unknowns `x`.
    pub(crate) fn place(&mut self, x: &[f64]) {
        for &(b, u, k) in &self.members {
            self.poses[b] = cluster::moved(&self.base[b], &u, &x[k..]);
        }
    }

    fn twists(&self, x: &[f64], b: usize) -> Option<(usize, usize, [Twist; 6])> {
        let i = self.member_of[b]?;
        let (_, u, k) = self.members[i];
        Some((k, u.count(), cluster::columns(&self.base[b], &u, &x[k..])))
    }
}

impl Equations for System<'_> {
    fn unknowns(&self) -> usize {
        self.n
    }
    fn equations(&self) -> usize {
        self.m
    }
    fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, mut jacobian: Option<&mut DMatrix<f64>>) {
        let x = x.as_slice();
        self.place(x);
        if let Some(j) = jacobian.as_deref_mut() {
            j.fill(0.0);
        }
        let mut row = 0;
        for k in 0..self.rows.len() {
            match &self.rows[k] {
                Row::Frames(e) => {
                    let f1 = WorldFrame::of(&self.poses[e.bodies[0]], e.at[0], e.z[0], e.x[0]);
                    let f2 = WorldFrame::of(&self.poses[e.bodies[1]], e.at[1], e.z[1], e.x[1]);
                    let n = e.kind.rows();
                    let v = e.kind.eval(&f1, &f2, self.inputs);
                    for i in 0..n {
                        r[row + i] = v[i];
                    }
                    if let Some(j) = jacobian.as_deref_mut() {
                        for side in 0..2 {
                            let b = e.bodies[side];
                            if side == 1 && e.bodies[0] == b {
                                continue;
                            }
                            let Some((first, count, tw)) = self.twists(x, b) else {
                                continue;
                            };
                            for (c, t) in tw.iter().take(count).enumerate() {
                                let zero = FrameRate::default();
                                let (d1, d2) = if side == 0 {
                                    (t.rate(&f1), if e.bodies[1] == b { t.rate(&f2) } else { zero })
                                } else {
                                    (zero, t.rate(&f2))
                                };
                                let d = e.kind.deriv(&f1, &f2, &d1, &d2, self.inputs);
                                for i in 0..n {
                                    j[(row + i, first + c)] += d[i];
                                }
                            }
                        }
                    }
                    row += n;
                }
                Row::Distance { a, b, len } => {
                    let (b, len) = (*b, *len);
                    let body = match a {
                        PointRef::Body { body, .. } | PointRef::Slid { body, .. } => Some(*body),
                        _ => None,
                    };
                    let pa = point_at(&self.poses, &[], a, self.inputs);
                    let ab = sub(pa, b);
                    r[row] = norm(ab) - len;
                    if let (Some(j), Some(body)) = (jacobian.as_deref_mut(), body) {
                        if let Some((first, count, tw)) = self.twists(x, body) {
                            let u = unit(ab);
                            for (c, t) in tw.iter().take(count).enumerate() {
                                j[(row, first + c)] = dot(u, t.velocity(pa));
                            }
                        }
                    }
                    row += 1;
                }
                Row::Pin { body, local } => {
                    let (body, local) = (*body, *local);
                    let w = self.poses[body].world(local);
                    for i in 0..3 {
                        r[row + i] = w[i] - self.inputs[i];
                    }
                    if let Some(j) = jacobian.as_deref_mut() {
                        if let Some((first, count, tw)) = self.twists(x, body) {
                            for (c, t) in tw.iter().take(count).enumerate() {
                                let v = t.velocity(w);
                                for i in 0..3 {
                                    j[(row + i, first + c)] = v[i];
                                }
                            }
                        }
                    }
                    row += 3;
                }
            }
        }
    }
}

/// The cluster's unknowns of each body, at `poses` and `temps` (of
/// `f64`s for a frame, of jets for its rates).
fn unknowns<T: Real>(poses: &[Pose3<T>], temps: &[Vec3<T>], c: &Cluster, inputs: &[T]) -> Vec<Unknowns<T>> {
    c.params
        .iter()
        .map(|p| match p {
            Param::Free { .. } => Unknowns::Free,
            Param::Pivot { pivot, .. } => Unknowns::Pivot(point_at(poses, temps, pivot, inputs)),
            Param::Axis { pivot, axis, .. } => Unknowns::Axis(
                point_at(poses, temps, pivot, inputs),
                dir_at(poses, temps, axis, inputs),
            ),
        })
        .collect()
}

/// The cluster's system at the poses and pseudo-markers a frame reached
/// before it (the warm start).
pub(crate) fn system<'a>(poses: &[Pose3], temps: &[Vec3], c: &'a Cluster, inputs: &'a [f64]) -> System<'a> {
    let mut members = Vec::new();
    let mut member_of = vec![None; poses.len()];
    let mut n = 0;
    for (p, u) in c.params.iter().zip(unknowns(poses, temps, c, inputs)) {
        member_of[p.body()] = Some(members.len());
        members.push((p.body(), u, n));
        n += u.count();
    }
    let point = |p: &PointRef| point_at(poses, temps, p, inputs);
    let rows: Vec<Row> = c
        .rows
        .iter()
        .map(|r| match r {
            ClusterRow::Equation(e) => Row::Frames(e),
            ClusterRow::Distance { a, b, c: pc, d, .. } => Row::Distance {
                a,
                b: point(b),
                len: norm(sub(point(d), point(pc))),
            },
            ClusterRow::Pin { body, local, .. } => Row::Pin {
                body: *body,
                local: *local,
            },
        })
        .collect();
    System {
        poses: poses.to_vec(),
        base: poses.to_vec(),
        members,
        member_of,
        rows,
        inputs,
        n,
        m: c.equations(),
    }
}

/// Solves a cluster in place, warm-started from the bodies' current poses.
pub fn solve(
    s: &mut InterpState,
    c: &Cluster,
    inputs: &[f64],
    ctx: &mut Ctx,
    step: u32,
) -> Result<(), Break> {
    let mut system = system(&s.poses, &s.temps, c, inputs);
    let n = system.n;
    let mut x = DVector::zeros(n);
    if c.rows.iter().any(|r| matches!(r, ClusterRow::Pin { .. })) {
        let result = drag(&mut system, &mut x, c.size, ctx, step);
        system.place(x.as_slice());
        s.poses.copy_from_slice(&system.poses);
        return result;
    }
    let report = Newton::new(n, system.m).solve(&mut system, &mut x, &options(c.size));
    system.place(x.as_slice());
    s.poses.copy_from_slice(&system.poses);
    finish(ctx, step, report)
}

/// [`solve`] with the rates, on the jets of a frame's rates: the cluster
/// solved on the values exactly as [`solve`] solves it (so the positions
/// are `solve`'s, bit for bit), then its unknowns' rates by the implicit
/// function theorem — the rows on jets with the unknowns held give
/// `ẋ = −J⁺·F′`, with them moving at `ẋ` they give `ẍ = −J⁺·F″`
/// ([`Implicit`], singular where `J` has lost rank: infinite rates) — and
/// the cluster bodies placed on jets ([`cluster::moved_rates`]). `jets` are
/// the inputs with their rates, `inputs` their values. Not for a drag's
/// cluster (pinned rows).
pub fn solve_rates(
    poses: &mut [Pose3<Jet2>],
    temps: &[Vec3<Jet2>],
    c: &Cluster,
    jets: &[Jet2],
    inputs: &[f64],
    ctx: &mut Ctx,
    step: u32,
) -> Result<(), Break> {
    let values: Vec<Pose3> = poses.iter().map(Pose3::value).collect();
    let temp_values: Vec<Vec3> = temps.iter().map(|t| value(*t)).collect();
    let mut system = system(&values, &temp_values, c, inputs);
    let (n, m) = (system.n, system.m);
    let mut x = DVector::zeros(n);
    let report = Newton::new(n, m).solve(&mut system, &mut x, &options(c.size));
    finish(ctx, step, report)?;
    let (mut r, mut j) = (DVector::zeros(m), DMatrix::zeros(m, n));
    system.eval(&x, &mut r, Some(&mut j));
    let implicit = Implicit::new(&j);

    // The same rows on jets.
    let units = unknowns(poses, temps, c, jets);
    let base: Vec<Pose3<Jet2>> = poses.to_vec();
    let point = |poses: &[Pose3<Jet2>], p: &PointRef| point_at(poses, temps, p, jets);
    let ends: Vec<Option<(Vec3<Jet2>, Jet2)>> = c
        .rows
        .iter()
        .map(|r| match r {
            ClusterRow::Distance { b, c: pc, d, .. } => {
                Some((point(&base, b), norm(sub(point(&base, d), point(&base, pc)))))
            }
            _ => None,
        })
        .collect();
    let place = |poses: &mut [Pose3<Jet2>], q: &[Jet2]| {
        let mut k = 0;
        for (p, u) in c.params.iter().zip(&units) {
            poses[p.body()] = cluster::moved_rates(&base[p.body()], u, &q[k..]);
            k += u.count();
        }
    };
    let residuals = |poses: &mut [Pose3<Jet2>], q: &[Jet2]| -> Vec<Jet2> {
        place(poses, q);
        let mut f = Vec::with_capacity(m);
        for (r, end) in c.rows.iter().zip(&ends) {
            match r {
                ClusterRow::Equation(e) => {
                    let f1 = WorldFrame::of(&poses[e.bodies[0]], e.at[0], e.z[0], e.x[0]);
                    let f2 = WorldFrame::of(&poses[e.bodies[1]], e.at[1], e.z[1], e.x[1]);
                    let v = e.kind.eval(&f1, &f2, jets);
                    f.extend_from_slice(&v[..e.kind.rows()]);
                }
                ClusterRow::Distance { a, .. } => {
                    let (end, len) = end.expect("a distance row's end");
                    f.push(norm(sub(point(poses, a), end)) - len);
                }
                ClusterRow::Pin { .. } => unreachable!("no rates for a drag's cluster"),
            }
        }
        f
    };
    let mut q: Vec<Jet2> = x.iter().map(|&v| Jet2::cst(v)).collect();
    // F with the unknowns held: its rate is ∂F/∂(upstream)·rates.
    let f = residuals(poses, &q);
    let q_dot = implicit.solve(&DVector::from_iterator(m, f.iter().map(|r| r.d)));
    for (q, d) in q.iter_mut().zip(q_dot.iter()) {
        q.d = *d;
    }
    // F with the unknowns moving at ẋ: its second derivative is all but J·ẍ.
    let f = residuals(poses, &q);
    let q_ddot = implicit.solve(&DVector::from_iterator(m, f.iter().map(|r| r.dd)));
    for (q, dd) in q.iter_mut().zip(q_ddot.iter()) {
        q.dd = *dd;
    }
    place(poses, &q);
    Ok(())
}

/// A drag's cluster by task priority: the joints' rows first (they must
/// hold), the pinned marker's three rows in what motion the joints leave
/// (Gauss–Newton in the joints' null space), so an unreachable target is
/// approached as closely as the joints allow and never opens one.
fn drag(system: &mut System, x: &mut DVector<f64>, size: f64, ctx: &mut Ctx, step: u32) -> Result<(), Break> {
    let (n, m) = (system.n, system.m);
    let joints = m - 3;
    let mut r = DVector::zeros(m);
    let mut j = DMatrix::zeros(m, n);
    let tol = 1e-12 * size;
    // Singular values below `cut` are dropped. The cut is relative to the
    // whole Jacobian, not to the matrix inverted: where the joints leave
    // the pinned marker no motion at all (a marker on a fixed axis), the
    // projected pin rows are rounding noise, and a cut relative to them
    // inverted the noise into steps that opened the joints.
    let pinv = |a: DMatrix<f64>, cut: f64| {
        let svd = a.svd(true, true);
        svd.pseudo_inverse(cut).unwrap_or_else(|_| DMatrix::zeros(n, 0))
    };
    for _ in 0..100 {
        system.eval(x, &mut r, Some(&mut j));
        let cut = 1e-10 * j.norm().max(1e-300);
        let (r1, r2) = (r.rows(0, joints).into_owned(), r.rows(joints, 3).into_owned());
        let (j1, j2) = (j.rows(0, joints).into_owned(), j.rows(joints, 3).into_owned());
        let j1p = pinv(j1.clone(), cut);
        let dx1 = -(&j1p * &r1);
        let null = DMatrix::identity(n, n) - &j1p * &j1;
        let j2n = &j2 * &null;
        let dx2 = pinv(j2n, cut) * (-(&r2) - &j2 * &dx1);
        // Small steps toward the target: a frame is a small motion of it.
        // Only the motion the joints leave is shortened; the step back
        // onto the joints is taken whole.
        let mut toward = &null * dx2;
        let len = toward.norm();
        if len > 0.25 * size {
            toward *= 0.25 * size / len;
        }
        let dx = dx1 + toward;
        *x += &dx;
        if dx.norm() <= tol && r1.amax() <= tol {
            break;
        }
    }
    system.eval(x, &mut r, None);
    let (joint_gap, pin_gap) = (r.rows(0, joints).amax(), r.rows(joints, 3).norm());
    if joint_gap.is_nan() || joint_gap > 1e-9 * size {
        return ctx.fail(step, dofplan_runtime::BreakKind::NoSolution, joint_gap);
    }
    if pin_gap > 1e-9 * size {
        // The closest approach: under stretch the frame keeps it and
        // reports the distance; otherwise it breaks.
        return ctx.fail(step, dofplan_runtime::BreakKind::NoSolution, pin_gap);
    }
    Ok(())
}
