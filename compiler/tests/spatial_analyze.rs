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
