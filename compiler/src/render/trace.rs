//! The traces: the path of each traced marker through every frame, split at
//! breaks, thinned to what the page can show, with an arrow giving the
//! direction of motion and the marker's name beside it.

use dofplan_runtime::planar::Point;
use dofplan_runtime::FrameStatus;
use svg::node::element::{Circle, Group, Polygon, Polyline, Text};

use super::style::{dashed, num, points, text_width};
use super::view::{dist, View};

/// Points closer than this on the page (pixels) to the last point kept are
/// dropped: the page cannot show them, and a sweep of 100,000 frames would
/// otherwise write 100,000 points.
pub(super) const THIN_PX: f64 = 0.5;
/// Width of a trace line in pixels.
const WIDTH: f64 = 1.75;
/// Searched frames closer than this to an earlier one of the same trace
/// share its mark.
const SEARCHED_MERGE_PX: f64 = 2.0;
/// Runs at least this long on the page carry an arrow.
const ARROW_RUN_PX: f64 = 30.0;

/// What a frame contributes to a trace.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Reach {
    /// The input was met: joined to its solved or stretched neighbours.
    Solved,
    /// The input was applied with a step relaxed (or a drag's closest
    /// approach): joined, drawn dashed.
    Stretched,
    /// Moved to the break point on the way to the input: a mark, never
    /// joined (the frames around it may be far apart in the input).
    Searched,
    /// Held at the last valid pose: nothing new to draw.
    Limited,
}

impl Reach {
    /// The reach of a frame of this status.
    pub fn of(status: &FrameStatus) -> Reach {
        match status {
            FrameStatus::Solved => Reach::Solved,
            FrameStatus::Stretched { .. } => Reach::Stretched,
            FrameStatus::Searched { .. } => Reach::Searched,
            // Unreached: no pose of the run yet, nothing to draw either.
            FrameStatus::Limited { .. } | FrameStatus::Unreached { .. } => Reach::Limited,
        }
    }

    /// Whether the frame's pose belongs to its own input, so a line may
    /// join it to the next frame's.
    fn joins(self) -> bool {
        matches!(self, Reach::Solved | Reach::Stretched)
    }
}

/// Part of a trace drawn as one polyline: consecutive frames that each met
/// their input (or came as close as the joints allow, `stretched`), thinned.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Run {
    /// Page points, at least one.
    pub points: Vec<Point>,
    /// Some frame of every segment was stretched: drawn dashed.
    pub stretched: bool,
}

impl Run {
    /// The length on the page.
    fn length(&self) -> f64 {
        self.points.windows(2).map(|w| dist(w[0], w[1])).sum()
    }

    /// The point `s` pixels along the run (clamped to its ends).
    fn at(&self, s: f64) -> Point {
        let mut left = s.max(0.0);
        for w in self.points.windows(2) {
            let d = dist(w[0], w[1]);
            if left <= d && d > 0.0 {
                let t = left / d;
                return [
                    w[0][0] + t * (w[1][0] - w[0][0]),
                    w[0][1] + t * (w[1][1] - w[0][1]),
                ];
            }
            left -= d;
        }
        *self.points.last().expect("a run has a point")
    }
}

/// One marker's trace, ready to draw.
#[derive(Clone, Debug)]
pub(super) struct Trace {
    /// "body.marker".
    pub name: String,
    pub colour: &'static str,
    pub runs: Vec<Run>,
    /// Where searched frames found the break point (merged when close).
    pub searched: Vec<Point>,
}

