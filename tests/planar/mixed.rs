//! Mixed plans (Brunkhart §4): the bundled mechanisms that need a numeric
//! cluster hand Newton–Raphson no more unknowns than Figure 30's Mixed
//! column, agree with pure Newton where both converge on the same branch,
//! and the compiled and interpreted clusters agree.

use dofplan::interp::Interpreter;
use dofplan::numeric::PureNewton;
use dofplan::simulate::{max_relative_residual, run, run_animate, sweep_inputs};
use dofplan_runtime::Options;
use dofplan_tests::{bundled, load, plan};

/// (file, Figure 30 Mixed unknowns, equations)
const ROWS: [(&str, usize, usize); 9] = [
    ("sixbar_b", 6, 6),
    ("eightbar", 12, 12),
    ("tenbar", 14, 14),
    ("duplex", 20, 20),
    ("chain_4", 5, 4),
    ("chain_6", 11, 8),
    ("chain_8", 17, 12),
    ("chain_10", 23, 16),
    ("chain_15", 38, 26),
];

/// Our mixed plans' (unknowns, equations), in `ROWS` order: pinned bodies
/// keep their angle, and free links hinged on a cluster body (joint
/// coordinates) their angle too, so a chain of n links between two ground
/// pivots leaves n − 1 angles and the one coincident row that closes it.
const OURS: [(usize, usize); 9] = [
    (4, 4),
    (6, 6),
    (6, 6),
    (8, 8),
    (3, 2),
    (5, 2),
    (7, 2),
    (9, 2),
    (14, 2),
];

#[test]
fn mixed_unknown_and_equation_counts() {
    for ((name, _, _), ours) in ROWS.iter().zip(OURS) {
        assert_eq!(plan(&load(name)).numeric_size(), ours, "{name}");
    }
}

#[test]
fn mixed_unknowns_are_at_most_figure_30s() {
    for (name, unknowns, _) in ROWS {
        let p = plan(&load(name));
        let (u, e) = p.numeric_size();
        assert!(p.clusters() >= 1, "{name} needs a cluster");
        assert!(
            u <= unknowns,
            "{name}: {u} unknowns, the reference has {unknowns}"
        );
        assert!(e >= 1 && u >= 1, "{name}: {u}/{e}");
    }
}

#[test]
fn closed_form_mechanisms_hand_newton_nothing() {
    for name in bundled() {
        if ROWS.iter().any(|r| r.0 == name) {
            continue;
        }
        assert_eq!(plan(&load(&name)).numeric_size(), (0, 0), "{name}");
    }
}

#[test]
fn mixed_and_pure_newton_agree_where_both_converge() {
    for (name, _, _) in ROWS {
        let m = load(name);
        let requested = sweep_inputs(&m, None);
        let mixed = run(Interpreter::new(plan(&m)), Options::default(), &requested);
        let newton = run(PureNewton::new(&m), Options::default(), &requested);
        for (i, (a, b)) in mixed.iter().zip(&newton).enumerate() {
            assert!(a.status.is_solved(), "{name} frame {i}: {:?}", a.status);
            assert!(
                max_relative_residual(&m, &a.poses, &a.inputs) <= 1e-9,
                "{name} frame {i}"
            );
            // Well-constrained mechanisms have one pose per branch; the
            // chains are under-constrained, and the two solvers' minimum-norm
            // steps differ (different unknowns), so only residuals compare.
            if b.status.is_solved() && !name.starts_with("chain") {
                for (pa, pb) in a.poses.iter().zip(&b.poses) {
                    let d = (pa.at[0] - pb.at[0]).abs().max((pa.at[1] - pb.at[1]).abs());
                    assert!(
                        d <= 1e-8 * m.size(),
                        "{name} frame {i}: mixed and pure Newton differ by {d:e}"
                    );
                }
            }
        }
    }
}

