//! Compiled spatial plans: every bundled 3D mechanism, and every spatial
//! fixture (tests/fixtures/spatial/: the steps and cluster rows no bundled
//! one needs), compiled by `dofplan-generated`'s build.rs (as a user's
//! build.rs does) runs every frame of its sweep as the interpreter does, to
//! 1e-12, under every breaking and branch policy — also past the ends of
//! the sweeps, where frames break — and a break leaves the compiled state
//! as it was.

use dofplan::analysis::spatial::analyse;
use dofplan::emit::ident_for;
use dofplan::interp::spatial::Interpreter;
use dofplan::model::spatial::Mechanism;
use dofplan::simulate::sweep_requests;
use dofplan_runtime::spatial::Pose3;
use dofplan_runtime::{Animate, BranchPolicy, Break, BreakPolicy, Ctx, Driver, FrameStatus, Options};
use dofplan_tests::{all_options, bundled_spatial, load_spatial, spatial_fixtures};

/// The bundled spatial mechanisms and the spatial fixtures, by name.
fn every_spatial() -> Vec<String> {
    let mut names = bundled_spatial();
    names.extend(spatial_fixtures());
    names
}

/// Whether a file is one of the long generated chains, whose sweeps are
/// checked on fewer frames (a debug build runs hundreds of steps a frame).
fn is_stress(m: &Mechanism) -> bool {
    m.name.starts_with("spatial_stress_")
}

/// Whether a file's frames are driven past its sweep: every bundled one
/// but the stress chains, and the fixtures in closed form. (The fixtures'
/// large clusters break into least-squares searches that take minutes in a
/// debug build; the Stewart platform's cluster breaks there already.)
fn overreach(m: &Mechanism) -> bool {
    !is_stress(m) && (bundled_spatial().contains(&m.name) || tol(m, Options::default()) == EXACT)
}

/// The frames of `m`'s sweep (at most `max` of them, same ends), with its
/// ranges stretched by `reach` (1 = as written; more drives the inputs past
/// where the mechanism assembles, so frames break).
fn requests(m: &Mechanism, max: usize, reach: f64) -> Vec<Vec<f64>> {
    let mut sweep = m.sweep.clone().expect("every bundled file has a sweep");
    sweep.steps = sweep.steps.min(max);
    for s in &mut sweep.inputs {
        s.to = s.from + reach * (s.to - s.from);
    }
    sweep_requests(&sweep, m.inputs.len()).collect()
}

/// What a frame shows.
struct Frame3 {
    status: FrameStatus,
    inputs: Vec<f64>,
    poses: Vec<Pose3>,
    /// Newton's iterations, when the plan has a cluster.
    iterations: Option<u32>,
}

fn run(driver: &mut dyn Animate<Pose3>, requested: &[Vec<f64>]) -> Vec<Frame3> {
    requested
        .iter()
        .map(|r| {
            let status = driver.frame(r);
            Frame3 {
                status,
                inputs: driver.inputs().to_vec(),
                poses: driver.poses().to_vec(),
                iterations: driver.numeric().map(|r| r.iterations),
            }
        })
        .collect()
}

/// The largest difference of two poses' rotation entries and positions.
fn pose_gap(a: &Pose3, b: &Pose3) -> f64 {
    let mut d = 0.0_f64;
    for i in 0..3 {
        d = d.max((a.pos[i] - b.pos[i]).abs());
        for j in 0..3 {
            d = d.max((a.rot.m[i][j] - b.rot.m[i][j]).abs());
        }
    }
    d
}

