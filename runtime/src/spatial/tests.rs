//! Tests of the spatial geometry: every root lies on both of its loci,
//! branch signs are the documented geometric ones and stay put along smooth
//! motions, misses break with the right kind and gap, and stretching returns
//! the closest point and records the gap.

use super::*;
use crate::frame::{Branch, BranchPolicy, BreakKind, Ctx};

/// A small deterministic generator (Knuth's MMIX LCG), so the tests need no
/// `rand` and always see the same inputs.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    fn point(&mut self, size: f64) -> Vec3 {
        [
            self.range(-size, size),
            self.range(-size, size),
            self.range(-size, size),
        ]
    }

    fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.point(1.0);
            let n = norm(v);
            if n > 0.1 && n <= 1.0 {
                return scale(v, 1.0 / n);
            }
        }
    }

    /// A unit vector perpendicular to the unit vector `n`.
    fn unit_perp(&mut self, n: Vec3) -> Vec3 {
        loop {
            let v = reject(self.unit(), n);
            if norm(v) > 0.1 {
                return unit(v);
            }
        }
    }

    fn rot(&mut self) -> Rot3 {
        let a = self.unit();
        let phi = self.range(-3.0, 3.0);
        Rot3::about_axis(a, phi.cos(), phi.sin())
    }

    fn pose(&mut self) -> Pose3 {
        Pose3 {
            rot: self.rot(),
            pos: self.point(10.0),
        }
    }
}

fn keep() -> Ctx {
    Ctx::new(BranchPolicy::Keep, false)
}

fn nearest() -> Ctx {
    Ctx::new(BranchPolicy::Nearest, false)
}

fn stretch() -> Ctx {
    Ctx::new(BranchPolicy::Keep, true)
}

fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
    dist(a, b) <= tol
}

#[track_caller]
fn assert_close(a: Vec3, b: Vec3, tol: f64) {
    assert!(close(a, b, tol), "{a:?} vs {b:?}: {:e}", dist(a, b));
}

/// The largest entry of `R·Rᵀ − I`.
fn orthonormality_error(r: &Rot3) -> f64 {
    let p = r.mul(&r.transpose());
    let mut worst = 0.0_f64;
    for i in 0..3 {
        for j in 0..3 {
            let e = if i == j { 1.0 } else { 0.0 };
            worst = worst.max((p.m[i][j] - e).abs());
        }
    }
    worst
}

fn det(r: &Rot3) -> f64 {
    dot(r.m[0], cross(r.m[1], r.m[2]))
}

fn poses_close(a: &Pose3, b: &Pose3, tol: f64) -> bool {
    (0..3).all(|i| close(a.rot.m[i], b.rot.m[i], tol)) && close(a.pos, b.pos, tol)
}

/// A circle in parts: centre, unit normal, radius (the arguments of
/// [`Circle::new`]).
type CircleParts = (Vec3, Vec3, f64);

/// A random circle through the point `x`.
fn circle_through(g: &mut Lcg, x: Vec3) -> CircleParts {
    let n = g.unit();
    let r = g.range(0.5, 5.0);
    let c = sub(x, scale(g.unit_perp(n), r));
    (c, n, r)
}

fn on_circle(x: Vec3, (c, n, r): CircleParts) -> f64 {
    circle_distance(x, c, n, r)
}

