//! `dofplan analyze --sensitivity` as a user runs it.

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
        .output()
        .expect("the dofplan binary runs")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn json_has_every_frames_derivatives_the_ranking_and_the_tolerance_study() {
    let file = mechanism("fourbar");
    let args = [
        "analyze",
        &file,
        "--sensitivity",
        "--json",
        "--tolerance",
        "0.01",
        "--monte-carlo",
        "30",
        "--steps",
        "37",
    ];
    let o = dofplan(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    let params: Vec<&str> = doc["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(params.len(), 10);
    let frames = doc["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 37);
    // At the drawing the coupler point moves with its own coordinates only.
    let at0 = &frames[0]["markers"]["coupler.P"];
    for name in &params {
        let d: Vec<f64> = at0[*name]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let own = match *name {
            "coupler.P.x" => [1.0, 0.0],
            "coupler.P.y" => [0.0, 1.0],
            _ => [0.0, 0.0],
        };
        assert!(
            (d[0] - own[0]).abs() < 1e-12 && (d[1] - own[1]).abs() < 1e-12,
            "{name}: {d:?}"
        );
    }
    // Ranked from the largest effect down, each parameter once.
    let ranking = doc["ranking"].as_array().unwrap();
    assert_eq!(ranking.len(), 10);
    let largest: Vec<f64> = ranking.iter().map(|r| r["largest"].as_f64().unwrap()).collect();
    assert!(largest.windows(2).all(|w| w[0] >= w[1]), "{largest:?}");
    // The first-order bound holds the sampled candidates (to second order).
    let bound = doc["tolerance"]["markers"]["coupler.P"]["worst_case"]
        .as_f64()
        .unwrap();
    let sampled = doc["monte_carlo"]["markers"]["coupler.P"]["largest"]
        .as_f64()
        .unwrap();
    assert!(sampled > 0.0 && sampled <= 1.05 * bound, "{sampled} vs {bound}");
    // Seeded: the same command, the same output.
    assert_eq!(dofplan(&args).stdout, o.stdout);
}

#[test]
fn text_names_the_parameters_and_the_worst_case() {
    let o = dofplan(&[
        "analyze",
        &mechanism("slider_crank"),
        "--sensitivity",
        "--tolerance",
        "0.001",
    ]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let out = text(&o.stdout);
    assert!(out.contains("design parameters over"), "{out}");
    assert!(out.contains("worst-case first-order deviation"), "{out}");
}

/// The spatial study: the Stewart platform's tool point (six legs driven
/// at once), its derivatives against central differences of candidates
/// planned again by the library and run through the same frames; and on
/// the RSSR (whose every perturbed candidate plans, unlike the Stewart
/// platform's pins), the exact worst case holding the Monte-Carlo samples.
#[test]
fn spatial_derivatives_match_central_differences_and_the_worst_case_holds() {
    use dofplan::model::Model;
    use dofplan::synth::spatial::Design;
    use dofplan_runtime::{Driver, Options};

    let file = mechanism("spatial/stewart");
    let o = dofplan(&["analyze", &file, "--sensitivity", "--json", "--steps", "9"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    let frames = doc["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 9);
    let Model::Spatial(m) = dofplan::load_any(std::path::Path::new(&file)).unwrap() else {
        panic!("the Stewart platform is spatial")
    };
    let design = Design::new(&m).unwrap();
    let id = m.find_marker("platform.tool").unwrap();
    let inputs = |f: usize| -> Vec<f64> {
        let v = frames[f]["inputs"].as_array().unwrap();
        v.iter().map(|x| x.as_f64().unwrap()).collect()
    };
    // The tool point at frame `f` of the candidate `values`, run through
    // the sweep's frames up to it; `None` where the candidate is planned
    // otherwise (a special geometry the planner relies on, moved off).
    let at = |values: &[f64], f: usize| {
        let c = design.prepare(values).ok()?;
        let mut driver = Driver::new(c.interpreter.clone(), Options::default());
        for k in 0..=f {
            assert!(driver.frame(&inputs(k)).is_solved());
        }
        Some(driver.poses()[id.body].world(c.mechanism.marker(id).at))
    };
    let (h, mut compared, mut replanned) = (1e-6 * m.size(), 0, 0);
    for f in [2, 5, 8] {
        for (k, name) in design.names().iter().enumerate() {
            let d = &frames[f]["markers"]["platform.tool"][name];
            let d: Vec<f64> = d
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect();
            let (mut up, mut down) = (design.drawn(), design.drawn());
            up[k] += h;
            down[k] -= h;
            let (Some(a), Some(b)) = (at(&up, f), at(&down, f)) else {
                replanned += 1;
                continue;
            };
            for c in 0..3 {
                let central = (a[c] - b[c]) / (2.0 * h);
                assert!(
                    (central - d[c]).abs() <= 1e-5 * (1.0 + central.abs()),
                    "{name} at frame {f}: {d:?} vs central {central}"
                );
            }
            compared += 1;
        }
    }
    // The six pins the planner relies on (the platform's special geometry)
    // are re-planned when moved, and have no difference here.
    assert!(compared >= 60, "{compared} compared, {replanned} re-planned");
    let rssr = mechanism("spatial/rssr");
    let args = [
        "analyze",
        &rssr,
        "--sensitivity",
        "--json",
        "--tolerance",
        "0.0001",
        "--monte-carlo",
        "20",
        "--steps",
        "13",
    ];
    let o = dofplan(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(doc["monte_carlo"]["failed"], 0);
    let bound = doc["tolerance"]["markers"]["coupler.M"]["worst_case"]
        .as_f64()
        .unwrap();
    let sampled = doc["monte_carlo"]["markers"]["coupler.M"]["largest"]
        .as_f64()
        .unwrap();
    assert!(sampled > 0.0 && sampled <= 1.05 * bound, "{sampled} vs {bound}");
    assert_eq!(dofplan(&args).stdout, o.stdout);
    // The Stewart platform's candidates move its special geometry apart
    // (pins the planner relies on): they are planned as mechanisms of
    // their own, and every one runs.
    let stewart = mechanism("spatial/stewart");
    let args = [
        "analyze",
        &stewart,
        "--sensitivity",
        "--json",
        "--tolerance",
        "0.001",
        "--monte-carlo",
        "10",
        "--steps",
        "3",
    ];
    let o = dofplan(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let doc: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(doc["monte_carlo"]["failed"], 0, "{}", doc["monte_carlo"]);
    let bound = doc["tolerance"]["markers"]["platform.tool"]["worst_case"]
        .as_f64()
        .unwrap();
    let sampled = doc["monte_carlo"]["markers"]["platform.tool"]["largest"]
        .as_f64()
        .unwrap();
    assert!(sampled > 0.0 && sampled <= 1.05 * bound, "{sampled} vs {bound}");
}

#[test]
fn what_has_no_derivatives_is_an_error_that_says_why() {
    // Under-constrained: the poses depend on the path.
    let o = dofplan(&["analyze", &mechanism("chain_4"), "--sensitivity"]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("freedom(s) open"), "{}", text(&o.stderr));
    // A tolerance needs the study, and must be positive.
    let o = dofplan(&["analyze", &mechanism("fourbar"), "--tolerance", "0.1"]);
    assert!(!o.status.success() && text(&o.stderr).contains("--sensitivity"));
    let o = dofplan(&[
        "analyze",
        &mechanism("fourbar"),
        "--sensitivity",
        "--tolerance",
        "-1",
    ]);
    assert!(
        !o.status.success() && text(&o.stderr).contains("not a positive number"),
        "{}",
        text(&o.stderr)
    );
    // Nothing traced: nothing to study.
    let dir = std::env::temp_dir().join(format!("dofplan-sensitivity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A point an idle spin turns (the RSSR's coupler point moved off its
    // B–C axis) has no derivatives the input decides: refused, by name.
    let rssr = std::fs::read_to_string(mechanism("spatial/rssr")).unwrap();
    let off_axis = dir.join("off_axis.toml");
    let moved = rssr.replace(
        "markers.M = [1.0185586535436917, 2.67, 0.2814413464563082]",
        "markers.M = [1.5, 2.67, 0.28]",
    );
    assert_ne!(moved, rssr);
    std::fs::write(&off_axis, moved).unwrap();
    let o = dofplan(&["analyze", off_axis.to_str().unwrap(), "--sensitivity"]);
    assert!(
        !o.status.success() && text(&o.stderr).contains("traced marker coupler.M moves with an idle spin"),
        "{}",
        text(&o.stderr)
    );
    let src = std::fs::read_to_string(mechanism("fourbar")).unwrap();
    let untraced = dir.join("untraced.toml");
    std::fs::write(&untraced, src.replace("trace = [\"coupler.P\"]", "")).unwrap();
    let o = dofplan(&["analyze", untraced.to_str().unwrap(), "--sensitivity"]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("traces no marker"),
        "{}",
        text(&o.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
