//! Tests of whole pictures: the SVG is parsed back (with the `svg` crate's
//! reader) and its elements counted and measured against independent
//! facts — the mechanism's own geometry, the frames' statuses, positions
//! recomputed from the poses.

use dofplan_runtime::planar::{Point, Pose, Rot};
use dofplan_runtime::{Break, BreakKind, BreakPolicy, FrameStatus, Options};

use super::*;
use crate::conflict::load_str;
use crate::model::Format;
use crate::render::tests::{parse, texts, with_class, El};

// The bundled files, not copies of them.
const FOURBAR: &str = include_str!("../../../../mechanisms/fourbar.toml");
const ROCKER_ROCKER: &str = include_str!("../../../../mechanisms/rocker_rocker.toml");
const SLIDER_CRANK: &str = include_str!("../../../../mechanisms/slider_crank.toml");
const STRESS_50: &str = include_str!("../../../../mechanisms/stress_50.toml");
const OPEN_CHAIN: &str = include_str!("../../../../mechanisms/drag/open_chain_15.toml");

fn load(text: &str) -> Mechanism {
    load_str("t.toml", text, Format::Toml).expect("the test mechanism loads")
}

fn simulate(m: &Mechanism, steps: usize, breaking: BreakPolicy) -> Vec<Frame> {
    let plan = crate::analysis::analyse(m).plan.expect("closed-form plan");
    crate::simulate::run(
        crate::interp::Interpreter::new(plan),
        Options {
            breaking,
            ..Options::default()
        },
        &crate::simulate::sweep_inputs(m, Some(steps)),
    )
}

fn trace_of(m: &Mechanism) -> Vec<MarkerId> {
    m.sweep.as_ref().map(|s| s.trace.clone()).unwrap_or_default()
}

/// The world-to-page transform, recovered from the ground pivot symbols
/// (whose apex is the pivot) of two fixed markers at known world points:
/// page = (ox + s·x, oy − s·y).
struct Transform {
    s: f64,
    ox: f64,
    oy: f64,
}

impl Transform {
    fn from_ground(els: &[El], a: Point, b: Point) -> Transform {
        let apexes: Vec<Point> = els
            .iter()
            .filter(|e| e.name == "polygon" && e.inside("ground"))
            .map(|e| e.points()[0])
            .collect();
        assert!(apexes.len() >= 2, "{apexes:?}");
        let (pa, pb) = (apexes[0], apexes[1]);
        let s = (pb[0] - pa[0]) / (b[0] - a[0]);
        Transform {
            s,
            ox: pa[0] - s * a[0],
            oy: pa[1] + s * a[1],
        }
    }

