//! The derivatives of poses and markers with respect to the design
//! parameters: against a hand-derived four-bar and against central
//! differences of re-planned candidates on every bundled planar sweep.

use dofplan::model::{MarkerId, Mechanism};
use dofplan::simulate::sweep_inputs;
use dofplan::synth::planar::{sensitivity, Candidate, Design};
use dofplan::synth::SynthError;
use dofplan_runtime::planar::Pose;
use dofplan_runtime::{Driver, Options};

fn load(path: &str) -> Mechanism {
    let file = format!("{}/mechanisms/{path}", env!("CARGO_MANIFEST_DIR"));
    dofplan::load_file(std::path::Path::new(&file)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Runs a candidate over `requested` from its drawing; the poses of every
/// frame (None where the frame is not solved).
fn run(candidate: &Candidate, requested: &[Vec<f64>]) -> Vec<Option<Vec<Pose>>> {
    let mut driver = Driver::new(candidate.interpreter.clone(), Options::default());
    requested
        .iter()
        .map(|inputs| driver.frame(inputs).is_solved().then(|| driver.poses().to_vec()))
        .collect()
}

fn marker(m: &Mechanism, poses: &[Pose], id: MarkerId) -> [f64; 2] {
    poses[id.body].world(m.marker(id).at)
}

fn close(a: [f64; 2], b: [f64; 2], tol: f64) -> bool {
    (a[0] - b[0]).hypot(a[1] - b[1]) <= tol
}

#[test]
fn parameters_are_joints_and_free_markers() {
    let m = load("fourbar.toml");
    let design = Design::new(&m).unwrap();
    let names: Vec<&str> = design.names().iter().map(String::as_str).collect();
    assert_eq!(
        names,
        [
            "A.x",
            "A.y",
            "B.x",
            "B.y",
            "C.x",
            "C.y",
            "D.x",
            "D.y",
            "coupler.P.x",
            "coupler.P.y"
        ]
    );
    assert_eq!(design.drawn(), [0.0, 0.0, 1.0, 1.0, 4.5, 2.5, 4.0, 0.0, 3.0, 3.5]);
    match design.index("E.x") {
        Err(SynthError::UnknownParameter { name, .. }) => assert_eq!(name, "E.x"),
        other => panic!("{other:?}"),
    }
}

/// A candidate is its own drawing at input 0, and its frames close every
/// joint (the candidate's plan, not the original's constants).
#[test]
fn a_candidate_reproduces_its_drawing_and_closes_its_joints() {
    let m = load("fourbar.toml");
    let design = Design::new(&m).unwrap();
    let mut p = design.drawn();
    // Longer crank, ground pivot D moved, coupler point elsewhere.
    p[2] = 1.2;
    p[6] = 4.3;
    p[9] = 4.0;
    let c = design.prepare(&p).unwrap();
    let frames = run(&c, &[vec![0.0], vec![40.0], vec![200.0]]);
    let at0 = frames[0].as_ref().unwrap();
    for id in c.mechanism.all_markers() {
        assert!(close(
            marker(&c.mechanism, at0, id),
            c.mechanism.marker(id).at,
            1e-12
        ));
    }
    for poses in frames.iter().map(|f| f.as_ref().unwrap()) {
        for j in &c.mechanism.joints {
            let [a, b] = j.markers;
            assert!(close(
                marker(&c.mechanism, poses, a),
                marker(&c.mechanism, poses, b),
                1e-12
            ));
        }
    }
    // Bad values: a clear error, not a panic.
    assert!(matches!(
        design.prepare(&p[..3]),
        Err(SynthError::WrongLength {
            given: 3,
            expected: 10
        })
    ));
    p[0] = f64::NAN;
    assert!(matches!(design.prepare(&p), Err(SynthError::NotFinite { name }) if name == "A.x"));
}

/// Hand derivation on the four-bar A(0,0) B(1,1) C(4.5,2.5) D(4,0) at
/// θ = 90°: the crank pin is B(θ) = A + R(θ)(B − A), so dB/dA.x = (I −
/// R)e_x = (1, −1) and dB/dB.x = R e_x = (0, 1). C solves |C − B| = |C₀ −
/// B₀| and |C − D| = |C₀ − D₀|; differentiating with respect to D.x
/// (which moves D and the drawn rocker length L₂ = |C₀ − D₀|):
/// (C − B)·dC = 0 and (C − D)·(dC − e_x) = L₂ dL₂ with dL₂ = (D₀ − C₀)·e_x / L₂.
#[test]
fn fourbar_derivatives_match_the_hand_derivation() {
    let m = load("fourbar.toml");
    let design = Design::new(&m).unwrap();
    let c = design.prepare(&design.drawn()).unwrap();
    let requested: Vec<Vec<f64>> = (0..=90).map(|t| vec![t as f64]).collect();
    let frames = run(&c, &requested);
    let poses = frames[90].as_ref().unwrap();
    let s = sensitivity(&design, &c, poses, &[90.0]).unwrap();
    let ix = |n: &str| design.index(n).unwrap();
    let b = s.marker(m.find_marker("crank.B").unwrap());
    assert!(close(b[ix("A.x")], [1.0, -1.0], 1e-12), "{:?}", b[ix("A.x")]);
    assert!(close(b[ix("B.x")], [0.0, 1.0], 1e-12), "{:?}", b[ix("B.x")]);
    assert!(close(b[ix("D.x")], [0.0, 0.0], 1e-15));

    let cid = m.find_marker("rocker.C").unwrap();
    let (bw, cw, d) = (
        marker(&m, poses, m.find_marker("crank.B").unwrap()),
        marker(&m, poses, cid),
        [4.0, 0.0],
    );
    let (c0, d0): ([f64; 2], [f64; 2]) = ([4.5, 2.5], [4.0, 0.0]);
    let l2 = (c0[0] - d0[0]).hypot(c0[1] - d0[1]);
    let dl2 = (d0[0] - c0[0]) / l2;
    // [ (C−B)ᵀ ; (C−D)ᵀ ] dC = [ 0 ; L₂ dL₂ + (C−D)·e_x ]
    let (a11, a12, a21, a22) = (cw[0] - bw[0], cw[1] - bw[1], cw[0] - d[0], cw[1] - d[1]);
    let rhs = [0.0, l2 * dl2 + a21];
    let det = a11 * a22 - a12 * a21;
    let hand = [
        (rhs[0] * a22 - a12 * rhs[1]) / det,
        (a11 * rhs[1] - a21 * rhs[0]) / det,
    ];
    let got = s.marker(cid)[ix("D.x")];
    assert!(close(got, hand, 1e-12), "{got:?} vs {hand:?}");

    // At the drawing (θ = 0) a marker moves exactly with its own node.
    let s0 = sensitivity(&design, &c, frames[0].as_ref().unwrap(), &[0.0]).unwrap();
    let p = s0.marker(m.find_marker("coupler.P").unwrap());
    for (k, d) in p.iter().enumerate() {
        let own = match design.names()[k].as_str() {
            "coupler.P.x" => [1.0, 0.0],
            "coupler.P.y" => [0.0, 1.0],
            _ => [0.0, 0.0],
        };
        assert!(close(*d, own, 1e-12), "{}: {d:?}", design.names()[k]);
    }
}

/// Every bundled planar sweep: at three frames away from dead points, the
/// derivative of every marker with respect to each parameter agrees with a
/// central difference of two re-planned candidates run over the same sweep
/// prefix (so on the same branch). Large mechanisms test an evenly spread
/// dozen of their parameters.
#[test]
fn derivatives_match_central_differences_on_every_planar_sweep() {
    let dir = format!("{}/mechanisms", env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    let (mut checked, mut skipped, mut near_dead) = (0, Vec::new(), Vec::new());
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let m = load(&name);
        let design = Design::new(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        let base = design.prepare(&design.drawn()).unwrap();
        let requested = sweep_inputs(&m, Some(37));
        let frames = run(&base, &requested);
        let n = design.names().len();
        let params: Vec<usize> = if n <= 12 {
            (0..n).collect()
        } else {
            (0..12).map(|i| i * n / 12).collect()
        };
        let size = m.size();
        let h = 1e-6 * size;
        for f in [9, 18, 27] {
            let Some(poses) = &frames[f] else { continue };
            let s = match sensitivity(&design, &base, poses, &requested[f]) {
                Ok(s) if s.conditioning > 1e-4 => s,
                other => {
                    let why = other.map(|s| format!("conditioning {:.1e}", s.conditioning));
                    near_dead.push(format!("{name} frame {f}: {why:?}"));
                    continue;
                }
            };
            for &k in &params {
                if s.misfit[k] > 1e-9 {
                    continue;
                }
                let at = |sign: f64| {
                    let mut p = design.drawn();
                    p[k] += sign * h;
                    let c = design
                        .prepare(&p)
                        .unwrap_or_else(|e| panic!("{name} {}: {e}", design.names()[k]));
                    let frames = run(&c, &requested[..=f]);
                    frames[f].clone().map(|poses| (c, poses))
                };
                // A mechanism drawn at a boundary of its class (a
                // parallelogram, Grashof's equality) stops turning fully on
                // one side of it: no two-sided difference there.
                let (Some((cp, pp)), Some((cm, pm))) = (at(1.0), at(-1.0)) else {
                    skipped.push(format!("{name} frame {f} {}", design.names()[k]));
                    continue;
                };
                for id in m.all_markers() {
                    let exact = s.marker(id)[k];
                    let (a, b) = (marker(&cp.mechanism, &pp, id), marker(&cm.mechanism, &pm, id));
                    let fd = [(a[0] - b[0]) / (2.0 * h), (a[1] - b[1]) / (2.0 * h)];
                    let tol = 1e-5 * (1.0 + exact[0].hypot(exact[1]));
                    assert!(
                        close(exact, fd, tol),
                        "{name} frame {f} d({})/d({}): exact {exact:?}, central difference {fd:?}",
                        m.marker_name(id),
                        design.names()[k]
                    );
                }
            }
            checked += 1;
        }
    }
    eprintln!("{checked} frames checked; near a dead point: {near_dead:?}; one-sided: {skipped:?}");
    assert!(checked >= 60, "only {checked} frames checked");
    // Only the parallelogram is drawn on a boundary of its class.
    assert!(
        skipped
            .iter()
            .all(|s: &String| s.starts_with("parallelogram.toml")),
        "{skipped:?}"
    );
}
