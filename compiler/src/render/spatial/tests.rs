//! Tests of the four-view pictures: the SVG is parsed back (with the `svg`
//! crate's reader, through the planar tests' parser) and its elements are
//! checked against independent facts — the file's markers, positions
//! recomputed from the driver's poses under each view's projection written
//! out here, the frames' statuses.

use std::collections::HashMap;

use dofplan_runtime::planar::Point;
use dofplan_runtime::spatial::{Pose3, Vec3};
use dofplan_runtime::{Break, BreakKind, FrameStatus};

use super::super::tests::{parse, texts, with_class, El};
use super::*;
use crate::conflict::load_any_str;
use crate::model::{Format, Model};

// The bundled files, not copies of them.
const RSSR: &str = include_str!("../../../../mechanisms/spatial/rssr.toml");
const STEWART: &str = include_str!("../../../../mechanisms/spatial/stewart.toml");
const SOFA_BED: &str = include_str!("../../../../mechanisms/spatial/sofa_bed.toml");
const EXCAVATOR: &str = include_str!("../../../../mechanisms/spatial/excavator.toml");
const BUNDLED: [(&str, &str); 14] = [
    (
        "bennett",
        include_str!("../../../../mechanisms/spatial/bennett.toml"),
    ),
    (
        "cardan",
        include_str!("../../../../mechanisms/spatial/cardan.toml"),
    ),
    (
        "double_cardan",
        include_str!("../../../../mechanisms/spatial/double_cardan.toml"),
    ),
    ("excavator", EXCAVATOR),
    ("rssr", RSSR),
    ("sofa_bed", SOFA_BED),
    (
        "spatial_stress_10",
        include_str!("../../../../mechanisms/spatial/spatial_stress_10.toml"),
    ),
    (
        "spatial_stress_20",
        include_str!("../../../../mechanisms/spatial/spatial_stress_20.toml"),
    ),
    (
        "spatial_stress_30",
        include_str!("../../../../mechanisms/spatial/spatial_stress_30.toml"),
    ),
    (
        "spatial_stress_50",
        include_str!("../../../../mechanisms/spatial/spatial_stress_50.toml"),
    ),
    (
        "spatial_stress_100",
        include_str!("../../../../mechanisms/spatial/spatial_stress_100.toml"),
    ),
    (
        "spherical_fourbar",
        include_str!("../../../../mechanisms/spatial/spherical_fourbar.toml"),
    ),
    ("stewart", STEWART),
    (
        "tilted_fourbar",
        include_str!("../../../../mechanisms/spatial/tilted_fourbar.toml"),
    ),
];

fn load(text: &str) -> Mechanism {
    match load_any_str("t.toml", text, Format::Toml) {
        Ok(Model::Spatial(m)) => m,
        Ok(Model::Planar(_)) => panic!("a planar file"),
        Err(e) => panic!("{}", e.render(false)),
    }
}

/// The file with its sweep cut to `steps` frames.
fn load_steps(text: &str, steps: usize) -> Mechanism {
    let mut m = load(text);
    m.sweep.as_mut().expect("a sweep").steps = steps;
    m
}

