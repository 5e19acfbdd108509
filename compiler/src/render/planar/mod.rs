//! Pictures of planar mechanisms: [`render`] draws a simulated sweep or a
//! drag.

mod gears;
pub(super) mod mechanism;
mod slots;
mod target;

#[cfg(test)]
mod tests;

use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::FrameStatus;
use svg::node::element::Group;

use super::caption::{dedupe_identical, heading, page, pick_poses, titles};
use super::legend::{self, Entry, Key, Layout};
use super::style::{num, short, trace_colour};
use super::trace::{self, Reach};
use super::view::{self, BBox, View};
use crate::model::{MarkerId, Mechanism};
use crate::simulate::Frame;
use mechanism::{
    body_colour, draw_ground, draw_pose, hulls, outlines, pin_labels, slide_ranges, valid, world, Detail,
    PoseStyle, Slide,
};

/// Options of the drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct SvgOptions {
    /// How many poses to draw at most (the first and the last frame
    /// included). Mechanisms of many bodies get fewer, so that the poses do
    /// not cover each other into a blur.
    pub poses: usize,
    /// Width of the picture in pixels (the height follows the mechanism).
    pub width: f64,
    /// The targets of a drag, one per frame, in world coordinates: drawn as
    /// the target's path and its final point, and the last pose (the one
    /// that reached for the final target) is drawn opaque. Empty for a
    /// sweep.
    pub targets: Vec<[f64; 2]>,
    /// Points to mark, in world coordinates: a synthesis's targets, drawn
    /// as rings over the traces.
    pub points: Vec<[f64; 2]>,
}

impl Default for SvgOptions {
    fn default() -> Self {
        SvgOptions {
            poses: 6,
            width: 800.0,
            targets: Vec::new(),
            points: Vec::new(),
        }
    }
}

/// Mobile bodies times poses drawn, at most: beyond it, fewer poses.
const POSE_BUDGET: usize = 600;
/// Beyond this many drawn bodies, labels do not look for a place off them
/// (they could not find one, and the search would be slow).
const LABEL_INK_BODIES: usize = 200;
const PAD: f64 = 16.0;
const HEADER: f64 = 56.0;

/// The ground (pivots and fixed slide lines, once, in the first pose of
/// `order`) and every other pose of `order`, fainter and fainter, drawn
/// faintest first so that nearer ones lie on top.
fn ground_and_faint_poses(
    m: &Mechanism,
    pose_sets: &[&[Pose]],
    order: &[usize],
    open_sets: &[Vec<bool>],
    slides: &[Slide],
    view: &View,
    detail: Detail,
) -> Vec<Group> {
    let Some(&first) = order.first() else {
        return Vec::new();
    };
    let mut out = vec![draw_ground(m, pose_sets[first], slides, view, detail)];
    let n = order.len();
    for (rank, &k) in order.iter().enumerate().skip(1).rev() {
        let opacity = if n > 2 {
            0.55 - 0.35 * (rank - 1) as f64 / (n - 2) as f64
        } else {
            0.45
        };
        let style = PoseStyle {
            highlighted: false,
            stretched: &open_sets[k],
        };
        out.push(draw_pose(m, pose_sets[k], slides, view, detail, &[], style).set("opacity", num(opacity)));
    }
    out
}

/// The bounding box of everything drawn, in world units: every marker in
/// every frame, the slides' ends in the drawn poses, the drag targets.
fn drawn_box(
    m: &Mechanism,
    all: &[(&[Pose], Reach)],
    pose_sets: &[&[Pose]],
    slides: &[Slide],
    targets: &[Point],
) -> BBox {
    let mut bbox = BBox::new();
    for (poses, _) in all {
        for id in m.all_markers() {
            if let Some(p) = world(m, poses, id) {
                bbox.add(p);
            }
        }
        gears::extend_box(m, poses, &mut bbox);
        slots::extend_box(m, poses, &mut bbox);
    }
    for poses in pose_sets {
        for s in slides {
            if let Some((a, b)) = s.ends(m, poses) {
                bbox.add(a);
                bbox.add(b);
            }
        }
    }
    for &t in targets {
        bbox.add(t);
    }
    bbox
}

