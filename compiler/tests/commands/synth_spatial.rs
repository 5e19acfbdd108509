//! `dofplan synth` on a spatial file, as a user runs it: the RSSR's output
//! angle law, its rocker's motion and its pin's path, sampled from the
//! bundled RSSR, found
//! again from a file whose pivots and pins were moved; the reported error
//! recomputed independently from the written file; and the options spatial
//! synthesis refuses.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use dofplan::model::spatial::Mechanism;
use dofplan::model::Model;
use dofplan::synth::spatial::output;
use dofplan_runtime::spatial::Pose3;
use dofplan_runtime::{Driver, Options};
use serde_json::Value;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn dofplan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .current_dir(root())
        .output()
        .expect("the dofplan binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dofplan-synth3-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn spatial(path: &Path) -> Mechanism {
    match dofplan::load_any(path).unwrap() {
        Model::Spatial(m) => m,
        Model::Planar(_) => panic!("{} is not spatial", path.display()),
    }
}

/// `read` at each of `inputs`, the mechanism run up from its drawing in
/// steps of a tenth of the way (so it stays on its branch).
fn run_up<T>(m: &Mechanism, inputs: &[f64], read: impl Fn(&[Pose3]) -> T) -> Vec<T> {
    let plan = dofplan::analysis::spatial::analyse(m).unwrap();
    let mut driver = Driver::new(
        dofplan::interp::spatial::Interpreter::new(plan),
        Options::default(),
    );
    let mut now = 0.0;
    (inputs.iter())
        .map(|&t| {
            for s in 1..=10 {
                assert!(driver.frame(&[now + (t - now) * s as f64 / 10.0]).is_solved());
            }
            now = t;
            read(driver.poses())
        })
        .collect()
}

/// Joint D's angle (degrees from the drawing) at `inputs`.
fn law(m: &Mechanism, inputs: &[f64]) -> Vec<f64> {
    let d = m.joints.iter().position(|j| j.name == "D").unwrap();
    run_up(m, inputs, |poses| output(m, d, poses))
}

const INPUTS: [f64; 12] = [
    0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0, 210.0, 240.0, 270.0, 300.0, 330.0,
];

/// The RSSR's file with D (both its markers) and C moved: a drawing to
/// start from that is not the answer.
fn moved_rssr(dir: &Path) -> PathBuf {
    let truth = std::fs::read_to_string(root().join("mechanisms/spatial/rssr.toml")).unwrap();
    let moved = truth.replace("[-0.5, 3.2, 2.0]", "[-0.42, 3.27, 1.93]").replace(
        "[1.0309310892394863, 4.45, 0.4690689107605137]",
        "[1.1, 4.38, 0.52]",
    );
    assert_ne!(moved, truth);
    let path = dir.join("rssr_moved.toml");
    std::fs::write(&path, moved).unwrap();
    path
}

