//! Intersections of loci in space: the closed-form core of a spatial plan.
//!
//! Each function either returns the point (direction, rotation) that meets
//! both loci, or — when none exists — reports a [`Break`] through the
//! context, which under the stretch policy instead returns the point that
//! comes closest (or the most reasonable one) and records the gap. Roots are
//! chosen by a geometric [`Branch`] sign, documented per function, so that
//! the branch of the drawn pose is kept along smooth motions. Every function
//! writes the root it returns into its [`Slot`]'s `last`; under
//! [`BranchPolicy::Nearest`] the root nearest `last` is taken and its sign
//! written back to the slot's `branch`.
//!
//! The loci are small values: a [`Circle`] (centre, normal, radius), a
//! [`Sphere`], a [`Line`], a [`Plane`] and a [`Cone`] of directions, so a
//! step reads as what it intersects: `circle_circle(ctx, id, Circle::new(c1,
//! n1, r1), Circle::new(c2, n2, r2), tol, Slot::new(branch, last))`. Radii
//! are non-negative; normals, axes and line directions are unit vectors (the
//! compiler normalises them once, at plan time).

use super::{
    add, cross, cross_by, cst, dot, dot_by, norm, norm2, perpendicular, reject, scale, scale_by, sub, unit,
    value, Vec3,
};
use crate::frame::{watch, Branch, BranchPolicy, Break, BreakKind, Ctx, StepId, NEAR_DEAD_POINT};
use crate::scalar::{Factor, Real};

/// Squared half-chords smaller than this (relative to the squared radii)
/// count as tangency rather than a miss: round-off at a tangent pose must
/// not break a mechanism that is exactly at its limit.
const TANGENT_TOLERANCE: f64 = 1e-12;

/// Two planes whose unit normals have a cross product at most this long
/// are treated as parallel: their line of intersection is too poorly
/// determined to use, and the problem is solved in one plane instead.
const COPLANAR: f64 = 1e-9;

/// A line whose unit direction makes a dot product at most this large with
/// a plane's unit normal is parallel to the plane (as planar `line_line`).
const PARALLEL: f64 = 1e-12;

/// Squared half-chords below this (relative to the squared radii) are dead
/// points for rates ([`Real::sqrt_dead`]), as in the planar steps.
const DEAD_FOR_RATES: f64 = 1e-10;

/// A circle in space: the locus of a point of a body turning about an
/// axis (the circle [`circle_about`] finds). The normal is of its own type
/// `N`, so that [`sphere_circle`] can take a constant of the plan (a fixed
/// hinge's) as three plain numbers, which a jet multiplies by at a third of
/// a jet product's cost; the other steps take `N = T`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle<T = f64, N = T> {
    /// The centre.
    pub centre: Vec3<T>,
    /// The unit normal of its plane.
    pub normal: [N; 3],
    /// The radius.
    pub radius: T,
}

impl<T, N> Circle<T, N> {
    /// The circle about `centre` in the plane of unit normal `normal`, of
    /// radius `radius`.
    #[inline(always)]
    pub const fn new(centre: Vec3<T>, normal: [N; 3], radius: T) -> Circle<T, N> {
        Circle {
            centre,
            normal,
            radius,
        }
    }
}

/// A sphere: the locus of a point at a fixed distance from a centre (a ball
/// joint's centre on a link about another ball joint).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere<T = f64> {
    /// The centre.
    pub centre: Vec3<T>,
    /// The radius.
    pub radius: T,
}

impl<T> Sphere<T> {
    /// The sphere about `centre` of radius `radius`.
    #[inline(always)]
    pub const fn new(centre: Vec3<T>, radius: T) -> Sphere<T> {
        Sphere { centre, radius }
    }
}

/// A line through a point along a unit direction (a slide's axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line<T = f64> {
    /// A point of the line.
    pub through: Vec3<T>,
    /// Its unit direction.
    pub dir: Vec3<T>,
}

impl<T> Line<T> {
    /// The line through `through` along the unit direction `dir`.
    #[inline(always)]
    pub const fn new(through: Vec3<T>, dir: Vec3<T>) -> Line<T> {
        Line { through, dir }
    }
}

/// A plane through a point, of a unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane<T = f64> {
    /// A point of the plane.
    pub through: Vec3<T>,
    /// Its unit normal.
    pub normal: Vec3<T>,
}

impl<T> Plane<T> {
    /// The plane through `through` of unit normal `normal`.
    #[inline(always)]
    pub const fn new(through: Vec3<T>, normal: Vec3<T>) -> Plane<T> {
        Plane { through, normal }
    }
}

/// A cone of directions about a unit axis through the origin: the unit
/// vectors `v` with `v·axis = cos` (a link of a spherical mechanism held at
/// a fixed angle from a hinge's axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone<T = f64> {
    /// The unit axis.
    pub axis: Vec3<T>,
    /// The cosine of the angle between the axis and the cone's directions.
    pub cos: f64,
}

impl<T> Cone<T> {
    /// The cone of the unit vectors `v` with `v·axis = cos`.
    #[inline(always)]
    pub const fn new(axis: Vec3<T>, cos: f64) -> Cone<T> {
        Cone { axis, cos }
    }
}

/// A branching step's slot: the root it takes ([`Branch`]) and what it
/// found last frame (a point, or the sine of a turn for
/// [`rotation_to_condition`]), which the nearest policy compares with.
pub struct Slot<'s, L> {
    /// The root the step takes.
    pub branch: &'s mut Branch,
    /// What the step found last frame.
    pub last: &'s mut L,
}

impl<'s, L> Slot<'s, L> {
    /// The slot of `branch` and `last`.
    #[inline(always)]
    pub fn new(branch: &'s mut Branch, last: &'s mut L) -> Slot<'s, L> {
        Slot { branch, last }
    }
}

