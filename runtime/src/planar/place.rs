//! Placing a body once its loci are met.

use super::{dot, sub, Pose, Rot};
use crate::frame::{lanes_differ, Break, BreakKind, Ctx, StepId};
use crate::scalar::{Factor, Real};

/// Sets a body's rotation to `from` followed by `rel` (a relative rotation
/// carried by a joint: the identity for a prismatic joint or an offset
/// constraint, the input angle for a driven revolute).
#[inline(always)]
pub fn orient<T: Real>(pose: &mut Pose<T>, from: Rot<T>, rel: Rot<T>) {
    pose.rot = from.then(rel);
}

/// Sets a body's rotation relative to the ground (whose rotation is the
/// identity, so composing with it would only cost multiplications).
#[inline(always)]
pub fn set_rotation<T: Real>(pose: &mut Pose<T>, rot: Rot<T>) {
    pose.rot = rot;
}

/// Translates a body whose rotation is known so that its marker `local`
/// lands on the world point `at`. The marker is a constant of the body
/// (`f64`) or a candidate's, with its derivatives with respect to the
/// design parameters (a [`Tangent`](crate::scalar::Tangent), as `T`).
#[inline(always)]
pub fn anchor<T: Real, L: Factor<T>>(pose: &mut Pose<T>, local: [L; 2], at: [T; 2]) {
    let r = pose.rot.apply_local(local);
    pose.at = [at[0] - r[0], at[1] - r[1]];
}

/// Places a body by two of its markers: `p` lands on `p_at` and `q` lies on
/// the ray from `p_at` through `q_at` (exactly on `q_at` when the distances
/// agree, which the step that computed `q_at` guarantees unless it was
/// stretched). The markers are constants or a candidate's, as in
/// [`anchor`].
#[inline(always)]
pub fn align<T: Real, L: Real + Factor<T>>(
    pose: &mut Pose<T>,
    p: [L; 2],
    p_at: [T; 2],
    q: [L; 2],
    q_at: [T; 2],
) {
    // The markers are constants of the body: their span and its length
    // are plain numbers, which jets and lanes multiply by for a third of a
    // product's cost.
    let dl = sub(q, p);
    let dw = sub(q_at, p_at);
    let l2 = dot(dl, dl);
    let w2 = dot(dw, dw);
    // The usual case: the world span has the local length (the step that
    // computed q_at put it on the circle of that radius), so normalising is
    // folded into the local span (a constant in compiled plans). The rest (a
    // stretched step, a span of zero length) is out of line: the hot path
    // then neither computes a square root speculatively nor depends on the
    // previous frame's pose.
    // (|w2 − l2| ≤ tol as two comparisons, which lanes make side by side;
    // for finite numbers a − b ≤ 0 exactly when a ≤ b.)
    let tol = T::cst(1e-12 * l2.value());
    let dev = w2 - l2.lift();
    if l2.value() > 0.0 && (dev - tol).all(|v| v <= 0.0) && (dev + tol).all(|v| v >= 0.0) {
        let k = [dl[0] / l2, dl[1] / l2];
        pose.rot = Rot {
            c: k[0].scale(dw[0]) + k[1].scale(dw[1]),
            s: k[0].scale(dw[1]) - k[1].scale(dw[0]),
        };
    } else {
        let (c, s) = (
            dl[0].scale(dw[0]) + dl[1].scale(dw[1]),
            dl[0].scale(dw[1]) - dl[1].scale(dw[0]),
        );
        align_rotation_slow(pose, l2.lift(), w2, c, s);
    }
    anchor(pose, p, p_at);
}

/// [`align`] for a body whose two targets come from different placed
/// bodies (it was pinned twice: one equation is redundant). The targets'
/// distance must equal the markers' — the consistency check after
/// contraction — or the step breaks (or, stretching, places the body
/// anyway and reports the gap).
#[inline(always)]
pub fn align_consistent<T: Real, L: Real + Factor<T>>(
    ctx: &mut Ctx,
    step: StepId,
    pose: &mut Pose<T>,
    p: [L; 2],
    p_at: [T; 2],
    q: [L; 2],
    q_at: [T; 2],
) -> Result<(), Break> {
    let dl = sub(q, p);
    let dw = sub(q_at, p_at);
    // The local span is the same in every lane (constants); the world
    // span is checked in each.
    let l = dot(dl, dl).value().sqrt();
    let tol = 1e-9 * l.max(1.0);
    let w = dot(dw, dw).sqrt();
    if w.any(|w| (w - l).abs() > tol) {
        lanes_differ::<T>(step)?;
        ctx.fail(step, BreakKind::Inconsistent, (w.value() - l).abs())?;
    }
    align(pose, p, p_at, q, q_at);
    Ok(())
}

/// The rotation of [`align`] when the world span's length differs from the
/// local one: normalise by both lengths, or keep the previous rotation when
/// either is zero (the rotation is undefined; keeping it is the continuous
/// choice).
#[cold]
#[inline(never)]
fn align_rotation_slow<T: Real>(pose: &mut Pose<T>, l2: T, w2: T, c: T, s: T) {
    let n = (l2 * w2).sqrt();
    pose.rot = Rot {
        c: n.select(|v| v > 0.0, c / n, pose.rot.c),
        s: n.select(|v| v > 0.0, s / n, pose.rot.s),
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn align_maps_both_markers() {
        let mut pose = Pose::IDENTITY;
        align(&mut pose, [1.0, 1.0], [2.0, 0.0], [3.0, 1.0], [2.0, 2.0]);
        let a = pose.world([1.0, 1.0]);
        let b = pose.world([3.0, 1.0]);
        assert!((a[0] - 2.0).abs() < 1e-12 && a[1].abs() < 1e-12);
        assert!((b[0] - 2.0).abs() < 1e-12 && (b[1] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn orient_then_anchor() {
        let mut pose = Pose::IDENTITY;
        orient(&mut pose, Rot::from_degrees(90.0), Rot::IDENTITY);
        anchor(&mut pose, [1.0, 0.0], [0.0, 0.0]);
        let o = pose.world([0.0, 0.0]);
        assert!(o[0].abs() < 1e-12 && (o[1] + 1.0).abs() < 1e-12);
    }
}