/// Builds runs from one page point per frame (`None` when not finite) and
/// the frame's reach.
///
/// A segment joins two consecutive frames only when both joined their
/// input: a limited frame holds an earlier pose and a searched one moves to
/// a break point, so a line through either would be a chord the mechanism
/// never follows. Within a run, points closer than `THIN_PX` to the last one
/// kept are dropped; a run's first and last points are always kept.
pub(super) fn build(
    name: String,
    colour: &'static str,
    frames: impl Iterator<Item = (Option<Point>, Reach)>,
) -> Trace {
    let mut runs: Vec<Run> = Vec::new();
    let mut searched: Vec<Point> = Vec::new();
    // The run being built, and the last point given to it (kept or not).
    let mut open: Option<(Run, Point)> = None;
    let mut previous: Option<(Point, Reach)> = None;
    let close = |open: &mut Option<(Run, Point)>, runs: &mut Vec<Run>| {
        if let Some((mut run, last)) = open.take() {
            if run.points.last() != Some(&last) {
                run.points.push(last);
            }
            runs.push(run);
        }
    };
    for (p, reach) in frames {
        let Some(p) = p.filter(|_| reach.joins()) else {
            close(&mut open, &mut runs);
            if let (Some(q), Reach::Searched) = (p, reach) {
                if !searched.iter().any(|s| dist(*s, q) < SEARCHED_MERGE_PX) {
                    searched.push(q);
                }
            }
            previous = None;
            continue;
        };
        match previous {
            Some((q, before)) => {
                let stretched = reach == Reach::Stretched || before == Reach::Stretched;
                match &mut open {
                    Some((run, last)) if run.stretched == stretched || run.points.len() == 1 => {
                        run.stretched = stretched;
                        if dist(*run.points.last().expect("a run has a point"), p) >= THIN_PX {
                            run.points.push(p);
                        }
                        *last = p;
                    }
                    _ => {
                        // The style changes: the new run starts where the old
                        // one ends, so the two meet.
                        close(&mut open, &mut runs);
                        let mut run = Run {
                            points: vec![q],
                            stretched,
                        };
                        if dist(q, p) >= THIN_PX {
                            run.points.push(p);
                        }
                        open = Some((run, p));
                    }
                }
            }
            None => {
                close(&mut open, &mut runs);
                open = Some((
                    Run {
                        points: vec![p],
                        stretched: reach == Reach::Stretched,
                    },
                    p,
                ));
            }
        }
        previous = Some((p, reach));
    }
    close(&mut open, &mut runs);
    Trace {
        name,
        colour,
        runs,
        searched,
    }
}

/// An arrow of motion: where it sits on the page and its unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Arrow {
    pub at: Point,
    pub dir: Point,
}

/// The arrows of a trace: one at the middle of every run long enough to
/// carry one, or on the longest run when none is.
pub(super) fn arrows(t: &Trace) -> Vec<Arrow> {
    let lengths: Vec<f64> = t.runs.iter().map(Run::length).collect();
    let mut chosen: Vec<usize> = (0..t.runs.len())
        .filter(|&i| lengths[i] >= ARROW_RUN_PX)
        .collect();
    if chosen.is_empty() {
        if let Some(i) = (0..t.runs.len())
            .filter(|&i| lengths[i] > 2.0)
            .max_by(|&a, &b| lengths[a].total_cmp(&lengths[b]))
        {
            chosen.push(i);
        }
    }
    chosen
        .into_iter()
        .filter_map(|i| {
            let run = &t.runs[i];
            let length = lengths[i];
            // The direction over a few pixels, not one (possibly tiny)
            // segment.
            let reach = 6.0f64.min(0.5 * length);
            let probe = |f: f64| {
                let s = f * length;
                let (a, b) = (run.at(s - reach), run.at(s + reach));
                (s, a, b, dist(a, b))
            };
            // Near the middle, but where the path runs straight on: at a
            // turning point (a slider's dead centre) the direction is moot.
            let (s, a, b, d) = ARROW_AT
                .iter()
                .map(|&f| probe(f))
                .find(|&(_, _, _, d)| d >= 1.8 * reach)
                .unwrap_or_else(|| probe(0.5));
            (d > 0.0).then(|| Arrow {
                at: run.at(s),
                dir: [(b[0] - a[0]) / d, (b[1] - a[1]) / d],
            })
        })
        .collect()
}

/// Where along a run (fractions of its length) an arrow may sit, in order
/// of preference.
const ARROW_AT: [f64; 7] = [0.5, 0.25, 0.75, 0.375, 0.625, 0.125, 0.875];

