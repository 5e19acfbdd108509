//! `dofplan import` on Pyslvs expressions written for these tests: a
//! crank-rocker four-bar, a slider-crank with a P joint, a quick-return
//! with an RP joint (a pin in a slot) and a six-bar with a point on three
//! links. Each is imported, loaded and run over its sweep, and in every
//! solved frame every imported joint is checked from the poses: a point's
//! markers coincide (a P or RP point's markers off the slot's link coincide
//! and lie on the slot's line; a P point's pinned links do not turn
//! relative to the slot's). The pose at input 0 is the expression's
//! drawing. The command line is run on the same files, and on bad ones.

use std::path::PathBuf;
use std::process::{Command, Output};

use dofplan::import::pmks::{parse, Expression, JointType};
use dofplan::interp::Interpreter;
use dofplan::model::{Format, Mechanism};
use dofplan_runtime::{Driver, Options, Pose, StartPolicy};

/// Crank-rocker: ground pivots P0 and P4, coupler point P3 traced.
const CRANK_ROCKER: &str = "
M[
  J[R, color[Green], P[0, 0], L[ground, crank]],
  J[R, P[10, 20], L[crank, coupler]],
  J[R, P[60, 50], L[coupler, rocker]],
  J[R, color[(200, 30, 30)], P[30, 60], L[coupler]],
  J[R, P[80, 0], L[ground, rocker]],
]
((0, 1),)
";

/// Slider-crank: the rod (40 long) pins the slider at P2, which slides on
/// ground at P3, 5 below, along x (a P joint: the slider never turns).
const SLIDER_CRANK: &str = "
M[
  J[R, P[0, 0], L[ground, crank]],
  J[R, P[6, 8], L[crank, rod]],
  J[R, P[45.191835884530846, 0], L[rod, slider]],
  J[P, A[0], P[45.191835884530846, -5], L[ground, slider]],
  J[R, P[25, 15], L[rod]],
]
((0, 1),)
";

/// Quick-return: the crank's pin P2 rides in the rocker's slot, which runs
/// (about) through the rocker's pivot P1 (an RP joint on a mobile slot).
const QUICK_RETURN: &str = "
M[
  J[R, P[0, 0], L[ground, crank]],
  J[R, P[0, -25], L[ground, rocker]],
  J[RP, A[81.55], P[5, 8.660254037844386], L[rocker, crank]],
  J[R, P[10, 50], L[rocker]],
]
((0, 2),)
";

/// Six-bar: a crank-rocker four-bar whose rocker pin P2 also carries link4,
/// which a dyad (link4, link5) ties to the ground pivot P5.
const SIX_BAR: &str = "
M[
  J[R, P[0, 0], L[ground, crank]],
  J[R, P[8, 6], L[crank, coupler]],
  J[R, P[30, 25], L[coupler, rocker, link4]],
  J[R, P[40, 0], L[ground, rocker]],
  J[R, P[55, 40], L[link4, link5]],
  J[R, P[65, 5], L[ground, link5]],
  J[R, P[45, 55], L[link4]],
]
((0, 1),)
";

fn dofplan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("the dofplan binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A file of its own for each test (they run in parallel).
fn file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dofplan-import-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write the expression");
    path
}

/// Imports `text` through the library and loads the file it wrote.
fn import(name: &str, text: &str) -> (Expression, Mechanism) {
    let toml = dofplan::import::pmks_to_toml(&format!("{name}.pmks"), text, None, name)
        .unwrap_or_else(|e| panic!("{name} imports: {e}"));
    let m = dofplan::load_str(&format!("{name}.toml"), &toml, Format::Toml)
        .unwrap_or_else(|e| panic!("{name}'s file loads: {e}\n{toml}"));
    let expr = parse(&format!("{name}.pmks"), text).expect("it parses");
    (expr, m)
}

/// The largest gap of any point's joint in the poses `poses` of `m`.
fn joint_gap(expr: &Expression, m: &Mechanism, poses: &[Pose]) -> f64 {
    let mut worst = 0.0_f64;
    for p in &expr.points {
        // Every marker of the point: (body, world position, world direction).
        let mut at = Vec::new();
        for (i, body) in m.bodies.iter().enumerate() {
            for k in body.markers.iter().filter(|k| k.name == p.name()) {
                let dir = k.unit_dir().map(|d| poses[i].world_dir(d));
                at.push((body.name.as_str(), poses[i].world(k.at), dir, i));
            }
        }
        assert!(
            at.len() >= p.links.len(),
            "{} has a marker on every link",
            p.name()
        );
        let slot = (p.kind != JointType::R && p.links.len() > 1).then(|| p.links[0].0.as_str());
        let pins: Vec<_> = at.iter().filter(|a| Some(a.0) != slot).collect();
        for q in &pins[1..] {
            worst = worst.max((q.1[0] - pins[0].1[0]).hypot(q.1[1] - pins[0].1[1]));
        }
        let Some(slot) = at.iter().find(|a| Some(a.0) == slot) else {
            continue;
        };
        let d = slot.2.expect("the slot's marker has a direction");
        for q in &pins {
            let off = [q.1[0] - slot.1[0], q.1[1] - slot.1[1]];
            worst = worst.max((d[0] * off[1] - d[1] * off[0]).abs());
            if p.kind == JointType::P {
                let turn = poses[q.3].rot.degrees() - poses[slot.3].rot.degrees();
                let turn = (turn + 180.0).rem_euclid(360.0) - 180.0;
                worst = worst.max(turn.to_radians().abs() * m.size());
            }
        }
    }
    worst
}

