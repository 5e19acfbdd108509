//! Bad input of every kind gets an error with `file:line:column` (or the
//! path in a JSON document), the names involved and a hint — never a panic.
//!
//! The TOML texts are small edits of one valid four-bar ([`FOURBAR`]), one
//! line replaced at a time, so every expected position is read off the
//! numbered lines below by hand.

use std::panic::{catch_unwind, AssertUnwindSafe};

use dofplan::analysis::analyse;
use dofplan::interp::Interpreter;
use dofplan::model::{Format, JointKind, Mechanism, ModelError};
use dofplan::simulate::{run, sweep_inputs};
use dofplan::{load_file, load_str};
use dofplan_tests::mechanisms_dir;

/// A valid crank-rocker four-bar, one line per entry (line n is
/// `FOURBAR[n - 1]`).
const FOURBAR: [&str; 31] = [
    /*  1 */ r#"name = "fourbar""#,
    /*  2 */ r#"[bodies.ground]"#,
    /*  3 */ r#"fixed = true"#,
    /*  4 */ r#"markers = { A = [0, 0], D = [4, 0] }"#,
    /*  5 */ r#"[bodies.crank]"#,
    /*  6 */ r#"markers = { A = [0, 0], B = [1, 1] }"#,
    /*  7 */ r#"[bodies.coupler]"#,
    /*  8 */ r#"markers = { B = [1, 1], C = [4.5, 2.5], P = [3, 3.5] }"#,
    /*  9 */ r#"[bodies.rocker]"#,
    /* 10 */ r#"markers = { C = [4.5, 2.5], D = [4, 0] }"#,
    /* 11 */ r#"[joints.A]"#,
    /* 12 */ r#"kind = "revolute""#,
    /* 13 */ r#"markers = ["ground.A", "crank.A"]"#,
    /* 14 */ r#"[joints.B]"#,
    /* 15 */ r#"kind = "revolute""#,
    /* 16 */ r#"markers = ["crank.B", "coupler.B"]"#,
    /* 17 */ r#"[joints.C]"#,
    /* 18 */ r#"kind = "revolute""#,
    /* 19 */ r#"markers = ["coupler.C", "rocker.C"]"#,
    /* 20 */ r#"[joints.D]"#,
    /* 21 */ r#"kind = "revolute""#,
    /* 22 */ r#"markers = ["rocker.D", "ground.D"]"#,
    /* 23 */ r#"[inputs.theta]"#,
    /* 24 */ r#"kind = "angle""#,
    /* 25 */ r#"joint = "A""#,
    /* 26 */ r#"[sweep]"#,
    /* 27 */ r#"input = "theta""#,
    /* 28 */ r#"from = 0.0"#,
    /* 29 */ r#"to = 360.0"#,
    /* 30 */ r#"steps = 361"#,
    /* 31 */ r#"trace = ["coupler.P"]"#,
];

/// The same four-bar as JSON, one line per entry.
const FOURBAR_JSON: [&str; 17] = [
    /*  1 */ r#"{"#,
    /*  2 */ r#"  "name": "fourbar","#,
    /*  3 */ r#"  "bodies": {"#,
    /*  4 */ r#"    "ground": { "fixed": true, "markers": { "A": [0, 0], "D": [4, 0] } },"#,
    /*  5 */ r#"    "crank": { "markers": { "A": [0, 0], "B": [1, 1] } },"#,
    /*  6 */ r#"    "coupler": { "markers": { "B": [1, 1], "C": [4.5, 2.5], "P": [3, 3.5] } },"#,
    /*  7 */ r#"    "rocker": { "markers": { "C": [4.5, 2.5], "D": [4, 0] } }"#,
    /*  8 */ r#"  },"#,
    /*  9 */ r#"  "joints": {"#,
    /* 10 */ r#"    "A": { "kind": "revolute", "markers": ["ground.A", "crank.A"] },"#,
    /* 11 */ r#"    "B": { "kind": "revolute", "markers": ["crank.B", "coupler.B"] },"#,
    /* 12 */ r#"    "C": { "kind": "revolute", "markers": ["coupler.C", "rocker.C"] },"#,
    /* 13 */ r#"    "D": { "kind": "revolute", "markers": ["rocker.D", "ground.D"] }"#,
    /* 14 */ r#"  },"#,
    /* 15 */ r#"  "inputs": { "theta": { "kind": "angle", "joint": "A" } },"#,
    /* 16 */
    r#"  "sweep": { "input": "theta", "from": 0, "to": 360, "steps": 361, "trace": ["coupler.P"] }"#,
    /* 17 */ r#"}"#,
];

/// `base` with the given (1-based) lines replaced; a replacement may hold
/// several lines (only used at the end, so earlier positions stay put).
fn edit(base: &[&str], edits: &[(usize, &str)]) -> String {
    let mut lines: Vec<String> = base.iter().map(|l| l.to_string()).collect();
    for &(n, text) in edits {
        assert!(n >= 1 && n <= lines.len(), "line {n} out of range");
        lines[n - 1] = text.to_string();
    }
    let mut out = lines.join("\n");
    out.push('\n');
    out
}

/// The four-bar TOML with some lines replaced.
fn fourbar(edits: &[(usize, &str)]) -> String {
    edit(&FOURBAR, edits)
}

/// The four-bar JSON with some lines replaced.
fn fourbar_json(edits: &[(usize, &str)]) -> String {
    edit(&FOURBAR_JSON, edits)
}

fn load_toml(text: &str) -> Result<Mechanism, ModelError> {
    load_str("t.toml", text, Format::Toml)
}