/// A root within round-off of tangency: the value 0 exactly (as the `f64`
/// steps take it), with infinite rates if the squared half-chord `h2`
/// moves (a dead point).
#[inline(always)]
fn tangent<T: Real>(h2: T) -> T {
    (h2 - T::cst(h2.value())).sqrt()
}

#[inline]
fn dist2(a: Vec3, b: Vec3) -> f64 {
    norm2(sub(a, b))
}

#[inline]
fn midpoint<T: Real>(a: Vec3<T>, b: Vec3<T>) -> Vec3<T> {
    scale(add(a, b), T::cst(0.5))
}

/// Chooses one of two roots by policy and records the choice. When the two
/// roots coincide (tangency, or a stretched step that has one closest point)
/// the branch is left alone: there is nothing to choose, and resetting it
/// would flip a mechanism passing through a tangent pose.
///
/// How close the roots are is recorded too ([`crate::frame::watch`]): their
/// half-separation squared, relative to `size2`, the squared size of the
/// loci (the sum of their squared radii).
#[inline]
fn choose<T: Real>(
    ctx: &mut Ctx,
    plus: Vec3<T>,
    minus: Vec3<T>,
    size2: f64,
    branch: &mut Branch,
    last: &mut Vec3<T>,
) -> Vec3<T> {
    let (pv, mv, lv) = (value(plus), value(minus), value(*last));
    let half2 = 0.25 * dist2(pv, mv);
    if half2 < NEAR_DEAD_POINT * size2 || ctx.measure {
        ctx.saw_near(half2 / size2);
    }
    if ctx.branch == BranchPolicy::Nearest && pv != mv {
        *branch = if dist2(pv, lv) <= dist2(mv, lv) {
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

/// [`choose`] between `base + off` (branch +) and `base − off`.
#[inline]
fn pick<T: Real>(
    ctx: &mut Ctx,
    base: Vec3<T>,
    off: Vec3<T>,
    size2: f64,
    branch: &mut Branch,
    last: &mut Vec3<T>,
) -> Vec3<T> {
    choose(ctx, add(base, off), sub(base, off), size2, branch, last)
}

/// A unit vector in the plane of unit normal `n` pointing from `c` toward
/// the projection of `toward`, or [`perpendicular`]`(n)` when `toward`
/// projects onto `c`: the direction a degenerate step (concentric loci)
/// falls back on, continuous with the last frame.
#[inline]
fn in_plane_toward<T: Real>(c: Vec3<T>, n: Vec3<T>, toward: Vec3<T>) -> Vec3<T> {
    let u = unit(reject(sub(toward, c), n));
    if norm2(u).value() > 0.0 {
        u
    } else {
        perpendicular(n)
    }
}

/// The distance from the point `x` to the circle of centre `c`, unit normal
/// `n` and radius `r` (the closest point of the circle is in the half-plane
/// of `x`, so the distance is `√((ρ − r)² + z²)` with ρ and z the radial
/// and normal coordinates of `x`).
#[inline]
pub fn circle_distance(x: Vec3, c: Vec3, n: Vec3, r: f64) -> f64 {
    let v = sub(x, c);
    let z = dot(v, n);
    let rho = norm(sub(v, scale(n, z)));
    let dr = rho - r;
    (dr * dr + z * z).sqrt()
}

/// Two circles in one plane of unit normal `n`.
enum Pair<T> {
    /// They meet at `base ± off`, `off` along `n × (c2 − c1)`.
    Meet { base: Vec3<T>, off: Vec3<T> },
    /// They do not meet: `at` is the midpoint of their closest points.
    Apart { at: Vec3<T> },
    /// They have the same centre.
    Concentric,
}

/// The points at distance `r1` from `c1` and `r2` from `c2` in the plane of
/// unit normal `n` through both centres: the planar dyad.
#[inline]
fn coplanar_pair<T: Real>(c1: Vec3<T>, r1: T, c2: Vec3<T>, r2: T, n: [impl Factor<T>; 3]) -> Pair<T> {
    let d_vec = sub(c2, c1);
    let d2 = norm2(d_vec);
    if d2.value() == 0.0 {
        return Pair::Concentric;
    }
    // As planar `circle_circle`: with k = (r1² − r2² + d²)/2 the chord's foot
    // is c1 + k/d²·(c2 − c1) and the half-chord (h·d)/d²·|c2 − c1|, where
    // (h·d)² = ((r1 + r2)² − d²)(d² − (r1 − r2)²)/4 is factored so that it
    // does not cancel near tangency.
    let k = (r1 * r1 - r2 * r2 + d2).mul_f64(0.5);
    let sum = r1 + r2;
    let diff = r1 - r2;
    let hd2 = ((sum * sum - d2) * (d2 - diff * diff)).mul_f64(0.25);
    let inv_d2 = d2.recip();
    let radii2 = (r1 * r1 + r2 * r2).value();
    let hd = if hd2.value() >= 0.0 {
        hd2.sqrt_dead(DEAD_FOR_RATES * radii2 * d2.value())
    } else if hd2.value() >= -TANGENT_TOLERANCE * radii2 * d2.value() {
        tangent(hd2)
    } else {
        return coplanar_apart(c1, r1, c2, r2, d_vec, d2);
    };
    Pair::Meet {
        base: add(c1, scale(d_vec, k * inv_d2)),
        off: scale(cross_by(n, d_vec), hd * inv_d2),
    }
}

/// Apart (d > r1 + r2) or nested (d < |r1 − r2|): the closest pair of points
/// lies on the centre line; the midpoint is what stretching places.
#[cold]
#[inline(never)]
fn coplanar_apart<T: Real>(c1: Vec3<T>, r1: T, c2: Vec3<T>, r2: T, d_vec: Vec3<T>, d2: T) -> Pair<T> {
    let d = d2.sqrt();
    let u = scale(d_vec, d.recip());
    let (dv, r1v, r2v) = (d.value(), r1.value(), r2.value());
    let apart = dv > r1v + r2v;
    let on1 = if apart || r1v >= r2v {
        add(c1, scale(u, r1))
    } else {
        sub(c1, scale(u, r1))
    };
    let on2 = if apart || r2v >= r1v {
        sub(c2, scale(u, r2))
    } else {
        add(c2, scale(u, r2))
    };
    Pair::Apart {
        at: midpoint(on1, on2),
    }
}

/// The half-chord that the line at distance `d` from a circle's centre, in
/// its plane, cuts from the circle of radius `r`; `None` if the line misses
/// it by more than `tol` (a line missing by at most `tol`, or by round-off,
/// touches it: half-chord 0).
#[inline]
fn half_chord<T: Real>(r: T, d: T, tol: f64) -> Option<T> {
    let h2 = (r - d) * (r + d);
    let (h2v, rv) = (h2.value(), r.value());
    if h2v >= 0.0 {
        Some(h2.sqrt_dead(DEAD_FOR_RATES * rv * rv))
    } else if d.value() - rv <= tol || h2v >= -TANGENT_TOLERANCE * rv * rv {
        Some(tangent(h2))
    } else {
        None
    }
}

/// The candidates for a point on two circles, as
/// [`circle_circle_candidates`] computes them: what [`circle_circle`]
/// chooses from at move time, and what the compiler inspects at plan time
/// to learn how many candidates pass (two: a branch to choose; one: a
/// unique point; none: the circles do not meet).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircleCandidates<T = f64> {
    /// The candidates: index 0 is branch +, index 1 branch −. When the
    /// circles do not meet these are the closest points the rules below
    /// find (possibly the same point twice).
    pub points: [Vec3<T>; 2],
    /// Each candidate's miss: its distance from circle 1 plus its distance
    /// from circle 2 (0 for a true intersection; for a point on one circle,
    /// its distance from the other).
    pub misses: [f64; 2],
    /// Whether each candidate's miss is within the tolerance (never, for
    /// concentric circles).
    pub passes: [bool; 2],
    /// The circles' planes are parallel (`|n1 × n2| ≤ 1e-9`): both
    /// candidates are the two roots of the planar dyad, related by the
    /// branch sign.
    pub coplanar: bool,
    /// The circles are coplanar and concentric: there is no isolated
    /// intersection (the points are one fallback point).
    pub concentric: bool,
}

impl<T> CircleCandidates<T> {
    /// How many candidates pass (0, 1 or 2).
    #[inline]
    pub fn count(&self) -> usize {
        self.passes[0] as usize + self.passes[1] as usize
    }
}

/// The candidates for a point on the circles `a` and `b`, with their
/// misses, for a step whose tolerance is `tol` (an absolute distance). See
/// [`circle_circle`] for how they are found and signed.
pub fn circle_circle_candidates(a: Circle, b: Circle, tol: f64) -> CircleCandidates {
    candidates(a, b, tol, a.centre)
}

/// [`circle_circle_candidates`], with the point `toward` whose direction
/// from `a.centre` the concentric fallback takes (the last frame's point).
#[inline]
fn candidates<T: Real>(a: Circle<T>, b: Circle<T>, tol: f64, toward: Vec3<T>) -> CircleCandidates<T> {
    let (c1, n1, r1) = (a.centre, a.normal, a.radius);
    let (c2, n2, r2) = (b.centre, b.normal, b.radius);
    let m = cross(n1, n2);
    let m2 = norm2(m);
    if m2.value() > COPLANAR * COPLANAR {
        return skew_candidates(a, b, tol, m, m2);
    }
    // Parallel planes: solve in circle 1's plane, then lift the result
    // halfway to circle 2's plane so that a small offset between the planes
    // is shared by both circles.
    let z = dot(sub(c2, c1), n1);
    let lift = scale(n1, z.mul_f64(0.5));
    let mut concentric = false;
    let points = match coplanar_pair(c1, r1, sub(c2, scale(n1, z)), r2, n1) {
        Pair::Meet { base, off } => [add(add(base, off), lift), add(sub(base, off), lift)],
        Pair::Apart { at } => [add(at, lift); 2],
        Pair::Concentric => {
            concentric = true;
            [add(add(c1, scale(in_plane_toward(c1, n1, toward), r1)), lift); 2]
        }
    };
    // The misses decide, on values.
    let (c1v, n1v, r1v, c2v, n2v, r2v) = (value(c1), value(n1), r1.value(), value(c2), value(n2), r2.value());
    let miss =
        |x: Vec3<T>| circle_distance(value(x), c1v, n1v, r1v) + circle_distance(value(x), c2v, n2v, r2v);
    let misses = [miss(points[0]), miss(points[1])];
    let ok = !concentric;
    CircleCandidates {
        points,
        misses,
        passes: [ok && misses[0] <= tol, ok && misses[1] <= tol],
        coplanar: true,
        concentric,
    }
}

/// The candidates of two circles in planes that are not parallel: the
/// points of the planes' common line ℓ on circle `b`, checked against
/// circle `a`. `m = n1 × n2` (`a.normal × b.normal`), `m2 = |m|²`.
#[inline]
fn skew_candidates<T: Real>(a: Circle<T>, b: Circle<T>, tol: f64, m: Vec3<T>, m2: T) -> CircleCandidates<T> {
    let (c1, n1, r1) = (a.centre, a.normal, a.radius);
    let (c2, n2, r2) = (b.centre, b.normal, b.radius);
    // The misses decide, on values.
    let (c1v, n1v, r1v, c2v, n2v, r2v) = (value(c1), value(n1), r1.value(), value(c2), value(n2), r2.value());
    let miss =
        |x: Vec3<T>| circle_distance(value(x), c1v, n1v, r1v) + circle_distance(value(x), c2v, n2v, r2v);
    let t = scale(m, m2.sqrt().recip());
    // p0, the point of ℓ nearest c1: c1 moved within plane 1 (along
    // m × n1 = n2 − (n1·n2)·n1) until it reaches plane 2. |m|² stands for
    // 1 − (n1·n2)², which would cancel for nearly parallel planes.
    let off1 = scale(cross(m, n1), dot(n2, sub(c2, c1)) / m2);
    let p0 = add(c1, off1);
    // Both circles as chords of ℓ, in the parameter τ along t from p0:
    // circle 1's is centred at 0, circle 2's at s2.
    let s2 = dot(sub(c2, p0), t);
    let d2 = norm(sub(c2, add(p0, scale(t, s2))));
    let h1 = half_chord(r1, norm(off1), tol);
    let h2 = half_chord(r2, d2, tol);
    let at = |tau: T| add(p0, scale(t, tau));
    // Index 0 is the larger τ (branch + along t). When ℓ misses circle 2,
    // circle 1's chord ends stand in; when it misses both, the two feet.
    let taus = match (h2, h1) {
        (Some(h2), _) => [s2 + h2, s2 - h2],
        (None, Some(h1)) => [h1, -h1],
        (None, None) => {
            // [max(s2, 0), min(s2, 0)]
            let zero = T::cst(0.0);
            if s2.value() > 0.0 {
                [s2, zero]
            } else {
                [zero, s2]
            }
        }
    };
    let mut points = [at(taus[0]), at(taus[1])];
    let mut misses = [miss(points[0]), miss(points[1])];
    if let (Some(h2), Some(h1)) = (h2, h1) {
        // A passing candidate is also an end of circle 1's chord, the one
        // on its side of 0. Each chord end is computed with an error of
        // about ε·r²/h (the square root of a difference of squares), so the
        // two are averaged with weights (h/r²)²: the result is as close to
        // both circles as the better conditioned chord allows, and moves
        // continuously as the conditioning changes.
        let weight = |h: T, r: T| {
            if r.value() > 0.0 {
                let q = h / (r * r);
                q * q
            } else {
                T::cst(0.0)
            }
        };
        let (w1, w2) = (weight(h1, r1), weight(h2, r2));
        for i in 0..2 {
            if misses[i] > tol {
                continue;
            }
            let tau1 = if taus[i].value() >= 0.0 { h1 } else { -h1 };
            let tau = if (w1 + w2).value() > 0.0 {
                (w1 * tau1 + w2 * taus[i]) / (w1 + w2)
            } else {
                (tau1 + taus[i]).mul_f64(0.5)
            };
            let x = at(tau);
            let e = miss(x);
            // Never worse than circle 2's own chord end.
            if e <= misses[i] {
                points[i] = x;
                misses[i] = e;
            }
        }
    }
    CircleCandidates {
        points,
        misses,
        passes: [misses[0] <= tol, misses[1] <= tol],
        coplanar: false,
        concentric: false,
    }
}

/// A point on both the circle `a` and the circle `b`: the spatial dyad.
/// `tol` is the distance within which a candidate counts as on both
/// circles.
///
/// - **Coplanar** (`|a.normal × b.normal| ≤ 1e-9`): the planar dyad in
///   `a`'s plane (`b.centre` projected into it; a small offset between the
///   planes is split between them). Branch + lies along `a.normal × e`, `e`
///   the direction from `a.centre` to the projected `b.centre`. Circles that
///   do not meet, planes further apart than `tol` or concentric circles
///   break ([`BreakKind::CirclesApart`]); stretching takes the midpoint of
///   the closest points (concentric: the point of `a` toward the slot's
///   `last`).
/// - **Not coplanar**: the point lies on the planes' common line ℓ (along
///   `t = unit(a.normal × b.normal)`). The candidates are where ℓ cuts `b`;
///   a candidate passes if it is also within `tol` of `a`.
///   - both pass (the circles lie on one sphere, as in spherical
///     mechanisms): branch + is the candidate further along `t`;
///   - one passes (two circles that touch at one point): it is taken and
///     the slot's `branch` is left unchanged;
///   - none: the step breaks ([`BreakKind::CirclesApart`], gap = the
///     smaller miss); stretching returns the candidate that misses least
///     (`a`'s chord ends stand in when ℓ misses `b`, the feet of the
///     centres on ℓ when it misses both).
///
/// A passing candidate is refined against `a`'s chord of ℓ so that it lies
/// on both circles as accurately as their conditioning allows.
#[inline]
pub fn circle_circle<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    a: Circle<T>,
    b: Circle<T>,
    tol: f64,
    slot: Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let Slot { branch, last } = slot;
    let cand = candidates(a, b, tol, *last);
    let [p, m] = cand.passes;
    let gap = cand.misses[0].min(cand.misses[1]);
    if cand.concentric {
        ctx.fail(step, BreakKind::CirclesApart, gap)?;
        *last = cand.points[0];
        return Ok(cand.points[0]);
    }
    if cand.coplanar || (p && m) {
        if !(p || m) {
            ctx.fail(step, BreakKind::CirclesApart, gap)?;
        }
        let size2 = a.radius.value().powi(2) + b.radius.value().powi(2);
        return Ok(choose(ctx, cand.points[0], cand.points[1], size2, branch, last));
    }
    let x = if p {
        cand.points[0]
    } else if m {
        cand.points[1]
    } else {
        ctx.fail(step, BreakKind::CirclesApart, gap)?;
        if cand.misses[0] <= cand.misses[1] {
            cand.points[0]
        } else {
            cand.points[1]
        }
    };
    *last = x;
    Ok(x)
}

/// A point on `sphere` (centre `cs`, radius `rs`) and on `circle` (centre
/// `c`, unit normal `n`, radius `r`).
///
/// The sphere cuts the circle's plane in the circle of centre `cs − s·n`
/// (`s = (cs − c)·n`) and radius `√(rs² − s²)`; the two coplanar circles are
/// then intersected. Branch + lies along `n × e`, `e` the direction from `c`
/// toward the projected sphere centre.
///
/// If the sphere does not reach the circle (or the projected centre is `c`
/// itself) the step breaks ([`BreakKind::CirclesApart`]) with the distance
/// between the sphere and the circle as its gap; stretching returns the
/// midpoint between the circle's point nearest the sphere and the sphere.
///
/// The circle's normal may be any [`Factor`] (a fixed hinge's, as plain
/// numbers).
#[inline]
pub fn sphere_circle<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    sphere: Sphere<T>,
    circle: Circle<T, impl Factor<T>>,
    slot: Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let (cs, rs) = (sphere.centre, sphere.radius);
    let (c, n, r) = (circle.centre, circle.normal, circle.radius);
    let Slot { branch, last } = slot;
    // The normal is a constant of the plan when the circle is (a fixed
    // hinge's): `Factor` multiplies by it as plain numbers then.
    let s = dot_by(sub(cs, c), n);
    let cp = sub(cs, scale_by(n, s));
    // |s|, its sign taken on the value.
    let s_abs = if s.value() < 0.0 { -s } else { s };
    let rho2 = (rs - s_abs) * (rs + s_abs);
    let (rho2v, rsv) = (rho2.value(), rs.value());
    let rho = if rho2v >= 0.0 {
        Some(rho2.sqrt_dead(DEAD_FOR_RATES * rsv * rsv))
    } else if rho2v >= -TANGENT_TOLERANCE * rsv * rsv {
        Some(tangent(rho2))
    } else {
        None
    };
    if let Some(rho) = rho {
        if let Pair::Meet { base, off } = coplanar_pair(c, r, cp, rho, n) {
            let size2 = rsv * rsv + r.value().powi(2);
            return Ok(pick(ctx, base, off, size2, branch, last));
        }
    }
    let circle: Circle<T> = Circle::new(c, n.map(Factor::lift), r);
    sphere_circle_miss(ctx, step, sphere, circle, s, cp, last)
}