/// Runs `m`'s sweep: every joint closes in every solved frame; returns the
/// frames solved and the frames run.
fn sweep_closes(expr: &Expression, m: &Mechanism) -> (usize, usize) {
    let plan = dofplan::analysis::analyse(m).plan.expect("a plan");
    let sweep = m.sweep.clone().expect("a sweep");
    let options = Options {
        start: StartPolicy::Sweep,
        ..Options::default()
    };
    let mut driver = Driver::new(Interpreter::new(plan), options);
    let mut inputs = vec![0.0; m.inputs.len()];
    let mut solved = 0;
    for i in 0..sweep.steps {
        sweep.set(i, &mut inputs);
        if !driver.frame(&inputs).is_solved() {
            continue;
        }
        solved += 1;
        let gap = joint_gap(expr, m, driver.poses());
        assert!(
            gap <= 1e-9 * m.size(),
            "{}: frame {i}: a joint is open by {gap:e}",
            m.name
        );
    }
    (solved, sweep.steps)
}

/// The pose at input 0 is the drawing: every marker Pk at point k's P[x, y].
fn drawn_is_the_expression(expr: &Expression, m: &Mechanism) {
    let plan = dofplan::analysis::analyse(m).plan.expect("a plan");
    let mut driver = Driver::new(Interpreter::new(plan), Options::default());
    assert!(driver.frame(&vec![0.0; m.inputs.len()]).is_solved());
    for (i, body) in m.bodies.iter().enumerate() {
        for k in &body.markers {
            let index: usize = k.name[1..].parse().expect("markers are named Pk");
            let want = expr.points[index].at;
            let got = driver.poses()[i].world(k.at);
            assert!(
                (got[0] - want[0]).hypot(got[1] - want[1]) <= 1e-9 * m.size(),
                "{}.{} is at {got:?}, drawn at {want:?}",
                body.name,
                k.name
            );
        }
    }
}

/// Imports, checks the bodies and joints made, and runs the sweep.
fn imported_mechanism_runs(name: &str, text: &str, bodies: &[&str], joints: &[&str]) -> Mechanism {
    let (expr, m) = import(name, text);
    let names: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, bodies, "{name}'s bodies");
    let names: Vec<&str> = m.joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, joints, "{name}'s joints");
    drawn_is_the_expression(&expr, &m);
    let (solved, steps) = sweep_closes(&expr, &m);
    assert_eq!(solved, steps, "{name}: every frame of its sweep is solved");
    m
}

#[test]
fn a_crank_rocker_imports_turns_fully_and_closes() {
    let m = imported_mechanism_runs(
        "crank_rocker",
        CRANK_ROCKER,
        &["ground", "crank", "coupler", "rocker"],
        &["P0", "P1", "P2", "P4"],
    );
    let sweep = m.sweep.as_ref().unwrap();
    assert_eq!(
        (sweep.primary().from, sweep.primary().to, sweep.steps),
        (0.0, 360.0, 361)
    );
    assert_eq!(m.marker_name(sweep.trace[0]), "coupler.P3");
    assert_eq!(m.inputs[0].name, "P0_P1");
}

#[test]
fn a_slider_crank_with_a_p_joint_imports_and_closes() {
    let m = imported_mechanism_runs(
        "slider_crank",
        SLIDER_CRANK,
        &["ground", "crank", "rod", "slider"],
        &["P0", "P1", "P2", "P3"],
    );
    let p3 = m.joints.iter().find(|j| j.name == "P3").unwrap();
    assert_eq!(p3.kind, dofplan::model::JointKind::Prismatic);
    assert_eq!(
        m.marker_name(p3.markers[0]),
        "ground.P3",
        "the slot's link comes first"
    );
}