/// The legend's entries, before the cap: traces and the picture's marks
/// (stretched or missed frames, searched break points, the drag target)
/// first, then the bodies.
fn legend_entries(m: &Mechanism, frames: &[Frame], traces: &[trace::Trace], targets: &[Point]) -> Vec<Entry> {
    let drag = !targets.is_empty();
    let mut entries: Vec<Entry> = traces
        .iter()
        .map(|t| Entry {
            key: Key::Trace(t.colour),
            label: format!("trace {}", t.name),
        })
        .collect();
    let stretched: Vec<&Frame> = (frames.iter())
        .filter(|f| matches!(f.status, FrameStatus::Stretched { .. }))
        .collect();
    let worst_stretch = (stretched.iter())
        .filter_map(|f| match f.status {
            FrameStatus::Stretched { residual, .. } => Some(residual),
            _ => None,
        })
        .fold(None, |acc: Option<f64>, r| Some(acc.map_or(r, |a| a.max(r))));
    if let Some(r) = worst_stretch {
        // Stitched bodies only where joints were pulled apart; a stretch
        // whose joints all hold missed only its input or its target.
        let opened = (stretched.iter()).any(|f| open_bodies(m, &f.poses).contains(&true));
        entries.push(if opened {
            Entry {
                key: Key::Stretched,
                label: format!("stretched (residual up to {})", short(r)),
            }
        } else if drag {
            Entry {
                key: Key::Dashed,
                label: format!(
                    "out of reach: up to {} short of the target (the joints hold)",
                    short(r)
                ),
            }
        } else {
            Entry {
                key: Key::Dashed,
                label: format!("input missed by up to {} (the joints hold)", short(r)),
            }
        });
    }
    if traces.iter().any(|t| !t.searched.is_empty()) {
        entries.push(Entry {
            key: Key::Searched,
            label: "break point found by search".to_string(),
        });
    }
    if let Some(t) = targets.last() {
        entries.push(Entry {
            key: Key::Target,
            label: format!("drag target ({}, {}) and its path", num(t[0]), num(t[1])),
        });
    }
    for (b, body) in m.bodies.iter().enumerate() {
        let label = if body.fixed {
            format!("{} (fixed)", body.name)
        } else {
            body.name.clone()
        };
        entries.push(Entry {
            key: Key::Body(body_colour(m, b)),
            label,
        });
    }
    entries
}