/// Whether two frame statuses say the same: the same outcome at the same
/// step, the numbers in them within `tol` (relative beyond 1). A cluster's
/// Newton runs at fixed size in compiled code and at dynamic size in the
/// interpreter, whose matrix products may round differently in the last
/// bits: the gap a broken cluster reports is the same to rounding, not to
/// the bit.
fn same_status(a: &FrameStatus, b: &FrameStatus, tol: f64) -> bool {
    let close = |x: f64, y: f64| (x - y).abs() <= tol * x.abs().max(y.abs()).max(1.0);
    let same_break = |x: &Break, y: &Break| x.step == y.step && x.kind == y.kind && close(x.gap, y.gap);
    match (a, b) {
        (FrameStatus::Solved, FrameStatus::Solved) => true,
        (FrameStatus::Limited { brk: x }, FrameStatus::Limited { brk: y }) => same_break(x, y),
        (FrameStatus::Searched { brk: x, reached: rx }, FrameStatus::Searched { brk: y, reached: ry }) => {
            same_break(x, y) && close(*rx, *ry)
        }
        (
            FrameStatus::Stretched {
                step: sx,
                residual: rx,
            },
            FrameStatus::Stretched {
                step: sy,
                residual: ry,
            },
        ) => sx == sy && close(*rx, *ry),
        _ => false,
    }
}

/// How closely the back ends agree: the same arithmetic step by step, so
/// to rounding everywhere a frame follows one Newton path...
const EXACT: f64 = 1e-12;
/// ... and where a cluster breaks (the Stewart platform's legs too short
/// for it), to what the ill-conditioned solve there amplifies rounding to.
/// The compiled cluster computes exactly the interpreter's residuals and
/// Jacobian, but Newton runs at fixed size in compiled code and at dynamic
/// size in the interpreter, and `nalgebra` orders the sums of a dynamic
/// matrix product differently: the last bits differ. (With a fixed-size
/// Newton in the interpreter the two agree bit for bit, every frame, every
/// policy.) The bisection of the search policy then ends on poses that
/// differ by about 1e-11: the tolerance of tests/planar/mixed.rs for planar
/// clusters covers it...
const AT_A_CLUSTER_BREAK: f64 = 1e-9;
/// ... and the stretch policy keeps the least-squares point of each broken
/// frame, which a flat minimum determines only so far: frame after frame
/// the two drift apart by up to 2e-6 (of a platform of size 3.3) over the
/// Stewart platform's overreach, each a least-squares point to rounding.
const STRETCHED_CLUSTER: f64 = 1e-5;