#[test]
fn compiled_and_interpreted_clusters_agree() {
    for (name, _, _) in ROWS {
        let m = load(name);
        let requested = sweep_inputs(&m, None);
        let a = run(Interpreter::new(plan(&m)), Options::default(), &requested);
        let mut driver = dofplan_generated::driver(name, Options::default()).unwrap();
        let b = run_animate(driver.as_mut(), &requested);
        for (i, (fa, fb)) in a.iter().zip(&b).enumerate() {
            assert_eq!(fa.status, fb.status, "{name} frame {i}");
            // The generated residuals and Jacobian are the runtime's,
            // written out: the same Newton path, iteration for iteration.
            let its = |f: &dofplan::simulate::Frame| f.numeric.map(|r| r.iterations);
            assert_eq!(its(fa), its(fb), "{name} frame {i}: Newton iterations");
            assert!(its(fa).is_some(), "{name} frame {i}: no Newton report");
            for (pa, pb) in fa.poses.iter().zip(&fb.poses) {
                let d = (pa.at[0] - pb.at[0]).abs().max((pa.at[1] - pb.at[1]).abs());
                assert!(
                    d <= 1e-9,
                    "{name} frame {i}: compiled and interpreted differ by {d:e}"
                );
            }
        }
    }
}

/// sixbar_b is sixbar_a driven from another joint: at the crank angle the
/// mixed plan finds, sixbar_a's closed-form plan must give the same pose.
#[test]
fn sixbar_b_is_sixbar_a_driven_from_another_joint() {
    let a = load("sixbar_a");
    let b = load("sixbar_b");
    let frames = run(
        Interpreter::new(plan(&b)),
        Options::default(),
        &sweep_inputs(&b, None),
    );
    let crank = b.bodies.iter().position(|x| x.name == "crank").unwrap();
    let requested: Vec<Vec<f64>> = frames
        .iter()
        .map(|f| {
            let r = f.poses[crank].rot;
            vec![r.s.atan2(r.c).to_degrees()]
        })
        .collect();
    let closed = run(Interpreter::new(plan(&a)), Options::default(), &requested);
    for (i, (fb, fa)) in frames.iter().zip(&closed).enumerate() {
        assert!(fb.status.is_solved() && fa.status.is_solved(), "frame {i}");
        for (pb, pa) in fb.poses.iter().zip(&fa.poses) {
            let d = (pb.at[0] - pa.at[0]).abs().max((pb.at[1] - pa.at[1]).abs());
            assert!(d <= 1e-9, "frame {i}: sixbar_b and sixbar_a differ by {d:e}");
        }
    }
}

/// tests/fixtures/sixbar_slotted.toml: a cluster with a sliding body and a
/// prismatic between two cluster bodies (parallel and in-line rows), the
/// generated code for which no bundled mechanism needs. Compiled and
/// interpreted agree, iteration for iteration, and every frame holds.
#[test]
fn slides_slots_and_parallels_in_a_compiled_cluster() {
    let m =
        dofplan::load_file(&dofplan_tests::mechanisms_dir().join("../tests/fixtures/sixbar_slotted.toml"))
            .unwrap_or_else(|e| panic!("{e}"));
    let p = plan(&m);
    assert_eq!(p.numeric_size(), (4, 4));
    let explained = p.explain_all();
    assert!(explained.contains("block (slide along"), "{explained}");
    let requested = sweep_inputs(&m, None);
    let a = run(Interpreter::new(p), Options::default(), &requested);
    let mut driver = dofplan_generated::driver("sixbar_slotted", Options::default()).unwrap();
    let b = run_animate(driver.as_mut(), &requested);
    for (i, (fa, fb)) in a.iter().zip(&b).enumerate() {
        assert!(fa.status.is_solved(), "frame {i}: {:?}", fa.status);
        assert!(
            max_relative_residual(&m, &fb.poses, &fb.inputs) <= 1e-9,
            "frame {i}"
        );
        assert_eq!(
            fa.numeric.map(|r| r.iterations),
            fb.numeric.map(|r| r.iterations),
            "frame {i}"
        );
        for (pa, pb) in fa.poses.iter().zip(&fb.poses) {
            let d = (pa.at[0] - pb.at[0]).abs().max((pa.at[1] - pb.at[1]).abs());
            assert!(d <= 1e-9, "frame {i}: compiled and interpreted differ by {d:e}");
        }
    }
}
