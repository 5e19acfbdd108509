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
    let f = SymbolAxes::new(axis, k);
    let g = Group::new();
    match kind {
        JointKind::Revolute => {
            let g = if f.l > 0.05 {
                g.add(f.axis_line((5.0 + 7.0 * f.l) * k))
            } else {
                g
            };
            g.add(
                Circle::new()
                    .set("r", num(4.5 * k))
                    .set("fill", "#ffffff")
                    .set("stroke", INK)
                    .set("stroke-width", f.sw),
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
            let [under, over] = cross(k);
            g.add(under).add(over)
        }
        JointKind::Prismatic => g.add(f.block()),
        JointKind::Cylindrical => g.add(f.block()).add(f.axis_line((7.0 + 6.0 * f.l) * k)),
        JointKind::Helical => g.add(f.block()).add(f.thread()),
        JointKind::Planar => {
            let r = 5.5 * k;
            g.add(
                Polygon::new()
                    .set("points", points(&[[0.0, -r], [r, 0.0], [0.0, r], [-r, 0.0]]))
                    .set("fill", "#ffffff")
                    .set("stroke", INK)
                    .set("stroke-width", f.sw),
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
                    .set("stroke-width", f.sw),
            )
        }
    }
}

/// A symbol's own axes on the page: `u` along the joint axis and `v`
/// across it, with the axis's foreshortening, so that blocks and lines
/// turn and shrink with the joint.
struct SymbolAxes {
    /// Along the joint axis (the page's x when the axis is seen end-on).
    u: Point,
    /// Across it.
    v: Point,
    /// How much of the axis lies in the page: 0 (end-on) to 1.
    l: f64,
    /// The symbol's size factor.
    k: f64,
    /// The stroke width.
    sw: String,
}

impl SymbolAxes {
    /// The frame of a joint whose axis on the page is `axis`, at size `k`.
    fn new(axis: Point, k: f64) -> SymbolAxes {
        let l = axis[0].hypot(axis[1]);
        let (u, l) = if l.is_finite() && l > 1e-3 {
            ([axis[0] / l, axis[1] / l], l.min(1.0))
        } else {
            ([1.0, 0.0], 0.0)
        };
        SymbolAxes {
            u,
            v: [-u[1], u[0]],
            l,
            k,
            sw: num((1.5 * k).max(0.75)),
        }
    }

    /// The page point `a` along the axis and `b` across it.
    fn at(&self, a: f64, b: f64) -> Point {
        [a * self.u[0] + b * self.v[0], a * self.u[1] + b * self.v[1]]
    }

    /// The axis drawn as a line `half` long either side of the joint.
    fn axis_line(&self, half: f64) -> Line {
        line(self.at(-half, 0.0), self.at(half, 0.0))
            .set("stroke", INK)
            .set("stroke-width", self.sw.clone())
            .set("stroke-linecap", "round")
    }

    /// The half length and half width of a sliding joint's block: longer
    /// the more the axis lies in the page.
    fn block_size(&self) -> (f64, f64) {
        ((4.0 + 5.0 * self.l) * self.k, 3.5 * self.k)
    }

    /// A sliding joint's block along the axis.
    fn block(&self) -> Polygon {
        let (hl, hw) = self.block_size();
        Polygon::new()
            .set(
                "points",
                points(&[
                    self.at(-hl, -hw),
                    self.at(hl, -hw),
                    self.at(hl, hw),
                    self.at(-hl, hw),
                ]),
            )
            .set("fill", "#ffffff")
            .set("stroke", INK)
            .set("stroke-width", self.sw.clone())
    }

    /// A helical joint's thread: two slanted strokes across its block.
    fn thread(&self) -> Path {
        let (hl, hw) = self.block_size();
        let d = format!(
            "M{} {}L{} {}M{} {}L{} {}",
            num(self.at(-0.5 * hl, hw)[0]),
            num(self.at(-0.5 * hl, hw)[1]),
            num(self.at(0.0, -hw)[0]),
            num(self.at(0.0, -hw)[1]),
            num(self.at(0.0, hw)[0]),
            num(self.at(0.0, hw)[1]),
            num(self.at(0.5 * hl, -hw)[0]),
            num(self.at(0.5 * hl, -hw)[1]),
        );
        Path::new()
            .set("d", d)
            .set("stroke", INK)
            .set("stroke-width", self.sw.clone())
    }
}

/// A universal joint's bold cross at size `k`: a white halo under the ink,
/// so that it reads over the bodies.
fn cross(k: f64) -> [Path; 2] {
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
    [
        Path::new()
            .set("d", d.clone())
            .set("stroke", "#ffffff")
            .set("stroke-width", num(4.5 * k))
            .set("stroke-linecap", "round"),
        Path::new()
            .set("d", d)
            .set("stroke", INK)
            .set("stroke-width", num(2.2 * k))
            .set("stroke-linecap", "round"),
    ]
}
