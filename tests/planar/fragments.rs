//! One small mechanism per plan fragment, each checked over a sweep
//! against its own closed form and its joint residuals: the dyads that
//! the bundled files do not already exercise (RPP, PRP), primitive
//! constraints written directly, and what happens when a mechanism is not
//! closed-form.

use dofplan::analysis::analyse;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan::plan::{Plan, StepKind};
use dofplan::simulate::{marker_at, max_relative_residual, run, Frame};
use dofplan_runtime::Options;

fn mechanism(text: &str) -> Mechanism {
    load_str("t.toml", text, Format::Toml).unwrap_or_else(|e| panic!("{e}"))
}

fn plan_of(m: &Mechanism) -> Plan {
    analyse(m).plan.unwrap_or_else(|e| panic!("{e}"))
}

fn sweep(m: &Mechanism, values: impl Iterator<Item = f64>) -> Vec<Frame> {
    let requested: Vec<Vec<f64>> = values.map(|v| vec![v]).collect();
    let frames = run(Interpreter::new(plan_of(m)), Options::default(), &requested);
    for f in &frames {
        assert!(f.status.is_solved(), "{:?} at {:?}", f.status, f.requested);
        assert!(max_relative_residual(m, &f.poses, &f.inputs) <= 1e-12);
    }
    frames
}

fn at(m: &Mechanism, f: &Frame, marker: &str) -> [f64; 2] {
    marker_at(m, &f.poses, m.find_marker(marker).unwrap())
}

/// Scotch yoke: a crank pin drives a block in the yoke's vertical slot
/// and the yoke slides on a horizontal track. The block keeps the ground's
/// rotation through the two prismatic joints (propagation), then the yoke
/// is the intersection of two lines (R-P-P).
const SCOTCH_YOKE: &str = r#"
name = "scotch_yoke"
[bodies.ground]
fixed = true
markers = { O = [0, 0], G = { at = [0, -2], dir = [1, 0] } }
[bodies.crank]
markers = { O = [0, 0], B = [1, 0] }
[bodies.block]
markers = { B = [1, 0], L = { at = [1, 0], dir = [0, 1] } }
[bodies.yoke]
markers = { Y = [1, -1], P = [1, -2] }
[joints.O]
kind = "revolute"
markers = ["ground.O", "crank.O"]
[joints.B]
kind = "revolute"
markers = ["crank.B", "block.B"]
[joints.S]
kind = "prismatic"
markers = ["block.L", "yoke.Y"]
[joints.T]
kind = "prismatic"
markers = ["ground.G", "yoke.P"]
[inputs.theta]
kind = "angle"
joint = "O"
"#;

#[test]
fn scotch_yoke_is_propagation_then_two_lines() {
    let m = mechanism(SCOTCH_YOKE);
    let plan = plan_of(&m);
    assert!(plan
        .steps
        .iter()
        .any(|s| matches!(s.kind, StepKind::LineLine { .. })));
    assert!(
        plan.branches.is_empty(),
        "no root to choose: {}",
        plan.explain_all()
    );
    let frames = sweep(&m, (0..=72).map(|i| f64::from(i) * 5.0));
    for f in &frames {
        let theta = f.requested[0].to_radians();
        let p = at(&m, f, "yoke.P");
        // The yoke follows the crank pin's x exactly: x = r cos θ.
        assert!(
            (p[0] - theta.cos()).abs() < 1e-12 && (p[1] + 2.0).abs() < 1e-12,
            "{p:?}"
        );
    }
}

/// A slide input moves a carriage along x; a runner slides along the
/// carriage's diagonal and a follower along the y axis; runner and follower
/// are pinned together: a P-R-P dyad, line ∩ line.
const CROSS_SLIDE: &str = r#"
name = "cross_slide"
[bodies.ground]
fixed = true
markers = { X = { at = [0, 0], dir = [1, 0] }, Y = { at = [0, 0], dir = [0, 1] } }
[bodies.carriage]
markers = { X = [2, 0], D = { at = [2, 0], dir = [-1, 1] } }
[bodies.runner]
markers = { D = [1, 1], J = [1, 1] }
[bodies.follower]
markers = { Y = [0, 2], J = [1, 1] }
[joints.C]
kind = "prismatic"
markers = ["ground.X", "carriage.X"]
[joints.R]
kind = "prismatic"
markers = ["carriage.D", "runner.D"]
[joints.F]
kind = "prismatic"
markers = ["ground.Y", "follower.Y"]
[joints.J]
kind = "revolute"
markers = ["runner.J", "follower.J"]
[inputs.s]
kind = "slide"
joint = "C"
"#;

#[test]
fn cross_slide_is_a_prp_dyad() {
    let m = mechanism(CROSS_SLIDE);
    let plan = plan_of(&m);
    assert!(
        plan.steps
            .iter()
            .any(|s| matches!(s.kind, StepKind::LineLine { .. })),
        "{}",
        plan.explain_all()
    );
    let frames = sweep(&m, (0..=20).map(|i| -1.0 + f64::from(i) * 0.1));
    for f in &frames {
        let s = f.requested[0];
        // The carriage's diagonal x + y = 2 + s meets the follower, which
        // keeps the joint at x = 1 (it only slides along y): y = 1 + s.
        let j = at(&m, f, "runner.J");
        assert!(
            (j[0] - 1.0).abs() < 1e-12 && (j[1] - (1.0 + s)).abs() < 1e-12,
            "{j:?} at s = {s}"
        );
        assert!((at(&m, f, "carriage.X")[0] - (2.0 + s)).abs() < 1e-12);
    }
}