/// The frames of the file's sweep, as `simulate --svg` makes them.
fn sweep(m: &Mechanism) -> Vec<SpatialFrame> {
    let plan = crate::analysis::spatial::analyse(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
    crate::report::spatial::frames::sweep_frames(plan, m.sweep.as_ref().expect("a sweep"), m.inputs.len())
}

/// Each view's projection, written out independently of the renderer:
/// world point → (right, up) in world units.
fn project(view: &str, p: Vec3) -> Point {
    let [x, y, z] = p;
    match view {
        "front" => [x, z],
        "side" => [y, z],
        "top" => [x, y],
        "isometric" => [(x + y) / 2f64.sqrt(), (-x + y + 2.0 * z) / 6f64.sqrt()],
        _ => panic!("no view {view}"),
    }
}

const VIEWS: [&str; 4] = ["front", "side", "top", "isometric"];

/// The elements of the picture by the view they are drawn in (those
/// outside every view, under "").
fn by_view(els: &[El]) -> HashMap<String, Vec<&El>> {
    let mut out: HashMap<String, Vec<&El>> = HashMap::new();
    let mut current = String::new();
    for e in els {
        if e.class() == "view" {
            current = e.attr("data-view").to_string();
            out.entry(current.clone()).or_default();
            continue;
        }
        let key = if e.inside("view") {
            current.clone()
        } else {
            String::new()
        };
        out.entry(key).or_default().push(e);
    }
    out
}

/// The page point a `translate(x y)` puts a symbol at.
fn translate(e: &El) -> Point {
    let t = e.attr("transform");
    let inner = t
        .strip_prefix("translate(")
        .and_then(|t| t.strip_suffix(')'))
        .unwrap_or_else(|| panic!("transform {t:?}"));
    let mut it = inner.split_whitespace().map(|v| v.parse::<f64>().unwrap());
    [it.next().unwrap(), it.next().unwrap()]
}

/// The joint symbols of a view's opaque pose, by joint name.
fn joints_of<'a>(els: &[&'a El]) -> HashMap<String, &'a El> {
    els.iter()
        .filter(|e| e.class() == "joint" && e.inside("pose"))
        .map(|e| (e.attr("data-joint").to_string(), *e))
        .collect()
}

/// A view's world-to-page transform, recovered from two joint symbols at
/// known world points `a` and `b`: page = (ox + s·right, oy − s·up).
struct Transform {
    s: f64,
    ox: f64,
    oy: f64,
    view: &'static str,
}

impl Transform {
    fn from_joints(view: &'static str, els: &[&El], a: (&str, Vec3), b: (&str, Vec3)) -> Transform {
        let joints = joints_of(els);
        let (pa, pb) = (translate(joints[a.0]), translate(joints[b.0]));
        let (wa, wb) = (project(view, a.1), project(view, b.1));
        let world = (wb[0] - wa[0]).hypot(wb[1] - wa[1]);
        let s = (pb[0] - pa[0]).hypot(pb[1] - pa[1]) / world;
        let t = Transform {
            s,
            ox: pa[0] - s * wa[0],
            oy: pa[1] + s * wa[1],
            view,
        };
        // The second point is where the transform puts it (not mirrored).
        assert!(dist(t.px(b.1), pb) < 0.05, "{view}: {:?} vs {pb:?}", t.px(b.1));
        t
    }

    fn px(&self, p: Vec3) -> Point {
        let [u, v] = project(self.view, p);
        [self.ox + self.s * u, self.oy - self.s * v]
    }
}

fn dist(a: Point, b: Point) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The trace polylines of `marker` in a view.
fn trace_lines<'a>(els: &[&'a El], marker: &str) -> Vec<&'a El> {
    els.iter()
        .filter(|e| e.name == "polyline" && e.class().starts_with("trace") && e.attr("data-marker") == marker)
        .copied()
        .collect()
}

/// Checks that `line` is `frames` thinned as the renderer promises: its
/// first point is the first frame's, every point is a later frame's (in
/// order), its last point is the last frame's, and every frame left out
/// lies within half a pixel of the point kept before it. Returns how many
/// points it has.
fn assert_thinned(line: &[Point], frames: &[Point]) -> usize {
    assert!(
        dist(line[0], frames[0]) < 0.02,
        "first point {:?} vs {:?}",
        line[0],
        frames[0]
    );
    let mut k = 0;
    for (i, &f) in frames.iter().enumerate().skip(1) {
        if k + 1 < line.len() && dist(line[k + 1], f) < 0.02 {
            k += 1;
        } else {
            assert!(
                dist(line[k], f) < 0.5 + 0.02 || i == frames.len() - 1,
                "frame {i} ({f:?}) was dropped {} px from the last point kept",
                dist(line[k], f)
            );
        }
    }
    assert_eq!(k + 1, line.len(), "points that are no frame's");
    assert!(dist(*line.last().unwrap(), *frames.last().unwrap()) < 0.02);
    line.len()
}

