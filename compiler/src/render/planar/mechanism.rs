//! The mechanism itself: ground pivots and slide lines, and the bodies and
//! revolute pins of one pose.

use dofplan_runtime::planar::{Point, Pose};
use svg::node::element::{Circle, Group, Path, Polygon, Polyline, Text};

use crate::model::{JointKind, MarkerId, Mechanism};
use crate::render::style::{colour_of, line, num, points, text_width, GREY, INK, STITCH_DASH};
use crate::render::trace::{crosses, overlaps, Rect};
use crate::render::view::{finite, hull, BBox, View};

/// The world position of a marker, if the ids are valid and it is finite.
pub(in crate::render) fn world(m: &Mechanism, poses: &[Pose], id: MarkerId) -> Option<Point> {
    let marker = m.bodies.get(id.body)?.markers.get(id.marker)?;
    let p = poses.get(id.body)?.world(marker.at);
    finite(p).then_some(p)
}

/// True when `id` names a marker of `m`.
pub(super) fn valid(m: &Mechanism, id: MarkerId) -> bool {
    m.bodies.get(id.body).is_some_and(|b| id.marker < b.markers.len())
}

/// The colour of body `b`: grey when fixed, else the palette in order of
/// the mobile bodies.
pub(super) fn body_colour(m: &Mechanism, b: usize) -> &'static str {
    colour_of(&m.bodies, b)
}

/// How much detail the page has room for: symbol sizes and line widths
/// shrink with the links' length on the page, so that a chain of hundreds of
/// links is a readable strip rather than overlapping pivots.
#[derive(Clone, Copy, Debug)]
pub(super) struct Detail {
    /// Factor on every symbol size and line width, 0.3 to 1.
    pub k: f64,
    /// Whether joint names fit.
    pub names: bool,
    /// Whether pins and the ground's hatching fit: links only a few pixels
    /// long would be hidden under them.
    pub pins: bool,
}

impl Detail {
    /// From the median length of the mobile bodies (the diagonal of their
    /// markers' box) on the page.
    pub fn new(m: &Mechanism, view: &View) -> Detail {
        let mut spans: Vec<f64> = m
            .bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| {
                let mut bb = BBox::new();
                for mk in &b.markers {
                    bb.add(mk.at);
                }
                (bb.hi[0] - bb.lo[0]).hypot(bb.hi[1] - bb.lo[1])
            })
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect();
        spans.sort_by(f64::total_cmp);
        let span = spans.get(spans.len() / 2).copied().unwrap_or_else(|| m.size());
        let link_px = span * view.scale;
        let k = if link_px.is_finite() {
            (link_px / 60.0).clamp(0.3, 1.0)
        } else {
            1.0
        };
        Detail {
            k,
            names: m.joints.len() <= 24 && k >= 0.5,
            // A link of unknown length (NaN) still gets its pins.
            pins: link_px.is_nan() || link_px >= 10.0,
        }
    }

    /// A size in pixels at this detail, never below `min`.
    fn px(&self, full: f64, min: f64) -> f64 {
        (full * self.k).max(min)
    }
}

/// A prismatic joint's slide line: through its first marker along that
/// marker's direction, from `lo` to `hi` (world lengths along the line).
pub(super) struct Slide {
    joint: usize,
    lo: f64,
    hi: f64,
}

impl Slide {
    /// The two ends of the line at `poses`.
    pub fn ends(&self, m: &Mechanism, poses: &[Pose]) -> Option<(Point, Point)> {
        let (a, d) = line_of(m, poses, self.joint)?;
        let e0 = [a[0] + d[0] * self.lo, a[1] + d[1] * self.lo];
        let e1 = [a[0] + d[0] * self.hi, a[1] + d[1] * self.hi];
        (finite(e0) && finite(e1)).then_some((e0, e1))
    }
}

/// The world point and unit direction of a prismatic joint's first marker.
fn line_of(m: &Mechanism, poses: &[Pose], joint: usize) -> Option<(Point, Point)> {
    let j = m.joints.get(joint)?;
    let a = j.markers[0];
    let dir = m.bodies.get(a.body)?.markers.get(a.marker)?.unit_dir()?;
    let d = poses.get(a.body)?.world_dir(dir);
    let p = world(m, poses, a)?;
    finite(d).then_some((p, d))
}

