//! `dofplan assemble` and `check` on spatial drawings whose joints do not
//! hold: the rough RSSR of `mechanisms/rough/rssr.toml` is assembled to
//! where its closed form says the loop closes (and to the bundled file),
//! `check` says where its open joint closes, and a Bennett linkage drawn
//! inconsistent is refused with its joints named.

use std::path::PathBuf;
use std::process::{Command, Output};

use dofplan::assemble::spatial::assemble_str;
use dofplan::load_any_str;
use dofplan::model::spatial::equations::equations;
use dofplan::model::spatial::Mechanism;
use dofplan::model::{Format, Model};
use dofplan_runtime::spatial::{add, cross, dist, dot, norm, scale, sub, unit, Pose3, Vec3};

fn mechanisms() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../mechanisms")
}

fn read(path: &str) -> String {
    std::fs::read_to_string(mechanisms().join(path)).expect("bundled file")
}

fn dofplan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .output()
        .expect("the dofplan binary runs")
}

fn spatial(name: &str, text: &str, format: Format) -> Mechanism {
    match load_any_str(name, text, format) {
        Ok(Model::Spatial(m)) => m,
        Ok(Model::Planar(_)) => panic!("{name} is planar"),
        Err(e) => panic!("{name} does not load: {e}"),
    }
}

fn at(m: &Mechanism, marker: &str) -> Vec3 {
    m.marker(m.find_marker(marker).expect(marker)).at
}

/// The largest residual of any joint, constraint or input in the drawn
/// pose (lengths, and sines times the size).
fn largest_gap(m: &Mechanism) -> f64 {
    let poses = vec![Pose3::IDENTITY; m.bodies.len()];
    let inputs = vec![0.0; m.inputs.len()];
    equations(m)
        .iter()
        .map(|e| e.gap(&poses, &inputs) * if e.linear() { 1.0 } else { m.size() })
        .fold(0.0, f64::max)
}

/// A text with every number literal replaced by `#`: the part `assemble`
/// must keep (comments, keys, order, layout). As in `assemble.rs`.
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

/// The rough RSSR's loop closed by hand: the rocker turns about its axis
/// (unit `a` through D) by φ, carrying its arm `u` = C − D; joint C closes
/// where |D + R(φ)u − B| is the coupler's length L, that is
/// `p cos φ + q sin φ = s` with p = 2(D − B)·u, q = 2(D − B)·(a × u),
/// s = L² − |D − B|² − |u|². Both roots, as points C.
fn closures(b: Vec3, d: Vec3, a: Vec3, u: Vec3, len: f64) -> [Vec3; 2] {
    let w = cross(a, u);
    let db = sub(d, b);
    let (p, q) = (2.0 * dot(db, u), 2.0 * dot(db, w));
    let s = len * len - dot(db, db) - dot(u, u);
    let (base, half) = (q.atan2(p), (s / p.hypot(q)).acos());
    [base + half, base - half].map(|phi| add(d, add(scale(u, phi.cos()), scale(w, phi.sin()))))
}

