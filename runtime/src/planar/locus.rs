//! Intersections of loci: the closed-form core of a planar plan.
//!
//! Each function either returns the point (or rotation) that meets both
//! loci, or — when none exists — reports a [`Break`] through the context,
//! which under the stretch policy instead returns the point that comes
//! closest and records the gap. Roots are chosen by [`Branch`] sign so that
//! the branch of the drawn pose is kept along smooth motions.

use super::{add, cross, dist2, dot, perp, scale, sub, Rot};
use crate::frame::{lanes_break, lanes_differ, watch, Branch, BranchPolicy, Break, BreakKind, Ctx, StepId};
use crate::scalar::{Factor, Real};

/// Squared half-chords smaller than this (relative to the squared radii)
/// count as tangency rather than a miss: round-off at a tangent pose must
/// not break a mechanism that is exactly at its limit.
const TANGENT_TOLERANCE: f64 = 1e-12;

/// Squared half-chords below this (relative to the squared radii) are dead
/// points for rates ([`Real::sqrt_dead`]): within about 1e-10 rad of the
/// pose where the two roots meet, where a break-point search stops.
const DEAD_FOR_RATES: f64 = 1e-10;

/// A circle: the locus of a point at a fixed distance from a centre (a
/// pin on a link turning about another pin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle<T = f64> {
    /// The centre.
    pub centre: [T; 2],
    /// The radius.
    pub radius: T,
}

impl<T> Circle<T> {
    /// The circle about `centre` of radius `radius`.
    #[inline(always)]
    pub const fn new(centre: [T; 2], radius: T) -> Circle<T> {
        Circle { centre, radius }
    }
}

/// A line through a point along a unit direction (a slide's axis). The
/// direction is any [`Factor`]: a constant of the plan stays a pair of
/// plain numbers, which a jet multiplies by at a third of a jet product's
/// cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line<T = f64, D = T> {
    /// A point of the line.
    pub through: [T; 2],
    /// Its unit direction.
    pub dir: [D; 2],
}

impl<T, D> Line<T, D> {
    /// The line through `through` along the unit direction `dir`.
    #[inline(always)]
    pub const fn new(through: [T; 2], dir: [D; 2]) -> Line<T, D> {
        Line { through, dir }
    }
}

/// A branching step's slot: the root it takes ([`Branch`]) and what it
/// found last frame (a point, or a rotation's cos/sin), which the nearest
/// policy compares with and a break leaves as it was.
pub struct Slot<'s, T> {
    /// The root the step takes.
    pub branch: &'s mut Branch,
    /// What the step found last frame.
    pub last: &'s mut [T; 2],
}

impl<'s, T> Slot<'s, T> {
    /// The slot of `branch` and `last`.
    #[inline(always)]
    pub fn new(branch: &'s mut Branch, last: &'s mut [T; 2]) -> Slot<'s, T> {
        Slot { branch, last }
    }
}

/// The nearest-root policy compares each frame with its own previous one:
/// frames solved together in lanes cannot follow it.
#[inline(always)]
fn nearest_on_lanes<T: Real>(ctx: &Ctx, step: StepId) -> Result<(), Break> {
    if ctx.branch == BranchPolicy::Nearest {
        lanes_differ::<T>(step)?;
    }
    Ok(())
}

/// Picks one of two roots `base ± off` by policy and records the choice.
/// (Lanes never reach the nearest policy: [`nearest_on_lanes`] stops them.)
#[inline(always)]
fn pick<T: Real>(ctx: &Ctx, base: [T; 2], off: [T; 2], branch: &mut Branch, last: &mut [T; 2]) -> [T; 2] {
    let plus = add(base, off);
    let minus = sub(base, off);
    if ctx.branch == BranchPolicy::Nearest {
        *branch = if dist2(plus, *last).value() <= dist2(minus, *last).value() {
            Branch::Plus
        } else {
            Branch::Minus
        };
    }
    let x = match *branch {
        Branch::Plus => plus,
        Branch::Minus => minus,
    };
    *last = x;
    x
}

