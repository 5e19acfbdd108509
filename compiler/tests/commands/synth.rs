//! `dofplan synth` as a user runs it: a standard target with constraints,
//! the written file checked by `check` and `analyze` and its error
//! recomputed independently, and the bad inputs a user makes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

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
    let dir = std::env::temp_dir().join(format!("dofplan-synth-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The targets of a target file (x,y rows after the comments and header).
fn targets(path: &Path) -> Vec<[f64; 2]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .filter_map(|l| {
            let v: Vec<f64> = l.split(',').filter_map(|t| t.trim().parse().ok()).collect();
            (v.len() == 2).then(|| [v[0], v[1]])
        })
        .collect()
}

#[test]
fn mkh_18_with_constraints_is_met_and_the_file_confirms_it() {
    let dir = scratch("mkh");
    let best = dir.join("best.toml");
    let picture = dir.join("best.svg");
    let mkh = root().join("tests/synth/targets/mkh_18.csv");
    let args = [
        "synth",
        "mechanisms/fourbar.toml",
        "--marker",
        "coupler.P",
        "--path",
        mkh.to_str().unwrap(),
        "--full-turn",
        "--min-transmission",
        "40",
        "--target",
        "4.96e-3",
        // A budget rather than a time: the same search on a loaded machine.
        "--evaluations",
        "200000",
        "--time-limit",
        "3600",
        "--json",
        "--out",
        best.to_str().unwrap(),
        "--svg",
        picture.to_str().unwrap(),
    ];
    let o = dofplan(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    let sum_sq = doc["error"]["sum_sq"].as_f64().unwrap();
    // The error of the linkage published with the target set.
    assert!(sum_sq <= 4.96e-3, "{sum_sq}");
    assert!(doc["evaluations"].as_u64().unwrap() > 0 && doc["seconds"].as_f64().unwrap() > 0.0);
    assert_eq!(doc["parameters"].as_object().unwrap().len(), 10);
    assert!(!doc["solutions"].as_array().unwrap().is_empty());
    for c in doc["constraints"].as_array().unwrap() {
        assert!(c["margin"].as_f64().unwrap() >= 0.0, "{c}");
    }
    // The picture marks the 18 targets.
    let svg = std::fs::read_to_string(&picture).unwrap();
    let marks = svg
        .split("class=\"target-points\"")
        .nth(1)
        .expect("the targets' group");
    let marks = &marks[..marks.find("</g>").unwrap()];
    assert_eq!(marks.matches("<circle").count(), 18);
    // `check` and `analyze` on the written file confirm both constraints.
    let o = dofplan(&["check", best.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stdout).contains("theta: turns fully"),
        "{}",
        text(&o.stdout)
    );
    // By its lengths too: a crank just past its change point is sampled
    // as turning while it stops for a fraction of a degree.
    assert!(
        text(&o.stdout).contains(": crank-rocker (") || text(&o.stdout).contains(": double-crank ("),
        "{}",
        text(&o.stdout)
    );
    let o = dofplan(&["analyze", best.to_str().unwrap(), "--steps", "1441"]);
    let out = text(&o.stdout);
    let line = out
        .lines()
        .find(|l| l.contains("transmission angle of"))
        .expect("a transmission line");
    let degrees: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|t| t.parse().ok())
        .collect();
    let (lo, hi) = (degrees[0], degrees[2]);
    assert!(lo >= 40.0 && hi <= 140.0, "{line}");
    // The error again, from the file alone: its coupler curve simulated
    // densely, each target's squared distance to the nearest point of it
    // (no more than at the input the synthesis gave it).
    let o = dofplan(&["simulate", best.to_str().unwrap(), "--steps", "7201", "--json"]);
    let sim: Value = serde_json::from_slice(&o.stdout).unwrap();
    let curve: Vec<[f64; 2]> = (sim["frames"].as_array().unwrap().iter())
        .map(|f| {
            let p = &f["markers"]["coupler.P"];
            [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()]
        })
        .collect();
    let dense: f64 = targets(&mkh)
        .iter()
        .map(|t| {
            curve
                .iter()
                .map(|c| (c[0] - t[0]).powi(2) + (c[1] - t[1]).powi(2))
                .fold(f64::INFINITY, f64::min)
        })
        .sum();
    assert!(
        dense <= sum_sq * (1.0 + 1e-3),
        "dense {dense} vs reported {sum_sq}"
    );
    assert!(dense >= 0.9 * sum_sq, "dense {dense} vs reported {sum_sq}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_input_is_a_clear_error() {
    let dir = scratch("bad");
    let write = |name: &str, body: &str| {
        let p = dir.join(name);
        std::fs::write(&p, body).unwrap();
        p.to_string_lossy().into_owned()
    };
    let run = |args: &[&str]| {
        let mut all = vec!["synth", "mechanisms/fourbar.toml"];
        all.extend_from_slice(args);
        let o = dofplan(&all);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(!text(&o.stderr).contains("panicked"), "{}", text(&o.stderr));
        text(&o.stderr)
    };
    let good = write("good.csv", "x,y\n1,2\n3,4\n");
    let empty = write("empty.csv", "# nothing here\n");
    let e = run(&["--marker", "coupler.P", "--path", &empty]);
    assert!(e.contains("no targets"), "{e}");
    let malformed = write("malformed.csv", "1,2\n3,oops\n");
    let e = run(&["--marker", "coupler.P", "--path", &malformed]);
    assert!(
        e.contains("malformed.csv:2:3: error: `oops` is not a finite number"),
        "{e}"
    );
    let e = run(&["--marker", "coupler.Q", "--path", &good]);
    assert!(
        e.contains("no marker 'coupler.Q'") && e.contains("coupler.P"),
        "{e}"
    );
    let pairs = write("pairs.csv", "0,0\n30,5\n");
    let e = run(&["--function", &pairs, "--output", "Z"]);
    assert!(
        e.contains("no joint 'Z'") && e.contains("one of A, B, C, D"),
        "{e}"
    );
    let e = run(&[
        "--marker",
        "coupler.P",
        "--path",
        &good,
        "--bounds",
        "10,10,20,20",
    ]);
    assert!(e.contains("exclude its drawn value"), "{e}");
    let e = run(&["--marker", "coupler.P", "--path", &good, "--bounds", "1,2,3"]);
    assert!(e.contains("four numbers"), "{e}");
    let e = run(&["--marker", "coupler.P", "--path", &good, "--vary", "E"]);
    assert!(e.contains("no design parameter 'E'"), "{e}");
    let e = run(&["--marker", "coupler.P", "--path", &good, "--timing", "given"]);
    assert!(e.contains("do not fit --timing given"), "{e}");
    // Constraints no candidate can keep: said, not a silent best effort.
    let e = run(&[
        "--marker",
        "coupler.P",
        "--path",
        &good,
        "--min-transmission",
        "89.9",
        "--max-ratio",
        "1.0001",
        "--evaluations",
        "3000",
        "--time-limit",
        "3600",
    ]);
    assert!(
        e.contains("no candidate in the box met the targets and the constraints"),
        "{e}"
    );
    // A goal is required; a spatial file names its own markers.
    let o = dofplan(&["synth", "mechanisms/fourbar.toml"]);
    assert!(
        !o.status.success() && text(&o.stderr).contains("--path"),
        "{}",
        text(&o.stderr)
    );
    let o = dofplan(&[
        "synth",
        "mechanisms/spatial/rssr.toml",
        "--marker",
        "coupler.P",
        "--path",
        &good,
    ]);
    assert!(
        !o.status.success()
            && text(&o.stderr).contains("no marker 'coupler.P'")
            && text(&o.stderr).contains("coupler.M"),
        "{}",
        text(&o.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
