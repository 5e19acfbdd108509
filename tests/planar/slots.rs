//! Pins in slots (`mechanisms/slots/`) against their closed forms, every
//! expected value derived here from the drawing:
//! - the Scotch yoke's displacement `r cos(φ0 + θ) − r cos φ0` and its
//!   velocity, the pin on the slot's line on every frame;
//! - the quick return's lever angle `atan2(r sin θ + d, r cos θ)`, its
//!   dead points (where the crank is square to the lever: sin θ = −r/d)
//!   and the 240°/120° strokes they split the turn into;
//! - a slot's ends as assembly limits: the search policy lands where the
//!   pin reaches an end, `asin(end/r) − φ0`, and stretch lets it run on;
//! - the slot's force is square to the slot, and the input torque holding
//!   a loaded yoke is virtual work's and the closed form's;
//! - load errors: a pin drawn outside the ends, ends given high first.

use dofplan::forces::planar::{force_plan, input_forces, reactions};
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan::simulate::{marker_at, max_relative_residual, run, sweep_inputs};
use dofplan_runtime::{BreakKind, BreakPolicy, Driver, FrameStatus, Options};
use dofplan_tests::{mechanisms_dir, plan};

fn text(name: &str) -> String {
    std::fs::read_to_string(mechanisms_dir().join(format!("slots/{name}.toml"))).unwrap()
}

fn load(name: &str) -> Mechanism {
    load_str(&format!("{name}.toml"), &text(name), Format::Toml).unwrap_or_else(|e| panic!("{e}"))
}

fn at(m: &Mechanism, name: &str) -> [f64; 2] {
    m.marker(m.find_marker(name).unwrap()).at
}

/// The Scotch yoke's crank radius and drawn angle, from its markers.
fn yoke_crank(m: &Mechanism) -> (f64, f64) {
    let (o, p) = (at(m, "frame.O"), at(m, "crank.P"));
    ((p[0] - o[0]).hypot(p[1] - o[1]), (p[1] - o[1]).atan2(p[0] - o[0]))
}

#[test]
fn the_scotch_yoke_moves_in_simple_harmonic_motion() {
    let m = load("scotch_yoke");
    let (r, phi0) = yoke_crank(&m);
    let interp = Interpreter::new(plan(&m));
    assert_eq!(plan(&m).clusters(), 0, "a slot plans in closed form");
    let requested = sweep_inputs(&m, None);
    let frames = run(interp.clone(), Options::default(), &requested);
    let yoke = m.bodies.iter().position(|b| b.name == "yoke").unwrap();
    let mut d = Driver::new(interp.clone(), Options::default());
    for f in &frames {
        let theta = f.inputs[0];
        assert_eq!(f.status, FrameStatus::Solved, "theta {theta}");
        let phi = phi0 + theta.to_radians();
        let x = f.poses[yoke].at[0];
        assert!(
            (x - (r * phi.cos() - r * phi0.cos())).abs() < 1e-12,
            "x {x} at {theta}"
        );
        assert!(f.poses[yoke].at[1].abs() < 1e-12 && f.poses[yoke].rot.s.abs() < 1e-12);
        assert!(
            max_relative_residual(&m, &f.poses, &f.inputs) < 1e-12,
            "residual at {theta}"
        );
        // The velocity at 1 degree per second.
        assert!(d.frame(&[theta]).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), &[1.0], &[0.0]).unwrap();
        let v = -r * phi.sin() * 1f64.to_radians();
        assert!((jets[yoke].at[0].d - v).abs() < 1e-12, "velocity at {theta}");
    }
}