/// The rough drawing assembles to the closed form's closure nearest the
/// drawing (which is the bundled file's assembly mode), every body moved
/// rigidly, the rocker's written x turned with it, and only the numbers of
/// the file changed.
#[test]
fn the_rough_rssr_assembles_where_its_closed_form_closes() {
    let rough_text = read("rough/rssr.toml");
    let done = assemble_str("rough/rssr.toml", &rough_text, Format::Toml).expect("the rough RSSR assembles");
    assert!(
        done.inputs_held,
        "the crank is drawn where the loop closes: it stays"
    );
    assert_eq!(done.opened, 1, "joint C");
    let rough = &done.mechanism;
    let m = spatial("assembled", &done.text, Format::Toml);
    let size = m.size();
    let gap = largest_gap(&m);
    assert!(
        gap <= 1e-10 * size,
        "assembled, every joint holds: largest gap {gap:e}"
    );
    assert_eq!(
        without_numbers(&done.text),
        without_numbers(&rough_text),
        "only numbers change"
    );

    // The closed form, from the rough drawing's own shapes.
    let (b, d) = (at(rough, "crank.B"), at(rough, "ground.D"));
    let a = unit(m.marker(m.find_marker("ground.D").unwrap()).axes.unwrap().z);
    let u = sub(at(rough, "rocker.C"), at(rough, "rocker.D"));
    let len = dist(at(rough, "coupler.C"), at(rough, "coupler.B"));
    let roots = closures(b, d, a, u, len);
    let c = at(&m, "coupler.C");
    let nearest = roots
        .iter()
        .copied()
        .min_by(|p, q| dist(*p, c).total_cmp(&dist(*q, c)))
        .unwrap();
    assert!(dist(c, nearest) <= 1e-9 * size, "C {c:?}, closed form {roots:?}");
    assert_eq!(at(&m, "rocker.C"), c, "the joined markers are written alike");
    // M stays on the coupler's line at 0.6 of |BC| (the body is rigid).
    let m_expected = add(b, scale(sub(c, b), 0.6));
    assert!(dist(at(&m, "coupler.M"), m_expected) <= 1e-9 * size);
    // Ground and crank as drawn.
    for name in [
        "ground.A",
        "ground.D",
        "crank.A",
        "crank.B",
        "coupler.B",
        "rocker.D",
    ] {
        assert_eq!(at(&m, name), at(rough, name), "{name} stays");
    }
    // ... and the bundled file, made by tools/generate/spatial.py, is this
    // assembly mode (the other root is 4.9 away).
    let bundled = spatial("rssr.toml", &read("spatial/rssr.toml"), Format::Toml);
    for name in ["coupler.C", "coupler.M", "rocker.C"] {
        let (got, want) = (at(&m, name), at(&bundled, name));
        assert!(
            dist(got, want) <= 1e-9 * size,
            "{name}: {got:?} vs bundled {want:?}"
        );
    }

    // The rocker's written x turns with the rocker about its axis, by the
    // angle its arm turned, and keeps its written length (√2).
    let (arm0, arm1) = (u, sub(c, d));
    let turn = dot(cross(arm0, arm1), a).atan2(dot(arm0, arm1));
    let x0 = [1.0, 0.0, -1.0];
    let want = add(scale(x0, turn.cos()), scale(cross(a, x0), turn.sin()));
    let written = rocker_x(&done.text);
    assert!(dist(written, want) <= 1e-11, "x {written:?}, turned {want:?}");
    assert!((norm(written) - 2f64.sqrt()).abs() <= 1e-11);
}

/// The `x = [..]` of the rocker's D marker as written.
fn rocker_x(text: &str) -> Vec3 {
    let line = text
        .lines()
        .find(|l| l.starts_with("markers.D = { at = [-0.5, 3.2, 2.0]") && l.contains("x ="));
    let line = line.expect("the rocker's D marker");
    let inner = &line[line.find("x = [").unwrap() + 5..];
    let numbers: Vec<f64> = inner[..inner.find(']').unwrap()]
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    [numbers[0], numbers[1], numbers[2]]
}

