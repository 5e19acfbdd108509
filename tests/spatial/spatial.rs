//! Spatial mechanisms end to end: file → model → equations → plan →
//! interpreter, checked against closed forms computed here from the file's
//! markers and against every raw joint residual, never against dofplan's
//! own output.

use std::path::{Path, PathBuf};

use dofplan::analysis::spatial::{analyse, count::count};
use dofplan::interp::spatial::Interpreter;
use dofplan::model::spatial::Mechanism;
use dofplan::model::{Format, Model};
use dofplan::simulate::spatial::residual;
use dofplan::simulate::sweep_requests;
use dofplan::{load_any, load_any_str};
use dofplan_runtime::spatial::{cross, dot, norm, sub};
use dofplan_runtime::{Driver, Options};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/spatial")
        .join(name)
}

fn load(path: &Path) -> Mechanism {
    match load_any(path) {
        Ok(Model::Spatial(m)) => m,
        Ok(Model::Planar(_)) => panic!("{} is planar", path.display()),
        Err(e) => panic!("{}", e.render(false)),
    }
}

/// Runs the file's sweep; every frame solved with every raw residual
/// ≤ 1e-9 of the size. Returns each frame's marker positions by name.
fn sweep(m: &Mechanism) -> Vec<(Vec<f64>, Vec<dofplan_runtime::spatial::Pose3>)> {
    let plan = analyse(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
    let mut driver = Driver::new(Interpreter::new(plan), Options::default());
    let s = m.sweep.as_ref().expect("a sweep");
    let mut out = Vec::new();
    for (i, req) in sweep_requests(s, m.inputs.len()).enumerate() {
        let status = driver.frame(&req);
        assert!(status.is_solved(), "{} frame {i}: {status:?}", m.name);
        let r = residual(m, driver.poses(), driver.inputs());
        assert!(r <= 1e-9, "{} frame {i}: residual {r:e}", m.name);
        out.push((req, driver.poses().to_vec()));
    }
    out
}

#[test]
fn cardan_joint_follows_its_output_law() {
    let m = load(&data("cardan_direct.toml"));
    let shaft1 = m.bodies.iter().position(|b| b.name == "shaft1").unwrap();
    let shaft2 = m.bodies.iter().position(|b| b.name == "shaft2").unwrap();
    let a1 = m.marker(m.find_marker("ground.A1").unwrap()).axes.unwrap().z;
    let a2 = m.marker(m.find_marker("ground.A2").unwrap()).axes.unwrap().z;
    let beta = dot(a1, a2).acos();
    // Shaft angles measured from the drawn yokes, about each shaft's axis.
    let y1 = m.marker(m.find_marker("shaft1.U").unwrap()).axes.unwrap().z;
    let y2 = m.marker(m.find_marker("shaft2.U").unwrap()).axes.unwrap().z;
    let angle =
        |axis: [f64; 3], drawn: [f64; 3], now: [f64; 3]| dot(cross(drawn, now), axis).atan2(dot(drawn, now));
    for (req, poses) in sweep(&m) {
        let t1 = angle(a1, y1, poses[shaft1].dir(y1));
        let t2 = angle(a2, y2, poses[shaft2].dir(y2));
        assert!((t1 - req[0].to_radians()).sin().abs() < 1e-12);
        // tan θ2 = tan θ1 / cos β, written without the poles of tan.
        let law = t2.sin() * t1.cos() * beta.cos() - t1.sin() * t2.cos();
        assert!(law.abs() < 1e-9, "theta1 {}: law off by {law:e}", req[0]);
    }
}

#[test]
fn cardan_counts_name_the_redundant_rows() {
    let m = load(&data("cardan_direct.toml"));
    let c = count(&m);
    // 2 moving bodies, revolute 5 + revolute 5 + universal 4 equations.
    assert_eq!((c.moving, c.equations, c.grubler), (2, 14, -2));
    // Both shafts keep the joint's centre where their axes meet: its three
    // coincident rows are dependent, and the mechanism has one freedom.
    assert_eq!((c.rank, c.mobility, c.redundant_equations), (11, 1, 3));
    assert_eq!(
        c.redundant,
        vec![("joint U".to_string(), "coincident".to_string(), 3)]
    );
    assert_eq!(c.idle_freedoms, 0);
    let plan = analyse(&m).unwrap();
    let checked: usize = plan.redundant().iter().map(|(_, n)| n).sum();
    assert_eq!(
        checked, c.redundant_equations,
        "the plan checks exactly the redundant rows"
    );
    assert_eq!(plan.cluster_size(), (0, 0), "closed form");
}

/// An RSSR four-bar drawn here (a crank-rocker): the coupler spins idle
/// about B–C; every frame closes both spheres and keeps the crank's and
/// rocker's revolutes.
#[test]
fn rssr_plans_in_closed_form_with_an_idle_coupler_spin() {
    // Crank |AB| = 1 about z through the origin; rocker about the axis
    // through D along (1, 0, 1); coupler |BC| chosen so it assembles for
    // every crank angle: C starts on the rocker's circle.
    let text = r#"
name = "rssr"
dimension = 3
[bodies.ground]
fixed = true
markers.A = { at = [0, 0, 0], z = [0, 0, 1] }
markers.D = { at = [1, 5, 0], z = [1, 0, 0] }
[bodies.crank]
markers.A = { at = [0, 0, 0], z = [0, 0, 1] }
markers.B = [1, 0, 0]
[bodies.coupler]
markers = { B = [1, 0, 0], C = [1, 5, 3], M = [1, 2, 2] }
[bodies.rocker]
markers.C = [1, 5, 3]
markers.D = { at = [1, 5, 0], z = [1, 0, 0] }
[joints.A]
kind = "revolute"
markers = ["ground.A", "crank.A"]
[joints.B]
kind = "spherical"
markers = ["crank.B", "coupler.B"]
[joints.C]
kind = "spherical"
markers = ["coupler.C", "rocker.C"]
[joints.D]
kind = "revolute"
markers = ["ground.D", "rocker.D"]
[inputs.theta]
kind = "angle"
joint = "A"
[sweep]
input = "theta"
from = 0.0
to = 360.0
steps = 73
trace = ["coupler.M"]
"#;
    let Ok(Model::Spatial(m)) = load_any_str("rssr.toml", text, Format::Toml) else {
        panic!("loads");
    };
    let c = count(&m);
    assert_eq!(
        (c.grubler, c.mobility, c.redundant_equations, c.idle_freedoms),
        (2, 2, 0, 1)
    );
    let plan = analyse(&m).unwrap();
    assert_eq!(plan.idle.len(), 1);
    assert_eq!(plan.bodies[plan.idle[0].0], "coupler");
    let b = m.find_marker("crank.B").unwrap();
    let cm = m.find_marker("rocker.C").unwrap();
    let len = norm(sub(m.marker(cm).at, m.marker(b).at));
    for (_, poses) in sweep(&m) {
        // The coupler's length, from the crank's and rocker's points alone.
        let pb = poses[b.body].world(m.marker(b).at);
        let pc = poses[cm.body].world(m.marker(cm).at);
        assert!((norm(sub(pc, pb)) - len).abs() < 1e-9);
    }
}

#[test]
fn bad_spatial_input_is_named_with_its_place() {
    let base = |joint: &str| {
        format!(
            r#"name = "bad"
dimension = 3
[bodies.ground]
fixed = true
markers.A = {{ at = [0, 0, 0], z = [0, 0, 1] }}
[bodies.arm]
markers.A = {{ at = [0, 0, 0], z = [0, 1, 0] }}
markers.B = [1, 0]
[joints.A]
{joint}
markers = ["ground.A", "arm.A"]
"#
        )
    };
    let err = |text: &str| match load_any_str("bad.toml", text, Format::Toml) {
        Err(e) => e.render(false),
        Ok(_) => panic!("accepted:\n{text}"),
    };
    let e = err(&base("kind = \"revolute\""));
    assert!(e.contains("bad.toml:8:"), "{e}");
    assert!(e.contains("must have 3 coordinates [x, y, z]"), "{e}");
    let e = err(&base("kind = \"revolute\"").replace("markers.B = [1, 0]", "markers.B = [1, 0, 0]"));
    assert!(e.contains("not parallel as drawn"), "{e}");
    assert!(e.contains("ground.A") && e.contains("arm.A"), "{e}");
    let e = err(&base("kind = \"hinge\"").replace("markers.B = [1, 0]", "markers.B = [1, 0, 0]"));
    assert!(
        e.contains("unknown kind `hinge`") && e.contains("universal"),
        "{e}"
    );
    let e = err(&base("kind = \"revolute\"")
        .replace("markers.B = [1, 0]", "markers.B = [1, 0, 0]")
        .replace("z = [0, 1, 0] }", "z = [0, 0, 1], x = [0, 0.5, 1] }"));
    assert!(e.contains("x is not perpendicular to z"), "{e}");
    let e = err(&format!(
        "{}[inputs.t]\nkind = \"angle\"\njoint = \"A\"\n",
        base("kind = \"spherical\"").replace("markers.B = [1, 0]", "markers.B = [1, 0, 0]")
    ));
    assert!(
        e.contains("an input needs a 1-DOF joint or a cylindrical joint"),
        "{e}"
    );
}

/// Every bundled spatial mechanism plans, and every frame of its sweep is
/// solved with every raw joint residual within 1e-9 of its size.
#[test]
fn every_bundled_spatial_sweep_closes_every_joint() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("mechanisms/spatial");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("mechanisms/spatial")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 9, "{files:?}");
    for f in files {
        let m = load(&f);
        // The 100-loop chain's sweep is long in a debug build: its plan is
        // checked on every tenth frame.
        let mut m = m;
        if let Some(s) = m.sweep.as_mut() {
            s.steps = s.steps.min(91);
        }
        sweep(&m);
    }
}

