//! Numeric clusters of spatial plans: Newton–Raphson on the cluster
//! bodies' reduced unknowns (a rotation about an axis, about a pivot, or a
//! free twist), with the exact Jacobian from the runtime's row derivatives
//! and minimum-norm steps (SVD pseudo-inverse) for under-constrained and
//! degenerate systems (Brunkhart §4).

use dofplan_runtime::spatial::rows::{FrameRate, WorldFrame};
use dofplan_runtime::spatial::{cross, dot, norm, scale, sub, unit, Rot3, Vec3};
use dofplan_runtime::{Break, BreakKind, Ctx};
use nalgebra::{DMatrix, DVector};

use super::spatial::{dir, point, State3};
use crate::plan::spatial::{Cluster3, ClusterRow3, Param3};

/// Iterations before giving up.
const MAX_ITERATIONS: usize = 50;

/// The motion of one unknown: a twist (ω, v) about `origin`.
struct Column {
    body: usize,
    omega: Vec3,
    v: Vec3,
    origin: Vec3,
}

fn columns(s: &State3, c: &Cluster3, inputs: &[f64]) -> Vec<Column> {
    let mut out = Vec::new();
    for p in &c.params {
        match p {
            Param3::Free { body } => {
                let o = s.poses[*body].pos;
                for k in 0..6 {
                    let mut e = [0.0; 3];
                    e[k % 3] = 1.0;
                    let (omega, v) = if k < 3 { (e, [0.0; 3]) } else { ([0.0; 3], e) };
                    out.push(Column {
                        body: *body,
                        omega,
                        v,
                        origin: o,
                    });
                }
            }
            Param3::Pivot { body, pivot } => {
                let o = point(s, pivot, inputs);
                for k in 0..3 {
                    let mut e = [0.0; 3];
                    e[k] = 1.0;
                    out.push(Column {
                        body: *body,
                        omega: e,
                        v: [0.0; 3],
                        origin: o,
                    });
                }
            }
            Param3::Axis { body, pivot, axis } => out.push(Column {
                body: *body,
                omega: dir(s, axis, inputs),
                v: [0.0; 3],
                origin: point(s, pivot, inputs),
            }),
        }
    }
    out
}

fn residual(
    s: &State3,
    c: &Cluster3,
    inputs: &[f64],
    cols: &[Column],
    jac: Option<&mut DMatrix<f64>>,
) -> DVector<f64> {
    let m = c.equations();
    let mut r = DVector::zeros(m);
    let mut jac = jac;
    let mut row = 0;
    for cr in &c.rows {
        match cr {
            ClusterRow3::Equation(e) => {
                let f1 = WorldFrame::of(&s.poses[e.bodies[0]], e.at[0], e.z[0], e.x[0]);
                let f2 = WorldFrame::of(&s.poses[e.bodies[1]], e.at[1], e.z[1], e.x[1]);
                let n = e.kind.rows();
                let v = e.kind.eval(&f1, &f2, inputs);
                for k in 0..n {
                    r[row + k] = v[k];
                }
                if let Some(j) = jac.as_deref_mut() {
                    for (ci, col) in cols.iter().enumerate() {
                        let zero = FrameRate::default();
                        let d1 = if col.body == e.bodies[0] {
                            FrameRate::of(&f1, col.omega, col.v, col.origin)
                        } else {
                            zero
                        };
                        let d2 = if col.body == e.bodies[1] {
                            FrameRate::of(&f2, col.omega, col.v, col.origin)
                        } else {
                            zero
                        };
                        let d = e.kind.deriv(&f1, &f2, &d1, &d2, inputs);
                        for k in 0..n {
                            j[(row + k, ci)] = d[k];
                        }
                    }
                }
                row += n;
            }
            ClusterRow3::Distance { a, b, c: pc, d, .. } => {
                let (pa, pb) = (point(s, a, inputs), point(s, b, inputs));
                let len = norm(sub(point(s, d, inputs), point(s, pc, inputs)));
                let ab = sub(pa, pb);
                r[row] = norm(ab) - len;
                if let Some(j) = jac.as_deref_mut() {
                    let u = unit(ab);
                    for (ci, col) in cols.iter().enumerate() {
                        // Only the ends that belong to a cluster body move.
                        let rate = |p: &crate::plan::spatial::P3, at: Vec3| match p {
                            crate::plan::spatial::P3::Body { body, .. } if *body == col.body => {
                                dofplan_runtime::spatial::add(cross(col.omega, sub(at, col.origin)), col.v)
                            }
                            _ => [0.0; 3],
                        };
                        j[(row, ci)] = dot(u, sub(rate(a, pa), rate(b, pb)));
                    }
                }
                row += 1;
            }
        }
    }
    r
}

/// Solves a cluster in place, warm-started from the bodies' current poses.
pub fn solve(s: &mut State3, c: &Cluster3, inputs: &[f64], ctx: &mut Ctx, step: u32) -> Result<(), Break> {
    let cols = columns(s, c, inputs);
    let (m, n) = (c.equations(), cols.len());
    let mut jac = DMatrix::zeros(m, n);
    let scale_len = s.poses.iter().map(|p| norm(p.pos)).fold(1.0_f64, f64::max);
    let tol = 1e-12 * scale_len;
    let mut last = f64::INFINITY;
    for _ in 0..MAX_ITERATIONS {
        let cols = columns(s, c, inputs);
        let r = residual(s, c, inputs, &cols, Some(&mut jac));
        let gap = r.amax();
        if gap <= tol {
            return Ok(());
        }
        let svd = jac.clone().svd(true, true);
        let dx = match svd.solve(&r, 1e-10 * svd.singular_values.max().max(1e-300)) {
            Ok(dx) => dx,
            Err(_) => break,
        };
        // Apply −dx as exact rigid motions.
        for (ci, col) in cols.iter().enumerate() {
            let k = -dx[ci];
            let w = scale(col.omega, k);
            let angle = norm(w);
            let pose = &mut s.poses[col.body];
            if angle > 0.0 {
                let r = Rot3::about_axis(scale(w, 1.0 / angle), angle.cos(), angle.sin());
                pose.rotate_about(col.origin, &r);
            }
            pose.translate(scale(col.v, k));
        }
        // Diverging (or NaN): stop.
        let improving = gap < 2.0 * last;
        last = gap;
        if !improving && gap > 1e3 * tol {
            break;
        }
    }
    let cols = columns(s, c, inputs);
    let r = residual(s, c, inputs, &cols, None);
    let gap = r.amax();
    if gap <= 1e-9 * scale_len {
        return Ok(());
    }
    let _ = (m, n, last);
    ctx.fail(step, BreakKind::NotConverged, gap)
}