/// The slide line of every prismatic joint, long enough to cover where its
/// second marker goes in every frame and at least ±size/3.
pub(super) fn slide_ranges<'a>(
    m: &Mechanism,
    all_poses: impl Iterator<Item = &'a [Pose]>,
    size: f64,
) -> Vec<Slide> {
    let prismatic: Vec<usize> = (0..m.joints.len())
        .filter(|&ji| m.joints[ji].kind == JointKind::Prismatic)
        .collect();
    let mut range = vec![(0.0f64, 0.0f64); prismatic.len()];
    if !prismatic.is_empty() {
        for poses in all_poses {
            for (k, &ji) in prismatic.iter().enumerate() {
                let j = &m.joints[ji];
                let (Some((a, d)), Some(b)) = (line_of(m, poses, ji), world(m, poses, j.markers[1])) else {
                    continue;
                };
                let t = (b[0] - a[0]) * d[0] + (b[1] - a[1]) * d[1];
                if t.is_finite() {
                    range[k].0 = range[k].0.min(t);
                    range[k].1 = range[k].1.max(t);
                }
            }
        }
    }
    prismatic
        .into_iter()
        .zip(range)
        .map(|(joint, (mut lo, mut hi))| {
            lo -= size / 12.0;
            hi += size / 12.0;
            if hi - lo < 2.0 * size / 3.0 {
                let c = 0.5 * (hi + lo);
                lo = c - size / 3.0;
                hi = c + size / 3.0;
            }
            Slide { joint, lo, hi }
        })
        .collect()
}

/// The ground: a pivot symbol at every fixed marker (except those that only
/// carry a slide line) and the slide lines fixed to the ground.
pub(super) fn draw_ground(
    m: &Mechanism,
    poses: &[Pose],
    slides: &[Slide],
    view: &View,
    detail: Detail,
) -> Group {
    let mut g = Group::new().set("class", "ground");
    for s in slides {
        let a = m.joints[s.joint].markers[0];
        if !m.bodies[a.body].fixed {
            continue;
        }
        if let Some((e0, e1)) = s.ends(m, poses) {
            g = g.add(
                line(view.px(e0), view.px(e1))
                    .set("stroke", GREY)
                    .set("stroke-width", 1.5)
                    .set("stroke-dasharray", "8 5"),
            );
        }
    }
    let k = detail.k;
    let mut done: Vec<Point> = Vec::new();
    let mut hatch = String::new();
    let mut symbols = Group::new()
        .set("fill", "#d9d9d9")
        .set("stroke", GREY)
        .set("stroke-width", num(detail.px(1.2, 0.6)));
    for (b, body) in m.bodies.iter().enumerate() {
        if !body.fixed {
            continue;
        }
        for i in 0..body.markers.len() {
            let id = MarkerId { body: b, marker: i };
            let slide_only = m
                .joints
                .iter()
                .any(|j| j.kind == JointKind::Prismatic && j.markers[0] == id)
                && !m
                    .joints
                    .iter()
                    .any(|j| j.kind == JointKind::Revolute && j.markers.contains(&id));
            if slide_only {
                continue;
            }
            let Some(p) = world(m, poses, id) else {
                continue;
            };
            let q = view.px(p);
            if done
                .iter()
                .any(|d| (d[0] - q[0]).abs() < 1.0 && (d[1] - q[1]).abs() < 1.0)
            {
                continue;
            }
            done.push(q);
            let (x, y) = (q[0], q[1]);
            symbols = symbols.add(Polygon::new().set(
                "points",
                points(&[[x, y], [x - 8.0 * k, y + 13.0 * k], [x + 8.0 * k, y + 13.0 * k]]),
            ));
            if !detail.pins {
                continue;
            }
            hatch.push_str(&format!(
                "M{} {}H{}",
                num(x - 13.0 * k),
                num(y + 13.0 * k),
                num(x + 13.0 * k)
            ));
            for h in 0..5 {
                let hx = x + (-9.0 + 5.5 * h as f64) * k;
                hatch.push_str(&format!(
                    "M{} {}L{} {}",
                    num(hx + 4.0 * k),
                    num(y + 13.0 * k),
                    num(hx - 1.0 * k),
                    num(y + 19.0 * k)
                ));
            }
        }
    }
    g = g.add(symbols);
    if !hatch.is_empty() {
        g = g.add(
            Path::new()
                .set("d", hatch)
                .set("fill", "none")
                .set("stroke", GREY)
                .set("stroke-width", num(detail.px(1.2, 0.6))),
        );
    }
    g
}

