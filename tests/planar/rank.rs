//! Mobility by Jacobian rank: agrees with Grübler on generic mechanisms,
//! finds the redundant joint of a non-generic one (Brunkhart fig. 14b: a
//! parallelogram with an extra parallel link) and names idle freedoms.

use dofplan::analysis::analyse;
use dofplan::analysis::planar::rank::rank_mobility;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan::simulate::{max_relative_residual, run};
use dofplan_runtime::Options;
use dofplan_tests::{bundled, load};

fn mechanism(text: &str) -> Mechanism {
    load_str("t.toml", text, Format::Toml).unwrap_or_else(|e| panic!("{e}"))
}

/// The bundled over-constrained mechanisms (Brunkhart §2.1.3–2.1.4) and the
/// one joint of each that repeats what the joints before it impose.
const REDUNDANT: [(&str, &str); 2] = [
    // Fig. 14b: the extra link parallel to crank and rocker.
    ("table", "joint F"),
    // Fig. 13: the V's second pin on the coupler.
    ("vlink", "joint W"),
];

#[test]
fn rank_and_grubler_agree_on_every_bundled_mechanism() {
    for name in bundled() {
        let m = load(&name);
        let by_rank = rank_mobility(&m);
        let grubler = analyse(&m).mobility.dof;
        match REDUNDANT.iter().find(|(n, _)| *n == name) {
            // One dependent equation: the Jacobian sees one freedom more.
            Some((_, joint)) => {
                assert_eq!(by_rank.dof, grubler + 1, "{name}");
                assert_eq!(by_rank.redundant, vec![(joint.to_string(), 1)], "{name}");
            }
            None => {
                assert_eq!(by_rank.dof, grubler, "{name}");
                assert!(by_rank.redundant.is_empty(), "{name}: {:?}", by_rank.redundant);
            }
        }
        assert!(by_rank.idle.is_empty(), "{name}: {:?}", by_rank.idle);
    }
    for (name, _) in REDUNDANT {
        assert!(bundled().iter().any(|n| n == name), "{name} is bundled");
    }
}

/// Fig. 14b: the extra link is parallel to crank and rocker, so it removes
/// no freedom though Grübler counts two equations for its second joint.
const PARALLELOGRAM_EXTRA: &str = r#"
name = "parallelogram_extra"
[bodies.ground]
fixed = true
markers = { A = [0, 0], E = [2, 0], D = [4, 0] }
[bodies.crank]
markers = { A = [0, 0], B = [1, 1.5] }
[bodies.coupler]
markers = { B = [1, 1.5], F = [3, 1.5], C = [5, 1.5] }
[bodies.rocker]
markers = { D = [4, 0], C = [5, 1.5] }
[bodies.extra]
markers = { E = [2, 0], F = [3, 1.5] }
[joints.A]
kind = "revolute"
markers = ["ground.A", "crank.A"]
[joints.B]
kind = "revolute"
markers = ["crank.B", "coupler.B"]
[joints.C]
kind = "revolute"
markers = ["coupler.C", "rocker.C"]
[joints.D]
kind = "revolute"
markers = ["rocker.D", "ground.D"]
[joints.E]
kind = "revolute"
markers = ["ground.E", "extra.E"]
[joints.F]
kind = "revolute"
markers = ["extra.F", "coupler.F"]
[inputs.theta]
kind = "angle"
joint = "A"
"#;

#[test]
fn a_redundant_parallel_link_is_found_and_still_animates() {
    let m = mechanism(PARALLELOGRAM_EXTRA);
    let analysis = analyse(&m);
    assert_eq!(analysis.mobility.dof, 0, "Grübler sees a structure");
    let by_rank = rank_mobility(&m);
    assert_eq!(by_rank.dof, 1, "the Jacobian sees the parallelogram's motion");
    assert_eq!(by_rank.redundant, vec![("joint F".to_string(), 1)]);
    // Consistent redundancy solves and animates (until the change point).
    let plan = analysis.plan.expect("closed form");
    let requested: Vec<Vec<f64>> = (0..=40).map(|i| vec![f64::from(i) * 2.0]).collect();
    for f in run(Interpreter::new(plan), Options::default(), &requested) {
        assert!(f.status.is_solved());
        assert!(max_relative_residual(&m, &f.poses, &f.inputs) <= 1e-12);
    }
}

#[test]
fn a_link_on_a_single_pin_is_an_idle_freedom() {
    let fourbar = std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml")).unwrap();
    let text = fourbar.replace(
        "[bodies.rocker]",
        "[bodies.flag]\nmarkers = { P = [3, 3.5], Q = [3, 4.5] }\n\n[joints.flag]\nkind = \"revolute\"\nmarkers = [\"coupler.P\", \"flag.P\"]\n\n[bodies.rocker]",
    );
    let m = mechanism(&text);
    let by_rank = rank_mobility(&m);
    assert_eq!(by_rank.dof, 2);
    assert_eq!(by_rank.idle, vec![("flag".to_string(), 1)]);
    assert!(by_rank.redundant.is_empty());
}