/// [`sphere_circle`] when the sphere misses the circle: the distances from
/// `cs` to the circle's points range over `[√(s² + (e − r)²), √(s² + (e +
/// r)²)]` (`e` the distance of the projected centre `cp` from `c`); the gap
/// is how far `rs` is outside that range.
#[cold]
#[inline(never)]
fn sphere_circle_miss<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    sphere: Sphere<T>,
    circle: Circle<T>,
    s: T,
    cp: Vec3<T>,
    last: &mut Vec3<T>,
) -> Result<Vec3<T>, Break> {
    let (cs, rs) = (sphere.centre, sphere.radius);
    let (c, n, r) = (circle.centre, circle.normal, circle.radius);
    let e_vec = sub(cp, c);
    let e = norm(e_vec);
    let (sv, ev, rv, rs_t, rs) = (s.value(), e.value(), r.value(), rs, rs.value());
    let near = (sv * sv + (ev - rv) * (ev - rv)).sqrt();
    let far = (sv * sv + (ev + rv) * (ev + rv)).sqrt();
    let gap = if rs < near {
        near - rs
    } else if rs > far {
        rs - far
    } else {
        // Concentric (every point of the circle is as far from cs), or
        // round-off at tangency.
        (rs - near).min(far - rs)
    };
    // Whether the sphere is nearer to reaching the circle's near side than
    // its far side (too small rather than too large).
    let near_side = rs - near <= far - rs;
    ctx.fail(step, BreakKind::CirclesApart, gap)?;
    let u = if ev > 0.0 {
        scale(e_vec, e.recip())
    } else {
        in_plane_toward(c, n, *last)
    };
    // The circle's point nearest the sphere: toward cs when the sphere is
    // too small to reach the circle, away from it when too large.
    let on_circle = if near_side || ev == 0.0 {
        add(c, scale(u, r))
    } else {
        sub(c, scale(u, r))
    };
    let toward = sub(on_circle, cs);
    let dn = norm(toward);
    let on_sphere = if dn.value() > 0.0 {
        add(cs, scale(toward, rs_t / dn))
    } else {
        on_circle
    };
    let x = midpoint(on_circle, on_sphere);
    *last = x;
    Ok(x)
}