/// The outlines of the mobile bodies at `poses` as page segments (the
/// edges of the shapes `draw_pose` fills, or its bars), for labels to keep
/// off.
pub(super) fn outlines(m: &Mechanism, poses: &[Pose], view: &View) -> Vec<[Point; 2]> {
    let mut out = Vec::new();
    for h in hulls(m, poses, view) {
        match h.len() {
            0 | 1 => {}
            2 => out.push([h[0], h[1]]),
            n => out.extend((0..n).map(|i| [h[i], h[(i + 1) % n]])),
        }
    }
    out
}

/// The mobile bodies at `poses` as page polygons (the hulls of their
/// markers: a bar has two corners).
pub(super) fn hulls(m: &Mechanism, poses: &[Pose], view: &View) -> Vec<Vec<Point>> {
    (m.bodies.iter().enumerate())
        .filter(|(_, body)| !body.fixed)
        .map(|(b, body)| {
            hull(
                (0..body.markers.len())
                    .filter_map(|i| world(m, poses, MarkerId { body: b, marker: i }))
                    .map(|p| view.px(p))
                    .collect(),
            )
        })
        .collect()
}

/// How one pose is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PoseStyle<'a> {
    /// The opaque pose, with the traced markers and the joint names.
    pub highlighted: bool,
    /// By body: pulled apart by a stretched frame (one of its joints
    /// open), stitched with a white dashed line along its outline (or its
    /// bar). Empty or all false: nothing stretched.
    pub stretched: &'a [bool],
}

/// One pose of the mobile bodies: their shapes, slide lines on mobile
/// bodies and revolute joints; for the highlighted pose also the traced
/// markers (in their trace colours) and the joint names.
pub(super) fn draw_pose(
    m: &Mechanism,
    poses: &[Pose],
    slides: &[Slide],
    view: &View,
    detail: Detail,
    traced: &[(MarkerId, &str)],
    style: PoseStyle,
) -> Group {
    let class = if style.stretched.contains(&true) {
        "pose stretched"
    } else {
        "pose"
    };
    let mut g = Group::new().set("class", class);
    for s in slides {
        let a = m.joints[s.joint].markers[0];
        if m.bodies[a.body].fixed {
            continue;
        }
        if let Some((e0, e1)) = s.ends(m, poses) {
            g = g.add(
                line(view.px(e0), view.px(e1))
                    .set("stroke", body_colour(m, a.body))
                    .set("stroke-width", 1.5)
                    .set("stroke-dasharray", "8 5"),
            );
        }
    }
    for (b, body) in m.bodies.iter().enumerate() {
        if !body.fixed {
            let stitched = style.stretched.get(b).copied().unwrap_or(false);
            g = add_body(g, m, poses, b, view, detail, stitched);
        }
    }
    if !m.gears.is_empty() {
        g = g.add(super::gears::draw(m, poses, view, detail.k));
    }
    if !m.slots.is_empty() {
        g = g.add(super::slots::draw(m, poses, view, detail.k));
    }
    g = g.add(pins(m, poses, view, detail));
    if style.highlighted {
        for &(id, colour) in traced {
            if let Some(p) = world(m, poses, id) {
                let q = view.px(p);
                g = g.add(
                    Circle::new()
                        .set("class", "traced")
                        .set("cx", num(q[0]))
                        .set("cy", num(q[1]))
                        .set("r", num(detail.px(3.5, 1.5)))
                        .set("fill", colour)
                        .set("stroke", "#ffffff")
                        .set("stroke-width", 1),
                );
            }
        }
    }
    g
}

