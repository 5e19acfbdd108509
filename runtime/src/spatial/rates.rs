//! Rates of spatial plans: [`Rates`](crate::rates::Rates) with every
//! body's [`Pose3`] on [`Jet2`]s. A pose's rates are its entries' derivatives: the velocity of
//! the local origin is `pos[i].d`, and the angular velocity ω is read from
//! `Ṙ = [ω]×·R` (for example as `ω = vee(Ṙ·Rᵀ)`).

use super::Pose3;
use crate::rates::{JetPose, RateError};
use crate::scalar::Jet2;

/// A spatial pose's version on jets, for [`Rates`](crate::rates::Rates).
impl JetPose for Pose3 {
    type Jets = Pose3<Jet2>;
}

/// `poses` if every rate in them is finite, else [`RateError::Singular`]
/// (a dead point): what a run of the spatial steps on jets returns.
pub fn checked3<P: AsRef<[Pose3<Jet2>]>>(poses: P) -> Result<P, RateError> {
    if poses.as_ref().iter().fold(0, |bits, p| bits | p.nonfinite_bits()) == 0 {
        Ok(poses)
    } else {
        Err(RateError::Singular)
    }
}

#[cfg(test)]
mod tests {
    use super::super::*;
    use crate::frame::{Branch, BranchPolicy, Ctx};
    use crate::planar::Degrees;
    use crate::scalar::{Jet2, Real};

    /// A point moving along `v` with the parameter: `a + t·v`.
    fn moving<T: Real>(t: T, a: Vec3, v: Vec3) -> Vec3<T> {
        [0, 1, 2].map(|k| T::cst(a[k]) + t.mul_f64(v[k]))
    }

    /// Each case, run on `f64` at t = 0 and t = ±h and on the jet
    /// (0, 1, 0): the jet's values are the `f64` run's bit for bit, and its
    /// derivatives are the central differences.
    fn agrees(name: &str, f: fn(f64) -> Vec<f64>, j: fn(Jet2) -> Vec<Jet2>) {
        let h = 1e-4;
        let (p, m, z) = (f(h), f(-h), f(0.0));
        let jets = j(Jet2::new(0.0, 1.0, 0.0));
        assert_eq!(jets.len(), z.len());
        for (k, x) in jets.iter().enumerate() {
            assert_eq!(x.v.to_bits(), z[k].to_bits(), "{name} [{k}]: value");
            let first = (p[k] - m[k]) / (2.0 * h);
            let second = (p[k] - 2.0 * z[k] + m[k]) / (h * h);
            assert!(
                (x.d - first).abs() < 1e-7 * (1.0 + first.abs()),
                "{name} [{k}]: {} vs {first}",
                x.d
            );
            assert!(
                (x.dd - second).abs() < 1e-4 * (1.0 + second.abs()),
                "{name} [{k}]: {} vs {second}",
                x.dd
            );
        }
    }

    fn ctx() -> Ctx {
        Ctx::new(BranchPolicy::Keep, false)
    }

    fn skew<T: Real>(t: T) -> Vec<T> {
        // Two circles on the unit sphere about the origin, in planes that
        // are not parallel; the second one's plane tilts with t.
        let n2 = unit(moving(t, [0.0, 0.6, 0.8], [0.3, 0.0, -0.1]));
        let (c1, n1) = (cst([0.0, 0.0, 0.5]), cst([0.0, 0.0, 1.0]));
        let r1 = T::cst(0.75_f64.sqrt());
        let c2 = scale(n2, T::cst(0.3));
        let r2 = T::cst(0.91_f64.sqrt());
        let mut last = cst([0.0; 3]);
        circle_circle(
            &mut ctx(),
            1,
            Circle::new(c1, n1, r1),
            Circle::new(c2, n2, r2),
            1e-9,
            Slot::new(&mut Branch::Plus, &mut last),
        )
        .unwrap()
        .to_vec()
    }

    fn coplanar<T: Real>(t: T) -> Vec<T> {
        let c2 = moving(t, [2.0, 0.5, 0.0], [0.2, -0.3, 0.0]);
        let n = cst([0.0, 0.0, 1.0]);
        let mut last = cst([0.0; 3]);
        circle_circle(
            &mut ctx(),
            1,
            Circle::new(cst([0.0; 3]), n, T::cst(1.5)),
            Circle::new(c2, n, T::cst(1.2)),
            1e-9,
            Slot::new(&mut Branch::Minus, &mut last),
        )
        .unwrap()
        .to_vec()
    }

