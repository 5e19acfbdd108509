//! Dragging (Brunkhart §5.1, fig. 28): an open chain follows its end with
//! minimum-norm motion, a four-bar dragged by its coupler point moves along
//! its one freedom (its coupler curve), and a target out of reach is a
//! break or a stretch by policy — every frame with every joint exact.

use dofplan::interp::Interpreter;
use dofplan::load_file;
use dofplan::numeric::planar::drag::{Drag, DragError};
use dofplan::simulate::{marker_at, max_relative_residual, run, Frame};
use dofplan_runtime::numeric::NewtonOutcome;
use dofplan_runtime::{BreakKind, BreakPolicy, FrameStatus, Options};
use dofplan_tests::vec2::{self, dist};
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
    // Pulled straight is a singular pose, and still a converged closest
    // approach: no solution within reach, never "not converged".
    assert_eq!(brk.kind, BreakKind::NoSolution, "{brk:?}");
    assert!((brk.gap - 5.0).abs() <= 1e-9, "{brk:?}");
    assert_eq!(limited[1].poses, limited[0].poses, "limit keeps the last pose");
    // Stretch relaxes the drag, never the joints: the chain is pulled
    // straight along the x axis, its end at 15.
    let frames = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Stretch), &far);
    for f in &frames {
        assert!(max_relative_residual(&m, &f.poses, &[]) <= 1e-9, "{:?}", f.status);
    }
    let FrameStatus::Stretched { residual, .. } = frames[1].status else {
        panic!("{:?}", frames[1].status)
    };
    assert!(dist(marker_at(&m, &frames[1].poses, end), [15.0, 0.0]) <= 1e-9);
    assert!((residual - 5.0).abs() <= 1e-9);
    assert_eq!(frames[1].numeric.unwrap().outcome, NewtonOutcome::NoSolution);
}

/// The open chain as the file draws it, read independently of the solver:
/// the pivot (the ground marker) and the length of each link (its two
/// markers' distance).
fn chain_geometry(m: &dofplan::model::Mechanism) -> ([f64; 2], f64) {
    let pivot = m.marker(m.find_marker("ground.O").unwrap()).at;
    let reach: f64 = (1..=15)
        .map(|i| {
            let s = m.marker(m.find_marker(&format!("link_{i}.S")).unwrap()).at;
            let e = m.marker(m.find_marker(&format!("link_{i}.E")).unwrap()).at;
            dist(s, e)
        })
        .sum();
    (pivot, reach)
}

/// Issue 7's drag: the chain's end pulled from where it is drawn to
/// (60, 80), far out of reach. Under stretch every frame beyond reach shows
/// the chain pulled straight toward its target — its end `reach` from the
/// pivot on the line to the target — with every joint closed, and reports
/// the true distance left as its residual.
#[test]
fn stretch_pulls_the_open_chain_straight_toward_a_target_out_of_reach() {
    let m = open_chain();
    let end = m.find_marker("link_15.E").unwrap();
    let (pivot, reach) = chain_geometry(&m);
    assert!((reach - 15.0).abs() < 1e-9, "the file's links are unit links");
    let path = targets(m.marker(end).at, [60.0, 80.0], 50);
    let frames = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Stretch), &path);
    assert!(frames[0].status.is_solved());
    for (i, f) in frames.iter().enumerate().skip(1) {
        assert!(max_relative_residual(&m, &f.poses, &[]) <= 1e-9, "frame {i}");
        let target = [f.requested[0], f.requested[1]];
        assert!(
            dist(target, pivot) > reach,
            "frame {i}: the path leaves reach at once"
        );
        let at = marker_at(&m, &f.poses, end);
        let straight = vec2::add(pivot, vec2::scale(vec2::unit(vec2::sub(target, pivot)), reach));
        assert!(
            dist(at, straight) <= 1e-8,
            "frame {i}: the end is {} from the straight pose",
            dist(at, straight)
        );
        let FrameStatus::Stretched { residual, .. } = f.status else {
            panic!("frame {i}: {:?}", f.status)
        };
        assert!((residual - dist(at, target)).abs() <= 1e-9, "frame {i}");
        assert_eq!(f.numeric.unwrap().outcome, NewtonOutcome::NoSolution, "frame {i}");
    }
}