/// `dofplan synth` from the moved RSSR with `goal` (its options), C and D
/// varied, until the sum of squares is 1e-18 (or 3,000 evaluations),
/// writing `best` if given: the output, which must be a success.
fn synth_moved(dir: &Path, goal: &[&str], best: Option<&Path>, json: bool) -> String {
    let start = moved_rssr(dir);
    let mut args = vec!["synth", start.to_str().unwrap()];
    args.extend_from_slice(goal);
    let budget = [
        "--vary",
        "C,D",
        "--evaluations",
        "3000",
        "--target",
        "1e-18",
        "--time-limit",
        "3600",
    ];
    args.extend_from_slice(&budget);
    if let Some(best) = best {
        args.extend_from_slice(&["--out", best.to_str().unwrap()]);
    }
    if json {
        args.push("--json");
    }
    let o = dofplan(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    text(&o.stdout)
}

#[test]
fn an_rssr_output_law_is_found_again_and_the_written_file_reproduces_it() {
    let dir = scratch("law");
    let truth = spatial(&root().join("mechanisms/spatial/rssr.toml"));
    let targets = law(&truth, &INPUTS);
    let csv: String =
        std::iter::once("# joint D's angle, sampled from the bundled RSSR\ninput,output\n".to_string())
            .chain(
                INPUTS
                    .iter()
                    .zip(&targets)
                    .map(|(t, o)| format!("{t},{o:.17e}\n")),
            )
            .collect();
    let pairs = dir.join("law.csv");
    std::fs::write(&pairs, csv).unwrap();
    let best = dir.join("best.toml");
    let goal = ["--function", pairs.to_str().unwrap(), "--output", "D"];
    let v: Value = serde_json::from_str(&synth_moved(&dir, &goal, Some(&best), true)).unwrap();
    let rms = v["error"]["rms"].as_f64().unwrap();
    assert!(rms <= 1e-9, "rms {rms} degrees");
    assert_eq!(v["goal"], "function generation of joint D at 12 input values");
    assert_eq!(v["varied"].as_array().unwrap().len(), 6);
    // Independently: the written file, loaded and run as any file, follows
    // the law to the reported error.
    let found = spatial(&best);
    let again = law(&found, &INPUTS);
    let worst = (again.iter().zip(&targets))
        .map(|(a, t)| (a - t).abs())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-8, "the written file's law is off by {worst}°");
    let max = v["error"]["max"].as_f64().unwrap();
    assert!(
        (worst - max).abs() <= 1e-9,
        "reported max {max}, recomputed {worst}"
    );
    // And `check` takes the file.
    let o = dofplan(&["check", best.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_rssr_rocker_motion_is_found_again_as_text() {
    let dir = scratch("motion");
    let truth = spatial(&root().join("mechanisms/spatial/rssr.toml"));
    let rocker = truth.bodies.iter().position(|b| b.name == "rocker").unwrap();
    let c = truth.find_marker("rocker.C").unwrap();
    let local = truth.marker(c).at;
    let drawn = run_up(&truth, &[0.0], |poses| poses[rocker])[0];
    let rows = run_up(&truth, &INPUTS, |poses| {
        let pose = poses[rocker];
        // The turn from the drawn pose, as a rotation vector in degrees.
        let r = nalgebra::Matrix3::from_fn(|a, b| pose.rot.m[a][b]);
        let r0 = nalgebra::Matrix3::from_fn(|a, b| drawn.rot.m[a][b]);
        let turn = nalgebra::Rotation3::from_matrix_unchecked(r * r0.transpose()).scaled_axis();
        (pose.world(local), turn.map(f64::to_degrees))
    });
    let csv: String = std::iter::once("input,x,y,z,rx,ry,rz\n".to_string())
        .chain(INPUTS.iter().zip(&rows).map(|(t, (p, r))| {
            format!(
                "{t},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e},{:.17e}\n",
                p[0], p[1], p[2], r[0], r[1], r[2]
            )
        }))
        .collect();
    let poses = dir.join("poses.csv");
    std::fs::write(&poses, csv).unwrap();
    let goal = [
        "--motion",
        poses.to_str().unwrap(),
        "--body",
        "rocker",
        "--marker",
        "rocker.C",
    ];
    let out = synth_moved(&dir, &goal, None, false);
    assert!(
        out.starts_with("rssr: motion generation of rocker through 12 poses (given timing), 6 of"),
        "{out}"
    );
    let best = out
        .lines()
        .find(|l| l.starts_with("best: sum of squares "))
        .unwrap();
    let sum_sq: f64 = best["best: sum of squares ".len()..]
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(sum_sq <= 1e-16, "{out}");
    // Every point is listed with three coordinates; the crank's held.
    assert!(out.contains("  A            (0, 0, 0)  (held)"), "{out}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The rocker's pin C: a point the input decides (the coupler's points
/// off its B–C axis turn with its idle spin).
#[test]
fn an_rssr_rocker_path_is_found_again() {
    let dir = scratch("path");
    let truth = spatial(&root().join("mechanisms/spatial/rssr.toml"));
    let rocker = truth.bodies.iter().position(|b| b.name == "rocker").unwrap();
    let local = truth.marker(truth.find_marker("rocker.C").unwrap()).at;
    let points = run_up(&truth, &INPUTS, |poses| poses[rocker].world(local));
    let csv: String = (INPUTS.iter().zip(&points))
        .map(|(t, p)| format!("{t},{:.17e},{:.17e},{:.17e}\n", p[0], p[1], p[2]))
        .collect();
    let targets = dir.join("path.csv");
    std::fs::write(&targets, csv).unwrap();
    let best = dir.join("best.toml");
    let goal = [
        "--path",
        targets.to_str().unwrap(),
        "--marker",
        "rocker.C",
        "--full-turn",
        "--max-ratio",
        "6",
    ];
    let v: Value = serde_json::from_str(&synth_moved(&dir, &goal, Some(&best), true)).unwrap();
    assert_eq!(
        v["goal"],
        "path generation of rocker.C through 12 points (given timing)"
    );
    let rms = v["error"]["rms"].as_f64().unwrap();
    assert!(rms <= 1e-9, "rms {rms}");
    // The constraints, as reported and as the written file has them: the
    // crank turns fully (`check` says so), and the links' lengths (ground
    // A–D, crank A–B, coupler B–C, rocker C–D) measured here.
    let c = v["constraints"].as_array().unwrap();
    assert_eq!(
        (c[0]["name"].as_str(), c[0]["value"].as_f64()),
        (Some("full-turn"), Some(1.0))
    );
    assert!(c[0]["margin"].as_f64().unwrap() >= 0.0, "{c:?}");
    let found = spatial(&best);
    let at = |n: &str| found.marker(found.find_marker(n).unwrap()).at;
    let dist = |a: &str, b: &str| (0..3).map(|k| (at(a)[k] - at(b)[k]).powi(2)).sum::<f64>().sqrt();
    let links = [
        dist("ground.A", "ground.D"),
        dist("crank.A", "crank.B"),
        dist("coupler.B", "coupler.C"),
        dist("rocker.C", "rocker.D"),
    ];
    let ratio =
        links.iter().fold(0.0f64, |a, &b| a.max(b)) / links.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    assert_eq!(c[1]["name"], "max-ratio");
    assert!(
        (c[1]["value"].as_f64().unwrap() - ratio).abs() <= 1e-9 * ratio,
        "{c:?}, {ratio}"
    );
    assert!(ratio <= 6.0, "{ratio}");
    let o = dofplan(&["check", best.to_str().unwrap()]);
    assert!(
        text(&o.stdout).contains("theta: turns fully"),
        "{}",
        text(&o.stdout)
    );
    // Independently: the written file's pin passes the targets.
    let local = found.marker(found.find_marker("rocker.C").unwrap()).at;
    let again = run_up(&found, &INPUTS, |poses| poses[rocker].world(local));
    let worst = (again.iter().zip(&points))
        .map(|(a, p)| (0..3).map(|k| (a[k] - p[k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-8, "the written file's path is off by {worst}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Free timing: the rocker's pin C through points of its arc, without
/// their input values. The search finds each point's input with the
/// dimensions; the arc (one swing of the rocker, away from its ends) is
/// found again exactly, though not the truth's timing: a pin on the same
/// circle, swinging through the points at other crank angles, passes them
/// as well.
#[test]
fn an_rssr_rocker_arc_is_found_with_free_timing() {
    let dir = scratch("free");
    let truth = spatial(&root().join("mechanisms/spatial/rssr.toml"));
    let rocker = truth.bodies.iter().position(|b| b.name == "rocker").unwrap();
    let local = truth.marker(truth.find_marker("rocker.C").unwrap()).at;
    let sampled: Vec<f64> = (0..13).map(|k| 110.0 + 10.0 * k as f64).collect();
    let points = run_up(&truth, &sampled, |poses| poses[rocker].world(local));
    let csv: String = (points.iter())
        .map(|p| format!("{:.17e},{:.17e},{:.17e}\n", p[0], p[1], p[2]))
        .collect();
    let targets = dir.join("arc.csv");
    std::fs::write(&targets, format!("# x,y,z\n{csv}")).unwrap();
    let best = dir.join("best.toml");
    let picture = dir.join("best.svg");
    let goal = [
        "--path",
        targets.to_str().unwrap(),
        "--marker",
        "rocker.C",
        "--svg",
        picture.to_str().unwrap(),
    ];
    let v: Value = serde_json::from_str(&synth_moved(&dir, &goal, Some(&best), true)).unwrap();
    assert_eq!(
        v["goal"],
        "path generation of rocker.C through 13 points (free timing)"
    );
    targets_lie_on_the_trace(&std::fs::read_to_string(&picture).unwrap(), 13);
    let rms = v["error"]["rms"].as_f64().unwrap();
    assert!(rms <= 1e-9, "rms {rms}");
    let inputs: Vec<f64> = (v["inputs"].as_array().unwrap().iter())
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(inputs.len(), 13);
    // Independently: the written file, run to each reported input, puts
    // its pin on the target.
    let found = spatial(&best);
    let local = found.marker(found.find_marker("rocker.C").unwrap()).at;
    let again = run_up(&found, &inputs, |poses| poses[rocker].world(local));
    let worst = (again.iter().zip(&points))
        .map(|(a, p)| (0..3).map(|k| (a[k] - p[k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    assert!(worst <= 1e-8, "the written file's pin is off by {worst}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The numbers of an attribute's value (`points="x,y x,y"` or `cx="…"`).
fn numbers(s: &str) -> Vec<f64> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter_map(|t| t.parse().ok())
        .collect()
}

/// Each attribute `name="…"` in `s`, in order.
fn attributes<'a>(s: &'a str, name: &str) -> Vec<&'a str> {
    let key = format!(" {name}=\"");
    s.split(key.as_str())
        .skip(1)
        .map(|rest| &rest[..rest.find('"').unwrap()])
        .collect()
}

/// In every one of a spatial synthesis picture's four views, `n` target
/// rings, each on the drawn trace of the marker (within a pixel and a
/// half: the fit is exact, and the trace is thinned to half a pixel).
fn targets_lie_on_the_trace(svg: &str, n: usize) {
    let views: Vec<&str> = svg.split("class=\"view\"").skip(1).collect();
    assert_eq!(views.len(), 4);
    for view in views {
        let marks = view
            .split("class=\"target-points\"")
            .nth(1)
            .expect("the targets' group");
        let marks = &marks[..marks.find("</g>").unwrap()];
        let cx: Vec<f64> = attributes(marks, "cx")
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        let cy: Vec<f64> = attributes(marks, "cy")
            .iter()
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(cx.len(), n);
        let trace: Vec<[f64; 2]> = view
            .split("<polyline")
            .skip(1)
            .filter(|p| p[..p.find('>').unwrap()].contains("class=\"trace\""))
            .flat_map(|p| {
                let pts = numbers(attributes(&p[..p.find('>').unwrap()], "points")[0]);
                pts.chunks(2).map(|c| [c[0], c[1]]).collect::<Vec<_>>()
            })
            .collect();
        assert!(trace.len() >= 2, "no trace drawn");
        for (&x, &y) in cx.iter().zip(&cy) {
            let gap = trace
                .windows(2)
                .map(|w| {
                    let (a, b) = (w[0], w[1]);
                    let d = [b[0] - a[0], b[1] - a[1]];
                    let l2 = d[0] * d[0] + d[1] * d[1];
                    let t = if l2 > 0.0 {
                        (((x - a[0]) * d[0] + (y - a[1]) * d[1]) / l2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    (x - a[0] - t * d[0]).hypot(y - a[1] - t * d[1])
                })
                .fold(f64::INFINITY, f64::min);
            assert!(gap <= 1.5, "a target {gap} px off the trace");
        }
    }
}

#[test]
fn what_spatial_synthesis_does_not_do_is_refused_by_name() {
    let dir = scratch("bad");
    let pairs = dir.join("pairs.csv");
    std::fs::write(&pairs, "0,0\n30,5\n").unwrap();
    let pairs = pairs.to_str().unwrap();
    let run = |args: &[&str]| {
        let mut all = vec!["synth", "mechanisms/spatial/rssr.toml"];
        all.extend_from_slice(args);
        let o = dofplan(&all);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(!text(&o.stderr).contains("panicked"), "{}", text(&o.stderr));
        text(&o.stderr)
    };
    let e = run(&["--function", pairs, "--output", "D", "--min-transmission", "40"]);
    assert!(
        e.contains("--min-transmission bounds the transmission angles of planar four-bar loops"),
        "{e}"
    );
    let o = dofplan(&[
        "synth",
        "mechanisms/spatial/excavator.toml",
        "--function",
        pairs,
        "--output",
        "slew_bearing",
        "--input",
        "boom_cyl",
        "--full-turn",
    ]);
    let e = text(&o.stderr);
    assert!(
        !o.status.success()
            && e.contains("--full-turn asks the input to turn through 360°, and boom_cyl is a slide"),
        "{e}"
    );
    let e = run(&["--function", pairs, "--output", "B"]);
    assert!(e.contains("joint B is not revolute"), "{e}");
    let e = run(&["--function", pairs, "--output", "Z"]);
    assert!(
        e.contains("no joint 'Z'") && e.contains("one of A, B, C, D"),
        "{e}"
    );
    let e = run(&["--function", pairs, "--output", "D", "--bounds", "0,0,1,1"]);
    assert!(e.contains("six numbers"), "{e}");
    let e = run(&[
        "--function",
        pairs,
        "--output",
        "D",
        "--bounds",
        "10,10,10,20,20,20",
    ]);
    assert!(e.contains("exclude its drawn value"), "{e}");
    let e = run(&["--path", pairs, "--marker", "ground.A"]);
    assert!(e.contains("input,x,y,z"), "{e}");
    let point = dir.join("point.csv");
    std::fs::write(&point, "0,1,2,3\n").unwrap();
    let e = run(&["--path", point.to_str().unwrap(), "--marker", "ground.A"]);
    assert!(e.contains("marker ground.A is on the fixed body"), "{e}");
    let e = run(&[
        "--path",
        point.to_str().unwrap(),
        "--marker",
        "coupler.M",
        "--timing",
        "free",
    ]);
    assert!(e.contains("4 columns do not fit --timing free"), "{e}");
    let e = run(&["--motion", pairs, "--body", "rocker", "--timing", "free"]);
    assert!(
        e.contains("--timing free (of a motion) works on planar files only for now"),
        "{e}"
    );
    // Off the coupler's spin axis, a point's path is not the input's.
    let start = moved_rssr(&dir);
    let (start, point) = (start.to_str().unwrap(), point.to_str().unwrap());
    let o = dofplan(&["synth", start, "--path", point, "--marker", "coupler.M"]);
    let e = text(&o.stderr);
    assert!(
        !o.status.success() && e.contains("marker coupler.M moves with an idle spin"),
        "{e}"
    );
    let e = run(&["--motion", pairs, "--body", "rocker"]);
    assert!(e.contains("input,x,y,z,rx,ry,rz"), "{e}");
    let pose = dir.join("pose.csv");
    std::fs::write(&pose, "0,1,2,3,0,0,0\n").unwrap();
    let e = run(&["--motion", pose.to_str().unwrap(), "--body", "ground"]);
    assert!(e.contains("body ground is fixed"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
