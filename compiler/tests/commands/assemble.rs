//! `dofplan assemble`: authoring from approximate coordinates. A bundled
//! file with its markers moved about is assembled back, written in place,
//! and must load with every joint held, bodies moved rigidly, and its text
//! unchanged apart from the numbers; joints that cannot close are refused.

use std::path::PathBuf;
use std::process::{Command, Output};

use dofplan::assemble::assemble_str;
use dofplan::format::length;
use dofplan::model::{load_str_drawn, Format, JointKind, Mechanism, DRAWN_TOLERANCE};
use dofplan::{load_file, load_str};

fn mechanisms() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mechanisms")
}

fn bundled(name: &str) -> String {
    std::fs::read_to_string(mechanisms().join(format!("{name}.toml"))).expect("bundled file")
}

fn dofplan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .output()
        .expect("the dofplan binary runs")
}

/// A fresh scratch folder for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dofplan-assemble-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A text with every number literal replaced by `#`: the part `assemble`
/// must keep (comments, keys, order, layout). A literal starts at a digit,
/// or a `-` before one, that does not continue a name (`chain_10`).
fn without_numbers(text: &str) -> String {
    let chars: Vec<char> = text.chars().collect();
    let mut out = String::new();
    let mut i = 0;
    while i < chars.len() {
        let after_name = i > 0 && (chars[i - 1].is_alphanumeric() || chars[i - 1] == '_');
        let digit_at = |k: usize| chars.get(k).is_some_and(char::is_ascii_digit);
        if !after_name && (digit_at(i) || (chars[i] == '-' && digit_at(i + 1))) {
            i += 1;
            while i < chars.len() {
                match chars[i] {
                    c if c.is_ascii_digit() || c == '.' => i += 1,
                    'e' | 'E' if digit_at(i + 1) || chars.get(i + 1) == Some(&'-') => i += 2,
                    _ => break,
                }
            }
            out.push('#');
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    out
}

/// The text with every coordinate of every marker of a mobile body moved by
/// up to `amount` in each axis (a fixed pseudo-random sequence), and the
/// ground's markers left alone. Only `markers = { ... }` lines are touched.
fn perturbed(text: &str, amount: f64) -> String {
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut fixed = false;
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with("[bodies.") {
            fixed = false;
        }
        if line.trim() == "fixed = true" {
            fixed = true;
        }
        if line.starts_with("markers = {") && !fixed {
            // Only `at` coordinates: numbers right after `[` or `, ` inside
            // a point; a `dir = [...]` is left as drawn.
            let mut edited = String::new();
            let mut rest = line;
            while let Some(open) = rest.find('[') {
                let (before, after) = rest.split_at(open);
                edited.push_str(before);
                let close = after.find(']').unwrap();
                let point = &after[1..close];
                if before.trim_end().ends_with("dir =") {
                    edited.push_str(&after[..=close]);
                } else {
                    let xy: Vec<f64> = point.split(',').map(|v| v.trim().parse().unwrap()).collect();
                    edited.push_str(&format!(
                        "[{}, {}]",
                        xy[0] + amount * next(),
                        xy[1] + amount * next()
                    ));
                }
                rest = &after[close + 1..];
            }
            edited.push_str(rest);
            out.push_str(&edited);
        } else {
            out.push_str(line);
        }
        out.push('\n');
    }
    out
}

/// How far apart the two markers of every joint are (revolute: their
/// distance; prismatic: the second's distance off the first's line), by
/// the model's drawn coordinates: computed here, not by the loader.
fn joint_gaps(m: &Mechanism) -> Vec<(String, f64)> {
    m.joints
        .iter()
        .map(|j| {
            let (a, b) = (m.marker(j.markers[0]), m.marker(j.markers[1]));
            let d = [b.at[0] - a.at[0], b.at[1] - a.at[1]];
            let gap = match j.kind {
                JointKind::Revolute => d[0].hypot(d[1]),
                JointKind::Prismatic => {
                    let u = a.unit_dir().unwrap();
                    (d[0] * u[1] - d[1] * u[0]).abs()
                }
            };
            (j.name.clone(), gap)
        })
        .collect()
}

/// Distances between every two markers of each body.
fn shapes(m: &Mechanism) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    for body in &m.bodies {
        for (i, p) in body.markers.iter().enumerate() {
            for q in &body.markers[i + 1..] {
                let d = (p.at[0] - q.at[0]).hypot(p.at[1] - q.at[1]);
                out.push((format!("{}.{}–{}", body.name, p.name, q.name), d));
            }
        }
    }
    out
}