/// Draws the mechanism at several poses plus the trace of every marker in
/// `trace`, and returns the SVG text.
///
/// Picks `options.poses` frames evenly spaced through `frames` (the first
/// and the last included; frames that did not meet their input are skipped
/// when there are others), draws one opaque (the first, or for a drag the
/// last) and the others fainter, and draws each traced marker's path
/// through every frame: joined only between consecutive solved (or
/// stretched, dashed) frames, never across a limited or searched frame.
/// Never panics: with no frames the drawn pose is shown under a "no frames"
/// title, and non-finite positions are left out.
pub fn render(m: &Mechanism, frames: &[Frame], trace: &[MarkerId], options: &SvgOptions) -> String {
    let size = m.size();
    let width = if options.width.is_finite() {
        options.width.clamp(200.0, 20_000.0)
    } else {
        800.0
    };
    let drag = !options.targets.is_empty();
    let targets: &[Point] = &options.targets;

    // Every frame's poses and how it met its input (the drawn pose alone
    // when there are no frames).
    let drawn = vec![Pose::IDENTITY; m.bodies.len()];
    let all: Vec<(&[Pose], Reach)> = if frames.is_empty() {
        vec![(&drawn[..], Reach::Solved)]
    } else {
        frames
            .iter()
            .map(|f| (&f.poses[..], Reach::of(&f.status)))
            .collect()
    };
    let mobile = m.bodies.iter().filter(|b| !b.fixed).count().max(1);
    let picked = Picked::new(
        m,
        frames,
        &drawn,
        options.poses.min((POSE_BUDGET / mobile).max(1)),
        drag,
    );
    let slides = slide_ranges(m, all.iter().map(|(p, _)| *p), size);
    let boxed: Vec<Point> = targets.iter().chain(&options.points).copied().collect();
    let bbox = drawn_box(m, &all, &picked.sets, &slides, &boxed);
    let plot_w = width - 2.0 * PAD;
    let view = View::fit(&bbox, size, plot_w, PAD, HEADER);
    let detail = Detail::new(m, &view);

    // Traces, through every frame.
    let trace: Vec<MarkerId> = trace.iter().copied().filter(|&id| valid(m, id)).collect();
    let traces = build_traces(m, &all, &trace, &view);
    let arrows: Vec<Vec<trace::Arrow>> = traces.iter().map(trace::arrows).collect();
    let mut entries = legend_entries(m, frames, &traces, targets);
    if !options.points.is_empty() {
        let label = format!("targets ({} points)", options.points.len());
        entries.insert(
            traces.len(),
            Entry {
                key: Key::Target,
                label,
            },
        );
    }
    let entries = legend::cap(entries);

    // Layout: header, plot, the scale bar's strip, legend.
    let layout = Layout::new(&entries, plot_w);
    let strip_top = HEADER + view.plot_h + 4.0;
    let legend_top = strip_top + view::SCALE_STRIP + 6.0;
    let height = legend_top + layout.height() + PAD;
    let (title, subtitle) = titles(m, frames, &picked.frames, drag && picked.frames.len() > 1);
    let mut doc = page(width, height, &title);

    let traced: Vec<(MarkerId, &str)> = trace
        .iter()
        .copied()
        .zip(traces.iter().map(|t| t.colour))
        .collect();
    for g in ground_and_faint_poses(
        m,
        &picked.sets,
        &picked.order,
        &picked.open,
        &slides,
        &view,
        detail,
    ) {
        doc = doc.add(g);
    }
    for (t, a) in traces.iter().zip(&arrows) {
        doc = doc.add(trace::draw(t, a));
    }
    if let Some(pose) = opaque_pose(m, &picked, &slides, &view, detail, &traced) {
        doc = doc.add(pose);
    }
    if !options.points.is_empty() {
        doc = doc.add(super::marks::marks(&options.points, &view));
    }
    if drag {
        let reached = match (frames.last(), trace.first()) {
            (Some(f), Some(&id)) => world(m, &f.poses, id),
            _ => None,
        };
        doc = doc.add(target::draw(targets, reached, &view));
    }
    for g in labels(m, &picked, &view, detail, &traces, &arrows, centre(&bbox, &view)) {
        doc = doc.add(g);
    }

    // Title, scale bar and legend.
    for text in heading(title, subtitle, PAD) {
        doc = doc.add(text);
    }
    if let Some(bar) = view::scale_bar(&view, width - PAD, strip_top) {
        doc = doc.add(bar);
    }
    doc = doc.add(legend::draw(&entries, &layout, PAD, legend_top));
    doc.to_string()
}

/// The poses drawn: which frames, the bodies each pulled apart, and the
/// order they are drawn in.
struct Picked<'a> {
    /// The pose sets drawn (the drawn pose alone when there are no frames).
    sets: Vec<&'a [Pose]>,
    /// The frame of each set (none when there are no frames).
    frames: Vec<usize>,
    /// Per set, the bodies a stretched frame pulled apart (those of its
    /// open joints); none when the frame is not stretched, or when its
    /// joints hold and only the input or the drag target was missed.
    open: Vec<Vec<bool>>,
    /// Opaque first, then fainter and fainter: along the sweep, or back
    /// from the end of a drag.
    order: Vec<usize>,
}

impl<'a> Picked<'a> {
    /// Up to `wanted` frames evenly spaced through `frames` ([`pick_poses`]),
    /// those identical to an earlier one dropped; `drawn` when there are no
    /// frames.
    fn new(m: &Mechanism, frames: &'a [Frame], drawn: &'a [Pose], wanted: usize, drag: bool) -> Picked<'a> {
        let picked = pick_poses(frames, wanted);
        let mut sets: Vec<&[Pose]> = if frames.is_empty() {
            vec![drawn]
        } else {
            picked.iter().map(|&i| &frames[i].poses[..]).collect()
        };
        let mut picked_frames: Vec<usize> = picked;
        dedupe_identical(m, &mut sets, &mut picked_frames, m.size());
        let open: Vec<Vec<bool>> = (0..sets.len())
            .map(|k| match picked_frames.get(k) {
                Some(&i) if matches!(frames[i].status, FrameStatus::Stretched { .. }) => {
                    open_bodies(m, &frames[i].poses)
                }
                _ => vec![false; m.bodies.len()],
            })
            .collect();
        let order: Vec<usize> = if drag {
            (0..sets.len()).rev().collect()
        } else {
            (0..sets.len()).collect()
        };
        Picked {
            sets,
            frames: picked_frames,
            open,
            order,
        }
    }
}