/// The point on both circles (RRR dyad): at distance `a.radius` from
/// `a.centre` and `b.radius` from `b.centre`.
///
/// Branch + lies to the left of the directed line from `a`'s centre to
/// `b`'s.
#[inline(always)]
pub fn circle_circle<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    a: Circle<T>,
    b: Circle<T>,
    slot: Slot<'_, T>,
) -> Result<[T; 2], Break> {
    let (
        Circle {
            centre: c1,
            radius: r1,
        },
        Circle {
            centre: c2,
            radius: r2,
        },
    ) = (a, b);
    let Slot { branch, last } = slot;
    nearest_on_lanes::<T>(ctx, step)?;
    let d_vec = sub(c2, c1);
    let d2 = dot(d_vec, d_vec);
    if d2.any(|v| v == 0.0) {
        // Concentric circles: no isolated intersection. Stretching puts the
        // point on the first circle, on the side of the last frame.
        lanes_differ::<T>(step)?;
        // Equal radii too (within round-off): the circles coincide, and
        // every point of them would do (a parallelogram at its change
        // point), which is not the same news as circles apart.
        let apart = (r1 - r2).value().abs();
        let kind = if apart <= 1e-12 * (r1.value().abs() + r2.value().abs()) {
            BreakKind::CirclesCoincide
        } else {
            BreakKind::CirclesApart
        };
        ctx.fail(step, kind, apart)?;
        let toward = sub(*last, c1);
        let n = dot(toward, toward).sqrt();
        let u = if n.value() > 0.0 {
            scale(toward, n.recip())
        } else {
            [T::cst(1.0), T::cst(0.0)]
        };
        let x = add(c1, scale(u, r1));
        *last = x;
        return Ok(x);
    }
    // With d² = |c2 − c1|², the chord's foot is c1 + k/d²·(c2 − c1) and the
    // half-chord (h·d)/d²·|c2 − c1|, where k = (r1² − r2² + d²)/2 and (h·d)² = r1²·d² − k².
    // Written this way the one division (1/d²) and the one square root
    // (of (h·d)²) do not wait for each other.
    // (h·d)² factored as ((r1 + r2)² − d²)(d² − (r1 − r2)²)/4: no
    // cancellation near tangency, and a shorter chain of operations.
    let k = (r1 * r1 - r2 * r2 + d2).mul_f64(0.5);
    let sum = r1 + r2;
    let diff = r1 - r2;
    let hd2 = ((sum * sum - d2) * (d2 - diff * diff)).mul_f64(0.25);
    let inv_d2 = d2.recip();
    watch(ctx, step, hd2, || (r1 * r1 + r2 * r2) * d2)?;
    let hd = if hd2.all(|v| v >= 0.0) {
        hd2.sqrt_dead(DEAD_FOR_RATES * (r1 * r1 + r2 * r2).value() * d2.value())
    } else if T::LANES {
        // Frames in lanes leave together when one leaves the usual path
        // (tangent or apart).
        return Err(lanes_break(step));
    } else if hd2.value() >= -TANGENT_TOLERANCE * (r1 * r1 + r2 * r2).value() * d2.value() {
        // Tangent within round-off: the two roots are one, and a rate
        // through it would be infinite (a dead point).
        (hd2 - T::cst(hd2.value())).sqrt()
    } else {
        // Apart (d > r1 + r2) or nested (d < |r1 - r2|): the closest pair of
        // points lies on the centre line; stretching takes their midpoint.
        let d = d2.sqrt();
        let u = scale(d_vec, d.recip());
        let (dv, r1v, r2v) = (d.value(), r1.value(), r2.value());
        let gap = if dv > r1v + r2v {
            dv - r1v - r2v
        } else {
            (r1v - r2v).abs() - dv
        };
        ctx.fail(step, BreakKind::CirclesApart, gap)?;
        let on1 = if dv > r1v + r2v || r1v >= r2v {
            add(c1, scale(u, r1))
        } else {
            sub(c1, scale(u, r1))
        };
        let on2 = if dv > r1v + r2v || r2v >= r1v {
            sub(c2, scale(u, r2))
        } else {
            add(c2, scale(u, r2))
        };
        let x = scale(add(on1, on2), T::cst(0.5));
        *last = x;
        return Ok(x);
    };
    let base = add(c1, scale(d_vec, k * inv_d2));
    Ok(pick(ctx, base, scale(perp(d_vec), hd * inv_d2), branch, last))
}

