//! Dragging (Brunkhart §5.1, fig. 28): an open chain follows its end with
//! minimum-norm motion, a four-bar dragged by its coupler point moves along
//! its one freedom (its coupler curve), and a target out of reach is a
//! break or a stretch by policy — every frame with every joint exact.

use dofplan::interp::Interpreter;
use dofplan::model::load_file;
use dofplan::numeric::drag::{Drag, DragError};
use dofplan::simulate::{marker_at, max_relative_residual, run, Frame};
use dofplan_runtime::numeric::NewtonOutcome;
use dofplan_runtime::{BreakKind, BreakPolicy, FrameStatus, Options};
use dofplan_tests::vec2::dist;
use dofplan_tests::{load, mechanisms_dir, plan};

fn open_chain() -> dofplan::model::Mechanism {
    load_file(&mechanisms_dir().join("drag/open_chain_15.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn targets(from: [f64; 2], to: [f64; 2], n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64;
            vec![from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
        })
        .collect()
}

fn options(breaking: BreakPolicy) -> Options {
    Options {
        breaking,
        ..Options::default()
    }
}

#[test]
fn an_open_chain_follows_its_end_smoothly() {
    let m = open_chain();
    let end = m.find_marker("link_15.E").unwrap();
    let start = m.marker(end).at;
    let path = targets(start, [6.0, 8.0], 80);
    let frames = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Limit), &path);
    let step = dist(path[0][..2].try_into().unwrap(), path[1][..2].try_into().unwrap());
    for (i, f) in frames.iter().enumerate() {
        assert!(f.status.is_solved(), "frame {i}: {:?}", f.status);
        assert!(max_relative_residual(&m, &f.poses, &f.inputs) <= 1e-9);
        let at = marker_at(&m, &f.poses, end);
        assert!(
            dist(at, [f.requested[0], f.requested[1]]) <= 1e-9,
            "frame {i}: the end is off its target"
        );
        assert!(f.numeric.unwrap().iterations <= 10);
    }
    // Smoothly: no joint of the chain moves much more than the target did.
    for w in frames.windows(2) {
        for id in m.all_markers() {
            let d = dist(marker_at(&m, &w[0].poses, id), marker_at(&m, &w[1].poses, id));
            assert!(
                d <= 3.0 * step,
                "{} jumps {d} for a target step of {step}",
                m.marker_name(id)
            );
        }
    }
}

#[test]
fn a_fourbar_dragged_by_its_coupler_moves_along_its_coupler_curve() {
    let m = load("fourbar");
    let p_id = m.find_marker("coupler.P").unwrap();
    // The coupler curve, independently: the closed-form plan over a fine sweep.
    let fine: Vec<Vec<f64>> = (0..=36000).map(|i| vec![f64::from(i) * 0.01]).collect();
    let curve: Vec<[f64; 2]> = run(Interpreter::new(plan(&m)), Options::default(), &fine)
        .iter()
        .map(|f: &Frame| marker_at(&m, &f.poses, p_id))
        .collect();
    let start = m.marker(p_id).at;
    let path = targets(start, [1.5, 4.0], 30);
    let frames = run(Drag::new(&m, p_id).unwrap(), options(BreakPolicy::Stretch), &path);
    for (i, f) in frames.iter().enumerate() {
        // The joints hold exactly; only the drag is relaxed.
        assert!(max_relative_residual(&m, &f.poses, &[0.0]) <= 1e-9 || !m.inputs.is_empty());
        let r = dofplan::simulate::residuals(&m, &f.poses, &[0.0]);
        assert!(
            r.iter()
                .filter(|x| x.name.starts_with("joint"))
                .all(|x| x.value <= 1e-9),
            "frame {i}"
        );
        let at = marker_at(&m, &f.poses, p_id);
        // P is on the coupler curve (within the 0.01° sampling) ...
        let off_curve = curve.iter().map(|c| dist(*c, at)).fold(f64::INFINITY, f64::min);
        assert!(
            off_curve < 1e-3,
            "frame {i}: P is {off_curve} off the coupler curve"
        );
        // ... at the curve's point nearest the target (locally).
        let target = [f.requested[0], f.requested[1]];
        let nearest = curve
            .iter()
            .map(|c| dist(*c, target))
            .fold(f64::INFINITY, f64::min);
        assert!(
            dist(at, target) <= nearest + 1e-3,
            "frame {i}: {} vs nearest {nearest}",
            dist(at, target)
        );
    }
}