/// The opaque pose (the first of the order), with the traced markers in
/// their colours; none when no pose is drawn.
fn opaque_pose(
    m: &Mechanism,
    picked: &Picked,
    slides: &[Slide],
    view: &View,
    detail: Detail,
    traced: &[(MarkerId, &str)],
) -> Option<Group> {
    let &first = picked.order.first()?;
    let style = PoseStyle {
        highlighted: true,
        stretched: &picked.open[first],
    };
    Some(draw_pose(
        m,
        picked.sets[first],
        slides,
        view,
        detail,
        traced,
        style,
    ))
}

/// The page point the trace labels are placed around: the middle of what
/// is drawn, or of the plot when nothing finite is.
fn centre(bbox: &BBox, view: &View) -> Point {
    if bbox.lo[0] <= bbox.hi[0] {
        view.px([0.5 * (bbox.lo[0] + bbox.hi[0]), 0.5 * (bbox.lo[1] + bbox.hi[1])])
    } else {
        [view.left + 0.5 * view.plot_w, view.top + 0.5 * view.plot_h]
    }
}

/// The path of every marker of `trace` through every frame of `all`, on
/// the page of `view`.
fn build_traces(
    m: &Mechanism,
    all: &[(&[Pose], Reach)],
    trace: &[MarkerId],
    view: &View,
) -> Vec<trace::Trace> {
    trace
        .iter()
        .enumerate()
        .map(|(k, &id)| {
            trace::build(
                m.marker_name(id),
                trace_colour(k),
                all.iter()
                    .map(|(poses, reach)| (world(m, poses, id).map(|p| view.px(p)), *reach)),
            )
        })
        .collect()
}

/// The labels: the pins' names first (they have few places to go), then
/// the traces' names off them, the pins and the arrows, around `centre`.
/// Both keep off the drawn bodies (unless there are very many) and the
/// traces.
fn labels(
    m: &Mechanism,
    picked: &Picked,
    view: &View,
    detail: Detail,
    traces: &[trace::Trace],
    arrows: &[Vec<trace::Arrow>],
    centre: Point,
) -> Vec<Group> {
    let mobile = m.bodies.iter().filter(|b| !b.fixed).count().max(1);
    let mut ink: Vec<[Point; 2]> = if mobile * picked.sets.len() <= LABEL_INK_BODIES {
        (picked.sets.iter())
            .flat_map(|poses| outlines(m, poses, view))
            .collect()
    } else {
        Vec::new()
    };
    let bodies: Vec<Vec<Point>> = if ink.is_empty() {
        Vec::new()
    } else {
        (picked.sets.iter())
            .flat_map(|poses| hulls(m, poses, view))
            .collect()
    };
    for t in traces {
        ink.extend(trace::segments(t, 1000));
    }
    let mut taken: Vec<trace::Rect> = arrows.iter().flatten().map(trace::arrow_box).collect();
    let mut out = Vec::new();
    if let (Some(&first), true) = (picked.order.first(), detail.names) {
        out.push(pin_labels(m, picked.sets[first], view, &bodies, &ink, &mut taken));
    }
    out.push(trace::labels(traces, view, centre, &taken, &ink));
    out
}

/// A joint or constraint open by more than this, relative to the
/// mechanism's size, was pulled apart (a solved frame's are round-off).
const OPEN: f64 = 1e-6;

/// Which bodies of `poses` a joint or constraint pulls apart (open by more
/// than [`OPEN`] of the mechanism's size): the mark of a stretched frame
/// goes on them only. Inputs are not counted: a drag's frames carry its
/// target, not the inputs, and a missed input opens no joint.
fn open_bodies(m: &Mechanism, poses: &[Pose]) -> Vec<bool> {
    let mut open = vec![false; m.bodies.len()];
    if poses.len() != m.bodies.len() {
        return open;
    }
    let tolerance = OPEN * m.size();
    let at_rest = vec![0.0; m.inputs.len()];
    for r in crate::simulate::residuals(m, poses, &at_rest) {
        if r.value <= tolerance {
            continue;
        }
        let markers = if let Some(name) = r.name.strip_prefix("joint ") {
            m.joints.iter().find(|j| j.name == name).map(|j| j.markers)
        } else if let Some(name) = r.name.strip_prefix("constraint ") {
            m.constraints.iter().find(|c| c.name == name).map(|c| c.markers)
        } else {
            None
        };
        for id in markers.into_iter().flatten() {
            open[id.body] = true;
        }
    }
    open
}
