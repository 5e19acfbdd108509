//! Gear pairs drawn: each gear's pitch circle with a radial tick that
//! turns with it (so its rotation shows), and a rack's pitch line with
//! tick marks that slide with it.

use dofplan_runtime::planar::{Point, Pose};
use svg::node::element::{Circle, Group};

use crate::model::planar::gears::{Gear, GearKind};
use crate::model::Mechanism;
use crate::render::style::{colour_of, line, num};
use crate::render::view::{finite, BBox, View};

/// Tick marks along a rack's pitch line per pinion turn (one per 30°).
const RACK_TICKS_PER_TURN: f64 = 12.0;

/// One pitch circle: (body, centre in the body's local coordinates,
/// radius, the tick's local direction).
type Pitch = (usize, Point, f64, Point);

fn unit(v: Point) -> Point {
    let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
    if n > 0.0 {
        [v[0] / n, v[1] / n]
    } else {
        [1.0, 0.0]
    }
}

/// The pitch circles of a gear pair (one for a rack and pinion: the
/// pinion's). Each tick points, as drawn, at the other pivot (the pitch
/// point's side).
fn pitch_circles(g: &Gear) -> Vec<Pitch> {
    let [a, b] = g.bodies;
    let [ca, cb] = g.centres;
    let towards = unit([cb[0] - ca[0], cb[1] - ca[1]]);
    match g.kind {
        GearKind::Gear { radii, .. } => vec![
            (a, ca, radii[0], towards),
            (b, cb, radii[1], [-towards[0], -towards[1]]),
        ],
        GearKind::RackPinion {
            radius, dir, side, ..
        } => {
            vec![(a, ca, radius, [-side * dir[1], side * dir[0]])]
        }
    }
}

/// A rack's pitch line in its own (drawn) coordinates: the point of it
/// nearest the pinion's pivot, and its direction.
fn pitch_line(g: &Gear) -> Option<(Point, Point)> {
    let GearKind::RackPinion {
        radius, dir, side, ..
    } = g.kind
    else {
        return None;
    };
    let c = g.centres[0];
    let n = [-side * dir[1], side * dir[0]];
    Some(([c[0] + radius * n[0], c[1] + radius * n[1]], dir))
}

/// How far a rack's pitch line is drawn either side of the point nearest
/// the pinion: the rack's markers' extent along it, and at least a turn of
/// the pinion's pitch circle.
fn rack_extent(m: &Mechanism, g: &Gear, at: Point, dir: Point) -> (f64, f64) {
    let GearKind::RackPinion { radius, .. } = g.kind else {
        return (0.0, 0.0);
    };
    let along = |p: Point| (p[0] - at[0]) * dir[0] + (p[1] - at[1]) * dir[1];
    let body = &m.bodies[g.bodies[1]];
    let (lo, hi) = (body.markers.iter())
        .map(|mk| along(mk.at))
        .fold((-radius, radius), |(lo, hi), s| (lo.min(s), hi.max(s)));
    (lo - 0.5 * radius, hi + 0.5 * radius)
}

/// Every gear pair's pitch circles and racks' pitch lines at `poses`, into
/// the picture's box (they reach past the markers).
pub(super) fn extend_box(m: &Mechanism, poses: &[Pose], bbox: &mut BBox) {
    for g in &m.gears {
        for (body, centre, r, _) in pitch_circles(g) {
            let c = poses[body].world(centre);
            if finite(c) {
                bbox.add([c[0] - r, c[1] - r]);
                bbox.add([c[0] + r, c[1] + r]);
            }
        }
        if let Some((at, dir)) = pitch_line(g) {
            let (lo, hi) = rack_extent(m, g, at, dir);
            for s in [lo, hi] {
                let p = poses[g.bodies[1]].world([at[0] + s * dir[0], at[1] + s * dir[1]]);
                if finite(p) {
                    bbox.add(p);
                }
            }
        }
    }
}

/// The gear pairs of one pose, in their bodies' colours, lines `k` times
/// the full width (the pose's detail).
pub(super) fn draw(m: &Mechanism, poses: &[Pose], view: &View, k: f64) -> Group {
    let body_colour = |m: &Mechanism, b: usize| colour_of(&m.bodies, b);
    let mut group = Group::new().set("class", "gears");
    let width = num(k * 1.5);
    for g in &m.gears {
        let mut pair = Group::new()
            .set("class", "gear")
            .set("data-gear", g.name.as_str());
        for (body, centre, r, tick) in pitch_circles(g) {
            let pose = &poses[body];
            let c = pose.world(centre);
            let edge = pose.world([centre[0] + r * tick[0], centre[1] + r * tick[1]]);
            if !finite(c) || !finite(edge) {
                continue;
            }
            let colour = body_colour(m, body);
            let q = view.px(c);
            pair = pair
                .add(
                    Circle::new()
                        .set("cx", num(q[0]))
                        .set("cy", num(q[1]))
                        .set("r", num(r * view.scale))
                        .set("fill", "none")
                        .set("stroke", colour)
                        .set("stroke-width", width.clone())
                        .set("stroke-dasharray", "6 3")
                        .set("data-body", m.bodies[body].name.as_str()),
                )
                .add(
                    line(q, view.px(edge))
                        .set("stroke", colour)
                        .set("stroke-width", width.clone()),
                );
        }
        if let Some((at, dir)) = pitch_line(g) {
            let rack = g.bodies[1];
            let pose = &poses[rack];
            let colour = body_colour(m, rack);
            let (lo, hi) = rack_extent(m, g, at, dir);
            let point = |s: f64| pose.world([at[0] + s * dir[0], at[1] + s * dir[1]]);
            let (a, b) = (point(lo), point(hi));
            if finite(a) && finite(b) {
                pair = pair.add(
                    line(view.px(a), view.px(b))
                        .set("stroke", colour)
                        .set("stroke-width", width.clone())
                        .set("stroke-dasharray", "6 3")
                        .set("data-body", m.bodies[rack].name.as_str()),
                );
                // Ticks a pitch step apart, on the rack's side of the line.
                let GearKind::RackPinion { radius, side, .. } = g.kind else {
                    unreachable!("a pitch line is a rack's")
                };
                let step = std::f64::consts::TAU * radius / RACK_TICKS_PER_TURN;
                let out = [-side * dir[1], side * dir[0]];
                let depth = 0.15 * radius;
                let first = (lo / step).ceil() as i64;
                let last = (hi / step).floor() as i64;
                for k in first..=last {
                    let s = k as f64 * step;
                    let p = [at[0] + s * dir[0], at[1] + s * dir[1]];
                    let (p0, p1) = (
                        pose.world(p),
                        pose.world([p[0] + depth * out[0], p[1] + depth * out[1]]),
                    );
                    if finite(p0) && finite(p1) {
                        pair = pair.add(
                            line(view.px(p0), view.px(p1))
                                .set("stroke", colour)
                                .set("stroke-width", width.clone()),
                        );
                    }
                }
            }
        }
        group = group.add(pair);
    }
    group
}