#[test]
fn the_quick_return_lever_follows_the_pin_and_returns_twice_as_fast() {
    let m = load("quick_return");
    let (o2, o4, a) = (at(&m, "frame.O2"), at(&m, "frame.O4"), at(&m, "crank.A"));
    let (r, d) = (
        (a[0] - o2[0]).hypot(a[1] - o2[1]),
        (o2[1] - o4[1]).hypot(o2[0] - o4[0]),
    );
    let theta0 = (a[1] - o2[1]).atan2(a[0] - o2[0]);
    // The lever's angle: from O4 toward the pin.
    let lever = |theta: f64| {
        let t = theta0 + theta.to_radians();
        (o2[1] + r * t.sin() - o4[1]).atan2(o2[0] + r * t.cos() - o4[0])
    };
    let rocker = m.bodies.iter().position(|b| b.name == "rocker").unwrap();
    let interp = Interpreter::new(plan(&m));
    let frames = run(interp.clone(), Options::default(), &sweep_inputs(&m, None));
    for f in &frames {
        let theta = f.inputs[0];
        assert_eq!(f.status, FrameStatus::Solved, "theta {theta}");
        let got = f.poses[rocker].rot.s.atan2(f.poses[rocker].rot.c);
        let want = lever(theta) - lever(0.0);
        assert!((got - want).abs() < 1e-12, "lever {got} vs {want} at {theta}");
        assert!(
            max_relative_residual(&m, &f.poses, &f.inputs) < 1e-12,
            "residual at {theta}"
        );
        let pin = marker_at(&m, &f.poses, m.find_marker("crank.A").unwrap());
        let reach = (pin[0] - o4[0]).hypot(pin[1] - o4[1]);
        assert!((d - r - 1e-12..=d + r + 1e-12).contains(&reach));
    }
    // The dead points: the crank square to the lever, where sin(θ0 + θ) =
    // −r/d; the lever's rate vanishes there and has one sign between.
    let dead = (-r / d).asin();
    let theta_a = (std::f64::consts::PI - dead - theta0).to_degrees();
    let theta_b = (2.0 * std::f64::consts::PI + dead - theta0).to_degrees();
    let mut drv = Driver::new(interp.clone(), Options::default());
    let mut omega = |theta: f64| {
        assert!(drv.frame(&[theta]).is_solved());
        let jets = interp.rates(drv.state(), drv.inputs(), &[1.0], &[0.0]).unwrap();
        let rot = jets[rocker].rot;
        rot.c.v * rot.s.d - rot.s.v * rot.c.d
    };
    assert!(omega(theta_a).abs() < 1e-12 && omega(theta_b).abs() < 1e-12);
    let stroke = theta_b - theta_a;
    assert!((stroke - 120.0).abs() < 1e-9, "the return stroke is {stroke}°");
    let (s1, s2) = (omega(theta_a + 1.0).signum(), omega(theta_b - 1.0).signum());
    assert_eq!(s1, s2);
    assert_eq!(omega(theta_b + 1.0).signum(), -s1);
    assert_eq!(omega(theta_a - 1.0).signum(), -s1);
}

#[test]
fn a_slot_s_end_is_a_limit_the_search_lands_on() {
    let short = text("scotch_yoke").replace("ends = [-1.25, 1.25]", "ends = [-0.8, 0.8]");
    let m = load_str("short.toml", &short, Format::Toml).unwrap();
    let (r, phi0) = yoke_crank(&m);
    // The pin reaches the upper end where r sin(φ0 + θ) = 0.8.
    let landing = ((0.8 / r).asin() - phi0).to_degrees();
    let search = Options {
        breaking: BreakPolicy::Search,
        ..Options::default()
    };
    let mut d = Driver::new(Interpreter::new(plan(&m)), search);
    let FrameStatus::Searched { brk, .. } = d.frame(&[40.0]) else {
        panic!("expected the search to stop at the slot's end");
    };
    assert_eq!(brk.kind, BreakKind::PastSlotEnd);
    let pin_height = |theta: f64| r * (phi0 + theta.to_radians()).sin();
    assert!(
        (brk.gap - (pin_height(40.0) - 0.8)).abs() < 1e-12,
        "gap {}",
        brk.gap
    );
    let got = d.inputs()[0];
    assert!(
        (got - landing).abs() < 1e-8,
        "searched to {got}, the end at {landing}"
    );
    // Stretched, the pin runs on along the slot's line past the end.
    let stretch = Options {
        breaking: BreakPolicy::Stretch,
        ..Options::default()
    };
    let mut d = Driver::new(Interpreter::new(plan(&m)), stretch);
    let status = d.frame(&[40.0]);
    assert!(matches!(status, FrameStatus::Stretched { .. }), "{status:?}");
    assert!(max_relative_residual(&m, d.poses(), d.inputs()) < 1e-12);
}

#[test]
fn the_slot_pushes_square_to_itself_and_the_crank_holds_the_yoke() {
    // A force F along x on the yoke: the crank holds it with
    // T = −F·dx/dθ = F·r·sin(φ0 + θ) (per radian), and the slot, square to
    // its own (vertical) line, passes F on to the pin.
    let loaded = format!(
        "{}\n[loads.push]\nkind = \"force\"\nmarker = \"yoke.Y\"\nforce = [-50.0, 0.0]\n",
        text("scotch_yoke")
    );
    let m = load_str("loaded.toml", &loaded, Format::Toml).unwrap();
    let (r, phi0) = yoke_crank(&m);
    let fp = force_plan(&m).unwrap();
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    for k in 0..36 {
        let theta = 10.0 * k as f64 + 5.0;
        assert!(d.frame(&[theta]).is_solved());
        let rx = reactions(&m, &fp, d.poses(), None).unwrap();
        let q = input_forces(&m, d.solver(), d.state(), d.inputs(), None).unwrap()[0];
        let torque = -50.0 * r * (phi0 + theta.to_radians()).sin();
        assert!(
            (q - torque).abs() < 1e-9,
            "virtual work {q} vs {torque} at {theta}"
        );
        assert!(
            (rx.inputs[0] - torque).abs() < 1e-9,
            "reactions {} at {theta}",
            rx.inputs[0]
        );
        let slot = rx.slots[0];
        assert!(slot[1].abs() < 1e-9, "square to the vertical slot: {slot:?}");
        assert!(
            (slot[0] + 50.0).abs() < 1e-9,
            "the slot passes the push on: {slot:?}"
        );
        assert!(rx.residual < 1e-9);
    }
}