/// A path that starts in reach and leaves it: the frames in reach are met
/// exactly; limit then keeps the last of them, search moves to the
/// boundary on the path (the end `reach` from the pivot, the chain
/// straight) and stays there.
#[test]
fn limit_and_search_stop_the_open_chain_where_the_path_leaves_its_reach() {
    let m = open_chain();
    let end = m.find_marker("link_15.E").unwrap();
    let (pivot, reach) = chain_geometry(&m);
    let path = targets([5.0, 5.0], [12.0, 12.0], 30);
    let inside: Vec<bool> = path.iter().map(|t| dist([t[0], t[1]], pivot) < reach).collect();
    for t in &path {
        assert!(
            (dist([t[0], t[1]], pivot) - reach).abs() > 1e-3,
            "no target on the boundary"
        );
    }
    let first_out = inside.iter().position(|&i| !i).unwrap();
    assert!(first_out > 1 && inside[first_out..].iter().all(|&i| !i));

    let limited = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Limit), &path);
    for (i, f) in limited.iter().enumerate() {
        assert!(max_relative_residual(&m, &f.poses, &[]) <= 1e-9, "frame {i}");
        if inside[i] {
            assert!(f.status.is_solved(), "frame {i}: {:?}", f.status);
            assert!(dist(marker_at(&m, &f.poses, end), [f.requested[0], f.requested[1]]) <= 1e-9);
        } else {
            let FrameStatus::Limited { brk } = f.status else {
                panic!("frame {i}: {:?}", f.status)
            };
            assert_eq!(brk.kind, BreakKind::NoSolution, "frame {i}");
            assert_eq!(
                f.poses,
                limited[first_out - 1].poses,
                "frame {i} keeps the last reachable pose"
            );
            assert_eq!(f.inputs, limited[first_out - 1].requested);
        }
    }

    let searched = run(Drag::new(&m, end).unwrap(), options(BreakPolicy::Search), &path);
    for (i, f) in searched.iter().enumerate() {
        assert!(max_relative_residual(&m, &f.poses, &[]) <= 1e-9, "frame {i}");
        if inside[i] {
            assert!(f.status.is_solved(), "frame {i}: {:?}", f.status);
            continue;
        }
        assert!(
            matches!(f.status, FrameStatus::Searched { .. }),
            "frame {i}: {:?}",
            f.status
        );
        // The boundary: on the path's segment into the unreachable, the
        // end `reach` from the pivot (the bisection stops within 1e-9 of
        // the break point in target units).
        let at = marker_at(&m, &f.poses, end);
        let from = [path[first_out - 1][0], path[first_out - 1][1]];
        let to = [path[first_out][0], path[first_out][1]];
        let along = vec2::dot(vec2::sub(at, from), vec2::unit(vec2::sub(to, from)));
        let on_segment = vec2::add(from, vec2::scale(vec2::unit(vec2::sub(to, from)), along));
        assert!(dist(at, on_segment) <= 1e-9, "frame {i}: off the path");
        let from_pivot = dist(at, pivot);
        assert!(
            from_pivot <= reach + 1e-12 && from_pivot >= reach - 1e-8,
            "frame {i}: the end is {from_pivot} from the pivot"
        );
        let boundary = marker_at(&m, &searched[first_out].poses, end);
        assert!(dist(at, boundary) <= 1e-8, "frame {i} stays on the boundary");
    }
}

