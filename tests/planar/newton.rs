//! Pure Newton mode (three unknowns per mobile link, no analysis): its
//! unknown and equation counts are Figure 30's, and where it converges it
//! finds the pose the closed-form plan finds, holding every joint.

use dofplan::interp::Interpreter;
use dofplan::numeric::PureNewton;
use dofplan::simulate::{max_relative_residual, run, sweep_inputs};
use dofplan_runtime::numeric::NewtonOutcome;
use dofplan_runtime::{BreakKind, BreakPolicy, FrameStatus, Options};
use dofplan_tests::{bundled, load, plan};

#[test]
fn unknowns_and_equations_are_figure_30s_newton_column() {
    // Brunkhart 1994, Figure 30, "Newton Unk/Eqs".
    for (name, unknowns, equations) in [
        ("fourbar", 6, 6),
        ("sixbar_a", 12, 12),
        ("stress_10", 24, 24),
        ("stress_20", 54, 54),
        ("stress_30", 84, 84),
        ("stress_40", 114, 114),
        ("stress_50", 144, 144),
    ] {
        let n = PureNewton::new(&load(name));
        assert_eq!((n.unknowns(), n.equations()), (unknowns, equations), "{name}");
    }
}

fn unique_pose(name: &str) -> bool {
    name != "parallelogram" && !name.starts_with("chain")
}

#[test]
fn pure_newton_agrees_with_the_plan_on_every_bundled_sweep() {
    // Pure Newton on stress_20 … stress_50 (54 to 144 unknowns, an SVD of
    // that size per iteration) takes milliseconds per frame even optimised;
    // their counts are checked above and the Figure 30 table times them.
    let large = ["stress_20", "stress_30", "stress_40", "stress_50"];
    for name in bundled().into_iter().filter(|n| !large.contains(&n.as_str())) {
        let m = load(&name);
        // Fine steps keep Newton's warm start on the plan's branch.
        let requested = sweep_inputs(&m, Some(721));
        let newton = run(PureNewton::new(&m), Options::default(), &requested);
        let planned = run(Interpreter::new(plan(&m)), Options::default(), &requested);
        let mut compared = 0;
        for (i, (n, p)) in newton.iter().zip(&planned).enumerate() {
            let report = n.numeric.expect("pure Newton reports every frame");
            if n.status.is_solved() {
                assert_eq!(report.outcome, NewtonOutcome::Converged);
                assert!(report.iterations <= 25, "{name} frame {i}: {report:?}");
                let r = max_relative_residual(&m, &n.poses, &n.inputs);
                assert!(r <= 1e-9, "{name} frame {i}: residual {r:e}");
            }
            // The parallelogram's change points are singular: there both
            // branches meet, Newton's tolerance on the residual allows
            // ~1e-6 in position, and past them the two solvers may follow
            // different assembly modes. Its residuals are checked above.
            // The chains are under-constrained: each solver's minimum-norm
            // steps (over different unknowns) pick a different pose among
            // the valid ones, so only residuals compare.
            if unique_pose(&name) && n.status.is_solved() && p.status.is_solved() {
                compared += 1;
                for (a, b) in n.poses.iter().zip(&p.poses) {
                    let d = (a.at[0] - b.at[0]).abs().max((a.at[1] - b.at[1]).abs());
                    let d = d.max((a.rot.c - b.rot.c).abs()).max((a.rot.s - b.rot.s).abs());
                    assert!(
                        d <= 1e-9 * m.size(),
                        "{name} frame {i}: Newton and the plan differ by {d:e}"
                    );
                }
            }
        }
        assert!(
            !unique_pose(&name) || compared > 60,
            "{name}: only {compared} frames compared"
        );
    }
}

#[test]
fn past_a_limit_newton_reports_no_solution_without_hanging() {
    let m = load("rocker_rocker");
    let requested: Vec<Vec<f64>> = [0.0, 20.0, 40.0, 60.0, 100.0].iter().map(|&v| vec![v]).collect();
    let frames = run(PureNewton::new(&m), Options::default(), &requested);
    assert!(frames[..3].iter().all(|f| f.status.is_solved()));
    for f in &frames[3..] {
        let FrameStatus::Limited { brk } = f.status else {
            panic!("expected a limit, got {:?}", f.status)
        };
        assert_eq!(brk.kind, BreakKind::NoSolution);
        let report = f.numeric.unwrap();
        assert_eq!(report.outcome, NewtonOutcome::NoSolution);
        assert!(report.residual > 0.01, "{report:?}");
        assert_eq!(f.inputs, vec![40.0], "the pose stays at the last valid input");
    }
    // Stretch accepts the least-squares pose and reports its residual.
    let stretched = run(
        PureNewton::new(&m),
        Options {
            breaking: BreakPolicy::Stretch,
            ..Options::default()
        },
        &requested,
    );
    let FrameStatus::Stretched { residual, .. } = stretched[4].status else {
        panic!("{:?}", stretched[4].status)
    };
    assert!(residual > 0.01);
    assert_eq!(stretched[4].inputs, vec![100.0]);
}