#[test]
fn render_spatial_draws_four_labelled_views_of_every_body_and_joint() {
    let m = load_steps(RSSR, 37);
    let frames = sweep(&m);
    let svg = render_spatial(&m, &frames);
    assert_eq!(svg, render_spatial(&m, &frames), "deterministic");
    let els = parse(&svg);
    let t = texts(&els);
    assert!(t.contains(&"rssr \u{2014} 37 frames, all solved"), "{t:?}");
    assert!(
        t.iter()
            .any(|s| s.starts_with("4 poses at theta = 0\u{b0}, 90\u{b0}, 180\u{b0}, 270\u{b0}")),
        "{t:?}"
    );
    let views = by_view(&els);
    let names: Vec<&str> = with_class(&els, "view")
        .iter()
        .map(|e| e.attr("data-view"))
        .collect();
    assert_eq!(names, VIEWS);
    for view in VIEWS {
        let els = &views[view];
        // A heading, the axes it shows and a scale bar.
        let headings: Vec<&str> = els
            .iter()
            .filter(|e| e.class() == "view-title")
            .map(|e| e.text.as_str())
            .collect();
        assert_eq!(headings.len(), 1, "{view}");
        assert!(
            view.starts_with(&headings[0].to_lowercase()),
            "{view}: {headings:?}"
        );
        let axes: Vec<&str> = els
            .iter()
            .filter(|e| e.class() == "axis-name")
            .map(|e| e.text.as_str())
            .collect();
        let want: &[&str] = match view {
            "front" => &["x", "z"],
            "side" => &["y", "z"],
            "top" => &["x", "y"],
            _ => &["x", "y", "z"],
        };
        assert_eq!(axes, want, "{view}");
        assert_eq!(
            els.iter().filter(|e| e.class() == "scale-bar").count(),
            1,
            "{view}"
        );

        // Every body in the opaque pose (the ground in its own group), once.
        let mut bodies: Vec<&str> = els
            .iter()
            .filter(|e| e.class() == "body" && e.inside("pose"))
            .map(|e| e.attr("data-body"))
            .collect();
        bodies.sort();
        assert_eq!(bodies, ["coupler", "crank", "rocker"], "{view}");
        let ground: Vec<&str> = els
            .iter()
            .filter(|e| e.class() == "body fixed" && e.inside("ground"))
            .map(|e| e.attr("data-body"))
            .collect();
        assert_eq!(ground, ["ground"], "{view}");
        // Faint poses: three more of every mobile body.
        let ghosts = els
            .iter()
            .filter(|e| e.class() == "body" && e.inside("pose ghost"))
            .count();
        assert_eq!(ghosts, 3 * 3, "{view}");

        // Every joint, with its kind.
        let joints = joints_of(els);
        let mut kinds: Vec<(&str, &str)> = joints
            .iter()
            .map(|(n, e)| (n.as_str(), e.attr("data-kind")))
            .collect();
        kinds.sort();
        assert_eq!(
            kinds,
            [
                ("A", "revolute"),
                ("B", "spherical"),
                ("C", "spherical"),
                ("D", "revolute")
            ],
            "{view}"
        );
    }
    // The legend names the trace, the joint kinds and the bodies.
    let legend: Vec<&str> = els
        .iter()
        .filter(|e| e.class() == "legend-entry")
        .map(|e| e.text.as_str())
        .collect();
    assert_eq!(
        legend,
        [
            "trace coupler.M",
            "revolute joint",
            "spherical joint",
            "ground (fixed)",
            "crank",
            "coupler",
            "rocker"
        ]
    );
}