/// The same, with the extra link not parallel: Grübler and the Jacobian
/// both see a structure, and driving it is an inconsistency the plan's
/// redundant step reports as a break naming its step — never a silently
/// open joint.
#[test]
fn an_inconsistent_redundant_link_breaks_when_driven() {
    let text = PARALLELOGRAM_EXTRA.replace("F = [3, 1.5]", "F = [3.5, 1.5]");
    let m = mechanism(&text);
    let by_rank = rank_mobility(&m);
    assert_eq!(by_rank.dof, 0, "locked: {by_rank:?}");
    let plan = analyse(&m).plan.expect("a plan");
    assert!(plan
        .explain_all()
        .contains("(redundant: the distance is checked)"));
    let frames = run(
        Interpreter::new(plan.clone()),
        Options::default(),
        &[vec![0.0], vec![5.0]],
    );
    assert!(frames[0].status.is_solved());
    let dofplan_runtime::FrameStatus::Limited { brk } = frames[1].status else {
        panic!("{:?}", frames[1].status)
    };
    assert_eq!(brk.kind, dofplan_runtime::BreakKind::Inconsistent);
    assert!(plan.explain(brk.step as usize).starts_with("extra:"));
    assert_eq!(frames[1].poses, frames[0].poses);
}

/// Rank, redundant equations and idle bodies, as `RankMobility` gives them.
type RankFacts = (usize, Vec<(String, usize)>, Vec<(String, usize)>);

/// The rank cross-check by its definition, independently of the sparse
/// elimination `rank_mobility` runs: the dense Jacobian of pure Newton at
/// the drawn pose, the SVD rank of every prefix of its rows (an equation
/// is redundant by as many rows as it adds no rank to the rows before it),
/// and the SVD rank of each body's three columns.
fn by_dense_svds(m: &Mechanism) -> RankFacts {
    use dofplan::numeric::PureNewton;
    use dofplan_runtime::numeric::rank;
    const CUTOFF: f64 = 1e-9;
    let mut free = m.clone();
    free.inputs.clear();
    let newton = PureNewton::new(&free);
    let (j, groups) = newton.drawn_jacobian();
    let mut redundant = Vec::new();
    let (mut taken, mut before) = (0, 0);
    for (origin, count) in groups {
        let r = rank(&j.rows(0, taken + count).into_owned(), CUTOFF);
        if r - before < count {
            redundant.push((origin, count - (r - before)));
        }
        (taken, before) = (taken + count, r);
    }
    let idle = newton
        .unknown_bodies()
        .into_iter()
        .filter_map(|(b, col)| {
            let alone = 3 - rank(&j.columns(col, 3).into_owned(), CUTOFF);
            (alone > 0).then(|| (m.bodies[b].name.clone(), alone))
        })
        .collect();
    (rank(&j, CUTOFF), redundant, idle)
}

#[test]
fn the_sparse_rank_equals_the_dense_svds() {
    let mut cases: Vec<(String, Mechanism)> = bundled().into_iter().map(|n| (n.clone(), load(&n))).collect();
    for file in ["drag/open_chain_15.toml", "../tests/fixtures/sixbar_slotted.toml"] {
        let path = dofplan_tests::mechanisms_dir().join(file);
        let m = dofplan::load_file(&path).unwrap_or_else(|e| panic!("{e}"));
        cases.push((file.to_string(), m));
    }
    let fourbar = std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml")).unwrap();
    let flagged = fourbar.replace(
        "[bodies.rocker]",
        "[bodies.flag]\nmarkers = { P = [3, 3.5], Q = [3, 4.5] }\n\n[joints.flag]\nkind = \"revolute\"\nmarkers = [\"coupler.P\", \"flag.P\"]\n\n[bodies.loose]\nmarkers = { L = [9, 9] }\n\n[bodies.rocker]",
    );
    for (name, text) in [
        ("parallelogram_extra", PARALLELOGRAM_EXTRA.to_string()),
        (
            "parallelogram_extra_off",
            PARALLELOGRAM_EXTRA.replace("F = [3, 1.5]", "F = [3.5, 1.5]"),
        ),
        ("flagged_fourbar", flagged),
        ("stress_chain_3", dofplan_tests::stress::stress_chain(3)),
        ("stress_chain_30", dofplan_tests::stress::stress_chain(30)),
    ] {
        cases.push((name.to_string(), mechanism(&text)));
    }
    for (name, m) in &cases {
        let sparse = rank_mobility(m);
        let (rank, redundant, idle) = by_dense_svds(m);
        assert_eq!(sparse.rank, rank, "{name}");
        assert_eq!(sparse.dof, sparse.unknowns as i64 - rank as i64, "{name}");
        assert_eq!(sparse.redundant, redundant, "{name}");
        assert_eq!(sparse.idle, idle, "{name}");
    }
    // The cases do exercise what is compared.
    assert!(cases.len() > 25);
    let found = |f: fn(&dofplan::analysis::planar::rank::RankMobility) -> bool| {
        cases.iter().any(|(_, m)| f(&rank_mobility(m)))
    };
    assert!(found(|r| !r.redundant.is_empty()));
    assert!(found(|r| r.idle.iter().any(|(_, n)| *n == 3)));
    assert!(found(|r| r.idle.iter().any(|(_, n)| *n == 1)));
}
