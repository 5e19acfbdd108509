//! Compiled design modules (`Config::design`): a candidate prepared by the
//! generated `prepare` runs the same frames as the same candidate planned
//! by the library's `Design` (re-analysis of the moved drawing: a second,
//! independent way to the candidate's numbers and branches), every frame
//! closing the candidate's joints; the drawn parameters give the module's
//! own plan to the bit; bad candidates are errors naming what is wrong.

use dofplan::interp::Interpreter;
use dofplan::simulate::planar::residuals;
use dofplan::simulate::sweep_inputs;
use dofplan::synth::planar::Design;
use dofplan_runtime::design::PrepareError;
use dofplan_runtime::{BranchPolicy, Break, Ctx, Pose, Solver};
use dofplan_tests::{bundled, designed, load, pose_gap};

/// One design module: its parameter count, and a candidate's frames (each
/// the poses, or the break) for parameter values and inputs.
type Frames = Result<Vec<Result<Vec<Pose>, Break>>, PrepareError>;
type Run = fn(&[f64], &[Vec<f64>]) -> Frames;
/// The module's own `solve` from its drawn state.
type Own = fn(&[Vec<f64>]) -> Vec<Result<Vec<Pose>, Break>>;
/// A candidate's frames through `solve_frames_with` (in lanes): every
/// frame's poses, or the first break and its frame.
type InLanes = fn(&[f64], &[Vec<f64>]) -> Result<Result<Vec<Vec<Pose>>, (usize, Break)>, PrepareError>;

macro_rules! design {
    ($m:ident) => {
        (
            stringify!($m),
            dofplan_generated::$m::design::PARAMETERS,
            (|values: &[f64], frames: &[Vec<f64>]| {
                use dofplan_generated::$m::design;
                let p = design::Params(values.try_into().expect("one value per parameter"));
                let g = design::prepare(&p)?;
                let mut s = g.state();
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                Ok(frames
                    .iter()
                    .map(|u| design::solve_with(&g, &mut s, u, &mut ctx).map(|()| s.poses.to_vec()))
                    .collect())
            }) as Run,
            (|frames: &[Vec<f64>]| {
                use dofplan_generated::$m as module;
                let mut s = module::State::DRAWN;
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                frames
                    .iter()
                    .map(|u| module::solve(&mut s, u, &mut ctx).map(|()| s.poses.to_vec()))
                    .collect()
            }) as Own,
            (|values: &[f64], frames: &[Vec<f64>]| {
                use dofplan_generated::$m::{design, BODIES};
                let p = design::Params(values.try_into().expect("one value per parameter"));
                let g = design::prepare(&p)?;
                let inputs: Vec<f64> = frames.concat();
                let mut out = vec![Pose::IDENTITY; frames.len() * BODIES.len()];
                Ok(design::solve_frames_with(&g, &inputs, &mut out)
                    .map(|()| out.chunks(BODIES.len()).map(|row| row.to_vec()).collect()))
            }) as InLanes,
        )
    };
}

/// Every design module dofplan-generated compiles.
fn modules() -> Vec<(&'static str, usize, Run, Own, InLanes)> {
    vec![
        design!(fourbar),
        design!(inverted_slider_crank),
        design!(jansen),
        design!(pantograph),
        design!(parallelogram),
        design!(peaucellier),
        design!(rocker_rocker),
        design!(sixbar_a),
        design!(slider_crank),
        design!(table),
        design!(trammel),
        design!(vlink),
    ]
}

#[test]
fn every_closed_form_bundled_mechanism_has_its_design_module_here() {
    let here: Vec<&str> = modules().iter().map(|m| m.0).collect();
    let expected: Vec<String> = bundled().into_iter().filter(|n| designed(n)).collect();
    assert_eq!(here, expected);
}

