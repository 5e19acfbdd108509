//! The drag target: the path the target was pulled along and where it
//! ended, so a drag picture shows where the user pulled as well as where the
//! marker went.

use dofplan_runtime::planar::Point;
use svg::node::element::{Circle, Group, Path, Polyline};

use crate::render::style::{line, num, points, TARGET_COLOUR};
use crate::render::trace::THIN_PX;
use crate::render::view::{dist, View};

/// The target's path (dashed), the final target (a ring with a cross) and,
/// when the dragged marker stopped short of it, a dotted line from where
/// the marker ended (`reached`, world) to the target.
pub(super) fn draw(targets: &[Point], reached: Option<Point>, view: &View) -> Group {
    let mut g = Group::new().set("class", "drag-target");
    let mut path: Vec<Point> = Vec::new();
    for &t in targets {
        let q = view.px(t);
        if !(q[0].is_finite() && q[1].is_finite()) {
            continue;
        }
        if path.last().is_none_or(|l| dist(*l, q) >= THIN_PX) {
            path.push(q);
        }
    }
    if path.len() >= 2 {
        g = g.add(
            Polyline::new()
                .set("class", "target-path")
                .set("points", points(&path))
                .set("fill", "none")
                .set("stroke", TARGET_COLOUR)
                .set("stroke-width", 1.25)
                .set("stroke-dasharray", "2 4")
                .set("stroke-linecap", "round"),
        );
    }
    let Some(&last) = targets
        .iter()
        .rev()
        .find(|t| t[0].is_finite() && t[1].is_finite())
    else {
        return g;
    };
    let q = view.px(last);
    if let Some(r) = reached.map(|r| view.px(r)) {
        if dist(r, q) > 3.0 {
            g = g.add(
                line(r, q)
                    .set("class", "target-gap")
                    .set("stroke", TARGET_COLOUR)
                    .set("stroke-width", 1)
                    .set("stroke-dasharray", "1 3"),
            );
        }
    }
    let (x, y) = (q[0], q[1]);
    let cross = format!(
        "M{} {}H{}M{} {}V{}",
        num(x - 11.0),
        num(y),
        num(x + 11.0),
        num(x),
        num(y - 11.0),
        num(y + 11.0)
    );
    g.add(
        Group::new()
            .set("class", "target")
            .set("data-x", num(last[0]))
            .set("data-y", num(last[1]))
            .set("fill", "none")
            .set("stroke", TARGET_COLOUR)
            .set("stroke-width", 1.5)
            .add(Circle::new().set("cx", num(x)).set("cy", num(y)).set("r", 6.5))
            .add(Path::new().set("d", cross)),
    )
}
