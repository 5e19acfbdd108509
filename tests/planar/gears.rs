//! Gear pairs and rack and pinion, the higher pairs of the plane, end to
//! end on the files of `mechanisms/gears/`.
//!
//! What is compared against what:
//! - the epicyclic train's arm, sun, planet and ring rotations and the
//!   planet's pivot and rim point, solved by the plan interpreter, against
//!   Willis' formula written here from the pitch radii (fresh solves on a
//!   grid of both inputs, and continuous runs with the sun, the ring or
//!   nothing held still against the textbook ratios of each case), and its
//!   angular velocities and accelerations from the plan's jets against the
//!   same formula differentiated;
//! - the geared five-bar's crank tips and coupler pin against the gear
//!   ratio and a circle–circle intersection computed here, frame by frame
//!   along its bundled sweep;
//! - the rack's slide (and its rates) against the rolling of the pinion's
//!   pitch point on the rack's pitch line;
//! - Grübler's count (a gear or rack and pinion is one equation), the plans
//!   (closed form, no numeric cluster), and the load errors of a gear drawn
//!   with the wrong centre distance, without a common pivot body, or with
//!   an unknown mesh.
//!
//! Every expected value is derived from the drawing: marker positions from
//! the loaded mechanism, pitch radii read from the file's text (not through
//! the loader, whose reading is under test) and checked against the drawn
//! centre distances. Nothing is copied from solver output.
//!
//! Sign conventions (those of the file format): angles counter-clockwise,
//! in degrees for inputs, every rotation relative to the drawn pose. Gears:
//! with φA, φB the rotations of A and B relative to their common carrier,
//! an external mesh rolls as rA·ΔφA = −rB·ΔφB, an internal one as
//! rA·ΔφA = +rB·ΔφB. The gear files are in `mechanisms/gears/`, which
//! `dofplan-generated` does not compile, so only the interpreter runs them.

use std::f64::consts::PI;

use dofplan::analysis::planar::Mobility;
use dofplan::interp::Interpreter;
use dofplan::model::{Format, Mechanism};
use dofplan::simulate::{marker_at, max_relative_residual, run, sweep_inputs, Frame};
use dofplan::{load_file, load_str};
use dofplan_runtime::planar::Pose;
use dofplan_runtime::real::Jet2;
use dofplan_runtime::{Ctx, Driver, FrameStatus, Options, Solver};
use dofplan_tests::vec2::{add, cross, dist, perp, rotate, scale, sub, unit, P};
use dofplan_tests::{mechanisms_dir, plan};

/// Tolerance of every closed-form comparison (absolute: lengths in the
/// mechanisms' units, which are a few units across, and cos/sin entries).
const TOL: f64 = 1e-9;

