//! Pictures of a spatial (3D) mechanism's motion, as standalone SVG.
//!
//! [`render_spatial`] draws a sweep in four views of one scale, in a 2×2
//! grid laid out as in a technical drawing: the front view (x–z, seen from
//! −y) top left, the side view (y–z, seen from +x) beside it sharing its
//! z rows, the top view (x–y, seen from +z) under it sharing its x
//! columns, and an isometric view (seen from (+x, −y, +z)) bottom right.
//! Every view is labelled, shows its axes and has a scale bar; all four
//! have the same number of pixels per unit, so sizes compare across them.
//!
//! In each view: the ground (hatched grey, with ground marks under its
//! markers), the first frame's pose opaque and a few evenly spaced later
//! ones faint, bodies far from the viewer first, each mobile body in its
//! colour (the planar drawing's palette and order) as the convex hull of
//! its markers (a bar for two, a block for markers on one spot), a symbol
//! per joint kind at its marker, and the path of every traced marker
//! through every frame (split at frames that did not meet their input,
//! thinned to half a pixel, with an arrow of motion and the marker's
//! name). Under the grid, a legend of the traces, the joint symbols and
//! the bodies. [`render_spatial_with`] also rings given world points (a
//! synthesis's targets) in every view (`g.target-points`).
//!
//! Elements carry a `class` and data attributes so that tests and style
//! sheets can find them: every view is a `g.view` with `data-view`
//! (`front`, `side`, `top`, `isometric`); bodies are `g.body` with
//! `data-body` inside `g.pose` (the opaque pose) or `g.pose ghost`; joints
//! are `g.joint` with `data-joint` and `data-kind`, placed by a
//! `translate` to the joint's page point; traces are the planar drawing's
//! `polyline.trace` with `data-marker`.

#[cfg(test)]
mod tests;

use dofplan_runtime::planar::Point;
use dofplan_runtime::spatial::{dot, Pose3, Vec3};
use dofplan_runtime::FrameStatus;
use svg::node::element::{Circle, Definitions, Group, Path, Polygon, Polyline, Rectangle, Text};

use super::caption::{heading, page, pick_of, titles_of, Shown};
use super::legend::{self, Entry, Key, Layout};
use super::style::colour_of;
use super::style::{dashed, line, num, points, text_width, trace_colour, GREY, GROUND_COLOUR, INK};
use super::trace::{self, Reach, Rect};
use super::view::hull;
use super::view::{self, BBox, View};
use crate::model::spatial::{JointKind, Mechanism};
use crate::model::MarkerId;
use symbol::{hatch_pattern, symbol, HATCH_ID};

pub(super) mod symbol;

/// One frame of a spatial sweep, as the drawing needs it.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialFrame {
    /// The inputs requested of the frame, one per input of the mechanism
    /// (the subtitle names the drawn poses by the swept input's values;
    /// when the length differs, by frame numbers).
    pub requested: Vec<f64>,
    /// How the frame met its input (`Driver::frame`'s answer).
    pub status: FrameStatus,
    /// Every body's pose, in the mechanism's body order (`Driver::poses`).
    pub poses: Vec<Pose3>,
}

/// Width of the picture in pixels (the height follows the mechanism).
const WIDTH: f64 = 1000.0;
/// Margin around the picture.
const PAD: f64 = 16.0;
/// Room for the title and subtitle.
const HEADER: f64 = 58.0;
/// Space between the cells of the grid.
const GAP: f64 = 12.0;
/// A cell's strip above its plot: the view's name.
const CELL_HEAD: f64 = 26.0;
/// A cell's strip under its plot: the axes and the scale bar.
const CELL_FOOT: f64 = 44.0;
/// Left and right inset of the plot in its cell.
const INSET: f64 = 8.0;
/// Pixels kept around the drawn world box inside a plot, for the symbols
/// and labels at its edge.
const PLOT_PAD: f64 = 22.0;
/// The smallest plot (a flat view still gets room for its symbols).
const MIN_PLOT_W: f64 = 200.0;
const MIN_PLOT_H: f64 = 130.0;
/// The grid's plots are at most this tall together, as a fraction of the
/// width.
const MAX_PLOTS_H: f64 = 1.15;
/// How many poses to draw at most (the first opaque, the others faint).
const POSES: usize = 5;
/// Mobile bodies times poses drawn, at most: beyond it, fewer poses.
const POSE_BUDGET: usize = 300;
/// The legend lists at most this many entries.
const LEGEND_ENTRIES: usize = 20;
/// Joint names are written when there are at most this many joints.
const NAMED_JOINTS: usize = 24;
/// Size of joint names.
const NAME_FONT: f64 = 10.5;

/// Colours of the axes arrows: x red, y green, z blue, darkened so that
/// they read on white.
const AXIS_COLOURS: [&str; 3] = ["#c62828", "#2e7d32", "#1565c0"];
const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

/// One of the four views.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Projection {
    /// x right, z up, seen from −y.
    Front,
    /// y right, z up, seen from +x.
    Side,
    /// x right, y up, seen from +z.
    Top,
    /// Isometric, seen from (+x, −y, +z): z up.
    Iso,
}

impl Projection {
    /// The views in grid order: row by row, front and side on top.
    pub const GRID: [Projection; 4] = [
        Projection::Front,
        Projection::Side,
        Projection::Top,
        Projection::Iso,
    ];