fn bundled3(name: &str) -> Mechanism {
    load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("mechanisms/spatial/{name}.toml")))
}

fn body(m: &Mechanism, name: &str) -> usize {
    m.bodies.iter().position(|b| b.name == name).unwrap()
}

/// The four-bar drawn in a tilted plane moves exactly as the planar
/// four-bar mapped into that plane: the plane's origin and axes are read
/// from the two files' ground pivots and crank pin, and the planar frames
/// come from the planar plan (its own closed form is tested in classics).
#[test]
fn tilted_fourbar_is_the_planar_fourbar_mapped_into_its_plane() {
    let m3 = bundled3("tilted_fourbar");
    let m2 = dofplan_tests::load("fourbar");
    let at3 = |n: &str| m3.marker(m3.find_marker(n).unwrap()).at;
    let at2 = |n: &str| m2.marker(m2.find_marker(n).unwrap()).at;
    // Planar A = (0, 0), D = (4, 0), B = (1, 1): o = A3, e1 = (DirRef − o)/4,
    // e2 = B3 − o − e1.
    assert_eq!(
        (at2("ground.A"), at2("ground.D"), at2("crank.B")),
        ([0.0, 0.0], [4.0, 0.0], [1.0, 1.0])
    );
    let o = at3("ground.A");
    let e1 = dofplan_runtime::spatial::scale(sub(at3("ground.D"), o), 0.25);
    let e2 = sub(sub(at3("crank.B"), o), e1);
    assert!((norm(e1) - 1.0).abs() < 1e-12 && (norm(e2) - 1.0).abs() < 1e-12 && dot(e1, e2).abs() < 1e-12);
    let map = |p: [f64; 2]| {
        let [x, y] = p;
        [
            o[0] + x * e1[0] + y * e2[0],
            o[1] + x * e1[1] + y * e2[1],
            o[2] + x * e1[2] + y * e2[2],
        ]
    };
    let plan2 = dofplan_tests::plan(&m2);
    let mut d2 = Driver::new(dofplan::interp::Interpreter::new(plan2), Options::default());
    let frames3 = sweep(&m3);
    let s2 = m2.sweep.as_ref().unwrap();
    assert_eq!(frames3.len(), s2.steps);
    for ((req, poses3), req2) in frames3.iter().zip(sweep_requests(s2, m2.inputs.len())) {
        assert_eq!(req, &req2);
        assert!(d2.frame(&req2).is_solved());
        for name in ["coupler.P", "coupler.C", "rocker.C", "crank.B"] {
            let (id2, id3) = (m2.find_marker(name).unwrap(), m3.find_marker(name).unwrap());
            let want = map(d2.poses()[id2.body].world(m2.marker(id2).at));
            let got = poses3[id3.body].world(m3.marker(id3).at);
            assert!(
                norm(sub(got, want)) < 1e-9,
                "{name} at {req:?}: {got:?} vs {want:?}"
            );
        }
    }
}