/// Runs `compiled` and the interpreter through `requested` and asserts
/// they agree frame by frame: the same status, the same inputs reached,
/// every pose within `tol` — and, at [`EXACT`], Newton's iterations the
/// same. Returns how many frames did not solve.
fn agree(
    m: &Mechanism,
    what: &str,
    compiled: &mut dyn Animate<Pose3>,
    opts: Options,
    requested: &[Vec<f64>],
    tol: f64,
) -> usize {
    let plan = analyse(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
    let mut interpreted = Driver::new(Interpreter::new(plan), opts);
    let a = run(&mut interpreted, requested);
    let b = run(compiled, requested);
    let name = &m.name;
    let (policy, branch) = (opts.breaking, opts.branch);
    for (i, (fa, fb)) in a.iter().zip(&b).enumerate() {
        assert!(
            same_status(&fa.status, &fb.status, tol),
            "{name} ({what}) frame {i} status ({policy:?}, {branch:?}): {:?} and {:?}",
            fa.status,
            fb.status
        );
        assert_eq!(fa.inputs, fb.inputs, "{name} ({what}) frame {i} inputs");
        if tol == EXACT {
            assert_eq!(
                fa.iterations, fb.iterations,
                "{name} ({what}) frame {i}: Newton iterations"
            );
        }
        for (k, (pa, pb)) in fa.poses.iter().zip(&fb.poses).enumerate() {
            let d = pose_gap(pa, pb);
            assert!(
                d <= tol,
                "{name} ({what}) frame {i} ({policy:?}, {branch:?}): body {k} differs by {d:e}"
            );
        }
    }
    a.iter().filter(|f| !f.status.is_solved()).count()
}

/// [`EXACT`] for a closed-form plan; for one with a numeric cluster, where
/// frames break, [`AT_A_CLUSTER_BREAK`], or [`STRETCHED_CLUSTER`] under the
/// stretch policy.
fn tol(m: &Mechanism, opts: Options) -> f64 {
    let plan = analyse(m).unwrap_or_else(|e| panic!("{}: {e}", m.name));
    if plan.cluster_size() == (0, 0) {
        EXACT
    } else if opts.breaking == BreakPolicy::Stretch {
        STRETCHED_CLUSTER
    } else {
        AT_A_CLUSTER_BREAK
    }
}

#[test]
fn every_bundled_spatial_mechanism_is_compiled() {
    let mut expected: Vec<String> = every_spatial()
        .iter()
        .map(|f| ident_for(&load_spatial(f).name))
        .collect();
    expected.sort();
    let mut compiled: Vec<String> = dofplan_generated::SPATIAL_MECHANISMS
        .iter()
        .map(|s| s.to_string())
        .collect();
    compiled.sort();
    assert_eq!(compiled, expected);
    // Planar names stay in `MECHANISMS` (their drivers animate planar
    // poses); `source` covers both.
    for name in &expected {
        assert!(!dofplan_generated::MECHANISMS.contains(&name.as_str()), "{name}");
        assert!(dofplan_generated::source(name).is_some(), "{name}");
        assert!(
            dofplan_generated::driver(name, Options::default()).is_none(),
            "{name}"
        );
    }
}

#[test]
fn compiled_and_interpreted_agree_on_every_frame() {
    for f in every_spatial() {
        let m = load_spatial(&f);
        let max = if is_stress(&m) { 13 } else { usize::MAX };
        let requested = requests(&m, max, 1.0);
        for opts in all_options() {
            let name = ident_for(&m.name);
            let mut compiled = dofplan_generated::spatial_driver(&name, opts)
                .unwrap_or_else(|| panic!("{name} is not compiled into dofplan-generated"));
            let broken = agree(&m, "sweep", compiled.as_mut(), opts, &requested, EXACT);
            assert_eq!(broken, 0, "{name}: the bundled sweeps solve every frame");
        }
    }
}

/// Past the ends of the sweeps (three times as far, either way) the
/// cylinders overreach and the linkages lock: frames break — in closed-form
/// steps (the excavator's dyads) and in a numeric cluster (the Stewart
/// platform's legs too short for it) — and the policies (hold, bisect,
/// stretch) act on both back ends alike.
#[test]
fn compiled_and_interpreted_agree_where_frames_break() {
    let mut broken = Vec::new();
    for f in every_spatial() {
        let m = load_spatial(&f);
        if !overreach(&m) {
            continue;
        }
        let name = ident_for(&m.name);
        let mut total = 0;
        for reach in [3.0, -3.0] {
            let requested = requests(&m, 61, reach);
            for opts in all_options() {
                let mut compiled = dofplan_generated::spatial_driver(&name, opts).expect("compiled");
                total += agree(
                    &m,
                    "overreach",
                    compiled.as_mut(),
                    opts,
                    &requested,
                    tol(&m, opts),
                );
            }
        }
        if total > 0 {
            broken.push(name);
        }
    }
    // The comparison above means something only where frames break.
    for expected in ["excavator", "stewart"] {
        assert!(
            broken.iter().any(|b| b == expected),
            "no frame of {expected} broke: {broken:?}"
        );
    }
}

/// The split form (`emit_spatial_chunked`, a function of a step or two
/// each): the same frames.
#[test]
fn the_split_form_agrees_too() {
    for f in every_spatial() {
        let m = load_spatial(&f);
        if is_stress(&m) {
            continue;
        }
        let name = ident_for(&m.name);
        for (reach, max) in [(1.0, usize::MAX), (3.0, 61), (-3.0, 61)] {
            if reach != 1.0 && !overreach(&m) {
                continue;
            }
            let requested = requests(&m, max, reach);
            for opts in all_options() {
                let mut compiled = dofplan_generated::chunked::spatial_driver(&name, opts)
                    .unwrap_or_else(|| panic!("{name} has no split form"));
                let tol = if reach == 1.0 { EXACT } else { tol(&m, opts) };
                agree(&m, "split", compiled.as_mut(), opts, &requested, tol);
            }
        }
    }
}

/// `solve` is a transaction: a frame that breaks returns the break and
/// leaves the state exactly as it was (poses, pseudo-markers, branches).
#[test]
fn a_break_leaves_the_compiled_state_unchanged() {
    use dofplan_generated::excavator::{solve, State, INPUTS};
    let m = load_spatial("excavator");
    let plan = analyse(&m).expect("plans");
    let mut interpreted = Driver::new(Interpreter::new(plan), Options::default());
    // A few frames in, so the state is not the drawing.
    let mut s = State::DRAWN;
    let mut inputs = vec![0.0; INPUTS.len()];
    for k in 1..=5 {
        inputs[0] = 4.0 * f64::from(k);
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        solve(&mut s, &inputs, &mut ctx).expect("a small slew solves");
        assert!(interpreted.frame(&inputs).is_solved());
    }
    let before = s;
    // Both cylinders far out: the boom's dyad cannot close.
    let far: Vec<f64> = (0..INPUTS.len())
        .map(|i| if i == 0 { 20.0 } else { 50.0 })
        .collect();
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    let brk = solve(&mut s, &far, &mut ctx).expect_err("the cylinders overreach");
    assert_eq!(s, before, "a break changed the state");
    // The interpreter breaks at the same step.
    match interpreted.frame(&far) {
        FrameStatus::Limited { brk: b } => assert_eq!(b.step, brk.step),
        other => panic!("the interpreter did not break: {other:?}"),
    }
    // And the state still solves the next frame from where it was.
    inputs[0] = 24.0;
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    solve(&mut s, &inputs, &mut ctx).expect("back in reach");
}

/// The generated constants name what the file names: each marker constant
/// reads the marker's world position from the compiled poses, and the
/// drawn state is the drawing.
#[test]
fn marker_constants_read_the_compiled_poses() {
    use dofplan_generated::rssr::{body, marker, Plan, State, BODIES, INPUTS, INPUT_KINDS};
    assert_eq!(BODIES[body::COUPLER], "coupler");
    assert_eq!(INPUTS, ["theta"]);
    assert_eq!(INPUT_KINDS, [dofplan_runtime::planar::InputKind::Angle]);
    let m = load_spatial("rssr");
    let id = m.find_marker("coupler.M").expect("rssr has coupler.M");
    assert_eq!(State::DRAWN.marker(marker::COUPLER_M), m.marker(id).at);
    let mut driver = Driver::new(Plan, Options::default());
    assert!(driver.frame(&[40.0]).is_solved());
    let at = marker::COUPLER_M.world(driver.poses());
    let expected = driver.poses()[id.body].world(m.marker(id).at);
    assert_eq!(at, expected);
    assert_ne!(at, m.marker(id).at, "the coupler moved");
}

/// Rotations composed frame after frame drift from orthonormal, and a body
/// that is no longer rigid eventually fails its mechanism's redundant
/// checks (the sofa bed did after about a million frames). Each frame
/// corrects them: after 120,000 frames every rotation is orthonormal to
/// rounding and every joint still closes.
#[test]
fn long_runs_keep_every_body_rigid() {
    use dofplan::simulate::spatial::residual;
    let m = dofplan_tests::load_spatial("sofa_bed");
    let inputs: Vec<Vec<f64>> =
        dofplan::simulate::sweep_requests(m.sweep.as_ref().unwrap(), m.inputs.len()).collect();
    let mut d = dofplan_generated::spatial_driver("sofa_bed", dofplan_runtime::Options::default()).unwrap();
    for _ in 0..2000 {
        for i in &inputs {
            assert!(d.frame(i).is_solved());
        }
    }
    for p in d.poses() {
        let r = &p.rot.m;
        for a in 0..3 {
            for b in 0..3 {
                let dot: f64 = (0..3).map(|k| r[k][a] * r[k][b]).sum();
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((dot - want).abs() < 2e-14, "RᵀR off by {:e}", dot - want);
            }
        }
    }
    assert!(residual(&m, d.poses(), d.inputs()) < 1e-12);
}