#[test]
fn render_spatial_projects_every_view_at_one_scale() {
    let m = load_steps(RSSR, 37);
    let frames = sweep(&m);
    let els = parse(&render_spatial(&m, &frames));
    let views = by_view(&els);
    let at = |name: &str| m.marker(m.find_marker(name).unwrap()).at;
    let mut scales = Vec::new();
    let mut transforms = HashMap::new();
    for view in VIEWS {
        let els = &views[view];
        // The transform from the two ground joints, A at the origin.
        let t = Transform::from_joints(view, els, ("A", at("ground.A")), ("D", at("ground.D")));
        // The scale bar says the same scale.
        let bar = els.iter().find(|e| e.class() == "scale-bar").unwrap();
        let length: f64 = bar.attr("data-length").parse().unwrap();
        let l = els
            .iter()
            .find(|e| e.name == "line" && e.inside("scale-bar"))
            .unwrap();
        let px = (l.f("x2") - l.f("x1")).hypot(l.f("y2") - l.f("y1"));
        assert!(
            (px / length - t.s).abs() < 0.01,
            "{view}: bar {} vs {}",
            px / length,
            t.s
        );
        scales.push(t.s);

        // Every joint is drawn at its marker of frame 0, projected.
        for (name, e) in joints_of(els) {
            let j = m.joints.iter().find(|j| j.name == name).unwrap();
            let id = j.markers[0];
            let p = frames[0].poses[id.body].world(m.marker(id).at);
            let q = translate(e);
            assert!(
                dist(t.px(p), q) < 0.02,
                "{view} joint {name}: {q:?} vs {:?}",
                t.px(p)
            );
        }
        // The traced marker's dot, and the trace's every point, are the
        // marker's positions of the frames, projected.
        let id = m.find_marker("coupler.M").unwrap();
        let world = |f: &SpatialFrame| f.poses[id.body].world(m.marker(id).at);
        let dot = els
            .iter()
            .find(|e| e.class() == "traced" && e.attr("data-marker") == "coupler.M")
            .unwrap();
        let q = [dot.f("cx"), dot.f("cy")];
        assert!(dist(q, t.px(world(&frames[0]))) < 0.02, "{view}");
        let lines = trace_lines(els, "coupler.M");
        assert_eq!(lines.len(), 1, "{view}");
        let pages: Vec<Point> = frames.iter().map(|f| t.px(world(f))).collect();
        assert_thinned(&lines[0].points(), &pages);
        transforms.insert(view, t);
    }
    // One scale for all four views.
    for s in &scales {
        assert!((s - scales[0]).abs() < 1e-3 * scales[0], "{scales:?}");
    }
    // The views line up as in a drawing: the top view under the front one
    // on the same x, the side view beside it on the same z.
    let p = at("coupler.C");
    let (front, side, top) = (
        transforms["front"].px(p),
        transforms["side"].px(p),
        transforms["top"].px(p),
    );
    assert!((front[0] - top[0]).abs() < 0.05 && top[1] > front[1]);
    assert!((front[1] - side[1]).abs() < 0.05 && side[0] > front[0]);
}

#[test]
fn render_spatial_trace_has_a_point_per_solved_frame() {
    for steps in [37, 361] {
        let m = load_steps(RSSR, steps);
        let frames = sweep(&m);
        let els = parse(&render_spatial(&m, &frames));
        let views = by_view(&els);
        let id = m.find_marker("coupler.M").unwrap();
        let at = |name: &str| m.marker(m.find_marker(name).unwrap()).at;
        for view in VIEWS {
            let els = &views[view];
            let t = Transform::from_joints(view, els, ("A", at("ground.A")), ("D", at("ground.D")));
            let pages: Vec<Point> = frames
                .iter()
                .map(|f| t.px(f.poses[id.body].world(m.marker(id).at)))
                .collect();
            let lines = trace_lines(els, "coupler.M");
            assert_eq!(lines.len(), 1, "{view}");
            let n = assert_thinned(&lines[0].points(), &pages);
            // Where consecutive frames are over half a pixel apart, none is
            // dropped.
            let spaced = pages.windows(2).all(|w| dist(w[0], w[1]) > 0.55);
            if spaced {
                assert_eq!(n, steps, "{view}");
            } else {
                assert!(n < steps, "{view}");
            }
            if steps == 37 {
                assert!(spaced, "{view}: 37 frames of rssr are far apart");
            }
        }
    }
}