/// A point on `line` (through `p` along the unit vector `d`) at distance
/// `r` from `c` (on `sphere`, of centre `c` and radius `r`). Branch + is the
/// root further along `d`. A line missing the sphere by round-off
/// (1e-12 relative, on the squared half-chord) touches it; otherwise the
/// step breaks ([`BreakKind::LineMissesCircle`], gap = how far the line
/// passes outside the sphere) and stretching returns the midpoint between
/// the line's point nearest `c` and the sphere.
#[inline]
pub fn line_sphere<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    line: Line<T>,
    sphere: Sphere<T>,
    slot: Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let (p, d) = (line.through, line.dir);
    let (c, r) = (sphere.centre, sphere.radius);
    let Slot { branch, last } = slot;
    let foot = add(p, scale(d, dot(sub(c, p), d)));
    let v = sub(foot, c);
    let off = norm(v);
    let h2 = (r - off) * (r + off);
    let (h2v, rv) = (h2.value(), r.value());
    let h = if h2v >= 0.0 {
        h2.sqrt_dead(DEAD_FOR_RATES * rv * rv)
    } else if h2v >= -TANGENT_TOLERANCE * rv * rv {
        tangent(h2)
    } else {
        ctx.fail(step, BreakKind::LineMissesCircle, off.value() - rv)?;
        // off > r ≥ 0 here, so the division is safe.
        let x = midpoint(add(c, scale(v, r / off)), foot);
        *last = x;
        return Ok(x);
    };
    Ok(pick(ctx, foot, scale(d, h), rv * rv, branch, last))
}