    fn px(&self, p: Point) -> Point {
        [self.ox + self.s * p[0], self.oy - self.s * p[1]]
    }
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The distance from `p` to the polyline `line`.
fn to_polyline(p: Point, line: &[Point]) -> f64 {
    if line.len() == 1 {
        return dist(p, line[0]);
    }
    line.windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let d = [b[0] - a[0], b[1] - a[1]];
            let l2 = d[0] * d[0] + d[1] * d[1];
            let t = if l2 > 0.0 {
                (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            dist(p, [a[0] + t * d[0], a[1] + t * d[1]])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Checks that every segment of every trace polyline of `marker` joins two
/// frames whose statuses allow it: each point is matched to the frame whose
/// marker lands there (`page` gives each frame's page point, recomputed
/// from its poses), and every frame from one point's to the next one's must
/// be solved or stretched — never limited or searched. Returns the
/// polylines' frame ranges.
fn assert_no_chord(
    els: &[El],
    frames: &[Frame],
    page: &[Option<Point>],
    marker: &str,
) -> Vec<(usize, usize)> {
    let mut ranges = Vec::new();
    for line in els
        .iter()
        .filter(|e| e.name == "polyline" && e.class().starts_with("trace") && e.attr("data-marker") == marker)
    {
        let pts = line.points();
        let mut prev: Option<usize> = None;
        let mut first = None;
        for p in &pts {
            // The first frame at or after the previous point's that lands
            // here (a closed curve revisits its points).
            let from = prev.unwrap_or(0);
            let i = (from..frames.len())
                .find(|&i| page[i].is_some_and(|q| dist(q, *p) <= 0.05))
                .unwrap_or_else(|| panic!("{p:?} of a {marker} trace is no frame's position"));
            if let Some(j) = prev {
                for (k, f) in frames.iter().enumerate().take(i + 1).skip(j) {
                    let name = f.status.name();
                    assert!(
                        name == "solved" || name == "stretched",
                        "the trace joins frames {j} and {i} across frame {k} ({name})"
                    );
                }
            }
            first.get_or_insert(i);
            prev = Some(i);
        }
        ranges.push((first.unwrap(), prev.unwrap()));
    }
    ranges
}

/// Every frame's page position of a marker.
fn page_points(m: &Mechanism, frames: &[Frame], id: MarkerId, t: &Transform) -> Vec<Option<Point>> {
    frames
        .iter()
        .map(|f| {
            let p = f.poses[id.body].world(m.marker(id).at);
            (p[0].is_finite() && p[1].is_finite()).then(|| t.px(p))
        })
        .collect()
}

#[test]
fn fourbar_from_the_pipeline() {
    let m = load(FOURBAR);
    let frames = simulate(&m, 37, BreakPolicy::Limit);
    assert_eq!(frames.len(), 37);
    let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
    assert!(svg.starts_with("<svg"), "{}", &svg[..40]);
    assert!(svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg, render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    let els = parse(&svg);
    let t = texts(&els);
    assert!(t.contains(&"fourbar \u{2014} 37 frames, all solved"));
    assert!(t.contains(&"trace coupler.P"));
    // 6 poses asked, the last equals the first (a full turn): 5 drawn.
    assert!(t.contains(&"5 poses at theta = 0\u{b0}, 70\u{b0}, 140\u{b0}, 220\u{b0}, 290\u{b0} (first opaque, later ones fainter)"));
    // Four revolute pins in each of the 5 poses, and the traced marker.
    assert_eq!(
        els.iter()
            .filter(|e| e.name == "circle" && e.inside("pose"))
            .count(),
        5 * 4 + 1
    );
    // No stretched pose, no drag target, no searched mark.
    assert!(with_class(&els, "pose stretched").is_empty());
    assert!(with_class(&els, "target").is_empty());
    assert!(with_class(&els, "searched").is_empty());

    // One trace through every frame: the full turn is one run.
    let lines = with_class(&els, "trace");
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].points().len(), 37);
    let tf = Transform::from_ground(&els, [0.0, 0.0], [4.0, 0.0]);
    let p = m.find_marker("coupler.P").unwrap();
    let page = page_points(&m, &frames, p, &tf);
    assert_eq!(assert_no_chord(&els, &frames, &page, "coupler.P"), vec![(0, 36)]);
}

#[test]
fn traces_are_labelled_and_carry_an_arrow_of_motion() {
    let m = load(FOURBAR);
    let frames = simulate(&m, 361, BreakPolicy::Limit);
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    let line = with_class(&els, "trace")[0].points();

    // The label names the marker and sits beside its trace.
    let labels = with_class(&els, "trace-label");
    assert_eq!(labels.len(), 1);
    assert_eq!(labels[0].text, "coupler.P");
    let at = [labels[0].f("x"), labels[0].f("y")];
    let near = to_polyline(at, &line);
    assert!(near <= 24.0, "the label is {near} px from its trace");

    // One arrow, on the trace, pointing the way the frames go: its tip is
    // nearer the points of later frames than of earlier ones.
    let arrows = with_class(&els, "arrow");
    assert_eq!(arrows.len(), 1);
    assert_eq!(arrows[0].attr("data-marker"), "coupler.P");
    let tri = arrows[0].points();
    let centre = [(tri[1][0] + tri[2][0]) / 2.0, (tri[1][1] + tri[2][1]) / 2.0];
    let tip = tri[0];
    let mid = [(centre[0] + tip[0]) / 2.0, (centre[1] + tip[1]) / 2.0];
    assert!(to_polyline(mid, &line) < 1.0, "the arrow is off its trace");
    let i = (0..line.len())
        .min_by(|&a, &b| dist(line[a], mid).total_cmp(&dist(line[b], mid)))
        .unwrap();
    assert!(i > 0 && i + 1 < line.len());
    let along = [line[i + 1][0] - line[i - 1][0], line[i + 1][1] - line[i - 1][1]];
    let points_to = [tip[0] - centre[0], tip[1] - centre[1]];
    assert!(
        along[0] * points_to[0] + along[1] * points_to[1] > 0.0,
        "the arrow points backwards"
    );
}

#[test]
fn the_scale_bar_is_a_round_length_at_the_picture_scale() {
    let m = load(FOURBAR);
    let frames = simulate(&m, 37, BreakPolicy::Limit);
    for width in [300.0, 800.0, 5000.0] {
        let options = SvgOptions {
            width,
            ..SvgOptions::default()
        };
        let els = parse(&render(&m, &frames, &trace_of(&m), &options));
        let groups = with_class(&els, "scale-bar");
        assert_eq!(groups.len(), 1);
        let length: f64 = groups[0].f("data-length");
        // 1, 2 or 5 times a power of ten.
        let exp = length.log10().floor();
        let mantissa = length / 10f64.powf(exp);
        assert!(
            [1.0, 2.0, 5.0].iter().any(|k| (mantissa - k).abs() < 1e-9),
            "{length} is not round"
        );
        let bar = els
            .iter()
            .find(|e| e.name == "line" && e.inside("scale-bar"))
            .unwrap();
        let px = bar.f("x2") - bar.f("x1");
        // Pixels per unit, measured independently between the ground
        // pivots A (0, 0) and D (4, 0).
        let tf = Transform::from_ground(&els, [0.0, 0.0], [4.0, 0.0]);
        assert!(
            (px / length - tf.s).abs() < 0.02 * tf.s / length.max(1.0) + 0.01,
            "{px} px for {length}"
        );
        assert!((40.0..=120.0).contains(&px), "{px}");
        let label = els
            .iter()
            .find(|e| e.name == "text" && e.inside("scale-bar"))
            .unwrap();
        let unit = if length == 1.0 { "unit" } else { "units" };
        assert_eq!(label.text, format!("{} {unit}", groups[0].attr("data-length")));
    }
}

#[test]
fn limited_frames_split_the_trace() {
    // The rocker-rocker's input cannot turn a full turn: sweeping through
    // -180..180 in 73 steps crosses both of its limits.
    let m = load(ROCKER_ROCKER);
    let frames = simulate(&m, 73, BreakPolicy::Limit);
    let statuses: Vec<&str> = frames.iter().map(|f| f.status.name()).collect();
    assert!(statuses.contains(&"limited") && statuses.contains(&"solved"));
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    let tf = Transform::from_ground(&els, [0.0, 0.0], [5.0, 0.0]);
    let p = m.find_marker("coupler.P").unwrap();
    let page = page_points(&m, &frames, p, &tf);
    let ranges = assert_no_chord(&els, &frames, &page, "coupler.P");
    // One polyline per maximal run of consecutive solved frames (of two
    // frames or more), covering it end to end.
    let mut runs = Vec::new();
    let mut i = 0;
    while i < frames.len() {
        if frames[i].status.is_solved() {
            let j = (i..frames.len())
                .take_while(|&k| frames[k].status.is_solved())
                .last()
                .unwrap();
            if j > i {
                runs.push((i, j));
            }
            i = j + 1;
        } else {
            i += 1;
        }
    }
    assert!(!runs.is_empty());
    assert_eq!(ranges, runs);
    // An arrow on every run long enough to carry one, at least one in all.
    assert!(!with_class(&els, "arrow").is_empty());
}

#[test]
fn searched_frames_are_marks_not_joined() {
    let m = load(ROCKER_ROCKER);
    let frames = simulate(&m, 73, BreakPolicy::Search);
    assert!(frames.iter().any(|f| f.status.name() == "searched"));
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    let tf = Transform::from_ground(&els, [0.0, 0.0], [5.0, 0.0]);
    let p = m.find_marker("coupler.P").unwrap();
    let page = page_points(&m, &frames, p, &tf);
    assert_no_chord(&els, &frames, &page, "coupler.P");
    // Every searched frame's position is marked (marks merge within 2 px).
    let marks: Vec<Point> = with_class(&els, "searched")
        .iter()
        .map(|e| [e.f("cx"), e.f("cy")])
        .collect();
    assert!(!marks.is_empty());
    for (i, f) in frames.iter().enumerate() {
        if f.status.name() == "searched" {
            let q = page[i].unwrap();
            assert!(
                marks.iter().any(|mk| dist(*mk, q) <= 2.0 + 0.01),
                "searched frame {i} has no mark"
            );
        }
    }
    assert!(texts(&els).contains(&"break point found by search"));
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
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    let t = texts(&els);
    assert!(t.contains(&"fourbar \u{2014} 10 frames, 3 limited"));
    // Frame 4's coupler is NaN and frames 7..9 are limited: runs 0..=3 and
    // 5..=6.
    let counts: Vec<usize> = with_class(&els, "trace")
        .iter()
        .map(|e| e.points().len())
        .collect();
    assert_eq!(counts, vec![4, 2]);
    // Only solved frames are drawn as poses: 0..=6.
    assert!(t.iter().any(
        |s| s.starts_with("6 poses at theta = 0\u{b0}, 10\u{b0}, 20\u{b0}, 40\u{b0}, 50\u{b0}, 60\u{b0}")
    ));

    // All frames unsolved: poses are still drawn, poses vectors too short
    // and bogus trace ids do not panic.
    for f in &mut frames {
        f.status = limited;
    }
    frames[9].poses.truncate(1);
    let bogus = [MarkerId { body: 9, marker: 0 }, MarkerId { body: 2, marker: 7 }];
    let options = SvgOptions {
        poses: 3,
        width: 300.0,
        targets: vec![[f64::NAN, 1.0]],
        points: vec![[f64::NAN, 0.0]],
    };
    let els = parse(&render(&m, &frames, &bogus, &options));
    assert!(texts(&els).contains(&"fourbar \u{2014} 10 frames, 10 limited"));
    assert!(with_class(&els, "trace").is_empty());
}

#[test]
fn no_frames_still_draws() {
    let m = load(FOURBAR);
    let els = parse(&render(&m, &[], &trace_of(&m), &SvgOptions::default()));
    assert!(texts(&els).contains(&"fourbar \u{2014} no frames"));
    // The drawn pose alone: one point, drawn as a dot, and labelled.
    assert!(with_class(&els, "trace").is_empty());
    assert_eq!(with_class(&els, "trace-point").len(), 1);
    assert_eq!(with_class(&els, "trace-label").len(), 1);
    let none = render(
        &m,
        &[],
        &[],
        &SvgOptions {
            poses: 0,
            width: f64::NAN,
            targets: Vec::new(),
            points: Vec::new(),
        },
    );
    parse(&none);
}

#[test]
fn a_long_sweep_is_thinned_to_what_the_page_shows() {
    let m = load(FOURBAR);
    let frames = simulate(&m, 100_000, BreakPolicy::Limit);
    let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
    let els = parse(&svg);
    let lines = with_class(&els, "trace");
    assert_eq!(lines.len(), 1);
    let line = lines[0].points();
    let length: f64 = line.windows(2).map(|w| dist(w[0], w[1])).sum();
    // At most one point per half pixel of the curve (plus its ends), far
    // fewer than the frames.
    assert!(
        line.len() as f64 <= length / 0.5 + 2.0,
        "{} points on {length} px",
        line.len()
    );
    assert!(line.len() < 5_000, "{} points", line.len());
    assert!(svg.len() < 120_000, "{} bytes", svg.len());
    // And the thinned line still passes within half a pixel (plus the
    // rounding to 0.01 px) of every frame's point.
    let tf = Transform::from_ground(&els, [0.0, 0.0], [4.0, 0.0]);
    let p = m.find_marker("coupler.P").unwrap();
    for (i, q) in page_points(&m, &frames, p, &tf)
        .into_iter()
        .enumerate()
        .step_by(37)
    {
        let d = to_polyline(q.unwrap(), &line);
        assert!(d <= 0.5 + 0.02, "frame {i} is {d} px off the thinned trace");
    }
}

#[test]
fn slider_crank_draws_its_track() {
    let m = load(SLIDER_CRANK);
    let frames = simulate(&m, 73, BreakPolicy::Limit);
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    assert!(els.iter().any(|e| e.attr("stroke-dasharray") == "8 5"));
    let counts: Vec<usize> = with_class(&els, "trace")
        .iter()
        .map(|e| e.points().len())
        .collect();
    // The crank pin's circle keeps all 73 points; the slider goes back and
    // forth on its line, and near its dead centres it moves less than half a
    // pixel from one frame to the next: thinned.
    assert_eq!(counts.len(), 2);
    assert!((60..73).contains(&counts[0]), "{counts:?}");
    assert_eq!(counts[1], 73);
    // Two traces, two labels that do not overlap, two arrows.
    let labels = with_class(&els, "trace-label");
    assert_eq!(labels.len(), 2);
    assert_ne!(
        (labels[0].attr("x"), labels[0].attr("y")),
        (labels[1].attr("x"), labels[1].attr("y"))
    );
    assert_eq!(with_class(&els, "arrow").len(), 2);
}

#[test]
fn stress_50_stays_small() {
    let m = load(STRESS_50);
    let frames = simulate(&m, 361, BreakPolicy::Limit);
    let svg = render(&m, &frames, &trace_of(&m), &SvgOptions::default());
    let els = parse(&svg);
    assert_eq!(with_class(&els, "trace").len(), 2);
    assert!(svg.len() < 300_000, "{} bytes", svg.len());
}

/// A drag of the four-bar's coupler point from its drawn position toward
/// `to`, `steps` targets, under `breaking`.
fn drag_fourbar(to: Point, steps: usize, breaking: BreakPolicy) -> (Mechanism, Vec<Frame>, Vec<[f64; 2]>) {
    let m = load(FOURBAR);
    let p = m.find_marker("coupler.P").unwrap();
    let from = m.marker(p).at;
    let targets: Vec<[f64; 2]> = (0..steps)
        .map(|i| {
            let t = i as f64 / (steps - 1) as f64;
            [from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
        })
        .collect();
    let requested: Vec<Vec<f64>> = targets.iter().map(|t| t.to_vec()).collect();
    let frames = crate::simulate::run(
        crate::numeric::planar::drag::Drag::new(&m, p).unwrap(),
        Options {
            breaking,
            ..Options::default()
        },
        &requested,
    );
    (m, frames, targets)
}

#[test]
fn a_drag_picture_shows_the_target_and_its_path() {
    let (m, frames, targets) = drag_fourbar([-3.0, 5.0], 50, BreakPolicy::Stretch);
    let p = m.find_marker("coupler.P").unwrap();
    let options = SvgOptions {
        targets: targets.clone(),
        ..SvgOptions::default()
    };
    let els = parse(&render(&m, &frames, &[p], &options));
    let tf = Transform::from_ground(&els, [0.0, 0.0], [4.0, 0.0]);
    // The final target, where it was asked for.
    let target = with_class(&els, "target");
    assert_eq!(target.len(), 1);
    assert_eq!((target[0].attr("data-x"), target[0].attr("data-y")), ("-3", "5"));
    let ring = els
        .iter()
        .find(|e| e.name == "circle" && e.inside("target"))
        .unwrap();
    let at = tf.px([-3.0, 5.0]);
    assert!(dist([ring.f("cx"), ring.f("cy")], at) < 0.05);
    // The target's path from the drawn position to the final target.
    let path = with_class(&els, "target-path");
    assert_eq!(path.len(), 1);
    let pts = path[0].points();
    assert!(dist(pts[0], tf.px(targets[0])) < 0.05);
    assert!(dist(*pts.last().unwrap(), at) < 0.05);
    assert!(texts(&els).contains(&"drag target (-3, 5) and its path"));
    // The last pose is the opaque one.
    assert!(texts(&els)
        .iter()
        .any(|t| t.ends_with("(last opaque, earlier ones fainter)")));
}

#[test]
fn stretched_frames_are_dashed_and_in_the_legend() {
    // Hand-made: the four-bar's sweep with its middle frames marked
    // stretched (the runtime sets that status when it relaxes a step).
    // The rocker is pulled off its joints (C and D) in those frames, so the
    // rocker and the coupler are stitched, not the crank.
    let m = load(FOURBAR);
    let rocker = m.bodies.iter().position(|b| b.name == "rocker").unwrap();
    let mut frames = simulate(&m, 37, BreakPolicy::Limit);
    for f in &mut frames[10..20] {
        f.status = FrameStatus::Stretched {
            step: 2,
            residual: 0.0567,
        };
        f.poses[rocker].at[0] += 0.0567;
    }
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    // Solved 0..=9, stretched 9..=20 (its segments touch a stretched
    // frame), solved 20..=36: three polylines meeting end to end.
    let lines: Vec<(&str, usize)> = els
        .iter()
        .filter(|e| e.name == "polyline" && e.class().starts_with("trace"))
        .map(|e| (e.class(), e.points().len()))
        .collect();
    assert_eq!(lines, vec![("trace", 10), ("trace stretched", 12), ("trace", 17)]);
    let stretched = with_class(&els, "trace stretched")[0];
    assert!(!stretched.attr("stroke-dasharray").is_empty());
    // Picked poses at frames 0, 7, 14, 22, 29 (36 repeats 0): the one at
    // frame 14 is stretched, its two bodies off their joints stitched.
    let poses = with_class(&els, "pose stretched");
    assert_eq!(poses.len(), 1);
    let stitches: Vec<&El> = els
        .iter()
        .filter(|e| e.inside("pose stretched") && e.class() == "stitch")
        .collect();
    assert_eq!(stitches.len(), 2);
    assert!(stitches.iter().all(|e| e.attr("stroke-dasharray") == "4 3"));
    assert_eq!(with_class(&els, "stitch").len(), 2);
    assert!(texts(&els).contains(&"stretched (residual up to 0.0567)"));
    let colours: Vec<&str> = stitches
        .iter()
        .map(|e| {
            // The stitch follows its body's outline, drawn just before it.
            let i = els.iter().position(|x| std::ptr::eq(x, *e)).unwrap();
            els[i - 1].attr("stroke")
        })
        .collect();
    let crank = m.bodies.iter().position(|b| b.name == "crank").unwrap();
    assert!(
        !colours.contains(&mechanism::body_colour(&m, crank)),
        "{colours:?}"
    );
    assert!(
        colours.contains(&mechanism::body_colour(&m, rocker)),
        "{colours:?}"
    );
}

/// A stretched frame whose joints all hold (the input, or a drag's target,
/// missed) stitches no body: its trace is dashed and the legend says the
/// joints hold.
#[test]
fn stretched_frames_with_joints_holding_stitch_no_body() {
    let m = load(FOURBAR);
    let mut frames = simulate(&m, 37, BreakPolicy::Limit);
    for f in &mut frames[10..20] {
        f.status = FrameStatus::Stretched {
            step: 2,
            residual: 0.0567,
        };
    }
    let els = parse(&render(&m, &frames, &trace_of(&m), &SvgOptions::default()));
    assert_eq!(with_class(&els, "trace stretched").len(), 1);
    assert!(with_class(&els, "pose stretched").is_empty());
    assert!(with_class(&els, "stitch").is_empty());
    assert!(texts(&els).contains(&"input missed by up to 0.0567 (the joints hold)"));
    // A drag of coupler.P out of reach: the joints hold in every frame.
    let targets: Vec<[f64; 2]> = (0..frames.len())
        .map(|i| [3.0 + i as f64, 3.5 + i as f64])
        .collect();
    let options = SvgOptions {
        targets,
        ..SvgOptions::default()
    };
    let els = parse(&render(&m, &frames, &trace_of(&m), &options));
    assert!(with_class(&els, "stitch").is_empty());
    assert!(texts(&els).contains(&"out of reach: up to 0.0567 short of the target (the joints hold)"));
}

#[test]
fn the_legend_is_capped() {
    let m = load(OPEN_CHAIN);
    assert_eq!(m.bodies.len(), 16);
    let els = parse(&render(&m, &[], &[], &SvgOptions::default()));
    let entries: Vec<&str> = els
        .iter()
        .filter(|e| e.class() == "legend-entry")
        .map(|e| e.text.as_str())
        .collect();
    assert_eq!(entries.len(), 13);
    assert_eq!(entries[0], "ground (fixed)");
    assert_eq!(entries[11], "link_11");
    assert_eq!(entries[12], "\u{2026} and 4 more bodies");
}

#[test]
fn residuals_are_short() {
    assert_eq!(short(0.056712), "0.0567");
    assert_eq!(short(12.3456), "12.3");
    assert_eq!(short(2.0), "2");
    assert_eq!(short(2.1e-7), "2.1e-7");
    assert_eq!(short(0.0), "0");
}

#[test]
fn numbers_are_short() {
    assert_eq!(num(1.0), "1");
    assert_eq!(num(-0.001), "0");
    assert_eq!(num(2.345678), "2.35");
    assert_eq!(num(10.50), "10.5");
    assert_eq!(num(f64::NAN), "0");
}

/// A text's box on the page, from its anchor, baseline and size.
fn text_box(e: &El, size: f64) -> trace::Rect {
    let w = crate::render::style::text_width(&e.text, size);
    let (x, y) = (e.f("x"), e.f("y"));
    let left = if e.attr("text-anchor") == "end" { x - w } else { x };
    [left, y - 0.8 * size, left + w, y + 0.2 * size]
}

/// Pin labels sit off the links where there is room (the rocker-rocker,
/// one pose: every pin has a free corner), and no two labels — pins' or
/// traces' — overlap.
#[test]
fn pin_and_trace_labels_keep_off_links_and_each_other() {
    for (text, steps) in [(ROCKER_ROCKER, 151), (FOURBAR, 37), (SLIDER_CRANK, 37)] {
        let m = load(text);
        let frames = simulate(&m, steps, BreakPolicy::Limit);
        let options = SvgOptions {
            poses: 1,
            ..SvgOptions::default()
        };
        let els = parse(&render(&m, &frames, &trace_of(&m), &options));
        let pins = with_class(&els, "pin-label");
        assert!(!pins.is_empty(), "{}", m.name);
        let traces = with_class(&els, "trace-label");
        let boxes: Vec<trace::Rect> = (pins.iter().map(|e| text_box(e, 11.0)))
            .chain(traces.iter().map(|e| text_box(e, 12.0)))
            .collect();
        for (i, a) in boxes.iter().enumerate() {
            for b in &boxes[i + 1..] {
                assert!(!trace::overlaps(a, b), "{}: {a:?} and {b:?} overlap", m.name);
            }
        }
        // The bars of the one pose drawn.
        let bars: Vec<Vec<Point>> = (els.iter())
            .filter(|e| e.name == "polyline" && e.inside("pose") && e.attr("stroke-linecap") == "round")
            .map(El::points)
            .collect();
        assert!(!bars.is_empty());
        for (e, r) in pins.iter().zip(&boxes) {
            for bar in &bars {
                for s in bar.windows(2) {
                    assert!(
                        !trace::crosses(r, s[0], s[1]),
                        "{}: pin label {:?} lies on a link",
                        m.name,
                        e.text
                    );
                }
            }
        }
    }
}