#[test]
fn render_spatial_breaks_the_trace_at_a_broken_frame() {
    let m = load_steps(RSSR, 37);
    let mut frames = sweep(&m);
    // Frame 10 held the last valid pose; frame 20 is not finite at all.
    let brk = Break {
        step: 0,
        kind: BreakKind::NoSolution,
        gap: 0.1,
    };
    frames[10].status = FrameStatus::Limited { brk };
    frames[10].poses = frames[9].poses.clone();
    frames[20].status = FrameStatus::Searched { brk, reached: 0.5 };
    let nan = Pose3 {
        pos: [f64::NAN; 3],
        ..Pose3::IDENTITY
    };
    frames[30].poses = vec![nan; m.bodies.len()];
    let svg = render_spatial(&m, &frames);
    let els = parse(&svg);
    assert!(texts(&els).contains(&"rssr \u{2014} 37 frames, 1 limited, 1 searched"));
    let views = by_view(&els);
    let id = m.find_marker("coupler.M").unwrap();
    let at = |name: &str| m.marker(m.find_marker(name).unwrap()).at;
    for view in VIEWS {
        let els = &views[view];
        let t = Transform::from_joints(view, els, ("A", at("ground.A")), ("D", at("ground.D")));
        let pages: Vec<Point> = frames
            .iter()
            .map(|f| t.px(f.poses[id.body].world(m.marker(id).at)))
            .collect();
        // Runs 0–9, 11–19, 21–29 and 31–36: never across a frame that did
        // not meet its input, nor one with no position.
        let lines = trace_lines(els, "coupler.M");
        let runs: Vec<usize> = lines
            .iter()
            .zip([0..10, 11..20, 21..30, 31..37])
            .map(|(l, r)| assert_thinned(&l.points(), &pages[r]))
            .collect();
        assert_eq!(runs, [10, 9, 9, 6], "{view}");
        // The searched frame is marked where it went.
        let rings: Vec<&&El> = els.iter().filter(|e| e.class() == "searched").collect();
        assert_eq!(rings.len(), 1, "{view}");
        assert!(dist([rings[0].f("cx"), rings[0].f("cy")], pages[20]) < 0.02);
    }
}

#[test]
fn render_spatial_without_frames_shows_the_drawn_pose() {
    let m = load(RSSR);
    let els = parse(&render_spatial(&m, &[]));
    assert!(texts(&els).contains(&"rssr \u{2014} no frames"));
    let views = by_view(&els);
    let at = |name: &str| m.marker(m.find_marker(name).unwrap()).at;
    for view in VIEWS {
        let els = &views[view];
        let t = Transform::from_joints(view, els, ("A", at("ground.A")), ("D", at("ground.D")));
        assert_eq!(joints_of(els).len(), 4);
        // The drawn position of a marker no joint sits on.
        let dot = els.iter().find(|e| e.class() == "traced").unwrap();
        assert!(dist([dot.f("cx"), dot.f("cy")], t.px(at("coupler.M"))) < 0.02);
        assert!(trace_lines(els, "coupler.M").len() <= 1);
        assert!(!els.iter().any(|e| e.inside("pose ghost")));
    }
}

/// The box of a text element, from the renderer's width estimate.
fn text_box(e: &El, font: f64) -> [f64; 4] {
    let w = text_width(&e.text, font);
    let (x, y) = (e.f("x"), e.f("y"));
    let left = match e.attr("text-anchor") {
        "end" => x - w,
        "middle" => x - 0.5 * w,
        _ => x,
    };
    [left, y - 0.8 * font, left + w, y + 0.25 * font]
}

#[test]
fn render_spatial_labels_keep_off_each_other() {
    for text in [STEWART, SOFA_BED, RSSR, EXCAVATOR] {
        let m = load(text);
        let frames = sweep(&m);
        let els = parse(&render_spatial(&m, &frames));
        let views = by_view(&els);
        for view in VIEWS {
            let els = &views[view];
            let mut boxes: Vec<(&str, [f64; 4])> = els
                .iter()
                .filter(|e| e.class() == "joint-name")
                .map(|e| (e.text.as_str(), text_box(e, NAME_FONT)))
                .collect();
            boxes.extend(
                els.iter()
                    .filter(|e| e.class() == "trace-label")
                    .map(|e| (e.text.as_str(), text_box(e, 12.0))),
            );
            assert!(!boxes.is_empty(), "{} {view}", m.name);
            for (i, (a, ra)) in boxes.iter().enumerate() {
                for (b, rb) in &boxes[i + 1..] {
                    let apart = ra[2] <= rb[0] || rb[2] <= ra[0] || ra[3] <= rb[1] || rb[3] <= ra[1];
                    assert!(apart, "{} {view}: {a:?} over {b:?}", m.name);
                }
            }
        }
    }
}

