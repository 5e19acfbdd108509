//! Over-constrained mechanisms (Brunkhart 1994, §2.1.3–2.1.4).
//!
//! A consistent redundant mechanism — the "table" of fig. 14b and the V-link
//! of fig. 13, both bundled — solves and animates, its redundant joint named
//! by `check`. An inconsistent one, drawn so that its joints cannot all
//! close, is an error naming the joints in conflict; one whose drawing is
//! merely off gets the drawn-pose error and a hint that it assembles. Each
//! property below is recomputed here from the markers, not read from the
//! plan.

use dofplan::analysis::analyse;
use dofplan::analysis::planar::rank::rank_mobility;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
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

// ------------------------------------------------ inconsistent redundancy

/// The bundled file's text with `from` replaced by `to` (exactly once).
fn edited(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(dofplan_tests::mechanisms_dir().join(format!("{name}.toml"))).unwrap();
    assert_eq!(text.matches(from).count(), 1, "{name}: `{from}`");
    text.replace(from, to)
}

/// `t.toml:LINE:1`, the position of the table header `[joints.NAME]`.
fn joint_position(text: &str, joint: &str) -> String {
    let header = format!("[joints.{joint}]");
    let line = text.lines().position(|l| l == header).expect("joint header") + 1;
    format!("t.toml:{line}:1")
}

/// The one error of a text that must not load.
fn error(text: &str) -> dofplan::model::Diagnostic {
    match load_str("t.toml", text, Format::Toml) {
        Ok(_) => panic!("loaded, but should not have:\n{text}"),
        Err(e) => {
            assert_eq!(e.diagnostics.len(), 1, "exactly one error:\n{e}");
            e.diagnostics[0].clone()
        }
    }
}

/// The joints an error says are in conflict ("joints A, B are in conflict").
fn named(message: &str) -> Vec<String> {
    let list = message
        .strip_prefix("joints ")
        .and_then(|m| m.split(" are in conflict").next())
        .unwrap_or_else(|| panic!("not a conflict error: {message}"));
    list.split(", ").map(str::to_string).collect()
}

/// The table with its extra link drawn too long: extra.E at (1.7, 0), 0.3
/// off the ground's E, so |EF| = √(1.3² + 1.5²) = 1.985 where the crank is
/// √3.25 = 1.803. No pose at all closes every joint: in the parallelogram
/// mode the coupler's F = B + (2, 0) stays exactly |AB| from E = (2, 0),
/// and the crossed mode (computed below, over a full turn of the crank)
/// never takes F farther than that either.
#[test]
fn an_extra_link_that_cannot_fit_is_an_error_naming_the_joints_in_conflict() {
    let text = edited(
        "table",
        "markers = { E = [2, 0], F = [3, 1.5] }",
        "markers = { E = [1.7, 0], F = [3, 1.5] }",
    );
    // Independent check that no pose closes E and F together.
    let m = load("table");
    let (a, d, e) = (
        drawn(&m, "ground.A"),
        drawn(&m, "ground.D"),
        drawn(&m, "ground.E"),
    );
    let crank = dist(drawn(&m, "crank.A"), drawn(&m, "crank.B"));
    let (coupler, rocker) = (
        dist(drawn(&m, "coupler.B"), drawn(&m, "coupler.C")),
        dist(drawn(&m, "rocker.D"), drawn(&m, "rocker.C")),
    );
    let bf = dist(drawn(&m, "coupler.B"), drawn(&m, "coupler.F"));
    let extra = dist([1.7, 0.0], drawn(&m, "extra.F"));
    let mut farthest: f64 = 0.0;
    for i in 0..3600 {
        let phi = f64::from(i).to_radians() / 10.0;
        let b = [a[0] + crank * phi.cos(), a[1] + crank * phi.sin()];
        // C on circle(B, coupler) ∩ circle(D, rocker), both roots.
        let (bd, u) = (dist(b, d), sub(d, b));
        let along = (coupler * coupler - rocker * rocker + bd * bd) / (2.0 * bd);
        let h2 = coupler * coupler - along * along;
        if h2 < 0.0 {
            continue;
        }
        for sign in [1.0, -1.0] {
            let c = [
                b[0] + (along * u[0] - sign * h2.sqrt() * u[1]) / bd,
                b[1] + (along * u[1] + sign * h2.sqrt() * u[0]) / bd,
            ];
            // F on the coupler, |BF| along B→C.
            let f = [
                b[0] + (c[0] - b[0]) * bf / coupler,
                b[1] + (c[1] - b[1]) * bf / coupler,
            ];
            farthest = farthest.max(dist(f, e));
        }
    }
    assert!(
        farthest < extra - 0.1,
        "F reaches {farthest}, the extra link is {extra}"
    );

    let d = error(&text);
    let shown = d.to_string();
    assert!(
        shown.starts_with(&format!("{}: error: joints ", joint_position(&text, "E"))),
        "at the open joint E:\n{shown}"
    );
    let joints = named(&d.message);
    // The extra link touches the rest only at E and F, and at a
    // least-squares point the pulls on it balance: both stay open. Every
    // other named joint must be one of the loop's.
    for must in ["E", "F"] {
        assert!(joints.iter().any(|j| j == must), "{must} not named:\n{shown}");
    }
    for j in &joints {
        assert!(
            ["A", "B", "C", "D", "E", "F"].contains(&j.as_str()),
            "{j}:\n{shown}"
        );
    }
    let mut sorted = joints.clone();
    sorted.sort();
    assert_eq!(joints, sorted, "in file order");
    for needle in [
        "are in conflict: no pose near the drawn one closes them all (least-squares gap ",
        "note: joint `E` does not hold in the drawn pose: ground.E at [2, 0] and extra.E at [1.7, 0] are 3.000e-1 apart",
        "help: a redundant link must be exactly consistent (e.g. parallel and equal to the link it duplicates)",
    ] {
        assert!(shown.contains(needle), "`{needle}` not in:\n{shown}");
    }
    // Every other joint in the conflict is pointed at.
    for j in joints.iter().filter(|j| *j != "E") {
        let note = format!(
            "{}: note: joint {j} is in the conflict: open by ",
            joint_position(&text, j)
        );
        assert!(shown.contains(&note), "`{note}` not in:\n{shown}");
    }
    // Removing any named joint (the open E aside) resolves the conflict: the
    // rest assembles, and the error becomes the drawn-pose one with a hint.
    for j in joints.iter().filter(|j| *j != "E") {
        let header = format!("[joints.{j}]");
        let start = text.find(&header).unwrap();
        let end = start + text[start..].find("\nmarkers").unwrap();
        let end = end + 1 + text[end + 1..].find('\n').unwrap() + 1;
        let mut without = text.clone();
        without.replace_range(start..end, "");
        if j == "A" {
            // The input drives joint A: drive the extra link's E instead.
            without = without.replace("joint = \"A\"", "joint = \"D\"");
        }
        let shown = error(&without).to_string();
        assert!(
            shown.contains("does not hold in the drawn pose")
                && shown.contains("the mechanism does assemble"),
            "without joint {j}:\n{shown}"
        );
    }
}