#[test]
fn primitive_constraints_solve_like_the_joints_they_spell() {
    // slider_crank with its prismatic joint written as in-line + offset.
    let joint_text =
        std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("slider_crank.toml")).unwrap();
    let with_joint = mechanism(&joint_text);
    let p = with_joint
        .joints
        .iter()
        .find(|j| j.kind == dofplan::model::JointKind::Prismatic)
        .unwrap();
    let [a, b] = p.markers;
    let (a, b) = (with_joint.marker_name(a), with_joint.marker_name(b));
    // Drop the prismatic joint's table and write two constraints instead.
    let mut text = String::new();
    let mut skipping = false;
    for line in joint_text.lines() {
        if line.starts_with('[') {
            skipping = line.trim() == format!("[joints.{}]", p.name);
        }
        if !skipping {
            text.push_str(line);
            text.push('\n');
        }
    }
    text.push_str(&format!(
        "[constraints.line]\nkind = \"in-line\"\nmarkers = [\"{a}\", \"{b}\"]\n[constraints.angle]\nkind = \"offset\"\nmarkers = [\"{a}\", \"{b}_dir\"]\n"
    ));
    // The offset relates directions: give the slider marker a direction.
    let (body, marker) = b.split_once('.').unwrap();
    let drawn = with_joint.marker(with_joint.find_marker(&b).unwrap()).at;
    text = text.replacen(
        &format!("[bodies.{body}]\nmarkers = {{ "),
        &format!(
            "[bodies.{body}]\nmarkers = {{ {marker}_dir = {{ at = [{}, {}], dir = [1, 0] }}, ",
            drawn[0], drawn[1]
        ),
        1,
    );
    let with_constraints = mechanism(&text);
    assert_eq!(with_constraints.constraints.len(), 2, "{text}");
    let values: Vec<Vec<f64>> = (0..=36).map(|i| vec![f64::from(i) * 10.0]).collect();
    let a = run(
        Interpreter::new(plan_of(&with_joint)),
        Options::default(),
        &values,
    );
    let b = run(
        Interpreter::new(plan_of(&with_constraints)),
        Options::default(),
        &values,
    );
    for (fa, fb) in a.iter().zip(&b) {
        assert!(fb.status.is_solved());
        assert!(max_relative_residual(&with_constraints, &fb.poses, &fb.inputs) <= 1e-12);
        for name in ["rod.C", "crank.B"] {
            let (pa, pb) = (at(&with_joint, fa, name), at(&with_constraints, fb, name));
            assert!(
                (pa[0] - pb[0]).abs() < 1e-12 && (pa[1] - pb[1]).abs() < 1e-12,
                "{name}"
            );
        }
    }
}

/// A five-bar with one input has two degrees of freedom: after the crank
/// nothing is a dyad, so the rest is a numeric cluster — the coupler links
/// pinned at the crank and the ground keep only their angles (Brunkhart's
/// Chain-4 row: 5 unknowns, 4 equations) and move by minimum-norm steps.
#[test]
fn what_the_closed_form_cannot_place_becomes_a_minimal_cluster() {
    // A five-bar with one input has two degrees of freedom: after the crank
    // nothing is a dyad.
    let text = r#"
name = "fivebar"
[bodies.ground]
fixed = true
markers = { A = [0, 0], E = [4, 0] }
[bodies.crank]
markers = { A = [0, 0], B = [0, 1] }
[bodies.link2]
markers = { B = [0, 1], C = [2, 2] }
[bodies.link3]
markers = { C = [2, 2], D = [4, 1] }
[bodies.link4]
markers = { D = [4, 1], E = [4, 0] }
[joints.A]
kind = "revolute"
markers = ["ground.A", "crank.A"]
[joints.B]
kind = "revolute"
markers = ["crank.B", "link2.B"]
[joints.C]
kind = "revolute"
markers = ["link2.C", "link3.C"]
[joints.D]
kind = "revolute"
markers = ["link3.D", "link4.D"]
[joints.E]
kind = "revolute"
markers = ["link4.E", "ground.E"]
[inputs.theta]
kind = "angle"
joint = "A"
"#;
    let m = mechanism(text);
    let analysis = analyse(&m);
    assert_eq!(analysis.mobility.dof, 2);
    assert_eq!(analysis.mobility.class(), dofplan::analysis::Class::Under);
    let plan = analysis.plan.expect("a mixed plan");
    assert_eq!(plan.clusters(), 1);
    // link3 is hinged on link2 (joint coordinates): joint C holds by
    // construction, and joint D is the cluster's one coincident row.
    assert_eq!(plan.numeric_size(), (3, 2));
    assert!(
        plan.explain_all().contains(
            "link2 (angle about crank.B), link4 (angle about ground.E), link3 (angle about link2.C)"
        ),
        "{}",
        plan.explain_all()
    );
    let frames = sweep(&m, (0..=30).map(|i| f64::from(i) * 2.0));
    for f in &frames {
        assert!(f.numeric.unwrap().iterations <= 10);
    }
}
