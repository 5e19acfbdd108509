//! An SVG drawing of a simulated sweep: the mechanism at a few poses, the
//! path of every traced marker through every frame, a title and a legend.
//!
//! The drawing stands on its own (no scripts, no external styles). World
//! coordinates have y up; points are transformed here (y flipped) so that
//! text stays upright and every length given in pixels (line widths, pivot
//! symbols) is independent of the mechanism's scale. The output is
//! deterministic and numbers carry at most two decimals.

use dofplan_runtime::planar::{Point, Pose};
use svg::node::element::{Circle, Group, Line, Path, Polygon, Polyline, Rectangle, Text, Title};
use svg::Document;

use crate::model::{InputKind, JointKind, MarkerId, Mechanism};
use crate::simulate::Frame;

/// Options of the drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgOptions {
    /// How many poses to draw (the first and the last frame included).
    pub poses: usize,
    /// Width of the picture in pixels (the height follows the mechanism).
    pub width: f64,
}

impl Default for SvgOptions {
    fn default() -> Self {
        SvgOptions {
            poses: 6,
            width: 800.0,
        }
    }
}

/// Colours of the mobile bodies, in order (a colour-blind-friendly
/// categorical palette without its grey, kept for the ground).
const BODY_COLOURS: [&str; 9] = [
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#bcbd22", "#17becf",
];
/// Colour of fixed bodies.
const GROUND_COLOUR: &str = "#7f7f7f";
/// Colours of the traces: darker and more saturated than the bodies'.
const TRACE_COLOURS: [&str; 6] = ["#c2185b", "#00695c", "#4527a0", "#e65100", "#1b5e20", "#283593"];
/// Dark ink for outlines and text.
const INK: &str = "#222222";

const PAD: f64 = 16.0;
const HEADER: f64 = 56.0;
const LEGEND_ROW: f64 = 18.0;
const MIN_PLOT_HEIGHT: f64 = 150.0;