fn load_json(text: &str) -> Result<Mechanism, ModelError> {
    load_str("t.json", text, Format::Json)
}

/// The error of a text that must not load.
fn toml_err(text: &str) -> ModelError {
    match load_toml(text) {
        Ok(_) => panic!("loaded, but should not have:\n{text}"),
        Err(e) => e,
    }
}

fn json_err(text: &str) -> ModelError {
    match load_json(text) {
        Ok(_) => panic!("loaded, but should not have:\n{text}"),
        Err(e) => e,
    }
}

/// Asserts that `e` is exactly one error, at `position` (e.g.
/// `t.toml:13:24`), whose text holds every one of `needles`.
fn assert_one(e: &ModelError, position: &str, needles: &[&str]) {
    let shown = e.to_string();
    assert_eq!(
        e.diagnostics.len(),
        1,
        "expected exactly one error, got:\n{shown}"
    );
    let head = format!("{position}: error: ");
    assert!(
        shown.starts_with(&head),
        "expected the error at `{position}`, got:\n{shown}"
    );
    for needle in needles {
        assert!(shown.contains(needle), "expected `{needle}` in:\n{shown}");
    }
}

#[test]
fn the_bases_are_valid() {
    let m = load_toml(&fourbar(&[])).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.name, "fourbar");
    assert_eq!(m.bodies.len(), 4);
    assert_eq!(m.joints.len(), 4);
    assert_eq!(m.inputs.len(), 1);
    let j = load_json(&fourbar_json(&[])).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(j.bodies.len(), 4);
    assert_eq!(j.joints.len(), 4);
    assert_eq!(j.sweep.as_ref().map(|s| s.steps), Some(361));
}

// ---------------------------------------------------------------- syntax

#[test]
fn toml_syntax_error() {
    // Line 3 `fixed = tru`: the bad value starts at column 9.
    let e = toml_err(&fourbar(&[(3, "fixed = tru")]));
    assert_one(&e, "t.toml:3:9", &["TOML syntax error"]);
}

