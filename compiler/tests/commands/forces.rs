//! `dofplan analyze --forces` as a user runs it, and the loader's answers
//! to bad masses, gravity and loads (file:line:column, the names involved,
//! what to write).

use std::path::PathBuf;
use std::process::{Command, Output};

use serde_json::Value;

fn mechanism(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../mechanisms")
        .join(format!("{name}.toml"));
    p.to_string_lossy().into_owned()
}

fn dofplan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("the dofplan binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn the_summary_names_each_input_s_peak_and_where() {
    let o = dofplan(&["analyze", &mechanism("loads/slider_crank_press"), "--forces"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    // The peak of the closed form T = -F_x dx_C/dphi over the sweep's
    // whole degrees (mechanisms/loads/slider_crank_press.toml's header).
    let (r, l, e, f) = (1.0f64, 3.5f64, 0.25f64, -100.0f64);
    let torque = |deg: f64| {
        let phi = (30.0 + deg).to_radians();
        let root = (l * l - (r * phi.sin() - e).powi(2)).sqrt();
        -f * (-r * phi.sin() - (r * phi.sin() - e) * r * phi.cos() / root)
    };
    let peak = (0..=360)
        .map(|d| d as f64)
        .max_by(|a, b| torque(*a).abs().total_cmp(&torque(*b).abs()))
        .unwrap();
    let mut lines = out.lines();
    assert_eq!(
        lines.next(),
        Some("slider_crank_press: 361 frames, held still at each pose (statics)")
    );
    let line = lines.next().unwrap();
    let shown: f64 = line
        .strip_prefix("  input theta: peak torque ")
        .and_then(|rest| rest.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert!((shown - torque(peak)).abs() < 1e-4, "{line}: {}", torque(peak));
    assert!(line.ends_with(&format!(" at theta = {peak}°")), "{line}: {peak}");
    // The two-force rod passes |R| = |F_x| / cos(beta) through O, B and C
    // alike: the first of them, O, is named, at the largest slope.
    let load = |deg: f64| {
        let phi = (30.0 + deg).to_radians();
        let (bx, by) = (r * phi.cos(), r * phi.sin());
        let cx = bx + (l * l - (by - e).powi(2)).sqrt();
        -f * (1.0 + ((e - by) / (cx - bx)).powi(2)).sqrt()
    };
    let worst = (0..=360)
        .map(|d| d as f64)
        .max_by(|a, b| load(*a).total_cmp(&load(*b)))
        .unwrap();
    let line = lines.next().unwrap();
    let shown: f64 = line
        .strip_prefix("  most loaded joint: O, ")
        .and_then(|rest| rest.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    assert!((shown - load(worst)).abs() < 1e-4, "{line}: {}", load(worst));
    assert!(
        line.ends_with(&format!(" at theta = {worst}°")),
        "{line}: {worst}"
    );
    // The ground takes the piston force, |F| = 100, along the track y = e:
    // a moment of 100 e = 25 about the origin, at every frame (the first
    // is named).
    assert_eq!(
        lines.next(),
        Some("  on the ground: force up to 100 at theta = 0°, moment (about the origin) up to 25 at theta = 0°")
    );
    assert_eq!(lines.next(), None);
}

#[test]
fn json_and_csv_stream_every_frame_s_input_force() {
    let file = mechanism("loads/fourbar_weights");
    let o = dofplan(&[
        "analyze", &file, "--forces", "--rate", "2", "--json", "--steps", "13",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(doc["forces"], "kinetostatic");
    let frames = doc["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 13);
    let json: Vec<f64> = frames
        .iter()
        .map(|f| f["input_force"]["theta"].as_f64().unwrap())
        .collect();
    let o = dofplan(&[
        "analyze", &file, "--forces", "--rate", "2", "--csv", "--steps", "13",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let csv = text(&o.stdout);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("frame,theta,status,theta.force,A.fx,A.fy,B.fx,B.fy,C.fx,C.fy,D.fx,D.fy,shaking.fx,shaking.fy,shaking.m")
    );
    let column: Vec<f64> = lines
        .map(|l| l.split(',').nth(3).unwrap().parse().unwrap())
        .collect();
    assert_eq!(column, json);
    // Held still, the answer differs: the inertia and the damper are gone.
    let o = dofplan(&["analyze", &file, "--forces", "--json", "--steps", "13"]);
    let still: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(still["forces"], "static");
    assert_ne!(
        still["frames"][3]["input_force"]["theta"].as_f64().unwrap(),
        json[3]
    );
}

#[test]
fn a_file_without_loads_or_a_spatial_file_is_told_what_to_do() {
    let o = dofplan(&["analyze", &mechanism("fourbar"), "--forces"]);
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(
        err.contains("the file gives no masses, gravity or loads, so every force is 0"),
        "{err}"
    );
    assert!(err.contains("help: add [loads.NAME] entries"), "{err}");
    let o = dofplan(&["analyze", &mechanism("spatial/rssr"), "--forces"]);
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(
        err.contains("the file gives no masses, gravity or loads, so every force is 0"),
        "{err}"
    );
}

/// `check` on the press with its load replaced by `load` (TOML lines
/// after `[loads.piston]`): the error text.
fn bad_load(load: &str) -> String {
    let good = std::fs::read_to_string(mechanism("loads/slider_crank_press")).unwrap();
    let start = good.find("kind = \"force\"\nmarker = \"slider.C\"").unwrap();
    let end = good[start..].find("\n\n").unwrap() + start;
    let edited = format!("{}{load}{}", &good[..start], &good[end..]);
    let dir = std::env::temp_dir().join(format!("dofplan-forces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("press.toml");
    std::fs::write(&path, edited).unwrap();
    let o = dofplan(&["check", path.to_str().unwrap()]);
    assert!(!o.status.success(), "{load}");
    text(&o.stderr).replace(&path.display().to_string(), "press.toml")
}

#[test]
fn bad_loads_get_their_position_names_and_a_hint() {
    // The line after `[loads.piston]`.
    let good = std::fs::read_to_string(mechanism("loads/slider_crank_press")).unwrap();
    let line = good.lines().position(|l| l == "[loads.piston]").unwrap() + 2;
    let e = bad_load("kind = \"push\"\nmarker = \"slider.C\"\nforce = [1, 0]");
    assert!(e.contains("error: load `piston`: unknown kind `push`"), "{e}");
    assert!(e.contains(&format!("press.toml:{line}:8")), "{e}");
    assert!(
        e.contains("expected one of: force, torque, spring, damper, torsion-spring"),
        "{e}"
    );
    let e = bad_load("kind = \"force\"\nmarker = \"slider.Q\"\nforce = [1, 0]");
    assert!(
        e.contains("error: load `piston`: body `slider` has no marker `Q`"),
        "{e}"
    );
    assert!(e.contains(&format!("press.toml:{}:10", line + 1)), "{e}");
    let e = bad_load("kind = \"force\"\nmarker = \"slider.C\"\nforce = [1, 0, 0]");
    assert!(
        e.contains(&format!("press.toml:{}:9", line + 2)) && e.contains("must have 2 coordinates"),
        "{e}"
    );
    let e = bad_load("kind = \"force\"\nmarker = \"slider.C\"\nforce = [1, 0]\naxes = \"local\"");
    assert!(
        e.contains("`axes` is \"world\" or \"body\", not \"local\""),
        "{e}"
    );
    let e = bad_load("kind = \"torsion-spring\"\njoint = \"S\"\nstiffness = 1\nfree_angle = 0");
    assert!(
        e.contains("joint `S` is prismatic; a torsion spring sits on a revolute joint"),
        "{e}"
    );
    let e = bad_load("kind = \"spring\"\nmarkers = [\"rod.B\", \"rod.C\"]\nstiffness = 1\nfree_length = 1");
    assert!(
        e.contains("load `piston` joins two markers of the same body `rod`"),
        "{e}"
    );
    let e =
        bad_load("kind = \"spring\"\nmarkers = [\"ground.O\", \"rod.C\"]\nstiffness = -1\nfree_length = 1");
    assert!(
        e.contains("`loads.piston.stiffness` is -1: it must be 0 or more"),
        "{e}"
    );
    let e = bad_load("kind = \"torque\"\nbody = \"wheel\"\ntorque = 1");
    assert!(
        e.contains("unknown body `wheel`") && e.contains("bodies are: ground, crank, rod, slider"),
        "{e}"
    );
    let e = bad_load("kind = \"damper\"\nmarkers = [\"ground.O\", \"rod.C\"]");
    assert!(e.contains("`loads.piston` is missing `damping`"), "{e}");
    let e = bad_load("kind = \"force\"\nmarker = \"slider.C\"\nforce = [1, 0]\nstiffness = 2");
    assert!(e.contains("unknown key `stiffness`"), "{e}");
}

#[test]
fn masses_come_whole_and_positive() {
    let good = std::fs::read_to_string(mechanism("loads/fourbar_weights")).unwrap();
    let edited = good.replace("centre = [0.5, 0.5]\n", "");
    let dir = std::env::temp_dir().join(format!("dofplan-masses-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("w.toml");
    std::fs::write(&path, edited).unwrap();
    let o = dofplan(&["check", path.to_str().unwrap()]);
    let e = text(&o.stderr);
    assert!(!o.status.success());
    assert!(
        e.contains("body `crank` has `mass` and `inertia` but not `centre`"),
        "{e}"
    );
    let edited = good.replace("mass = 2.0", "mass = 0");
    std::fs::write(&path, edited).unwrap();
    let e = text(&dofplan(&["check", path.to_str().unwrap()]).stderr);
    assert!(
        e.contains("`bodies.coupler.mass` is 0: it must be more than 0"),
        "{e}"
    );
}

/// `check` on the Cardan drive with `from` replaced by `to`: its errors.
fn cardan_edited(from: &str, to: &str) -> String {
    let good = std::fs::read_to_string(mechanism("loads/cardan_torque")).unwrap();
    assert!(good.contains(from), "{from}");
    let dir = std::env::temp_dir().join(format!("dofplan-forces3-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("cardan-{}.toml", from.len() + to.len()));
    std::fs::write(&path, good.replacen(from, to, 1)).unwrap();
    let o = dofplan(&["check", path.to_str().unwrap()]);
    assert!(!o.status.success());
    text(&o.stderr)
}

#[test]
fn a_spatial_file_s_loads_are_checked_in_three_dimensions() {
    let e = cardan_edited("g = [0.0, 0.0, -9.81]", "g = [0.0, -9.81]");
    assert!(e.contains("gravity.g"), "{e}");
    assert!(e.contains("x, y, z"), "{e}");
    let e = cardan_edited(
        "[0.0, 0.05, 0.0], [0.0, 0.0, 0.05]]",
        "[0.1, 0.05, 0.0], [0.0, 0.0, 0.05]]",
    );
    assert!(
        e.contains("`bodies.shaft1.inertia` is not symmetric (differs by 0.1 across the diagonal)"),
        "{e}"
    );
    assert!(e.contains(".toml:23:11"), "{e}");
    let e = cardan_edited("inertia = [[0.002, 0.0, 0.0]", "inertia = [[-0.002, 0.0, 0.0]");
    assert!(
        e.contains("`bodies.shaft1.inertia` has a negative principal moment (-0.002)"),
        "{e}"
    );
    let e = cardan_edited(
        "inertia = [[0.002, 0.0, 0.0], [0.0, 0.05, 0.0], [0.0, 0.0, 0.05]]",
        "inertia = 0.05",
    );
    assert!(e.contains("`bodies.shaft1.inertia` must be a 3×3 tensor"), "{e}");
    let e = cardan_edited(
        "[loads.resisting]",
        "[loads.spring]\nkind = \"torsion-spring\"\njoint = \"U\"\nstiffness = 1.0\nfree_angle = 0.0\n\n[loads.resisting]",
    );
    assert!(
        e.contains("`loads.spring.joint`: joint `U` is universal; a torsion spring sits on a revolute or cylindrical joint"),
        "{e}"
    );
    let e = cardan_edited(
        "torque = [-8.660254037844387, -4.999999999999999, 0.0]",
        "torque = -10.0",
    );
    assert!(e.contains("loads.resisting.torque"), "{e}");
}

#[test]
fn a_cardan_drive_needs_the_load_times_its_speed_ratio() {
    // 10 N m on the output shaft at 30 degrees between the shafts: the
    // input's peak is 10 / cos 30 deg at theta = 0 (the ratio's closed
    // form, cos b / (1 - sin^2 b cos^2 theta)); the shafts' weight, 2 x 2
    // kg, is all the ground carries.
    let o = dofplan(&["analyze", &mechanism("loads/cardan_torque"), "--forces"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    let peak = 10.0 / 30f64.to_radians().cos();
    assert!(
        out.contains(&format!("input theta: peak torque {peak:.3} at theta = 0°")),
        "{out}"
    );
    assert!(
        out.contains(&format!("on the ground: force up to {} at", 4.0 * 9.81)),
        "{out}"
    );
    assert!(out.contains("the reactions at A, B, U are not unique"), "{out}");
    let o = dofplan(&[
        "analyze",
        &mechanism("loads/cardan_torque"),
        "--forces",
        "--json",
        "--steps",
        "3",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&text(&o.stdout)).unwrap();
    assert_eq!(v["dimension"], 3);
    let frame = &v["frames"][1];
    let theta = frame["inputs"]["theta"].as_f64().unwrap().to_radians();
    let b = 30f64.to_radians();
    let expected = 10.0 * b.cos() / (1.0 - b.sin().powi(2) * theta.cos().powi(2));
    let got = frame["input_force"]["theta"].as_f64().unwrap();
    assert!(
        (got - expected).abs() < 1e-10 * expected,
        "{got} against {expected}"
    );
    for joint in ["A", "B", "U"] {
        assert_eq!(frame["reactions"][joint].as_array().unwrap().len(), 3, "{frame}");
        assert_eq!(
            frame["reaction_moments"][joint].as_array().unwrap().len(),
            3,
            "{frame}"
        );
    }
    assert_eq!(frame["shaking"]["force"].as_array().unwrap().len(), 3);
    assert_eq!(frame["shaking"]["moment"].as_array().unwrap().len(), 3);
    let o = dofplan(&[
        "analyze",
        &mechanism("loads/cardan_torque"),
        "--forces",
        "--csv",
        "--steps",
        "3",
    ]);
    let out = text(&o.stdout);
    let head = out.lines().next().unwrap();
    assert_eq!(
        head,
        "frame,theta,status,theta.force,A.fx,A.fy,A.fz,A.mx,A.my,A.mz,B.fx,B.fy,B.fz,B.mx,B.my,B.mz,U.fx,U.fy,U.fz,U.mx,U.my,U.mz,shaking.fx,shaking.fy,shaking.fz,shaking.mx,shaking.my,shaking.mz"
    );
    assert_eq!(out.lines().count(), 4);
    assert!(out
        .lines()
        .skip(1)
        .all(|l| l.split(',').count() == head.split(',').count()));
}

#[test]
fn json_has_every_joint_s_reaction_and_names_what_is_not_unique() {
    let o = dofplan(&[
        "analyze",
        &mechanism("loads/slider_crank_press"),
        "--forces",
        "--json",
        "--steps",
        "5",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    for f in doc["frames"].as_array().unwrap() {
        let r = f["reactions"].as_object().unwrap();
        assert_eq!(r.keys().collect::<Vec<_>>(), ["O", "B", "C", "S"]);
        // The rail takes no load along itself, and the slider no moment.
        assert!(r["S"][0].as_f64().unwrap().abs() < 1e-9);
        assert!(f["reaction_moments"]["S"].as_f64().unwrap().abs() < 1e-9);
        assert!(f.get("indeterminate").is_none());
    }
    // vlink's V pinned twice to the coupler: its pins' shares are not unique.
    let text_of = std::fs::read_to_string(mechanism("vlink")).unwrap()
        + "\n[loads.tip]\nkind = \"force\"\nmarker = \"vee.T\"\nforce = [5.0, -10.0]\n";
    let dir = std::env::temp_dir().join(format!("dofplan-vlink-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("vlink_loaded.toml");
    std::fs::write(&path, text_of).unwrap();
    let o = dofplan(&["analyze", path.to_str().unwrap(), "--forces", "--steps", "5"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(out.contains("the reactions at"), "{out}");
    assert!(
        out.contains("are not unique (the mechanism is over-constrained; the least-norm ones are given)"),
        "{out}"
    );
    let o = dofplan(&[
        "analyze",
        path.to_str().unwrap(),
        "--forces",
        "--json",
        "--steps",
        "5",
    ]);
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    let loose: Vec<&str> = doc["frames"][1]["indeterminate"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert!(
        loose.contains(&"U") && loose.contains(&"W") && !loose.contains(&"A"),
        "{loose:?}"
    );
}

#[test]
fn svg_draws_each_input_s_force_and_each_joint_s_reaction() {
    let dir = std::env::temp_dir().join(format!("dofplan-forces-svg-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("forces.svg");
    let o = dofplan(&[
        "analyze",
        &mechanism("loads/fourbar_weights"),
        "--forces",
        "--rate",
        "2",
        "--svg",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).ends_with(&format!("wrote {}\n", out.display())));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(
        svg.contains("fourbar_weights: each input&apos;s force or torque, theta at 2 rad/s"),
        "{svg}"
    );
    assert!(svg.contains("each joint&apos;s reaction, its magnitude"));
    for joint in [">A<", ">B<", ">C<", ">D<", ">theta<"] {
        assert!(svg.contains(joint), "{joint}");
    }
}

#[test]
fn svg_draws_a_joint_s_reaction_as_a_polar_diagram() {
    // By default the most loaded joint (the summary's), else --polar's;
    // a joint the file does not have, or --polar without --svg, is told.
    let dir = std::env::temp_dir().join(format!("dofplan-forces-polar-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("polar.svg");
    let press = mechanism("loads/slider_crank_press");
    let o = dofplan(&["analyze", &press, "--forces", "--svg", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(text(&o.stdout).contains("most loaded joint: O, 107.0607"));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains("joint O&apos;s reaction, polar"), "{svg}");
    assert!(svg.contains(">largest, 107.1<"), "{svg}");
    assert!(svg.contains(r#"class="origin""#) && svg.contains(r#"class="start""#));
    let o = dofplan(&[
        "analyze",
        &press,
        "--forces",
        "--svg",
        out.to_str().unwrap(),
        "--polar",
        "C",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains("joint C&apos;s reaction, polar"), "{svg}");
    let o = dofplan(&[
        "analyze",
        &press,
        "--forces",
        "--svg",
        out.to_str().unwrap(),
        "--polar",
        "Q",
    ]);
    assert!(!o.status.success());
    let e = text(&o.stderr);
    assert!(e.contains("`Q` is not a joint of slider_crank_press"), "{e}");
    assert!(e.contains("its joints are: O, B, C, S"), "{e}");
    let o = dofplan(&["analyze", &press, "--forces", "--polar", "C"]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("--svg <OUT>"), "{}", text(&o.stderr));
    let o = dofplan(&[
        "analyze",
        &mechanism("loads/excavator_load"),
        "--forces",
        "--svg",
        out.to_str().unwrap(),
        "--polar",
        "boom_pivot",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.contains("joint boom_pivot&apos;s reaction, polar"), "{svg}");
    assert!(svg.contains("along the joint&apos;s x"), "{svg}");
}

#[test]
fn check_says_which_loads_it_read() {
    let o = dofplan(&["check", &mechanism("loads/fourbar_weights")]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains(
            "  loads: gravity, mass on 3 bodies, 5 loads (force payload, torque brake, spring return_spring, damper damper, torsion-spring pivot_spring) — `analyze --forces` computes from them\n"
        ),
        "{}",
        text(&o.stdout)
    );
    let o = dofplan(&["check", &mechanism("loads/cardan_torque")]);
    assert!(
        text(&o.stdout).contains("  loads: gravity, mass on 2 bodies, 1 load (torque resisting)"),
        "{}",
        text(&o.stdout)
    );
    let o = dofplan(&["check", &mechanism("fourbar")]);
    assert!(!text(&o.stdout).contains("loads:"), "{}", text(&o.stdout));
}

#[test]
fn an_acceleration_is_given_with_a_rate_and_said_in_the_report() {
    let file = mechanism("loads/fourbar_weights");
    let run = |extra: &[&str]| {
        let mut args = vec!["analyze", &file, "--forces", "--steps", "5"];
        args.extend_from_slice(extra);
        dofplan(&args)
    };
    let o = run(&["--rate", "2", "--acceleration", "-3"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(
        text(&o.stdout).lines().next(),
        Some("fourbar_weights: 5 frames, running with theta at 2 rad/s, accelerating at -3 rad/s² (kinetostatics)")
    );
    let json = |extra: &[&str]| -> Value {
        let mut args = extra.to_vec();
        args.push("--json");
        let o = run(&args);
        assert!(o.status.success(), "{}", text(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    let braking = json(&["--rate", "2", "--acceleration", "-3"]);
    assert_eq!(
        (braking["rate"].as_f64(), braking["acceleration"].as_f64()),
        (Some(2.0), Some(-3.0))
    );
    // Slowing down, the crank needs less torque than steady at the same
    // speed wherever the bodies' inertia resists the crank turning (a
    // positive generalised mass): never more.
    let steady = json(&["--rate", "2"]);
    assert_eq!(steady["acceleration"].as_f64(), Some(0.0));
    let torque = |doc: &Value, k: usize| doc["frames"][k]["input_force"]["theta"].as_f64().unwrap();
    for k in 0..5 {
        assert!(torque(&braking, k) < torque(&steady, k), "frame {k}");
    }
    // Held still there is neither.
    let held = json(&[]);
    assert!(held.get("rate").is_none() && held.get("acceleration").is_none());
    // An acceleration alone is refused, naming what it needs.
    let o = run(&["--acceleration", "5"]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("--rate <RATE>"), "{}", text(&o.stderr));
}