#[test]
fn render_spatial_draws_every_bundled_file() {
    for (name, text) in BUNDLED {
        let m = load(text);
        // A short sweep where the file plans, else the drawn pose.
        let frames = match crate::analysis::spatial::analyse(&m) {
            Ok(_) => {
                let mut short = m.clone();
                if let Some(s) = short.sweep.as_mut() {
                    s.steps = s.steps.min(25);
                }
                sweep(&short)
            }
            Err(_) => Vec::new(),
        };
        let els = parse(&render_spatial(&m, &frames));
        let views = by_view(&els);
        for view in VIEWS {
            let els = &views[view];
            let mut joints: Vec<String> = joints_of(els).into_keys().collect();
            joints.sort();
            let mut want: Vec<String> = m.joints.iter().map(|j| j.name.clone()).collect();
            want.sort();
            assert_eq!(joints, want, "{name} {view}");
            let bodies = els
                .iter()
                .filter(|e| e.class() == "body" && e.inside("pose"))
                .count();
            assert_eq!(bodies, m.moving(), "{name} {view}");
        }
    }
}

/// A stretched frame marks only the bodies whose joints it pulled apart:
/// with every joint holding (a drag's target out of reach) no body is
/// dashed and the legend says the joints hold; with the rocker moved off
/// its joints, the rocker and the coupler (its joint C) are, the crank
/// not.
#[test]
fn render_spatial_marks_only_what_is_stretched() {
    let m = load_steps(RSSR, 37);
    let mut frames = sweep(&m);
    for f in &mut frames {
        f.status = FrameStatus::Stretched {
            step: 3,
            residual: 0.25,
        };
    }
    let els = parse(&render_spatial(&m, &frames));
    assert!(
        els.iter()
            .all(|e| !e.class().contains("stretched") || e.class().starts_with("trace")),
        "no pose marked stretched"
    );
    assert!(texts(&els).contains(&"stretched: missed by up to 0.25 (the joints hold)"));
    let rocker = m.bodies.iter().position(|b| b.name == "rocker").unwrap();
    for f in &mut frames {
        f.poses[rocker].pos[2] += 0.25;
    }
    let els = parse(&render_spatial(&m, &frames));
    assert!(texts(&els).contains(&"stretched (residual up to 0.25)"));
    let dashed: Vec<&str> = (els.iter())
        .filter(|e| {
            e.inside("pose stretched") && !e.attr("stroke-dasharray").is_empty() && e.class() != "slide"
        })
        .map(|e| {
            // The body group it is drawn in.
            e.within
                .iter()
                .rev()
                .find(|c| *c == "body")
                .map_or("", |_| e.attr("stroke"))
        })
        .collect();
    assert!(!dashed.is_empty());
    let crank = m.bodies.iter().position(|b| b.name == "crank").unwrap();
    assert!(!dashed.contains(&colour_of(&m.bodies, crank)), "{dashed:?}");
    assert!(dashed.contains(&colour_of(&m.bodies, rocker)), "{dashed:?}");
}

/// Synthesis targets are one of the legend's entries before it is cut:
/// on a chain of a hundred bodies the legend keeps its cap (the entries
/// shown and one line counting the rest) and still names the targets,
/// right after the trace.
#[test]
fn render_spatial_targets_count_within_the_legend_cap() {
    let (_, text) = BUNDLED
        .iter()
        .find(|(name, _)| *name == "spatial_stress_50")
        .expect("the bundled chain");
    let m = load_steps(text, 3);
    assert!(m.bodies.len() > LEGEND_ENTRIES, "enough bodies to hit the cap");
    let frames = sweep(&m);
    let targets: [Vec3; 2] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
    let svg = render_spatial_with(&m, &frames, &targets);
    let els = parse(&svg);
    let legend: Vec<&str> = els
        .iter()
        .filter(|e| e.class() == "legend-entry")
        .map(|e| e.text.as_str())
        .collect();
    assert_eq!(legend.len(), LEGEND_ENTRIES + 1, "{legend:?}");
    let traces = m.sweep.as_ref().map_or(0, |s| s.trace.len());
    assert_eq!(legend[traces], "targets (2 points)", "{legend:?}");
    assert!(
        legend[LEGEND_ENTRIES].starts_with("\u{2026} and "),
        "the last line counts the rest: {legend:?}"
    );
}