/// Loads `mechanisms/gears/{name}.toml`, with the file's text.
fn gear_file(name: &str) -> (Mechanism, String) {
    let path = mechanisms_dir().join("gears").join(format!("{name}.toml"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let m = load_file(&path).unwrap_or_else(|e| panic!("{e}"));
    (m, text)
}

/// The numbers written as `key = x` or `key = [x, y]` in the table
/// `[joints.{joint}]` of a mechanism file's text: the pitch radii as
/// written, read by hand so that the expected values do not depend on the
/// loader.
fn joint_numbers(text: &str, joint: &str, key: &str) -> Vec<f64> {
    let header = format!("[joints.{joint}]");
    let value = text
        .lines()
        .skip_while(|l| l.trim() != header)
        .skip(1)
        .take_while(|l| !l.trim_start().starts_with('['))
        .find_map(|l| {
            let (k, v) = l.split('#').next()?.split_once('=')?;
            (k.trim() == key).then(|| v.trim().to_string())
        })
        .unwrap_or_else(|| panic!("no `{key}` in {header}"));
    value
        .trim_start_matches('[')
        .trim_end_matches(']')
        .split(',')
        .map(|x| {
            x.trim()
                .parse()
                .unwrap_or_else(|e| panic!("{header} {key}: {x}: {e}"))
        })
        .collect()
}

/// The two pitch radii of the gear `joint`, in body order.
fn radii(text: &str, joint: &str) -> [f64; 2] {
    match joint_numbers(text, joint, "radii")[..] {
        [a, b] => [a, b],
        ref other => panic!("{joint}: radii {other:?}"),
    }
}

/// Drawn (= local) position of the marker "body.marker".
fn drawn(m: &Mechanism, name: &str) -> P {
    let id = m
        .find_marker(name)
        .unwrap_or_else(|| panic!("{}: no marker {name}", m.name));
    m.marker(id).at
}

/// World position of the marker "body.marker" at `poses`.
fn at(m: &Mechanism, poses: &[Pose], name: &str) -> P {
    marker_at(m, poses, m.find_marker(name).unwrap())
}

/// Index of the body `name`.
fn body(m: &Mechanism, name: &str) -> usize {
    m.bodies
        .iter()
        .position(|b| b.name == name)
        .unwrap_or_else(|| panic!("{}: no body {name}", m.name))
}

/// Index of the input `name`.
fn input(m: &Mechanism, name: &str) -> usize {
    m.inputs
        .iter()
        .position(|i| i.name == name)
        .unwrap_or_else(|| panic!("{}: no input {name}", m.name))
}

/// How far a pose's rotation is from a turn of `degrees` counter-clockwise
/// from the drawn pose: the larger gap of its cos and sin. The angle is
/// reduced modulo 360 first (exactly), so that many turns cost no digits.
fn rot_gap(pose: &Pose, degrees: f64) -> f64 {
    let a = (degrees % 360.0).to_radians();
    (pose.rot.c - a.cos()).abs().max((pose.rot.s - a.sin()).abs())
}

/// `v` turned by `degrees` counter-clockwise (reduced modulo 360 first).
fn turn(v: P, degrees: f64) -> P {
    rotate(v, (degrees % 360.0).to_radians())
}

/// Asserts `err ≤ TOL` and returns it (for the running maximum).
fn check(err: f64, what: impl FnOnce() -> String) -> f64 {
    assert!(err <= TOL, "{}: off by {err:e}", what());
    err
}

/// Asserts a frame solved exactly as requested and holds its joints, gear
/// pairs and inputs (`max_relative_residual` checks them from the model;
/// each test's closed form checks the gear relations again).
fn assert_solved(m: &Mechanism, f: &Frame, what: &str) {
    assert_eq!(f.status, FrameStatus::Solved, "{what}: {:?}", f.requested);
    assert_eq!(f.inputs, f.requested, "{what}");
    let r = max_relative_residual(m, &f.poses, &f.inputs);
    assert!(r <= TOL, "{what} at {:?}: relative residual {r:e}", f.inputs);
}

/// A body's angular velocity and acceleration from its rotation's jets:
/// for a unit (c, s), ω = c·ṡ − s·ċ and α = c·s̈ − s·c̈.
fn omega_alpha(p: &Pose<Jet2>) -> (f64, f64) {
    let (c, s) = (p.rot.c, p.rot.s);
    (c.v * s.d - s.v * c.d, c.v * s.dd - s.v * c.dd)
}

/// The epicyclic train's drawing: the common centre O, the planet's pivot
/// and rim point as drawn, and the pitch radii.
struct Epicyclic {
    m: Mechanism,
    o: P,
    p0: P,
    q0: P,
    rs: f64,
    rp: f64,
    rr: f64,
}

impl Epicyclic {
    fn new() -> Epicyclic {
        let (m, text) = gear_file("epicyclic");
        let [rs, rp] = radii(&text, "sp");
        let [rp_ring, rr] = radii(&text, "pr");
        assert_eq!(rp, rp_ring, "one planet radius in both meshes");
        let o = drawn(&m, "frame.O");
        for name in ["arm.O", "sun.O", "ring.O"] {
            assert_eq!(drawn(&m, name), o, "{name} at the centre");
        }
        let p0 = drawn(&m, "arm.P");
        assert_eq!(drawn(&m, "planet.P"), p0);
        // The load rule, recomputed: the centre distances as drawn.
        let d = dist(o, p0);
        assert!(
            (d - (rs + rp)).abs() <= 1e-12,
            "sun–planet: |OP| = {d} vs rS + rP"
        );
        assert!(
            (d - (rr - rp)).abs() <= 1e-12,
            "planet–ring: |OP| = {d} vs rR − rP"
        );
        let q0 = drawn(&m, "planet.Q");
        Epicyclic {
            m,
            o,
            p0,
            q0,
            rs,
            rp,
            rr,
        }
    }

    /// The inputs vector for carrier `c` and sun-relative-to-arm `s`.
    fn inputs(&self, c: f64, s: f64) -> Vec<f64> {
        let mut u = vec![0.0; self.m.inputs.len()];
        u[input(&self.m, "carrier")] = c;
        u[input(&self.m, "sun_rel")] = s;
        u
    }

    /// Absolute rotations (degrees) of [arm, sun, planet, ring] for carrier
    /// `c` and sun-relative-to-arm `s`. Relative to the arm, the sun turns
    /// by s; the external mesh rS·s = −rP·p gives the planet's p; the
    /// internal one rP·p = +rR·q the ring's q. Each adds the arm's c.
    fn rotations(&self, c: f64, s: f64) -> [f64; 4] {
        let p = -(self.rs / self.rp) * s;
        let q = (self.rp / self.rr) * p;
        [c, c + s, c + p, c + q]
    }

    /// Checks every body of a solved frame against `expected` rotations
    /// ([arm, sun, planet, ring], degrees) and the markers they carry;
    /// returns the worst deviation.
    fn check(&self, poses: &[Pose], expected: [f64; 4], what: &dyn Fn(&str) -> String) -> f64 {
        let m = &self.m;
        let mut worst = 0.0_f64;
        for (name, e) in ["arm", "sun", "planet", "ring"].into_iter().zip(expected) {
            worst = worst.max(check(rot_gap(&poses[body(m, name)], e), || what(name)));
        }
        // The planet's pivot goes round with the arm; its rim point turns
        // with the planet about that pivot.
        let [arm, _, planet, _] = expected;
        let p = add(self.o, turn(sub(self.p0, self.o), arm));
        let q = add(p, turn(sub(self.q0, self.p0), planet));
        for (name, x) in [("arm.P", p), ("planet.P", p), ("planet.Q", q)] {
            worst = worst.max(check(dist(at(m, poses, name), x), || what(name)));
        }
        for name in ["arm.O", "sun.O", "ring.O"] {
            worst = worst.max(check(dist(at(m, poses, name), self.o), || what(name)));
        }
        worst
    }
}

/// Single frames solved from a fresh state on a grid of (carrier, sun
/// relative to the arm), the carrier beyond a turn either way: each body's
/// rotation is Willis' formula. The sun's relative angle stays within a
/// quarter turn, so that even the planet (turning rS/rP = 2 times as
/// fast) stays within a half turn of the drawing: which way round a
/// fresh solve counts a larger relative angle is no part of this check
/// (the continuous runs below hold the turns).
#[test]
fn epicyclic_bodies_turn_as_willis_says() {
    let e = Epicyclic::new();
    let interp = Interpreter::new(plan(&e.m));
    let mut worst = 0.0_f64;
    for c in [0.0, 37.0, 200.0, 500.0, -730.0] {
        for s in [0.0, 25.0, -60.0, 85.0, -89.0] {
            let u = e.inputs(c, s);
            let mut state = interp.initial_state();
            let mut ctx = Ctx::new(Default::default(), false);
            interp
                .solve(&mut state, &u, &mut ctx)
                .unwrap_or_else(|b| panic!("carrier {c}, sun_rel {s}: {b:?}"));
            let poses = Interpreter::poses(&state);
            let r = max_relative_residual(&e.m, poses, &u);
            assert!(r <= TOL, "carrier {c}, sun_rel {s}: relative residual {r:e}");
            let what = |n: &str| format!("epicyclic carrier {c}, sun_rel {s}: {n}");
            worst = worst.max(e.check(poses, e.rotations(c, s), &what));
            // Willis' ratio, from the solved rotations relative to the arm
            // (angles within a half turn here, so atan2 reads them whole).
            if s != 0.0 {
                let rel = |b: &str| {
                    let (a, x) = (poses[body(&e.m, "arm")].rot, poses[body(&e.m, b)].rot);
                    (a.c * x.s - a.s * x.c).atan2(a.c * x.c + a.s * x.s)
                };
                let willis = rel("ring") / rel("sun");
                assert!(
                    (willis + e.rs / e.rr).abs() <= TOL,
                    "carrier {c}, sun_rel {s}: (ωring − ωarm)/(ωsun − ωarm) = {willis}, not −rS/rR"
                );
            }
        }
    }
    eprintln!("epicyclic: worst deviation from Willis {worst:e}");
}

/// Continuous runs through two turns of the arm, with the textbook ratios
/// of each case written out (not through [`Epicyclic::rotations`]):
/// - sun held still (sun_rel = −carrier): the planet turns c·(1 + rS/rP),
///   the ring c·(1 + rS/rR);
/// - ring held still (sun_rel = c·rR/rS): the sun turns c·(1 + rR/rS), the
///   planet, rolling inside the ring, c·(1 − rR/rP);
/// - the bundled sweep holds the sun still too (sun_rel = −carrier).
///
/// The relative angles pass many half turns: a solver that read a gear's
/// driving angle back from a rotation without its turns would jump.
#[test]
fn epicyclic_counts_whole_turns_with_the_sun_or_the_ring_held() {
    let e = Epicyclic::new();
    let (rs, rp, rr) = (e.rs, e.rp, e.rr);
    let carriers: Vec<f64> = (0..=144).map(|k| 5.0 * f64::from(k)).collect();
    type Case = (&'static str, Box<dyn Fn(f64) -> (f64, [f64; 4])>);
    let cases: Vec<Case> = vec![
        (
            "sun still",
            Box::new(move |c| (-c, [c, 0.0, c * (1.0 + rs / rp), c * (1.0 + rs / rr)])),
        ),
        (
            "ring still",
            Box::new(move |c| (c * rr / rs, [c, c * (1.0 + rr / rs), c * (1.0 - rr / rp), 0.0])),
        ),
    ];
    let interp = Interpreter::new(plan(&e.m));
    for (label, case) in &cases {
        let requested: Vec<Vec<f64>> = carriers.iter().map(|&c| e.inputs(c, case(c).0)).collect();
        let frames = run(interp.clone(), Options::default(), &requested);
        let mut worst = 0.0_f64;
        for (f, &c) in frames.iter().zip(&carriers) {
            assert_solved(&e.m, f, label);
            let what = |n: &str| format!("epicyclic, {label}, carrier {c}: {n}");
            worst = worst.max(e.check(&f.poses, case(c).1, &what));
        }
        eprintln!("epicyclic, {label}: worst deviation {worst:e}");
    }
    // The bundled sweep holds the sun still while the arm turns once.
    let requested = sweep_inputs(&e.m, None);
    assert_eq!(requested.len(), 73);
    let frames = run(interp, Options::default(), &requested);
    let (ic, is) = (input(&e.m, "carrier"), input(&e.m, "sun_rel"));
    for f in &frames {
        assert_solved(&e.m, f, "epicyclic sweep");
        let (c, s) = (f.inputs[ic], f.inputs[is]);
        assert!(
            (s + c).abs() < 1e-12,
            "the sweep holds the sun: sun_rel {s} at carrier {c}"
        );
        let what = |n: &str| format!("epicyclic sweep, carrier {c}: {n}");
        e.check(&f.poses, cases[0].1(c).1, &what);
    }
}

/// Willis' formula differentiated: with the carrier at ω_c and the sun at
/// ω_s relative to the arm (degrees per second, as inputs are), the planet
/// turns at ω_c − (rS/rP)·ω_s and the ring at ω_c − (rS/rR)·ω_s (the
/// relations are linear, so the accelerations follow the same ratios),
/// against the plan's jets.
#[test]
fn epicyclic_rates_follow_willis() {
    let e = Epicyclic::new();
    let interp = Interpreter::new(plan(&e.m));
    let k = PI / 180.0;
    let (wc, ws, ac, as_) = (30.0, -12.0, 4.0, 7.0);
    let rates = e.inputs(wc, ws);
    let accels = e.inputs(ac, as_);
    let ratio = |b: &str| match b {
        "arm" => 0.0,
        "sun" => 1.0,
        "planet" => -e.rs / e.rp,
        _ => -e.rs / e.rr,
    };
    for (c, s) in [(0.0, 0.0), (40.0, -30.0), (130.0, 70.0), (-400.0, 15.0)] {
        // A driver of its own for each point: the first frame from the drawing.
        let mut d = Driver::new(interp.clone(), Options::default());
        let u = e.inputs(c, s);
        assert_eq!(d.frame(&u), FrameStatus::Solved, "carrier {c}, sun_rel {s}");
        let jets = interp
            .rates(d.state(), &u, &rates, &accels)
            .unwrap_or_else(|err| panic!("carrier {c}, sun_rel {s}: {err}"));
        for b in ["arm", "sun", "planet", "ring"] {
            let (w, a) = omega_alpha(&jets[body(&e.m, b)]);
            let (w_e, a_e) = ((wc + ratio(b) * ws) * k, (ac + ratio(b) * as_) * k);
            assert!(
                (w - w_e).abs() <= TOL * (1.0 + w_e.abs()),
                "carrier {c}, sun_rel {s}: ω {b} {w} vs {w_e}"
            );
            assert!(
                (a - a_e).abs() <= TOL * (1.0 + a_e.abs()),
                "carrier {c}, sun_rel {s}: α {b} {a} vs {a_e}"
            );
        }
    }
}

/// Both intersections of circle(`c1`, `r1`) and circle(`c2`, `r2`) (law of
/// cosines for the chord's foot on the centre line, Pythagoras for the
/// half-chord), and the half-chord.
fn circle_roots(c1: P, r1: f64, c2: P, r2: f64) -> ([P; 2], f64) {
    let d = dist(c1, c2);
    let along = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h2 = r1 * r1 - along * along;
    assert!(h2 > 0.0, "circles do not meet (h² = {h2})");
    let h = h2.sqrt();
    let e = unit(sub(c2, c1));
    let foot = add(c1, scale(e, along));
    ([add(foot, scale(perp(e), h)), add(foot, scale(perp(e), -h))], h)
}

/// The geared five-bar along its bundled sweep: crank 1 turns by the
/// input θ, crank 2 by −(r1/r2)·θ (external mesh, both on the frame),
/// which is the gear relation r1·Δφ1 = −r2·Δφ2 checked on the solved
/// rotations; the coupler pin C is the intersection of circle(B1, l3) and
/// circle(B2, l4) nearest the previous frame's (continuity, starting from
/// the drawn C), computed here.
#[test]
fn geared_fivebar_coupler_follows_the_gear_ratio_and_the_dyad() {
    let (m, text) = gear_file("geared_fivebar");
    let [r1, r2] = radii(&text, "g");
    let (o1, o2) = (drawn(&m, "frame.O1"), drawn(&m, "frame.O2"));
    assert!(
        (dist(o1, o2) - (r1 + r2)).abs() <= 1e-12,
        "external mesh: |O1 O2| = r1 + r2"
    );
    let (b10, b20, c0) = (
        drawn(&m, "crank1.B1"),
        drawn(&m, "crank2.B2"),
        drawn(&m, "coupler1.C"),
    );
    assert_eq!(drawn(&m, "coupler2.C"), c0);
    let (l3, l4) = (dist(b10, c0), dist(b20, c0));
    let ratio = -r1 / r2;
    let requested = sweep_inputs(&m, None);
    assert_eq!(requested.len(), 73);
    let frames = run(Interpreter::new(plan(&m)), Options::default(), &requested);
    let (crank1, crank2) = (body(&m, "crank1"), body(&m, "crank2"));
    let mut previous = c0;
    let mut worst = 0.0_f64;
    for f in &frames {
        assert_solved(&m, f, "geared_fivebar");
        let theta = f.inputs[0];
        let phi2 = ratio * theta;
        let what = |n: &str| format!("geared_fivebar theta = {theta}: {n}");
        worst = worst.max(check(rot_gap(&f.poses[crank1], theta), || what("crank1")));
        worst = worst.max(check(rot_gap(&f.poses[crank2], phi2), || what("crank2 (gear)")));
        let b1 = add(o1, turn(sub(b10, o1), theta));
        let b2 = add(o2, turn(sub(b20, o2), phi2));
        let (roots, h) = circle_roots(b1, l3, b2, l4);
        // The roots are far apart compared with a step's motion, so the
        // nearest one is the continued assembly.
        assert!(h > 0.5, "theta = {theta}: the dyad nearly lines up (h = {h})");
        let c = if dist(roots[0], previous) <= dist(roots[1], previous) {
            roots[0]
        } else {
            roots[1]
        };
        previous = c;
        for (name, x) in [
            ("crank1.B1", b1),
            ("coupler1.B1", b1),
            ("crank2.B2", b2),
            ("coupler2.B2", b2),
            ("coupler1.C", c),
            ("coupler2.C", c),
        ] {
            worst = worst.max(check(dist(at(&m, &f.poses, name), x), || what(name)));
        }
    }
    eprintln!("geared_fivebar: worst deviation {worst:e}");
}

/// The rack and pinion's closed form from the drawing: the pinion turns on
/// the frame about O; the rack slides along the unit `dir` of the frame's
/// prismatic marker, its pitch line on side σ of the line through O along
/// `dir` (σ = +1 to the left, −1 to the right: where the rack's marker of
/// that joint lies). The pinion's pitch point on that side,
/// O + σ·r·perp(dir), moves at ω × σ·r·perp(dir) = −σ·r·ω·dir, and the rack
/// with it: its slide along `dir` is −σ·r·θ (θ in radians).
struct RackPinion {
    m: Mechanism,
    dir: P,
    /// Slide of the rack along `dir` per degree of the pinion.
    per_degree: f64,
}

impl RackPinion {
    fn new() -> RackPinion {
        let (m, text) = gear_file("rack_pinion");
        let r = match joint_numbers(&text, "R", "radius")[..] {
            [r] => r,
            ref other => panic!("radius {other:?}"),
        };
        let o = drawn(&m, "frame.O");
        assert_eq!(drawn(&m, "pinion.O"), o);
        let track = m.marker(m.find_marker("frame.T").unwrap());
        let dir = track.unit_dir().expect("the prismatic marker has a dir");
        let left = cross(dir, sub(drawn(&m, "rack.T"), o));
        assert!(left != 0.0, "the rack's marker is off the line through the pivot");
        let sigma = left.signum();
        let per_degree = -sigma * r * PI / 180.0;
        // As the file's header says: rack below, slide r·θ along +x.
        assert!(sigma < 0.0 && per_degree > 0.0);
        RackPinion { m, dir, per_degree }
    }
}

/// The rack slides r·θ along +x on every frame of the bundled sweep, its
/// y and its rotation unchanged, while the pinion turns by θ.
#[test]
fn rack_slides_by_the_arc_rolled_on_its_pitch_line() {
    let rp = RackPinion::new();
    let m = &rp.m;
    let requested = sweep_inputs(m, None);
    assert!(requested.len() > 1);
    let frames = run(Interpreter::new(plan(m)), Options::default(), &requested);
    let (pinion, rack) = (body(m, "pinion"), body(m, "rack"));
    let (o, q0) = (drawn(m, "frame.O"), drawn(m, "pinion.Q"));
    let mut worst = 0.0_f64;
    for f in &frames {
        assert_solved(m, f, "rack_pinion");
        let theta = f.inputs[0];
        let what = |n: &str| format!("rack_pinion theta = {theta}: {n}");
        let slide = scale(rp.dir, rp.per_degree * theta);
        for name in ["rack.T", "rack.E"] {
            let moved = sub(at(m, &f.poses, name), drawn(m, name));
            worst = worst.max(check(dist(moved, slide), || what(name)));
            // Across the track (y for a track along x) it stays put.
            worst = worst.max(check(cross(rp.dir, moved).abs(), || what(name)));
        }
        worst = worst.max(check(rot_gap(&f.poses[rack], 0.0), || what("rack rotation")));
        worst = worst.max(check(rot_gap(&f.poses[pinion], theta), || what("pinion")));
        let q = add(o, turn(sub(q0, o), theta));
        worst = worst.max(check(dist(at(m, &f.poses, "pinion.Q"), q), || what("pinion.Q")));
    }
    eprintln!("rack_pinion: worst deviation {worst:e}");
}

/// `simulate`'s residual checks rolling without slip on the turns the
/// inputs give, unwrapped: the hoist's drum (1:3 on the motor's pinion)
/// is a third of a turn back after one motor turn. Turned 5° off that,
/// or left at the drawn angle (where a check of wrapped angles against
/// the input modulo a turn would put it), the drum is off by the arc of
/// its pitch circle; a rack slid off its pinion's arc, by the slide.
#[test]
fn the_residual_holds_gears_to_rolling_past_whole_turns() {
    use dofplan::simulate::residuals;
    use dofplan_runtime::planar::Rot;
    let (m, text) = gear_file("geared_hoist");
    let [_, r_drum] = radii(&text, "mesh");
    let frames = run(Interpreter::new(plan(&m)), Options::default(), &[vec![360.0]]);
    assert_solved(&m, &frames[0], "geared_hoist");
    let drum = body(&m, "drum");
    let pivot = drawn(&m, "frame.B");
    assert!(rot_gap(&frames[0].poses[drum], -120.0) <= TOL);
    let mesh = |poses: &[Pose]| {
        let r = residuals(&m, poses, &[360.0]);
        r.iter()
            .find(|r| r.name == "joint mesh")
            .expect("the gear pair's residual")
            .value
    };
    assert!(mesh(&frames[0].poses) <= TOL);
    // The drum turned about its pivot to `degrees` (its pivot stays put).
    let drum_at = |degrees: f64| {
        let mut poses = frames[0].poses.clone();
        let rot = Rot::from_degrees(degrees);
        let p = rot.apply(pivot);
        poses[drum] = Pose {
            at: [pivot[0] - p[0], pivot[1] - p[1]],
            rot,
        };
        poses
    };
    assert!(mesh(&drum_at(-120.0)) <= TOL);
    let off = mesh(&drum_at(-115.0));
    assert!((off - r_drum * 5f64.to_radians()).abs() <= TOL, "5° off: {off}");
    let wrapped = mesh(&drum_at(0.0));
    assert!(
        (wrapped - r_drum * 120f64.to_radians()).abs() <= TOL,
        "at the drawing: {wrapped}"
    );
    // The rack pushed 0.1 along its track, its pinion where it was.
    let rp = RackPinion::new();
    let frames = run(Interpreter::new(plan(&rp.m)), Options::default(), &[vec![400.0]]);
    assert_solved(&rp.m, &frames[0], "rack_pinion");
    let mut poses = frames[0].poses.clone();
    let rack = body(&rp.m, "rack");
    poses[rack].at = add(poses[rack].at, scale(rp.dir, 0.1));
    let r = residuals(&rp.m, &poses, &[400.0]);
    let slid = r
        .iter()
        .find(|r| r.name == "joint R")
        .expect("the rack and pinion's residual");
    assert!((slid.value - 0.1).abs() <= TOL, "slid 0.1: {}", slid.value);
    // Along its track the prismatic joint still holds.
    assert!(r.iter().find(|r| r.name == "joint T").expect("the track").value <= TOL);
}

/// The rack's velocity and acceleration from the plan's jets: the slide
/// per degree times the pinion's rate (and acceleration), in degrees per
/// second as inputs are; none across the track.
#[test]
fn rack_rates_are_the_pinion_rates_times_the_pitch_radius() {
    let rp = RackPinion::new();
    let m = &rp.m;
    let interp = Interpreter::new(plan(m));
    let rack = body(m, "rack");
    let t_local = drawn(m, "rack.T");
    let (rate, accel) = (45.0, -6.0);
    let mut d = Driver::new(interp.clone(), Options::default());
    for theta in [-60.0, -5.0, 0.0, 30.0, 85.0] {
        assert_eq!(d.frame(&[theta]), FrameStatus::Solved, "theta = {theta}");
        let jets = interp
            .rates(d.state(), &[theta], &[rate], &[accel])
            .unwrap_or_else(|e| panic!("theta = {theta}: {e}"));
        let p = jets[rack].world(t_local);
        for (k, e) in rp.dir.into_iter().enumerate() {
            let (v, a) = (rp.per_degree * rate * e, rp.per_degree * accel * e);
            assert!(
                (p[k].d - v).abs() <= TOL * (1.0 + v.abs()),
                "theta = {theta}: velocity[{k}] {} vs {v}",
                p[k].d
            );
            assert!(
                (p[k].dd - a).abs() <= TOL * (1.0 + a.abs()),
                "theta = {theta}: acceleration[{k}] {} vs {a}",
                p[k].dd
            );
        }
    }
}

/// Grübler's count with a gear or rack and pinion as one equation:
/// D = 3(L − 1) − 2·(lower pairs) − (higher pairs): 3·4 − 2·4 − 2 = 2 for
/// the epicyclic train, 3·4 − 2·5 − 1 = 1 for the geared five-bar,
/// 3·2 − 2·2 − 1 = 1 for the rack and pinion; each driven by as many inputs.
#[test]
fn gears_count_as_one_equation_each_in_grublers_count() {
    for (name, dof) in [("epicyclic", 2), ("geared_fivebar", 1), ("rack_pinion", 1)] {
        let (m, _) = gear_file(name);
        assert_eq!(Mobility::of(&m).dof, dof, "{name}");
        assert_eq!(m.inputs.len() as i64, dof, "{name}: as many inputs as freedoms");
    }
}

/// A gear turns one relative angle from another: a closed-form step, so
/// neither train needs Newton's method anywhere.
#[test]
fn geared_trains_plan_in_closed_form() {
    for name in ["epicyclic", "geared_fivebar"] {
        let (m, _) = gear_file(name);
        assert_eq!(plan(&m).clusters(), 0, "{name}: numeric clusters");
    }
}

/// Two wheels on the frame, 3 apart, meshing as `gear` (the lines of the
/// gear's table after `kind`), with `left_wheel` driven.
fn two_wheels(gear: &str) -> String {
    format!(
        r#"
name = "two_wheels"
[bodies.frame]
fixed = true
markers = {{ O1 = [0.0, 0.0], O2 = [3.0, 0.0] }}
[bodies.left_wheel]
markers = {{ O1 = [0.0, 0.0] }}
[bodies.right_wheel]
markers = {{ O2 = [3.0, 0.0] }}
[joints.J1]
kind = "revolute"
markers = ["frame.O1", "left_wheel.O1"]
[joints.J2]
kind = "revolute"
markers = ["frame.O2", "right_wheel.O2"]
[joints.spur]
kind = "gear"
{gear}
[inputs.theta]
kind = "angle"
joint = "J1"
"#
    )
}

/// The error text of a mechanism that must not load.
fn load_error(text: &str) -> String {
    match load_str("t.toml", text, Format::Toml) {
        Ok(_) => panic!("loaded, but should not have:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The loose checks below only mean something if the same file loads with
/// consistent radii: both meshes, centre distance 3 = 1 + 2 = 4 − 1.
#[test]
fn two_wheels_load_when_the_radii_fit_the_drawing() {
    for gear in [
        "bodies = [\"left_wheel\", \"right_wheel\"]\nradii = [1.0, 2.0]\nmesh = \"external\"",
        "bodies = [\"left_wheel\", \"right_wheel\"]\nradii = [1.0, 4.0]\nmesh = \"internal\"",
    ] {
        let m = load_str("t.toml", &two_wheels(gear), Format::Toml).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(Mobility::of(&m).dof, 1, "{gear}");
    }
}

/// Pitch radii that do not fit the drawn centre distance |O1 O2| = 3 (as
/// an external or an internal mesh) are an error naming the gear and its
/// radii.
#[test]
fn a_gear_whose_radii_miss_the_centre_distance_is_an_error() {
    for (radii, mesh) in [
        ("[1.0, 1.5]", "external"),
        ("[1.0, 2.0]", "internal"),
        ("[1.0, 3.0]", "internal"),
    ] {
        let gear = format!("bodies = [\"left_wheel\", \"right_wheel\"]\nradii = {radii}\nmesh = \"{mesh}\"");
        let e = load_error(&two_wheels(&gear));
        assert!(
            e.contains("spur") && e.contains("radii"),
            "{mesh} {radii}: the error names the gear and its radii:\n{e}"
        );
    }
}

/// Pitch radii must be positive.
#[test]
fn a_gear_with_a_zero_radius_is_an_error() {
    let gear = "bodies = [\"left_wheel\", \"right_wheel\"]\nradii = [0.0, 3.0]\nmesh = \"external\"";
    let e = load_error(&two_wheels(gear));
    assert!(e.contains("spur"), "the error names the gear:\n{e}");
}

/// A mesh that is neither external nor internal is an error.
#[test]
fn a_gear_with_an_unknown_mesh_is_an_error() {
    let gear = "bodies = [\"left_wheel\", \"right_wheel\"]\nradii = [1.0, 2.0]\nmesh = \"sideways\"";
    let e = load_error(&two_wheels(gear));
    assert!(
        e.contains("spur") && (e.contains("mesh") || e.contains("sideways")),
        "the error names the gear and its mesh:\n{e}"
    );
}

/// Two wheels that turn on different bodies (one on the frame, one on an
/// arm that itself turns on the frame elsewhere) have no common carrier:
/// an error naming both. The drawn centre distance fits the radii, so
/// that is the only fault.
#[test]
fn a_gear_without_a_common_pivot_body_is_an_error() {
    let text = r#"
name = "no_carrier"
[bodies.frame]
fixed = true
markers = { O1 = [0.0, 0.0], A = [5.0, 0.0] }
[bodies.arm]
markers = { A = [5.0, 0.0], O2 = [3.0, 0.0] }
[bodies.left_wheel]
markers = { O1 = [0.0, 0.0] }
[bodies.right_wheel]
markers = { O2 = [3.0, 0.0] }
[joints.J1]
kind = "revolute"
markers = ["frame.O1", "left_wheel.O1"]
[joints.JA]
kind = "revolute"
markers = ["frame.A", "arm.A"]
[joints.J2]
kind = "revolute"
markers = ["arm.O2", "right_wheel.O2"]
[joints.spur]
kind = "gear"
bodies = ["left_wheel", "right_wheel"]
radii = [1.0, 2.0]
mesh = "external"
[inputs.theta]
kind = "angle"
joint = "J1"
[inputs.swing]
kind = "angle"
joint = "JA"
"#;
    let e = load_error(text);
    assert!(
        e.contains("left_wheel") && e.contains("right_wheel"),
        "the error names both bodies:\n{e}"
    );
}
