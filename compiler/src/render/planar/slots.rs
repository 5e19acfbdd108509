//! Slots drawn: each straight slot as a rounded channel on its body, from
//! end to end, that the pin runs in.

use dofplan_runtime::planar::{Point, Pose};
use svg::node::element::Group;

use crate::model::Mechanism;
use crate::render::style::{colour_of, line, num};
use crate::render::view::{finite, BBox, View};

/// A slot's two ends in its body's local (drawn) coordinates.
fn ends_local(m: &Mechanism, k: usize) -> [Point; 2] {
    let slot = &m.slots[k];
    let marker = m.marker(slot.markers[0]);
    let d = marker.unit_dir().unwrap_or([1.0, 0.0]);
    slot.ends
        .map(|s| [marker.at[0] + s * d[0], marker.at[1] + s * d[1]])
}

/// Every slot's ends at `poses`, into the picture's box.
pub(super) fn extend_box(m: &Mechanism, poses: &[Pose], bbox: &mut BBox) {
    for k in 0..m.slots.len() {
        let body = m.slots[k].markers[0].body;
        for p in ends_local(m, k) {
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
    for (i, slot) in m.slots.iter().enumerate() {
        let body = slot.markers[0].body;
        let [a, b] = ends_local(m, i).map(|p| poses[body].world(p));
        if !finite(a) || !finite(b) {
            continue;
        }
        let (pa, pb) = (view.px(a), view.px(b));
        // A channel: a wide stroke in the body's colour with a white core,
        // both with round ends.
        group = group.add(
            Group::new()
                .set("class", "slot")
                .set("data-slot", slot.name.as_str())
                .add(
                    line(pa, pb)
                        .set("stroke", colour_of(&m.bodies, body))
                        .set("stroke-width", num(9.0 * k))
                        .set("stroke-linecap", "round"),
                )
                .add(
                    line(pa, pb)
                        .set("stroke", "#ffffff")
                        .set("stroke-width", num(5.0 * k))
                        .set("stroke-linecap", "round"),
                ),
        );
    }
    group
}