/// Draws the mechanism at several poses plus the trace of every marker in
/// `trace`.
///
/// Picks `options.poses` frames evenly spaced through `frames` (the first
/// and the last included; unsolved frames are skipped when there are solved
/// ones), draws the first one opaque and the others fainter along the sweep,
/// and draws each traced marker's path through every frame. Never panics:
/// with no frames the drawn pose is shown under a "no frames" title, and
/// non-finite positions are left out.
pub fn render(m: &Mechanism, frames: &[Frame], trace: &[MarkerId], options: &SvgOptions) -> String {
    let size = m.size();
    let width = if options.width.is_finite() {
        options.width.clamp(200.0, 20_000.0)
    } else {
        800.0
    };

    // The pose sets to draw, first one highlighted.
    let drawn = vec![Pose::IDENTITY; m.bodies.len()];
    let picked = pick_poses(frames, options.poses);
    let mut pose_sets: Vec<&[Pose]> = if frames.is_empty() {
        vec![&drawn[..]]
    } else {
        picked.iter().map(|&i| &frames[i].poses[..]).collect()
    };
    let mut picked_frames: Vec<usize> = picked.clone();
    dedupe_identical(m, &mut pose_sets, &mut picked_frames, size);

    // Every frame's poses (the drawn pose alone when there are none).
    let all_poses: Vec<&[Pose]> = if frames.is_empty() {
        vec![&drawn[..]]
    } else {
        frames.iter().map(|f| &f.poses[..]).collect()
    };
    let slides = slide_ranges(m, &all_poses, size);

    // Bounding box of everything drawn in world units.
    let mut bbox = BBox::new();
    for poses in &all_poses {
        for id in m.all_markers() {
            if let Some(p) = world(m, poses, id) {
                bbox.add(p);
            }
        }
    }
    for poses in &pose_sets {
        for s in &slides {
            if let Some((a, b)) = s.ends(m, poses) {
                bbox.add(a);
                bbox.add(b);
            }
        }
    }

    // Legend entries: traces first, then bodies.
    let trace: Vec<MarkerId> = trace.iter().copied().filter(|&id| valid(m, id)).collect();
    let mut legend: Vec<(LegendKind, String, String)> = Vec::new();
    for (k, &id) in trace.iter().enumerate() {
        legend.push((
            LegendKind::Trace,
            trace_colour(k).to_string(),
            format!("trace {}", m.marker_name(id)),
        ));
    }
    for (b, body) in m.bodies.iter().enumerate() {
        let label = if body.fixed {
            format!("{} (fixed)", body.name)
        } else {
            body.name.clone()
        };
        legend.push((LegendKind::Body, body_colour(m, b).to_string(), label));
    }

    // Layout.
    let plot_w = width - 2.0 * PAD;
    let view = View::fit(&bbox, size, plot_w, PAD, HEADER);
    let label_w = legend.iter().map(|e| text_width(&e.2, 12.0)).fold(0.0, f64::max);
    let col_w = (label_w + 34.0).min(plot_w);
    let cols = ((plot_w / col_w).floor() as usize).max(1);
    let rows = legend.len().div_ceil(cols);
    let legend_top = HEADER + view.plot_h + 8.0;
    let height = legend_top + rows as f64 * LEGEND_ROW + PAD;

    let mut doc = Document::new()
        .set("width", num(width))
        .set("height", num(height))
        .set("viewBox", format!("0 0 {} {}", num(width), num(height)))
        .set("font-family", "Helvetica, Arial, sans-serif");
    let (title, subtitle) = titles(m, frames, &picked_frames);
    doc = doc.add(Title::new(title.clone()));
    doc = doc.add(
        Rectangle::new()
            .set("x", 0)
            .set("y", 0)
            .set("width", num(width))
            .set("height", num(height))
            .set("fill", "#ffffff"),
    );

    // Ground: pivots and fixed slide lines, once.
    if let Some(first) = pose_sets.first() {
        doc = doc.add(draw_ground(m, first, &slides, &view));
    }

    // Faint poses, last first so that earlier ones lie on top.
    let n = pose_sets.len();
    for k in (1..n).rev() {
        let opacity = if n > 2 {
            0.55 - 0.35 * (k - 1) as f64 / (n - 2) as f64
        } else {
            0.45
        };
        let g = draw_pose(m, pose_sets[k], &slides, &view, &[], false).set("opacity", num(opacity));
        doc = doc.add(g);
    }

    // Traces through every frame.
    let mut traces = Group::new().set("fill", "none").set("stroke-width", "1.75");
    for (k, &id) in trace.iter().enumerate() {
        let pts: Vec<String> = all_poses
            .iter()
            .filter_map(|poses| world(m, poses, id))
            .map(|p| view.pt(p))
            .collect();
        if pts.is_empty() {
            continue;
        }
        traces = traces.add(
            Polyline::new()
                .set("class", "trace")
                .set("data-marker", m.marker_name(id))
                .set("points", pts.join(" "))
                .set("stroke", trace_colour(k))
                .set("stroke-linejoin", "round")
                .set("stroke-linecap", "round"),
        );
    }
    doc = doc.add(traces);

    // The first pose, opaque, with the traced markers and joint names.
    if let Some(first) = pose_sets.first() {
        doc = doc.add(draw_pose(m, first, &slides, &view, &trace, true));
    }

    // Title and legend.
    doc = doc.add(
        Text::new(title)
            .set("x", num(PAD))
            .set("y", 26)
            .set("font-size", 18)
            .set("font-weight", "bold")
            .set("fill", INK),
    );
    doc = doc.add(
        Text::new(subtitle)
            .set("x", num(PAD))
            .set("y", 45)
            .set("font-size", 12)
            .set("fill", "#555555"),
    );
    let mut lg = Group::new().set("font-size", 12).set("fill", INK);
    for (i, (kind, colour, label)) in legend.iter().enumerate() {
        // Column by column, so that a long list reads downwards.
        let x = PAD + (i / rows) as f64 * col_w;
        let y = legend_top + (i % rows) as f64 * LEGEND_ROW;
        lg = match kind {
            LegendKind::Trace => lg.add(
                Line::new()
                    .set("x1", num(x))
                    .set("y1", num(y + 7.0))
                    .set("x2", num(x + 22.0))
                    .set("y2", num(y + 7.0))
                    .set("stroke", colour.as_str())
                    .set("stroke-width", 2.5),
            ),
            LegendKind::Body => lg.add(
                Rectangle::new()
                    .set("x", num(x + 3.0))
                    .set("y", num(y + 1.0))
                    .set("width", 16)
                    .set("height", 12)
                    .set("fill", colour.as_str())
                    .set("stroke", INK)
                    .set("stroke-width", 0.5),
            ),
        };
        lg = lg.add(
            Text::new(label.clone())
                .set("x", num(x + 28.0))
                .set("y", num(y + 11.5)),
        );
    }
    doc = doc.add(lg);
    doc.to_string()
}