/// A double Cardan shaft in the Z arrangement turns its output exactly as
/// its input.
#[test]
fn double_cardan_output_equals_input() {
    let m = bundled3("double_cardan");
    let (inp, out) = (body(&m, "input"), body(&m, "output"));
    let axis = m.marker(m.find_marker("ground.A").unwrap()).axes.unwrap().z;
    let y = [0.0, 1.0, 0.0];
    let turned = |p: &dofplan_runtime::spatial::Pose3| {
        let now = p.dir(y);
        dot(cross(y, now), axis).atan2(dot(y, now))
    };
    for (req, poses) in sweep(&m) {
        let (a, b) = (turned(&poses[inp]), turned(&poses[out]));
        assert!(
            (a - b).sin().abs() < 1e-9 && (a - b).cos() > 0.0,
            "theta {}: {a} vs {b}",
            req[0]
        );
        assert!((a - req[0].to_radians()).sin().abs() < 1e-12);
    }
}

/// Every bundled mechanism small enough for it agrees with pure Newton (a
/// second, analysis-free solver on the raw joint equations) on every
/// marker of every body without idle freedom, frame by frame.
#[test]
fn plans_agree_with_pure_newton_on_the_raw_equations() {
    for name in [
        "cardan",
        "double_cardan",
        "rssr",
        "spherical_fourbar",
        "bennett",
        "tilted_fourbar",
        "excavator",
        "sofa_bed",
        "stewart",
    ] {
        let m = bundled3(name);
        let plan = analyse(&m).unwrap();
        let idle: Vec<usize> = plan.idle.iter().map(|(b, _, _)| *b).collect();
        let mut newton = Driver::new(
            Interpreter::new(dofplan::numeric::spatial::pure_newton(&m)),
            Options::default(),
        );
        let frames = sweep(&m);
        for (k, (req, poses)) in frames.iter().enumerate().step_by(3) {
            // Small steps for Newton: every frame up to this one.
            let _ = k;
            let status = newton.frame(req);
            assert!(status.is_solved(), "{name} {req:?}: pure Newton {status:?}");
            for id in m.all_markers() {
                if idle.contains(&id.body) {
                    continue;
                }
                let p = m.marker(id).at;
                let gap = norm(sub(poses[id.body].world(p), newton.poses()[id.body].world(p)));
                assert!(
                    gap < 1e-7 * m.size(),
                    "{name} {} at {req:?}: {gap:e}",
                    m.marker_name(id)
                );
            }
        }
    }
}