/// A point on `line` (through `p` along the unit vector `d`) and on
/// `circle` (centre `c`, unit normal `n`, radius `r`); `tol` is the distance
/// within which a point counts as on the circle.
///
/// - The line parallel to the plane (`|d·n| ≤ 1e-9`): it must lie in the
///   plane within `tol`; the roots are those of the line and the circle in
///   the plane, branch + further along `d`. A line too far from the plane or
///   missing the circle breaks ([`BreakKind::LineMissesCircle`], gap = the
///   distance between the line and the circle); stretching moves the point
///   halfway to the circle.
/// - Otherwise the line crosses the plane at one point, which is taken if it
///   is within `tol` of the circle (the slot's `branch` is left unchanged),
///   and breaks otherwise; stretching returns the midpoint between it and
///   the circle.
#[inline]
pub fn line_circle<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    line: Line<T>,
    circle: Circle<T>,
    tol: f64,
    slot: Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let (p, d) = (line.through, line.dir);
    let (c, n, r) = (circle.centre, circle.normal, circle.radius);
    let Slot { branch, last } = slot;
    let dn = dot(d, n);
    if dn.value().abs() > COPLANAR {
        let x = add(p, scale(d, dot(sub(c, p), n) / dn));
        let miss = circle_distance(value(x), value(c), value(n), r.value());
        if miss > tol {
            ctx.fail(step, BreakKind::LineMissesCircle, miss)?;
            let on_circle = add(c, scale(in_plane_toward(c, n, x), r));
            let x = midpoint(x, on_circle);
            *last = x;
            return Ok(x);
        }
        *last = x;
        return Ok(x);
    }
    // The line's point nearest c, its height z above the plane and its
    // distance from c within the plane.
    let foot = add(p, scale(d, dot(sub(c, p), d)));
    let v = sub(foot, c);
    let z = dot(v, n);
    let v_in = sub(v, scale(n, z));
    let off = norm(v_in);
    let h2 = (r - off) * (r + off);
    let (h2v, rv) = (h2.value(), r.value());
    let h = if h2v >= 0.0 {
        h2.sqrt_dead(DEAD_FOR_RATES * rv * rv)
    } else if h2v >= -TANGENT_TOLERANCE * rv * rv {
        tangent(h2)
    } else {
        let (dr, zv) = (off.value() - rv, z.value());
        ctx.fail(step, BreakKind::LineMissesCircle, (dr * dr + zv * zv).sqrt())?;
        let x = midpoint(add(c, scale(v_in, r / off)), foot);
        *last = x;
        return Ok(x);
    };
    let mut base = foot;
    if z.value().abs() > tol {
        ctx.fail(step, BreakKind::LineMissesCircle, z.value().abs())?;
        // Halfway down to the circle's plane, above the in-plane roots.
        base = sub(foot, scale(n, z.mul_f64(0.5)));
    }
    Ok(pick(ctx, base, scale(d, h), rv * rv, branch, last))
}