    fn sphere<T: Real>(t: T) -> Vec<T> {
        let cs = moving(t, [0.5, 0.2, 0.7], [0.1, 0.4, -0.2]);
        let n = unit(moving(t, [0.1, 0.0, 1.0], [0.0, 0.2, 0.0]));
        let mut last = cst([0.0; 3]);
        sphere_circle(
            &mut ctx(),
            1,
            Sphere::new(cs, T::cst(1.3)),
            Circle::new(cst([0.0; 3]), n, T::cst(1.1)),
            Slot::new(&mut Branch::Plus, &mut last),
        )
        .unwrap()
        .to_vec()
    }

    fn line_and_circle<T: Real>(t: T) -> Vec<T> {
        let p = moving(t, [0.3, -2.0, 0.0], [0.5, 0.0, 0.0]);
        let d = unit(moving(t, [0.1, 1.0, 0.0], [0.0, 0.0, 0.0]));
        let mut last = cst([0.0; 3]);
        let (c, n) = (cst([0.0; 3]), cst([0.0, 0.0, 1.0]));
        let mut x = line_circle(
            &mut ctx(),
            1,
            Line::new(p, d),
            Circle::new(c, n, T::cst(1.0)),
            1e-9,
            Slot::new(&mut Branch::Plus, &mut last),
        )
        .unwrap()
        .to_vec();
        let mut last = cst([0.0; 3]);
        x.extend(
            line_sphere(
                &mut ctx(),
                2,
                Line::new(p, d),
                Sphere::new(cst([0.1, 0.2, 0.3]), T::cst(1.4)),
                Slot::new(&mut Branch::Minus, &mut last),
            )
            .unwrap(),
        );
        let q = moving(t, [0.0, 0.0, 0.2], [0.0, 0.0, 0.3]);
        let nq = unit(moving(t, [0.2, 0.1, 1.0], [0.1, 0.0, 0.0]));
        let mut last = cst([0.0; 3]);
        x.extend(
            plane_circle(
                &mut ctx(),
                3,
                Plane::new(q, nq),
                Circle::new(cst([0.1; 3]), unit(cst([1.0, 0.2, 0.1])), T::cst(0.9)),
                Slot::new(&mut Branch::Plus, &mut last),
            )
            .unwrap(),
        );
        x
    }

    fn cones_and_turns<T: Degrees>(t: T) -> Vec<T> {
        let w1 = unit(moving(t, [1.0, 0.0, 0.2], [0.0, 0.3, 0.0]));
        let w2 = cst([0.0, 1.0, 0.0]);
        let mut last = cst([0.0; 3]);
        let mut x = cone_cone(
            &mut ctx(),
            1,
            Cone::new(w1, 0.3),
            Cone::new(w2, 0.4),
            Slot::new(&mut Branch::Plus, &mut last),
        )
        .unwrap()
        .to_vec();
        let axis = cst([0.0, 0.0, 1.0]);
        let v = moving(t, [1.0, 0.0, 0.3], [0.0, 0.5, 0.0]);
        let w = unit(moving(t, [0.5, 0.5, 0.5], [0.0, 0.0, 0.4]));
        let (c, s) = rotation_to_condition(
            &mut ctx(),
            2,
            axis,
            v,
            w,
            0.2,
            Slot::new(&mut Branch::Plus, &mut 0.0),
        )
        .unwrap();
        x.extend([c, s]);
        let x1 = cst([1.0, 0.0, 0.0]);
        let x2 = unit(moving(t, [0.6, 0.8, 0.0], [-0.2, 0.1, 0.0]));
        let (s, c) = twist_correction(axis, x1, x2, (T::cst(20.0) + t.mul_f64(30.0)).degrees_rot(), -1.0);
        x.extend([s, c]);
        x
    }

    fn pose_entries<T: Real>(p: &Pose3<T>) -> Vec<T> {
        p.rot.m.iter().flatten().chain(&p.pos).copied().collect()
    }