enum LegendKind {
    Trace,
    Body,
}

/// Indices of up to `n` frames evenly spaced among the solved ones (among
/// all when none is solved), the first and the last included, ascending.
fn pick_poses(frames: &[Frame], n: usize) -> Vec<usize> {
    // Frames whose pose belongs to the requested input: solved, or
    // stretched (the input applied, a step relaxed — a drag's closest
    // approach).
    let solved: Vec<usize> = (0..frames.len())
        .filter(|&i| frames[i].status.is_solved() || frames[i].status.name() == "stretched")
        .collect();
    let candidates: Vec<usize> = if solved.is_empty() {
        (0..frames.len()).collect()
    } else {
        solved
    };
    let n = n.min(candidates.len());
    if n == 0 {
        return Vec::new();
    }
    if n == 1 {
        return vec![candidates[0]];
    }
    let last = candidates.len() - 1;
    let mut out: Vec<usize> = Vec::with_capacity(n);
    for k in 0..n {
        let i = candidates[(k * last + (n - 1) / 2) / (n - 1)];
        if out.last() != Some(&i) {
            out.push(i);
        }
    }
    out
}

/// Drops poses identical to an earlier one (a full turn ends where it
/// started), keeping the first.
fn dedupe_identical(m: &Mechanism, sets: &mut Vec<&[Pose]>, frames: &mut Vec<usize>, size: f64) {
    let tol = 1e-6 * size;
    let mut keep: Vec<bool> = Vec::with_capacity(sets.len());
    for k in 0..sets.len() {
        let same = (0..k).any(|j| {
            keep[j]
                && m.all_markers()
                    .all(|id| match (world(m, sets[j], id), world(m, sets[k], id)) {
                        (Some(a), Some(b)) => (a[0] - b[0]).abs() <= tol && (a[1] - b[1]).abs() <= tol,
                        (None, None) => true,
                        _ => false,
                    })
        });
        keep.push(!same);
    }
    let mut it = keep.iter();
    sets.retain(|_| *it.next().unwrap_or(&true));
    if frames.len() == keep.len() {
        let mut it = keep.iter();
        frames.retain(|_| *it.next().unwrap_or(&true));
    }
}

/// The title ("name — 361 frames, all solved") and the subtitle (where the
/// poses were drawn).
fn titles(m: &Mechanism, frames: &[Frame], picked: &[usize]) -> (String, String) {
    if frames.is_empty() {
        return (
            format!("{} \u{2014} no frames", m.name),
            "no frames: the mechanism is shown as drawn".to_string(),
        );
    }
    let n = frames.len();
    let mut not_solved: Vec<String> = Vec::new();
    for name in ["limited", "searched", "stretched"] {
        let c = frames.iter().filter(|f| f.status.name() == name).count();
        if c > 0 {
            not_solved.push(format!("{c} {name}"));
        }
    }
    let status = if not_solved.is_empty() {
        "all solved".to_string()
    } else {
        not_solved.join(", ")
    };
    let plural = if n == 1 { "frame" } else { "frames" };
    let title = format!("{} \u{2014} {n} {plural}, {status}", m.name);

    let input = m.sweep.as_ref().map(|s| s.input).unwrap_or(0);
    // Frames of a drag carry targets, not the mechanism's inputs.
    let of_inputs = frames[0].requested.len() == m.inputs.len();
    let at = match m.inputs.get(input).filter(|_| of_inputs) {
        Some(inp) => {
            let unit = match inp.kind {
                InputKind::Angle => "\u{b0}",
                InputKind::Slide => "",
            };
            let values: Vec<String> = picked
                .iter()
                .map(|&i| match frames[i].requested.get(input) {
                    Some(v) => format!("{}{unit}", num(*v)),
                    None => "?".to_string(),
                })
                .collect();
            format!("{} = {}", inp.name, values.join(", "))
        }
        None => {
            let values: Vec<String> = picked.iter().map(|i| i.to_string()).collect();
            format!("frames {}", values.join(", "))
        }
    };
    let poses = if picked.len() == 1 { "pose" } else { "poses" };
    let subtitle = format!(
        "{} {poses} at {at} (first opaque, later ones fainter)",
        picked.len()
    );
    (title, subtitle)
}