/// The point where `circle` meets `line` (RRP dyad). Branch + lies ahead
/// of the foot of the circle's centre along the line's direction.
#[inline(always)]
pub fn circle_line<T: Real, D: Factor<T>>(
    ctx: &mut Ctx,
    step: StepId,
    circle: Circle<T>,
    line: Line<T, D>,
    slot: Slot<'_, T>,
) -> Result<[T; 2], Break> {
    let (Circle { centre: c, radius: r }, Line { through: p, dir }) = (circle, line);
    let Slot { branch, last } = slot;
    nearest_on_lanes::<T>(ctx, step)?;
    // The direction is often a constant of the plan (a slide on the
    // ground): `Factor` multiplies by it as a plain number then.
    let along = |k: T| [dir[0].times(k), dir[1].times(k)];
    let cp = sub(c, p);
    let foot = add(p, along(dir[0].times(cp[0]) + dir[1].times(cp[1])));
    let off2 = dist2(c, foot);
    let h2 = r * r - off2;
    watch(ctx, step, h2, || r * r)?;
    let h = if h2.all(|v| v >= 0.0) {
        h2.sqrt_dead(DEAD_FOR_RATES * (r * r).value())
    } else if T::LANES {
        return Err(lanes_break(step));
    } else if h2.value() >= -TANGENT_TOLERANCE * (r * r).value() {
        // Tangent within round-off (a dead point for rates, as in
        // `circle_circle`).
        (h2 - T::cst(h2.value())).sqrt()
    } else {
        let off = off2.sqrt();
        ctx.fail(step, BreakKind::LineMissesCircle, (off - r).value())?;
        // Midway between the line and the circle's nearest point.
        let on_circle = add(c, scale(sub(foot, c), r / off));
        let x = scale(add(on_circle, foot), T::cst(0.5));
        *last = x;
        return Ok(x);
    };
    Ok(pick(ctx, foot, along(h), branch, last))
}

/// The point common to the line through `p1` along `d1` and the line through
/// `p2` along `d2` (PRP dyad; directions of unit length).
#[inline(always)]
pub fn line_line<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    p1: [T; 2],
    d1: [T; 2],
    p2: [T; 2],
    d2: [T; 2],
) -> Result<[T; 2], Break> {
    let det = cross(d1, d2);
    if det.any(|v| v.abs() < 1e-12) {
        lanes_differ::<T>(step)?;
        let gap = cross(sub(p2, p1), d1).value().abs();
        ctx.fail(step, BreakKind::ParallelLines, gap)?;
        // Midway between the two parallel lines, at the foot of p1.
        let foot = add(p2, scale(d2, dot(sub(p1, p2), d2)));
        return Ok(scale(add(p1, foot), T::cst(0.5)));
    }
    let s = cross(sub(p2, p1), d2) / det;
    Ok(add(p1, scale(d1, s)))
}