/// The drawn parameters give the module's own frames: to the bit where
/// every number is a marker's coordinate or a radius (the same operations
/// on the same numbers), to round-off where a turned line's offset is
/// computed from the point it passes rather than from the line's marker.
#[test]
fn the_drawn_parameters_give_the_modules_own_frames() {
    for (name, n, run, own, _) in modules() {
        let m = load(name);
        let design = Design::new(&m).expect("a design");
        assert_eq!(n, design.names().len(), "{name}");
        let frames = sweep_inputs(&m, None);
        let compiled = run(&design.drawn(), &frames).unwrap_or_else(|e| panic!("{name}: {e}"));
        let own = own(&frames);
        let turns =
            (design.plan().steps.iter()).any(|s| matches!(s.kind, dofplan::plan::StepKind::TurnLine { .. }));
        if !turns {
            assert!(compiled == own, "{name}: not the same frames to the bit");
        }
        for (i, (a, b)) in compiled.iter().zip(&own).enumerate() {
            match (a, b) {
                (Ok(a), Ok(b)) => {
                    let d = a.iter().zip(b).map(|(p, q)| pose_gap(p, q)).fold(0.0, f64::max);
                    assert!(d <= 1e-12, "{name} frame {i}: differ by {d:e}");
                }
                (Err(a), Err(b)) => assert_eq!(a.step, b.step, "{name} frame {i}"),
                _ => panic!("{name} frame {i}: one breaks, the other does not"),
            }
        }
    }
}

/// A small generator of deterministic candidates (no dependency for it).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

#[test]
fn compiled_candidates_run_the_frames_of_the_re_planned_ones_and_close_their_joints() {
    let mut checked = 0;
    for (name, _, run, _, _) in modules() {
        let m = load(name);
        let design = Design::new(&m).expect("a design");
        let size = m.size();
        let frames = sweep_inputs(&m, Some(60));
        let mut rng = Lcg(0x5eed ^ name.len() as u64);
        for candidate in 0..6 {
            // Every parameter moved by up to 2 % of the mechanism's size.
            let values: Vec<f64> = design
                .drawn()
                .iter()
                .map(|v| v + 0.02 * size * rng.next())
                .collect();
            let replanned = match design.prepare(&values) {
                Ok(c) => c,
                // The library refuses a candidate whose re-analysis makes
                // another plan; the compiled prepare is not asked to.
                Err(_) => continue,
            };
            let compiled =
                run(&values, &frames).unwrap_or_else(|e| panic!("{name} candidate {candidate}: {e}"));
            let interp: &Interpreter = &replanned.interpreter;
            let mut state = interp.initial_state();
            let mut ctx = Ctx::new(BranchPolicy::Keep, false);
            for (i, (inputs, got)) in frames.iter().zip(&compiled).enumerate() {
                let want = interp.solve(&mut state, inputs, &mut ctx);
                let Ok(poses) = got else {
                    assert!(
                        want.is_err(),
                        "{name} candidate {candidate} frame {i}: only compiled breaks"
                    );
                    continue;
                };
                assert!(
                    want.is_ok(),
                    "{name} candidate {candidate} frame {i}: only the interpreter breaks"
                );
                for (a, b) in poses.iter().zip(&state.poses) {
                    let d = pose_gap(a, b);
                    assert!(
                        d <= 1e-9,
                        "{name} candidate {candidate} frame {i}: differ by {d:e}"
                    );
                }
                let worst = residuals(&replanned.mechanism, poses, inputs)
                    .iter()
                    .map(|r| r.value)
                    .fold(0.0, f64::max);
                assert!(
                    worst <= 1e-9 * size,
                    "{name} candidate {candidate} frame {i}: residual {worst:e}"
                );
                checked += 1;
            }
        }
    }
    // Most candidates keep their plan: the comparison is not vacuous.
    assert!(checked > 2000, "only {checked} frames compared");
}