/// The world position of a marker, if the ids are valid and it is finite.
fn world(m: &Mechanism, poses: &[Pose], id: MarkerId) -> Option<Point> {
    let marker = m.bodies.get(id.body)?.markers.get(id.marker)?;
    let p = poses.get(id.body)?.world(marker.at);
    finite(p).then_some(p)
}

fn valid(m: &Mechanism, id: MarkerId) -> bool {
    m.bodies.get(id.body).is_some_and(|b| id.marker < b.markers.len())
}

fn finite(p: Point) -> bool {
    p[0].is_finite() && p[1].is_finite()
}

fn body_colour(m: &Mechanism, b: usize) -> &'static str {
    if m.bodies.get(b).is_none_or(|body| body.fixed) {
        return GROUND_COLOUR;
    }
    let rank = m.bodies[..b].iter().filter(|body| !body.fixed).count();
    BODY_COLOURS[rank % BODY_COLOURS.len()]
}

fn trace_colour(k: usize) -> &'static str {
    TRACE_COLOURS[k % TRACE_COLOURS.len()]
}

/// A number with at most two decimals, no trailing zeros.
fn num(x: f64) -> String {
    if !x.is_finite() {
        return "0".to_string();
    }
    let mut s = format!("{x:.2}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

/// A rough width of a text in pixels.
fn text_width(text: &str, font_size: f64) -> f64 {
    text.chars().count() as f64 * font_size * 0.6
}

struct BBox {
    lo: Point,
    hi: Point,
}

impl BBox {
    fn new() -> BBox {
        BBox {
            lo: [f64::INFINITY; 2],
            hi: [f64::NEG_INFINITY; 2],
        }
    }

    fn add(&mut self, p: Point) {
        if !finite(p) {
            return;
        }
        for (k, v) in p.into_iter().enumerate() {
            self.lo[k] = self.lo[k].min(v);
            self.hi[k] = self.hi[k].max(v);
        }
    }
}

/// World to picture coordinates: uniform scale, y flipped.
struct View {
    scale: f64,
    x0: f64,
    y1: f64,
    ox: f64,
    oy: f64,
    plot_h: f64,
}

impl View {
    /// Fits `bbox` (with a margin) into a plot `plot_w` wide whose top-left
    /// corner is at (`left`, `top`), keeping the aspect ratio.
    fn fit(bbox: &BBox, size: f64, plot_w: f64, left: f64, top: f64) -> View {
        let (mut lo, mut hi) = if bbox.lo[0] <= bbox.hi[0] {
            (bbox.lo, bbox.hi)
        } else {
            ([0.0, 0.0], [0.0, 0.0])
        };
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let extent = if extent.is_finite() && extent > 0.0 {
            extent
        } else {
            size
        };
        let margin = 0.08 * extent;
        for k in 0..2 {
            lo[k] -= margin;
            hi[k] += margin;
            // A flat box still gets some height (or width).
            let min = 0.3 * extent;
            if hi[k] - lo[k] < min {
                let c = 0.5 * (hi[k] + lo[k]);
                lo[k] = c - 0.5 * min;
                hi[k] = c + 0.5 * min;
            }
        }
        let ww = hi[0] - lo[0];
        let wh = hi[1] - lo[1];
        let plot_h = (plot_w * wh / ww).clamp(MIN_PLOT_HEIGHT, 1.25 * plot_w);
        let scale = (plot_w / ww).min(plot_h / wh);
        let scale = if scale.is_finite() && scale > 0.0 {
            scale
        } else {
            1.0
        };
        View {
            scale,
            x0: lo[0],
            y1: hi[1],
            ox: left + 0.5 * (plot_w - ww * scale),
            oy: top + 0.5 * (plot_h - wh * scale),
            plot_h,
        }
    }

    fn px(&self, p: Point) -> Point {
        [
            self.ox + (p[0] - self.x0) * self.scale,
            self.oy + (self.y1 - p[1]) * self.scale,
        ]
    }

    fn pt(&self, p: Point) -> String {
        let q = self.px(p);
        format!("{},{}", num(q[0]), num(q[1]))
    }
}

/// A prismatic joint's slide line: through its first marker along that
/// marker's direction, from `lo` to `hi` (world lengths along the line).
struct Slide {
    joint: usize,
    lo: f64,
    hi: f64,
}

impl Slide {
    /// The two ends of the line at `poses`.
    fn ends(&self, m: &Mechanism, poses: &[Pose]) -> Option<(Point, Point)> {
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
fn slide_ranges(m: &Mechanism, all_poses: &[&[Pose]], size: f64) -> Vec<Slide> {
    let mut out = Vec::new();
    for (ji, j) in m.joints.iter().enumerate() {
        if j.kind != JointKind::Prismatic {
            continue;
        }
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for poses in all_poses {
            let (Some((a, d)), Some(b)) = (line_of(m, poses, ji), world(m, poses, j.markers[1])) else {
                continue;
            };
            let t = (b[0] - a[0]) * d[0] + (b[1] - a[1]) * d[1];
            if t.is_finite() {
                lo = lo.min(t);
                hi = hi.max(t);
            }
        }
        lo -= size / 12.0;
        hi += size / 12.0;
        if hi - lo < 2.0 * size / 3.0 {
            let c = 0.5 * (hi + lo);
            lo = c - size / 3.0;
            hi = c + size / 3.0;
        }
        out.push(Slide { joint: ji, lo, hi });
    }
    out
}

fn line(a: Point, b: Point) -> Line {
    Line::new()
        .set("x1", num(a[0]))
        .set("y1", num(a[1]))
        .set("x2", num(b[0]))
        .set("y2", num(b[1]))
}

fn points(ps: &[Point]) -> String {
    ps.iter()
        .map(|p| format!("{},{}", num(p[0]), num(p[1])))
        .collect::<Vec<_>>()
        .join(" ")
}

/// The ground: a pivot symbol at every fixed marker (except those that only
/// carry a slide line) and the slide lines fixed to the ground.
fn draw_ground(m: &Mechanism, poses: &[Pose], slides: &[Slide], view: &View) -> Group {
    let mut g = Group::new();
    for s in slides {
        let a = m.joints[s.joint].markers[0];
        if !m.bodies[a.body].fixed {
            continue;
        }
        if let Some((e0, e1)) = s.ends(m, poses) {
            g = g.add(
                line(view.px(e0), view.px(e1))
                    .set("stroke", "#555555")
                    .set("stroke-width", 1.5)
                    .set("stroke-dasharray", "8 5"),
            );
        }
    }
    let mut done: Vec<Point> = Vec::new();
    let mut hatch = String::new();
    let mut symbols = Group::new()
        .set("fill", "#d9d9d9")
        .set("stroke", "#555555")
        .set("stroke-width", 1.2);
    for (b, body) in m.bodies.iter().enumerate() {
        if !body.fixed {
            continue;
        }
        for k in 0..body.markers.len() {
            let id = MarkerId { body: b, marker: k };
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
                points(&[[x, y], [x - 8.0, y + 13.0], [x + 8.0, y + 13.0]]),
            ));
            hatch.push_str(&format!("M{} {}H{}", num(x - 13.0), num(y + 13.0), num(x + 13.0)));
            for i in 0..5 {
                let hx = x - 9.0 + 5.5 * i as f64;
                hatch.push_str(&format!(
                    "M{} {}L{} {}",
                    num(hx + 4.0),
                    num(y + 13.0),
                    num(hx - 1.0),
                    num(y + 19.0)
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
                .set("stroke", "#555555")
                .set("stroke-width", 1.2),
        );
    }
    g
}

/// Convex hull (monotone chain) of pixel points, counter-clockwise on the
/// page, collinear points dropped.
fn hull(mut ps: Vec<Point>) -> Vec<Point> {
    ps.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    ps.dedup_by(|a, b| (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
    if ps.len() < 3 {
        return ps;
    }
    let cross = |o: Point, a: Point, b: Point| (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    let mut out: Vec<Point> = Vec::with_capacity(2 * ps.len());
    for pass in 0..2 {
        let start = out.len();
        let iter: Box<dyn Iterator<Item = &Point>> = if pass == 0 {
            Box::new(ps.iter())
        } else {
            Box::new(ps.iter().rev())
        };
        for &p in iter {
            while out.len() >= start + 2 && cross(out[out.len() - 2], out[out.len() - 1], p) <= 0.0 {
                out.pop();
            }
            out.push(p);
        }
        out.pop();
    }
    out
}

/// One pose of the mobile bodies: their shapes, slide lines on mobile
/// bodies and revolute joints; for the highlighted pose also the traced
/// markers and the joint names.
fn draw_pose(
    m: &Mechanism,
    poses: &[Pose],
    slides: &[Slide],
    view: &View,
    trace: &[MarkerId],
    highlighted: bool,
) -> Group {
    let mut g = Group::new();
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
        if body.fixed {
            continue;
        }
        let colour = body_colour(m, b);
        let ps: Vec<Point> = (0..body.markers.len())
            .filter_map(|k| world(m, poses, MarkerId { body: b, marker: k }))
            .map(|p| view.px(p))
            .collect();
        if ps.is_empty() {
            continue;
        }
        let h = hull(ps.clone());
        let spread = h
            .iter()
            .flat_map(|a| h.iter().map(move |c| (a[0] - c[0]).hypot(a[1] - c[1])))
            .fold(0.0, f64::max);
        if spread < 4.0 {
            // Markers (nearly) on one spot: a slider block.
            let c = [
                ps.iter().map(|p| p[0]).sum::<f64>() / ps.len() as f64,
                ps.iter().map(|p| p[1]).sum::<f64>() / ps.len() as f64,
            ];
            let u = block_axis(m, poses, b);
            let v = [-u[1], u[0]];
            let corner = |su: f64, sv: f64| {
                [
                    c[0] + u[0] * 12.0 * su + v[0] * 7.0 * sv,
                    c[1] + u[1] * 12.0 * su + v[1] * 7.0 * sv,
                ]
            };
            let quad = [
                corner(1.0, 1.0),
                corner(-1.0, 1.0),
                corner(-1.0, -1.0),
                corner(1.0, -1.0),
            ];
            g = g.add(
                Polygon::new()
                    .set("points", points(&quad))
                    .set("fill", colour)
                    .set("fill-opacity", 0.6)
                    .set("stroke", colour)
                    .set("stroke-width", 2),
            );
        } else if h.len() >= 3 {
            g = g.add(
                Polygon::new()
                    .set("points", points(&h))
                    .set("fill", colour)
                    .set("fill-opacity", 0.25)
                    .set("stroke", colour)
                    .set("stroke-width", 3)
                    .set("stroke-linejoin", "round"),
            );
        } else {
            // Two markers, or several on one line: a bar.
            g = g.add(
                Polyline::new()
                    .set("points", points(&h))
                    .set("fill", "none")
                    .set("stroke", colour)
                    .set("stroke-width", 6)
                    .set("stroke-linecap", "round"),
            );
        }
    }
    let mut pins = Group::new()
        .set("fill", "#ffffff")
        .set("stroke", INK)
        .set("stroke-width", 1.5);
    for j in &m.joints {
        if j.kind != JointKind::Revolute {
            continue;
        }
        if let Some(p) = world(m, poses, j.markers[0]) {
            let q = view.px(p);
            pins = pins.add(
                Circle::new()
                    .set("cx", num(q[0]))
                    .set("cy", num(q[1]))
                    .set("r", 4),
            );
        }
    }
    g = g.add(pins);
    if highlighted {
        for (k, &id) in trace.iter().enumerate() {
            if let Some(p) = world(m, poses, id) {
                let q = view.px(p);
                g = g.add(
                    Circle::new()
                        .set("cx", num(q[0]))
                        .set("cy", num(q[1]))
                        .set("r", 3.5)
                        .set("fill", trace_colour(k))
                        .set("stroke", "#ffffff")
                        .set("stroke-width", 1),
                );
            }
        }
        if m.joints.len() <= 24 {
            // Joints on one spot share a label ("O1, A1").
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
            let mut labels = Group::new().set("font-size", 11).set("fill", "#333333");
            for (q, names) in spots {
                labels = labels.add(
                    Text::new(names)
                        .set("x", num(q[0] + 6.0))
                        .set("y", num(q[1] - 6.0)),
                );
            }
            g = g.add(labels);
        }
    }
    g
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{load_str, Format};
    use dofplan_runtime::planar::Rot;
    use dofplan_runtime::{Break, BreakKind, FrameStatus};

    // The bundled four-bar, not a copy of it.
    const FOURBAR: &str = include_str!("../../mechanisms/fourbar.toml");

    fn load(text: &str) -> Mechanism {
        load_str("t.toml", text, Format::Toml).expect("the test mechanism loads")
    }

    fn simulate(m: &Mechanism, steps: usize) -> Vec<Frame> {
        let plan = crate::analysis::analyse(m).plan.expect("closed-form plan");
        crate::simulate::run(
            crate::interp::Interpreter::new(plan),
            Default::default(),
            &crate::simulate::sweep_inputs(m, Some(steps)),
        )
    }

    fn trace_of(m: &Mechanism) -> Vec<MarkerId> {
        m.sweep.as_ref().map(|s| s.trace.clone()).unwrap_or_default()
    }

    /// Checks that tags nest properly, with a single `<svg>` root.
    fn assert_well_formed(svg: &str) {
        let mut stack: Vec<String> = Vec::new();
        let mut roots = 0;
        let mut rest = svg;
        while let Some(start) = rest.find('<') {
            let end = start + rest[start..].find('>').expect("every tag closes");
            let tag = &rest[start + 1..end];
            rest = &rest[end + 1..];
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop().as_deref(), Some(name.trim()), "mismatched </{name}>");
                continue;
            }
            assert!(
                !tag.starts_with('!') && !tag.starts_with('?'),
                "unexpected <{tag}>"
            );
            let name: String = tag
                .chars()
                .take_while(|c| !c.is_whitespace() && *c != '/')
                .collect();
            if stack.is_empty() {
                roots += 1;
                assert_eq!(name, "svg");
            }
            if !tag.ends_with('/') {
                stack.push(name);
            }
        }
        assert!(stack.is_empty(), "unclosed tags: {stack:?}");
        assert_eq!(roots, 1);
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "non-finite number in the SVG"
        );
    }

    /// The number of points of every trace polyline.
    fn trace_points(svg: &str) -> Vec<usize> {
        svg.split("<polyline")
            .skip(1)
            .filter(|s| s[..s.find('>').unwrap()].contains(r#"class="trace""#))
            .map(|s| {
                let p = s.find(r#"points=""#).unwrap() + 8;
                let q = p + s[p..].find('"').unwrap();
                s[p..q].split_whitespace().count()
            })
            .collect()
    }

    #[test]
    fn fourbar_from_the_pipeline() {
        let m = load(FOURBAR);
        let frames = simulate(&m, 37);
        assert_eq!(frames.len(), 37);
        let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
        assert!(svg.starts_with("<svg"), "{}", &svg[..40]);
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("fourbar \u{2014} 37 frames, all solved"));
        assert!(svg.contains("trace coupler.P"));
        assert_eq!(trace_points(&svg), vec![37]);
        assert_well_formed(&svg);
        // 6 poses asked, the last equals the first (a full turn): 5 drawn.
        assert!(svg.contains("5 poses at theta = 0\u{b0}, 70\u{b0}, 140\u{b0}, 220\u{b0}, 290\u{b0}"));
        // Two ground pivots, four revolute pins in each of the 5 poses.
        assert_eq!(svg.matches("<circle").count(), 5 * 4 + 1);
        assert_eq!(svg, render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    }

    #[test]
    fn no_frames_still_draws() {
        let m = load(FOURBAR);
        let svg = render(&m, &[], &trace_of(&m), &SvgOptions::default());
        assert!(svg.starts_with("<svg"));
        assert!(svg.contains("fourbar \u{2014} no frames"));
        assert_well_formed(&svg);
        // The drawn pose alone: one point per trace.
        assert_eq!(trace_points(&svg), vec![1]);
        let none = render(
            &m,
            &[],
            &[],
            &SvgOptions {
                poses: 0,
                width: f64::NAN,
            },
        );
        assert_well_formed(&none);
    }

    #[test]
    fn handmade_frames_with_breaks_and_nan() {
        let m = load(FOURBAR);
        let n = m.bodies.len();
        let limited = FrameStatus::Limited {
            brk: Break {
                step: 3,
                kind: BreakKind::CirclesApart,
                gap: 0.1,
            },
        };
        let mut frames = Vec::new();
        for i in 0..10 {
            let mut poses = vec![Pose::IDENTITY; n];
            poses[1] = Pose {
                at: [0.0, 0.0],
                rot: Rot::from_degrees(10.0 * i as f64),
            };
            poses[2] = Pose {
                at: [0.1 * i as f64, 0.0],
                rot: Rot::IDENTITY,
            };
            if i == 4 {
                poses[2].at = [f64::NAN, 0.0];
            }
            frames.push(Frame {
                requested: vec![10.0 * i as f64],
                inputs: vec![10.0 * i as f64],
                status: if i >= 7 { limited } else { FrameStatus::Solved },
                poses,
                numeric: None,
            });
        }
        let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
        assert!(svg.contains("fourbar \u{2014} 10 frames, 3 limited"));
        // Frame 4's coupler is NaN: its point is skipped.
        assert_eq!(trace_points(&svg), vec![9]);
        assert_well_formed(&svg);
        // Only solved frames are drawn as poses: 0..=6.
        assert!(svg.contains("poses at theta = 0\u{b0}, 10\u{b0}, 20\u{b0}, 40\u{b0}, 50\u{b0}, 60\u{b0}"));

        // All frames unsolved: poses are still drawn, poses vectors too
        // short and bogus trace ids do not panic.
        for f in &mut frames {
            f.status = limited;
        }
        frames[9].poses.truncate(1);
        let bogus = [MarkerId { body: 9, marker: 0 }, MarkerId { body: 2, marker: 7 }];
        let svg = render(
            &m,
            &frames,
            &bogus,
            &SvgOptions {
                poses: 3,
                width: 300.0,
            },
        );
        assert!(svg.contains("10 frames, 10 limited"));
        assert_well_formed(&svg);
    }

    #[test]
    fn picks_first_and_last() {
        let frame = |solved: bool| Frame {
            requested: vec![],
            inputs: vec![],
            status: if solved {
                FrameStatus::Solved
            } else {
                FrameStatus::Limited {
                    brk: dofplan_runtime::Break {
                        step: 0,
                        kind: dofplan_runtime::BreakKind::CirclesApart,
                        gap: 1.0,
                    },
                }
            },
            poses: vec![],
            numeric: None,
        };
        let frames: Vec<Frame> = (0..361).map(|_| frame(true)).collect();
        assert_eq!(pick_poses(&frames, 6), vec![0, 72, 144, 216, 288, 360]);
        assert_eq!(pick_poses(&frames, 1), vec![0]);
        assert_eq!(pick_poses(&frames, 0), Vec::<usize>::new());
        assert_eq!(pick_poses(&frames[..3], 6), vec![0, 1, 2]);
        assert_eq!(pick_poses(&[], 6), Vec::<usize>::new());
        let mixed: Vec<Frame> = (0..10).map(|i| frame((2..8).contains(&i))).collect();
        assert_eq!(pick_poses(&mixed, 3), vec![2, 5, 7]);
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(-0.001), "0");
        assert_eq!(num(2.345678), "2.35");
        assert_eq!(num(10.50), "10.5");
        assert_eq!(num(f64::NAN), "0");
    }

    #[test]
    fn slider_crank_draws_its_track() {
        let m = load(include_str!("../../mechanisms/slider_crank.toml"));
        let frames = simulate(&m, 73);
        let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
        assert!(svg.contains("stroke-dasharray"));
        assert_eq!(trace_points(&svg), vec![73, 73]);
        assert_well_formed(&svg);
    }

    #[test]
    fn stress_50_stays_small() {
        let m = load(include_str!("../../mechanisms/stress_50.toml"));
        let frames = simulate(&m, 361);
        let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
        assert_well_formed(&svg);
        assert_eq!(trace_points(&svg), vec![361, 361]);
        assert!(svg.len() < 300_000, "{} bytes", svg.len());
    }
}