    /// The `data-view` name.
    pub fn name(self) -> &'static str {
        match self {
            Projection::Front => "front",
            Projection::Side => "side",
            Projection::Top => "top",
            Projection::Iso => "isometric",
        }
    }

    /// The heading of the view: its name, and its plane and direction.
    fn heading(self) -> (&'static str, &'static str) {
        match self {
            Projection::Front => ("Front", "x\u{2013}z plane, seen from \u{2212}y"),
            Projection::Side => ("Side", "y\u{2013}z plane, seen from +x"),
            Projection::Top => ("Top", "x\u{2013}y plane, seen from +z"),
            Projection::Iso => ("Isometric", "seen from (+x, \u{2212}y, +z)"),
        }
    }

    /// The world directions of the page's right and up.
    pub fn basis(self) -> (Vec3, Vec3) {
        let (r2, r6) = (0.5f64.sqrt(), 1.0 / 6f64.sqrt());
        match self {
            Projection::Front => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
            Projection::Side => ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
            Projection::Top => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            Projection::Iso => ([r2, r2, 0.0], [-r6, r6, 2.0 * r6]),
        }
    }

    /// A world point in the view's plane coordinates (right, up), in world
    /// units.
    pub fn project(self, p: Vec3) -> Point {
        let (r, u) = self.basis();
        [dot(p, r), dot(p, u)]
    }

    /// How near a world point is to the viewer (larger is nearer).
    fn depth(self, p: Vec3) -> f64 {
        let (r, u) = self.basis();
        dot(p, dofplan_runtime::spatial::cross(r, u))
    }

    /// A world direction on the page (y down): its length is the
    /// direction's foreshortening.
    fn page_dir(self, d: Vec3) -> Point {
        let [x, y] = self.project(d);
        [x, -y]
    }
}

/// A marker's world position at `poses`, if the ids are valid and it is
/// finite.
fn world(m: &Mechanism, poses: &[Pose3], id: MarkerId) -> Option<Vec3> {
    let marker = m.bodies.get(id.body)?.markers.get(id.marker)?;
    let p = poses.get(id.body)?.world(marker.at);
    p.iter().all(|v| v.is_finite()).then_some(p)
}

/// The world direction of a joint's axis (its first marker's z) at
/// `poses`, if the marker has axes.
fn joint_axis(m: &Mechanism, poses: &[Pose3], id: MarkerId) -> Option<Vec3> {
    let z = m.bodies.get(id.body)?.markers.get(id.marker)?.axes?.z;
    let d = poses.get(id.body)?.dir(z);
    d.iter().all(|v| v.is_finite()).then_some(d)
}

/// Where a joint is drawn: the constrained (second) marker of a joint that
/// slides (it moves along the first marker's line or plane), else the
/// first marker.
fn joint_marker(kind: JointKind, markers: [MarkerId; 2]) -> MarkerId {
    match kind {
        JointKind::Prismatic | JointKind::Cylindrical | JointKind::Helical | JointKind::Planar => markers[1],
        _ => markers[0],
    }
}

/// Drops pose sets identical to an earlier one (a full turn ends where it
/// started), keeping the first.
fn dedupe(m: &Mechanism, sets: &mut Vec<(usize, &[Pose3])>) {
    let tol = 1e-6 * m.size();
    let mut kept: Vec<(usize, &[Pose3])> = Vec::with_capacity(sets.len());
    for &(i, poses) in sets.iter() {
        let same = kept.iter().any(|&(_, other)| {
            m.all_markers()
                .all(|id| match (world(m, other, id), world(m, poses, id)) {
                    (Some(a), Some(b)) => (0..3).all(|k| (a[k] - b[k]).abs() <= tol),
                    (None, None) => true,
                    _ => false,
                })
        });
        if !same {
            kept.push((i, poses));
        }
    }
    *sets = kept;
}

/// How much detail the page has room for (as the planar drawing's
/// `Detail`): symbol sizes shrink with the bodies' length on the page.
#[derive(Clone, Copy, Debug)]
struct Detail {
    /// Factor on every symbol size and line width, 0.35 to 1.
    k: f64,
    /// Whether joint names are written.
    names: bool,
}

impl Detail {
    fn new(m: &Mechanism, scale: f64) -> Detail {
        let mut spans: Vec<f64> = m
            .bodies
            .iter()
            .filter(|b| !b.fixed)
            .map(|b| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for mk in &b.markers {
                    for k in 0..3 {
                        lo[k] = lo[k].min(mk.at[k]);
                        hi[k] = hi[k].max(mk.at[k]);
                    }
                }
                (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
            })
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect();
        spans.sort_by(f64::total_cmp);
        let span = spans.get(spans.len() / 2).copied().unwrap_or_else(|| m.size());
        let px = span * scale;
        let k = if px.is_finite() {
            (px / 60.0).clamp(0.35, 1.0)
        } else {
            1.0
        };
        Detail {
            k,
            names: m.joints.len() <= NAMED_JOINTS && k >= 0.5,
        }
    }

    /// A size in pixels at this detail, never below `min`.
    fn px(&self, full: f64, min: f64) -> f64 {
        (full * self.k).max(min)
    }
}

/// One view placed on the page.
struct Cell {
    proj: Projection,
    view: View,
    /// The cell's box: left, top, width, height.
    left: f64,
    top: f64,
    width: f64,
    height: f64,
}

/// Draws the mechanism in four views at several poses, plus the path of
/// every marker the sweep traces, and returns the SVG text.
///
/// Picks up to five frames evenly spaced through `frames` (the first and
/// the last included; frames that did not meet their input are skipped
/// when there are others, and a last pose equal to the first is dropped),
/// draws the first opaque and the others faint, and draws each traced
/// marker's path through every frame, joined only between consecutive
/// solved (or stretched, dashed) frames, never across a limited or
/// searched one. Never panics: with no frames the drawn pose is shown under
/// a "no frames" title, and non-finite positions are left out.
pub fn render_spatial(m: &Mechanism, frames: &[SpatialFrame]) -> String {
    render_spatial_with(m, frames, &[])
}