/// Dragging a marker with the inputs released: the Stewart platform's tool
/// follows a reachable target exactly; an RSSR's coupler point (one freedom
/// that moves it) comes as close to an unreachable one as the joints allow,
/// and no joint ever opens.
#[test]
fn spatial_drags_follow_the_target_and_keep_every_joint_closed() {
    use dofplan::numeric::spatial::{drag_plan, released};
    use dofplan_runtime::{BreakPolicy, FrameStatus};
    let run = |name: &str, marker: &str, to: [f64; 3], steps: usize| {
        let m = bundled3(name);
        let id = m.find_marker(marker).unwrap();
        let free = released(&m);
        let options = Options {
            breaking: BreakPolicy::Stretch,
            ..Options::default()
        };
        let mut d = Driver::new(Interpreter::new(drag_plan(&m, id)), options);
        let from = m.marker(id).at;
        let mut out = Vec::new();
        for i in 0..steps {
            let t = (i + 1) as f64 / steps as f64;
            let target: Vec<f64> = (0..3).map(|k| from[k] + t * (to[k] - from[k])).collect();
            let status = d.frame(&target);
            let r = residual(&free, d.poses(), &[]);
            assert!(
                r <= 1e-9,
                "{name} frame {i}: a joint opened by {r:e} ({status:?})"
            );
            let at = d.poses()[id.body].world(m.marker(id).at);
            out.push((status, norm(sub(at, [target[0], target[1], target[2]]))));
        }
        (out, from)
    };
    let (frames, _) = run("stewart", "platform.tool", [0.1, 0.1, 1.4], 20);
    for (status, gap) in &frames {
        assert!(status.is_solved() && *gap < 1e-9, "{status:?} {gap:e}");
    }
    let to = [0.5, 2.5, 0.3];
    let (frames, from) = run("rssr", "coupler.M", to, 20);
    let start = norm(sub(from, to));
    let (last, gap) = frames.last().unwrap();
    assert!(matches!(last, FrameStatus::Stretched { .. }), "{last:?}");
    assert!(*gap < start, "approached: {gap} < {start}");
    // A marker the joints leave no motion at all: the RSSR crank's point
    // on its fixed axis. The pin's rows, projected into the joints' motion,
    // are rounding noise there; inverted, they used to open every joint
    // (by 0.11 for a target 0.17 away) and put the marker on the target.
    let to = [0.1, 0.1, 0.1];
    let (frames, from) = run("rssr", "crank.A", to, 4);
    assert_eq!(from, [0.0, 0.0, 0.0]);
    for (i, (status, gap)) in frames.iter().enumerate() {
        let target = norm(to) * (i + 1) as f64 / 4.0;
        assert!(matches!(status, FrameStatus::Stretched { .. }), "{status:?}");
        assert!(
            (gap - target).abs() < 1e-12,
            "frame {i}: the marker moved: {gap} from a target {target} away"
        );
    }
    // Far targets, 50 units off, on the other bundled linkages.
    for (name, marker) in [
        ("tilted_fourbar", "crank.A"),
        ("bennett", "crank.A"),
        ("spherical_fourbar", "crank.A"),
    ] {
        run(name, marker, [50.0, 50.0, 50.0], 10);
    }
}