/// Draws a trace: its runs (stretched ones dashed), lone points as dots,
/// searched break points as rings, and its arrows.
pub(super) fn draw(t: &Trace, arrows: &[Arrow]) -> Group {
    let mut g = Group::new()
        .set("class", "trace-group")
        .set("data-marker", t.name.as_str());
    for run in &t.runs {
        if run.points.len() == 1 {
            let p = run.points[0];
            g = g.add(
                Circle::new()
                    .set("class", "trace-point")
                    .set("data-marker", t.name.as_str())
                    .set("cx", num(p[0]))
                    .set("cy", num(p[1]))
                    .set("r", 1.5)
                    .set("fill", t.colour),
            );
            continue;
        }
        let class = if run.stretched { "trace stretched" } else { "trace" };
        g = g.add(dashed(
            Polyline::new()
                .set("class", class)
                .set("data-marker", t.name.as_str())
                .set("points", points(&run.points))
                .set("fill", "none")
                .set("stroke", t.colour)
                .set("stroke-width", WIDTH)
                .set("stroke-linejoin", "round")
                .set("stroke-linecap", "round"),
            WIDTH,
            run.stretched,
        ));
    }
    for p in &t.searched {
        g = g.add(
            Circle::new()
                .set("class", "searched")
                .set("data-marker", t.name.as_str())
                .set("cx", num(p[0]))
                .set("cy", num(p[1]))
                .set("r", 3.5)
                .set("fill", "#ffffff")
                .set("stroke", t.colour)
                .set("stroke-width", 1.5),
        );
    }
    for a in arrows {
        g = g.add(
            arrow_head(a, 7.0, 4.5)
                .set("class", "arrow")
                .set("data-marker", t.name.as_str())
                .set("fill", t.colour)
                .set("stroke", "#ffffff")
                .set("stroke-width", 0.75),
        );
    }
    g
}

/// A filled triangle centred on `a.at` pointing along `a.dir`, `half_len`
/// from centre to tip and `half_width` wide at its base.
pub(super) fn arrow_head(a: &Arrow, half_len: f64, half_width: f64) -> Polygon {
    let [x, y] = a.at;
    let [dx, dy] = a.dir;
    let (nx, ny) = (-dy, dx);
    let tip = [x + dx * half_len, y + dy * half_len];
    let back = [x - dx * half_len, y - dy * half_len];
    Polygon::new().set(
        "points",
        points(&[
            tip,
            [back[0] + nx * half_width, back[1] + ny * half_width],
            [back[0] - nx * half_width, back[1] - ny * half_width],
        ]),
    )
}

/// A box on the page: left, top, right, bottom.
pub(super) type Rect = [f64; 4];

pub(super) fn overlaps(a: &Rect, b: &Rect) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// The size of trace labels.
const LABEL_FONT: f64 = 12.0;