/// [`render_spatial`] with `targets` (world points, a synthesis's targets)
/// marked by a ring in every view, the views fitted to hold them, and a
/// legend entry "targets (N points)" after the traces'.
pub fn render_spatial_with(m: &Mechanism, frames: &[SpatialFrame], targets: &[Vec3]) -> String {
    let drawn = vec![Pose3::IDENTITY; m.bodies.len()];
    // Every frame's poses and how it met its input (the drawn pose alone
    // when there are no frames).
    let all: Vec<(&[Pose3], Reach)> = if frames.is_empty() {
        vec![(&drawn[..], Reach::Solved)]
    } else {
        frames
            .iter()
            .map(|f| (&f.poses[..], Reach::of(&f.status)))
            .collect()
    };
    let picked = Picked::new(m, frames, &drawn);
    let cells = layout(m, &view_boxes(m, &all, targets));
    let detail = Detail::new(m, cells[0].view.scale);

    // Traces and legend.
    let traced: Vec<MarkerId> = m
        .sweep
        .as_ref()
        .map(|s| s.trace.clone())
        .unwrap_or_default()
        .into_iter()
        .filter(|id| m.bodies.get(id.body).is_some_and(|b| id.marker < b.markers.len()))
        .collect();
    let entries = legend_entries(m, frames, &traced, &all, targets.len());
    let grid_bottom = cells.iter().map(|c| c.top + c.height).fold(HEADER, f64::max);
    let legend_w = WIDTH - 2.0 * PAD;
    let layout = Layout::new(&entries, legend_w);
    let legend_top = grid_bottom + 14.0;
    let height = legend_top + layout.height() + PAD;

    let shown: Vec<Shown> = frames
        .iter()
        .map(|f| Shown {
            status: &f.status,
            requested: &f.requested,
        })
        .collect();
    let picked_frames: Vec<usize> = if frames.is_empty() {
        Vec::new()
    } else {
        picked.sets.iter().map(|&(i, _)| i).collect()
    };
    let (title, subtitle) = titles_of(
        &m.name,
        &m.inputs,
        m.sweep.as_ref(),
        &shown,
        &picked_frames,
        false,
    );

    let mut doc = page(WIDTH, height, &title).add(Definitions::new().add(hatch_pattern()));
    for text in heading(title, format!("{subtitle}; the four views share one scale"), PAD) {
        doc = doc.add(text);
    }
    for cell in &cells {
        let mut view = draw_view(m, cell, &all, &picked, &traced, detail);
        if !targets.is_empty() {
            let marked: Vec<Point> = targets.iter().map(|&p| cell.proj.project(p)).collect();
            view = view.add(super::marks::marks(&marked, &cell.view));
        }
        doc = doc.add(view);
    }
    doc = doc.add(legend::draw(&entries, &layout, PAD, legend_top));
    doc.to_string()
}

/// The poses drawn, the opaque one first, with the bodies each pulled
/// apart.
struct Picked<'a> {
    /// The frame of each pose drawn, and its poses.
    sets: Vec<(usize, &'a [Pose3])>,
    /// Per frame drawn, the bodies it pulled apart (those of its open
    /// joints and constraints): a stretched frame whose joints hold (a
    /// drag's target out of reach) stitches none.
    opened: Vec<(usize, Vec<bool>)>,
}

impl<'a> Picked<'a> {
    /// Up to [`POSES`] frames evenly spaced through `frames` (fewer for
    /// many bodies), those identical to an earlier one dropped; `drawn`
    /// when there are no frames.
    fn new(m: &Mechanism, frames: &'a [SpatialFrame], drawn: &'a [Pose3]) -> Picked<'a> {
        let mobile = m.moving().max(1);
        let wanted = POSES.min((POSE_BUDGET / mobile).max(1));
        let mut sets: Vec<(usize, &[Pose3])> = if frames.is_empty() {
            vec![(0, drawn)]
        } else {
            pick_of(frames.iter().map(|f| &f.status), wanted)
                .into_iter()
                .map(|i| (i, &frames[i].poses[..]))
                .collect()
        };
        dedupe(m, &mut sets);
        let opened: Vec<(usize, Vec<bool>)> = (sets.iter())
            .map(|&(i, poses)| {
                let stretched = frames
                    .get(i)
                    .is_some_and(|f| matches!(f.status, FrameStatus::Stretched { .. }));
                let open = if stretched {
                    open_bodies(m, poses)
                } else {
                    vec![false; m.bodies.len()]
                };
                (i, open)
            })
            .collect();
        Picked { sets, opened }
    }

    /// The bodies frame `i` pulled apart (none when it is not drawn).
    fn stretched(&self, i: usize) -> &[bool] {
        (self.opened.iter())
            .find(|(k, _)| *k == i)
            .map_or(&[][..], |(_, open)| &open[..])
    }
}

/// The box of everything drawn (every marker in every frame, and the
/// targets), in each view's plane.
fn view_boxes(m: &Mechanism, all: &[(&[Pose3], Reach)], targets: &[Vec3]) -> [BBox; 4] {
    let mut boxes: [BBox; 4] = std::array::from_fn(|_| BBox::new());
    for &p in targets.iter().filter(|p| p.iter().all(|v| v.is_finite())) {
        for (b, proj) in boxes.iter_mut().zip(Projection::GRID) {
            b.add(proj.project(p));
        }
    }
    for (poses, _) in all {
        for id in m.all_markers() {
            if let Some(p) = world(m, poses, id) {
                for (b, proj) in boxes.iter_mut().zip(Projection::GRID) {
                    b.add(proj.project(p));
                }
            }
        }
    }
    boxes
}

