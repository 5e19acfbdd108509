//! Which poses to draw, and the title and subtitle that say what the
//! picture shows, on the page they head.

use dofplan_runtime::planar::Pose;
use dofplan_runtime::FrameStatus;
use svg::node::element::{Rectangle, Text, Title};
use svg::Document;

use super::planar::mechanism::world;
use super::style::{num, GREY, INK};
use crate::model::{Input, InputKind, Mechanism, Sweep};
use crate::simulate::Frame;

/// Indices of up to `n` frames evenly spaced among those whose pose belongs
/// to their own input (solved or stretched; among all when there are none),
/// the first and the last included, ascending.
pub(super) fn pick_poses(frames: &[Frame], n: usize) -> Vec<usize> {
    pick_of(frames.iter().map(|f| &f.status), n)
}

/// [`pick_poses`] over the frames' statuses alone (the spatial drawing's
/// frames are of another type).
pub(super) fn pick_of<'a>(statuses: impl Iterator<Item = &'a FrameStatus>, n: usize) -> Vec<usize> {
    let statuses: Vec<&FrameStatus> = statuses.collect();
    // Stretched frames count: the input was applied with a step relaxed
    // (a drag's closest approach), and they are drawn marked as such.
    let solved: Vec<usize> = (0..statuses.len())
        .filter(|&i| statuses[i].is_solved() || statuses[i].name() == "stretched")
        .collect();
    let candidates: Vec<usize> = if solved.is_empty() {
        (0..statuses.len()).collect()
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
pub(super) fn dedupe_identical(m: &Mechanism, sets: &mut Vec<&[Pose]>, frames: &mut Vec<usize>, size: f64) {
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
/// poses were drawn, and which one is opaque).
pub(super) fn titles(
    m: &Mechanism,
    frames: &[Frame],
    picked: &[usize],
    last_opaque: bool,
) -> (String, String) {
    let shown: Vec<Shown> = frames
        .iter()
        .map(|f| Shown {
            status: &f.status,
            requested: &f.requested,
        })
        .collect();
    titles_of(&m.name, &m.inputs, m.sweep.as_ref(), &shown, picked, last_opaque)
}

/// What the title and subtitle need of a frame.
pub(super) struct Shown<'a> {
    pub status: &'a FrameStatus,
    /// The inputs requested (one per input of the mechanism, else the
    /// subtitle names frames by number).
    pub requested: &'a [f64],
}

/// [`titles`] for a mechanism of either dimension: its name, inputs and
/// sweep, and what is known of each frame.
pub(super) fn titles_of(
    name: &str,
    inputs: &[Input],
    sweep: Option<&Sweep>,
    frames: &[Shown],
    picked: &[usize],
    last_opaque: bool,
) -> (String, String) {
    if frames.is_empty() {
        return (
            format!("{name} \u{2014} no frames"),
            "no frames: the mechanism is shown as drawn".to_string(),
        );
    }
    let n = frames.len();
    let mut not_solved: Vec<String> = Vec::new();
    for status in ["limited", "searched", "stretched"] {
        let c = frames.iter().filter(|f| f.status.name() == status).count();
        if c > 0 {
            not_solved.push(format!("{c} {status}"));
        }
    }
    let status = if not_solved.is_empty() {
        "all solved".to_string()
    } else {
        not_solved.join(", ")
    };
    let plural = if n == 1 { "frame" } else { "frames" };
    let title = format!("{name} \u{2014} {n} {plural}, {status}");

    let input = sweep.map(|s| s.primary().input).unwrap_or(0);
    // Frames of a drag carry targets, not the mechanism's inputs.
    let of_inputs = frames[0].requested.len() == inputs.len();
    let at = match inputs.get(input).filter(|_| of_inputs) {
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
            let frames = if picked.len() == 1 { "frame" } else { "frames" };
            format!("{frames} {}", values.join(", "))
        }
    };
    let poses = if picked.len() == 1 { "pose" } else { "poses" };
    let order = match (picked.len(), last_opaque) {
        (0 | 1, _) => "",
        (_, false) => " (first opaque, later ones fainter)",
        (_, true) => " (last opaque, earlier ones fainter)",
    };
    let subtitle = format!("{} {poses} at {at}{order}", picked.len());
    (title, subtitle)
}

/// A blank page of `width` × `height` pixels named `title` (what a viewer
/// shows as the file's name), on a white ground.
pub(super) fn page(width: f64, height: f64, title: &str) -> Document {
    Document::new()
        .set("width", num(width))
        .set("height", num(height))
        .set("viewBox", format!("0 0 {} {}", num(width), num(height)))
        .set("font-family", "Helvetica, Arial, sans-serif")
        .add(Title::new(title.to_string()))
        .add(
            Rectangle::new()
                .set("x", 0)
                .set("y", 0)
                .set("width", num(width))
                .set("height", num(height))
                .set("fill", "#ffffff"),
        )
}

/// The title and subtitle written at the page's top, from `left`.
pub(super) fn heading(title: String, subtitle: String, left: f64) -> [Text; 2] {
    [
        Text::new(title)
            .set("x", num(left))
            .set("y", 26)
            .set("font-size", 18)
            .set("font-weight", "bold")
            .set("fill", INK),
        Text::new(subtitle)
            .set("x", num(left))
            .set("y", 45)
            .set("font-size", 12)
            .set("fill", GREY),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
