//! Marked points: a synthesis's targets, a ring on each, in either
//! dimension's picture (a spatial picture passes each view's projection of
//! them).

use dofplan_runtime::planar::Point;
use svg::node::element::{Circle, Group};

use crate::render::style::{num, TARGET_COLOUR};
use crate::render::view::View;

/// A ring on each of `points` (world coordinates of the plot `view`
/// shows); points off the page's number range are left out.
pub(super) fn marks(points: &[Point], view: &View) -> Group {
    let mut g = Group::new()
        .set("class", "target-points")
        .set("fill", "none")
        .set("stroke", TARGET_COLOUR)
        .set("stroke-width", 1.25);
    for &p in points {
        let q = view.px(p);
        if q[0].is_finite() && q[1].is_finite() {
            g = g.add(
                Circle::new()
                    .set("cx", num(q[0]))
                    .set("cy", num(q[1]))
                    .set("r", 4),
            );
        }
    }
    g
}