/// Names each trace beside it: at the point of the trace farthest from the
/// mechanism's centre `centre` that leaves its label inside the plot and
/// off the other labels and `obstacles` (the arrows), text set outwards.
///
/// `ink` are the drawn bodies' outlines (page segments): a place off them is
/// preferred, but a label still goes on the bodies rather than nowhere.
pub(super) fn labels(
    traces: &[Trace],
    view: &View,
    centre: Point,
    obstacles: &[Rect],
    ink: &[[Point; 2]],
) -> Group {
    let mut taken: Vec<Rect> = obstacles.to_vec();
    let mut g = Group::new()
        .set("class", "trace-labels")
        .set("font-size", LABEL_FONT)
        .set("font-weight", "bold")
        .set("stroke", "#ffffff")
        .set("stroke-width", 3)
        .set("stroke-linejoin", "round")
        .set("paint-order", "stroke");
    for t in traces {
        let all: Vec<Point> = t
            .runs
            .iter()
            .flat_map(|r| r.points.iter().copied())
            .chain(t.searched.iter().copied())
            .collect();
        if all.is_empty() {
            continue;
        }
        // At most a few hundred candidates, evenly along the trace.
        let stride = all.len().div_ceil(256).max(1);
        let mut candidates: Vec<Point> = all.iter().copied().step_by(stride).collect();
        candidates.sort_by(|a, b| dist(*b, centre).total_cmp(&dist(*a, centre)));
        let w = text_width(&t.name, LABEL_FONT);
        // The label of point `p` set off along unit `u`, anchored at its
        // start or its end: the anchor, the baseline and its box.
        let place = |p: Point, u: Point, start: bool| {
            let o = [p[0] + 9.0 * u[0], p[1] + 9.0 * u[1]];
            // Below the point when set off downwards, above when upwards.
            let baseline = o[1] + 4.0 + 6.0 * u[1];
            let left = if start { o[0] } else { o[0] - w };
            let rect: Rect = [left, baseline - 10.0, left + w, baseline + 3.0];
            (start, o[0], baseline, rect)
        };
        let outward = |p: Point| {
            let d = dist(p, centre);
            let u = if d > 1e-9 {
                [(p[0] - centre[0]) / d, (p[1] - centre[1]) / d]
            } else {
                [1.0, 0.0]
            };
            (u, u[0] >= -0.2)
        };
        let fits = |r: &Rect| view.contains([r[0], r[1]]) && view.contains([r[2], r[3]]);
        // Outwards from the farthest point that has room; else above or
        // below one (reading rightwards or ending at it), left or right.
        let sides: [Option<(Point, bool)>; 7] = [
            None,
            Some(([0.0, -1.0], true)),
            Some(([0.0, -1.0], false)),
            Some(([0.0, 1.0], true)),
            Some(([0.0, 1.0], false)),
            Some(([-1.0, 0.0], false)),
            Some(([1.0, 0.0], true)),
        ];
        let placements = || {
            sides.iter().flat_map(|side| {
                candidates.iter().map(move |&p| {
                    let (u, start) = side.unwrap_or_else(|| outward(p));
                    place(p, u, start)
                })
            })
        };
        let free = |r: &Rect| fits(r) && !taken.iter().any(|o| overlaps(o, r));
        let chosen = placements()
            .find(|(_, _, _, r)| free(r) && !ink.iter().any(|s| crosses(r, s[0], s[1])))
            .or_else(|| placements().find(|(_, _, _, r)| free(r)))
            .unwrap_or_else(|| {
                // Nowhere free: the outermost point, pulled into the plot.
                let (u, start) = outward(candidates[0]);
                let (start, x, y, r) = place(candidates[0], u, start);
                let dx = (view.left - r[0]).max(0.0) - (r[2] - view.left - view.plot_w).max(0.0);
                let dy = (view.top - r[1]).max(0.0) - (r[3] - view.top - view.plot_h).max(0.0);
                (
                    start,
                    x + dx,
                    y + dy,
                    [r[0] + dx, r[1] + dy, r[2] + dx, r[3] + dy],
                )
            });
        let (start, x, y, rect) = chosen;
        taken.push(rect);
        g = g.add(
            Text::new(t.name.clone())
                .set("class", "trace-label")
                .set("data-marker", t.name.as_str())
                .set("x", num(x))
                .set("y", num(y))
                .set("text-anchor", if start { "start" } else { "end" })
                .set("fill", t.colour),
        );
    }
    g
}

/// The trace as at most about `most` page segments (every k-th point of
/// each run, its last one kept), for labels to keep off.
pub(super) fn segments(t: &Trace, most: usize) -> Vec<[Point; 2]> {
    let total: usize = t.runs.iter().map(|r| r.points.len()).sum();
    let stride = total.div_ceil(most.max(1)).max(1);
    let mut out = Vec::new();
    for run in &t.runs {
        let mut kept: Vec<Point> = run.points.iter().copied().step_by(stride).collect();
        let last = *run.points.last().expect("a run has a point");
        if kept.last() != Some(&last) {
            kept.push(last);
        }
        out.extend(kept.windows(2).map(|w| [w[0], w[1]]));
    }
    out
}

/// Whether the segment `a`–`b` meets the box `r` (Liang–Barsky clipping).
pub(super) fn crosses(r: &Rect, a: Point, b: Point) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d[0], a[0] - r[0]),
        (d[0], r[2] - a[0]),
        (-d[1], a[1] - r[1]),
        (d[1], r[3] - a[1]),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// The box an arrow covers, for label placement.
