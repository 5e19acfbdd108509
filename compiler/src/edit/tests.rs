//! Edits checked against what the loader and the analysis say of the
//! resulting file, written independently (hand-written texts, distances
//! computed here), never against the editor's own output alone.

use super::*;
use crate::analysis::analyse;
use crate::analysis::planar::rank::rank_mobility;
use crate::interp::Interpreter;
use dofplan_runtime::{Driver, FrameStatus, Options};

const FOURBAR: &str = include_str!("../../../mechanisms/fourbar.toml");

fn edit(e: &mut Editor, json: &str) -> Result<String, EditError> {
    let op: Edit = serde_json::from_str(json).expect("a well-formed edit");
    e.apply(&op)
}

fn at(e: &Editor, name: &str) -> [f64; 2] {
    let m = e.mechanism();
    let (b, k) = name.split_once('.').unwrap();
    let body = m.bodies.iter().find(|x| x.name == b).unwrap();
    body.markers.iter().find(|x| x.name == k).unwrap().at
}

#[test]
fn a_fourbar_built_by_hand_plans_and_turns() {
    let mut e = Editor::empty("new.toml");
    // Ground pivots O = (0, 0) (the empty document's) and D = (4, 0).
    edit(&mut e, r#"{"op": "add_marker", "body": "ground", "at": [4, 0]}"#).unwrap();
    // Links drawn by clicks, each then dropped onto its neighbours.
    edit(
        &mut e,
        r#"{"op": "add_body", "name": "crank", "markers": [[0.05, 0.02], [1, 1]]}"#,
    )
    .unwrap();
    edit(
        &mut e,
        r#"{"op": "add_body", "name": "coupler", "markers": [[1.02, 0.98], [4.5, 2.5]]}"#,
    )
    .unwrap();
    edit(
        &mut e,
        r#"{"op": "add_body", "name": "rocker", "markers": [[4.5, 2.52], [4.01, 0]]}"#,
    )
    .unwrap();
    for (a, b) in [
        ("ground.O", "crank.A"),
        ("crank.B", "coupler.A"),
        ("coupler.B", "rocker.A"),
        ("ground.A", "rocker.B"),
    ] {
        let s = edit(
            &mut e,
            &format!(r#"{{"op": "join", "a": "{a}", "b": "{b}", "snap": true}}"#),
        )
        .unwrap();
        assert!(s.contains("revolute joint"), "{s}");
    }
    let s = edit(&mut e, r#"{"op": "add_input", "joint": "J1"}"#).unwrap();
    assert_eq!(s, "joint J1 is driven by angle input theta");
    // Snapping put every joined pair on one point.
    assert_eq!(at(&e, "crank.A"), [0.0, 0.0]);
    assert_eq!(at(&e, "rocker.B"), [4.0, 0.0]);
    // The file the editor wrote loads by itself, is a one-DOF four-bar by
    // rank, and its plan turns the crank a full turn with every joint
    // closed (distances computed here from the markers).
    let text = e.text();
    let m = load_str("new.toml", &text, Format::Toml).expect("the saved file loads");
    assert_eq!(rank_mobility(&m).dof, 1);
    let plan = analyse(&m).plan.expect("plans");
    let mut d = Driver::new(Interpreter::new(plan), Options::default());
    for deg in (0..360).step_by(10) {
        assert_eq!(d.frame(&[deg as f64]), FrameStatus::Solved, "{deg}°");
        for j in &m.joints {
            let [a, b] = j.markers.map(|id| d.poses()[id.body].world(m.marker(id).at));
            assert!(
                (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9,
                "joint {} open at {deg}°",
                j.name
            );
        }
    }
}

#[test]
fn an_edit_that_breaks_the_file_gets_checks_message_and_changes_nothing() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let before = e.text();
    // Joining markers 1.4 apart without snapping: the loader's message for
    // the same file written by hand.
    let err = edit(
        &mut e,
        r#"{"op": "join", "a": "ground.A", "b": "coupler.B", "name": "X"}"#,
    )
    .unwrap_err();
    // The new joint goes after the last one, where a person would add it.
    let last = "markers = [\"rocker.D\", \"ground.D\"]\n";
    let by_hand = FOURBAR.replace(
        last,
        &format!("{last}\n[joints.X]\nkind = \"revolute\"\nmarkers = [\"ground.A\", \"coupler.B\"]\n"),
    );
    let expected = load_str("fourbar.toml", &by_hand, Format::Toml)
        .unwrap_err()
        .render(false);
    assert_eq!(err, EditError::Invalid(expected));
    assert!(err.to_string().contains("joint `X` does not hold"), "{err}");
    assert_eq!(e.text(), before);
    assert!(!e.can().0, "a refused edit is not in the history");
    // Names that are not there, and the last ground.
    for (json, says) in [
        (r#"{"op": "delete_body", "body": "ground"}"#, "only fixed body"),
        (
            r#"{"op": "move_marker", "marker": "crank.Z", "to": [0, 0]}"#,
            "no marker Z",
        ),
        (r#"{"op": "toggle", "joint": "Q"}"#, "no joint named Q"),
        (
            r#"{"op": "add_body", "markers": [[0, 0]]}"#,
            "two or more markers",
        ),
        (r#"{"op": "join", "a": "crank.A", "b": "crank.B"}"#, "same body"),
    ] {
        let err = edit(&mut e, json).unwrap_err();
        assert!(err.to_string().contains(says), "{json}: {err}");
    }
    assert!(serde_json::from_str::<Edit>(r#"{"op": "add_body", "markers": [], "colour": 1}"#).is_err());
}

#[test]
fn moving_a_pivot_keeps_comments_order_and_its_joint() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let s = edit(
        &mut e,
        r#"{"op": "move_marker", "marker": "ground.D", "to": [4.2, 0]}"#,
    )
    .unwrap();
    assert_eq!(s, "moved ground.D, rocker.D to (4.2, 0)");
    let text = e.text();
    // Only the two marker lines changed; comments and the rest are as read.
    let changed: Vec<(&str, &str)> = FOURBAR
        .lines()
        .zip(text.lines())
        .filter(|(a, b)| a != b)
        .collect();
    assert_eq!(
        changed,
        [
            (
                "markers = { A = [0, 0], D = [4, 0] }",
                "markers = { A = [0, 0], D = [4.2, 0.0] }"
            ),
            (
                "markers = { C = [4.5, 2.5], D = [4, 0] }",
                "markers = { C = [4.5, 2.5], D = [4.2, 0.0] }"
            ),
        ]
    );
    assert_eq!(FOURBAR.lines().count(), text.lines().count());
    // Undo and redo give the texts back exactly.
    assert!(e.undo());
    assert_eq!(e.text(), FOURBAR);
    assert!(!e.undo());
    assert!(e.redo());
    assert_eq!(e.text(), text);
}

#[test]
fn deleting_says_everything_it_removes() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_body", "body": "crank"}"#).unwrap();
    assert_eq!(
        s,
        "deleted body crank; also removed joint A, input theta, the sweep, joint B"
    );
    let m = e.mechanism();
    assert!(m.inputs.is_empty() && m.sweep.is_none());
    assert_eq!(
        m.joints.iter().map(|j| j.name.as_str()).collect::<Vec<_>>(),
        ["C", "D"]
    );
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_marker", "marker": "coupler.P"}"#).unwrap();
    assert_eq!(s, "deleted marker coupler.P; also removed the trace of coupler.P");
    assert!(e.text().contains("trace = []"));
}

#[test]
fn toggling_a_joint_makes_it_slide_along_the_line_of_its_bodies() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    // Joint D: rocker.D first, so the line runs from D toward the nearest
    // other marker of the ground, A: along (−1, 0).
    let s = edit(&mut e, r#"{"op": "toggle", "joint": "D"}"#).unwrap();
    assert_eq!(s, "joint D is now prismatic along (-1, 0)");
    let m = e.mechanism();
    let d = m.joints.iter().find(|j| j.name == "D").unwrap();
    assert_eq!(d.kind, JointKindForTests::Prismatic);
    assert_eq!(m.marker(d.markers[0]).dir, Some([-1.0, 0.0]));
    // A slider-crank now: one DOF by rank.
    assert_eq!(rank_mobility(m).dof, 1);
    // The input on a toggled joint changes kind with it.
    let s = edit(&mut e, r#"{"op": "toggle", "joint": "A"}"#).unwrap();
    assert!(s.contains("input theta is now a slide"), "{s}");
    edit(&mut e, r#"{"op": "toggle", "joint": "A"}"#).unwrap();
    assert!(e.text().contains("kind = \"angle\""));
}

use crate::model::JointKind as JointKindForTests;

#[test]
fn redrawing_at_a_solved_pose_makes_it_the_drawn_one() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let m = e.mechanism().clone();
    let plan = analyse(&m).plan.unwrap();
    let mut d = Driver::new(Interpreter::new(plan), Options::default());
    assert_eq!(d.frame(&[30.0]), FrameStatus::Solved);
    let poses = d.poses().to_vec();
    e.redraw(&poses).unwrap();
    // The crank's B is now at 30° further round: |AB| = √2 at 45° + 30°.
    let b = at(&e, "crank.B");
    let angle = 75f64.to_radians();
    assert!(
        (b[0] - 2f64.sqrt() * angle.cos()).abs() < 1e-12 && (b[1] - 2f64.sqrt() * angle.sin()).abs() < 1e-12
    );
    // And the redrawn file loaded (its joints hold as drawn), so the next
    // edit starts from the pose that was on screen.
    assert!(e.can().0);
}

#[test]
fn edits_made_together_at_a_pose_are_one_undo_and_all_or_nothing() {
    let mut e = Editor::empty("new.toml");
    edit(&mut e, r#"{"op": "add_marker", "body": "ground", "at": [4, 0]}"#).unwrap();
    let before = e.text();
    let ops: Vec<Edit> = serde_json::from_str(
        r#"[{"op": "add_body", "name": "crank", "markers": [[0, 0], [1, 1]]},
            {"op": "join", "a": "ground.O", "b": "crank.A"}]"#,
    )
    .unwrap();
    let summaries = e.apply_at(None, &ops).unwrap();
    assert_eq!(summaries.len(), 2, "{summaries:?}");
    assert_eq!(e.mechanism().joints.len(), 1);
    assert!(e.undo());
    assert_eq!(e.text(), before, "one undo takes both back");
    // The second edit fails (no such marker): the first is not made either.
    let bad: Vec<Edit> = serde_json::from_str(
        r#"[{"op": "add_body", "markers": [[0, 0], [1, 1]]},
            {"op": "join", "a": "ground.O", "b": "link1.Z"}]"#,
    )
    .unwrap();
    assert!(e.apply_at(None, &bad).is_err());
    assert_eq!(e.text(), before);
    assert_eq!(e.can(), (true, true), "the refused edits left the history alone");
}

#[test]
fn an_edit_at_the_pose_on_screen_redraws_first() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let m = e.mechanism().clone();
    let plan = analyse(&m).plan.unwrap();
    let mut d = Driver::new(Interpreter::new(plan), Options::default());
    assert_eq!(d.frame(&[30.0]), FrameStatus::Solved);
    let poses = d.poses().to_vec();
    let add: Vec<Edit> =
        serde_json::from_str(r#"[{"op": "add_marker", "body": "crank", "at": [0, 0]}]"#).unwrap();
    let summaries = e.apply_at(Some(&poses), &add).unwrap();
    assert_eq!(summaries.len(), 2, "the redraw's summary, then the edit's");
    let b = at(&e, "crank.B");
    let angle = 75f64.to_radians();
    assert!(
        (b[0] - 2f64.sqrt() * angle.cos()).abs() < 1e-12,
        "drawn at 30° ({b:?})"
    );
    assert!(
        e.undo() && !e.can().0,
        "one undo takes back the redraw and the edit"
    );
    assert_eq!(e.text(), FOURBAR);
}

#[test]
fn a_renamed_file_is_named_so_in_diagnostics() {
    let mut e = Editor::empty("untitled.toml");
    e.set_file_name("linkage.toml");
    edit(&mut e, r#"{"op": "add_body", "markers": [[1, 0], [2, 0]]}"#).unwrap();
    // Not snapped: ground.O and link1.A are a unit apart, which check
    // refuses, naming the file.
    let err = edit(&mut e, r#"{"op": "join", "a": "ground.O", "b": "link1.A"}"#).unwrap_err();
    assert!(matches!(err, EditError::Invalid(_)), "{err:?}");
    assert!(
        err.to_string().contains("linkage.toml") && !err.to_string().contains("untitled"),
        "{err}"
    );
}

#[test]
fn the_sweep_and_its_traces_are_set_from_edits_and_load_as_written() {
    // The four-bar without its sweep: a mechanism built by mouse has none.
    let text = FOURBAR.split("[sweep]").next().unwrap();
    let mut e = Editor::new("f.toml", text).unwrap();
    assert!(e.mechanism().sweep.is_none());
    let refused = edit(&mut e, r#"{"op": "trace", "marker": "coupler.P", "on": true}"#);
    assert!(
        matches!(&refused, Err(EditError::Refused(w)) if w.contains("no sweep")),
        "{refused:?}"
    );
    let s = edit(
        &mut e,
        r#"{"op": "set_sweep", "input": "theta", "from": -30, "to": 90, "steps": 13}"#,
    )
    .unwrap();
    assert_eq!(s, "added the sweep: theta from -30 to 90 in 13 steps");
    let sweep = e.mechanism().sweep.clone().expect("a sweep");
    assert_eq!((sweep.steps, sweep.inputs.len()), (13, 1));
    assert_eq!((sweep.primary().from, sweep.primary().to), (-30.0, 90.0));
    assert_eq!(sweep.value(1), -20.0, "13 frames from -30 to 90 are 10° apart");
    edit(&mut e, r#"{"op": "trace", "marker": "coupler.P", "on": true}"#).unwrap();
    edit(&mut e, r#"{"op": "trace", "marker": "rocker.C", "on": true}"#).unwrap();
    let again = edit(&mut e, r#"{"op": "trace", "marker": "rocker.C", "on": true}"#);
    assert!(matches!(again, Err(EditError::Refused(_))), "{again:?}");
    let names: Vec<String> = e
        .mechanism()
        .sweep
        .as_ref()
        .unwrap()
        .trace
        .iter()
        .map(|&id| e.mechanism().marker_name(id))
        .collect();
    assert_eq!(names, ["coupler.P", "rocker.C"]);
    // Setting the range again keeps the traces; the text says it plainly.
    edit(
        &mut e,
        r#"{"op": "set_sweep", "input": "theta", "from": 0, "to": 360, "steps": 361}"#,
    )
    .unwrap();
    let written = e.text();
    assert!(
        written.contains("[sweep]\ninput = \"theta\"\nfrom = 0.0\nto = 360.0\nsteps = 361\ntrace = [\"coupler.P\", \"rocker.C\"]"),
        "{written}"
    );
    edit(&mut e, r#"{"op": "trace", "marker": "rocker.C", "on": false}"#).unwrap();
    assert_eq!(e.mechanism().sweep.as_ref().unwrap().trace.len(), 1);
    // No frames is not a sweep: check's message, nothing changed.
    let before = e.text();
    let zero = edit(
        &mut e,
        r#"{"op": "set_sweep", "input": "theta", "from": 0, "to": 1, "steps": 0}"#,
    );
    assert!(
        matches!(&zero, Err(EditError::Invalid(w)) if w.contains("sweep.steps")),
        "{zero:?}"
    );
    let unknown = edit(
        &mut e,
        r#"{"op": "set_sweep", "input": "phi", "from": 0, "to": 1, "steps": 2}"#,
    );
    assert!(matches!(unknown, Err(EditError::Refused(_))), "{unknown:?}");
    assert_eq!(e.text(), before);
    edit(&mut e, r#"{"op": "delete_sweep"}"#).unwrap();
    assert!(e.mechanism().sweep.is_none() && !e.text().contains("[sweep]"));
}

#[test]
fn a_sweep_of_several_inputs_is_not_narrowed_to_one() {
    let text = "name = \"two\"\n[bodies.ground]\nfixed = true\nmarkers = { O = [0, 0], D = [3, 0] }\n\
        [bodies.a]\nmarkers = { A = [0, 0], B = [1, 0] }\n[bodies.b]\nmarkers = { A = [3, 0], B = [4, 0] }\n\
        [joints.J1]\nkind = \"revolute\"\nmarkers = [\"ground.O\", \"a.A\"]\n\
        [joints.J2]\nkind = \"revolute\"\nmarkers = [\"ground.D\", \"b.A\"]\n\
        [inputs.p]\nkind = \"angle\"\njoint = \"J1\"\n[inputs.q]\nkind = \"angle\"\njoint = \"J2\"\n\
        [sweep]\nsteps = 3\ninputs = { p = [0, 90], q = [0, -90] }\n";
    let mut e = Editor::new("two.toml", text).unwrap();
    let r = edit(
        &mut e,
        r#"{"op": "set_sweep", "input": "p", "from": 0, "to": 10, "steps": 2}"#,
    );
    assert!(
        matches!(&r, Err(EditError::Refused(w)) if w.contains("several inputs")),
        "{r:?}"
    );
    assert_eq!(e.text(), text);
}

#[test]
fn the_whole_text_is_replaced_checked_and_undone() {
    let mut e = Editor::new("fourbar.toml", FOURBAR).unwrap();
    let renamed = FOURBAR.replace("name = \"fourbar\"", "name = \"typed\"");
    let s = e.set_text(&renamed).unwrap();
    assert!(s.starts_with("the file's text replaced"), "{s}");
    assert_eq!(e.mechanism().name, "typed");
    // A typo: check's message with its place, nothing changed.
    let typo = renamed.replace("[bodies.crank]", "[bodies.crank");
    let why = e.set_text(&typo).unwrap_err().to_string();
    assert!(why.contains("fourbar.toml:"), "{why}");
    assert_eq!(e.text(), renamed);
    assert!(e.undo());
    assert_eq!(e.text(), FOURBAR);
    let same = e.set_text(FOURBAR);
    assert!(matches!(same, Err(EditError::Refused(_))), "{same:?}");
}

#[test]
fn a_new_named_document_is_called_after_its_file() {
    let e = Editor::new_named("new.toml", "new").unwrap();
    assert_eq!(e.mechanism().name, "new");
    assert_eq!(e.mechanism().bodies.len(), 1);
    let mut e = Editor::new("n.toml", &e.text()).unwrap();
    edit(&mut e, r#"{"op": "rename", "name": "other"}"#).unwrap();
    assert!(e.text().starts_with("name = \"other\""), "{}", e.text());
    assert!(edit(&mut e, r#"{"op": "rename", "name": " "}"#).is_err());
}

const EPICYCLIC: &str = include_str!("../../../mechanisms/gears/epicyclic.toml");

#[test]
fn deleting_a_geared_body_or_pivot_removes_the_pairs_that_turn_on_it() {
    // The planet: its pivot P, both pairs it meshes in, the trace of
    // planet.Q; what is left loads (the sun and ring, two inputs).
    let mut e = Editor::new("epicyclic.toml", EPICYCLIC).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_body", "body": "planet"}"#).unwrap();
    assert_eq!(
        s,
        "deleted body planet; also removed joint P, joint sp, joint pr, the trace of planet.Q"
    );
    assert!(e.mechanism().gears.is_empty() && !e.text().contains("[joints.sp]"));
    // The ring's pivot R: the pair pr with it, sp stays.
    let mut e = Editor::new("epicyclic.toml", EPICYCLIC).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_joint", "joint": "R"}"#).unwrap();
    assert_eq!(s, "deleted joint R; also removed joint pr");
    let names: Vec<&str> = e.mechanism().gears.iter().map(|g| g.name.as_str()).collect();
    assert_eq!(names, ["sp"]);
    // A pair by its name, alone.
    let s = edit(&mut e, r#"{"op": "delete_joint", "joint": "sp"}"#).unwrap();
    assert_eq!(s, "deleted joint sp");
    assert!(e.mechanism().gears.is_empty());
    assert_eq!(e.mechanism().joints.len(), 3);
}

#[test]
fn a_geared_file_redrawn_at_a_turned_pose_loads_and_meshes_from_there() {
    // The arm turned 60° with the sun held: redrawn there, the pairs hold
    // as drawn, and the plan of the redrawn file turns the planet as the
    // file's own plan does (c − 2s absolute, counted from the new drawing).
    let mut e = Editor::new("epicyclic.toml", EPICYCLIC).unwrap();
    let plan = analyse(e.mechanism()).plan.unwrap();
    let mut d = Driver::new(Interpreter::new(plan), Options::default());
    assert_eq!(d.frame(&[60.0, -60.0]), FrameStatus::Solved);
    e.redraw(d.poses()).unwrap();
    let p = at(&e, "planet.P");
    assert!(
        (p[0] - 1.5).abs() < 1e-12 && (p[1] - 3f64.sqrt() * 1.5).abs() < 1e-12,
        "{p:?}"
    );
    let m = e.mechanism();
    assert!(
        (m.gears[0].centres[1][0] - 1.5).abs() < 1e-12,
        "{:?}",
        m.gears[0].centres
    );
    let mut r = Driver::new(Interpreter::new(analyse(m).plan.unwrap()), Options::default());
    assert_eq!(r.frame(&[30.0, 10.0]), FrameStatus::Solved);
    assert_eq!(d.frame(&[90.0, -50.0]), FrameStatus::Solved);
    let planet = m.bodies.iter().position(|b| b.name == "planet").unwrap();
    // Redrawn, the planet's drawing is the old pose turned 180°.
    let turned = |rot: dofplan_runtime::planar::Rot| rot.s.atan2(rot.c).to_degrees();
    let (a, b) = (
        turned(r.poses()[planet].rot) + 180.0,
        turned(d.poses()[planet].rot),
    );
    assert!(
        ((a - b + 180.0).rem_euclid(360.0) - 180.0).abs() < 1e-9,
        "{a} against {b}"
    );
}

const QUICK_RETURN: &str = include_str!("../../../mechanisms/slots/quick_return.toml");

#[test]
fn deleting_a_slotted_body_or_the_pins_body_removes_the_slot() {
    // The rocker carries the slot: its pivot O4, the slot S and the trace
    // of rocker.B go with it; what is left loads (the crank on its input).
    let mut e = Editor::new("quick_return.toml", QUICK_RETURN).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_body", "body": "rocker"}"#).unwrap();
    assert_eq!(
        s,
        "deleted body rocker; also removed joint O4, joint S, the trace of rocker.B"
    );
    assert!(e.mechanism().slots.is_empty() && !e.text().contains("[joints.S]"));
    assert_eq!(e.mechanism().inputs.len(), 1);
    // The crank carries the pin: its pivot O2 with the input on it (and the
    // sweep of that input), and the slot.
    let mut e = Editor::new("quick_return.toml", QUICK_RETURN).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_body", "body": "crank"}"#).unwrap();
    assert_eq!(
        s,
        "deleted body crank; also removed joint O2, input theta, the sweep, joint S"
    );
    assert!(e.mechanism().slots.is_empty() && !e.text().contains("[joints.S]"));
    let names: Vec<&str> = e.mechanism().joints.iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["O4"]);
    // The pin's marker alone, and the slot by its name.
    let mut e = Editor::new("quick_return.toml", QUICK_RETURN).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_marker", "marker": "crank.A"}"#).unwrap();
    assert_eq!(s, "deleted marker crank.A; also removed joint S");
    assert!(e.mechanism().slots.is_empty());
    let mut e = Editor::new("quick_return.toml", QUICK_RETURN).unwrap();
    let s = edit(&mut e, r#"{"op": "delete_joint", "joint": "S"}"#).unwrap();
    assert_eq!(s, "deleted joint S");
    assert!(e.mechanism().slots.is_empty());
    assert_eq!(e.mechanism().joints.len(), 2);
}

#[test]
fn a_new_joint_is_not_named_after_a_slot() {
    // A file whose slot is called J1: the next joint is J2, and naming one
    // J1 is refused.
    let text = QUICK_RETURN.replace("[joints.S]", "[joints.J1]");
    let mut e = Editor::new("quick_return.toml", &text).unwrap();
    edit(&mut e, r#"{"op": "add_marker", "body": "rocker", "at": [3, 3]}"#).unwrap();
    edit(&mut e, r#"{"op": "add_marker", "body": "frame", "at": [3, 3]}"#).unwrap();
    assert!(edit(
        &mut e,
        r#"{"op": "join", "a": "frame.A", "b": "rocker.A", "name": "J1"}"#
    )
    .is_err());
    let s = edit(&mut e, r#"{"op": "join", "a": "frame.A", "b": "rocker.A"}"#).unwrap();
    assert!(s.ends_with("revolute joint J2"), "{s}");
}

#[test]
fn a_slotted_file_redrawn_at_a_turned_pose_loads_and_runs_from_there() {
    // The rocker turned with the crank at 90°: redrawn there (the slot's
    // dir turned with it), the file loads (the pin within the ends) and its
    // plan moves the pin along the turned slot as the file's own plan
    // does, from the new drawing.
    let mut e = Editor::new("quick_return.toml", QUICK_RETURN).unwrap();
    let plan = analyse(e.mechanism()).plan.unwrap();
    let mut d = Driver::new(Interpreter::new(plan), Options::default());
    assert_eq!(d.frame(&[90.0]), FrameStatus::Solved);
    e.redraw(d.poses()).unwrap();
    assert_eq!(at(&e, "crank.A").map(|v| (v * 1e12).round() / 1e12), [0.0, 1.0]);
    let m = e.mechanism();
    let rocker = m.bodies.iter().find(|b| b.name == "rocker").unwrap();
    let slot = rocker.markers.iter().find(|k| k.name == "S").unwrap();
    // The slot points from O4 = (0, -2) to the pin at (0, 1): straight up.
    let u = slot.unit_dir().unwrap();
    assert!(u[0].abs() < 1e-12 && (u[1] - 1.0).abs() < 1e-12, "{u:?}");
    let mut r = Driver::new(Interpreter::new(analyse(m).plan.unwrap()), Options::default());
    for theta in [30.0, 150.0, 250.0] {
        assert_eq!(r.frame(&[theta - 90.0]), FrameStatus::Solved, "{theta}");
        assert_eq!(d.frame(&[theta]), FrameStatus::Solved, "{theta}");
        let (a, b) = (
            r.poses()[1].world(at(&e, "crank.A")),
            d.poses()[1].world([1.0, 0.0]),
        );
        assert!(
            (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9,
            "{theta}: {a:?} against {b:?}"
        );
    }
}