#[test]
fn toml_unterminated_string() {
    // Line 12 `kind = "revolute`: the parser wants the closing `"` at the
    // end of the line, column 17.
    let e = toml_err(&fourbar(&[(12, r#"kind = "revolute"#)]));
    assert_one(
        &e,
        "t.toml:12:17",
        &["TOML syntax error: invalid basic string, expected `\"`"],
    );
}

#[test]
fn json_syntax_error_has_line_and_column() {
    // Line 5 with the comma between the markers left out: serde_json stops
    // at the `"` of "B", column 41.
    let e = json_err(&fourbar_json(&[(
        5,
        r#"    "crank": { "markers": { "A": [0, 0] "B": [1, 1] } },"#,
    )]));
    assert_one(&e, "t.json:5:41", &["JSON syntax error", "expected `,` or `}`"]);
    // The position is given once, not repeated from serde_json's message.
    assert!(!e.to_string().contains("at line"), "{e}");
}

#[test]
fn json_syntax_error_at_the_end_has_a_1_based_column() {
    // The closing `}` left out: the object is still open at the end, the
    // start of line 17 (serde_json says column 0 there).
    let text = fourbar_json(&[]).replace("\n}\n", "\n");
    let e = json_err(&text);
    assert_one(
        &e,
        "t.json:17:1",
        &["JSON syntax error", "EOF while parsing an object"],
    );
    // Cut inside line 2, after `  "name": "four` (15 characters): the string
    // is unterminated, the end is column 16.
    let e = json_err("{\n  \"name\": \"four");
    assert_one(&e, "t.json:2:16", &["EOF while parsing a string"]);
}

#[test]
fn json_syntax_error_column_counts_characters() {
    // Line 2 with a two-byte `é` in the name and a stray `x` after it: the
    // `x` is character 20 of the line (byte 21, which serde_json reports).
    let e = json_err(&fourbar_json(&[(2, r#"  "name": "fourbé" x,"#)]));
    assert_one(&e, "t.json:2:20", &["expected `,` or `}`"]);
}

// ------------------------------------------------------ names and references

#[test]
fn unknown_body() {
    // `"crnk.A"` starts at column 24 of line 13.
    let e = toml_err(&fourbar(&[(13, r#"markers = ["ground.A", "crnk.A"]"#)]));
    assert_one(
        &e,
        "t.toml:13:24",
        &[
            "joint `A`",
            "unknown body `crnk`",
            "`crnk.A`",
            "help: bodies are: ground, crank, coupler, rocker",
        ],
    );
}

#[test]
fn unknown_marker() {
    // `"coupler.Q"` starts at column 23 of line 16.
    let e = toml_err(&fourbar(&[(16, r#"markers = ["crank.B", "coupler.Q"]"#)]));
    assert_one(
        &e,
        "t.toml:16:23",
        &[
            "joint `B`",
            "body `coupler` has no marker `Q`",
            "help: markers of `coupler` are: B, C, P",
        ],
    );
}

#[test]
fn marker_reference_without_a_dot() {
    // `"crankB"` starts at column 12 of line 16.
    let e = toml_err(&fourbar(&[(16, r#"markers = ["crankB", "coupler.B"]"#)]));
    assert_one(
        &e,
        "t.toml:16:12",
        &["joint `B`", "`crankB` is not of the form \"body.marker\""],
    );
}

#[test]
fn unknown_trace_marker() {
    // `"coupler.X"` starts at column 10 of line 31.
    let e = toml_err(&fourbar(&[(31, r#"trace = ["coupler.X"]"#)]));
    assert_one(
        &e,
        "t.toml:31:10",
        &["sweep trace", "body `coupler` has no marker `X`"],
    );
}

#[test]
fn duplicate_body_name_is_a_toml_error() {
    // Line 9 becomes a second `[bodies.crank]` header; TOML itself rejects
    // the duplicate table, pointing at its key `crank` (column 9).
    let e = toml_err(&fourbar(&[(9, "[bodies.crank]")]));
    assert_one(
        &e,
        "t.toml:9:9",
        &[
            "TOML syntax error: duplicate key `crank`",
            "help: a name may be defined only once in a table",
        ],
    );
}

#[test]
fn duplicate_marker_name_is_a_toml_error() {
    // The second `A` of line 6 is at column 25.
    let e = toml_err(&fourbar(&[(6, "markers = { A = [0, 0], A = [1, 1] }")]));
    assert_one(&e, "t.toml:6:25", &["TOML syntax error: duplicate key `A`"]);
}

#[test]
fn duplicate_name_between_a_joint_and_a_constraint() {
    // A constraint `B` appended as lines 31..=34 (line 31 keeps its trace);
    // the key `B` of `[constraints.B]` is at column 14 of line 32, the
    // joint's key `B` of `[joints.B]` at column 9 of line 14.
    let e = toml_err(&fourbar(&[(
        31,
        "trace = [\"coupler.P\"]\n\
         [constraints.B]\n\
         kind = \"coincident\"\n\
         markers = [\"crank.B\", \"coupler.B\"]",
    )]));
    assert_one(
        &e,
        "t.toml:32:14",
        &[
            "duplicate name `B`: a joint already has it",
            "\n  t.toml:14:9: note: the joint is defined here",
            "help: joints and constraints share one namespace; rename one",
        ],
    );
}

#[test]
fn duplicate_names_in_json_are_caught_by_the_validator() {
    // JSON allows repeated keys; line 11 names a second joint `A`.
    let e = json_err(&fourbar_json(&[(
        11,
        r#"    "A": { "kind": "revolute", "markers": ["crank.B", "coupler.B"] },"#,
    )]));
    assert_one(
        &e,
        "t.json (at joints.A)",
        &[
            "duplicate name `A` in `joints`",
            "note: first defined here",
            "help: rename one of them",
        ],
    );
}

#[test]
fn bad_names() {
    // A marker named with a space: the quoted key starts at column 25.
    let e = toml_err(&fourbar(&[
        (6, r#"markers = { A = [0, 0], "B 1" = [1, 1] }"#),
        (16, r#"markers = ["crank.B 1", "coupler.B"]"#),
    ]));
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    assert!(
        e.to_string()
            .starts_with("t.toml:6:25: error: marker name `B 1` must be non-empty, without dots or spaces"),
        "{e}"
    );
}

// ------------------------------------------------------------------ ground

#[test]
fn no_fixed_body() {
    // The error points at the `bodies` table: its key in the first header,
    // `[bodies.ground]`, column 2 of line 2.
    let e = toml_err(&fourbar(&[(3, "fixed = false")]));
    assert_one(
        &e,
        "t.toml:2:2",
        &[
            "no fixed body: a mechanism needs a ground",
            "help: add `fixed = true` to the ground body (e.g. [bodies.ground])",
        ],
    );
}

// ----------------------------------------------------------------- numbers

#[test]
fn nan_coordinate() {
    // `nan` is at column 30 of line 6.
    let e = toml_err(&fourbar(&[(6, "markers = { A = [0, 0], B = [nan, 1] }")]));
    assert_one(
        &e,
        "t.toml:6:30",
        &[
            "`bodies.crank.markers.B[0]` is NaN, not a finite number",
            "help: write a finite number",
        ],
    );
}

#[test]
fn infinite_coordinate() {
    // `inf` is at column 35 of line 8.
    let e = toml_err(&fourbar(&[(
        8,
        "markers = { B = [1, 1], C = [4.5, inf], P = [3, 3.5] }",
    )]));
    assert_one(
        &e,
        "t.toml:8:35",
        &["`bodies.coupler.markers.C[1]` is inf, not a finite number"],
    );
    // And negative infinity in the sweep: `-inf` is at column 8 of line 28.
    let e = toml_err(&fourbar(&[(28, "from = -inf")]));
    assert_one(&e, "t.toml:28:8", &["`sweep.from` is -inf, not a finite number"]);
}

#[test]
fn zero_direction() {
    // The `dir` value of line 4 starts at column 50.
    let e = toml_err(&fourbar(&[(
        4,
        "markers = { A = [0, 0], D = { at = [4, 0], dir = [0, 0] } }",
    )]));
    assert_one(
        &e,
        "t.toml:4:50",
        &[
            "marker `ground.D` has a zero direction",
            "help: a direction needs a non-zero length",
        ],
    );
}

#[test]
fn direction_too_small_to_normalise() {
    // Its squared length underflows to 0: as good as zero.
    let e = toml_err(&fourbar(&[(
        4,
        "markers = { A = [0, 0], D = { at = [4, 0], dir = [1e-200, 0] } }",
    )]));
    assert_one(
        &e,
        "t.toml:4:50",
        &["marker `ground.D` has a direction too short or too long to normalise"],
    );
}

#[test]
fn marker_with_three_coordinates() {
    // `[1, 1, 0]` starts at column 29 of line 6.
    let e = toml_err(&fourbar(&[(6, "markers = { A = [0, 0], B = [1, 1, 0] }")]));
    assert_one(
        &e,
        "t.toml:6:29",
        &[
            "`bodies.crank.markers.B` must have 2 coordinates [x, y], found 3",
            "help: dimension is 2: write [x, y]",
        ],
    );
}

#[test]
fn sweep_steps_must_be_positive() {
    // `0` is at column 9 of line 30.
    let e = toml_err(&fourbar(&[(30, "steps = 0")]));
    assert_one(
        &e,
        "t.toml:30:9",
        &["`sweep.steps` must be a whole number from 1 to 1000000"],
    );
    // A count no sweep could allocate is rejected too, rather than panicking
    // later when the frames are made.
    let e = toml_err(&fourbar(&[(30, "steps = 9223372036854775807")]));
    assert_one(
        &e,
        "t.toml:30:9",
        &["`sweep.steps` must be a whole number from 1 to 1000000"],
    );
    load_toml(&fourbar(&[(30, "steps = 1000000")])).unwrap_or_else(|e| panic!("{e}"));
}

// ------------------------------------------------------------------ joints

#[test]
fn joint_between_markers_of_one_body() {
    // The array of line 19 starts at column 11.
    let e = toml_err(&fourbar(&[(19, r#"markers = ["coupler.C", "coupler.B"]"#)]));
    assert_one(
        &e,
        "t.toml:19:11",
        &[
            "joint `C` joins two markers of the same body `coupler`",
            "help: a joint or constraint connects markers of two different bodies",
        ],
    );
}

#[test]
fn revolute_joint_that_does_not_hold_in_the_drawn_pose() {
    // crank.B is 1e-3 above coupler.B; the error points at `[joints.B]`.
    let e = toml_err(&fourbar(&[(6, "markers = { A = [0, 0], B = [1, 1.001] }")]));
    assert_one(
        &e,
        "t.toml:14:1",
        &[
            "joint `B` does not hold in the drawn pose",
            "crank.B at [1, 1.001]",
            "coupler.B at [1, 1]",
            "1.000e-3 apart",
            "help: markers are world coordinates",
        ],
    );
}

#[test]
fn a_joint_open_in_the_drawing_of_a_mechanism_that_assembles_says_so() {
    // coupler.C drawn 0.01 above rocker.C: the four-bar still assembles, so
    // the error is the drawing's, and the help says where C closes.
    let e = toml_err(&fourbar(&[(
        8,
        "markers = { B = [1, 1], C = [4.5, 2.51], P = [3, 3.5] }",
    )]));
    assert_one(
        &e,
        "t.toml:17:1",
        &[
            "joint `C` does not hold in the drawn pose",
            "1.000e-2 apart",
            "help: markers are world coordinates",
            "the mechanism does assemble with joint C closed (at [",
            "only the drawing is off",
        ],
    );
    // That point is a real assembly: as far from ground.D as the rocker's
    // C is from its D (six decimals shown).
    let shown = e.to_string();
    let at = shown
        .split("closed (at [")
        .nth(1)
        .and_then(|s| s.split(']').next())
        .unwrap();
    let c: Vec<f64> = at.split(", ").map(|v| v.parse().unwrap()).collect();
    let rocker = (0.5f64.powi(2) + 2.5f64.powi(2)).sqrt();
    let from_d = ((c[0] - 4.0).powi(2) + c[1].powi(2)).sqrt();
    assert!(
        (from_d - rocker).abs() < 2e-6,
        "C at {c:?}: {from_d} from D, rocker {rocker}"
    );
}

#[test]
fn the_drawn_pose_tolerance_is_1e_9_relative() {
    // The four-bar's size (diagonal of its markers' box) is sqrt(32.5) =
    // 5.70: a gap of 1e-9 holds, one of 1e-8 does not.
    load_toml(&fourbar(&[(6, "markers = { A = [0, 0], B = [1, 1.000000001] }")]))
        .unwrap_or_else(|e| panic!("{e}"));
    let e = toml_err(&fourbar(&[(6, "markers = { A = [0, 0], B = [1, 1.00000001] }")]));
    assert_one(
        &e,
        "t.toml:14:1",
        &["joint `B`", "1.000e-8 apart", "tolerance 5.7e-9"],
    );
    // Relative: the same 1e-6 gap fails on a 5-unit mechanism and holds on
    // a 5000-unit one.
    let small = "name = \"s\"\n[bodies.ground]\nfixed = true\nmarkers = { O = [0, 0], F = [3, 4] }\n\
                 [bodies.crank]\nmarkers = { O = [0.000001, 0] }\n\
                 [joints.O]\nkind = \"revolute\"\nmarkers = [\"ground.O\", \"crank.O\"]\n";
    let e = toml_err(small);
    assert_one(
        &e,
        "t.toml:7:1",
        &["joint `O`", "1.000e-6 apart", "tolerance 5.0e-9"],
    );
    let big = small.replace("[3, 4]", "[3000, 4000]");
    load_toml(&big).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn prismatic_joint_whose_first_marker_has_no_dir() {
    let e = toml_err(&fourbar(&[(12, r#"kind = "prismatic""#)]));
    assert_one(
        &e,
        "t.toml:11:1",
        &[
            "joint `A`",
            "the first marker of a prismatic joint carries the line",
            "`ground.A` has no direction",
            "help: write it as A = { at = [0, 0], dir = [dx, dy] }",
        ],
    );
}

#[test]
fn prismatic_joint_off_its_line() {
    // ground.A slides along x; crank.A drawn 0.5 above the line.
    let e = toml_err(&fourbar(&[
        (4, "markers = { A = { at = [0, 0], dir = [1, 0] }, D = [4, 0] }"),
        (6, "markers = { A = [0, 0.5], B = [1, 1] }"),
        (12, r#"kind = "prismatic""#),
        (24, r#"kind = "slide""#),
    ]));
    assert_one(
        &e,
        "t.toml:11:1",
        &[
            "joint `A` does not hold in the drawn pose",
            "crank.A is 5.000e-1 off the line of ground.A",
        ],
    );
}

#[test]
fn unknown_joint_kind() {
    // `"hinge"` is at column 8 of line 12.
    let e = toml_err(&fourbar(&[(12, r#"kind = "hinge""#)]));
    assert_one(
        &e,
        "t.toml:12:8",
        &[
            "joint `A`: unknown kind `hinge`",
            "help: expected one of: revolute, prismatic",
        ],
    );
}

// ------------------------------------------------------------------ inputs

#[test]
fn input_on_a_missing_joint() {
    // `"Z"` is at column 9 of line 25.
    let e = toml_err(&fourbar(&[(25, r#"joint = "Z""#)]));
    assert_one(
        &e,
        "t.toml:25:9",
        &[
            "input `theta` drives joint `Z`, which does not exist",
            "help: joints are: A, B, C, D",
        ],
    );
}

#[test]
fn angle_input_on_a_prismatic_joint() {
    // Joint A made prismatic (ground.A gets a dir along x); the input's
    // kind `"angle"` is at column 8 of line 24, the joint at line 11.
    let e = toml_err(&fourbar(&[
        (4, "markers = { A = { at = [0, 0], dir = [1, 0] }, D = [4, 0] }"),
        (12, r#"kind = "prismatic""#),
    ]));
    assert_one(
        &e,
        "t.toml:24:8",
        &[
            "input `theta` is of kind `angle` but joint `A` is prismatic",
            "\n  t.toml:11:1: note: joint `A` is defined here",
            "help: an angle input drives a revolute joint and a slide input a prismatic one; use kind = \"slide\"",
        ],
    );
}

#[test]
fn slide_input_on_a_revolute_joint() {
    let e = toml_err(&fourbar(&[(24, r#"kind = "slide""#)]));
    assert_one(
        &e,
        "t.toml:24:8",
        &[
            "input `theta` is of kind `slide` but joint `A` is revolute",
            "\n  t.toml:11:1: note: joint `A` is defined here",
            "use kind = \"angle\"",
        ],
    );
}

#[test]
fn input_on_a_joint_between_fixed_bodies() {
    // The rocker made fixed too: joint D joins two fixed bodies.
    let e = toml_err(&fourbar(&[
        (10, "markers = { C = [4.5, 2.5], D = [4, 0] }\nfixed = true"),
        (25, r#"joint = "D""#),
    ]));
    // Line 10 became two lines, so the input's joint is on line 26.
    assert_one(
        &e,
        "t.toml:26:9",
        &["input `theta` drives joint `D`, which joins two fixed bodies"],
    );
}

// ------------------------------------------------------------------- sweep

#[test]
fn sweep_of_an_unknown_input() {
    // `"phi"` is at column 9 of line 27.
    let e = toml_err(&fourbar(&[(27, r#"input = "phi""#)]));
    assert_one(
        &e,
        "t.toml:27:9",
        &[
            "the sweep drives input `phi`, which does not exist",
            "help: inputs are: theta",
        ],
    );
}

// ---------------------------------------------------------- keys and types

#[test]
fn unknown_key() {
    // `fixd` at column 1 of line 3. The ground is then not fixed, which is
    // reported too (after).
    let e = toml_err(&fourbar(&[(3, "fixd = true")]));
    let shown = e.to_string();
    assert!(
        shown.starts_with(
            "t.toml:3:1: error: unknown key `fixd` in `bodies.ground`\n  help: expected one of: fixed, markers"
        ),
        "{shown}"
    );
    assert!(shown.contains("no fixed body"), "{shown}");
}

#[test]
fn unknown_top_level_key() {
    let e = toml_err(&fourbar(&[(1, "nme = \"fourbar\"")]));
    let shown = e.to_string();
    assert!(
        shown.starts_with("t.toml:1:1: error: unknown key `nme` in the file"),
        "{shown}"
    );
    assert!(
        shown.contains("help: expected one of: name, dimension, bodies"),
        "{shown}"
    );
    assert!(shown.contains("is missing `name`"), "{shown}");
}

#[test]
fn wrong_type() {
    // `"x"` at column 11 of line 6.
    let e = toml_err(&fourbar(&[(6, r#"markers = "x""#)]));
    assert_one(
        &e,
        "t.toml:6:11",
        &["`bodies.crank.markers` must be a table, found a string"],
    );
    // `fixed = 1`: the value at column 9 of line 3.
    let e = toml_err(&fourbar(&[(3, "fixed = 1")]));
    assert!(
        e.to_string()
            .starts_with("t.toml:3:9: error: `bodies.ground.fixed` must be true or false, found an integer"),
        "{e}"
    );
    // A date where a number belongs: column 21 of line 6.
    let e = toml_err(&fourbar(&[(6, "markers = { A = [0, 1979-05-27], B = [1, 1] }")]));
    assert_one(
        &e,
        "t.toml:6:21",
        &["a date or time is not a valid value", "help: write a number"],
    );
    assert!(!e.to_string().contains("__toml"), "{e}");
}

#[test]
fn joint_markers_not_a_pair() {
    // The array of line 13 at column 11.
    let e = toml_err(&fourbar(&[(13, r#"markers = ["ground.A"]"#)]));
    assert_one(&e, "t.toml:13:11", &["joint `A`: `markers` must be two markers"]);
}

#[test]
fn missing_field() {
    // Joint B without markers: the error points at `[joints.B]`.
    let e = toml_err(&fourbar(&[(16, "")]));
    assert_one(&e, "t.toml:14:1", &["`joints.B` is missing `markers`"]);
}

#[test]
fn the_planar_loader_points_a_spatial_file_to_load_any() {
    // `load_str` reads planar files; a 3D file is for `load_any` (the CLI
    // and build.rs call it), which validates it in 3D: the planar fourbar's
    // 2-coordinate markers are then the error.
    let text = fourbar(&[(1, "name = \"fourbar\"\ndimension = 3")]);
    let e = toml_err(&text);
    assert_one(
        &e,
        "t.toml:2:13",
        &[
            "spatial mechanism (dimension = 3)",
            "help: load it with `dofplan::load_any`",
        ],
    );
    let e = dofplan::load_any_str("t.toml", &text, dofplan::model::Format::Toml)
        .expect_err("2D markers in a 3D file")
        .render(false);
    assert!(e.contains("must have 3 coordinates [x, y, z]"), "{e}");
}

#[test]
fn dimension_other_than_two_or_three_is_refused() {
    let e = toml_err(&fourbar(&[(1, "name = \"fourbar\"\ndimension = 4")]));
    assert_one(&e, "t.toml:2:13", &["`dimension` must be 2 or 3"]);
}

// -------------------------------------------------------------------- JSON

#[test]
fn json_semantic_error_names_the_path() {
    let e = json_err(&fourbar_json(&[(
        10,
        r#"    "A": { "kind": "revolute", "markers": ["ground.A", "crnk.A"] },"#,
    )]));
    assert_one(
        &e,
        "t.json (at joints.A.markers[1])",
        &[
            "joint `A`: unknown body `crnk` in `crnk.A`",
            "help: bodies are: ground, crank, coupler, rocker",
        ],
    );
}

#[test]
fn json_wrong_kind_and_unknown_sweep_input() {
    let e = json_err(&fourbar_json(&[(
        15,
        r#"  "inputs": { "theta": { "kind": "slide", "joint": "A" } },"#,
    )]));
    assert_one(
        &e,
        "t.json (at inputs.theta.kind)",
        &[
            "input `theta` is of kind `slide` but joint `A` is revolute",
            "t.json (at joints.A): note: joint `A` is defined here",
        ],
    );
    let e = json_err(&fourbar_json(&[(
        16,
        r#"  "sweep": { "input": "phi", "from": 0, "to": 360, "steps": 361, "trace": ["coupler.P"] }"#,
    )]));
    assert_one(
        &e,
        "t.json (at sweep.input)",
        &[
            "the sweep drives input `phi`, which does not exist",
            "help: inputs are: theta",
        ],
    );
}

#[test]
fn json_bad_numbers() {
    // JSON has no NaN; a literal out of range is a syntax error with a
    // position (the `1` of `1e999` at column 34 of line 5).
    let e = json_err(&fourbar_json(&[(
        5,
        r#"    "crank": { "markers": { "A": [1e999, 0], "B": [1, 1] } },"#,
    )]));
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    assert!(e.to_string().starts_with("t.json:5:"), "{e}");
    assert!(e.to_string().contains("JSON syntax error"), "{e}");
    // A string where a number belongs.
    let e = json_err(&fourbar_json(&[(
        5,
        r#"    "crank": { "markers": { "A": [0, 0], "B": [1, "1"] } },"#,
    )]));
    assert_one(
        &e,
        "t.json (at bodies.crank.markers.B[1])",
        &["must be a number, found a string"],
    );
    // null where a table belongs.
    let e = json_err(&fourbar_json(&[(15, r#"  "inputs": null,"#)]));
    let shown = e.to_string();
    assert!(
        shown.starts_with("t.json (at inputs): error: `inputs` must be a table, found null"),
        "{shown}"
    );
}

#[test]
fn json_root_must_be_an_object() {
    let e = json_err("[1, 2]");
    assert_one(&e, "t.json (at )", &["must be a table, found an array"]);
}

// -------------------------------------------------------------------- files

#[test]
fn a_file_that_does_not_exist() {
    let path = mechanisms_dir().join("no_such_mechanism.toml");
    let e = load_file(&path).expect_err("the file does not exist");
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    let shown = e.to_string();
    let head = format!("{}: error: cannot read the file: ", path.display());
    assert!(shown.starts_with(&head), "{shown}");
    assert!(shown.contains("no_such_mechanism.toml"), "{shown}");
    assert!(shown.contains("help: check the path"), "{shown}");
}

#[test]
fn a_file_with_a_syntax_error_names_the_file() {
    let dir = std::env::temp_dir().join(format!("dofplan-bad-input-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("broken.toml");
    std::fs::write(&path, fourbar(&[(3, "fixed = tru")])).unwrap();
    let e = load_file(&path).expect_err("syntax error");
    let _ = std::fs::remove_dir_all(&dir);
    let head = format!("{}:3:9: error: TOML syntax error", path.display());
    assert!(e.to_string().starts_with(&head), "{e}");
}

#[test]
fn an_empty_file_says_so() {
    for (text, message) in [
        ("", "the file is empty"),
        ("\n  \n", "the file is empty (only white space)"),
    ] {
        for (e, head) in [(toml_err(text), "t.toml"), (json_err(text), "t.json")] {
            assert_one(&e, head, &[message, "needs a `name`, `bodies`", "`joints`"]);
        }
    }
    let e = toml_err("# a comment\n\n# and another\n");
    assert_one(
        &e,
        "t.toml",
        &[
            "the file defines nothing (it has only comments)",
            "needs a `name`",
        ],
    );
    let e = json_err("{ }");
    assert_one(&e, "t.json", &["the file defines nothing (an empty object)"]);
    // From disk, the error names the file.
    let dir = std::env::temp_dir().join(format!("dofplan-bad-input-empty-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("empty.toml");
    std::fs::write(&path, "").unwrap();
    let e = load_file(&path).expect_err("an empty file");
    let _ = std::fs::remove_dir_all(&dir);
    assert_one(&e, &path.display().to_string(), &["the file is empty"]);
}

#[test]
fn a_binary_file_is_not_utf8_text() {
    // Two good lines, then a byte that starts no UTF-8 character: line 3,
    // after `ab` (column 3), byte offset 24.
    let dir = std::env::temp_dir().join(format!("dofplan-bad-input-binary-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("image.toml");
    let mut bytes = b"name = \"x\"\n[bodies.g]\nab".to_vec();
    bytes.extend([0xff, 0xd8, 0x00, 0x10]);
    std::fs::write(&path, &bytes).unwrap();
    let e = load_file(&path).expect_err("not text");
    let _ = std::fs::remove_dir_all(&dir);
    assert_one(
        &e,
        &format!("{}:3:3", path.display()),
        &[
            "the file is not UTF-8 text: byte 0xff at offset 24",
            "help: mechanism files are TOML or JSON text in UTF-8",
        ],
    );
    assert!(!e.to_string().contains("check the path"), "{e}");
    // A NUL is valid UTF-8 but no text file has one; here at the start of
    // line 2.
    let dir = std::env::temp_dir().join(format!("dofplan-bad-input-nul-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("program.toml");
    std::fs::write(&path, b"\x7fELF\n\x00\x00\x01").unwrap();
    let e = load_file(&path).expect_err("not text");
    let _ = std::fs::remove_dir_all(&dir);
    assert_one(
        &e,
        &format!("{}:2:1", path.display()),
        &["the file is not UTF-8 text: byte 0x00 at offset 5 is not valid UTF-8 text"],
    );
}

// -------------------------------------------------------------- valid forms

#[test]
fn integers_and_floats_mix() {
    let m = load_toml(&fourbar(&[
        (4, "markers = { A = [0.0, 0], D = [4, 0.0] }"),
        (6, "markers = { A = [0, 0.0], B = [1.0, 1] }"),
        (28, "from = 0"),
        (29, "to = 360"),
    ]))
    .unwrap_or_else(|e| panic!("{e}"));
    let ground = &m.bodies[0];
    assert_eq!(ground.markers[1].at, [4.0, 0.0]);
    let sweep = m.sweep.as_ref().unwrap();
    assert_eq!((sweep.primary().from, sweep.primary().to), (0.0, 360.0));
}

#[test]
fn marker_tables_with_a_direction() {
    // Joint A made prismatic along the ground's x axis, driven by a slide.
    let m = load_toml(&fourbar(&[
        (4, "markers = { A = { at = [0, 0], dir = [2, 0] }, D = [4, 0] }"),
        (12, r#"kind = "prismatic""#),
        (24, r#"kind = "slide""#),
    ]))
    .unwrap_or_else(|e| panic!("{e}"));
    let a = &m.bodies[0].markers[0];
    assert_eq!(a.name, "A");
    assert_eq!(a.at, [0.0, 0.0]);
    assert_eq!(a.dir, Some([2.0, 0.0]));
    assert_eq!(a.unit_dir(), Some([1.0, 0.0]));
    assert_eq!(m.joints[0].kind, JointKind::Prismatic);
    // A marker table without dir is a plain point.
    let m = load_toml(&fourbar(&[(6, "markers = { A = { at = [0, 0] }, B = [1, 1] }")]))
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.bodies[1].markers[0].dir, None);
    // The bundled slider-crank uses one too.
    let m = load_file(&mechanisms_dir().join("slider_crank.toml")).unwrap_or_else(|e| panic!("{e}"));
    assert!(m.bodies[0].markers.iter().any(|mk| mk.dir == Some([1.0, 0.0])));
}

// ------------------------------------------------------------ never panics

/// Loads `text`; if it loads, analyses it and runs a short sweep of its
/// plan. Returns a description of a panic, if any.
fn exercise(label: &str, text: &str, format: Format) -> Result<Reached, String> {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let file = if format == Format::Json {
            "t.json"
        } else {
            "t.toml"
        };
        let m = match load_str(file, text, format) {
            Ok(m) => m,
            Err(e) => {
                // Every error can be shown, and has at least one diagnostic.
                assert!(!e.diagnostics.is_empty(), "an error without diagnostics");
                let _ = e.to_string();
                return Reached::Rejected;
            }
        };
        let analysis = analyse(&m);
        let Ok(plan) = analysis.plan else {
            return Reached::Loaded;
        };
        // The whole sweep's inputs (bounded by validation), then 5 frames.
        let _ = sweep_inputs(&m, None);
        let requested = sweep_inputs(&m, Some(5));
        let _ = run(Interpreter::new(plan), Default::default(), &requested);
        Reached::Simulated
    }));
    outcome.map_err(|p| {
        let what = p
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_default();
        format!("{label}: {what}\n--- text ---\n{text}\n------------")
    })
}

/// How far [`exercise`] got with a text.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Reached {
    /// The loader rejected it.
    Rejected,
    /// It loaded and was analysed, without a plan.
    Loaded,
    /// It was planned and simulated.
    Simulated,
}

/// Byte ranges of number literals (and `nan`/`inf`-free digits runs).
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = (bytes[i].is_ascii_digit() || bytes[i] == b'-')
            && (i == 0
                || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'.' || bytes[i - 1] == b'_'));
        if starts {
            let mut j = i + 1;
            while j < bytes.len() && (bytes[j].is_ascii_digit() || bytes[j] == b'.' || bytes[j] == b'e') {
                j += 1;
            }
            if bytes[i..j].iter().any(u8::is_ascii_digit) {
                spans.push((i, j));
            }
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

/// Byte ranges of string literals (with their quotes).
fn string_spans(text: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut open = None;
    for (i, c) in text.char_indices() {
        if c == '"' {
            match open.take() {
                None => open = Some(i),
                Some(s) => spans.push((s, i + 1)),
            }
        }
    }
    spans
}

fn mutations(text: &str, json: bool) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let lines: Vec<&str> = text.lines().collect();
    for i in 0..lines.len() {
        let mut l = lines.clone();
        l.remove(i);
        out.push((format!("without line {}", i + 1), l.join("\n")));
    }
    for cut in (0..text.len()).step_by(7) {
        if text.is_char_boundary(cut) {
            out.push((format!("truncated at {cut}"), text[..cut].to_string()));
        }
    }
    let number_subs: &[&str] = if json {
        &[
            "\"s\"", "[]", "{}", "null", "true", "1e300", "-1e300", "1e-300", "0", "-0.0", "3", "-1",
            "1e-200",
        ]
    } else {
        &[
            "nan",
            "inf",
            "-inf",
            "\"s\"",
            "[]",
            "{}",
            "true",
            "1e300",
            "-1e300",
            "1e-300",
            "0",
            "-0.0",
            "3",
            "-1",
            "1e-200",
            "1979-05-27",
            "9223372036854775807",
        ]
    };
    for (s, e) in number_spans(text) {
        for sub in number_subs {
            out.push((
                format!("number `{}` at {s} -> {sub}", &text[s..e]),
                format!("{}{sub}{}", &text[..s], &text[e..]),
            ));
        }
    }
    let string_subs: &[&str] = &[
        "\"\"",
        "\".\"",
        "\"x.y\"",
        "\"ground.A\"",
        "\"A\"",
        "1",
        "[]",
        "{}",
    ];
    for (s, e) in string_spans(text) {
        for sub in string_subs {
            out.push((
                format!("string `{}` at {s} -> {sub}", &text[s..e]),
                format!("{}{sub}{}", &text[..s], &text[e..]),
            ));
        }
    }
    out
}

#[test]
fn never_panics() {
    let slider_crank = std::fs::read_to_string(mechanisms_dir().join("slider_crank.toml")).unwrap();
    let prismatic = fourbar(&[
        (4, "markers = { A = { at = [0, 0], dir = [1, 0] }, D = [4, 0] }"),
        (12, r#"kind = "prismatic""#),
        (24, r#"kind = "slide""#),
    ]);
    let bases: Vec<(&str, String, Format)> = vec![
        ("fourbar", fourbar(&[]), Format::Toml),
        ("fourbar prismatic", prismatic, Format::Toml),
        ("slider_crank.toml", slider_crank, Format::Toml),
        ("fourbar json", fourbar_json(&[]), Format::Json),
    ];
    let mut panics = Vec::new();
    let mut tried = 0;
    let mut reached = std::collections::HashMap::new();
    for (name, text, format) in &bases {
        assert_eq!(
            exercise(name, text, *format),
            Ok(Reached::Simulated),
            "{name} base"
        );
        for (label, mutated) in mutations(text, *format == Format::Json) {
            tried += 1;
            match exercise(&format!("{name}, {label}"), &mutated, *format) {
                Ok(r) => *reached.entry(r).or_insert(0) += 1,
                Err(p) => panics.push(p),
            }
        }
    }
    assert!(tried > 1000, "only {tried} mutations");
    // The mutations reach every stage, not just the loader's errors. (No
    // single mutation of these files loads without a plan: the ones that did
    // put a marker at ±1e300, where the plan failed with an internal error;
    // the loader now rejects coordinates that far out.)
    for stage in [Reached::Rejected, Reached::Simulated] {
        assert!(
            reached.get(&stage).copied().unwrap_or(0) > 10,
            "few mutations reach {stage:?}: {reached:?}"
        );
    }
    assert!(
        panics.is_empty(),
        "{} of {tried} mutations panic:\n{}",
        panics.len(),
        panics.join("\n")
    );
}

#[test]
fn garbage_never_panics() {
    for text in [
        "", "\n", "=", "[", "[[bodies]]", "name = 1", "bodies = []", "bodies = 3", "joints = 1\nbodies = {}",
        "name = \"x\"\n[bodies.a]\n[bodies.b]\nfixed = true\nmarkers = {}\n",
        "name = \"x\"\n[bodies]\n\"\" = { fixed = true, markers = { \"\" = [0, 0] } }\n",
        "name = \"x\"\nsweep = { input = 1 }\n[bodies.g]\nfixed = true\nmarkers = { O = [0, 0] }\n",
        "name = \"x\"\n[bodies.g]\nfixed = true\nmarkers = { O = [0, 0] }\n[inputs.i]\nkind = \"angle\"\njoint = \"j\"\n",
    ] {
        if let Err(p) = exercise("toml garbage", text, Format::Toml) {
            panic!("{p}");
        }
    }
    for text in [
        "",
        "{",
        "null",
        "[]",
        "1",
        "\"s\"",
        "{\"name\": {}}",
        "{} {}",
        "{\"bodies\": {\"a\": null}}",
    ] {
        if let Err(p) = exercise("json garbage", text, Format::Json) {
            panic!("{p}");
        }
        assert!(load_json(text).is_err(), "{text:?}");
    }
}