/// The point where `line` (through `p` along the unit vector `d`) crosses
/// `plane` (through `q`, of unit normal `n`). A line parallel to
/// the plane (`|d·n| ≤ 1e-12`) breaks ([`BreakKind::ParallelLines`], gap =
/// its distance from the plane); stretching returns the point halfway from
/// `p` to the plane.
#[inline]
pub fn line_plane<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    line: Line<T>,
    plane: Plane<T>,
) -> Result<Vec3<T>, Break> {
    let (p, d) = (line.through, line.dir);
    let (q, n) = (plane.through, plane.normal);
    let dn = dot(d, n);
    let z = dot(sub(q, p), n);
    if dn.value().abs() <= PARALLEL {
        ctx.fail(step, BreakKind::ParallelLines, z.value().abs())?;
        return Ok(add(p, scale(n, z.mul_f64(0.5))));
    }
    Ok(add(p, scale(d, z / dn)))
}

/// A point on `plane` (through `q`, of unit normal `nq`) and on `circle`
/// (centre `c`, unit normal `n`, radius `r`): the circle's points on
/// the line the two planes share. Branch + lies along `nq × n`.
///
/// A plane parallel to the circle's (`|nq × n| ≤ 1e-12`) breaks
/// ([`BreakKind::ParallelLines`], gap = the planes' distance; stretching
/// returns the circle's point toward the slot's `last`, halfway to the
/// plane). A plane that misses the circle breaks
/// ([`BreakKind::LineMissesCircle`], gap = the distance from the plane to
/// the circle's nearest point; stretching returns that point moved halfway
/// to the plane).
#[inline]
pub fn plane_circle<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    plane: Plane<T>,
    circle: Circle<T>,
    slot: Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let (q, nq) = (plane.through, plane.normal);
    let (c, n, r) = (circle.centre, circle.normal, circle.radius);
    let Slot { branch, last } = slot;
    let t = cross(nq, n);
    let t2 = norm2(t);
    // Height of the circle's centre above the plane.
    let zc = dot(sub(c, q), nq);
    if t2.value() <= PARALLEL * PARALLEL {
        ctx.fail(step, BreakKind::ParallelLines, zc.value().abs())?;
        let on_circle = add(c, scale(in_plane_toward(c, n, *last), r));
        let x = sub(on_circle, scale(nq, dot(sub(on_circle, q), nq).mul_f64(0.5)));
        *last = x;
        return Ok(x);
    }
    // w = n × t is nq's component in the circle's plane, |w| = |t|. The
    // circle's point at angle θ from w has height zc + r·|w|·cos θ, so the
    // roots are c − zc/|w|²·w ± √(r²|w|² − zc²)/|w|²·t.
    let w = cross(n, t);
    let rw = r * t2.sqrt();
    let zc_abs = if zc.value() < 0.0 { -zc } else { zc };
    let h2 = (rw - zc_abs) * (rw + zc_abs);
    let (h2v, rwv) = (h2.value(), rw.value());
    let h = if h2v >= 0.0 {
        h2.sqrt_dead(DEAD_FOR_RATES * rwv * rwv)
    } else if h2v >= -TANGENT_TOLERANCE * rwv * rwv {
        tangent(h2)
    } else {
        ctx.fail(step, BreakKind::LineMissesCircle, zc_abs.value() - rwv)?;
        let toward = scale(w, (r / t2.sqrt()).mul_f64(-zc.value().signum()));
        let on_circle = add(c, toward);
        let x = sub(on_circle, scale(nq, dot(sub(on_circle, q), nq).mul_f64(0.5)));
        *last = x;
        return Ok(x);
    };
    let inv_t2 = t2.recip();
    let base = sub(c, scale(w, zc * inv_t2));
    Ok(pick(
        ctx,
        base,
        scale(t, h * inv_t2),
        r.value().powi(2),
        branch,
        last,
    ))
}