/// Assembles `name` with its markers perturbed by ~1e-2 through the CLI's
/// `--write`, and checks the written file.
fn perturb_and_assemble(name: &str) {
    let dir = scratch(name);
    let path = dir.join(format!("{name}.toml"));
    let text = perturbed(&bundled(name), 1e-2);
    std::fs::write(&path, &text).unwrap();
    let before = load_str_drawn("before", &text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    assert!(!before.open.is_empty(), "{name}: the perturbation opens joints");
    assert!(
        load_file(&path).is_err(),
        "{name}: the perturbed file does not load as it is"
    );

    let o = dofplan(&["assemble", path.to_str().unwrap(), "--write"]);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "{name}: {err}");
    assert!(out.contains(&format!("wrote {}", path.display())), "{out}");

    // It loads: every joint holds to the loader's tolerance, and by the
    // test's own measure too.
    let after = load_file(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let size = after.size();
    for (joint, gap) in joint_gaps(&after) {
        assert!(
            gap <= DRAWN_TOLERANCE * size,
            "{name}: joint {joint} open by {gap:e}"
        );
    }
    // Markers a revolute joint joins are written with the same numbers.
    for j in after.joints.iter().filter(|j| j.kind == JointKind::Revolute) {
        let [a, b] = j.markers.map(|id| after.marker(id).at);
        assert_eq!(a, b, "{name}: joint {}", j.name);
    }
    // Comments, key order, layout: all but the numbers is the same text.
    let written = std::fs::read_to_string(&path).unwrap();
    assert_eq!(
        without_numbers(&written),
        without_numbers(&text),
        "{name}: only numbers change"
    );
    // Bodies moved rigidly: the same distances between each body's markers.
    for ((pair, d0), (_, d1)) in shapes(&before.mechanism).iter().zip(shapes(&after)) {
        assert!((d0 - d1).abs() <= 1e-9 * size, "{name}: {pair} was {d0}, is {d1}");
    }
    // Fixed bodies stay put, and every marker moves little (the drawn
    // coordinates were ~1e-2 off).
    let mut most: f64 = 0.0;
    for id in after.all_markers() {
        let (p, q) = (before.mechanism.marker(id).at, after.marker(id).at);
        let d = (p[0] - q[0]).hypot(p[1] - q[1]);
        if after.bodies[id.body].fixed {
            assert_eq!(p, q, "{name}: {} is on the ground", after.marker_name(id));
        }
        most = most.max(d);
        // The report names it, with how far it moved.
        assert!(out.contains(&format!("  {} ", after.marker_name(id))), "{out}");
    }
    assert!(most > 1e-3 && most < 0.1, "{name}: markers moved up to {most}");
    // Running it again finds nothing to do.
    let again = dofplan(&["assemble", path.to_str().unwrap()]);
    assert!(again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("already assembled, nothing moved"));
    assert_eq!(
        String::from_utf8_lossy(&again.stdout),
        written,
        "printed as it is"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_perturbed_fourbar_is_assembled_in_place() {
    perturb_and_assemble("fourbar");
}

#[test]
fn a_perturbed_peaucellier_is_assembled_in_place() {
    perturb_and_assemble("peaucellier");
}

/// A prismatic joint whose line is carried by a mobile body (the rocker's
/// slot): its `dir` turns with the body.
#[test]
fn a_perturbed_inverted_slider_crank_turns_its_slot_with_the_rocker() {
    perturb_and_assemble("inverted_slider_crank");
    let text = perturbed(&bundled("inverted_slider_crank"), 1e-2);
    let done = assemble_str("isc.toml", &text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    let before = load_str_drawn("isc.toml", &text, Format::Toml).unwrap().mechanism;
    let after = load_str("isc.toml", &done.text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    let slot = after.find_marker("rocker.S").unwrap();
    let tip = after.find_marker("rocker.T").unwrap();
    // The slot's direction keeps its angle to the rocker's O4→T.
    let angle = |m: &Mechanism| {
        let (s, t) = (m.marker(slot), m.marker(tip));
        let u = s.unit_dir().unwrap();
        let v = [t.at[0] - s.at[0], t.at[1] - s.at[1]];
        (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1])
    };
    assert!(
        (angle(&before) - angle(&after)).abs() < 1e-9,
        "{} vs {}",
        angle(&before),
        angle(&after)
    );
    let turned = done.moves.iter().find(|mv| mv.marker == slot).unwrap().turn;
    assert!(turned.abs() > 1e-3, "the rocker turns ({turned}°)");
}

#[test]
fn a_file_whose_joints_hold_is_already_assembled() {
    let path = mechanisms().join("fourbar.toml");
    let o = dofplan(&["assemble", path.to_str().unwrap()]);
    assert!(o.status.success());
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "fourbar: already assembled, nothing moved\n"
    );
    assert_eq!(String::from_utf8_lossy(&o.stdout), bundled("fourbar"));
}

/// Fig. 13's V-link with one hole 0.01 off cannot close (the coupler's
/// |UW| is not the V's): refused with the loader's conflict error, and
/// `--write` leaves the file alone.
#[test]
fn joints_that_cannot_all_close_are_refused_naming_them() {
    let dir = scratch("vlink");
    let path = dir.join("vlink.toml");
    let text = bundled("vlink").replace(
        "markers = { U = [2, 2], T = [2.5, 4.5], W = [4, 3] }",
        "markers = { U = [2, 2], T = [2.5, 4.5], W = [4.01, 3] }",
    );
    std::fs::write(&path, &text).unwrap();
    let o = dofplan(&["assemble", path.to_str().unwrap(), "--write"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    let line = text.lines().position(|l| l == "[joints.W]").unwrap() + 1;
    assert!(
        err.contains("error: joints U, W are in conflict: no pose near the drawn one closes them all"),
        "{err}"
    );
    assert!(err.contains(&format!("┌─ {}:{line}:1", path.display())), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "left as it was");
    assert!(o.stdout.is_empty());
    let _ = std::fs::remove_dir_all(dir);
}

/// Only "does not hold in the drawn pose" errors are assembled away: a
/// file with any other error is refused with the loader's error.
#[test]
fn other_errors_are_still_errors() {
    let text = perturbed(&bundled("fourbar"), 1e-2).replace("\"coupler.C\"", "\"coupler.Q\"");
    let e = assemble_str("t.toml", &text, Format::Toml).expect_err("an unknown marker");
    let shown = e.to_string();
    assert!(shown.contains("body `coupler` has no marker `Q`"), "{shown}");
    let e = assemble_str("t.toml", "name = ", Format::Toml).expect_err("a syntax error");
    assert!(e.to_string().starts_with("t.toml:1:"), "{e}");
}

/// JSON files keep their key order (the layout is serde_json's).
#[test]
fn a_json_file_keeps_its_key_order() {
    let m = load_str("fourbar.toml", &bundled("fourbar"), Format::Toml).unwrap();
    // The bundled four-bar as JSON, keys in file order, crank.B 0.02 off.
    let mut bodies = serde_json::Map::new();
    for body in &m.bodies {
        let mut markers = serde_json::Map::new();
        for mk in &body.markers {
            let mut at = mk.at;
            if body.name == "crank" && mk.name == "B" {
                at[0] += 0.02;
            }
            markers.insert(mk.name.clone(), serde_json::json!(at));
        }
        let mut b = serde_json::Map::new();
        if body.fixed {
            b.insert("fixed".into(), true.into());
        }
        b.insert("markers".into(), markers.into());
        bodies.insert(body.name.clone(), b.into());
    }
    let joints: serde_json::Map<String, serde_json::Value> = m
        .joints
        .iter()
        .map(|j| {
            let names = j.markers.map(|id| m.marker_name(id));
            (
                j.name.clone(),
                serde_json::json!({"kind": "revolute", "markers": names}),
            )
        })
        .collect();
    let doc = serde_json::json!({"name": "fourbar", "bodies": bodies, "joints": joints});
    let text = serde_json::to_string(&doc).unwrap();
    let done = assemble_str("f.json", &text, Format::Json).unwrap_or_else(|e| panic!("{e}"));
    let after = load_str("f.json", &done.text, Format::Json).unwrap_or_else(|e| panic!("{e}"));
    for (joint, gap) in joint_gaps(&after) {
        assert!(
            gap <= DRAWN_TOLERANCE * after.size(),
            "joint {joint} open by {gap:e}"
        );
    }
    let keys = |text: &str| -> Vec<String> {
        let v: serde_json::Value = serde_json::from_str(text).unwrap();
        let mut out = Vec::new();
        fn walk(v: &serde_json::Value, path: &str, out: &mut Vec<String>) {
            if let Some(o) = v.as_object() {
                for (k, v) in o {
                    out.push(format!("{path}.{k}"));
                    walk(v, &format!("{path}.{k}"), out);
                }
            }
        }
        walk(&v, "", &mut out);
        out
    };
    assert_eq!(keys(&done.text), keys(&text));
    assert!(done.moves.iter().any(|mv| mv.changed));
}

/// Theo Jansen's "holy numbers", by the pairs of markers they separate.
const HOLY: [(&str, &str, f64); 11] = [
    ("crank.O", "crank.A", 15.0),   // m
    ("link_j.A", "link_j.C", 50.0), // j
    ("upper.B", "upper.C", 41.5),   // b
    ("upper.B", "upper.D", 40.1),   // d
    ("upper.C", "upper.D", 55.8),   // e
    ("link_k.A", "link_k.E", 61.9), // k
    ("link_c.B", "link_c.E", 39.3), // c
    ("link_f.D", "link_f.F", 39.4), // f
    ("foot.E", "foot.F", 36.7),     // g
    ("foot.E", "foot.G", 49.0),     // i
    ("foot.F", "foot.G", 65.7),     // h
];

fn distance(m: &Mechanism, a: &str, b: &str) -> f64 {
    let (p, q) = (
        m.marker(m.find_marker(a).unwrap()).at,
        m.marker(m.find_marker(b).unwrap()).at,
    );
    (p[0] - q[0]).hypot(p[1] - q[1])
}

/// The bundled Jansen leg is its rough drawing assembled: the same
/// coordinates, every link its holy number, the ground pivot at (−a, −l).
#[test]
fn the_bundled_jansen_leg_is_its_rough_drawing_assembled() {
    let rough_path = mechanisms().join("rough/jansen.toml");
    let rough = std::fs::read_to_string(&rough_path).unwrap();
    let drawn = load_str_drawn("rough.toml", &rough, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    assert!(drawn.open.len() >= 4, "the rough drawing has open joints");
    let done = assemble_str("rough.toml", &rough, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    let assembled = load_str("rough.toml", &done.text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    let bundled = load_file(&mechanisms().join("jansen.toml")).unwrap_or_else(|e| panic!("{e}"));
    let size = bundled.size();
    for id in bundled.all_markers() {
        let (p, q) = (bundled.marker(id).at, assembled.marker(id).at);
        assert!(
            (p[0] - q[0]).hypot(p[1] - q[1]) <= 1e-9 * size,
            "{}: bundled {p:?}, assembled {q:?}",
            bundled.marker_name(id)
        );
    }
    for m in [&drawn.mechanism, &bundled] {
        for (a, b, length) in HOLY {
            let d = distance(m, a, b);
            assert!((d - length).abs() <= 1e-9 * size, "|{a} {b}| = {d}, not {length}");
        }
        let b = m.marker(m.find_marker("ground.B").unwrap()).at;
        assert_eq!(b, [-38.0, -7.8], "a = 38, l = 7.8");
    }
    // Every joint of the bundled file holds exactly: joined markers are
    // written with the same numbers.
    for (joint, gap) in joint_gaps(&bundled) {
        assert_eq!(gap, 0.0, "joint {joint} open by {gap:e}");
    }
}

#[test]
fn the_report_names_every_marker_and_how_far_it_moved() {
    let rough = std::fs::read_to_string(mechanisms().join("rough/jansen.toml")).unwrap();
    let done = assemble_str("rough.toml", &rough, Format::Toml).unwrap();
    let report = done.report();
    let first = report.lines().next().unwrap();
    assert!(first.starts_with("jansen: "), "{report}");
    assert!(report.contains("  ground.B  "), "{report}");
    // The ground never moves; the crank's pivot neither (it is on it).
    for line in report.lines().filter(|l| l.trim_start().starts_with("ground.")) {
        assert!(line.contains("unchanged"), "{line}");
    }
    // Each moved marker's line ends with its distance, as computed.
    for mv in done.moves.iter().filter(|mv| mv.changed) {
        let name = done.mechanism.marker_name(mv.marker);
        let line = report
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{name} ")))
            .unwrap_or_else(|| panic!("{name} in {report}"));
        assert!(line.ends_with(&length(mv.distance)), "{line}");
        let (p, q) = (mv.from, mv.to);
        assert!(((p[0] - q[0]).hypot(p[1] - q[1]) - mv.distance).abs() < 1e-12);
    }
}