/// The legend: traces, the `targets` synthesis points (if any), the
/// marks of stretched and searched frames, the joint kinds drawn, then
/// the bodies, cut to the cap with every entry counted.
fn legend_entries(
    m: &Mechanism,
    frames: &[SpatialFrame],
    traced: &[MarkerId],
    all: &[(&[Pose3], Reach)],
    targets: usize,
) -> Vec<Entry> {
    let mut entries: Vec<Entry> = traced
        .iter()
        .enumerate()
        .map(|(k, &id)| Entry {
            key: Key::Trace(trace_colour(k)),
            label: format!("trace {}", m.marker_name(id)),
        })
        .collect();
    if targets > 0 {
        entries.push(Entry {
            key: Key::Target,
            label: format!("targets ({targets} points)"),
        });
    }
    let worst_stretch = frames
        .iter()
        .filter_map(|f| match f.status {
            FrameStatus::Stretched { residual, .. } => Some(residual),
            _ => None,
        })
        .fold(None, |acc: Option<f64>, r| Some(acc.map_or(r, |a: f64| a.max(r))));
    if let Some(r) = worst_stretch {
        let opened = (frames.iter())
            .filter(|f| matches!(f.status, FrameStatus::Stretched { .. }))
            .any(|f| open_bodies(m, &f.poses).contains(&true));
        entries.push(if opened {
            Entry {
                key: Key::Stretched,
                label: format!("stretched (residual up to {})", super::style::short(r)),
            }
        } else {
            Entry {
                key: Key::Dashed,
                label: format!(
                    "stretched: missed by up to {} (the joints hold)",
                    super::style::short(r)
                ),
            }
        });
    }
    // Searched frames leave a mark only where a traced marker is finite.
    let searched = !traced.is_empty()
        && all.iter().any(|(poses, r)| {
            *r == Reach::Searched && traced.iter().any(|&id| world(m, poses, id).is_some())
        });
    if searched {
        entries.push(Entry {
            key: Key::Searched,
            label: "break point found by search".to_string(),
        });
    }
    for kind in JointKind::ALL {
        if m.joints.iter().any(|j| j.kind == kind) {
            entries.push(Entry {
                key: Key::Joint(kind),
                label: format!("{} joint", kind.name()),
            });
        }
    }
    for (b, body) in m.bodies.iter().enumerate() {
        let label = if body.fixed {
            format!("{} (fixed)", body.name)
        } else {
            body.name.clone()
        };
        let key = if body.fixed {
            Key::Ground
        } else {
            Key::Body(colour_of(&m.bodies, b))
        };
        entries.push(Entry { key, label });
    }
    legend::cap_at(entries, LEGEND_ENTRIES)
}

/// Places the four views: one scale for all, the front and top views in a
/// column of the x range, the front and side views in a row of the z
/// range, as wide as the page allows and at most `MAX_PLOTS_H` of the
/// width tall.
fn layout(m: &Mechanism, boxes: &[BBox; 4]) -> Vec<Cell> {
    let size = m.size();
    // The world box of each view (right, up), with a margin; a flat view
    // still gets some height.
    let windows: Vec<(Point, Point)> = boxes
        .iter()
        .map(|b| {
            if b.lo[0] <= b.hi[0] {
                (b.lo, b.hi)
            } else {
                ([0.0; 2], [0.0; 2])
            }
        })
        .collect();
    let extent = windows
        .iter()
        .flat_map(|(lo, hi)| [hi[0] - lo[0], hi[1] - lo[1]])
        .fold(0.0, f64::max);
    let extent = if extent.is_finite() && extent > 0.0 {
        extent
    } else {
        size
    };
    let windows: Vec<(Point, Point)> = windows
        .into_iter()
        .map(|(mut lo, mut hi)| {
            for k in 0..2 {
                lo[k] -= 0.04 * extent;
                hi[k] += 0.04 * extent;
                let min = 0.15 * extent;
                if hi[k] - lo[k] < min {
                    let c = 0.5 * (hi[k] + lo[k]);
                    lo[k] = c - 0.5 * min;
                    hi[k] = c + 0.5 * min;
                }
            }
            (lo, hi)
        })
        .collect();
    let w = |i: usize| windows[i].1[0] - windows[i].0[0];
    let h = |i: usize| windows[i].1[1] - windows[i].0[1];
    // Columns: front and top (x), side and iso; rows: front and side (z),
    // top and iso.
    let cols = [w(0).max(w(2)), w(1).max(w(3))];
    let rows = [h(0).max(h(1)), h(2).max(h(3))];

    let avail = WIDTH - 2.0 * PAD - GAP - 4.0 * INSET - 4.0 * PLOT_PAD;
    let min_w = MIN_PLOT_W - 2.0 * PLOT_PAD;
    let mut s = avail / (cols[0] + cols[1]);
    // A narrow column gets its least width and the other the rest.
    for (a, b) in [(0, 1), (1, 0)] {
        if cols[a] * s < min_w {
            s = (avail - min_w) / cols[b];
        }
    }
    let max_h = MAX_PLOTS_H * WIDTH - 4.0 * PLOT_PAD;
    s = s.min(max_h / (rows[0] + rows[1]));
    let s = if s.is_finite() && s > 0.0 { s } else { 1.0 };

    let plot_w0 = (cols[0] * s + 2.0 * PLOT_PAD).max(MIN_PLOT_W);
    let plot_ws = [plot_w0, WIDTH - 2.0 * PAD - GAP - 4.0 * INSET - plot_w0];
    let plot_hs = rows.map(|r| (r * s + 2.0 * PLOT_PAD).max(MIN_PLOT_H));
    let mut cells = Vec::with_capacity(4);
    for (i, proj) in Projection::GRID.into_iter().enumerate() {
        let (col, row) = (i % 2, i / 2);
        let left = PAD + col as f64 * (plot_ws[0] + 2.0 * INSET + GAP);
        let top = HEADER + row as f64 * (plot_hs[0] + CELL_HEAD + CELL_FOOT + GAP);
        let (lo, hi) = windows[i];
        let centre = [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])];
        let view = View::centred(
            centre,
            s,
            left + INSET,
            top + CELL_HEAD,
            plot_ws[col],
            plot_hs[row],
        );
        cells.push(Cell {
            proj,
            view,
            left,
            top,
            width: plot_ws[col] + 2.0 * INSET,
            height: CELL_HEAD + plot_hs[row] + CELL_FOOT,
        });
    }
    cells
}