/// Breaking policies in space: the excavator's boom cylinder pushed far
/// past what its loop can close. Limit holds the last pose, search stops at
/// the reachable boundary (a little further breaks), stretch relaxes the
/// intersection and reports the gap — and no policy reports a solved frame
/// with an open joint.
#[test]
fn breaking_policies_hold_search_and_stretch_in_space() {
    use dofplan_runtime::{BranchPolicy, BreakPolicy, FrameStatus};
    let m = bundled3("excavator");
    let plan = analyse(&m).unwrap();
    let boom = m.inputs.iter().position(|i| i.name == "boom_cyl").unwrap();
    let mut far = vec![0.0; m.inputs.len()];
    far[boom] = 10.0;
    for breaking in [BreakPolicy::Limit, BreakPolicy::Search, BreakPolicy::Stretch] {
        let options = Options {
            breaking,
            branch: BranchPolicy::Keep,
            ..Options::default()
        };
        let mut d = Driver::new(Interpreter::new(plan.clone()), options);
        let status = d.frame(&far);
        match (breaking, status) {
            (BreakPolicy::Limit, FrameStatus::Limited { .. }) => {
                assert_eq!(
                    d.inputs(),
                    &vec![0.0; m.inputs.len()][..],
                    "held at the drawn pose"
                );
                assert!(residual(&m, d.poses(), d.inputs()) < 1e-12);
            }
            (BreakPolicy::Search, FrameStatus::Searched { reached, .. }) => {
                assert!(reached > 0.0 && reached < 1.0, "{reached}");
                // The pose it holds closes every joint at the inputs reached…
                assert!(residual(&m, d.poses(), d.inputs()) < 1e-9);
                // …and it is the boundary: a little further breaks.
                let mut beyond = d.inputs().to_vec();
                beyond[boom] += 1e-6;
                let mut probe = Driver::new(Interpreter::new(plan.clone()), Options::default());
                let mut step = vec![0.0; m.inputs.len()];
                for k in 1..=100 {
                    step[boom] = d.inputs()[boom] * k as f64 / 100.0;
                    assert!(probe.frame(&step).is_solved(), "reachable on the way");
                }
                assert!(!probe.frame(&beyond).is_solved(), "just past the boundary breaks");
            }
            (BreakPolicy::Stretch, FrameStatus::Stretched { residual: gap, .. }) => {
                assert!(gap > 0.0);
            }
            other => panic!("{other:?}"),
        }
    }
}

/// A spherical four-bar with every joint marker at the common centre has
/// only directions to close its loop on (cone ∩ cone): it plans in closed
/// form, and every body turns exactly as in the bundled spherical four-bar,
/// whose revolute axes are the same.
#[test]
fn a_spherical_linkage_drawn_at_its_centre_closes_on_directions() {
    let centre = dofplan_tests::load_spatial("spherical_centre");
    let plan = analyse(&centre).unwrap();
    assert_eq!(plan.cluster_size(), (0, 0), "closed form");
    assert!(plan
        .steps
        .iter()
        .any(|s| matches!(s.kind, dofplan::plan::spatial::StepKind::IntersectDir { .. })));
    let bundled = bundled3("spherical_fourbar");
    let a = sweep(&centre);
    let b = sweep(&bundled);
    for ((req, pa), (_, pb)) in a.iter().zip(&b) {
        for (x, y) in pa.iter().zip(pb) {
            for r in 0..3 {
                for c in 0..3 {
                    assert!((x.rot.m[r][c] - y.rot.m[r][c]).abs() < 1e-9, "{req:?}");
                }
            }
        }
    }
}
