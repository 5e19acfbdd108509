//! Reading planar frames: marker positions, each joint's, constraint's and
//! input's residual (a gear pair's in `gears`), and (`kinematics`) a
//! frame's rates and transmission angles.

mod gears;
pub mod kinematics;

use crate::model::planar::slots::Shape;
use crate::model::{ConstraintKind, InputKind, JointKind, MarkerId, Mechanism};
use dofplan_runtime::planar::{Point, Pose};

/// World position of a marker.
pub fn marker_at(m: &Mechanism, poses: &[Pose], id: MarkerId) -> Point {
    poses[id.body].world(m.marker(id).at)
}

/// Every marker's world position, keyed "body.marker", in file order.
pub fn marker_positions(m: &Mechanism, poses: &[Pose]) -> Vec<(String, Point)> {
    m.all_markers()
        .map(|id| (m.marker_name(id), marker_at(m, poses, id)))
        .collect()
}

/// How far a joint, constraint or input is from holding.
#[derive(Clone, Debug, PartialEq)]
pub struct Residual {
    /// "joint A", "constraint c", "input theta".
    pub name: String,
    /// The violation as a length: a gap between points, a distance off a
    /// line, or an angle error times the mechanism's size.
    pub value: f64,
}

fn dist(a: Point, b: Point) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// The distance of `p` from the line through `a` along unit `d`, and the
/// position of its foot along the line.
fn off_line(a: Point, d: Point, p: Point) -> (f64, f64) {
    let v = [p[0] - a[0], p[1] - a[1]];
    ((v[0] * d[1] - v[1] * d[0]).abs(), v[0] * d[0] + v[1] * d[1])
}

/// Relative rotation angle (radians) of body `b` with respect to `a`.
fn relative_angle(poses: &[Pose], a: usize, b: usize) -> f64 {
    let r = poses[a].rot.inverse().then(poses[b].rot);
    r.s.atan2(r.c)
}

fn wrap(angle: f64) -> f64 {
    let t = std::f64::consts::TAU;
    (angle + std::f64::consts::PI).rem_euclid(t) - std::f64::consts::PI
}

/// The residual of every joint, constraint and input at `poses` for
/// `inputs`. Computed from the model alone (not from the plan), so it checks
/// a plan independently of how the plan placed the bodies.
pub fn residuals(m: &Mechanism, poses: &[Pose], inputs: &[f64]) -> Vec<Residual> {
    let mut out = Vec::new();
    each_residual(m, poses, inputs, m.size(), |what, name, value| {
        out.push(Residual {
            name: format!("{what} {name}"),
            value,
        });
    });
    out
}

/// Each residual of [`residuals`] handed to `visit` with what it is
/// ("joint", "input", "constraint") and its name, in the same order: a
/// caller that wants only the values builds no names.
fn each_residual(
    m: &Mechanism,
    poses: &[Pose],
    inputs: &[f64],
    size: f64,
    mut visit: impl FnMut(&'static str, &str, f64),
) {
    let at = |id: MarkerId| marker_at(m, poses, id);
    let line = |id: MarkerId| {
        let d = m
            .marker(id)
            .unit_dir()
            .expect("validated: line markers carry a dir");
        (at(id), poses[id.body].world_dir(d))
    };
    for (ji, j) in m.joints.iter().enumerate() {
        let [a, b] = j.markers;
        let value = match j.kind {
            JointKind::Revolute => dist(at(a), at(b)),
            JointKind::Prismatic => {
                let (p, d) = line(a);
                let (off, _) = off_line(p, d, at(b));
                off.max(relative_angle(poses, a.body, b.body).abs() * size)
            }
        };
        visit("joint", &j.name, value);
        if let Some(k) = m.inputs.iter().position(|i| i.joint == ji) {
            let value = match m.inputs[k].kind {
                // Reduced modulo 360 first (exact), as `Rot::from_degrees`
                // does: a huge angle in radians has lost its turn.
                InputKind::Angle => {
                    wrap(relative_angle(poses, a.body, b.body) - (inputs[k] % 360.0).to_radians()).abs()
                        * size
                }
                InputKind::Slide => {
                    let (p, d) = line(a);
                    let (_, along) = off_line(p, d, at(b));
                    let drawn = off_line(m.marker(a).at, m.marker(a).unit_dir().unwrap(), m.marker(b).at).1;
                    (along - drawn - inputs[k]).abs()
                }
            };
            visit("input", &m.inputs[k].name, value);
        }
    }
    // A pin in a slot: on the slot's line or circle (its ends are limits,
    // which the plan checks).
    for slot in &m.slots {
        let [s, pin] = slot.markers;
        let off = match slot.shape {
            Shape::Straight => {
                let (p, d) = line(s);
                off_line(p, d, at(pin)).0
            }
            Shape::Arc { radius } => (dist(at(s), at(pin)) - radius).abs(),
        };
        visit("joint", &slot.name, off);
    }
    // A gear pair: rolling without slip, on the turns the inputs give.
    if !m.gears.is_empty() {
        let turns = gears::turns(m, inputs);
        for gear in &m.gears {
            visit("joint", &gear.name, gears::residual(m, gear, poses, &turns));
        }
    }
    for c in &m.constraints {
        let [a, b] = c.markers;
        let value = match c.kind {
            ConstraintKind::Coincident => dist(at(a), at(b)),
            ConstraintKind::InLine => {
                let (p, d) = line(a);
                off_line(p, d, at(b)).0
            }
            ConstraintKind::Offset => relative_angle(poses, a.body, b.body).abs() * size,
        };
        visit("constraint", &c.name, value);
    }
}

/// The largest residual, relative to the mechanism's size; NaN if any is
/// NaN (`f64::max` alone would drop it, and a NaN pose would pass a check).
pub fn max_relative_residual(m: &Mechanism, poses: &[Pose], inputs: &[f64]) -> f64 {
    max_relative_residual_at(m, m.size(), poses, inputs)
}

/// [`max_relative_residual`] for a mechanism of size `size` (its
/// [`Mechanism::size`], which a caller checking many frames computes once).
pub fn max_relative_residual_at(m: &Mechanism, size: f64, poses: &[Pose], inputs: &[f64]) -> f64 {
    let mut worst = 0.0_f64;
    each_residual(m, poses, inputs, size, |_, _, value| {
        let r = value / size;
        worst = if worst.is_nan() || r.is_nan() {
            f64::NAN
        } else {
            worst.max(r)
        };
    });
    worst
}