/// A unit vector `v` on the cones `a` (axis `w1`, `v·w1 = cos1`) and `b`
/// (axis `w2`, `v·w2 = cos2`) about unit axes through the origin (the
/// direction of a link of a spherical mechanism, or the axis of a body held
/// at two angles).
///
/// With `c = w1·w2` and `m = w1 × w2`,
/// `v = ((cos1 − c·cos2)·w1 + (cos2 − c·cos1)·w2 ± √D·m)/|m|²`, where
/// `D = (1 − cos1²)·|m|² − (cos2 − c·cos1)²` (the Gram determinant of `w1`,
/// `w2` and `v`; `|m|²` stands for `1 − c²`, which would cancel for nearly
/// parallel axes). Branch + lies along `w1 × w2`.
///
/// Cones that do not meet break ([`BreakKind::CirclesApart`], gap = the
/// angle in radians between them, the arc length on the unit sphere);
/// stretching returns the direction midway between their closest
/// directions. Axes parallel or opposite (`|m| ≤ 1e-9`) give no isolated
/// root and break too (stretching: midway toward the slot's `last`).
#[inline]
pub fn cone_cone<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    a: Cone<T>,
    b: Cone<T>,
    slot: Slot<'_, Vec3<T>>,
) -> Result<Vec3<T>, Break> {
    let (w1, cos1, w2, cos2) = (a.axis, a.cos, b.axis, b.cos);
    let Slot { branch, last } = slot;
    let c = dot(w1, w2);
    let m = cross(w1, w2);
    let m2 = norm2(m);
    if m2.value() <= COPLANAR * COPLANAR {
        return cone_cone_coaxial(ctx, step, a, b, c, last);
    }
    let xp = T::cst(cos1) - c.mul_f64(cos2);
    let yp = T::cst(cos2) - c.mul_f64(cos1);
    let det = m2.mul_f64((1.0 - cos1) * (1.0 + cos1)) - yp * yp;
    let m2v = m2.value();
    let root = if det.value() >= 0.0 {
        det.sqrt_dead(DEAD_FOR_RATES * m2v)
    } else if det.value() >= -TANGENT_TOLERANCE * m2v {
        tangent(det)
    } else {
        return cone_cone_apart(ctx, step, a, b, Axes { c, m, m2 }, last);
    };
    let inv_m2 = m2.recip();
    let base = scale(add(scale(w1, xp), scale(w2, yp)), inv_m2);
    // Unit directions: the loci's size is 1.
    Ok(pick(ctx, base, scale(m, root * inv_m2), 1.0, branch, last))
}

/// The signed angle `a − b` wrapped into (−π, π].
fn wrap(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI {
        d - TAU
    } else {
        d
    }
}

/// How the axes `w1` and `w2` of two cones lie, as [`cone_cone`] computes
/// it once for its roots and its misses: `c = w1·w2`, `m = w1 × w2`,
/// `m2 = |m|²`.
#[derive(Clone, Copy)]
struct Axes<T> {
    c: T,
    m: Vec3<T>,
    m2: T,
}

/// [`cone_cone`] for cones that do not meet. Their closest directions lie
/// in the plane of the axes (the configuration is symmetric about it): in
/// that plane, at angles ±α from `w1` (cone `a`) and γ ± β (cone `b`), γ
/// the angle from `w1` to `w2`.
#[cold]
#[inline(never)]
fn cone_cone_apart<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    a: Cone<T>,
    b: Cone<T>,
    axes: Axes<T>,
    last: &mut Vec3<T>,
) -> Result<Vec3<T>, Break> {
    let (w1, cos1, cos2) = (a.axis, a.cos, b.cos);
    let Axes { c, m, m2 } = axes;
    let mn = m2.sqrt();
    let alpha = cos1.clamp(-1.0, 1.0).acos();
    let beta = cos2.clamp(-1.0, 1.0).acos();
    let gamma = mn.atan2(c);
    let mut best = (f64::INFINITY, T::cst(0.0));
    for a in [alpha, -alpha] {
        for b in [gamma + T::cst(beta), gamma - T::cst(beta)] {
            // wrap(a, b) on the value, with the rates of a − b.
            let d = (T::cst(a) - b).with_value(wrap(a, b.value()));
            if d.value().abs() < best.0 {
                best = (d.value().abs(), b + d.mul_f64(0.5));
            }
        }
    }
    ctx.fail(step, BreakKind::CirclesApart, best.0)?;
    // The unit vector of the axes' plane perpendicular to w1, toward w2.
    let u = scale(cross(m, w1), mn.recip());
    let (s, co) = best.1.sin_cos();
    let x = add(scale(w1, co), scale(u, s));
    *last = x;
    Ok(x)
}

