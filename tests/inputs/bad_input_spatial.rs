//! Every rule of spatial files gets its own error, at its place
//! (file:line:column) and with the names involved — one test per rule.

use dofplan::load_any_str;
use dofplan::model::{Format, Model};

/// A valid spatial file: a crank on a revolute joint, a rod on a
/// spherical one, a slider on a cylindrical one, all holding as drawn.
const BASE: &str = r#"name = "base"
dimension = 3
[bodies.ground]
fixed = true
markers.A = { at = [0, 0, 0], z = [0, 0, 1] }
markers.L = { at = [5, 0, 0], z = [1, 0, 0] }
[bodies.crank]
markers.A = { at = [0, 0, 0], z = [0, 0, 1] }
markers.B = { at = [1, 0, 0], z = [0, 1, 0] }
[bodies.rod]
markers.B = [1, 0, 0]
markers.C = [5, 0, 0]
[bodies.slider]
markers.C = [5, 0, 0]
markers.L = { at = [5, 0, 0], z = [1, 0, 0] }
[joints.A]
kind = "revolute"
markers = ["ground.A", "crank.A"]
[joints.B]
kind = "spherical"
markers = ["crank.B", "rod.B"]
[joints.C]
kind = "spherical"
markers = ["rod.C", "slider.C"]
[joints.L]
kind = "cylindrical"
markers = ["ground.L", "slider.L"]
[inputs.theta]
kind = "angle"
joint = "A"
"#;

/// The file with `from` replaced by `to` (which must occur once).
fn with(from: &str, to: &str) -> String {
    assert_eq!(BASE.matches(from).count(), 1, "`{from}` occurs once");
    BASE.replace(from, to)
}

/// The errors of a file that must not load, rendered without colour.
fn errors(text: &str) -> String {
    match load_any_str("t.toml", text, Format::Toml) {
        Err(e) => e.render(false),
        Ok(_) => panic!("loaded, but should not have:\n{text}"),
    }
}

/// Asserts an error on the (first) line of `text` that contains `at`,
/// mentioning every needle.
fn check(text: &str, at: &str, needles: &[&str]) {
    let line = 1 + text
        .lines()
        .position(|l| l.contains(at))
        .unwrap_or_else(|| panic!("no line with `{at}`"));
    let e = errors(text);
    assert!(
        e.contains(&format!("t.toml:{line}:")),
        "expected line {line}:\n{e}"
    );
    for n in needles {
        assert!(e.contains(n), "expected `{n}` in:\n{e}");
    }
}

#[test]
fn the_base_file_is_valid() {
    let Ok(Model::Spatial(m)) = load_any_str("t.toml", BASE, Format::Toml) else {
        panic!("the base file loads");
    };
    assert_eq!(m.joints.len(), 4);
}

#[test]
fn a_point_has_three_coordinates() {
    check(
        &with(
            "markers.C = [5, 0, 0]\n[bodies.slider]",
            "markers.C = [5, 0]\n[bodies.slider]",
        ),
        "markers.C = [5, 0]",
        &[
            "`bodies.rod.markers.C` must have 3 coordinates [x, y, z], found 2",
            "dimension is 3",
        ],
    );
}

#[test]
fn an_axis_is_not_zero() {
    check(
        &with(
            "markers.L = { at = [5, 0, 0], z = [1, 0, 0] }\n[bodies.crank]",
            "markers.L = { at = [5, 0, 0], z = [0, 0, 0] }\n[bodies.crank]",
        ),
        "z = [0, 0, 0]",
        &["marker `ground.L` has a zero z axis"],
    );
}

#[test]
fn x_must_be_perpendicular_to_z() {
    check(
        &with(
            "markers.B = { at = [1, 0, 0], z = [0, 1, 0] }",
            "markers.B = { at = [1, 0, 0], z = [0, 1, 0], x = [1, 1, 0] }",
        ),
        "x = [1, 1, 0]",
        &[
            "marker `crank.B`: x is not perpendicular to z (angle 45.0000°)",
            "the nearest perpendicular x is [1, 0, 0]",
        ],
    );
}