#[test]
fn a_target_out_of_reach_is_a_limit_or_a_stretch_never_a_hang() {
    let m = open_chain();
    let end = m.find_marker("link_15.E").unwrap();
    // 15 unit links pinned at the origin reach 15 at most.
    let far = vec![vec![14.0, 0.0], vec![20.0, 0.0]];
    let limited = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Limit), &far);
    assert!(limited[0].status.is_solved());
    let FrameStatus::Limited { brk } = limited[1].status else {
        panic!("{:?}", limited[1].status)
    };
    // Pulled straight (a singular pose) Newton cannot tell "no solution"
    // from "not converged" within its budget; either is a break.
    assert!(
        matches!(brk.kind, BreakKind::NoSolution | BreakKind::NotConverged),
        "{brk:?}"
    );
    assert_eq!(limited[1].poses, limited[0].poses, "limit keeps the last pose");
    // Stretch relaxes the drag, never the joints: the chain pulled toward
    // 20 either shows a pose with every joint exact and the end short of the
    // target, or (pulled straight, a singular pose) keeps the last one.
    for policy in [BreakPolicy::Stretch, BreakPolicy::Search] {
        let frames = run(Drag::new(&m, end).unwrap(), options(policy), &far);
        for f in &frames {
            assert!(
                dofplan::simulate::residuals(&m, &f.poses, &[])
                    .iter()
                    .all(|r| r.value <= 1e-9),
                "{policy:?}: {:?}",
                f.status
            );
            let at = marker_at(&m, &f.poses, end);
            assert!(dist(at, [0.0, 0.0]) <= 15.0 + 1e-9);
        }
        assert!(!frames[1].status.is_solved());
    }
}

/// A target off the coupler curve of a four-bar is out of reach: stretch
/// shows the closest approach with the joints exact (above); limit keeps
/// the last pose that met its target.
#[test]
fn limit_keeps_the_last_pose_that_met_its_target() {
    let m = load("fourbar");
    let p_id = m.find_marker("coupler.P").unwrap();
    let start = m.marker(p_id).at;
    let frames = run(
        Drag::new(&m, p_id).unwrap(),
        options(BreakPolicy::Limit),
        &[vec![start[0], start[1]], vec![start[0] - 1.0, start[1] + 1.0]],
    );
    assert!(frames[0].status.is_solved());
    let FrameStatus::Limited { brk } = frames[1].status else {
        panic!("{:?}", frames[1].status)
    };
    assert_eq!(brk.kind, BreakKind::NoSolution);
    assert_eq!(frames[1].poses, frames[0].poses);
    assert_eq!(frames[1].numeric.unwrap().outcome, NewtonOutcome::NoSolution);
}

#[test]
fn a_marker_of_the_ground_cannot_be_dragged() {
    let m = load("fourbar");
    let err = Drag::new(&m, m.find_marker("ground.A").unwrap()).unwrap_err();
    assert_eq!(err, DragError::FixedBody("ground.A".into()));
}

/// The open chain's drag is planned like an input: link_1 pinned at the
/// ground and link_15 at the target each keep their angle, links 2–14 are
/// hinged end to end, and the one coincident row left closes the chain.
#[test]
fn an_open_chain_drag_is_planned_as_one_small_cluster() {
    let m = open_chain();
    let end = m.find_marker("link_15.E").unwrap();
    assert_eq!(Drag::new(&m, end).unwrap().planned(), Some((15, 2)));
    // A four-bar has one DOF: a drag over-determines it, so it is never
    // planned (task priority follows the coupler curve instead).
    let four = load("fourbar");
    let p = four.find_marker("coupler.P").unwrap();
    assert_eq!(Drag::new(&four, p).unwrap().planned(), None);
}

/// The compiled drag (`Config::drag` in dofplan-generated's build.rs) and
/// the library's planned drag agree frame by frame, and every frame meets
/// its target with the joints exact.
#[test]
fn the_compiled_drag_agrees_with_the_library() {
    use dofplan_generated::open_chain_15_drag_link_15_e as compiled;
    let m = open_chain();
    let end = m.find_marker("link_15.E").unwrap();
    let start = m.marker(end).at;
    let path = targets(start, [6.0, 8.0], 200);
    let library = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Limit), &path);
    let slides: Vec<Vec<f64>> = path
        .iter()
        .map(|t| vec![t[0] - start[0], t[1] - start[1]])
        .collect();
    let mut driver = dofplan_runtime::Driver::new(compiled::Plan, options(BreakPolicy::Limit));
    let n = m.bodies.len();
    assert_eq!(
        &compiled::BODIES[..n],
        m.bodies.iter().map(|b| b.name.as_str()).collect::<Vec<_>>()
    );
    for (i, (f, s)) in library.iter().zip(&slides).enumerate() {
        assert!(driver.frame(s).is_solved(), "frame {i}");
        let poses = &driver.poses()[..n];
        assert!(max_relative_residual(&m, poses, &[]) <= 1e-9, "frame {i}");
        assert!(dist(marker_at(&m, poses, end), [f.requested[0], f.requested[1]]) <= 1e-9);
        for (a, b) in poses.iter().zip(&f.poses) {
            let d = (a.at[0] - b.at[0]).abs().max((a.at[1] - b.at[1]).abs());
            assert!(d <= 1e-9, "frame {i}: compiled and library differ by {d:e}");
        }
    }
}
