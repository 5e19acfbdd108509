//! Spatial function and motion generation on the bundled RSSR: its output
//! angle law, and its rocker's motion (a marker's position and the body's
//! turn), each sampled from the RSSR and found again from another drawing
//! and a random population to RMS ≤ 1e-9 for ten seeds of ten; and both
//! problems' Jacobians against central differences.

use dofplan::model::spatial::Mechanism;
use dofplan::synth::search::{self, Objective, Options};
use dofplan::synth::spatial::{output, BodyPose, Design, Function, Motion};
use dofplan_runtime::spatial::Pose3;
use dofplan_runtime::{Driver, Options as DriveOptions};

fn rssr() -> Mechanism {
    let path = format!("{}/mechanisms/spatial/rssr.toml", env!("CARGO_MANIFEST_DIR"));
    match dofplan::load_any(std::path::Path::new(&path)).unwrap() {
        dofplan::model::Model::Spatial(m) => m,
        _ => unreachable!("the RSSR is spatial"),
    }
}

/// `read` of the poses at each of `inputs`, the mechanism run up from its
/// drawing in steps of a tenth of the way (so it stays on its branch).
fn run_up<T>(m: &Mechanism, inputs: &[f64], read: impl Fn(f64, &[Pose3]) -> T) -> Vec<T> {
    let plan = dofplan::analysis::spatial::analyse(m).unwrap();
    let mut driver = Driver::new(
        dofplan::interp::spatial::Interpreter::new(plan),
        DriveOptions::default(),
    );
    let mut now = 0.0;
    inputs
        .iter()
        .map(|&t| {
            for s in 1..=10 {
                assert!(driver.frame(&[now + (t - now) * s as f64 / 10.0]).is_solved());
            }
            now = t;
            read(t, driver.poses())
        })
        .collect()
}

/// The output angle of joint D at `inputs`.
fn law(m: &Mechanism, inputs: &[f64]) -> Vec<[f64; 2]> {
    let d = m.joints.iter().position(|j| j.name == "D").unwrap();
    run_up(m, inputs, |t, poses| [t, output(m, d, poses)])
}

/// The problem on a drawing with every pivot and pin moved, the coupler
/// point held (it plays no part in the output).
fn problem(truth: &Mechanism) -> Function {
    let inputs: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
    let pairs = law(truth, &inputs);
    let d0 = Design::new(truth).unwrap();
    let nudge = [
        0.05, -0.04, 0.03, 0.06, -0.05, 0.02, -0.03, 0.05, 0.04, -0.06, 0.03, 0.05,
    ];
    let mut p = d0.drawn();
    let vary: Vec<usize> = (0..12).collect();
    for (&k, d) in vary.iter().zip(nudge) {
        p[k] += d;
    }
    let design = Design::new(&d0.drawing(&p).unwrap()).unwrap();
    assert_eq!(
        design.names()[..12].join(" "),
        "A.x A.y A.z B.x B.y B.z C.x C.y C.z D.x D.y D.z"
    );
    let bounds = vary.iter().map(|&k| [p[k] - 0.3, p[k] + 0.3]).collect();
    let joint = truth.joints.iter().position(|j| j.name == "D").unwrap();
    Function::new(design, joint, pairs, 0, vary, bounds).unwrap()
}

#[test]
fn the_jacobian_matches_central_differences() {
    jacobian_matches_central_differences(&problem(&rssr()));
}

/// The exact Jacobian of `f` at its box's centre against central
/// differences.
fn jacobian_matches_central_differences(f: &impl Objective) {
    let x: Vec<f64> = f.bounds().iter().map(|b| 0.5 * (b[0] + b[1])).collect();
    let (_, j) = f.residuals(&x, true).unwrap();
    let j = j.unwrap();
    let h = 1e-6;
    for k in 0..x.len() {
        let at = |s: f64| {
            let mut y = x.clone();
            y[k] += s * h;
            f.residuals(&y, false).unwrap().0
        };
        let fd = (at(1.0) - at(-1.0)) / (2.0 * h);
        for i in 0..fd.len() {
            assert!(
                (fd[i] - j[(i, k)]).abs() <= 1e-5 * (1.0 + j[(i, k)].abs()),
                "row {i} column {k}: {} vs {}",
                j[(i, k)],
                fd[i]
            );
        }
    }
}