/// The fourbar of `mechanisms/fourbar.toml` by its own circle
/// intersections (not the solver's): coupler.P for crank angle `theta`
/// (radians, from the ground) on the assembly branch of the drawn pose.
struct FourBar {
    a: [f64; 2],
    d: [f64; 2],
    crank: f64,
    coupler: f64,
    rocker: f64,
    /// P in the coupler's frame: along B→C and across it.
    p: [f64; 2],
    /// The side of the line B→D that C is drawn on.
    side: f64,
}

impl FourBar {
    fn of(m: &dofplan::model::Mechanism) -> FourBar {
        let at = |name: &str| m.marker(m.find_marker(name).unwrap()).at;
        let (a, d, b, c, p) = (
            at("ground.A"),
            at("ground.D"),
            at("crank.B"),
            at("coupler.C"),
            at("coupler.P"),
        );
        let u = vec2::unit(vec2::sub(c, b));
        let bp = vec2::sub(p, b);
        FourBar {
            a,
            d,
            crank: dist(a, b),
            coupler: dist(b, c),
            rocker: dist(c, d),
            p: [vec2::dot(bp, u), vec2::cross(u, bp)],
            side: vec2::cross(vec2::sub(d, b), vec2::sub(c, b)).signum(),
        }
    }

    fn point(&self, theta: f64) -> [f64; 2] {
        let b = vec2::add(self.a, [self.crank * theta.cos(), self.crank * theta.sin()]);
        let bd = vec2::sub(self.d, b);
        let l = vec2::norm(bd);
        let along = (self.coupler.powi(2) - self.rocker.powi(2) + l * l) / (2.0 * l);
        let across = (self.coupler.powi(2) - along * along).sqrt();
        let e = vec2::unit(bd);
        // C on the drawn side of B→D: cross(bd, c − b) has the drawn sign.
        let c = vec2::add(
            vec2::add(b, vec2::scale(e, along)),
            vec2::scale(vec2::perp(e), self.side * across),
        );
        let u = vec2::unit(vec2::sub(c, b));
        vec2::add(
            vec2::add(b, vec2::scale(u, self.p[0])),
            vec2::scale(vec2::perp(u), self.p[1]),
        )
    }
}