/// Adds mobile body `b` of one pose to `g`, shaped by how its markers lie
/// on the page: a slider block (on one spot), a filled hull, or a bar (two
/// markers, or several on one line); `stitched` when a stretched frame
/// pulled it apart.
fn add_body(
    g: Group,
    m: &Mechanism,
    poses: &[Pose],
    b: usize,
    view: &View,
    detail: Detail,
    stitched: bool,
) -> Group {
    let colour = body_colour(m, b);
    let ps: Vec<Point> = (0..m.bodies[b].markers.len())
        .filter_map(|i| world(m, poses, MarkerId { body: b, marker: i }))
        .map(|p| view.px(p))
        .collect();
    if ps.is_empty() {
        return g;
    }
    let h = hull(ps.clone());
    let spread = h
        .iter()
        .flat_map(|a| h.iter().map(move |c| (a[0] - c[0]).hypot(a[1] - c[1])))
        .fold(0.0, f64::max);
    if spread < 4.0 {
        // Markers (nearly) on one spot: a slider block.
        let quad = block_corners(&ps, block_axis(m, poses, b), detail.k);
        let w = detail.px(2.0, 1.0);
        let g = g.add(
            Polygon::new()
                .set("points", points(&quad))
                .set("fill", colour)
                .set("fill-opacity", 0.6)
                .set("stroke", colour)
                .set("stroke-width", num(w)),
        );
        if stitched {
            return g.add(stitch(Polygon::new().set("points", points(&quad)), detail));
        }
        g
    } else if h.len() >= 3 {
        let w = detail.px(3.0, 1.0);
        let g = g.add(
            Polygon::new()
                .set("points", points(&h))
                .set("fill", colour)
                .set("fill-opacity", 0.25)
                .set("stroke", colour)
                .set("stroke-width", num(w))
                .set("stroke-linejoin", "round"),
        );
        if stitched {
            return g.add(stitch(Polygon::new().set("points", points(&h)), detail));
        }
        g
    } else {
        let w = detail.px(6.0, 1.5);
        let g = g.add(
            Polyline::new()
                .set("points", points(&h))
                .set("fill", "none")
                .set("stroke", colour)
                .set("stroke-width", num(w))
                .set("stroke-linecap", "round"),
        );
        if stitched {
            return g.add(stitch(Polyline::new().set("points", points(&h)), detail));
        }
        g
    }
}

/// The corners of a slider block around the centre of its page points
/// `ps`, long along its axis `u`, at detail `k`.
fn block_corners(ps: &[Point], u: Point, k: f64) -> [Point; 4] {
    let c = [
        ps.iter().map(|p| p[0]).sum::<f64>() / ps.len() as f64,
        ps.iter().map(|p| p[1]).sum::<f64>() / ps.len() as f64,
    ];
    let v = [-u[1], u[0]];
    let corner = |su: f64, sv: f64| {
        [
            c[0] + (u[0] * 12.0 * su + v[0] * 7.0 * sv) * k,
            c[1] + (u[1] * 12.0 * su + v[1] * 7.0 * sv) * k,
        ]
    };
    [
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
    ]
}

/// The revolute joints' pins of one pose, when the detail has room for
/// them.
fn pins(m: &Mechanism, poses: &[Pose], view: &View, detail: Detail) -> Group {
    let mut pins = Group::new()
        .set("fill", "#ffffff")
        .set("stroke", INK)
        .set("stroke-width", num(detail.px(1.5, 0.5)));
    for j in &m.joints {
        if j.kind != JointKind::Revolute || !detail.pins {
            continue;
        }
        if let Some(p) = world(m, poses, j.markers[0]) {
            let q = view.px(p);
            pins = pins.add(
                Circle::new()
                    .set("cx", num(q[0]))
                    .set("cy", num(q[1]))
                    .set("r", num(detail.px(4.0, 1.0))),
            );
        }
    }
    pins
}

/// A white dashed line over a body's outline (or bar): the mark of a
/// stretched pose, visible on every body colour without hiding which body
/// it is.
fn stitch<N: svg::Node>(mut node: N, detail: Detail) -> N {
    for (k, v) in [
        ("class", "stitch".to_string()),
        ("fill", "none".to_string()),
        ("stroke", "#ffffff".to_string()),
        ("stroke-width", num(detail.px(1.5, 0.75))),
        ("stroke-dasharray", STITCH_DASH.to_string()),
    ] {
        node.assign(k, v);
    }
    node
}

