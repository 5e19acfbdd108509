//! Gear pairs drawn: each gear's pitch circle with a radial tick that
//! turns with it (so its rotation shows), and a rack's pitch line with
//! tick marks that slide with it.

use dofplan_runtime::planar::{Point, Pose};
use svg::node::element::{Circle, Group};

use crate::model::planar::gears::{Gear, PitchCircle, PitchLine};
use crate::model::Mechanism;
use crate::render::style::{colour_of, line, num};
use crate::render::view::{finite, BBox, View};

/// Tick marks along a rack's pitch line per pinion turn (one per 30°).
const RACK_TICKS_PER_TURN: f64 = 12.0;

/// One pitch circle with its tick's direction in the body's drawn
/// coordinates: toward the other gear's pivot, or a pinion's toward its
/// rack.
fn ticked(g: &Gear) -> Vec<(PitchCircle, Point)> {
    let [ca, cb] = g.centres;
    let towards = unit([cb[0] - ca[0], cb[1] - ca[1]]);
    let line = g.pitch_line(std::iter::empty());
    (g.pitch_circles().into_iter().enumerate())
        .map(|(k, c)| {
            let tick = match (&line, k) {
                (Some(l), _) => l.normal,
                (None, 0) => towards,
                (None, _) => [-towards[0], -towards[1]],
            };
            (c, tick)
        })
        .collect()
}

fn unit(v: Point) -> Point {
    let n = (v[0] * v[0] + v[1] * v[1]).sqrt();
    if n > 0.0 {
        [v[0] / n, v[1] / n]
    } else {
        [1.0, 0.0]
    }
}

/// A rack's pitch line, reaching over the rack's markers.
fn rack_line(m: &Mechanism, g: &Gear) -> Option<PitchLine> {
    g.pitch_line(m.bodies[g.bodies[1]].markers.iter().map(|k| k.at))
}

/// Every gear pair's pitch circles and racks' pitch lines at `poses`, into
/// the picture's box (they reach past the markers).
pub(super) fn extend_box(m: &Mechanism, poses: &[Pose], bbox: &mut BBox) {
    for g in &m.gears {
        for c in g.pitch_circles() {
            let (w, r) = (poses[c.body].world(c.centre), c.radius);
            if finite(w) {
                bbox.add([w[0] - r, w[1] - r]);
                bbox.add([w[0] + r, w[1] + r]);
            }
        }
        if let Some(l) = rack_line(m, g) {
            for s in [l.from, l.to] {
                let p = poses[g.bodies[1]].world([l.at[0] + s * l.dir[0], l.at[1] + s * l.dir[1]]);
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
        for (
            PitchCircle {
                body,
                centre,
                radius: r,
            },
            tick,
        ) in ticked(g)
        {
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
        if let Some(PitchLine {
            at,
            dir,
            from: lo,
            to: hi,
            normal: out,
        }) = rack_line(m, g)
        {
            let rack = g.bodies[1];
            let pose = &poses[rack];
            let colour = body_colour(m, rack);
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
                let radius = g.pitch_circles()[0].radius;
                let step = std::f64::consts::TAU * radius / RACK_TICKS_PER_TURN;
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