    fn placing<T: Real>(t: T) -> Vec<T> {
        let mut pose = Pose3::cst(Pose3 {
            rot: Rot3::about_axis([0.0, 0.6, 0.8], 0.8, 0.6),
            pos: [0.1, 0.2, 0.3],
        });
        let pivot = pose.world([1.0, 0.0, 0.0]);
        // Already aligned at t = 0 (the shortcut), turning with t.
        let from = pose.dir([0.0, 1.0, 0.0]);
        let to = add(from, scale(moving(t, [0.0; 3], [0.3, -0.2, 0.5]), t));
        let to = add(to, scale(cst([0.1, 0.4, 0.0]), t));
        rotate_about_point(&mut pose, pivot, from, to);
        let mut x = pose_entries(&pose);
        // A real turn, then a turn about an axis onto a point, a hinge and a
        // tilt.
        let from = pose.dir([1.0, 0.0, 0.0]);
        rotate_about_point(
            &mut pose,
            pivot,
            from,
            moving(t, [0.3, 1.0, 0.2], [0.5, 0.0, 0.1]),
        );
        let from = pose.world([0.0, 0.0, 0.0]);
        rotate_about_axis_onto(
            &mut pose,
            pivot,
            cst([0.0, 0.0, 1.0]),
            from,
            moving(t, [2.0, 1.0, 0.0], [0.0, 0.7, 0.0]),
        );
        x.extend(pose_entries(&pose));
        hinge_onto(
            &mut pose,
            [0.0, 0.0, 1.0],
            [0.6, 0.0, 0.8],
            [1.0, 0.0, 0.0],
            moving(t, [0.0, 1.0, 0.5], [0.4, 0.0, 0.0]),
        );
        let from = pose.dir([0.0, 0.0, 1.0]);
        tilt(
            &mut pose,
            cst([0.1; 3]),
            from,
            moving(t, [0.0, 1.0, 0.0], [0.3, 0.0, 0.3]),
            0.4,
        );
        x.extend(pose_entries(&pose));
        x
    }

    /// A body no step has turned yet (its directions without rates) turned
    /// onto a moving point: the minimal rotation from a still direction,
    /// composed with a still rotation.
    fn turning_from_still<T: Real>(t: T) -> Vec<T> {
        let mut pose = Pose3::cst(Pose3 {
            rot: Rot3::about_axis([0.0, 0.6, 0.8], 0.8, 0.6),
            pos: [0.1, 0.2, 0.3],
        });
        let pivot = pose.world([1.0, 0.0, 0.0]);
        let from = sub(pose.world([0.0, 2.0, 0.0]), pivot);
        rotate_about_point(
            &mut pose,
            pivot,
            from,
            moving(t, [0.3, 1.0, -0.2], [0.5, -0.4, 0.1]),
        );
        pose_entries(&pose)
    }

    #[test]
    fn jets_through_the_spatial_steps_are_their_derivatives() {
        agrees(
            "turning from still",
            turning_from_still::<f64>,
            turning_from_still::<Jet2>,
        );
        agrees("skew circles", skew::<f64>, skew::<Jet2>);
        agrees("coplanar circles", coplanar::<f64>, coplanar::<Jet2>);
        agrees("sphere and circle", sphere::<f64>, sphere::<Jet2>);
        agrees("lines", line_and_circle::<f64>, line_and_circle::<Jet2>);
        agrees("cones and turns", cones_and_turns::<f64>, cones_and_turns::<Jet2>);
        agrees("placing", placing::<f64>, placing::<Jet2>);
    }

    /// Two coplanar circles moving apart through tangency: at the tangent
    /// pose the rates are infinite (a dead point), not a huge number.
    #[test]
    fn a_tangency_is_a_dead_point() {
        let t = Jet2::new(0.0, 1.0, 0.0);
        let c2 = moving(t, [2.5, 0.0, 0.0], [1.0, 0.0, 0.0]);
        let n = cst([0.0, 0.0, 1.0]);
        let mut last = cst([0.0; 3]);
        let x = circle_circle(
            &mut Ctx::new(BranchPolicy::Keep, false),
            1,
            Circle::new(cst([0.0; 3]), n, Jet2::cst(1.5)),
            Circle::new(c2, n, Jet2::cst(1.0)),
            1e-9,
            Slot::new(&mut Branch::Plus, &mut last),
        )
        .unwrap();
        assert!((x[0].v - 1.5).abs() < 1e-12 && x[1].v.abs() < 1e-6);
        assert!(!x[1].finite(), "{x:?}");
    }
}