#[test]
fn a_quick_return_with_an_rp_joint_imports_with_a_slider_block_and_closes() {
    let m = imported_mechanism_runs(
        "quick_return",
        QUICK_RETURN,
        &["ground", "crank", "rocker", "P2_block"],
        &["P0", "P1", "P2", "P2_crank"],
    );
    let slot = m.find_marker("rocker.P2").unwrap();
    let dir = m.marker(slot).unit_dir().unwrap();
    let a = 81.55_f64.to_radians();
    assert!((dir[0] - a.cos()).abs() < 1e-15 && (dir[1] - a.sin()).abs() < 1e-15);
}

#[test]
fn a_six_bar_with_a_point_on_three_links_imports_and_closes() {
    imported_mechanism_runs(
        "six_bar",
        SIX_BAR,
        &["ground", "crank", "coupler", "rocker", "link4", "link5"],
        &["P0", "P1", "P2_rocker", "P2_link4", "P3", "P4", "P5"],
    );
}

#[test]
fn the_command_writes_the_file_with_the_pairs_of_the_expression_or_of_input() {
    let source = file("cli_crank_rocker.pmks", CRANK_ROCKER);
    let o = dofplan(&["import", source.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.starts_with("# Imported by `dofplan import` from the Pyslvs (PMKS) expression in"));
    assert!(text.contains("name = \"cli_crank_rocker\""), "{text}");
    assert!(
        text.contains("[inputs.P0_P1]\nkind = \"angle\"\njoint = \"P0\""),
        "{text}"
    );
    // --input replaces the pairs; --out writes the file, which `check` takes.
    let out = source.with_file_name("cli_crank_rocker.toml");
    let o = dofplan(&[
        "import",
        source.to_str().unwrap(),
        "--input",
        "4,2",
        "--name",
        "four_bar",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        format!("wrote {}: 4 bodies, 4 joints, 1 input(s)\n", out.display())
    );
    let written = std::fs::read_to_string(&out).unwrap();
    assert!(
        written.contains("[inputs.P4_P2]\nkind = \"angle\"\njoint = \"P4\""),
        "{written}"
    );
    assert!(written.contains("name = \"four_bar\""));
    let o = dofplan(&["check", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn the_command_reports_bad_expressions_at_their_line_and_column() {
    // (expression, where the error points, its message)
    let cases = [
        (
            "M[\n  J[R, P[0, 0], L[ground, L1]],\n  J[Q, P[1, 1], L[L1]],\n]",
            "3:5",
            "unknown joint type `Q` of point P1",
        ),
        (
            "M[J[R, P[0, 0], L[ground, L1]], J[R, P[1, 1], L[]]]",
            "1:47",
            "point P1 is on no link",
        ),
        (
            "M[J[R, P[0, 0], L[ground, L1]], J[R, P[3, 4], L[L1]]]\n((0, 5),)",
            "2:2",
            "input pair (0, 5): there is no point P5 (the expression has 2 points, P0 to P1)",
        ),
        (
            "M[J[R, P[0, 0], L[ground, L1]], J[R, P[3, 4], L[L1, L2]], J[R, P[9, 9], L[ground, L2]]]\n((0, 2),)",
            "2:2",
            "input pair (0, 2): P0 and P2 are both on ground, which never turns",
        ),
        (
            "M[J[R, P[0, 0], L[ground, L1]], J[R, P[3, 4], L[L1 L2]]]",
            "1:52",
            "expected `,` or `]` in the links of point P1, found `L2`",
        ),
    ];
    for (i, (text, at, message)) in cases.into_iter().enumerate() {
        let source = file(&format!("bad_{i}.pmks"), text);
        let o = dofplan(&["import", source.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1), "{text}");
        assert!(o.stdout.is_empty());
        let err = stderr(&o);
        assert!(err.starts_with(&format!("error: {message}\n")), "{text}\n{err}");
        assert!(
            err.contains(&format!("{}:{at}\n", source.display())),
            "{text}\n{err}"
        );
        assert!(err.contains("= help: "), "{text}\n{err}");
    }
    // --input pairs have no place in the file: the error points at the base
    // point.
    let source = file("bad_input.pmks", CRANK_ROCKER);
    let o = dofplan(&["import", source.to_str().unwrap(), "--input", "1,4"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.starts_with(
            "error: input pair (1, 4): P1 (on crank, coupler) and P4 (on ground, rocker) share no link, so the pair turns nothing\n"
        ),
        "{err}"
    );
    assert!(err.contains(&format!("{}:4:3\n", source.display())), "{err}");
    let o = dofplan(&["import", source.to_str().unwrap(), "--input", "1"]);
    assert_eq!(o.status.code(), Some(2), "clap refuses a malformed --input");
    assert!(stderr(&o).contains("expected B,D (two point indices), got `1`"));
    let o = dofplan(&["import", "/nonexistent/m.pmks"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("/nonexistent/m.pmks: error: cannot read it"));
}
