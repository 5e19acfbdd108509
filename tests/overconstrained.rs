//! Over-constrained mechanisms (Brunkhart 1994, §2.1.3–2.1.4).
//!
//! A consistent redundant mechanism — the "table" of fig. 14b and the V-link
//! of fig. 13, both bundled — solves and animates, its redundant joint named
//! by `check`. Each property below is recomputed here from the markers, not
//! read from the plan.

use dofplan::analysis::analyse;
use dofplan::analysis::rank::rank_mobility;
use dofplan::interp::Interpreter;
use dofplan::model::Mechanism;
use dofplan::simulate::{marker_at, max_relative_residual, run, run_animate, sweep_inputs, Frame};
use dofplan_runtime::Options;
use dofplan_tests::vec2::{cross, dist, norm, sub, P};
use dofplan_tests::{load, plan};

/// World position of "body.marker" in a frame.
fn at(m: &Mechanism, f: &Frame, name: &str) -> P {
    marker_at(m, &f.poses, m.find_marker(name).expect("marker"))
}

/// Drawn position of "body.marker".
fn drawn(m: &Mechanism, name: &str) -> P {
    m.marker(m.find_marker(name).expect("marker")).at
}

/// Every frame of the bundled sweep, interpreted and compiled: all solved,
/// every joint and the input held to 1e-9 of the mechanism's size.
fn sweep(name: &str) -> (Mechanism, Vec<Vec<Frame>>) {
    let m = load(name);
    let requested = sweep_inputs(&m, None);
    assert!(requested.len() > 100, "{name}: a real sweep");
    let interpreted = run(Interpreter::new(plan(&m)), Options::default(), &requested);
    let mut driver = dofplan_generated::driver(name, Options::default()).expect("compiled");
    let compiled = run_animate(driver.as_mut(), &requested);
    for (backend, frames) in [("interpreted", &interpreted), ("compiled", &compiled)] {
        assert_eq!(frames.len(), requested.len());
        for (i, f) in frames.iter().enumerate() {
            assert!(
                f.status.is_solved(),
                "{name} ({backend}) frame {i}: {:?}",
                f.status
            );
            assert_eq!(f.inputs, requested[i]);
            let r = max_relative_residual(&m, &f.poses, &f.inputs);
            assert!(r <= 1e-9, "{name} ({backend}) frame {i}: relative residual {r:e}");
        }
    }
    (m, vec![interpreted, compiled])
}

/// What `dofplan check` reports: Grübler 0, rank 1, the redundant joint.
fn check_counts(name: &str, redundant: &str) {
    let m = load(name);
    assert_eq!(
        m.bodies.iter().filter(|b| !b.fixed).count(),
        4,
        "{name}: mobile links"
    );
    assert_eq!(m.joints.len(), 6, "{name}: joints");
    let analysis = analyse(&m);
    assert_eq!(analysis.mobility.dof, 0, "{name}: Grübler 3·4 − 2·6");
    let by_rank = rank_mobility(&m);
    assert_eq!((by_rank.unknowns, by_rank.equations), (12, 12), "{name}");
    assert_eq!(by_rank.rank, 11, "{name}");
    assert_eq!(by_rank.dof, 1, "{name}: the Jacobian sees the motion");
    assert_eq!(by_rank.redundant, vec![(redundant.to_string(), 1)], "{name}");
    assert!(by_rank.idle.is_empty(), "{name}: {:?}", by_rank.idle);
    // Planned in closed form; the redundant joint's distance is checked.
    let p = analysis.plan.expect("a plan");
    assert_eq!(p.numeric_size(), (0, 0), "{name}");
    assert!(
        p.explain_all().contains("(redundant: the distance is checked)"),
        "{name}:\n{}",
        p.explain_all()
    );
}

#[test]
fn check_names_the_redundant_joint_of_the_table() {
    check_counts("table", "joint F");
}

#[test]
fn check_names_the_redundant_joint_of_the_vlink() {
    check_counts("vlink", "joint W");
}

/// Fig. 14b: ABFE stays a parallelogram, so the extra link E→F stays
/// parallel and equal to the crank A→B, and the top translates (B→C and
/// B→T keep their drawn vectors).
#[test]
fn the_tables_extra_link_stays_parallel_to_the_crank() {
    let (m, runs) = sweep("table");
    let crank0 = sub(drawn(&m, "crank.B"), drawn(&m, "crank.A"));
    let extra0 = sub(drawn(&m, "extra.F"), drawn(&m, "extra.E"));
    assert!(dist(crank0, extra0) == 0.0, "drawn parallel and equal");
    let top0 = [
        sub(drawn(&m, "coupler.C"), drawn(&m, "coupler.B")),
        sub(drawn(&m, "coupler.T"), drawn(&m, "coupler.B")),
    ];
    let tol = 1e-9 * m.size();
    let mut turned: f64 = 0.0;
    for frames in &runs {
        for f in frames {
            let crank = sub(at(&m, f, "crank.B"), at(&m, f, "crank.A"));
            let extra = sub(at(&m, f, "extra.F"), at(&m, f, "extra.E"));
            assert!(
                cross(crank, extra).abs() <= tol * norm(crank),
                "{:?}: not parallel",
                f.inputs
            );
            assert!(dist(crank, extra) <= tol, "{:?}: extra ≠ crank", f.inputs);
            for (k, v0) in top0.iter().enumerate() {
                let v = sub(at(&m, f, ["coupler.C", "coupler.T"][k]), at(&m, f, "coupler.B"));
                assert!(dist(v, *v0) <= tol, "{:?}: the top turned", f.inputs);
            }
            turned = turned.max(dist(crank, crank0));
        }
    }
    assert!(turned > 1.0, "the sweep moves the crank ({turned})");
}

/// Fig. 13: the V moves with the coupler as one rigid body — every distance
/// between a V marker and a coupler marker stays as drawn, and so does the
/// orientation (no mirror image).
#[test]
fn the_vee_moves_rigidly_with_the_coupler() {
    let (m, runs) = sweep("vlink");
    let vee = ["vee.U", "vee.T", "vee.W"];
    let coupler = ["coupler.B", "coupler.C", "coupler.P", "coupler.U", "coupler.W"];
    let tol = 1e-9 * m.size();
    let area = |a: P, b: P, c: P| cross(sub(b, a), sub(c, a));
    let area0 = area(drawn(&m, "vee.T"), drawn(&m, "coupler.B"), drawn(&m, "coupler.C"));
    let mut moved: f64 = 0.0;
    for frames in &runs {
        for f in frames {
            for v in vee {
                for c in coupler {
                    let d0 = dist(drawn(&m, v), drawn(&m, c));
                    let d = dist(at(&m, f, v), at(&m, f, c));
                    assert!(
                        (d - d0).abs() <= tol,
                        "{:?}: |{v} {c}| = {d}, drawn {d0}",
                        f.inputs
                    );
                }
            }
            let a = area(at(&m, f, "vee.T"), at(&m, f, "coupler.B"), at(&m, f, "coupler.C"));
            assert!(
                (a - area0).abs() <= tol * m.size(),
                "{:?}: the V flipped",
                f.inputs
            );
            moved = moved.max(dist(at(&m, f, "vee.T"), drawn(&m, "vee.T")));
        }
    }
    assert!(moved > 1.0, "the V's tip travels ({moved})");
}
