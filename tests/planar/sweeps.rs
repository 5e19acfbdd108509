//! Every frame of every bundled sweep: every joint, constraint and input
//! holds to 1e-9 of the mechanism's size, and the compiled plan and the
//! interpreter agree to 1e-12, under every breaking policy.

use dofplan::interp::Interpreter;
use dofplan::simulate::{max_relative_residual, run, run_animate, sweep_inputs, Frame};
use dofplan_runtime::{BranchPolicy, BreakPolicy, Options};
use dofplan_tests::{bundled, load, plan};

fn options(breaking: BreakPolicy, branch: BranchPolicy) -> Options {
    Options {
        breaking,
        branch,
        ..Options::default()
    }
}

fn compiled(name: &str, opts: Options, requested: &[Vec<f64>]) -> Vec<Frame> {
    let mut driver = dofplan_generated::driver(name, opts)
        .unwrap_or_else(|| panic!("{name} is not compiled into dofplan-generated"));
    run_animate(driver.as_mut(), requested)
}

#[test]
fn every_bundled_mechanism_is_compiled() {
    // ... and the drag demo, compiled by `Config::drag`.
    let mut expected = bundled();
    expected.push("open_chain_15_drag_link_15_e".to_string());
    // ... and the test fixtures.
    expected.push("sixbar_slotted".to_string());
    expected.push("slider_driven".to_string());
    expected.push("fivebar_arm".to_string());
    expected.push("narrow_gap".to_string());
    // ... and the planar files with loads, with their forces modules.
    expected.push("fourbar_weights".to_string());
    expected.push("slider_crank_press".to_string());
    expected.push("arc_yoke_press".to_string());
    // ... and the geared ones and those with slots.
    for name in [
        "epicyclic",
        "geared_fivebar",
        "geared_hoist",
        "rack_pinion",
        "quick_return",
        "scotch_yoke",
        "arc_yoke",
        "curved_lever",
    ] {
        expected.push(name.to_string());
    }
    expected.sort();
    let mut compiled: Vec<String> = dofplan_generated::MECHANISMS
        .iter()
        .map(|s| s.to_string())
        .collect();
    compiled.sort();
    assert_eq!(compiled, expected);
}

#[test]
fn every_frame_of_every_sweep_holds_its_joints() {
    for name in bundled() {
        let m = load(&name);
        let requested = sweep_inputs(&m, None);
        assert!(!requested.is_empty(), "{name} has a sweep");
        for (policy, branch) in [
            (BreakPolicy::Limit, BranchPolicy::Keep),
            (BreakPolicy::Search, BranchPolicy::Keep),
            (BreakPolicy::Limit, BranchPolicy::Nearest),
        ] {
            let frames = run(Interpreter::new(plan(&m)), options(policy, branch), &requested);
            for (i, f) in frames.iter().enumerate() {
                // A broken frame stays at (limit) or moves to (search) a
                // valid pose whose inputs are `f.inputs`.
                let r = max_relative_residual(&m, &f.poses, &f.inputs);
                assert!(
                    r <= 1e-9,
                    "{name} frame {i} ({policy:?}, {branch:?}, {}): relative residual {r:e}",
                    f.status.name()
                );
            }
        }
    }
}

#[test]
fn sweeps_without_break_points_solve_every_frame() {
    // rocker_rocker is driven past its limits on purpose; everything else
    // turns through its whole sweep.
    for name in bundled().into_iter().filter(|n| n != "rocker_rocker") {
        let m = load(&name);
        let frames = run(
            Interpreter::new(plan(&m)),
            Options::default(),
            &sweep_inputs(&m, None),
        );
        let broken: Vec<usize> = (0..frames.len())
            .filter(|&i| !frames[i].status.is_solved())
            .collect();
        assert!(broken.is_empty(), "{name}: frames {broken:?} did not solve");
    }
}

#[test]
fn compiled_and_interpreted_agree_on_every_frame() {
    for name in bundled() {
        let m = load(&name);
        let requested = sweep_inputs(&m, None);
        for policy in [BreakPolicy::Limit, BreakPolicy::Search, BreakPolicy::Stretch] {
            for branch in [BranchPolicy::Keep, BranchPolicy::Nearest] {
                let opts = options(policy, branch);
                let a = run(Interpreter::new(plan(&m)), opts, &requested);
                let b = compiled(&name, opts, &requested);
                assert_eq!(a.len(), b.len());
                for (i, (fa, fb)) in a.iter().zip(&b).enumerate() {
                    assert_eq!(
                        fa.status, fb.status,
                        "{name} frame {i} status ({policy:?}, {branch:?})"
                    );
                    assert_eq!(fa.inputs, fb.inputs, "{name} frame {i} inputs");
                    for (pa, pb) in fa.poses.iter().zip(&fb.poses) {
                        let d = dofplan_tests::pose_gap(pa, pb);
                        assert!(
                            d <= 1e-12,
                            "{name} frame {i}: compiled and interpreted differ by {d:e}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn plans_reproduce_the_drawn_pose_at_zero_input() {
    for name in bundled() {
        let m = load(&name);
        let zero = vec![vec![0.0; m.inputs.len()]];
        let frames = run(Interpreter::new(plan(&m)), Options::default(), &zero);
        for (id, pose) in frames[0].poses.iter().enumerate() {
            for marker in &m.bodies[id].markers {
                let w = pose.world(marker.at);
                let gap = (w[0] - marker.at[0]).hypot(w[1] - marker.at[1]);
                assert!(
                    gap <= 1e-9 * m.size(),
                    "{name}: {}.{} off by {gap:e}",
                    m.bodies[id].name,
                    marker.name
                );
            }
        }
    }
}

#[test]
fn keep_branch_never_flips_on_a_smooth_sweep() {
    // Away from singular poses, consecutive frames of a fine sweep move every
    // marker by a small amount: a branch flip would jump.
    for name in bundled()
        .into_iter()
        .filter(|n| n != "rocker_rocker" && n != "parallelogram")
    {
        let m = load(&name);
        let frames = run(
            Interpreter::new(plan(&m)),
            Options::default(),
            &sweep_inputs(&m, Some(3601)),
        );
        let size = m.size();
        for w in frames.windows(2) {
            for (pa, pb) in w[0].poses.iter().zip(&w[1].poses) {
                let jump = (pa.at[0] - pb.at[0]).hypot(pa.at[1] - pb.at[1]);
                assert!(
                    jump < 0.05 * size,
                    "{name}: a body jumps {jump} between frames {:?} and {:?}",
                    w[0].requested,
                    w[1].requested
                );
            }
        }
    }
}