/// A link on a single pin can always close, so it is never in a conflict.
#[test]
fn a_joint_that_can_close_on_its_own_is_not_in_the_conflict() {
    let text = edited(
        "table",
        "markers = { E = [2, 0], F = [3, 1.5] }",
        "markers = { E = [1.7, 0], F = [3, 1.5] }",
    )
    .replace(
        "[joints.A]",
        "[bodies.flag]\nmarkers = { T = [3, 2.5], Q = [3, 3.5] }\n\n[joints.flag]\nkind = \"revolute\"\nmarkers = [\"coupler.T\", \"flag.T\"]\n[joints.A]",
    );
    let d = error(&text);
    let joints = named(&d.message);
    assert!(
        joints.contains(&"E".to_string()) && joints.contains(&"F".to_string()),
        "{d}"
    );
    assert!(!joints.contains(&"flag".to_string()), "{d}");
}

/// Fig. 13 with one of the V's holes 0.01 off: the V needs |UW| on both
/// bodies, and no motion of the four-bar changes the coupler's |UW|, so the
/// four-bar's joints close and exactly U and W stay open.
#[test]
fn a_vee_whose_holes_do_not_match_names_its_two_joints() {
    let text = edited(
        "vlink",
        "markers = { U = [2, 2], T = [2.5, 4.5], W = [4, 3] }",
        "markers = { U = [2, 2], T = [2.5, 4.5], W = [4.01, 3] }",
    );
    let d = error(&text);
    let shown = d.to_string();
    assert!(
        shown.starts_with(&format!(
            "{}: error: joints U, W are in conflict: no pose near the drawn one closes them all (least-squares gap ",
            joint_position(&text, "W")
        )),
        "{shown}"
    );
    // The least-squares gap, by hand: two holes on the V, two on the
    // coupler, |UW| longer on the V by `mismatch`. The best rigid fit turns
    // the V to the coupler's U→W and centres it, leaving each hole open by
    // half the mismatch: ‖r‖ = √2 · mismatch / 2.
    let gap: f64 = shown
        .split("least-squares gap ")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .and_then(|s| s.parse().ok())
        .expect("a gap");
    let mismatch = dist([2.0, 2.0], [4.01, 3.0]) - dist([2.0, 2.0], [4.0, 3.0]);
    let expected = mismatch / 2f64.sqrt();
    // The message shows two significant digits.
    assert!(
        (gap - expected).abs() <= 0.06e-3,
        "gap {gap}, expected {expected}"
    );
    assert!(shown.contains(&format!(
        "{}: note: joint U is in the conflict",
        joint_position(&text, "U")
    )));
}

/// The table with its ground pivot E moved by 0.3: the extra link is no
/// longer parallel to the crank, but it still fits — F must be |AB| from
/// E' = (2.3, 0) and (parallelogram mode) |AB| from (2, 0), two circles
/// that meet — so the mechanism assembles (as a rigid structure) and the
/// error is only the drawing's.
#[test]
fn a_non_parallel_extra_link_that_still_fits_is_only_a_drawing_error() {
    let text = edited(
        "table",
        "markers = { A = [0, 0], E = [2, 0], D = [4, 0] }",
        "markers = { A = [0, 0], E = [2.3, 0], D = [4, 0] }",
    );
    let shown = error(&text).to_string();
    assert!(
        shown.starts_with(&format!(
            "{}: error: joint `E` does not hold in the drawn pose",
            joint_position(&text, "E")
        )),
        "{shown}"
    );
    assert!(
        shown.contains("the mechanism does assemble with joint E closed (at [2.3, 0])"),
        "{shown}"
    );
    assert!(!shown.contains("conflict"), "{shown}");
}
