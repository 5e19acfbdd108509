//! The higher pairs compiled: the geared mechanisms' (`mechanisms/gears/`)
//! geared steps (a body turned to an angle affine in the inputs, a rack
//! moved by its pinion) and the slotted ones' (`mechanisms/slots/`) checks
//! of the slots' ends give the interpreter's frames and rates, one frame
//! at a time, in lanes (`solve_batch`) and in the split form, with the
//! inputs well past a full turn.

use dofplan::interp::Interpreter;
use dofplan::simulate::{run, sweep_inputs};
use dofplan_runtime::{BranchPolicy, Ctx, FrameStatus, Options, Solver};
use dofplan_tests::{mechanisms_dir, pose_gap};

fn load(name: &str) -> dofplan::model::Mechanism {
    let folder = if ["quick_return", "scotch_yoke", "arc_yoke", "curved_lever"].contains(&name) {
        "slots"
    } else {
        "gears"
    };
    dofplan::load_file(&mechanisms_dir().join(format!("{folder}/{name}.toml")))
        .unwrap_or_else(|e| panic!("{e}"))
}

/// The bundled sweep and, for every input, the same inputs turned or slid
/// past a full turn both ways (a gear's angle is kept unwrapped).
fn requests(m: &dofplan::model::Mechanism) -> Vec<Vec<f64>> {
    let mut out = sweep_inputs(m, None);
    for k in 0..24 {
        let t = -900.0 + 75.0 * k as f64;
        out.push((0..m.inputs.len()).map(|i| t * (1.0 + 0.37 * i as f64)).collect());
    }
    out
}

#[test]
fn compiled_higher_pairs_give_the_interpreter_s_frames_rates_and_lanes() {
    macro_rules! check {
        ($($module:ident),* $(,)?) => {$({
            use dofplan_generated::$module as compiled;
            use dofplan_generated::chunked::$module as split;
            let name = stringify!($module);
            let m = load(name);
            let plan = dofplan_tests::plan(&m);
            assert_eq!(plan.clusters(), 0, "{name}: gears and slots plan in closed form");
            let interp = Interpreter::new(plan);
            let requested = requests(&m);
            let frames = run(interp.clone(), Options::default(), &requested);
            let n = m.inputs.len();
            let rates: Vec<f64> = (0..n).map(|k| 30.0 - 7.0 * k as f64).collect();
            let accels: Vec<f64> = (0..n).map(|k| 2.0 + k as f64).collect();
            let (mut whole, mut chunked) = (compiled::State::DRAWN, split::State::DRAWN);
            for (i, (u, f)) in requested.iter().zip(&frames).enumerate() {
                assert_eq!(f.status, FrameStatus::Solved, "{name} frame {i}");
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                compiled::solve(&mut whole, u, &mut ctx).unwrap_or_else(|b| panic!("{name} frame {i}: {b:?}"));
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                split::solve(&mut chunked, u, &mut ctx).unwrap_or_else(|b| panic!("{name} frame {i}: {b:?}"));
                for (b, p) in f.poses.iter().enumerate() {
                    let gap = pose_gap(p, &whole.poses[b]).max(pose_gap(p, &chunked.poses[b]));
                    assert!(gap <= 1e-12, "{name} frame {i} body {b}: {gap:e}");
                }
                // Rates: the interpreter's jets from its own state.
                let mut state = interp.initial_state();
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                interp.solve(&mut state, u, &mut ctx).unwrap();
                let want = interp.rates(&state, u, &rates, &accels).unwrap();
                let got = compiled::rates(&whole, u, &rates, &accels).unwrap();
                for (b, (a, c)) in want.iter().zip(&got).enumerate() {
                    let gap = (a.rot.c.d - c.rot.c.d).abs()
                        .max((a.rot.s.dd - c.rot.s.dd).abs())
                        .max((a.at[0].d - c.at[0].d).abs())
                        .max((a.at[1].dd - c.at[1].dd).abs());
                    assert!(gap <= 1e-9, "{name} frame {i} body {b}: rates differ by {gap:e}");
                }
            }
            // In lanes, every frame on its own from the drawn pose.
            let flat: Vec<f64> = requested.iter().flatten().copied().collect();
            let bodies = m.bodies.len();
            let mut out = vec![dofplan_runtime::planar::Pose::IDENTITY; requested.len() * bodies];
            let mut status = vec![FrameStatus::Solved; requested.len()];
            compiled::solve_batch(&flat, &mut out, &mut status);
            for (i, f) in frames.iter().enumerate() {
                assert_eq!(status[i], FrameStatus::Solved, "{name} lane frame {i}");
                for b in 0..bodies {
                    let gap = pose_gap(&f.poses[b], &out[i * bodies + b]);
                    assert!(gap <= 1e-12, "{name} lane frame {i} body {b}: {gap:e}");
                }
            }
        })*};
    }
    check!(
        epicyclic,
        geared_fivebar,
        geared_hoist,
        rack_pinion,
        quick_return,
        scotch_yoke,
        arc_yoke,
        curved_lever
    );
}