/// One view: its frame and heading, the ground, the faint poses, the
/// traces, the opaque pose, the labels, the axes and the scale bar.
fn draw_view(
    m: &Mechanism,
    cell: &Cell,
    all: &[(&[Pose3], Reach)],
    picked: &Picked,
    traced: &[MarkerId],
    detail: Detail,
) -> Group {
    let proj = cell.proj;
    let view = &cell.view;
    let page = |p: Vec3| view.px(proj.project(p));
    let mut g = add_heading(
        Group::new().set("class", "view").set("data-view", proj.name()),
        cell,
    );
    let Some(&(first_frame, first)) = picked.sets.first() else {
        return g;
    };
    let (ground, ground_boxes) = draw_ground(m, first, proj, view, detail);
    g = g.add(ground);
    g = add_ghosts(g, m, picked, proj, view, detail);

    // Traces through every frame.
    let traces: Vec<trace::Trace> = traced
        .iter()
        .enumerate()
        .map(|(k, &id)| {
            trace::build(
                m.marker_name(id),
                trace_colour(k),
                all.iter()
                    .map(|(poses, reach)| (world(m, poses, id).map(page), *reach)),
            )
        })
        .collect();
    let arrows: Vec<Vec<trace::Arrow>> = traces.iter().map(trace::arrows).collect();
    for (t, a) in traces.iter().zip(&arrows) {
        g = g.add(trace::draw(t, a));
    }

    // The opaque pose, its joints and traced markers.
    let (pose, mut symbols) = opaque_pose(m, first, picked.stretched(first_frame), cell, traced, detail);
    symbols.extend(ground_boxes);
    g = g.add(pose);

    // Labels keep off the bodies, the joints and the traces.
    let mut ink: Vec<[Point; 2]> = if m.moving() * picked.sets.len() <= 200 {
        (picked.sets.iter())
            .flat_map(|(_, poses)| outlines(m, poses, &page))
            .collect()
    } else {
        Vec::new()
    };
    for t in &traces {
        ink.extend(trace::segments(t, 1000));
    }
    // Joint names keep off every symbol; trace names off the joint names
    // and the arrows, and where they can off the symbols too (a chain of
    // hundreds of joints leaves no place free of them).
    let mut taken: Vec<Rect> = Vec::new();
    if detail.names {
        let (names, rects) = joint_names(m, first, &page, view, &symbols, &ink);
        g = g.add(names);
        taken.extend(rects);
    }
    taken.extend(arrows.iter().flatten().map(trace::arrow_box));
    for r in &symbols {
        let corners = [[r[0], r[1]], [r[2], r[1]], [r[2], r[3]], [r[0], r[3]]];
        ink.extend((0..4).map(|i| [corners[i], corners[(i + 1) % 4]]));
    }
    let centre = [view.left + 0.5 * view.plot_w, view.top + 0.5 * view.plot_h];
    g = g.add(trace::labels(&traces, view, centre, &taken, &ink));

    // Axes bottom left, the scale bar bottom right.
    let foot = cell.top + cell.height - CELL_FOOT;
    g = g.add(axes(proj, [cell.left + 20.0, foot + 28.0]));
    if let Some(bar) = view::scale_bar(view, cell.left + cell.width - 12.0, foot + 12.0) {
        g = g.add(bar);
    }
    g
}

/// Adds a view's frame and heading (its name, then its plane and
/// direction) to `g`.
fn add_heading(g: Group, cell: &Cell) -> Group {
    let (name, plane) = cell.proj.heading();
    g.add(
        Rectangle::new()
            .set("class", "view-frame")
            .set("x", num(cell.left))
            .set("y", num(cell.top))
            .set("width", num(cell.width))
            .set("height", num(cell.height))
            .set("rx", 4)
            .set("fill", "#fcfcfc")
            .set("stroke", "#d0d0d0")
            .set("stroke-width", 1),
    )
    .add(
        Text::new(name)
            .set("class", "view-title")
            .set("x", num(cell.left + 10.0))
            .set("y", num(cell.top + 18.0))
            .set("font-size", 14)
            .set("font-weight", "bold")
            .set("fill", INK),
    )
    .add(
        Text::new(plane)
            .set("class", "view-plane")
            .set("x", num(cell.left + 18.0 + text_width(name, 14.0) * 0.95))
            .set("y", num(cell.top + 18.0))
            .set("font-size", 12)
            .set("fill", GREY),
    )
}

/// Adds the faint poses (all but the first) to `g`, latest (faintest)
/// first so that nearer ones lie on top.
fn add_ghosts(
    mut g: Group,
    m: &Mechanism,
    picked: &Picked,
    proj: Projection,
    view: &View,
    detail: Detail,
) -> Group {
    let n = picked.sets.len();
    for (rank, &(i, poses)) in picked.sets.iter().enumerate().skip(1).rev() {
        let opacity = if n > 2 {
            0.42 - 0.22 * (rank - 1) as f64 / (n - 2) as f64
        } else {
            0.4
        };
        let stretched = picked.stretched(i);
        g = g.add(
            draw_bodies(m, poses, proj, view, detail, true, stretched)
                .set(
                    "class",
                    if stretched.contains(&true) {
                        "pose ghost stretched"
                    } else {
                        "pose ghost"
                    },
                )
                .set("opacity", num(opacity)),
        );
    }
    g
}

/// The opaque pose of a view: its bodies (`stretched` those pulled
/// apart), its joints and the traced markers in their colours; with the
/// boxes the joint symbols take (for labels to keep off).
fn opaque_pose(
    m: &Mechanism,
    poses: &[Pose3],
    stretched: &[bool],
    cell: &Cell,
    traced: &[MarkerId],
    detail: Detail,
) -> (Group, Vec<Rect>) {
    let (proj, view) = (cell.proj, &cell.view);
    let pose = draw_bodies(m, poses, proj, view, detail, false, stretched).set(
        "class",
        if stretched.contains(&true) {
            "pose stretched"
        } else {
            "pose"
        },
    );
    let (joints, symbols) = draw_joints(m, poses, proj, view, detail);
    let mut pose = pose.add(joints);
    for (k, &id) in traced.iter().enumerate() {
        if let Some(p) = world(m, poses, id) {
            let q = view.px(proj.project(p));
            pose = pose.add(
                Circle::new()
                    .set("class", "traced")
                    .set("data-marker", m.marker_name(id))
                    .set("cx", num(q[0]))
                    .set("cy", num(q[1]))
                    .set("r", num(detail.px(3.5, 1.5)))
                    .set("fill", trace_colour(k))
                    .set("stroke", "#ffffff")
                    .set("stroke-width", 1),
            );
        }
    }
    (pose, symbols)
}

