//! Slots drawn: each slot as a rounded channel on its body, along its
//! centre line from end to end (straight, or an arc), that the pin runs in.

use dofplan_runtime::planar::Pose;
use svg::node::element::{Group, Polyline};
use svg::Node;

use crate::model::Mechanism;
use crate::render::style::{colour_of, line, num, points};
use crate::render::view::{finite, BBox, View};

/// Every slot's centre line at `poses`, into the picture's box.
pub(super) fn extend_box(m: &Mechanism, poses: &[Pose], bbox: &mut BBox) {
    for slot in &m.slots {
        let body = slot.markers[0].body;
        for p in slot.centre_line(m) {
            let w = poses[body].world(p);
            if finite(w) {
                bbox.add(w);
            }
        }
    }
}

/// The slots of one pose: a channel in the slotted body's colour, lines
/// `k` times the full width.
pub(super) fn draw(m: &Mechanism, poses: &[Pose], view: &View, k: f64) -> Group {
    let mut group = Group::new().set("class", "slots");
    for slot in &m.slots {
        let body = slot.markers[0].body;
        let world: Vec<_> = slot
            .centre_line(m)
            .into_iter()
            .map(|p| poses[body].world(p))
            .collect();
        if !world.iter().all(|&w| finite(w)) {
            continue;
        }
        let page: Vec<_> = world.iter().map(|&w| view.px(w)).collect();
        // A channel: a wide stroke in the body's colour with a white core,
        // both with round ends.
        let stroke = |colour: &str, width: f64| -> Box<dyn Node> {
            if let [a, b] = page[..] {
                Box::new(
                    line(a, b)
                        .set("stroke", colour)
                        .set("stroke-width", num(width * k))
                        .set("stroke-linecap", "round"),
                )
            } else {
                Box::new(
                    Polyline::new()
                        .set("points", points(&page))
                        .set("fill", "none")
                        .set("stroke", colour)
                        .set("stroke-width", num(width * k))
                        .set("stroke-linecap", "round")
                        .set("stroke-linejoin", "round"),
                )
            }
        };
        group = group.add(
            Group::new()
                .set("class", "slot")
                .set("data-slot", slot.name.as_str())
                .add(stroke(colour_of(&m.bodies, body), 9.0))
                .add(stroke("#ffffff", 5.0)),
        );
    }
    group
}