#[test]
fn x_needs_a_z() {
    check(
        &with(
            "markers.B = [1, 0, 0]\nmarkers.C",
            "markers.B = { at = [1, 0, 0], x = [1, 0, 0] }\nmarkers.C",
        ),
        "x = [1, 0, 0] }",
        &["marker `rod.B` has an x axis but no z"],
    );
}

#[test]
fn a_spatial_marker_has_no_dir() {
    check(
        &with(
            "markers.B = [1, 0, 0]\nmarkers.C",
            "markers.B = { at = [1, 0, 0], dir = [1, 0, 0] }\nmarkers.C",
        ),
        "dir =",
        &["in 3D a marker has `z` (and `x`) instead of `dir`"],
    );
}

#[test]
fn an_axial_joint_needs_its_first_markers_z() {
    check(
        &with(
            "markers.A = { at = [0, 0, 0], z = [0, 0, 1] }\nmarkers.L",
            "markers.A = [0, 0, 0]\nmarkers.L",
        ),
        "[joints.A]",
        &["joint `A`: the first marker of a revolute joint carries its axis, but `ground.A` has no z"],
    );
}

#[test]
fn a_joints_axes_are_parallel_as_drawn() {
    check(
        &with(
            "markers.A = { at = [0, 0, 0], z = [0, 0, 1] }\nmarkers.B",
            "markers.A = { at = [0, 0, 0], z = [0, 1, 1] }\nmarkers.B",
        ),
        "[joints.A]",
        &["joint `A`: the axes of `ground.A` and `crank.A` are 45.0000° apart, not parallel as drawn"],
    );
}

#[test]
fn a_universal_joint_has_two_perpendicular_crosspins() {
    let text = with(
        "kind = \"spherical\"\nmarkers = [\"crank.B\"",
        "kind = \"universal\"\nmarkers = [\"crank.B\"",
    );
    check(
        &text,
        "[joints.B]",
        &["a universal joint's markers carry its two crosspin axes, but `rod.B` has no z"],
    );
    let text = text.replace(
        "markers.B = [1, 0, 0]",
        "markers.B = { at = [1, 0, 0], z = [0, 1, 1] }",
    );
    check(
        &text,
        "[joints.B]",
        &["the crosspin axes of `crank.B` and `rod.B` are at 45.0000°, not perpendicular as drawn"],
    );
}

#[test]
fn a_joint_holds_in_the_drawn_pose() {
    check(
        &with(
            "markers.C = [5, 0, 0]\n[bodies.slider]",
            "markers.C = [5, 0.5, 0]\n[bodies.slider]",
        ),
        "[joints.C]",
        &["joint `C` does not hold in the drawn pose (coincident): rod.C and slider.C are 5.000e-1 apart"],
    );
}

#[test]
fn an_input_fits_its_joint() {
    let text = format!("{BASE}[inputs.tilt]\nkind = \"angle\" # tilt\njoint = \"B\"\n");
    check(
        &text,
        "# tilt",
        &[
            "input `tilt` is of kind `angle` but joint `B` is spherical",
            "joint `B` has 3 freedoms; an input needs a 1-DOF joint or a cylindrical joint",
        ],
    );
    let text = format!("{BASE}[inputs.push]\nkind = \"slide\" # push\njoint = \"A\"\n");
    check(
        &text,
        "# push",
        &[
            "input `push` is of kind `slide` but joint `A` is revolute",
            "use kind = \"angle\"",
        ],
    );
}

#[test]
fn helical_joints_need_a_pitch_and_others_take_none() {
    let helical = with("kind = \"cylindrical\"", "kind = \"helical\"");
    check(&helical, "[joints.L]", &["`joints.L` is missing `pitch`"]);
    check(
        &helical.replace("kind = \"helical\"", "kind = \"helical\"\npitch = 0"),
        "pitch = 0",
        &["joint `L`: `pitch` must not be 0"],
    );
    check(
        &with("kind = \"cylindrical\"", "kind = \"cylindrical\"\npitch = 2"),
        "pitch = 2",
        &["joint `L`: only a helical joint has a `pitch`"],
    );
}