/// The axes of a view, from `origin`: an arrow per world axis that is not
/// seen end-on, in its colour and named at its tip.
fn axes(proj: Projection, origin: Point) -> Group {
    let mut g = Group::new()
        .set("class", "axes")
        .set("font-size", 12)
        .set("font-weight", "bold");
    const LEN: f64 = 26.0;
    for k in 0..3 {
        let mut e = [0.0; 3];
        e[k] = 1.0;
        let d = proj.page_dir(e);
        let l = d[0].hypot(d[1]);
        if l < 0.2 {
            continue;
        }
        let u = [d[0] / l, d[1] / l];
        let tip = [origin[0] + LEN * d[0], origin[1] + LEN * d[1]];
        let head = trace::arrow_head(
            &trace::Arrow {
                at: [tip[0] - 3.5 * u[0], tip[1] - 3.5 * u[1]],
                dir: u,
            },
            3.5,
            3.0,
        );
        let label = [tip[0] + 8.0 * u[0], tip[1] + 8.0 * u[1] + 4.0];
        g = g
            .add(
                line(origin, [tip[0] - 3.0 * u[0], tip[1] - 3.0 * u[1]])
                    .set("stroke", AXIS_COLOURS[k])
                    .set("stroke-width", 1.5),
            )
            .add(head.set("fill", AXIS_COLOURS[k]))
            .add(
                Text::new(AXIS_NAMES[k])
                    .set("class", "axis-name")
                    .set("x", num(label[0]))
                    .set("y", num(label[1]))
                    .set("text-anchor", "middle")
                    .set("fill", AXIS_COLOURS[k]),
            );
    }
    g.add(
        Circle::new()
            .set("cx", num(origin[0]))
            .set("cy", num(origin[1]))
            .set("r", 1.5)
            .set("fill", INK),
    )
}

/// The page points of a body's markers at `poses`.
fn body_points(m: &Mechanism, poses: &[Pose3], b: usize, page: &dyn Fn(Vec3) -> Point) -> Vec<Point> {
    (0..m.bodies[b].markers.len())
        .filter_map(|i| world(m, poses, MarkerId { body: b, marker: i }))
        .map(page)
        .collect()
}

/// The outlines of the mobile bodies at `poses` as page segments, for
/// labels to keep off.
fn outlines(m: &Mechanism, poses: &[Pose3], page: &dyn Fn(Vec3) -> Point) -> Vec<[Point; 2]> {
    let mut out = Vec::new();
    for (b, body) in m.bodies.iter().enumerate() {
        if body.fixed {
            continue;
        }
        let h = hull(body_points(m, poses, b, page));
        match h.len() {
            0 | 1 => {}
            2 => out.push([h[0], h[1]]),
            n => out.extend((0..n).map(|i| [h[i], h[(i + 1) % n]])),
        }
    }
    out
}

/// The ground: its markers' hull hatched (a dashed line for two markers)
/// and a ground mark under each of its markers. Returns the drawing and
/// the boxes of the marks (for labels to keep off).
fn draw_ground(
    m: &Mechanism,
    poses: &[Pose3],
    proj: Projection,
    view: &View,
    detail: Detail,
) -> (Group, Vec<Rect>) {
    let page = |p: Vec3| view.px(proj.project(p));
    let mut g = Group::new().set("class", "ground");
    let mut boxes: Vec<Rect> = Vec::new();
    let k = detail.k;
    let stroke = num(detail.px(1.2, 0.6));
    for (b, body) in m.bodies.iter().enumerate() {
        if !body.fixed {
            continue;
        }
        let mut bg = Group::new()
            .set("class", "body fixed")
            .set("data-body", body.name.as_str());
        let ps = body_points(m, poses, b, &page);
        let h = hull(ps.clone());
        if h.len() >= 3 {
            bg = bg.add(
                Polygon::new()
                    .set("points", points(&h))
                    .set("fill", format!("url(#{HATCH_ID})"))
                    .set("fill-opacity", 0.6)
                    .set("stroke", GROUND_COLOUR)
                    .set("stroke-width", 1.5)
                    .set("stroke-dasharray", "6 4"),
            );
        } else if h.len() == 2 {
            bg = bg.add(
                line(h[0], h[1])
                    .set("stroke", GROUND_COLOUR)
                    .set("stroke-width", 1.5)
                    .set("stroke-dasharray", "6 4"),
            );
        }
        // A ground mark (the planar drawing's pivot) under each marker.
        let mut done: Vec<Point> = Vec::new();
        let mut marks = Group::new()
            .set("fill", "#d9d9d9")
            .set("stroke", GREY)
            .set("stroke-width", stroke.clone());
        let mut hatch = String::new();
        for q in ps {
            if done
                .iter()
                .any(|d| (d[0] - q[0]).abs() < 1.0 && (d[1] - q[1]).abs() < 1.0)
            {
                continue;
            }
            done.push(q);
            let (x, y) = (q[0], q[1]);
            boxes.push([x - 11.0 * k, y + 2.0 * k, x + 11.0 * k, y + 17.0 * k]);
            marks = marks.add(Polygon::new().set(
                "points",
                points(&[[x, y], [x - 7.0 * k, y + 12.0 * k], [x + 7.0 * k, y + 12.0 * k]]),
            ));
            hatch.push_str(&format!(
                "M{} {}H{}",
                num(x - 11.0 * k),
                num(y + 12.0 * k),
                num(x + 11.0 * k)
            ));
            for i in 0..4 {
                let hx = x + (-7.5 + 5.0 * i as f64) * k;
                hatch.push_str(&format!(
                    "M{} {}L{} {}",
                    num(hx + 4.0 * k),
                    num(y + 12.0 * k),
                    num(hx - 0.5 * k),
                    num(y + 17.0 * k)
                ));
            }
        }
        bg = bg.add(marks);
        if !hatch.is_empty() {
            bg = bg.add(
                Path::new()
                    .set("d", hatch)
                    .set("fill", "none")
                    .set("stroke", GREY)
                    .set("stroke-width", stroke.clone()),
            );
        }
        g = g.add(bg);
    }
    (g, boxes)
}