#[test]
fn an_rssr_output_law_is_recovered() {
    recovered_for_ten_seeds(&problem(&rssr()), 12, 100_000);
}

/// A rotation matrix's rotation vector in degrees (angles below 180°),
/// written out here rather than taken from the library under test: the
/// angle as the arc tangent of the skew part's length over the trace's
/// cosine, exact to round-off near the identity (the arc cosine of the
/// trace alone loses half the digits there).
fn rotation_vector(m: [[f64; 3]; 3]) -> [f64; 3] {
    let v = [
        (m[2][1] - m[1][2]) / 2.0,
        (m[0][2] - m[2][0]) / 2.0,
        (m[1][0] - m[0][1]) / 2.0,
    ];
    let sin = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let cos = (m[0][0] + m[1][1] + m[2][2] - 1.0) / 2.0;
    if sin == 0.0 {
        return [0.0; 3];
    }
    let k = sin.atan2(cos) / sin;
    v.map(|x| (x * k).to_degrees())
}

/// The rocker's motion (its marker C and its turn) at `inputs`.
fn rocker_motion(m: &Mechanism, inputs: &[f64]) -> Vec<BodyPose> {
    let c = m.find_marker("rocker.C").unwrap();
    let local = m.marker(c).at;
    run_up(m, inputs, |t, poses| {
        let pose = poses[c.body];
        BodyPose {
            input: t,
            at: pose.world(local),
            turn: rotation_vector(pose.rot.m),
        }
    })
}

/// Motion generation of the RSSR's rocker on a drawing with every pivot
/// and pin moved, as [`problem`] does for its output law.
fn motion_problem(truth: &Mechanism) -> Motion {
    let inputs: Vec<f64> = (0..12).map(|k| 30.0 * k as f64).collect();
    let poses = rocker_motion(truth, &inputs);
    let d0 = Design::new(truth).unwrap();
    let nudge = [
        0.05, -0.04, 0.03, 0.06, -0.05, 0.02, -0.03, 0.05, 0.04, -0.06, 0.03, 0.05,
    ];
    let mut p = d0.drawn();
    let vary: Vec<usize> = (0..12).collect();
    for (&k, d) in vary.iter().zip(nudge) {
        p[k] += d;
    }
    let moved = d0.drawing(&p).unwrap();
    let marker = moved.find_marker("rocker.C").unwrap();
    let design = Design::new(&moved).unwrap();
    let bounds = vary.iter().map(|&k| [p[k] - 0.3, p[k] + 0.3]).collect();
    Motion::new(design, marker, poses, 0, vary, bounds).unwrap()
}

#[test]
fn the_motion_jacobian_matches_central_differences() {
    jacobian_matches_central_differences(&motion_problem(&rssr()));
}

/// The rocker's motion — marker C's position and the rocker's turn at 12
/// crank angles, 72 residuals — found again from the moved drawing and a
/// random population, to RMS ≤ 1e-9 (length units, and radians times the
/// size) for ten seeds of ten.
#[test]
fn an_rssr_rockers_motion_is_recovered() {
    recovered_for_ten_seeds(&motion_problem(&rssr()), 72, 20_000);
}

/// The search finds `f`'s targets again to RMS ≤ 1e-9 over its `residuals`
/// for seeds 0 to 9, each within `evaluations`.
fn recovered_for_ten_seeds(f: &impl Objective, residuals: usize, evaluations: usize) {
    let n = residuals as f64;
    for seed in 0..10 {
        let options = Options {
            seed,
            target: 1e-18 * n,
            time_limit: std::time::Duration::from_secs(3600),
            evaluations: Some(evaluations),
            ..Options::default()
        };
        let out = search::run(f, &options, &mut |_| {});
        let best = out
            .found
            .first()
            .unwrap_or_else(|| panic!("seed {seed}: nothing found"));
        let rms = (best.sum_sq / n).sqrt();
        assert!(
            rms <= 1e-9,
            "seed {seed}: rms {rms:e} ({:?}, {} evaluations)",
            out.stop,
            out.evaluations
        );
    }
}
