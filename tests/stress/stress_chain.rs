//! The stress-chain generator used by the scaling measurements: its files
//! load, plan in closed form and sweep a full crank turn with every joint
//! held, and the parallelogram loops copy the rocker angles as designed.

use dofplan::analysis::analyse;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::Format;
use dofplan::simulate::{marker_at, max_relative_residual, run, sweep_inputs};
use dofplan_runtime::Options;
use dofplan_tests::stress::stress_chain;
use dofplan_tests::vec2::{dist, sub};

#[test]
fn stress_chains_plan_in_closed_form_and_hold_every_joint_over_a_turn() {
    for loops in [1, 2, 3, 12] {
        let text = stress_chain(loops);
        let m = load_str("chain.toml", &text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.bodies.len(), 2 * loops + 2);
        assert_eq!(m.joints.len(), 3 * loops + 1);
        let plan = analyse(&m).plan.unwrap_or_else(|e| panic!("{loops} loops: {e}"));
        assert_eq!(plan.clusters(), 0, "{loops} loops: closed form");
        let frames = run(
            Interpreter::new(plan),
            Options::default(),
            &sweep_inputs(&m, None),
        );
        assert_eq!(frames.len(), 361);
        for (i, f) in frames.iter().enumerate() {
            assert!(
                f.status.is_solved(),
                "{loops} loops, frame {i}: {}",
                f.status.name()
            );
            let r = max_relative_residual(&m, &f.poses, &f.inputs);
            assert!(r <= 1e-9, "{loops} loops, frame {i}: relative residual {r:e}");
            // Every later loop is a parallelogram: its coupler keeps the
            // ground spacing's direction and length, independently of the
            // plan's own steps.
            for j in 2..=loops {
                let c = marker_at(&m, &f.poses, m.find_marker(&format!("coupler_{j}.C{j}")).unwrap());
                let r = marker_at(&m, &f.poses, m.find_marker(&format!("coupler_{j}.R{j}")).unwrap());
                let d = sub(r, c);
                assert!(
                    dist(d, [4.0, 0.0]) < 1e-9,
                    "{loops} loops, frame {i}, loop {j}: {d:?}"
                );
            }
        }
    }
}