/// The mobile bodies of one pose, those far from the viewer first: each
/// the hull of its markers in its colour (a bar for markers on a line, a
/// block for markers on one spot). A `ghost` is drawn lighter: outlines
/// and thin bars.
fn draw_bodies(
    m: &Mechanism,
    poses: &[Pose3],
    proj: Projection,
    view: &View,
    detail: Detail,
    ghost: bool,
    stretched: &[bool],
) -> Group {
    let page = |p: Vec3| view.px(proj.project(p));
    let mut g = slide_lines(Group::new(), m, poses, &page, detail, ghost);
    for b in far_first(m, poses, proj) {
        let stretched = stretched.get(b).copied().unwrap_or(false);
        g = g.add(draw_body(m, poses, b, &page, detail, ghost, stretched));
    }
    g
}

/// The mobile bodies of `poses`, those far from the viewer first (by the
/// mean depth of their markers; ties in body order).
fn far_first(m: &Mechanism, poses: &[Pose3], proj: Projection) -> Vec<usize> {
    let mut order: Vec<(f64, usize)> = m
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| !b.fixed)
        .map(|(b, body)| {
            let depths: Vec<f64> = (0..body.markers.len())
                .filter_map(|i| world(m, poses, MarkerId { body: b, marker: i }))
                .map(|p| proj.depth(p))
                .collect();
            let d = if depths.is_empty() {
                0.0
            } else {
                depths.iter().sum::<f64>() / depths.len() as f64
            };
            (d, b)
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    order.into_iter().map(|(_, b)| b).collect()
}

/// Adds to `g` the line of every sliding joint, from its first marker to
/// where the second is, dashed in the first body's colour (the planar
/// drawing's slide lines): it joins a cylinder's barrel to its rod.
fn slide_lines(
    mut g: Group,
    m: &Mechanism,
    poses: &[Pose3],
    page: &dyn Fn(Vec3) -> Point,
    detail: Detail,
    ghost: bool,
) -> Group {
    for j in &m.joints {
        if !matches!(
            j.kind,
            JointKind::Prismatic | JointKind::Cylindrical | JointKind::Helical
        ) {
            continue;
        }
        let (Some(a), Some(b)) = (world(m, poses, j.markers[0]), world(m, poses, j.markers[1])) else {
            continue;
        };
        let (pa, pb) = (page(a), page(b));
        if view::dist(pa, pb) < 1.0 {
            continue;
        }
        g = g.add(
            line(pa, pb)
                .set("class", "slide")
                .set("data-joint", j.name.as_str())
                .set("stroke", colour_of(&m.bodies, j.markers[0].body))
                .set(
                    "stroke-width",
                    num(detail.px(if ghost { 1.0 } else { 1.75 }, 0.75)),
                )
                .set("stroke-dasharray", "6 4"),
        );
    }
    g
}

/// Mobile body `b` of one pose, in its colour: a block for markers on one
/// spot, the hull of its markers, or a bar for markers on a line; lighter
/// for a `ghost`, stitched when `stretched` (pulled apart).
fn draw_body(
    m: &Mechanism,
    poses: &[Pose3],
    b: usize,
    page: &dyn Fn(Vec3) -> Point,
    detail: Detail,
    ghost: bool,
    stretched: bool,
) -> Group {
    let colour = colour_of(&m.bodies, b);
    let ps = body_points(m, poses, b, page);
    let bg = Group::new()
        .set("class", "body")
        .set("data-body", m.bodies[b].name.as_str());
    if ps.is_empty() {
        return bg;
    }
    let h = hull(ps.clone());
    let spread = h
        .iter()
        .flat_map(|a| h.iter().map(move |c| (a[0] - c[0]).hypot(a[1] - c[1])))
        .fold(0.0, f64::max);
    let stitch = |w: f64| {
        move |node: Polygon| {
            if stretched {
                dashed(node, w, true)
            } else {
                node
            }
        }
    };
    if spread < 4.0 {
        // Markers (nearly) on one spot: a block.
        let c = [
            ps.iter().map(|p| p[0]).sum::<f64>() / ps.len() as f64,
            ps.iter().map(|p| p[1]).sum::<f64>() / ps.len() as f64,
        ];
        let r = detail.px(6.0, 2.5);
        let quad = [
            [c[0] - r, c[1] - r],
            [c[0] + r, c[1] - r],
            [c[0] + r, c[1] + r],
            [c[0] - r, c[1] + r],
        ];
        bg.add(stitch(1.5)(
            Polygon::new()
                .set("points", points(&quad))
                .set("fill", colour)
                .set("fill-opacity", if ghost { 0.2 } else { 0.6 })
                .set("stroke", colour)
                .set("stroke-width", num(detail.px(2.0, 1.0))),
        ))
    } else if h.len() >= 3 {
        let w = if ghost {
            detail.px(1.5, 0.75)
        } else {
            detail.px(2.5, 1.0)
        };
        bg.add(stitch(w)(
            Polygon::new()
                .set("points", points(&h))
                .set("fill", colour)
                .set("fill-opacity", if ghost { 0.08 } else { 0.22 })
                .set("stroke", colour)
                .set("stroke-width", num(w))
                .set("stroke-linejoin", "round"),
        ))
    } else {
        // Two markers, or several on one line: a bar.
        let w = if ghost {
            detail.px(3.0, 1.0)
        } else {
            detail.px(6.0, 1.5)
        };
        bg.add(dashed(
            Polyline::new()
                .set("points", points(&h))
                .set("fill", "none")
                .set("stroke", colour)
                .set("stroke-width", num(w))
                .set("stroke-linecap", "round"),
            w,
            stretched,
        ))
    }
}

/// Every joint of one pose as its symbol (nearest the viewer last), and
/// the boxes the symbols take (for labels to keep off).
fn draw_joints(
    m: &Mechanism,
    poses: &[Pose3],
    proj: Projection,
    view: &View,
    detail: Detail,
) -> (Group, Vec<Rect>) {
    let mut order: Vec<(f64, usize, Vec3)> = m
        .joints
        .iter()
        .enumerate()
        .filter_map(|(ji, j)| {
            let p = world(m, poses, joint_marker(j.kind, j.markers))?;
            Some((proj.depth(p), ji, p))
        })
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut g = Group::new().set("class", "joints");
    let mut boxes = Vec::with_capacity(order.len());
    let k = detail.k;
    for (_, ji, p) in order {
        let j = &m.joints[ji];
        let q = view.px(proj.project(p));
        let axis = joint_axis(m, poses, j.markers[0])
            .map(|d| proj.page_dir(d))
            .unwrap_or([1.0, 0.0]);
        let r = 9.0 * k;
        boxes.push([q[0] - r, q[1] - r, q[0] + r, q[1] + r]);
        g = g.add(
            symbol(j.kind, axis, k)
                .set("class", "joint")
                .set("data-joint", j.name.as_str())
                .set("data-kind", j.kind.name())
                .set("transform", format!("translate({} {})", num(q[0]), num(q[1]))),
        );
    }
    (g, boxes)
}

/// The distance from a page point to a box (0 inside it).
fn rect_distance(r: &Rect, p: Point) -> f64 {
    let dx = (r[0] - p[0]).max(p[0] - r[2]).max(0.0);
    let dy = (r[1] - p[1]).max(p[1] - r[3]).max(0.0);
    dx.hypot(dy)
}

/// The joint names beside their symbols: joints on one spot share a label
/// ("B, C"); each label goes where it is off the other labels and the
/// `taken` boxes, inside the plot, preferably off the `ink`, else it is
/// left out. Returns the labels and their boxes.
fn joint_names(
    m: &Mechanism,
    poses: &[Pose3],
    page: &dyn Fn(Vec3) -> Point,
    view: &View,
    taken: &[Rect],
    ink: &[[Point; 2]],
) -> (Group, Vec<Rect>) {
    let mut spots: Vec<(Point, String)> = Vec::new();
    for j in &m.joints {
        let Some(p) = world(m, poses, joint_marker(j.kind, j.markers)) else {
            continue;
        };
        let q = page(p);
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
    let mut g = Group::new()
        .set("class", "joint-names")
        .set("font-size", NAME_FONT)
        .set("fill", "#333333")
        .set("stroke", "#ffffff")
        .set("stroke-width", 3)
        .set("stroke-linejoin", "round")
        .set("paint-order", "stroke");
    // Every spot's candidate places: (anchor point, text-anchor, box).
    let candidates: Vec<Vec<(Point, &str, Rect)>> = spots
        .iter()
        .map(|(q, names)| {
            let w = text_width(names, NAME_FONT);
            let mut out = Vec::new();
            // Above right first, then the other corners and sides; near
            // the symbol, then a little farther.
            for d in [8.0, 13.0, 19.0] {
                for (o, anchor) in [
                    ([d, -d + 2.0], "start"),
                    ([-d, -d + 2.0], "end"),
                    ([d, d + 8.0], "start"),
                    ([-d, d + 8.0], "end"),
                    ([d + 2.0, 4.0], "start"),
                    ([-d - 2.0, 4.0], "end"),
                    ([0.0, -d - 2.0], "middle"),
                    ([0.0, d + 10.0], "middle"),
                ] {
                    let at = [q[0] + o[0], q[1] + o[1]];
                    let left = match anchor {
                        "start" => at[0],
                        "end" => at[0] - w,
                        _ => at[0] - 0.5 * w,
                    };
                    let r: Rect = [left, at[1] - 0.8 * NAME_FONT, left + w, at[1] + 0.25 * NAME_FONT];
                    // Inside the plot, and nearer its own joint than any
                    // other (so that it names the right one).
                    let own = rect_distance(&r, *q);
                    let inside = view.contains([r[0], r[1]]) && view.contains([r[2], r[3]]);
                    if inside
                        && spots
                            .iter()
                            .all(|(p, _)| p == q || rect_distance(&r, *p) > own + 2.0)
                    {
                        out.push((at, anchor, r));
                    }
                }
            }
            out
        })
        .collect();
    let overlaps = |a: &Rect, b: &Rect| a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
    let mut placed: Vec<Rect> = Vec::new();
    let mut todo: Vec<usize> = (0..spots.len()).collect();
    // The spot with the fewest free places goes first, at its first place
    // off the ink (else its first free place); a spot with none is left
    // unnamed.
    while !todo.is_empty() {
        let free = |c: &(Point, &str, Rect)| !placed.iter().chain(taken).any(|o| overlaps(o, &c.2));
        let (at, &spot) = todo
            .iter()
            .enumerate()
            .min_by_key(|(_, &i)| (candidates[i].iter().filter(|c| free(c)).count(), i))
            .expect("todo is not empty");
        todo.remove(at);
        let chosen = candidates[spot]
            .iter()
            .find(|c| free(c) && !ink.iter().any(|s| trace::crosses(&c.2, s[0], s[1])))
            .or_else(|| candidates[spot].iter().find(|c| free(c)));
        let Some(&(p, anchor, r)) = chosen else {
            continue;
        };
        placed.push(r);
        g = g.add(
            Text::new(spots[spot].1.clone())
                .set("class", "joint-name")
                .set("x", num(p[0]))
                .set("y", num(p[1]))
                .set("text-anchor", anchor),
        );
    }
    (g, placed)
}

/// Which bodies of `poses` a joint or constraint pulls apart: a row open
/// by more than 1e-6 of the mechanism's size (lengths) or 1e-6 (sines of
/// angles). Inputs are not counted (a missed input opens no joint).
fn open_bodies(m: &Mechanism, poses: &[Pose3]) -> Vec<bool> {
    let mut open = vec![false; m.bodies.len()];
    if poses.len() != m.bodies.len() {
        return open;
    }
    let size = m.size();
    let at_rest = vec![0.0; m.inputs.len()];
    for e in crate::model::spatial::equations::equations(m) {
        if e.origin.starts_with("input ") {
            continue;
        }
        let tolerance = if e.linear() { 1e-6 * size } else { 1e-6 };
        if e.gap(poses, &at_rest) > tolerance {
            for b in e.bodies {
                open[b] = true;
            }
        }
    }
    open
}
