//! Recovery: targets sampled from a known mechanism with given timing, the
//! search started from another drawing (every point moved) and a random
//! population, the known behaviour found again to RMS ≤ 1e-9, for ten
//! seeds out of ten.

use dofplan::model::{MarkerId, Mechanism};
use dofplan::synth::planar::{output, Constraints, Design, Goal, Problem};
use dofplan::synth::search::{self, Objective, Options};
use dofplan_runtime::planar::Pose;
use dofplan_runtime::{Driver, Options as DriveOptions};

fn load(path: &str) -> Mechanism {
    let file = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    dofplan::load_file(std::path::Path::new(&file)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The known mechanism's frames at `inputs`, run up from its drawing.
fn frames(m: &Mechanism, inputs: &[f64]) -> Vec<Vec<Pose>> {
    let plan = dofplan::analysis::analyse(m).plan.unwrap();
    let mut driver = Driver::new(dofplan::interp::Interpreter::new(plan), DriveOptions::default());
    let mut now = 0.0;
    inputs
        .iter()
        .map(|&t| {
            for s in 1..=10 {
                assert!(driver.frame(&[now + (t - now) * s as f64 / 10.0]).is_solved());
            }
            now = t;
            driver.poses().to_vec()
        })
        .collect()
}

fn marker(m: &Mechanism, poses: &[Pose], id: MarkerId) -> [f64; 2] {
    poses[id.body].world(m.marker(id).at)
}

/// The designer's starting file: the known one with every point moved by
/// up to `by` (a fixed pattern), and a box of ±`half` around it, which
/// holds the known mechanism.
fn start(truth: &Mechanism, by: f64, half: f64) -> (Design, Vec<[f64; 2]>) {
    let d0 = Design::new(truth).unwrap();
    let p: Vec<f64> = (d0.drawn().iter().enumerate())
        .map(|(k, v)| v + by * [0.7, -0.4, 0.5, 0.9, -0.8, 0.3, -0.6, 1.0, 0.2, -0.9][k % 10])
        .collect();
    let design = Design::new(&d0.drawing(&p).unwrap()).unwrap();
    let bounds = p.iter().map(|v| [v - half, v + half]).collect();
    (design, bounds)
}

/// Ten seeds; each must reach RMS ≤ 1e-9 over `n` targets.
fn recovers(problem: &Problem, n: usize, what: &str) {
    for seed in 0..10 {
        let options = Options {
            seed,
            target: 1e-18 * n as f64,
            // A budget, not a time limit: the same search on any machine.
            time_limit: std::time::Duration::from_secs(3600),
            evaluations: Some(100_000),
            ..Options::default()
        };
        let out = search::run(problem, &options, &mut |_| {});
        let best = out
            .found
            .first()
            .unwrap_or_else(|| panic!("{what} seed {seed}: nothing found"));
        let rms = (best.sum_sq / n as f64).sqrt();
        assert!(
            rms <= 1e-9,
            "{what} seed {seed}: rms {rms:e} ({:?}, {} evaluations)",
            out.stop,
            out.evaluations
        );
        // The residuals say so too, recomputed at the solution.
        let (r, _) = problem.residuals(&best.z, false).unwrap();
        assert!((r.norm_squared() / n as f64).sqrt() <= 1e-9);
    }
}

fn path_recovery(file: &str, traced: &str, inputs: Vec<f64>, by: f64, half: f64) {
    let truth = load(file);
    let id = truth.find_marker(traced).unwrap();
    let points = frames(&truth, &inputs)
        .iter()
        .map(|p| marker(&truth, p, id))
        .collect();
    let (design, bounds) = start(&truth, by, half);
    let n = design.names().len();
    let goal = Goal::Path {
        marker: id,
        points,
        inputs: Some(inputs.clone()),
    };
    let problem = Problem::new(design, goal, 0, (0..n).collect(), bounds, Constraints::default()).unwrap();
    recovers(&problem, inputs.len(), file);
}

#[test]
fn a_fourbar_path_is_recovered() {
    let inputs = (0..18).map(|k| 20.0 * k as f64).collect();
    path_recovery("mechanisms/fourbar.toml", "coupler.P", inputs, 0.25, 1.0);
}

#[test]
fn a_slider_crank_path_is_recovered() {
    let inputs = (0..18).map(|k| 20.0 * k as f64).collect();
    path_recovery("mechanisms/slider_crank.toml", "slider.C", inputs, 0.1, 0.5);
}

#[test]
fn a_watt_sixbar_path_is_recovered() {
    let inputs = (0..18).map(|k| 20.0 * k as f64).collect();
    path_recovery("tests/synth/watt_sixbar.toml", "link4.Q", inputs, 0.1, 0.5);
}

#[test]
fn a_stephenson_sixbar_path_is_recovered() {
    let inputs = (0..18).map(|k| 20.0 * k as f64).collect();
    path_recovery("mechanisms/sixbar_a.toml", "link4.P", inputs, 0.1, 0.5);
}

#[test]
fn a_fourbar_function_is_recovered() {
    let truth = load("mechanisms/fourbar.toml");
    let inputs: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
    let joint = truth.joints.iter().position(|j| j.name == "D").unwrap();
    let pairs = (inputs.iter().zip(frames(&truth, &inputs)))
        .map(|(t, poses)| [*t, output(&truth, joint, &poses)])
        .collect();
    let (design, bounds) = start(&truth, 0.2, 1.0);
    // The coupler point plays no part in the output: held.
    let vary: Vec<usize> = (0..8).collect();
    let bounds = bounds[..8].to_vec();
    let problem = Problem::new(
        design,
        Goal::Function { joint, pairs },
        0,
        vary,
        bounds,
        Constraints::default(),
    )
    .unwrap();
    recovers(&problem, inputs.len(), "fourbar function");
}

#[test]
fn a_fourbar_coupler_motion_is_recovered() {
    let truth = load("mechanisms/fourbar.toml");
    let inputs: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
    let id = truth.find_marker("coupler.P").unwrap();
    let poses = (frames(&truth, &inputs).iter())
        .map(|p| {
            let w = marker(&truth, p, id);
            [w[0], w[1], p[id.body].rot.s.atan2(p[id.body].rot.c).to_degrees()]
        })
        .collect();
    let (design, bounds) = start(&truth, 0.2, 1.0);
    let n = design.names().len();
    let goal = Goal::Motion {
        body: id.body,
        marker: id,
        poses,
        inputs: Some(inputs.clone()),
    };
    let problem = Problem::new(design, goal, 0, (0..n).collect(), bounds, Constraints::default()).unwrap();
    recovers(&problem, inputs.len(), "fourbar motion");
}
