//! `dofplan check`'s assembly ranges and `dofplan analyze` on spatial
//! (`dimension = 3`) files, held to computations made here from the files'
//! geometry: an RSSR whose coupler cannot reach the rocker's circle over
//! part of the crank's turn, and the Cardan joint's velocity ratio.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

fn spatial(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../mechanisms/spatial")
        .join(format!("{name}.toml"))
}

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(format!("{name}.toml"))
}

fn dofplan(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan"))
        .args(args)
        .output()
        .expect("the dofplan binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json_of(args: &[&str]) -> Value {
    let o = dofplan(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    serde_json::from_str(&stdout(&o)).unwrap_or_else(|e| panic!("{args:?}: not JSON ({e}): {}", stdout(&o)))
}

fn path(p: &Path) -> &str {
    p.to_str().unwrap()
}

type V3 = [f64; 3];

fn sub(u: V3, v: V3) -> V3 {
    [u[0] - v[0], u[1] - v[1], u[2] - v[2]]
}

fn dot(u: V3, v: V3) -> f64 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

fn cross(u: V3, v: V3) -> V3 {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

fn unit(v: V3) -> V3 {
    let n = dot(v, v).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

fn vec3(v: &Value) -> V3 {
    let a = v.as_array().unwrap_or_else(|| panic!("a 3-vector: {v}"));
    assert_eq!(a.len(), 3, "{v}");
    [0, 1, 2].map(|k| a[k].as_f64().unwrap())
}

/// The geometry of tests/data/rssr_reach.toml, typed in from its markers.
struct Rssr {
    crank: f64,
    d: V3,
    axis: V3,
    rocker: f64,
    coupler: f64,
}

fn rssr_reach() -> Rssr {
    let b0 = [2.5, 0.0, 0.0];
    let c0 = [1.0309310892394863, 4.45, 0.4690689107605137];
    let d = [-0.5, 3.2, 2.0];
    let axis = unit([1.0, 0.0, 1.0]);
    let cd = sub(c0, d);
    Rssr {
        crank: dot(b0, b0).sqrt(),
        d,
        axis,
        // C − D is normal to the axis as drawn, so this is the radius.
        rocker: dot(cd, cd).sqrt(),
        coupler: dot(sub(c0, b0), sub(c0, b0)).sqrt(),
    }
}

impl Rssr {
    /// |BC| minus the farthest and the nearest distance from B (crank at
    /// `theta` degrees) to the rocker's circle: the sphere about B meets
    /// the circle while the first is ≤ 0 and the second ≥ 0.
    fn gaps(&self, theta: f64) -> (f64, f64) {
        let t = theta.to_radians();
        let b = [self.crank * t.cos(), self.crank * t.sin(), 0.0];
        let v = sub(b, self.d);
        let h = dot(v, self.axis);
        let w = sub(v, self.axis.map(|x| x * h));
        let rho = dot(w, w).sqrt();
        (
            self.coupler - h.hypot(rho + self.rocker),
            self.coupler - h.hypot(rho - self.rocker),
        )
    }

    /// Whether the chain closes with the crank at `theta`.
    fn closes(&self, theta: f64) -> bool {
        let (far, near) = self.gaps(theta);
        far <= 0.0 && near >= 0.0
    }

    /// The crank angle between `ok` (closes) and `bad` (does not) where it
    /// stops closing, bisected to 1e-12 degrees.
    fn edge(&self, mut ok: f64, mut bad: f64) -> f64 {
        assert!(self.closes(ok) && !self.closes(bad));
        while (bad - ok).abs() > 1e-12 {
            let mid = 0.5 * (ok + bad);
            if self.closes(mid) {
                ok = mid;
            } else {
                bad = mid;
            }
        }
        ok
    }
}

/// The RSSR whose coupler is too short for part of the crank's turn: the
/// plan breaks exactly where the sphere about the crank pin stops meeting
/// the rocker's circle, each edge computed here by bisection on the
/// distances from the pin to the circle (no plan involved), to 1e-6°.
#[test]
fn spatial_check_reports_where_an_rssr_closes() {
    let g = rssr_reach();
    // Scan the turn for where closing changes, one degree apart.
    let mut edges = Vec::new();
    for k in -180..180 {
        let (a, b) = (k as f64, (k + 1) as f64);
        match (g.closes(a), g.closes(b)) {
            (true, false) => edges.push(g.edge(a, b)),
            (false, true) => edges.push(g.edge(b, a)),
            _ => {}
        }
    }
    assert_eq!(edges.len(), 2, "{edges:?}");
    let (opens, closes) = (edges[0], edges[1]);
    assert!(opens > 0.0 && closes > opens, "{edges:?}");
    let v = json_of(&["check", path(&data("rssr_reach")), "--json"]);
    assert_eq!(v["dimension"], 3);
    let theta = v["ranges"]["theta"].as_array().unwrap_or_else(|| panic!("{v}"));
    assert_eq!(theta.len(), 2, "{v}");
    let at = |i: usize, j: usize| theta[i][j].as_f64().unwrap();
    assert_eq!((at(0, 0), at(1, 1)), (-180.0, 180.0), "{v}");
    assert!((at(0, 1) - opens).abs() < 1e-6, "{} vs {opens}", at(0, 1));
    assert!((at(1, 0) - closes).abs() < 1e-6, "{} vs {closes}", at(1, 0));
    // The text names the step that breaks and why.
    let o = dofplan(&["check", path(&data("rssr_reach"))]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("assembly ranges (each input alone, the others at 0; break points to 1e-9):"),
        "{out}"
    );
    assert!(
        out.contains("    theta: from -180° (end of the range searched) to 82.05695"),
        "{out}"
    );
    assert!(out.contains("breaks beyond: the circles do not meet"), "{out}");
    // A spatial mechanism that turns fully, and one with slides.
    let v = json_of(&["check", path(&spatial("cardan")), "--json"]);
    assert_eq!(v["ranges"]["theta"], serde_json::json!([[-180.0, 180.0]]));
    let v = json_of(&["check", path(&spatial("excavator")), "--json"]);
    for input in ["slew", "boom_cyl", "stick_cyl"] {
        assert_eq!(
            v["ranges"][input].as_array().map(Vec::len),
            Some(1),
            "{input}: {v}"
        );
    }
}

/// A body's rotation matrix from a JSON frame (rows).
fn rotation(frame: &Value, body: &str) -> [[f64; 3]; 3] {
    let r = &frame["bodies"][body]["rotation"];
    [0, 1, 2].map(|i| vec3(&r[i]))
}

fn apply(r: &[[f64; 3]; 3], v: V3) -> V3 {
    [0, 1, 2].map(|i| dot(r[i], v))
}

/// `analyze --json` on the Cardan joint at 1 rad/s: the output shaft's
/// angular velocity about its axis is cos β / (1 − sin²β cos²θ₁) (β = 30°
/// from the bearings' axes, θ₁ the input yoke's angle from the plane of
/// the shafts, read off each frame's rotation), the input's is 1 about its
/// axis, and each traced tip's velocity and acceleration are the central
/// differences of the positions the same output gives (1° apart); every
/// frame has simulate's keys and the rates'.
#[test]
fn spatial_analyze_gives_the_cardan_velocity_ratio() {
    let v = json_of(&["analyze", path(&spatial("cardan")), "--json"]);
    assert_eq!(v["name"], "cardan");
    assert_eq!(v["dimension"], 3);
    assert!((v["rates"]["theta"].as_f64().unwrap() - 1f64.to_degrees()).abs() < 1e-12);
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 361);
    for key in [
        "frame",
        "status",
        "requested",
        "inputs",
        "markers",
        "bodies",
        "residual",
        "velocity",
        "acceleration",
        "angular",
    ] {
        assert!(frames.iter().all(|f| f.get(key).is_some()), "no {key}");
    }
    // The geometry, from the file: the bearings' axes and the input yoke.
    let (a1, a2) = ([1.0, 0.0, 0.0], [0.8660254037844387, 0.49999999999999994, 0.0]);
    let yoke = [0.0, 1.0, 0.0];
    let beta = dot(a1, a2).acos();
    let (sb, cb) = beta.sin_cos();
    let in_plane = unit(cross(cross(a1, a2), a1));
    let g = |t: f64| cb / (1.0 - sb * sb * t.cos() * t.cos());
    let (mut lo, mut hi) = (f64::INFINITY, 0.0_f64);
    for f in frames {
        assert_eq!(f["status"], "solved");
        let now = apply(&rotation(f, "shaft1"), yoke);
        let theta1 = dot(cross(in_plane, now), a1).atan2(dot(in_plane, now));
        let w1 = vec3(&f["angular"]["shaft1"]["omega"]);
        let w2 = vec3(&f["angular"]["shaft2"]["omega"]);
        assert!((dot(w1, a1) - 1.0).abs() < 1e-12, "{w1:?}");
        let ratio = dot(w2, a2) / dot(w1, a1);
        assert!(
            (ratio - g(theta1)).abs() < 1e-9,
            "θ₁ {:.3}°: {ratio} vs {}",
            theta1.to_degrees(),
            g(theta1)
        );
        // The output turns about its own axis only; the ground not at all.
        assert!(dot(cross(w2, a2), cross(w2, a2)).sqrt() < 1e-12, "{w2:?}");
        assert_eq!(vec3(&f["angular"]["ground"]["omega"]), [0.0; 3]);
        lo = lo.min(ratio);
        hi = hi.max(ratio);
    }
    // The header's range of the ratio: cos β .. 1 / cos β.
    assert!(
        (lo - cb).abs() < 1e-6 && (hi - 1.0 / cb).abs() < 1e-6,
        "{lo} {hi}"
    );
    // Velocities and accelerations against central differences (h = 1°).
    let h = 1f64.to_radians();
    for tip in ["shaft1.tip", "shaft2.tip"] {
        for i in 1..frames.len() - 1 {
            let p = |k: usize| vec3(&frames[k]["markers"][tip]);
            let (before, here, after) = (p(i - 1), p(i), p(i + 1));
            let vel = vec3(&frames[i]["velocity"][tip]);
            let acc = vec3(&frames[i]["acceleration"][tip]);
            for k in 0..3 {
                let first = (after[k] - before[k]) / (2.0 * h);
                let second = (after[k] - 2.0 * here[k] + before[k]) / (h * h);
                assert!(
                    (vel[k] - first).abs() < 1e-4,
                    "{tip} frame {i}: v {vel:?} vs {first}"
                );
                assert!(
                    (acc[k] - second).abs() < 1e-4,
                    "{tip} frame {i}: a {acc:?} vs {second}"
                );
            }
        }
    }
    // The summary names the traced markers' largest speed: shaft2.tip, at
    // 0.5 from its axis, at most 0.5 / cos β; shaft1.tip, 0.5 from the
    // input shaft's axis turning at 1 rad/s, has speed 0.5 throughout.
    let o = dofplan(&["analyze", path(&spatial("cardan"))]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.starts_with("cardan: 361 frames, theta at 57.2958°/s (1 rad/s)\n"),
        "{out}"
    );
    assert!(
        out.contains("  shaft2.tip: largest speed 0.5774 at theta = "),
        "{out}"
    );
    assert!(
        out.contains("  shaft1.tip: speed 0.5 throughout, acceleration 0.5 throughout\n"),
        "{out}"
    );
}

/// `analyze --csv` of a spatial file: frame, status, inputs, nine columns
/// a marker (x, y, z, vx, vy, vz, ax, ay, az), six a body (ω and α), the
/// residual; one row a frame. `--svg` draws the position, speed and
/// acceleration panels.
#[test]
fn spatial_analyze_writes_csv_and_plots() {
    let o = dofplan(&["analyze", path(&spatial("cardan")), "--csv", "--steps", "5"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = stdout(&o);
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 6, "{csv}");
    let head: Vec<&str> = lines[0].split(',').collect();
    // 8 markers, 3 bodies.
    assert_eq!(head.len(), 3 + 8 * 9 + 3 * 6 + 1, "{head:?}");
    assert_eq!(
        &head[..6],
        [
            "frame",
            "status",
            "theta",
            "ground.A.x",
            "ground.A.y",
            "ground.A.z"
        ]
    );
    assert!(head.contains(&"shaft2.tip.vz") && head.contains(&"shaft2.omega.x"));
    assert_eq!(head.last(), Some(&"residual"));
    for row in &lines[1..] {
        assert_eq!(row.split(',').count(), head.len(), "{row}");
    }
    // shaft1 turns at 1 rad/s about x.
    let col = head.iter().position(|c| *c == "shaft1.omega.x").unwrap();
    let w: f64 = lines[2].split(',').nth(col).unwrap().parse().unwrap();
    assert!((w - 1.0).abs() < 1e-12, "{w}");
    let dir = std::env::temp_dir().join(format!("dofplan-analyze3-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let svg = dir.join("plots.svg");
    let o = dofplan(&[
        "analyze",
        path(&spatial("cardan")),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    for caption in [
        "position of the traced markers",
        "speed |v|",
        "acceleration |a|",
        "shaft2.tip",
    ] {
        assert!(text.contains(caption), "no {caption:?} in the plots");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A plan whose rates the library does not compute (the Stewart platform's
/// numeric cluster, for now) still runs: positions written, the rates null
/// with "unavailable" saying why (the library's own reason), and the
/// summary saying it once. If the library computes them, they are written.
#[test]
fn spatial_analyze_says_when_a_plan_has_no_rates() {
    use dofplan::analysis::spatial::analyse;
    use dofplan::interp::spatial::Interpreter;
    use dofplan::load_any;
    use dofplan::model::Model;
    use dofplan_runtime::Solver;
    let Ok(Model::Spatial(m)) = load_any(&spatial("stewart")) else {
        panic!("stewart is spatial")
    };
    let interp = Interpreter::new(analyse(&m).unwrap());
    let n = m.inputs.len();
    let library = interp.rates(
        &interp.initial_state(),
        &vec![0.0; n],
        &vec![1.0; n],
        &vec![0.0; n],
    );
    let v = json_of(&["analyze", path(&spatial("stewart")), "--json", "--steps", "3"]);
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    for f in frames {
        assert_eq!(
            f["markers"].as_object().map(|o| o.len()),
            Some(m.all_markers().count())
        );
        match &library {
            Err(e) => {
                assert!(f["velocity"].is_null() && f["angular"].is_null(), "{f}");
                assert_eq!(f["unavailable"], e.to_string());
            }
            Ok(_) => assert!(f["velocity"].is_object() && f.get("unavailable").is_none(), "{f}"),
        }
    }
    let o = dofplan(&["analyze", path(&spatial("stewart")), "--steps", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said = stdout(&o).contains("rates unavailable for this plan");
    assert_eq!(said, library.is_err(), "{}", stdout(&o));
}
