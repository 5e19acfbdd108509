//! The marks of a spatial picture that the legend repeats: each joint
//! kind's symbol and the ground's hatching.

use dofplan_runtime::planar::Point;
use svg::node::element::{Circle, Group, Line, Path, Pattern, Polygon, Rectangle};

use crate::model::spatial::JointKind;
use crate::render::style::{line, num, points, GREY, GROUND_COLOUR, INK};

/// The id of the ground's hatching.
pub(in crate::render) const HATCH_ID: &str = "dofplan-ground-hatch";

/// The hatching that fills the ground.
pub(super) fn hatch_pattern() -> Pattern {
    Pattern::new()
        .set("id", HATCH_ID)
        .set("width", 6)
        .set("height", 6)
        .set("patternUnits", "userSpaceOnUse")
        .set("patternTransform", "rotate(45)")
        .add(
            Line::new()
                .set("x1", 0)
                .set("y1", 0)
                .set("x2", 0)
                .set("y2", 6)
                .set("stroke", GROUND_COLOUR)
                .set("stroke-width", 1.5),
        )
}

/// A joint's symbol around the page origin (placed by a `translate`), `k`
/// times its full size. `axis` is the joint axis on the page: its length
/// is the axis's foreshortening (1 in the page's plane, 0 seen end-on).
///
/// Revolute: a ring with a short line along the axis. Spherical: a filled
/// dot. Universal: a bold cross. Prismatic: a block along the axis;
/// cylindrical: the same with the axis through it; helical: the same with
/// a thread. Planar: a diamond. Fixed: a filled square.
pub(in crate::render) fn symbol(kind: JointKind, axis: Point, k: f64) -> Group {
    let l = axis[0].hypot(axis[1]);
    let (u, l) = if l.is_finite() && l > 1e-3 {
        ([axis[0] / l, axis[1] / l], l.min(1.0))
    } else {
        ([1.0, 0.0], 0.0)
    };
    let v = [-u[1], u[0]];
    let at = |a: f64, b: f64| [a * u[0] + b * v[0], a * u[1] + b * v[1]];
    let sw = num((1.5 * k).max(0.75));
    let g = Group::new();
    let axis_line = |half: f64| {
        line(at(-half, 0.0), at(half, 0.0))
            .set("stroke", INK)
            .set("stroke-width", sw.clone())
            .set("stroke-linecap", "round")
    };
    // A block along the axis: longer the more the axis lies in the page.
    let block = || {
        let (hl, hw) = ((4.0 + 5.0 * l) * k, 3.5 * k);
        Polygon::new()
            .set(
                "points",
                points(&[at(-hl, -hw), at(hl, -hw), at(hl, hw), at(-hl, hw)]),
            )
            .set("fill", "#ffffff")
            .set("stroke", INK)
            .set("stroke-width", sw.clone())
    };
    match kind {
        JointKind::Revolute => {
            let g = if l > 0.05 {
                g.add(axis_line((5.0 + 7.0 * l) * k))
            } else {
                g
            };
            g.add(
                Circle::new()
                    .set("r", num(4.5 * k))
                    .set("fill", "#ffffff")
                    .set("stroke", INK)
                    .set("stroke-width", sw),
            )
        }
        JointKind::Spherical => g.add(
            Circle::new()
                .set("r", num(4.5 * k))
                .set("fill", INK)
                .set("stroke", "#ffffff")
                .set("stroke-width", num(k)),
        ),
        JointKind::Universal => {
            let r = 4.5 * k;
            let d = format!(
                "M{} {}L{} {}M{} {}L{} {}",
                num(-r),
                num(-r),
                num(r),
                num(r),
                num(-r),
                num(r),
                num(r),
                num(-r)
            );
            g.add(
                Path::new()
                    .set("d", d.clone())
                    .set("stroke", "#ffffff")
                    .set("stroke-width", num(4.5 * k))
                    .set("stroke-linecap", "round"),
            )
            .add(
                Path::new()
                    .set("d", d)
                    .set("stroke", INK)
                    .set("stroke-width", num(2.2 * k))
                    .set("stroke-linecap", "round"),
            )
        }
        JointKind::Prismatic => g.add(block()),
        JointKind::Cylindrical => g.add(block()).add(axis_line((7.0 + 6.0 * l) * k)),
        JointKind::Helical => {
            let hl = (4.0 + 5.0 * l) * k;
            let hw = 3.5 * k;
            let thread = format!(
                "M{} {}L{} {}M{} {}L{} {}",
                num(at(-0.5 * hl, hw)[0]),
                num(at(-0.5 * hl, hw)[1]),
                num(at(0.0, -hw)[0]),
                num(at(0.0, -hw)[1]),
                num(at(0.0, hw)[0]),
                num(at(0.0, hw)[1]),
                num(at(0.5 * hl, -hw)[0]),
                num(at(0.5 * hl, -hw)[1]),
            );
            g.add(block()).add(
                Path::new()
                    .set("d", thread)
                    .set("stroke", INK)
                    .set("stroke-width", sw),
            )
        }
        JointKind::Planar => {
            let r = 5.5 * k;
            g.add(
                Polygon::new()
                    .set("points", points(&[[0.0, -r], [r, 0.0], [0.0, r], [-r, 0.0]]))
                    .set("fill", "#ffffff")
                    .set("stroke", INK)
                    .set("stroke-width", sw),
            )
        }
        JointKind::Fixed => {
            let r = 3.5 * k;
            g.add(
                Rectangle::new()
                    .set("x", num(-r))
                    .set("y", num(-r))
                    .set("width", num(2.0 * r))
                    .set("height", num(2.0 * r))
                    .set("fill", GREY)
                    .set("stroke", INK)
                    .set("stroke-width", sw),
            )
        }
    }
}