#[test]
fn a_pin_outside_its_slot_s_ends_or_ends_given_high_first_are_errors() {
    let outside = text("scotch_yoke").replace("ends = [-1.25, 1.25]", "ends = [0.6, 1.25]");
    let e = load_str("o.toml", &outside, Format::Toml)
        .unwrap_err()
        .to_string();
    assert!(e.contains("joint `S`") && e.contains("outside its ends"), "{e}");
    let reversed = text("scotch_yoke").replace("ends = [-1.25, 1.25]", "ends = [1.25, -1.25]");
    let e = load_str("r.toml", &reversed, Format::Toml)
        .unwrap_err()
        .to_string();
    assert!(e.contains("ends") && e.contains("below"), "{e}");
    let driven = format!(
        "{}\n[inputs.bad]\nkind = \"slide\"\njoint = \"S\"\n",
        text("scotch_yoke")
    );
    let e = load_str("d.toml", &driven, Format::Toml).unwrap_err().to_string();
    assert!(e.contains("input `bad`") && e.contains("joint `S`"), "{e}");
}

#[test]
fn pure_newton_and_a_drag_hold_a_pin_within_its_slot_s_ends() {
    // The short Scotch yoke (ends ±0.8): the pin is sin(30° + θ) up the
    // slot, past the end beyond θ = asin(0.8) − 30°. Pure Newton and a
    // drag keep the pin on the slot's line by their equations, and check
    // the ends on every frame as the plan does.
    use dofplan::numeric::planar::drag::Drag;
    use dofplan::numeric::PureNewton;
    let short = text("scotch_yoke").replace("ends = [-1.25, 1.25]", "ends = [-0.8, 0.8]");
    let m = load_str("short.toml", &short, Format::Toml).unwrap();
    let (r, phi0) = yoke_crank(&m);
    let height = |theta: f64| r * (phi0 + theta.to_radians()).sin();
    let mut d = Driver::new(PureNewton::new(&m), Options::default());
    assert!(d.frame(&[10.0]).is_solved());
    let held = d.poses().to_vec();
    let FrameStatus::Limited { brk } = d.frame(&[40.0]) else {
        panic!("pure Newton past the end should be limited");
    };
    assert_eq!(brk.kind, BreakKind::PastSlotEnd);
    assert!((brk.gap - (height(40.0) - 0.8)).abs() < 1e-9, "gap {}", brk.gap);
    assert_eq!(d.poses(), &held[..], "held at the last pose within the slot");
    let search = Options {
        breaking: BreakPolicy::Search,
        ..Options::default()
    };
    let mut d = Driver::new(PureNewton::new(&m), search);
    assert!(matches!(d.frame(&[40.0]), FrameStatus::Searched { .. }));
    let landing = ((0.8 / r).asin() - phi0).to_degrees();
    assert!(
        (d.inputs()[0] - landing).abs() < 1e-6,
        "{} vs {landing}",
        d.inputs()[0]
    );
    // Dragging the yoke's marker Y up the frame's rail turns the crank
    // (the yoke at x = cos(30° + θ) − cos 30° from the drawing): to the
    // left, until the pin meets the slot's end.
    let yoke_y = m.find_marker("yoke.Y").unwrap();
    let mut d = Driver::new(Drag::new(&m, yoke_y).unwrap(), Options::default());
    let y0 = at(&m, "yoke.Y");
    // The drag releases the inputs: its residuals are the joints' alone.
    let mut free = m.clone();
    free.inputs.clear();
    let mut last = None;
    for k in 1..=40 {
        let status = d.frame(&[y0[0] - 0.02 * k as f64, y0[1]]);
        let pin = marker_at(&m, d.poses(), m.find_marker("crank.P").unwrap());
        assert!(
            pin[1] <= 0.8 + 1e-9,
            "the pin within the slot: {pin:?} at step {k}"
        );
        assert!(max_relative_residual(&free, d.poses(), &[]) < 1e-9);
        if let FrameStatus::Limited { brk } = status {
            assert_eq!(brk.kind, BreakKind::PastSlotEnd, "step {k}");
            last = Some(k);
            break;
        }
    }
    assert!(last.is_some(), "the drag reaches the slot's end");
}