pub(super) fn arrow_box(a: &Arrow) -> Rect {
    [a.at[0] - 8.0, a.at[1] - 8.0, a.at[0] + 8.0, a.at[1] + 8.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(points: &[(Option<Point>, Reach)]) -> Trace {
        build("b.m".into(), "#000", points.iter().copied())
    }

    #[test]
    fn segments_meet_boxes() {
        let r: Rect = [0.0, 0.0, 10.0, 5.0];
        assert!(crosses(&r, [-5.0, 2.0], [15.0, 2.0]));
        assert!(crosses(&r, [2.0, 2.0], [3.0, 3.0]));
        assert!(crosses(&r, [-1.0, -1.0], [11.0, 6.0]));
        assert!(!crosses(&r, [-5.0, 6.0], [15.0, 6.0]));
        assert!(!crosses(&r, [11.0, -10.0], [11.0, 10.0]));
        assert!(!crosses(&r, [-3.0, 4.0], [1.0, 9.0]));
    }

    #[test]
    fn breaks_split_runs() {
        use Reach::*;
        let p = |x: f64| Some([x, 0.0]);
        let t = trace(&[
            (p(0.0), Solved),
            (p(10.0), Solved),
            (p(20.0), Solved),
            // Held: the pose of frame 2 again; the next solved frame is far.
            (p(20.0), Limited),
            (p(20.0), Limited),
            (p(50.0), Solved),
            (p(60.0), Solved),
            (p(65.0), Searched),
            (p(65.1), Searched),
            (p(70.0), Solved),
        ]);
        assert_eq!(
            t.runs,
            vec![
                Run {
                    points: vec![[0.0, 0.0], [10.0, 0.0], [20.0, 0.0]],
                    stretched: false
                },
                Run {
                    points: vec![[50.0, 0.0], [60.0, 0.0]],
                    stretched: false
                },
                Run {
                    points: vec![[70.0, 0.0]],
                    stretched: false
                },
            ]
        );
        // Two searched frames 0.1 px apart share one mark.
        assert_eq!(t.searched, vec![[65.0, 0.0]]);
    }

    #[test]
    fn non_finite_points_split_runs() {
        use Reach::*;
        let t = trace(&[
            (Some([0.0, 0.0]), Solved),
            (None, Solved),
            (Some([9.0, 0.0]), Solved),
        ]);
        assert_eq!(t.runs.len(), 2);
        assert!(t.runs.iter().all(|r| r.points.len() == 1));
    }

    #[test]
    fn stretched_segments_are_their_own_runs_and_meet_the_solved_ones() {
        use Reach::*;
        let p = |x: f64| Some([x, 0.0]);
        let t = trace(&[
            (p(0.0), Solved),
            (p(10.0), Solved),
            (p(20.0), Stretched),
            (p(30.0), Stretched),
            (p(40.0), Solved),
            (p(50.0), Solved),
        ]);
        let styles: Vec<(bool, Vec<f64>)> = t
            .runs
            .iter()
            .map(|r| (r.stretched, r.points.iter().map(|p| p[0]).collect()))
            .collect();
        assert_eq!(
            styles,
            vec![
                (false, vec![0.0, 10.0]),
                (true, vec![10.0, 20.0, 30.0, 40.0]),
                (false, vec![40.0, 50.0]),
            ]
        );
    }

    #[test]
    fn thinning_keeps_ends_and_spacing() {
        // 1,001 points 0.01 px apart along x: 10 px long.
        let pts: Vec<(Option<Point>, Reach)> = (0..=1000)
            .map(|i| (Some([0.01 * i as f64, 0.0]), Reach::Solved))
            .collect();
        let t = trace(&pts);
        assert_eq!(t.runs.len(), 1);
        let run = &t.runs[0];
        assert_eq!(run.points.first(), Some(&[0.0, 0.0]));
        assert_eq!(run.points.last(), Some(&[10.0, 0.0]));
        // One point per half pixel, plus the last.
        assert!((20..=22).contains(&run.points.len()), "{}", run.points.len());
        for w in run.points.windows(2) {
            assert!(dist(w[0], w[1]) >= THIN_PX - 1e-9 || w[1] == [10.0, 0.0]);
        }
    }

    #[test]
    fn arrows_point_along_the_motion() {
        use Reach::*;
        // Right 100 px, then a break, then a 10 px run going up (short: no
        // arrow while a long run has one).
        let mut pts: Vec<(Option<Point>, Reach)> =
            (0..=100).map(|i| (Some([i as f64, 0.0]), Solved)).collect();
        pts.push((None, Limited));
        pts.extend((0..=10).map(|i| (Some([0.0, -(i as f64)]), Solved)));
        let t = trace(&pts);
        let a = arrows(&t);
        assert_eq!(a.len(), 1);
        assert!((a[0].at[0] - 50.0).abs() < 1e-9 && a[0].at[1].abs() < 1e-9);
        assert!((a[0].dir[0] - 1.0).abs() < 1e-12);
        // Alone, the short run gets its arrow, pointing up the page.
        let t = trace(&pts[102..]);
        let a = arrows(&t);
        assert_eq!(a.len(), 1);
        assert!((a[0].dir[1] + 1.0).abs() < 1e-12);
        // A single point has no direction.
        assert!(arrows(&trace(&pts[..1])).is_empty());
    }
}