/// The joint names beside their pins at `poses` (joints on one spot share
/// a label, "O1, A1"), each at the one of ten places around its pin that
/// stays inside the plot, off the other labels and the `taken` boxes
/// (arrows, pins), and covers least of the drawing: the `ink` segments it
/// crosses (outlines and traces; a bar counts its width) and the `bodies`
/// polygons it lies in. With no such place, above right. Each label's box
/// is added to `taken`. White-haloed, as the trace labels, so a label
/// that must lie on a body still reads.
pub(super) fn pin_labels(
    m: &Mechanism,
    poses: &[Pose],
    view: &View,
    bodies: &[Vec<Point>],
    ink: &[[Point; 2]],
    taken: &mut Vec<Rect>,
) -> Group {
    let mut spots: Vec<(Point, String)> = Vec::new();
    for j in &m.joints {
        let Some(p) = world(m, poses, j.markers[0]) else {
            continue;
        };
        let q = view.px(p);
        match spots
            .iter_mut()
            .find(|(s, _)| (s[0] - q[0]).abs() < 3.0 && (s[1] - q[1]).abs() < 3.0)
        {
            Some((_, names)) => {
                names.push_str(", ");
                names.push_str(&j.name);
            }
            None => spots.push((q, j.name.clone())),
        }
    }
    // Every pin is an obstacle to every label.
    taken.extend(
        spots
            .iter()
            .map(|(q, _)| [q[0] - 5.0, q[1] - 5.0, q[0] + 5.0, q[1] + 5.0]),
    );
    let mut labels = Group::new()
        .set("class", "pin-labels")
        .set("font-size", PIN_FONT)
        .set("fill", "#333333")
        .set("stroke", "#ffffff")
        .set("stroke-width", 2.5)
        .set("stroke-linejoin", "round")
        .set("paint-order", "stroke");
    for (q, names) in spots {
        let w = text_width(&names, PIN_FONT);
        // (dx, baseline dy, anchored at its start): above right first,
        // then the other corners, the sides, and the same farther out.
        let places = [
            (6.0, -6.0, true),
            (-6.0, -6.0, false),
            (6.0, 14.0, true),
            (-6.0, 14.0, false),
            (8.0, 4.0, true),
            (-8.0, 4.0, false),
            (14.0, -12.0, true),
            (-14.0, -12.0, false),
            (14.0, 20.0, true),
            (-14.0, 20.0, false),
        ];
        let boxed = |&(dx, dy, start): &(f64, f64, bool)| {
            let x = q[0] + dx;
            let left = if start { x } else { x - w };
            (
                x,
                q[1] + dy,
                start,
                [left, q[1] + dy - 9.0, left + w, q[1] + dy + 2.0],
            )
        };
        let inside = |r: &Rect| view.contains([r[0], r[1]]) && view.contains([r[2], r[3]]);
        let free = |r: &Rect| inside(r) && !taken.iter().any(|t| overlaps(t, r));
        // How much of the drawing a place covers: the lines it crosses (a
        // bar is drawn up to 3 px either side of its segment) and the
        // bodies it lies in.
        let covered = |r: &Rect| {
            let wide = [r[0] - 3.0, r[1] - 3.0, r[2] + 3.0, r[3] + 3.0];
            let centre = [0.5 * (r[0] + r[2]), 0.5 * (r[1] + r[3])];
            ink.iter().filter(|s| crosses(&wide, s[0], s[1])).count()
                + (bodies.iter())
                    .filter(|b| b.len() >= 3 && in_polygon(centre, b))
                    .count()
        };
        // The free place covering least (the first of equals); else above
        // right.
        let (x, y, start, rect) = (places.iter().map(boxed))
            .filter(|(_, _, _, r)| free(r))
            .min_by_key(|(_, _, _, r)| covered(r))
            .unwrap_or_else(|| boxed(&places[0]));
        taken.push(rect);
        labels = labels.add(
            Text::new(names)
                .set("class", "pin-label")
                .set("x", num(x))
                .set("y", num(y))
                .set("text-anchor", if start { "start" } else { "end" }),
        );
    }
    labels
}

/// The font size of pin labels.
const PIN_FONT: f64 = 11.0;

/// Whether `p` is inside the polygon `poly` (even–odd rule).
fn in_polygon(p: Point, poly: &[Point]) -> bool {
    let mut inside = false;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The long axis of a slider block on the page: along the line of a
/// prismatic joint the body takes part in, else along the body's x axis.
fn block_axis(m: &Mechanism, poses: &[Pose], b: usize) -> Point {
    let dir = m
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| j.kind == JointKind::Prismatic && j.markers.iter().any(|id| id.body == b))
        .find_map(|(ji, _)| line_of(m, poses, ji).map(|(_, d)| d))
        .or_else(|| poses.get(b).map(|p| p.world_dir([1.0, 0.0])))
        .unwrap_or([1.0, 0.0]);
    // Page y points down.
    let (x, y) = (dir[0], -dir[1]);
    let n = x.hypot(y);
    if n.is_finite() && n > 0.0 {
        [x / n, y / n]
    } else {
        [1.0, 0.0]
    }
}