#[test]
fn vector_helpers() {
    assert_eq!(cross([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
    assert_eq!(unit([0.0; 3]), [0.0; 3]);
    assert_eq!(perpendicular([0.0; 3]), [0.0; 3]);
    assert_eq!(norm([3.0, 4.0, 12.0]), 13.0);
    assert_eq!(dist([1.0, 1.0, 1.0], [4.0, 5.0, 1.0]), 5.0);
    // Ties between the least aligned axes go to x, then y.
    assert_eq!(perpendicular([0.0, 0.0, 2.0]), [0.0, 1.0, 0.0]);
    assert_eq!(perpendicular([2.0, 0.0, 0.0]), [0.0, 0.0, 1.0]);
    let h = 0.5f64.sqrt();
    assert_close(perpendicular([1.0, 0.0, 1.0]), [-h, 0.0, h], 1e-15);
    let mut g = Lcg(1);
    for _ in 0..1000 {
        let v = g.point(5.0);
        let p = perpendicular(v);
        assert!(dot(p, v).abs() < 1e-14 * norm(v));
        assert!((norm(p) - 1.0).abs() < 1e-15);
    }
}

#[test]
fn about_axis_is_right_handed_and_exact_at_zero() {
    let r = Rot3::about_axis([0.0, 0.0, 1.0], 0.0, 1.0);
    assert_eq!(r.apply([1.0, 0.0, 0.0]), [0.0, 1.0, 0.0]);
    let r = Rot3::about_axis_degrees([1.0, 0.0, 0.0], 90.0);
    assert_eq!(r.apply([0.0, 1.0, 0.0]), [0.0, 0.0, 1.0]);
    let mut g = Lcg(2);
    for _ in 0..200 {
        let a = g.unit();
        assert_eq!(Rot3::about_axis(a, 1.0, 0.0), Rot3::IDENTITY);
        let deg = g.range(-720.0, 720.0);
        let r = Rot3::about_axis_degrees(a, deg);
        // Rodrigues' formula: a few ulps (minimal's quaternion does better).
        assert!(orthonormality_error(&r) < 3e-15);
        assert!((det(&r) - 1.0).abs() < 3e-15);
        // The axis is fixed; a perpendicular turns by the angle.
        assert_close(r.apply(a), a, 1e-15);
        let u = g.unit_perp(a);
        let (s, c) = deg.to_radians().sin_cos();
        assert_close(r.apply(u), add(scale(u, c), scale(cross(a, u), s)), 1e-14);
        // The inverse undoes it.
        let v = g.point(3.0);
        assert_close(r.apply_inverse(r.apply(v)), v, 1e-14);
        assert_close(r.transpose().apply(r.apply(v)), v, 1e-14);
    }
}

#[test]
fn then_and_mul_compose_in_the_documented_order() {
    let mut g = Lcg(3);
    for _ in 0..100 {
        let (a, b) = (g.rot(), g.rot());
        let v = g.point(2.0);
        assert_close(a.then(&b).apply(v), b.apply(a.apply(v)), 1e-14);
        assert_close(a.mul(&b).apply(v), a.apply(b.apply(v)), 1e-14);
    }
}

#[test]
fn minimal_rotation_maps_from_to_to() {
    let mut g = Lcg(4);
    for _ in 0..2000 {
        let from = scale(g.unit(), g.range(0.1, 10.0));
        let to = scale(g.unit(), g.range(0.1, 10.0));
        let r = Rot3::minimal(from, to);
        // A few ulps: Rodrigues' form from unnormalised vectors rounds to
        // 1.1e-15 at worst over these cases.
        assert!(
            orthonormality_error(&r) <= 2e-15,
            "{:e}",
            orthonormality_error(&r)
        );
        assert!((det(&r) - 1.0).abs() < 3e-15);
        assert_close(r.apply(unit(from)), unit(to), 2e-15);
        // Minimal: the axis from × to is fixed.
        let axis = cross(from, to);
        assert_close(r.apply(axis), axis, 1e-13 * norm(axis).max(1.0));
    }
}

#[test]
fn minimal_rotation_parallel_and_antiparallel() {
    let mut g = Lcg(5);
    for _ in 0..200 {
        let a = g.unit();
        assert_eq!(Rot3::minimal(a, scale(a, 3.0)), Rot3::IDENTITY);
        let r = Rot3::minimal(scale(a, 2.0), scale(a, -0.5));
        let p = perpendicular(scale(a, 2.0));
        assert_close(r.apply(a), scale(a, -1.0), 1e-15);
        assert_close(r.apply(p), p, 1e-15);
        assert!(orthonormality_error(&r) <= 1e-15);
        // Nearly opposite (1e-9 rad away): the half-way quaternion keeps the
        // map exact where 1 + cos would cancel.
        let b = unit(add(scale(a, -1.0), scale(g.unit_perp(a), 1e-9)));
        let r = Rot3::minimal(a, b);
        assert_close(r.apply(a), b, 2e-15);
        assert!(orthonormality_error(&r) <= 1e-15);
        // Nearly parallel.
        let b = unit(add(a, scale(g.unit_perp(a), 1e-9)));
        assert_close(Rot3::minimal(a, b).apply(a), b, 2e-15);
    }
    assert_eq!(Rot3::minimal([0.0; 3], [1.0, 0.0, 0.0]), Rot3::IDENTITY);
    // Exactly opposite: the half turn about perpendicular(x).
    let r = Rot3::minimal([1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]);
    let p = perpendicular([1.0, 0.0, 0.0]);
    assert_eq!(r.apply(p), p);
    assert_eq!(r.apply([1.0, 0.0, 0.0]), [-1.0, 0.0, 0.0]);
}

#[test]
fn orthonormalize_cleans_up_a_drifted_rotation() {
    let mut g = Lcg(6);
    for _ in 0..200 {
        let r = g.rot();
        let mut drift = r;
        for row in drift.m.iter_mut() {
            for x in row.iter_mut() {
                *x += g.range(-1e-6, 1e-6);
            }
        }
        let o = drift.orthonormalize();
        assert!(orthonormality_error(&o) <= 1e-15);
        assert!((det(&o) - 1.0).abs() < 2e-15);
        assert!((0..3).all(|i| close(o.m[i], r.m[i], 1e-5)));
    }
    assert_eq!(Rot3::IDENTITY.orthonormalize(), Rot3::IDENTITY);
    let o = Rot3 { m: [[0.0; 3]; 3] }.orthonormalize();
    assert!(orthonormality_error(&o) <= 1e-15);
}

#[test]
fn pose_compose_and_inverse_round_trip() {
    let mut g = Lcg(7);
    for _ in 0..500 {
        let (a, b) = (g.pose(), g.pose());
        let q = g.point(5.0);
        assert_close(a.compose(&b).world(q), a.world(b.world(q)), 1e-13);
        assert_close(a.inverse().world(a.world(q)), q, 1e-13);
        assert!(poses_close(&a.compose(&a.inverse()), &Pose3::IDENTITY, 1e-13));
        assert!(poses_close(&a.inverse().compose(&a), &Pose3::IDENTITY, 1e-13));
        assert!(poses_close(&a.inverse().inverse(), &a, 1e-13));
        assert_close(a.dir(q), sub(a.world(q), a.world([0.0; 3])), 1e-13);
    }
}

#[test]
fn rotate_about_moves_points_about_the_pivot() {
    let mut g = Lcg(8);
    for _ in 0..200 {
        let mut p = g.pose();
        let before = p;
        let (pivot, r) = (g.point(5.0), g.rot());
        p.rotate_about(pivot, &r);
        let q = g.point(5.0);
        let expect = add(pivot, r.apply(sub(before.world(q), pivot)));
        assert_close(p.world(q), expect, 1e-13);
        let v = g.point(1.0);
        p.translate(v);
        assert_close(p.world(q), add(expect, v), 1e-13);
    }
}

#[test]
fn joint_pose_turns_about_its_line_and_slides_along_it() {
    let mut g = Lcg(9);
    for _ in 0..200 {
        let (axis, at) = (g.unit(), g.point(10.0));
        assert_eq!(joint_pose(axis, at, 1.0, 0.0, 0.0), Pose3::IDENTITY);
        let phi = g.range(-3.0, 3.0);
        let (s, c) = phi.sin_cos();
        let slide = g.range(-2.0, 2.0);
        let j = joint_pose(axis, at, c, s, slide);
        // Points of the axis only slide.
        let on = add(at, scale(axis, g.range(-3.0, 3.0)));
        assert_close(j.world(on), add(on, scale(axis, slide)), 1e-13);
        // A point off the axis turns about it by phi.
        let u = scale(g.unit_perp(axis), g.range(0.5, 3.0));
        let turned = add(
            add(at, add(scale(u, c), scale(cross(axis, u), s))),
            scale(axis, slide),
        );
        assert_close(j.world(add(at, u)), turned, 1e-13);
        // Compared with building it from rotate_about: the same pose.
        let mut p = Pose3::IDENTITY;
        p.rotate_about(at, &Rot3::about_axis(axis, c, s));
        p.translate(scale(axis, slide));
        assert!(poses_close(&j, &p, 1e-13));
        // On a parent: the joint's line moves with the parent.
        let parent = g.pose();
        let child = parent.compose(&j);
        assert_close(
            child.world(on),
            add(parent.world(on), scale(parent.dir(axis), slide)),
            1e-12,
        );
    }
}

#[test]
fn place_actions() {
    let mut g = Lcg(10);
    for _ in 0..200 {
        let pivot = g.point(5.0);
        let marker = g.point(5.0);
        let target = g.point(5.0);
        // About a point, by directions and by points.
        let mut p = Pose3::IDENTITY;
        rotate_about_point(&mut p, pivot, sub(marker, pivot), sub(target, pivot));
        assert_close(p.world(pivot), pivot, 1e-13);
        assert_close(unit(sub(p.world(marker), pivot)), unit(sub(target, pivot)), 1e-14);
        let mut q = Pose3::IDENTITY;
        rotate_about_point_onto(&mut q, pivot, marker, target);
        assert!(poses_close(&p, &q, 0.0));

        // About an axis: the marker's perpendicular turns onto the target's.
        let axis = g.unit();
        let mut p = g.pose();
        let local = g.point(5.0);
        let from = p.world(local);
        rotate_about_axis_onto(&mut p, pivot, axis, from, target);
        let moved = p.world(local);
        // Same height along the axis and same distance from it as before...
        assert!((dot(sub(moved, pivot), axis) - dot(sub(from, pivot), axis)).abs() < 1e-12);
        let (rm, rf) = (reject(sub(moved, pivot), axis), reject(sub(from, pivot), axis));
        assert!((norm(rm) - norm(rf)).abs() < 1e-12);
        // ... and in the target's half-plane.
        assert_close(unit(rm), unit(reject(sub(target, pivot), axis)), 1e-13);
        // A point at the target's height and radius lands on it.
        let mut p = Pose3::IDENTITY;
        let u = g.unit_perp(axis);
        let t_at = add(pivot, add(scale(axis, 0.7), scale(u, 2.0)));
        let f_at = add(pivot, add(scale(axis, 0.7), scale(g.unit_perp(axis), 2.0)));
        rotate_about_axis_onto(&mut p, pivot, axis, f_at, t_at);
        assert_close(p.world(f_at), t_at, 1e-13);
        // By directions: the same rotation.
        let mut q = Pose3::IDENTITY;
        rotate_about_axis_dir(&mut q, pivot, axis, sub(f_at, pivot), sub(t_at, pivot));
        assert!(poses_close(&p, &q, 1e-15));
        // On the axis: no rotation.
        let mut p = Pose3::IDENTITY;
        rotate_about_axis_onto(&mut p, pivot, axis, add(pivot, scale(axis, 3.0)), t_at);
        assert_eq!(p, Pose3::IDENTITY);
        rotate_about_axis_dir(&mut p, pivot, axis, scale(axis, -1.0), [1.0, 2.0, 3.0]);
        assert_eq!(p, Pose3::IDENTITY);
        // By an angle.
        let mut p = Pose3::IDENTITY;
        rotate_about_axis_angle(&mut p, pivot, axis, 0.0, 1.0);
        assert_close(p.world(add(pivot, u)), add(pivot, cross(axis, u)), 1e-14);
        // Translating.
        let mut p = g.pose();
        let before = p.world(local);
        translate_onto(&mut p, before, target);
        assert_close(p.world(local), target, 1e-13);
    }
}

// ---------------------------------------------------------------- circles

#[test]
fn coplanar_circles_meet_on_both_sides() {
    let mut g = Lcg(11);
    for _ in 0..2000 {
        let n = g.unit();
        let x = g.point(5.0);
        let c1 = sub(x, scale(g.unit_perp(n), g.range(0.5, 5.0)));
        let c2 = sub(x, scale(g.unit_perp(n), g.range(0.5, 5.0)));
        let (r1, r2) = (dist(x, c1), dist(x, c2));
        if dist(c1, c2) < 0.1 {
            continue;
        }
        // The same plane, the normals a little different or opposite.
        let n2 = if g.next() < 0.5 { scale(n, -1.0) } else { n };
        let e = unit(sub(c2, c1));
        let mut last = [0.0; 3];
        let mut found = false;
        for b in [Branch::Plus, Branch::Minus] {
            let mut branch = b;
            let y = circle_circle(
                &mut keep(),
                0,
                Circle::new(c1, n, r1),
                Circle::new(c2, n2, r2),
                1e-9,
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert_eq!(branch, b);
            assert_eq!(last, y);
            assert!(on_circle(y, (c1, n, r1)) < 1e-12 && on_circle(y, (c2, n2, r2)) < 1e-12);
            // Branch + lies along n1 × e.
            let side = dot(sub(y, c1), cross(n, e));
            assert!(side * b.sign() >= -1e-12, "{b:?} side {side}");
            found |= close(y, x, 1e-9);
        }
        assert!(found, "the constructed point is one of the roots");
        let cand = circle_circle_candidates(Circle::new(c1, n, r1), Circle::new(c2, n2, r2), 1e-9);
        assert!(cand.coplanar && cand.count() == 2);
    }
}

#[test]
fn coplanar_circles_apart_break_or_stretch() {
    let z = [0.0, 0.0, 1.0];
    let mut b = Branch::Plus;
    let mut last = [0.0; 3];
    let e = circle_circle(
        &mut keep(),
        7,
        Circle::new([0.0; 3], z, 1.0),
        Circle::new([5.0, 0.0, 0.0], z, 1.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.step, e.kind), (7, BreakKind::CirclesApart));
    assert!((e.gap - 3.0).abs() < 1e-12);
    let mut s = stretch();
    let x = circle_circle(
        &mut s,
        7,
        Circle::new([0.0; 3], z, 1.0),
        Circle::new([5.0, 0.0, 0.0], z, 1.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(x, [2.5, 0.0, 0.0], 1e-12);
    assert_eq!(s.stretched, Some((7, 3.0)));
    // Nested.
    let e = circle_circle(
        &mut keep(),
        1,
        Circle::new([0.0; 3], z, 5.0),
        Circle::new([1.0, 0.0, 0.0], z, 1.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert!((e.gap - 3.0).abs() < 1e-12);
    // Parallel planes 0.5 apart: the in-plane roots exist, the planes miss.
    let e = circle_circle(
        &mut keep(),
        2,
        Circle::new([0.0; 3], z, 5.0),
        Circle::new([8.0, 0.0, 0.5], z, 5.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert!((e.gap - 0.5).abs() < 1e-12);
    let mut s = stretch();
    let x = circle_circle(
        &mut s,
        2,
        Circle::new([0.0; 3], z, 5.0),
        Circle::new([8.0, 0.0, 0.5], z, 5.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(x, [4.0, 3.0, 0.25], 1e-12);
    // Concentric: no isolated point, even with equal radii.
    let e = circle_circle(
        &mut keep(),
        3,
        Circle::new([0.0; 3], z, 2.0),
        Circle::new([0.0; 3], z, 2.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!(e.gap, 0.0);
    let mut last = [0.0, -7.0, 0.0];
    let x = circle_circle(
        &mut stretch(),
        3,
        Circle::new([0.0; 3], z, 2.0),
        Circle::new([0.0; 3], z, 3.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(x, [0.0, -2.0, 0.0], 1e-15);
}

#[test]
fn tangent_circles_are_accepted() {
    let z = [0.0, 0.0, 1.0];
    let mut b = Branch::Minus;
    let mut last = [0.0; 3];
    let mut c = nearest();
    // Externally tangent, with the distance off by round-off.
    let x = circle_circle(
        &mut c,
        0,
        Circle::new([0.0; 3], z, 1.0),
        Circle::new([0.1 + 0.2 + 1.7, 0.0, 0.0], z, 1.0 + 1e-16),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(x, [1.0, 0.0, 0.0], 1e-7);
    // Both roots coincide: the nearest policy keeps the branch.
    assert_eq!(b, Branch::Minus);
    let mut b = Branch::Plus;
    let x = line_sphere(
        &mut keep(),
        0,
        Line::new([-5.0, 2.0 * (1.0 + 1e-14), 0.0], [1.0, 0.0, 0.0]),
        Sphere::new([0.0; 3], 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(x, [0.0, 2.0, 0.0], 1e-12);
}

/// Two circles in different planes that meet at `x` only: both contain the
/// chord of their planes' common line from `x`, circle 1's ending at
/// `x + l1·t`, circle 2's at `x + l2·t`, `l2 − l1 = apart`.
fn touching_circles(g: &mut Lcg, x: Vec3, apart: f64) -> (CircleParts, CircleParts, Vec3) {
    let t = g.unit();
    let l1 = g.range(0.5, 4.0) * if g.next() < 0.5 { 1.0 } else { -1.0 };
    let l2 = l1 + apart;
    let mut circle = |l: f64| {
        let n = g.unit_perp(t);
        let mid = add(x, scale(t, 0.5 * l));
        let c = add(mid, scale(cross(n, t), g.range(-3.0, 3.0)));
        (c, n, dist(c, x))
    };
    let (k1, k2) = (circle(l1), circle(l2));
    (k1, k2, t)
}

#[test]
fn skew_circles_with_one_common_point() {
    let mut g = Lcg(12);
    let mut checked = 0;
    for i in 0..2000 {
        let x = g.point(5.0);
        // The other chord ends miss by a macroscopic amount or just barely.
        let apart = if i % 2 == 0 {
            g.range(0.5, 2.0)
        } else {
            g.range(1e-6, 1e-4)
        };
        let ((c1, n1, r1), (c2, n2, r2), _) = touching_circles(&mut g, x, apart);
        if norm(cross(n1, n2)) < 0.05 {
            continue;
        }
        checked += 1;
        let cand = circle_circle_candidates(Circle::new(c1, n1, r1), Circle::new(c2, n2, r2), 1e-9);
        assert!(!cand.coplanar);
        assert_eq!(cand.count(), 1, "{cand:?}");
        for policy in [BranchPolicy::Keep, BranchPolicy::Nearest] {
            for b in [Branch::Plus, Branch::Minus] {
                let mut branch = b;
                let mut last = g.point(10.0);
                let mut ctx = Ctx::new(policy, false);
                let y = circle_circle(
                    &mut ctx,
                    0,
                    Circle::new(c1, n1, r1),
                    Circle::new(c2, n2, r2),
                    1e-9,
                    Slot::new(&mut branch, &mut last),
                )
                .unwrap();
                assert_close(y, x, 1e-12);
                assert!(on_circle(y, (c1, n1, r1)) < 1e-12 && on_circle(y, (c2, n2, r2)) < 1e-12);
                assert_eq!(branch, b, "a single candidate leaves the branch alone");
                assert_eq!(last, y);
            }
        }
    }
    assert!(checked > 1000);
}

#[test]
fn skew_circles_that_miss_break_or_stretch() {
    let mut g = Lcg(13);
    for _ in 0..200 {
        let x = g.point(5.0);
        let ((c1, n1, r1), (c2, n2, r2), _) = touching_circles(&mut g, x, 1.0);
        if norm(cross(n1, n2)) < 0.05 {
            continue;
        }
        // Shrinking circle 2 about its centre opens the common point.
        let r2 = r2 * 0.9;
        let cand = circle_circle_candidates(Circle::new(c1, n1, r1), Circle::new(c2, n2, r2), 1e-9);
        let gap = cand.misses[0].min(cand.misses[1]);
        assert!(cand.count() == 0 && gap > 1e-9);
        let mut b = Branch::Plus;
        let mut last = [0.0; 3];
        let e = circle_circle(
            &mut keep(),
            4,
            Circle::new(c1, n1, r1),
            Circle::new(c2, n2, r2),
            1e-9,
            Slot::new(&mut b, &mut last),
        )
        .unwrap_err();
        assert_eq!((e.step, e.kind, e.gap), (4, BreakKind::CirclesApart, gap));
        let mut s = stretch();
        let y = circle_circle(
            &mut s,
            4,
            Circle::new(c1, n1, r1),
            Circle::new(c2, n2, r2),
            1e-9,
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        assert_eq!(s.stretched, Some((4, gap)));
        // The returned point misses by the gap.
        let miss = on_circle(y, (c1, n1, r1)) + on_circle(y, (c2, n2, r2));
        assert!((miss - gap).abs() < 1e-12);
        assert_eq!(last, y);
    }
    // Planes crossing in a line that misses both circles: the feet.
    let (z, x) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    let cand = circle_circle_candidates(
        Circle::new([0.0, 0.0, 0.0], z, 1.0),
        Circle::new([3.0, 0.0, 5.0], x, 1.0),
        1e-9,
    );
    assert_eq!(cand.count(), 0);
    let mut b = Branch::Plus;
    let mut last = [0.0; 3];
    let y = circle_circle(
        &mut stretch(),
        0,
        Circle::new([0.0; 3], z, 1.0),
        Circle::new([3.0, 0.0, 5.0], x, 1.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert!(y.iter().all(|v| v.is_finite()));
    assert!((y[0] - 3.0).abs() < 1e-15 && y[2].abs() < 1e-15);
}

/// Two circles cut from one sphere by two random planes.
fn spherical_pair(g: &mut Lcg, centre: Vec3, radius: f64) -> (CircleParts, CircleParts) {
    let mut cut = || {
        let n = g.unit();
        let h = g.range(-0.6, 0.6) * radius;
        (add(centre, scale(n, h)), n, (radius * radius - h * h).sqrt())
    };
    (cut(), cut())
}

#[test]
fn circles_on_one_sphere_have_two_branches() {
    let mut g = Lcg(14);
    let mut checked = 0;
    for _ in 0..3000 {
        let (o, rad) = (g.point(5.0), g.range(1.0, 5.0));
        let ((c1, n1, r1), (c2, n2, r2)) = spherical_pair(&mut g, o, rad);
        let cand = circle_circle_candidates(Circle::new(c1, n1, r1), Circle::new(c2, n2, r2), 1e-9);
        let t = unit(cross(n1, n2));
        // Keep well away from coplanarity and tangency, where the roots are
        // ill-conditioned: the circles meet where the planes' common line
        // meets the sphere, so the distance from o to that line decides.
        let cn = dot(n1, n2);
        let (h1, h2) = (dot(sub(c1, o), n1), dot(sub(c2, o), n2));
        let k = 1.0 - cn * cn;
        let (al, be) = ((h1 - cn * h2) / k, (h2 - cn * h1) / k);
        let to_line = norm(add(scale(n1, al), scale(n2, be)));
        if norm(cross(n1, n2)) < 0.05 || to_line > 0.95 * rad {
            continue;
        }
        checked += 1;
        assert_eq!(cand.count(), 2, "{cand:?}");
        let mut roots = [[0.0; 3]; 2];
        for (i, b) in [Branch::Plus, Branch::Minus].into_iter().enumerate() {
            let mut branch = b;
            let mut last = [0.0; 3];
            let y = circle_circle(
                &mut keep(),
                0,
                Circle::new(c1, n1, r1),
                Circle::new(c2, n2, r2),
                1e-9,
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!(on_circle(y, (c1, n1, r1)) < 1e-12 && on_circle(y, (c2, n2, r2)) < 1e-12);
            assert!((dist(y, o) - rad).abs() < 1e-12);
            roots[i] = y;
        }
        // Branch + is further along n1 × n2.
        assert!(dot(sub(roots[0], roots[1]), t) > 0.0);
        // Nearest takes the root nearest the last point and remembers it.
        let mut branch = Branch::Plus;
        let mut last = add(roots[1], scale(g.unit(), 0.01 * rad));
        let y = circle_circle(
            &mut nearest(),
            0,
            Circle::new(c1, n1, r1),
            Circle::new(c2, n2, r2),
            1e-9,
            Slot::new(&mut branch, &mut last),
        )
        .unwrap();
        assert_eq!((y, branch, last), (roots[1], Branch::Minus, roots[1]));
    }
    assert!(checked > 1000);
}

#[test]
fn branches_stay_continuous_along_a_sweep() {
    // A spherical four-bar's coupler point: circle 1 fixed, circle 2's
    // plane turning about an axis through the sphere's centre. Along the
    // sweep the kept root moves continuously, and the nearest policy never
    // changes the branch.
    let mut g = Lcg(15);
    let mut steps = 0;
    for _ in 0..20 {
        let (o, rad) = (g.point(3.0), g.range(1.0, 3.0));
        let n1 = g.unit();
        let (c1, r1) = (add(o, scale(n1, 0.2 * rad)), rad * (1.0f64 - 0.04).sqrt());
        let spin = g.unit();
        let n2_0 = unit(add(g.unit_perp(n1), scale(n1, 0.1)));
        for start in [Branch::Plus, Branch::Minus] {
            let mut kept = start;
            let mut near = start;
            let mut prev: Option<Vec3> = None;
            let mut last_near = [0.0; 3];
            for k in 0..400 {
                let a = 0.2 * (k as f64 / 400.0) * std::f64::consts::TAU;
                let n2 = Rot3::about_axis(spin, a.cos(), a.sin()).apply(n2_0);
                let (c2, r2) = (add(o, scale(n2, -0.1 * rad)), rad * (1.0f64 - 0.01).sqrt());
                let cand = circle_circle_candidates(Circle::new(c1, n1, r1), Circle::new(c2, n2, r2), 1e-9);
                if norm(cross(n1, n2)) < 0.1
                    || cand.count() != 2
                    || dist(cand.points[0], cand.points[1]) < 0.05 * rad
                {
                    break;
                }
                let mut scratch = [0.0; 3];
                let y = circle_circle(
                    &mut keep(),
                    0,
                    Circle::new(c1, n1, r1),
                    Circle::new(c2, n2, r2),
                    1e-9,
                    Slot::new(&mut kept, &mut scratch),
                )
                .unwrap();
                if let Some(p) = prev {
                    assert!(dist(p, y) < 0.1 * rad, "jump of {}", dist(p, y));
                } else {
                    last_near = y;
                }
                prev = Some(y);
                let z = circle_circle(
                    &mut nearest(),
                    0,
                    Circle::new(c1, n1, r1),
                    Circle::new(c2, n2, r2),
                    1e-9,
                    Slot::new(&mut near, &mut last_near),
                )
                .unwrap();
                assert_eq!((z, near), (y, start));
                steps += 1;
            }
            assert_eq!(kept, start);
        }
    }
    assert!(steps > 2000, "{steps} steps checked");
}

#[test]
fn coplanar_branch_is_continuous_along_a_sweep() {
    let z = [0.0, 0.0, 1.0];
    let mut b = Branch::Plus;
    let mut bn = Branch::Plus;
    let mut last = [0.0; 3];
    let mut last_n = [0.0, 3.0, 0.0];
    let mut prev: Option<Vec3> = None;
    for k in 0..=100 {
        // The second centre circles the first: the + root stays on the left
        // of the moving centre line.
        let a = k as f64 * 0.05;
        let c2 = [6.0 * a.cos(), 6.0 * a.sin(), 0.0];
        let y = circle_circle(
            &mut keep(),
            0,
            Circle::new([0.0; 3], z, 5.0),
            Circle::new(c2, z, 5.0),
            1e-9,
            Slot::new(&mut b, &mut last),
        )
        .unwrap();
        let yn = circle_circle(
            &mut nearest(),
            0,
            Circle::new([0.0; 3], z, 5.0),
            Circle::new(c2, z, 5.0),
            1e-9,
            Slot::new(&mut bn, &mut last_n),
        )
        .unwrap();
        assert_eq!((y, bn), (yn, Branch::Plus));
        assert!(cross(c2, y)[2] > 0.0);
        if let Some(p) = prev {
            assert!(dist(p, y) < 0.31);
        }
        prev = Some(y);
    }
}

// ---------------------------------------------------------------- spheres, lines, planes

#[test]
fn sphere_meets_circle() {
    let mut g = Lcg(16);
    for _ in 0..2000 {
        let x = g.point(5.0);
        let k = circle_through(&mut g, x);
        let cs = g.point(5.0);
        let rs = dist(cs, x);
        let (c, n, r) = k;
        let cp = sub(cs, scale(n, dot(sub(cs, c), n)));
        let e = unit(sub(cp, c));
        if norm(sub(cp, c)) < 0.1 {
            continue;
        }
        let mut found = false;
        for b in [Branch::Plus, Branch::Minus] {
            let mut branch = b;
            let mut last = [0.0; 3];
            let y = sphere_circle(
                &mut keep(),
                0,
                Sphere::new(cs, rs),
                Circle::new(c, n, r),
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!((dist(y, cs) - rs).abs() < 1e-12 && on_circle(y, k) < 1e-12);
            assert!(dot(sub(y, c), cross(n, e)) * b.sign() >= -1e-12);
            found |= close(y, x, 1e-8);
        }
        assert!(found);
    }
    // Too small and too large: the gap is the distance between the loci.
    let z = [0.0, 0.0, 1.0];
    let mut b = Branch::Plus;
    let mut last = [0.0; 3];
    let e = sphere_circle(
        &mut keep(),
        3,
        Sphere::new([3.0, 0.0, 0.0], 1.0),
        Circle::new([0.0; 3], z, 1.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.step, e.kind), (3, BreakKind::CirclesApart));
    assert!((e.gap - 1.0).abs() < 1e-15);
    let mut s = stretch();
    let y = sphere_circle(
        &mut s,
        3,
        Sphere::new([3.0, 0.0, 0.0], 1.0),
        Circle::new([0.0; 3], z, 1.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(y, [1.5, 0.0, 0.0], 1e-15);
    assert_eq!(s.stretched, Some((3, 1.0)));
    // Far above the plane, too large.
    let e = sphere_circle(
        &mut keep(),
        3,
        Sphere::new([0.0, 3.0, 4.0], 12.0),
        Circle::new([0.0; 3], z, 3.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert!((e.gap - (12.0 - 52.0f64.sqrt())).abs() < 1e-14);
    // Missing the plane altogether.
    let e = sphere_circle(
        &mut keep(),
        3,
        Sphere::new([0.0, 0.0, 4.0], 2.0),
        Circle::new([0.0; 3], z, 3.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert!((e.gap - 3.0).abs() < 1e-15);
}

#[test]
fn line_meets_sphere() {
    let mut g = Lcg(17);
    for _ in 0..2000 {
        let (p, d) = (g.point(5.0), g.unit());
        let x = add(p, scale(d, g.range(-5.0, 5.0)));
        let c = g.point(5.0);
        let r = dist(c, x);
        let foot = add(p, scale(d, dot(sub(c, p), d)));
        for b in [Branch::Plus, Branch::Minus] {
            let mut branch = b;
            let mut last = [0.0; 3];
            let y = line_sphere(
                &mut keep(),
                0,
                Line::new(p, d),
                Sphere::new(c, r),
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!((dist(y, c) - r).abs() < 1e-12);
            assert!(norm(cross(sub(y, p), d)) < 1e-12);
            assert!(dot(sub(y, foot), d) * b.sign() >= 0.0);
        }
    }
    let mut b = Branch::Plus;
    let mut last = [9.0, 0.0, 0.0];
    let mut c = nearest();
    let y = line_sphere(
        &mut c,
        0,
        Line::new([0.0; 3], [1.0, 0.0, 0.0]),
        Sphere::new([0.0; 3], 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_eq!((y, b), ([2.0, 0.0, 0.0], Branch::Plus));
    last = [-1.0, 0.0, 0.0];
    let y = line_sphere(
        &mut c,
        0,
        Line::new([0.0; 3], [1.0, 0.0, 0.0]),
        Sphere::new([0.0; 3], 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_eq!((y, b, last), ([-2.0, 0.0, 0.0], Branch::Minus, [-2.0, 0.0, 0.0]));
    // A miss.
    let e = line_sphere(
        &mut keep(),
        5,
        Line::new([0.0, 3.0, 0.0], [1.0, 0.0, 0.0]),
        Sphere::new([0.0; 3], 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.step, e.kind, e.gap), (5, BreakKind::LineMissesCircle, 1.0));
    let mut s = stretch();
    let y = line_sphere(
        &mut s,
        5,
        Line::new([0.0, 3.0, 0.0], [1.0, 0.0, 0.0]),
        Sphere::new([0.0; 3], 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_eq!(y, [0.0, 2.5, 0.0]);
    assert_eq!(s.stretched, Some((5, 1.0)));
}

#[test]
fn line_meets_circle() {
    let mut g = Lcg(18);
    for _ in 0..2000 {
        let x = g.point(5.0);
        let k = circle_through(&mut g, x);
        let (c, n, r) = k;
        // A line in the circle's plane through x.
        let d = g.unit_perp(n);
        let p = add(x, scale(d, g.range(-3.0, 3.0)));
        let foot = add(p, scale(d, dot(sub(c, p), d)));
        if dist(foot, c) > 0.98 * r {
            continue;
        }
        for b in [Branch::Plus, Branch::Minus] {
            let mut branch = b;
            let mut last = [0.0; 3];
            let y = line_circle(
                &mut keep(),
                0,
                Line::new(p, d),
                Circle::new(c, n, r),
                1e-9,
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!(on_circle(y, k) < 1e-12 && norm(cross(sub(y, p), d)) < 1e-12);
            assert!(dot(sub(y, foot), d) * b.sign() >= 0.0);
        }
        // A line crossing the plane at x: one point, the branch untouched.
        let d = g.unit();
        if dot(d, n).abs() < 0.1 {
            continue;
        }
        let p = add(x, scale(d, g.range(-3.0, 3.0)));
        let mut branch = Branch::Minus;
        let mut last = [0.0; 3];
        let mut ctx = nearest();
        let y = line_circle(
            &mut ctx,
            0,
            Line::new(p, d),
            Circle::new(c, n, r),
            1e-9,
            Slot::new(&mut branch, &mut last),
        )
        .unwrap();
        assert_close(y, x, 1e-12);
        assert_eq!((branch, last), (Branch::Minus, y));
        // Moved off the circle: a break whose gap is the distance.
        let q = add(p, scale(g.unit_perp(d), 0.1));
        let e = line_circle(
            &mut keep(),
            2,
            Line::new(q, d),
            Circle::new(c, n, r),
            1e-9,
            Slot::new(&mut branch, &mut last),
        )
        .unwrap_err();
        let xq = add(q, scale(d, dot(sub(c, q), n) / dot(d, n)));
        assert_eq!(e.kind, BreakKind::LineMissesCircle);
        assert!((e.gap - on_circle(xq, k)).abs() < 1e-12);
    }
    // A line parallel to the plane but above it.
    let z = [0.0, 0.0, 1.0];
    let mut b = Branch::Plus;
    let mut last = [0.0; 3];
    let e = line_circle(
        &mut keep(),
        1,
        Line::new([0.0, 0.0, 0.5], [1.0, 0.0, 0.0]),
        Circle::new([0.0; 3], z, 2.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.kind, e.gap), (BreakKind::LineMissesCircle, 0.5));
    let y = line_circle(
        &mut stretch(),
        1,
        Line::new([0.0, 0.0, 0.5], [1.0, 0.0, 0.0]),
        Circle::new([0.0; 3], z, 2.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_eq!(y, [2.0, 0.0, 0.25]);
    // In the plane, missing the circle.
    let e = line_circle(
        &mut keep(),
        1,
        Line::new([0.0, 3.0, 0.0], [1.0, 0.0, 0.0]),
        Circle::new([0.0; 3], z, 2.0),
        1e-9,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!(e.gap, 1.0);
}

#[test]
fn line_meets_plane() {
    let mut g = Lcg(19);
    for _ in 0..1000 {
        let (p, d, q, n) = (g.point(5.0), g.unit(), g.point(5.0), g.unit());
        if dot(d, n).abs() < 0.1 {
            continue;
        }
        let y = line_plane(&mut keep(), 0, Line::new(p, d), Plane::new(q, n)).unwrap();
        assert!(dot(sub(y, q), n).abs() < 1e-12 && norm(cross(sub(y, p), d)) < 1e-11);
    }
    let z = [0.0, 0.0, 1.0];
    let e = line_plane(
        &mut keep(),
        8,
        Line::new([0.0, 0.0, 2.0], [1.0, 0.0, 0.0]),
        Plane::new([0.0; 3], z),
    )
    .unwrap_err();
    assert_eq!((e.step, e.kind, e.gap), (8, BreakKind::ParallelLines, 2.0));
    let mut s = stretch();
    let y = line_plane(
        &mut s,
        8,
        Line::new([0.0, 0.0, 2.0], [1.0, 0.0, 0.0]),
        Plane::new([0.0; 3], z),
    )
    .unwrap();
    assert_eq!(y, [0.0, 0.0, 1.0]);
    assert_eq!(s.stretched, Some((8, 2.0)));
}

#[test]
fn plane_meets_circle() {
    let mut g = Lcg(20);
    for _ in 0..2000 {
        let x = g.point(5.0);
        let k = circle_through(&mut g, x);
        let (c, n, r) = k;
        let nq = g.unit();
        if norm(cross(nq, n)) < 0.1 {
            continue;
        }
        let t = cross(nq, n);
        for b in [Branch::Plus, Branch::Minus] {
            let mut branch = b;
            let mut last = [0.0; 3];
            let y = plane_circle(
                &mut keep(),
                0,
                Plane::new(x, nq),
                Circle::new(c, n, r),
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!(dot(sub(y, x), nq).abs() < 1e-12 && on_circle(y, k) < 1e-12);
            // The two roots differ along nq × n, + ahead.
            let mut other = match b {
                Branch::Plus => Branch::Minus,
                Branch::Minus => Branch::Plus,
            };
            let z = plane_circle(
                &mut keep(),
                0,
                Plane::new(x, nq),
                Circle::new(c, n, r),
                Slot::new(&mut other, &mut last),
            )
            .unwrap();
            assert!(dot(sub(y, z), t) * b.sign() >= -1e-12);
        }
    }
    let z = [0.0, 0.0, 1.0];
    let xn = [1.0, 0.0, 0.0];
    let mut b = Branch::Plus;
    let mut last = [0.0; 3];
    let y = plane_circle(
        &mut keep(),
        0,
        Plane::new([1.0, 0.0, 0.0], xn),
        Circle::new([0.0; 3], z, 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    // nq × n = x × z = −y: branch + has negative y.
    assert_close(y, [1.0, -3.0f64.sqrt(), 0.0], 1e-15);
    // A plane past the circle.
    let e = plane_circle(
        &mut keep(),
        6,
        Plane::new([3.0, 0.0, 0.0], xn),
        Circle::new([0.0; 3], z, 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.step, e.kind, e.gap), (6, BreakKind::LineMissesCircle, 1.0));
    let y = plane_circle(
        &mut stretch(),
        6,
        Plane::new([3.0, 0.0, 0.0], xn),
        Circle::new([0.0; 3], z, 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(y, [2.5, 0.0, 0.0], 1e-15);
    // Parallel to the circle's plane.
    let e = plane_circle(
        &mut keep(),
        6,
        Plane::new([0.0, 0.0, 1.0], z),
        Circle::new([0.0; 3], z, 2.0),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.kind, e.gap), (BreakKind::ParallelLines, 1.0));
}

// ---------------------------------------------------------------- directions and angles

#[test]
fn cones_meet() {
    let mut g = Lcg(21);
    for _ in 0..2000 {
        let v = g.unit();
        let (w1, w2) = (g.unit(), g.unit());
        if norm(cross(w1, w2)) < 0.05 {
            continue;
        }
        let (cos1, cos2) = (dot(v, w1), dot(v, w2));
        let m = cross(w1, w2);
        let mut roots = [[0.0; 3]; 2];
        for (i, b) in [Branch::Plus, Branch::Minus].into_iter().enumerate() {
            let mut branch = b;
            let mut last = [0.0; 3];
            let y = cone_cone(
                &mut keep(),
                0,
                Cone::new(w1, cos1),
                Cone::new(w2, cos2),
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!((norm(y) - 1.0).abs() < 1e-12);
            assert!((dot(y, w1) - cos1).abs() < 1e-12 && (dot(y, w2) - cos2).abs() < 1e-12);
            roots[i] = y;
        }
        assert!(dot(sub(roots[0], roots[1]), m) >= 0.0);
        assert!(close(roots[0], v, 1e-6) || close(roots[1], v, 1e-6));
    }
    // Axes 90° apart, cones of 30°: 30° apart.
    let (x, y) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    let c30 = 30.0f64.to_radians().cos();
    let mut b = Branch::Plus;
    let mut last = [0.0; 3];
    let e = cone_cone(
        &mut keep(),
        9,
        Cone::new(x, c30),
        Cone::new(y, c30),
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!((e.step, e.kind), (9, BreakKind::CirclesApart));
    assert!((e.gap - 30.0f64.to_radians()).abs() < 1e-15);
    let mut s = stretch();
    let v = cone_cone(
        &mut s,
        9,
        Cone::new(x, c30),
        Cone::new(y, c30),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    let h = 0.5f64.sqrt();
    assert_close(v, [h, h, 0.0], 1e-15);
    assert!(s.stretched.is_some());
    // Coaxial: no isolated root.
    assert!(cone_cone(
        &mut keep(),
        9,
        Cone::new(x, 0.5),
        Cone::new(x, 0.5),
        Slot::new(&mut b, &mut last)
    )
    .is_err());
    // Tangent cones (60° + 30° = 90°) meet at the one direction.
    let v = cone_cone(
        &mut keep(),
        9,
        Cone::new(x, 0.5),
        Cone::new(y, c30),
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_close(v, [0.5, c30, 0.0], 1e-7);
}

#[test]
fn rotation_meets_its_condition() {
    let mut g = Lcg(22);
    for _ in 0..2000 {
        let (axis, v, w) = (g.unit(), g.point(3.0), g.point(3.0));
        // A condition that is met: rotate v by a random angle first.
        let phi = g.range(-3.0, 3.0);
        let target = dot(Rot3::about_axis(axis, phi.cos(), phi.sin()).apply(v), w);
        let a = dot(reject(v, axis), w);
        let bb = dot(cross(axis, v), w);
        if (a * a + bb * bb).sqrt() < 0.1 {
            continue;
        }
        let phi0 = bb.atan2(a);
        let mut roots = [(0.0, 0.0); 2];
        for (i, b) in [Branch::Plus, Branch::Minus].into_iter().enumerate() {
            let mut branch = b;
            let mut last = 0.0;
            let (c, s) = rotation_to_condition(
                &mut keep(),
                0,
                axis,
                v,
                w,
                target,
                Slot::new(&mut branch, &mut last),
            )
            .unwrap();
            assert!((c * c + s * s - 1.0).abs() < 1e-15);
            let got = dot(Rot3::about_axis(axis, c, s).apply(v), w);
            assert!((got - target).abs() < 1e-12 * (1.0 + norm(v) * norm(w)));
            assert_eq!(last, s, "the record of the root is its sine");
            // Branch + is the root atan2(B, A) + acos(...), i.e. counter-
            // clockwise from atan2(B, A) by at most π.
            let off = (s.atan2(c) - phi0).rem_euclid(std::f64::consts::TAU);
            if b == Branch::Plus {
                assert!(off <= std::f64::consts::PI + 1e-9, "{off}");
            } else {
                assert!(off >= std::f64::consts::PI - 1e-9, "{off}");
            }
            roots[i] = (c, s);
        }
        // Nearest: the smaller turn.
        let mut branch = Branch::Plus;
        let mut last = 0.0;
        let r = rotation_to_condition(
            &mut nearest(),
            0,
            axis,
            v,
            w,
            target,
            Slot::new(&mut branch, &mut last),
        )
        .unwrap();
        let best = if roots[0].0 >= roots[1].0 { 0 } else { 1 };
        assert_eq!(r, roots[best]);
        assert_eq!(branch, [Branch::Plus, Branch::Minus][best]);
    }
    let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let mut b = Branch::Plus;
    let mut last = 0.0;
    // Turning x about z until it has 0.5 along y: atan2(B, A) = 90° and
    // acos(C/R) = 60°, so branch + is 150° and branch − is 30°.
    let (c, s) = rotation_to_condition(&mut keep(), 0, z, x, y, 0.5, Slot::new(&mut b, &mut last)).unwrap();
    assert!((c + 0.75f64.sqrt()).abs() < 1e-15 && (s - 0.5).abs() < 1e-15);
    b = Branch::Minus;
    let (c, s) = rotation_to_condition(&mut keep(), 0, z, x, y, 0.5, Slot::new(&mut b, &mut last)).unwrap();
    assert!((c - 0.75f64.sqrt()).abs() < 1e-15 && (s - 0.5).abs() < 1e-15);
    assert_eq!(last, s, "the record of the root is its sine");
    // Out of reach: y component 2 for a unit vector.
    let e = rotation_to_condition(&mut keep(), 4, z, x, y, 2.0, Slot::new(&mut b, &mut last)).unwrap_err();
    assert_eq!((e.step, e.kind, e.gap), (4, BreakKind::LineCannotReach, 1.0));
    let mut s = stretch();
    let r = rotation_to_condition(&mut s, 4, z, x, y, -2.0, Slot::new(&mut b, &mut last)).unwrap();
    assert!(r.0.abs() < 1e-15 && (r.1 + 1.0).abs() < 1e-15);
    assert_eq!(s.stretched, Some((4, 1.0)));
    // Tangent: exactly reachable at one angle.
    let r =
        rotation_to_condition(&mut keep(), 4, z, x, y, 1.0 + 1e-15, Slot::new(&mut b, &mut last)).unwrap();
    assert!(r.0.abs() < 1e-15 && (r.1 - 1.0).abs() < 1e-15);
    // Independent of the angle (v along the axis): identity when it holds,
    // a break when it does not.
    let r = rotation_to_condition(
        &mut keep(),
        4,
        z,
        z,
        [0.0, 1.0, 1.0],
        1.0,
        Slot::new(&mut b, &mut last),
    )
    .unwrap();
    assert_eq!((r, last), ((1.0, 0.0), 0.0));
    let e = rotation_to_condition(
        &mut keep(),
        4,
        z,
        z,
        [0.0, 1.0, 1.0],
        0.5,
        Slot::new(&mut b, &mut last),
    )
    .unwrap_err();
    assert_eq!(e.gap, 0.5);
}

/// A hinged body set outright lands where turning it from any pose about
/// its hinge lands, keeps its line fixed, and is exactly rigid. The
/// reference turn is Rodrigues' formula written out here, not the
/// runtime's.
#[test]
fn hinge_sets_the_pose_a_turn_about_the_line_reaches() {
    let mut g = Lcg(17);
    for _ in 0..200 {
        let (pivot, axis) = (g.point(5.0), g.unit());
        let (from, to) = (g.point(5.0), g.point(5.0));
        let mut set = Pose3::IDENTITY;
        hinge_onto(&mut set, pivot, axis, from, to);
        // Rigid: RᵀR = I to rounding, and the line stays where it is.
        let m = set.rot.then(&set.rot.transpose());
        for (i, row) in m.m.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-14);
            }
        }
        let on_line = add(pivot, scale(axis, 2.5));
        assert!(dist(set.world(on_line), on_line) < 1e-13);
        // `from` went onto the half-plane of `to`: same height along the
        // axis, perpendiculars parallel and pointing the same way.
        let f = set.world(from);
        let (uf, ut) = (reject(sub(f, pivot), axis), reject(sub(to, pivot), axis));
        assert!((dot(sub(f, pivot), axis) - dot(sub(from, pivot), axis)).abs() < 1e-12);
        assert!(norm(cross(uf, ut)) < 1e-12 * norm(uf) * norm(ut) + 1e-13);
        assert!(dot(uf, ut) > 0.0);
        // Rodrigues about the line by the angle measured here, applied to
        // a point of the body: the same place.
        let u0 = reject(sub(from, pivot), axis);
        let angle = dot(cross(u0, ut), axis).atan2(dot(u0, ut));
        let q = g.point(5.0);
        let v = sub(q, pivot);
        let (c, s) = (angle.cos(), angle.sin());
        let turned = add(
            add(scale(v, c), scale(cross(axis, v), s)),
            scale(axis, dot(axis, v) * (1.0 - c)),
        );
        assert!(dist(set.world(q), add(pivot, turned)) < 1e-11);
        // From a pose already turned about the line, the relative turn of
        // the plan reaches the same pose.
        let mut relative = Pose3::IDENTITY;
        rotate_about_axis_angle(&mut relative, pivot, axis, 0.3_f64.cos(), 0.3_f64.sin());
        let moved = relative.world(from);
        rotate_about_axis_onto(&mut relative, pivot, axis, moved, to);
        assert!(dist(relative.world(q), set.world(q)) < 1e-11);
    }
    // An angle input: 90° about z through (1, 0, 0) takes (2, 0, 0) to
    // (1, 1, 0) exactly.
    let mut p = Pose3::IDENTITY;
    hinge_degrees(&mut p, [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 90.0);
    assert_eq!(p.world([2.0, 0.0, 0.0]), [1.0, 1.0, 0.0]);
    // A point on the line has no angle: the pose is kept.
    let before = p;
    hinge_onto(
        &mut p,
        [0.0; 3],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 3.0],
        [1.0, 0.0, 0.0],
    );
    assert_eq!(p, before);
}

/// A jet rotation times one without rates (a body no step has turned yet
/// this frame) takes the short product; it gives the jets of the full
/// product, written out here on `Jet2`s entry by entry.
#[test]
fn product_by_a_still_rotation_is_the_full_jet_product() {
    use crate::scalar::Jet2;
    let t = Jet2::new(0.3, 0.7, -1.1);
    let (s, c) = t.sin_cos();
    let turning = Rot3::about_axis(cst::<Jet2>([0.0, 0.6, 0.8]), c, s);
    let still: Rot3<Jet2> = Rot3::cst(Rot3::about_axis([1.0, 0.0, 0.0], 0.2_f64.cos(), 0.2_f64.sin()));
    let short = turning.mul(&still);
    let (a, b) = (&turning.m, &still.m);
    for (i, row) in a.iter().enumerate() {
        for (j, x) in short.m[i].iter().enumerate() {
            let full = row[0] * b[0][j] + row[1] * b[1][j] + row[2] * b[2][j];
            assert_eq!(*x, full, "[{i}][{j}]");
        }
    }
    // And a rotation with rates on the right takes the full product.
    let both = still.mul(&turning);
    let full =
        still.m[1][0] * turning.m[0][2] + still.m[1][1] * turning.m[1][2] + still.m[1][2] * turning.m[2][2];
    assert_eq!(both.m[1][2], full);
}

/// An aligned turn between directions without rates leaves a jet pose as
/// it was, rates included; with rates on one direction the pose takes the
/// turn's rates (about the pivot), its values unchanged.
#[test]
fn aligned_turn_without_rates_leaves_the_pose() {
    use crate::scalar::Jet2;
    let t = Jet2::new(0.4, 1.3, 0.2);
    let (s, c) = t.sin_cos();
    let mut pose = Pose3::<Jet2>::cst(Pose3::IDENTITY);
    pose.rotate_about(
        cst([1.0, 2.0, 0.0]),
        &Rot3::about_axis(cst::<Jet2>([0.0, 0.0, 1.0]), c, s),
    );
    let before = pose;
    let (pivot, dir) = (pose.world([0.5, 0.0, 0.0]), cst([0.0, 0.6, 0.8]));
    place::rotate_about_point(&mut pose, pivot, dir, scale(dir, Jet2::cst(2.0)));
    assert_eq!(pose, before);
    // The same directions, the target now tilting: values kept, rates not.
    let tilting = [Jet2::cst(0.0), Jet2::new(0.6, 0.0, 0.0), Jet2::new(0.8, 0.5, 0.0)];
    place::rotate_about_point(&mut pose, pivot, dir, tilting);
    assert_eq!(pose.value(), before.value());
    assert_ne!(pose, before);
}

/// A hinge on a fixed line (its axis as plain numbers) turned by an angle
/// with rates leaves the axis's own direction without rates: exactly zero
/// for an axis along a coordinate axis (the versine's rates are minus the
/// cosine's, and the other products are by 0 and 1), so a later step sees
/// it still; rounding's worth for any other axis. A direction across the
/// axis turns at the angle's rate.
#[test]
fn a_hinge_leaves_its_axis_without_rates() {
    use crate::scalar::Jet2;
    for (axis, exact) in [
        ([0.0, 0.0, 1.0], true),
        ([0.0, 1.0, 0.0], true),
        (unit([0.3, -0.2, 0.9]), false),
    ] {
        let mut pose = Pose3::<Jet2>::cst(Pose3::IDENTITY);
        for t in [0.1_f64, 0.9, 2.5, -1.2] {
            place::hinge_degrees(
                &mut pose,
                [1.0, 2.0, 0.5],
                axis,
                Jet2::new(t.to_degrees(), 40.0, -3.0),
            );
            let along = pose.dir(axis);
            if exact {
                assert_eq!(rate_bits(along), 0, "{along:?}");
            } else {
                assert!(
                    along.iter().all(|x| x.d.abs() < 1e-15 && x.dd.abs() < 1e-15),
                    "{along:?}"
                );
            }
            let v = reject([1.0, 1.0, 0.0], axis);
            let across = pose.dir(v);
            let speed = across.iter().map(|x| x.d * x.d).sum::<f64>().sqrt();
            assert!((speed - 40f64.to_radians() * norm(v)).abs() < 1e-12, "{speed}");
        }
    }
}

/// sphere_circle with the circle's normal as plain numbers (a fixed hinge's,
/// as compiled plans pass it) gives the jet normal's root: the same values
/// bit for bit, the same rates to rounding.
#[test]
fn sphere_circle_takes_a_plain_normal() {
    use crate::scalar::Jet2;
    let t = Jet2::new(0.4, 1.0, 0.3);
    let cs = [Jet2::cst(0.5) + t, Jet2::cst(0.2), t * t];
    let (c, n, r) = ([1.0, 0.5, 0.2], unit([0.2, -0.1, 1.0]), 1.5);
    let run = |plain: bool| {
        let (mut last, mut b) = (cst([2.0, 0.5, 0.2]), Branch::Plus);
        let rs = Jet2::cst(1.8);
        if plain {
            locus::sphere_circle(
                &mut keep(),
                0,
                Sphere::new(cs, rs),
                Circle::new(cst(c), n, Jet2::cst(r)),
                Slot::new(&mut b, &mut last),
            )
        } else {
            locus::sphere_circle(
                &mut keep(),
                0,
                Sphere::new(cs, rs),
                Circle::new(cst(c), cst::<Jet2>(n), Jet2::cst(r)),
                Slot::new(&mut b, &mut last),
            )
        }
        .unwrap()
    };
    let (plain, jets) = (run(true), run(false));
    for k in 0..3 {
        assert_eq!(plain[k].v.to_bits(), jets[k].v.to_bits());
        assert!((plain[k].d - jets[k].d).abs() <= 1e-13 && (plain[k].dd - jets[k].dd).abs() <= 1e-12);
    }
    // On the sphere, rates included.
    let e = sub(plain, cs);
    let d2 = dot(e, e);
    assert!((d2.v - 1.8 * 1.8).abs() < 1e-12 && d2.d.abs() < 1e-12 && d2.dd.abs() < 1e-11);
}