#[test]
fn offset_z_takes_an_angle_strictly_between_0_and_180() {
    let text = format!(
        "{BASE}[constraints.K]\nkind = \"offset-z\"\nmarkers = [\"ground.L\", \"crank.B\"]\nangle = 180\n"
    );
    check(
        &text,
        "angle = 180",
        &[
            "offset-z takes an angle strictly between 0° and 180°, not 180",
            "use parallel-z",
        ],
    );
}

#[test]
fn only_offsets_take_an_angle() {
    let text = format!(
        "{BASE}[constraints.K]\nkind = \"parallel-z\"\nmarkers = [\"ground.L\", \"slider.L\"]\nangle = 10\n"
    );
    check(
        &text,
        "angle = 10",
        &["constraint `K`: only offset-z and offset-x take an `angle`"],
    );
}

#[test]
fn a_constraints_angle_holds_as_drawn() {
    // ground.L's z is x, crank.B's z is y: 90° apart as drawn, not 60°.
    let text = format!(
        "{BASE}[constraints.K]\nkind = \"offset-z\"\nmarkers = [\"ground.L\", \"crank.B\"]\nangle = 60\n"
    );
    check(
        &text,
        "[constraints.K]",
        &["constraint `K` does not hold in the drawn pose (offset-z)"],
    );
}

#[test]
fn a_primitive_on_directions_needs_both_z() {
    let text = format!("{BASE}[constraints.K]\nkind = \"parallel-z\"\nmarkers = [\"ground.L\", \"rod.C\"]\n");
    check(
        &text,
        "[constraints.K]",
        &["constraint `K`: parallel-z needs the second marker's z, but `rod.C` has none"],
    );
}

#[test]
fn a_sweep_has_one_form() {
    let text = format!(
        "{BASE}[sweep]\nsteps = 3\ninput = \"theta\"\nfrom = 0\nto = 1\ninputs = {{ theta = [0, 1] }}\n"
    );
    check(
        &text,
        "input = \"theta\"",
        &["`sweep.input` cannot stand beside `sweep.inputs`"],
    );
    let text = format!("{BASE}[sweep]\nsteps = 3\ninputs = {{ phi = [0, 1] }}\n");
    check(
        &text,
        "phi = [0, 1]",
        &[
            "the sweep drives input `phi`, which does not exist",
            "inputs are: theta",
        ],
    );
}

#[test]
fn an_open_joint_is_told_from_joints_in_conflict() {
    // rod.C drawn 0.01 off slider.C: the mechanism closes nearby, the
    // crank held as drawn, so C slides to 1 + |BC| = 1 + √16.0001 =
    // 5.0000125 on the slider's axis.
    let off = with(
        "markers.C = [5, 0, 0]\n[bodies.slider]",
        "markers.C = [5, 0.01, 0]\n[bodies.slider]",
    );
    check(
        &off,
        "[joints.C]",
        &[
            "joint `C` does not hold in the drawn pose",
            "the mechanism does assemble with joint C closed at [5.000012, 0, 0]",
            "rod.C moves from [5, 0.01, 0] to [5.000012, 0, 0]",
            "only the drawing is off",
        ],
    );
    // The crank's pin (1 from its pivot) held at ground.L (5 away): no pose
    // closes both.
    let conflict =
        format!("{BASE}[constraints.K]\nkind = \"coincident\"\nmarkers = [\"ground.L\", \"crank.B\"]\n");
    check(
        &conflict,
        "[constraints.K]",
        &[
            "constraint `K` does not hold in the drawn pose",
            "joint A, constraint K are in conflict: no pose near the drawn one closes them all",
            "constraint K open by",
        ],
    );
}