/// `check` on the rough drawing: joint C does not hold, and its help says
/// where it closes (the closed form's point, printed to six decimals) and
/// which markers move there from where.
#[test]
fn check_says_where_an_open_spatial_joint_closes() {
    let path = mechanisms().join("rough/rssr.toml");
    let o = dofplan(&["check", path.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("error: joint `C` does not hold in the drawn pose (coincident)"),
        "{err}"
    );
    let said = "the mechanism does assemble with joint C closed at [";
    let start = err.find(said).unwrap_or_else(|| panic!("{err}")) + said.len();
    let shown: Vec<f64> = err[start..start + err[start..].find(']').unwrap()]
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let rough = match dofplan::model::spatial::load_str_drawn("r", &read("rough/rssr.toml"), Format::Toml) {
        Ok(d) => d.mechanism,
        Err(e) => panic!("{e}"),
    };
    let (b, d) = (at(&rough, "crank.B"), at(&rough, "ground.D"));
    let a = unit(
        rough
            .marker(rough.find_marker("ground.D").unwrap())
            .axes
            .unwrap()
            .z,
    );
    let u = sub(at(&rough, "rocker.C"), d);
    let len = dist(at(&rough, "coupler.C"), b);
    let c = closures(b, d, a, u, len)
        .into_iter()
        .find(|p| dist(*p, [shown[0], shown[1], shown[2]]) < 1e-3)
        .unwrap_or_else(|| panic!("{shown:?} is no closure of joint C"));
    for k in 0..3 {
        assert!((shown[k] - c[k]).abs() <= 1e-6, "{shown:?} vs {c:?}");
    }
    assert!(
        err.contains("coupler.C moves from [1, 4.474761, 0] to ["),
        "{err}"
    );
    assert!(err.contains("rocker.C moves from [-0.5, 5.7, 2] to ["), "{err}");
    assert!(
        err.contains("the inputs at their drawn values: only the drawing is off"),
        "{err}"
    );
}

/// The bundled Bennett linkage with ground.D moved 0.05 along the ground
/// link: its 4R loop is no longer a Bennett linkage, and a general 4R loop
/// does not close. `check` and `assemble` both name the joints in conflict;
/// `--write` leaves the file as it was.
#[test]
fn joints_that_cannot_all_close_are_refused_naming_them() {
    let exact = "markers.D = { at = [-1.4004150764194194, 0.0, 0.0]";
    let text = read("spatial/bennett.toml").replacen(exact, "markers.D = { at = [-1.45, 0.0, 0.0]", 1);
    assert_ne!(text, read("spatial/bennett.toml"));
    let e = assemble_str("bennett.toml", &text, Format::Toml).expect_err("no assembly");
    let shown = e.to_string();
    assert!(
        shown.contains("joint `D` does not hold in the drawn pose (coincident)"),
        "{shown}"
    );
    assert!(
        shown.contains("joints A, B, C, D are in conflict: no pose near the drawn one closes them all"),
        "{shown}"
    );

    let dir = std::env::temp_dir().join(format!("dofplan-assemble3-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bennett.toml");
    std::fs::write(&path, &text).unwrap();
    let o = dofplan(&["assemble", path.to_str().unwrap(), "--write"]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("are in conflict"), "{err}");
    assert!(o.stdout.is_empty());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "left as it was");
    let _ = std::fs::remove_dir_all(dir);
}

/// A coupler drawn longer (6.6) than the rocker can reach from the crank
/// as drawn: held at its drawn value the crank leaves joint C open, so the
/// input is freed and the crank turns. The result holds every joint, and
/// every body keeps its drawn shape.
#[test]
fn a_crank_drawn_out_of_reach_is_turned_with_the_input_freed() {
    let text = read("rough/rssr.toml")
        .replace(
            "markers.C = [1.0, 4.47476059419, 0.0]",
            "markers.C = [1.0, 6.6, 0.0]",
        )
        .replace(
            "markers.M = [1.0, 2.684856356514, 0.0]",
            "markers.M = [1.0, 3.96, 0.0]",
        );
    let done = assemble_str("long.toml", &text, Format::Toml).expect("it assembles");
    assert!(!done.inputs_held);
    assert!(done
        .report()
        .contains("inputs free (held at their drawn values the joints do not close)"));
    let m = spatial("long", &done.text, Format::Toml);
    assert!(largest_gap(&m) <= 1e-10 * m.size());
    let (b, c) = (at(&m, "coupler.B"), at(&m, "coupler.C"));
    assert!((dist(b, c) - 6.6).abs() <= 1e-10, "the coupler keeps its length");
    assert!((dist(b, at(&m, "coupler.M")) - 3.96).abs() <= 1e-10);
    assert!((dist(at(&m, "rocker.C"), at(&m, "rocker.D")) - 2.5).abs() <= 1e-10);
    assert!(
        (norm(b) - 1.0).abs() <= 1e-10 && b[2].abs() <= 1e-10,
        "B on the crank circle"
    );
    assert!(dist(b, [1.0, 0.0, 0.0]) > 0.1, "the crank turned");
}

/// A file whose joints hold is left as it is; a JSON drawing assembles
/// like its TOML form.
#[test]
fn assembled_files_stay_and_json_drawings_assemble() {
    let bundled = read("spatial/rssr.toml");
    let done = assemble_str("rssr.toml", &bundled, Format::Toml).unwrap();
    assert!(done.unchanged());
    assert_eq!(done.text, bundled);
    assert_eq!(done.report(), "rssr: already assembled, nothing moved\n");

    let value: serde_json::Value = toml::from_str(&read("rough/rssr.toml")).unwrap();
    let json = serde_json::to_string_pretty(&value).unwrap();
    let done = assemble_str("rssr.json", &json, Format::Json).expect("the JSON drawing assembles");
    let m = spatial("rssr.json", &done.text, Format::Json);
    assert!(largest_gap(&m) <= 1e-10 * m.size());
    let toml = assemble_str("rssr.toml", &read("rough/rssr.toml"), Format::Toml).unwrap();
    let t = spatial("rssr.toml", &toml.text, Format::Toml);
    for id in t.all_markers() {
        let name = t.marker_name(id);
        assert!(dist(at(&m, &name), t.marker(id).at) <= 1e-12, "{name}");
    }
}