/// [`cone_cone`] for parallel or opposite axes (`c = w1·w2`): cone `b` is a
/// cone about `w1` (of angle β or π − β), so the cones coincide or miss
/// entirely.
#[cold]
#[inline(never)]
fn cone_cone_coaxial<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    a: Cone<T>,
    b: Cone<T>,
    c: T,
    last: &mut Vec3<T>,
) -> Result<Vec3<T>, Break> {
    let (w1, cos1, cos2) = (a.axis, a.cos, b.cos);
    let alpha = cos1.clamp(-1.0, 1.0).acos();
    let beta = (c.value().signum() * cos2).clamp(-1.0, 1.0).acos();
    ctx.fail(step, BreakKind::CirclesApart, (alpha - beta).abs())?;
    let u = in_plane_toward(cst([0.0; 3]), w1, *last);
    let (s, co) = (0.5 * (alpha + beta)).sin_cos();
    let x = add(scale(w1, T::cst(co)), scale(u, T::cst(s)));
    *last = x;
    Ok(x)
}

/// The rotation about the unit vector `axis` by the angle φ for which
/// `(Rot(axis, φ)·v)·w = c`, returned as `(cos φ, sin φ)`: the turn of a
/// body about a known axis that brings its direction `v` to the angle with
/// the direction `w` given by `c` (or a point to a plane, with `w` the
/// plane's normal and `c` its offset).
///
/// The condition is `A cos φ + B sin φ = C` with `A = v⊥·w`,
/// `B = (axis × v)·w`, `C = c − (v·axis)(axis·w)` (`v⊥` the part of `v`
/// perpendicular to the axis), so φ = atan2(B, A) ± acos(C/√(A² + B²)).
/// The roots are computed from (cos, sin) pairs, without trigonometry:
/// with `R² = A² + B²` and `S = √(R² − C²)`, branch + is
/// `((A·C − B·S)/R², (B·C + A·S)/R²)` and branch − has `S` negated.
///
/// - [`BranchPolicy::Nearest`] takes the root nearest φ = 0 (the larger
///   cosine): the step turns a body that is still in its previous frame's
///   pose, so the nearest root is the smaller turn. The slot's `last` is
///   only written: sin φ of the chosen root (a record for reports; no frame
///   needs the angle itself, and an `atan2` per frame would cost more than
///   the step).
/// - `√(A² + B²)` ≈ 0 (1e-12 of `|v||w|`): the condition does not depend
///   on φ; it returns the identity (1, 0) if it holds, else breaks.
/// - `|C| > √(A² + B²)` beyond round-off: [`BreakKind::LineCannotReach`],
///   gap = `|C| − √(A² + B²)` (in the units of `c`); stretching returns the
///   closest angle, atan2(B, A) (or that plus π when C < 0).
#[inline]
pub fn rotation_to_condition<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    axis: Vec3<T>,
    v: Vec3<T>,
    w: Vec3<T>,
    c: f64,
    slot: Slot<'_, f64>,
) -> Result<(T, T), Break> {
    let Slot { branch, last } = slot;
    let va = dot(v, axis);
    let a = dot(reject(v, axis), w);
    let b = dot(cross(axis, v), w);
    let cc = T::cst(c) - va * dot(axis, w);
    let r2 = a * a + b * b;
    let r = r2.sqrt();
    // |v||w| with one square root.
    let size = (norm2(v) * norm2(w)).value().sqrt();
    // |C|, its sign taken on the value.
    let cc_abs = if cc.value() < 0.0 { -cc } else { cc };
    let s2 = (r - cc_abs) * (r + cc_abs);
    let (rv, ccv) = (r.value(), cc.value());
    if s2.value() < 0.0 && ccv.abs() - rv > TANGENT_TOLERANCE * size {
        ctx.fail(step, BreakKind::LineCannotReach, ccv.abs() - rv)?;
        let (co, si) = if rv > TANGENT_TOLERANCE * size {
            let k = r.recip().mul_f64(ccv.signum());
            (a * k, b * k)
        } else {
            (T::cst(1.0), T::cst(0.0))
        };
        *last = si.value();
        return Ok((co, si));
    }
    if rv <= TANGENT_TOLERANCE * size || r2.value() == 0.0 {
        *last = 0.0;
        return Ok((T::cst(1.0), T::cst(0.0)));
    }
    watch(ctx, step, s2, || r2)?;
    let s = if s2.value() > 0.0 {
        s2.sqrt_dead(DEAD_FOR_RATES * r2.value())
    } else {
        tangent(s2)
    };
    // Normalised by their own lengths so that both are unit pairs to
    // rounding (C is clamped to ±R at tangency).
    let cl = if ccv < -rv {
        -r
    } else if ccv > rv {
        r
    } else {
        cc
    };
    let unit_pair = |co: T, si: T| {
        let n = (co * co + si * si).sqrt();
        (co / n, si / n)
    };
    // Only the root asked for is normalised, unless the nearest of the two
    // is to be chosen: (A·C ∓ B·S, B·C ± A·S), both of length R².
    if ctx.branch == BranchPolicy::Nearest {
        let (pc, mc) = ((a * cl - b * s).value(), (a * cl + b * s).value());
        // Both pairs have the same length: the larger cosine is the larger
        // first component.
        if s.value() != 0.0 {
            *branch = if pc >= mc { Branch::Plus } else { Branch::Minus };
        }
    }
    let x = match *branch {
        Branch::Plus => unit_pair(a * cl - b * s, b * cl + a * s),
        Branch::Minus => unit_pair(a * cl + b * s, b * cl - a * s),
    };
    *last = x.1.value();
    Ok(x)
}

/// The circle a point `at` traces turning about the line (`pivot`, unit
/// `axis`): its centre (the foot of `at` on the axis), normal and radius,
/// in the order [`Circle::new`] takes them.
#[inline]
pub fn circle_about<T: Real>(pivot: Vec3<T>, axis: Vec3<T>, at: Vec3<T>) -> (Vec3<T>, Vec3<T>, T) {
    let centre = add(pivot, scale(axis, dot(sub(at, pivot), axis)));
    (centre, axis, norm(sub(at, centre)))
}