/// Issue 7's second drag: the fourbar's coupler point pulled from where it
/// is drawn to (−3, 5), off its coupler curve. Under stretch it follows the
/// curve and ends at the curve's point nearest the target — checked
/// against the closed-form curve of the drawn branch sampled every 0.001°
/// of the crank — with every joint closed and the true distance reported.
#[test]
fn stretch_takes_a_coupler_point_to_the_nearest_point_of_its_curve() {
    let m = load("fourbar");
    let p_id = m.find_marker("coupler.P").unwrap();
    let mut released = m.clone();
    released.inputs.clear();
    let four = FourBar::of(&m);
    let samples = 360_000;
    let curve: Vec<[f64; 2]> = (0..samples)
        .map(|i| four.point(std::f64::consts::TAU * f64::from(i) / f64::from(samples)))
        .collect();
    // The sampling's resolution: the largest gap between neighbours.
    let spacing = curve
        .iter()
        .zip(curve.iter().cycle().skip(1))
        .map(|(a, b)| dist(*a, *b))
        .fold(0.0, f64::max);
    assert!(spacing < 1e-4, "{spacing}");
    assert!(
        curve.iter().any(|c| dist(*c, m.marker(p_id).at) <= spacing),
        "the curve passes through the drawn P"
    );
    // Distance to the sampled curve: the nearest of every 100th sample, then
    // every sample around it (a full scan per frame is slow in a debug build).
    let off_curve = |at: [f64; 2]| {
        let coarse = (0..samples as usize / 100)
            .min_by(|&i, &j| dist(curve[100 * i], at).total_cmp(&dist(curve[100 * j], at)))
            .unwrap();
        (0..601)
            .map(|k| curve[(100 * coarse + curve.len() + k - 300) % curve.len()])
            .map(|c| dist(c, at))
            .fold(f64::INFINITY, f64::min)
    };

    let target = [-3.0, 5.0];
    let path = targets(m.marker(p_id).at, target, 50);
    let frames = run(Drag::new(&m, p_id).unwrap(), options(BreakPolicy::Stretch), &path);
    let mut previous = m.marker(p_id).at;
    for (i, f) in frames.iter().enumerate() {
        assert!(
            max_relative_residual(&released, &f.poses, &[]) <= 1e-9,
            "frame {i}"
        );
        let at = marker_at(&m, &f.poses, p_id);
        // On the drawn branch's curve, moving along it (continuation: no
        // jump to the other branch).
        assert!(
            off_curve(at) <= spacing,
            "frame {i}: {} off the curve",
            off_curve(at)
        );
        assert!(
            dist(at, previous) <= 0.5,
            "frame {i}: P jumps {}",
            dist(at, previous)
        );
        previous = at;
        if i > 0 {
            let FrameStatus::Stretched { residual, .. } = f.status else {
                panic!("frame {i}: {:?}", f.status)
            };
            assert!((residual - dist(at, [f.requested[0], f.requested[1]])).abs() <= 1e-9);
        }
    }
    let last = frames.last().unwrap();
    let at = marker_at(&m, &last.poses, p_id);
    let nearest = *curve
        .iter()
        .min_by(|a, b| dist(**a, target).total_cmp(&dist(**b, target)))
        .unwrap();
    assert!(
        dist(at, nearest) <= spacing,
        "P ends {} from the curve's nearest point {nearest:?}",
        dist(at, nearest)
    );
    assert!((dist(at, target) - dist(nearest, target)).abs() <= spacing);
    assert_eq!(last.numeric.unwrap().outcome, NewtonOutcome::NoSolution);

    // Search and limit keep P on the curve too: its path leaves the curve
    // at once, so both hold the drawn pose (the boundary is the start).
    for policy in [BreakPolicy::Limit, BreakPolicy::Search] {
        let frames = run(Drag::new(&m, p_id).unwrap(), options(policy), &path);
        for (i, f) in frames.iter().enumerate() {
            assert!(
                max_relative_residual(&released, &f.poses, &[]) <= 1e-9,
                "{policy:?} frame {i}"
            );
            let at = marker_at(&m, &f.poses, p_id);
            assert!(off_curve(at) <= spacing, "{policy:?} frame {i}");
            assert!(
                dist(at, m.marker(p_id).at) <= 1e-6,
                "{policy:?} frame {i}: {at:?}"
            );
        }
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

/// A marker the joints hold still (the crank's pivot) cannot approach its
/// target at all: every frame is a closest approach where it stands — the
/// marker's motion is zero, which is stationary, not undecided.
#[test]
fn a_marker_the_joints_hold_still_stays_where_it_is() {
    let m = load("fourbar");
    let pivot = m.find_marker("crank.A").unwrap();
    let path = targets([0.0, 0.0], [3.0, 3.0], 5);
    let frames = run(
        Drag::new(&m, pivot).unwrap(),
        options(BreakPolicy::Stretch),
        &path,
    );
    let mut released = m.clone();
    released.inputs.clear();
    for (i, f) in frames.iter().enumerate().skip(1) {
        assert!(
            max_relative_residual(&released, &f.poses, &[]) <= 1e-9,
            "frame {i}"
        );
        let at = marker_at(&m, &f.poses, pivot);
        assert!(dist(at, [0.0, 0.0]) <= 1e-12, "frame {i}: {at:?}");
        let FrameStatus::Stretched { residual, .. } = f.status else {
            panic!("frame {i}: {:?}", f.status)
        };
        assert!((residual - dist([0.0, 0.0], [f.requested[0], f.requested[1]])).abs() <= 1e-12);
        assert_eq!(f.numeric.unwrap().outcome, NewtonOutcome::NoSolution, "frame {i}");
    }
}