/// The rotation `R` of a body pinned at `pivot` whose line (local unit
/// direction `dir`) must pass at signed distance `kappa` from `target`:
/// `cross(target − pivot, R·dir) = kappa` (RPR dyad, or a slotted link
/// turning through a placed point).
///
/// Branch + has the line pointing away from the pivot towards the target
/// (positive cosine between `R·dir` and `target − pivot`). `last` keeps the
/// previous (cos, sin) for the nearest policy.
#[inline(always)]
pub fn turn_line_through<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    pivot: [T; 2],
    target: [T; 2],
    dir: [T; 2],
    kappa: T,
    slot: Slot<'_, T>,
) -> Result<Rot<T>, Break> {
    let Slot { branch, last } = slot;
    nearest_on_lanes::<T>(ctx, step)?;
    let e_vec = sub(target, pivot);
    let e = dot(e_vec, e_vec).sqrt();
    let mut sin_a = e.select(|v| v > 0.0, kappa / e, T::cst(f64::INFINITY));
    if sin_a.any(|v| v.abs() > 1.0) {
        lanes_differ::<T>(step)?;
        if sin_a.value().abs() > 1.0 + TANGENT_TOLERANCE {
            ctx.fail(step, BreakKind::LineCannotReach, kappa.value().abs() - e.value())?;
        }
        if e.value() == 0.0 {
            // The target sits on the pivot: any rotation is as good; keep
            // the last one.
            return Ok(Rot {
                c: last[0],
                s: last[1],
            });
        }
        sin_a = T::cst(sin_a.value().signum());
    }
    let one_less = T::cst(1.0) - sin_a * sin_a;
    watch(ctx, step, one_less, || T::cst(1.0))?;
    // Within round-off of ±1: the two roots meet (a dead point for rates).
    let cos_a = if one_less.all(|v| v > 0.0) {
        one_less.sqrt_dead(DEAD_FOR_RATES)
    } else if T::LANES {
        return Err(lanes_break(step));
    } else {
        (one_less - T::cst(one_less.value())).sqrt()
    };
    let eu = scale(e_vec, e.recip());
    // World direction of the line for each root: eu turned by ±alpha.
    let line_dir = |cos: T| -> Rot<T> {
        let w = [eu[0] * cos - eu[1] * sin_a, eu[0] * sin_a + eu[1] * cos];
        // R maps dir to w: R = w · conj(dir) as complex numbers.
        Rot {
            c: w[0] * dir[0] + w[1] * dir[1],
            s: w[1] * dir[0] - w[0] * dir[1],
        }
    };
    let plus = line_dir(cos_a);
    let minus = line_dir(-cos_a);
    if ctx.branch == BranchPolicy::Nearest {
        let far = |r: Rot<T>| (r.c - last[0]).value().powi(2) + (r.s - last[1]).value().powi(2);
        *branch = if far(plus) <= far(minus) {
            Branch::Plus
        } else {
            Branch::Minus
        };
    }
    let r = match *branch {
        Branch::Plus => plus,
        Branch::Minus => minus,
    };
    *last = [r.c, r.s];
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ctx() -> Ctx {
        Ctx::new(BranchPolicy::Keep, false)
    }

    #[test]
    fn circles_meet_on_both_sides() {
        let mut last = [0.0; 2];
        let mut b = Branch::Plus;
        let x = circle_circle(
            &mut ctx(),
            0,
            Circle::new([0.0, 0.0], 5.0),
            Circle::new([8.0, 0.0], 5.0),
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        assert!((x[0] - 4.0).abs() < 1e-12 && (x[1] - 3.0).abs() < 1e-12);
        let mut b = Branch::Minus;
        let x = circle_circle(
            &mut ctx(),
            0,
            Circle::new([0.0, 0.0], 5.0),
            Circle::new([8.0, 0.0], 5.0),
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        assert!((x[1] + 3.0).abs() < 1e-12);
    }

    #[test]
    fn coincident_circles_are_named_as_such_not_apart() {
        let mut last = [0.0; 2];
        let mut b = Branch::Plus;
        let e = circle_circle(
            &mut ctx(),
            3,
            Circle::new([1.0, 2.0], 2.0),
            Circle::new([1.0, 2.0], 2.0),
            Slot::new(&mut b, &mut last),
        )
        .unwrap_err();
        assert_eq!((e.step, e.kind, e.gap), (3, BreakKind::CirclesCoincide, 0.0));
        // Concentric with different radii: apart by their difference.
        let e = circle_circle(
            &mut ctx(),
            3,
            Circle::new([1.0, 2.0], 2.0),
            Circle::new([1.0, 2.0], 0.5),
            Slot::new(&mut b, &mut last),
        )
        .unwrap_err();
        assert_eq!((e.kind, e.gap), (BreakKind::CirclesApart, 1.5));
    }

    #[test]
    fn apart_circles_break_or_stretch() {
        let mut last = [0.0; 2];
        let mut b = Branch::Plus;
        let e = circle_circle(
            &mut ctx(),
            7,
            Circle::new([0.0, 0.0], 1.0),
            Circle::new([5.0, 0.0], 1.0),
            Slot::new(&mut b, &mut last),
        )
        .unwrap_err();
        assert_eq!(e.step, 7);
        assert!((e.gap - 3.0).abs() < 1e-12);
        let mut s = Ctx::new(BranchPolicy::Keep, true);
        let x = circle_circle(
            &mut s,
            7,
            Circle::new([0.0, 0.0], 1.0),
            Circle::new([5.0, 0.0], 1.0),
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        assert!((x[0] - 2.5).abs() < 1e-12);
        assert_eq!(s.stretched, Some((7, 3.0)));
    }

    #[test]
    fn nearest_policy_follows_the_last_point() {
        let mut last = [4.0, -2.9];
        let mut b = Branch::Plus;
        let mut c = Ctx::new(BranchPolicy::Nearest, false);
        let x = circle_circle(
            &mut c,
            0,
            Circle::new([0.0, 0.0], 5.0),
            Circle::new([8.0, 0.0], 5.0),
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        assert_eq!(b, Branch::Minus);
        assert!((x[1] + 3.0).abs() < 1e-12);
    }

    #[test]
    fn circle_meets_line() {
        let mut last = [0.0; 2];
        let mut b = Branch::Plus;
        let circle = Circle::new([0.0, 0.0], 5.0);
        let line = Line::new([-10.0, 3.0], [1.0, 0.0]);
        let x = circle_line(&mut ctx(), 0, circle, line, Slot::new(&mut b, &mut last)).unwrap();
        assert!((x[0] - 4.0).abs() < 1e-12 && (x[1] - 3.0).abs() < 1e-12);
    }

    /// A fixed direction given as plain numbers (as compiled plans pass a
    /// slide on the ground) gives the jet direction's point: the same values
    /// bit for bit, the same rates to rounding.
    #[test]
    fn circle_line_takes_a_plain_direction() {
        use crate::scalar::Jet2;
        let t = Jet2::new(0.3, 1.0, 0.0);
        let c = [Jet2::cst(0.5) + t, Jet2::cst(0.2) + t * t];
        let p = [Jet2::cst(-4.0), Jet2::cst(-3.0)];
        let d = [0.6, 0.8];
        let (mut last, mut b) = ([Jet2::cst(0.0); 2], Branch::Plus);
        let circle = Circle::new(c, Jet2::cst(5.0));
        let plain = circle_line(
            &mut ctx(),
            0,
            circle,
            Line::new(p, d),
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        let (mut last, mut b) = ([Jet2::cst(0.0); 2], Branch::Plus);
        let jets = circle_line(
            &mut ctx(),
            0,
            circle,
            Line::new(p, d.map(Jet2::cst)),
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        for k in 0..2 {
            assert_eq!(plain[k].v.to_bits(), jets[k].v.to_bits());
            assert!((plain[k].d - jets[k].d).abs() <= 1e-14 && (plain[k].dd - jets[k].dd).abs() <= 1e-13);
        }
        // And on the circle with it, rates included: (x − c)·(x − c) = 25.
        let e = [plain[0] - c[0], plain[1] - c[1]];
        let r2 = e[0] * e[0] + e[1] * e[1];
        assert!((r2.v - 25.0).abs() < 1e-12 && r2.d.abs() < 1e-12 && r2.dd.abs() < 1e-11);
    }

    #[test]
    fn lines_meet() {
        let x = line_line(&mut ctx(), 0, [0.0, 1.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]).unwrap();
        assert_eq!(x, [2.0, 1.0]);
        assert!(line_line(&mut ctx(), 0, [0.0, 1.0], [1.0, 0.0], [2.0, 0.0], [1.0, 0.0]).is_err());
    }

    #[test]
    fn turned_line_passes_through_target() {
        // A slot through the pivot (kappa = 0) must point at the target.
        let mut last = [1.0, 0.0];
        let mut b = Branch::Plus;
        let r = turn_line_through(
            &mut ctx(),
            0,
            [0.0, 0.0],
            [0.0, 2.0],
            [1.0, 0.0],
            0.0,
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        let w = r.apply([1.0, 0.0]);
        assert!(w[0].abs() < 1e-12 && (w[1] - 1.0).abs() < 1e-12);
        // An offset slot: the line at signed distance 1 from the target.
        let r = turn_line_through(
            &mut ctx(),
            0,
            [0.0, 0.0],
            [3.0, 0.0],
            [1.0, 0.0],
            1.0,
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        let w = r.apply([1.0, 0.0]);
        assert!((cross([3.0, 0.0], w) - 1.0).abs() < 1e-12);
    }
}