/// A candidate's frames in lanes (`solve_frames_with`: each from the
/// candidate's drawn state, eight at a time) are, to the bit, those of
/// `solve_with` frame after frame; where a frame breaks, the lanes report
/// that frame and the same step, the frames before it the same poses.
#[test]
fn a_candidates_frames_in_lanes_are_its_frames_one_by_one() {
    let (mut compared, mut broken) = (0, 0);
    for (name, _, run, _, in_lanes) in modules() {
        let m = load(name);
        let design = Design::new(&m).expect("a design");
        let size = m.size();
        // A sweep past the input's range where it has one: frames break.
        let mut frames = sweep_inputs(&m, Some(60));
        frames.extend(
            sweep_inputs(&m, Some(60))
                .iter()
                .map(|u| u.iter().map(|v| 1.7 * v).collect::<Vec<_>>()),
        );
        let mut rng = Lcg(0x1a9e5 ^ name.len() as u64);
        for candidate in 0..6 {
            let values: Vec<f64> = (design.drawn().iter())
                .map(|v| {
                    if candidate == 0 {
                        *v
                    } else {
                        v + 0.02 * size * rng.next()
                    }
                })
                .collect();
            let Ok(one_by_one) = run(&values, &frames) else {
                continue;
            };
            let lanes = in_lanes(&values, &frames).expect("prepared above");
            let first_break = one_by_one.iter().position(|f| f.is_err());
            match (&lanes, first_break) {
                (Ok(rows), None) => {
                    let want: Vec<Vec<Pose>> = one_by_one.into_iter().map(|f| f.unwrap()).collect();
                    assert!(
                        *rows == want,
                        "{name} candidate {candidate}: not the same frames to the bit"
                    );
                    compared += rows.len();
                }
                (Err((at, b)), Some(k)) => {
                    assert_eq!(*at, k, "{name} candidate {candidate}: another frame breaks");
                    assert_eq!(
                        b.step,
                        one_by_one[k].as_ref().unwrap_err().step,
                        "{name} candidate {candidate}"
                    );
                    broken += 1;
                }
                _ => panic!(
                    "{name} candidate {candidate}: lanes {:?}, one by one breaks at {first_break:?}",
                    lanes.as_ref().err()
                ),
            }
        }
    }
    assert!(
        compared > 1000 && broken > 0,
        "{compared} frames compared, {broken} candidates broke"
    );
}

#[test]
fn bad_candidates_are_errors_that_say_what_is_wrong() {
    use dofplan_generated::fourbar::design::{self, Params};
    let mut p = Params::DRAWN;
    let dy = Params::index("D.y").expect("fourbar has D");
    p.0[dy] = f64::NAN;
    let e = design::prepare(&p).expect_err("NaN");
    assert_eq!(e, PrepareError::NotFinite { parameter: "D.y" });
    assert!(e.to_string().contains("D.y"), "{e}");
    // The rocker's pivot D on the crank's tip B: the coupler's two circles
    // are concentric, so the coupler point is not determined.
    let mut p = Params::DRAWN;
    let (bx, by, dx) = (
        Params::index("B.x").unwrap(),
        Params::index("B.y").unwrap(),
        Params::index("D.x").unwrap(),
    );
    (p.0[dx], p.0[dy]) = (p.0[bx], p.0[by]);
    let e = design::prepare(&p).expect_err("concentric circles");
    assert!(matches!(e, PrepareError::Broken { step: 2, .. }), "{e:?}");
    assert!(e.to_string().contains("step 2"), "{e}");
    assert_eq!(Params::index("nowhere.x"), None);
}

#[test]
fn a_candidate_marker_is_read_where_the_candidate_draws_it() {
    use dofplan_generated::fourbar::{design, marker};
    let mut p = design::Params::DRAWN;
    let px = design::Params::index("coupler.P.x").unwrap();
    p.0[px] += 0.25;
    let g = design::prepare(&p).expect("a small move");
    let moved = g.marker(marker::COUPLER_P);
    assert_eq!(moved.local[0], marker::COUPLER_P.local[0] + 0.25);
    // At the drawing every body is at its identity pose: the marker is
    // where the candidate draws it.
    assert_eq!(g.state().marker(moved), moved.local);
}
