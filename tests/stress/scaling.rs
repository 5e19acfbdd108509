//! Plan time scales with the mechanism: on stress chains of hundreds of
//! loops the work of every stage of `check` — the planner's, the rank's,
//! the four-bar search's (counted, not timed) — grows linearly, and the rank cross-check still finds exactly what Grübler's
//! count says — or, with a redundant link hung mid-chain, that link.

use dofplan::analysis::analyse;
use dofplan::analysis::planar::grashof::four_bars_counted;
use dofplan::analysis::planar::rank::rank_mobility;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan_tests::stress::stress_chain;

fn chain(loops: usize) -> Mechanism {
    load_str("chain.toml", &stress_chain(loops), Format::Toml).unwrap_or_else(|e| panic!("{e}"))
}

/// (planner candidate checks, rank eliminations, four-bar search steps)
/// on a chain, and its number of four-bar loops.
fn work(loops: usize) -> ([usize; 3], usize) {
    let m = chain(loops);
    let (bars, search) = four_bars_counted(&m);
    (
        [analyse(&m).planner_checks, rank_mobility(&m).eliminations, search],
        bars.len(),
    )
}

#[test]
fn every_stage_of_checks_work_grows_linearly_with_the_chain() {
    let ((w100, n100), (w200, n200), (w400, n400)) = (work(100), work(200), work(400));
    // Each loop of the chain is one four-bar, whatever the search does.
    assert_eq!((n100, n200, n400), (100, 200, 400));
    for (k, what) in ["planner checks", "rank eliminations", "four-bar search steps"]
        .into_iter()
        .enumerate()
    {
        let (a, b, c) = (w100[k], w200[k], w400[k]);
        // Every loop after the first costs the same: the work is affine in
        // the number of loops, exactly (a quadratic part would make the
        // second difference grow).
        assert_eq!(
            c - b,
            2 * (b - a),
            "{what}: {a}, {b}, {c} for 100, 200, 400 loops"
        );
        // And it is a handful of units per loop (each loop has 2 bodies,
        // 3 joints and 6 scalar equations).
        let per_loop = (b - a) / 100;
        assert!((1..=40).contains(&per_loop), "{what}: {per_loop} per loop");
    }
}

#[test]
fn the_rank_of_a_long_chain_is_grublers_count() {
    let m = chain(1000);
    assert_eq!(m.bodies.len(), 2002);
    let grubler = analyse(&m).mobility;
    assert_eq!(grubler.dof, 1);
    let by_rank = rank_mobility(&m);
    assert_eq!(by_rank.unknowns, 3 * 2001);
    assert_eq!(by_rank.equations, 2 * 3001);
    assert_eq!(by_rank.rank, 6002);
    assert_eq!(by_rank.dof, 1);
    assert!(by_rank.redundant.is_empty(), "{:?}", by_rank.redundant);
    assert!(by_rank.idle.is_empty(), "{:?}", by_rank.idle);
}

/// A chain with the table's redundant link (Brunkhart fig. 14b) hung on its
/// parallelogram loop `j`: a link from the ground midway between the
/// loop's pivots to the coupler midway between its pins, parallel and
/// equal to both arms. Its joints are written last.
fn chain_with_redundant_link(loops: usize, j: usize) -> Mechanism {
    let text = stress_chain(loops);
    let m = load_str("chain.toml", &text, Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    let c = m.marker(m.find_marker(&format!("coupler_{j}.C{j}")).unwrap()).at;
    let ground = [4.0 * (j - 1) as f64 + 2.0, 0.0];
    let pin = [c[0] + 2.0, c[1]];
    let pt = |p: [f64; 2]| format!("[{:?}, {:?}]", p[0], p[1]);
    let text = text
        .replacen(
            "[bodies.ground]\nfixed = true\nmarkers = { ",
            &format!("[bodies.ground]\nfixed = true\nmarkers = {{ E = {}, ", pt(ground)),
            1,
        )
        .replacen(
            &format!("[bodies.coupler_{j}]\nmarkers = {{ "),
            &format!("[bodies.coupler_{j}]\nmarkers = {{ F = {}, ", pt(pin)),
            1,
        )
        .replacen(
            "[inputs.theta]",
            &format!(
                "[bodies.extra]\nmarkers = {{ E = {}, F = {} }}\n\n\
                 [joints.E]\nkind = \"revolute\"\nmarkers = [\"ground.E\", \"extra.E\"]\n\n\
                 [joints.F]\nkind = \"revolute\"\nmarkers = [\"extra.F\", \"coupler_{j}.F\"]\n\n\
                 [inputs.theta]",
                pt(ground),
                pt(pin)
            ),
            1,
        );
    load_str("chain.toml", &text, Format::Toml).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_redundant_link_mid_chain_is_named() {
    let m = chain_with_redundant_link(300, 150);
    assert_eq!(analyse(&m).mobility.dof, 0, "Grübler sees one freedom fewer");
    let by_rank = rank_mobility(&m);
    assert_eq!(by_rank.dof, 1, "the Jacobian sees the chain's motion");
    assert_eq!(by_rank.redundant, vec![("joint F".to_string(), 1)]);
    assert!(by_rank.idle.is_empty(), "{:?}", by_rank.idle);
}

/// The CLI's test of `check` on a long chain reads this generator's file.
#[test]
fn the_cli_tests_chain_is_the_generators() {
    let kept = std::fs::read_to_string(
        dofplan_tests::mechanisms_dir().join("../compiler/tests/data/stress_loops_200.toml"),
    )
    .expect("kept in compiler/tests/data");
    assert!(
        kept == stress_chain(200),
        "regenerate it: cargo run -p dofplan-gen -- stress-chain 200 > compiler/tests/data/stress_loops_200.toml"
    );
}

/// A misdrawn joint in a long chain: the loader's error names it at once;
/// the dense assembly that would tell a misdrawn joint from a conflict is
/// not run on a mechanism this large, and the help says so.
#[test]
fn a_misdrawn_joint_in_a_long_chain_is_reported_without_the_assembly() {
    let text = stress_chain(100);
    let m = chain(100);
    let r5 = m.marker(m.find_marker("coupler_5.R5").unwrap()).at;
    let drawn = format!("R5 = [{:?}, {:?}]", r5[0], r5[1]);
    let moved = format!("R5 = [{:?}, {:?}]", r5[0] + 0.3, r5[1]);
    let at = text.find("[bodies.coupler_5]").unwrap();
    let text = format!("{}{}", &text[..at], text[at..].replacen(&drawn, &moved, 1));
    let e = load_str("chain.toml", &text, Format::Toml).expect_err("joint R5 is open");
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    let d = &e.diagnostics[0];
    assert!(
        d.message
            .starts_with("joint `R5` does not hold in the drawn pose"),
        "{e}"
    );
    let help = d.help.as_deref().unwrap_or_default();
    assert!(
        help.contains("was not checked")
            && help.contains(&format!(
                "at most {}",
                dofplan::conflict::planar::MAX_REVIEWED_BODIES
            )),
        "{help}"
    );
}
