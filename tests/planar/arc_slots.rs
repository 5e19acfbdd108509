//! Pins in circular (arc) slots (`mechanisms/slots/arc_yoke.toml`,
//! `curved_lever.toml`) against their closed forms, every expected value
//! derived here from the drawing:
//! - the arc yoke is a slider-crank with a connecting rod the arc's
//!   radius long: the yoke's centre at `r cos φ + √(R² − r² sin² φ)`, and
//!   its velocity, the derivative of that;
//! - the curved lever is the four-bar O-P-C-Q: its centre C where the
//!   circle about Q meets the circle about the pin, solved here;
//! - an arc's end is a limit the search lands on (the pin's angle about
//!   the centre, `−asin(r sin φ / R)`, reaching the end), with the arc
//!   length past it as the gap;
//! - the arc's force is along its radius, and the input torque holding a
//!   loaded yoke is virtual work's, the force plan's and the closed form's;
//! - pure Newton, which solves the on-circle equation numerically, finds
//!   the plan's poses;
//! - load errors: a radius that is not the drawn distance, a centre
//!   without a dir, ends more than a turn apart, a pin outside the ends.

use dofplan::forces::planar::{force_plan, input_forces, reactions};
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan::numeric::PureNewton;
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

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// The arc yoke's crank radius r, drawn angle φ0 and arc radius R, from
/// its markers.
fn yoke_dims(m: &Mechanism) -> (f64, f64, f64) {
    let (o, p, c) = (at(m, "frame.O"), at(m, "crank.P"), at(m, "yoke.C"));
    (dist(o, p), (p[1] - o[1]).atan2(p[0] - o[0]), dist(p, c))
}

/// The yoke's centre C along x, and its rate per radian of the crank.
fn yoke_centre(r: f64, big_r: f64, phi: f64) -> (f64, f64) {
    let root = (big_r * big_r - (r * phi.sin()).powi(2)).sqrt();
    (
        r * phi.cos() + root,
        -r * phi.sin() - r * r * phi.sin() * phi.cos() / root,
    )
}

#[test]
fn the_arc_yoke_moves_as_a_slider_crank_with_the_arc_s_radius_as_its_rod() {
    let m = load("arc_yoke");
    let (r, phi0, big_r) = yoke_dims(&m);
    assert!((big_r - 3.0).abs() < 1e-12, "the arc's radius is drawn: {big_r}");
    let p = plan(&m);
    assert_eq!(p.clusters(), 0, "an arc slot plans in closed form");
    let interp = Interpreter::new(p);
    let frames = run(interp.clone(), Options::default(), &sweep_inputs(&m, Some(361)));
    let yoke = m.bodies.iter().position(|b| b.name == "yoke").unwrap();
    let c0 = at(&m, "yoke.C")[0];
    let mut d = Driver::new(interp.clone(), Options::default());
    for f in &frames {
        let theta = f.inputs[0];
        assert_eq!(f.status, FrameStatus::Solved, "theta {theta}");
        let phi = phi0 + theta.to_radians();
        let (x, v) = yoke_centre(r, big_r, phi);
        let got = f.poses[yoke].at[0];
        assert!((got - (x - c0)).abs() < 1e-12, "x {got} vs {} at {theta}", x - c0);
        assert!(f.poses[yoke].at[1].abs() < 1e-12 && f.poses[yoke].rot.s.abs() < 1e-12);
        let pin = marker_at(&m, &f.poses, m.find_marker("crank.P").unwrap());
        let centre = marker_at(&m, &f.poses, m.find_marker("yoke.C").unwrap());
        assert!(
            (dist(pin, centre) - big_r).abs() < 1e-12,
            "the pin on the arc at {theta}"
        );
        assert!(
            max_relative_residual(&m, &f.poses, &f.inputs) < 1e-12,
            "residual at {theta}"
        );
        assert!(d.frame(&[theta]).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), &[1.0], &[0.0]).unwrap();
        let want = v * 1f64.to_radians();
        assert!((jets[yoke].at[0].d - want).abs() < 1e-12, "velocity at {theta}");
    }
}

/// Where the circle of radius `r1` about `c1` meets the one of radius `r2`
/// about `c2`, on the left of the line from `c1` to `c2`.
fn circles_meet(c1: [f64; 2], r1: f64, c2: [f64; 2], r2: f64) -> [f64; 2] {
    let d = dist(c1, c2);
    let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h = (r1 * r1 - a * a).sqrt();
    let u = [(c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d];
    [c1[0] + a * u[0] - h * u[1], c1[1] + a * u[1] + h * u[0]]
}

#[test]
fn the_curved_lever_moves_as_the_four_bar_its_arc_makes() {
    let m = load("curved_lever");
    let (o, q, p0, c0) = (
        at(&m, "frame.O"),
        at(&m, "frame.Q"),
        at(&m, "crank.P"),
        at(&m, "lever.C"),
    );
    let (r, big_r, l) = (dist(o, p0), dist(p0, c0), dist(q, c0));
    let phi0 = (p0[1] - o[1]).atan2(p0[0] - o[0]);
    // C as drawn is on the left of the line from the pin to Q.
    assert!(dist(circles_meet(p0, big_r, q, l), c0) < 1e-12);
    let p = plan(&m);
    assert_eq!(p.clusters(), 0);
    let frames = run(
        Interpreter::new(p),
        Options::default(),
        &sweep_inputs(&m, Some(361)),
    );
    let lever = m.bodies.iter().position(|b| b.name == "lever").unwrap();
    let lever0 = (c0[1] - q[1]).atan2(c0[0] - q[0]);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for f in &frames {
        let theta = f.inputs[0];
        assert_eq!(f.status, FrameStatus::Solved, "theta {theta}");
        let phi = phi0 + theta.to_radians();
        let pin = [o[0] + r * phi.cos(), o[1] + r * phi.sin()];
        let c = circles_meet(pin, big_r, q, l);
        let got = marker_at(&m, &f.poses, m.find_marker("lever.C").unwrap());
        assert!(dist(got, c) < 1e-12, "C {got:?} vs {c:?} at {theta}");
        let turn = f.poses[lever].rot.s.atan2(f.poses[lever].rot.c);
        let want = (c[1] - q[1]).atan2(c[0] - q[0]) - lever0;
        assert!(
            (turn - want).abs() < 1e-12,
            "lever turned {turn} vs {want} at {theta}"
        );
        assert!(max_relative_residual(&m, &f.poses, &f.inputs) < 1e-12);
        // The pin's angle about C, from C's dir turned with the lever.
        let dir = f.poses[lever].world_dir(m.marker(m.find_marker("lever.C").unwrap()).unit_dir().unwrap());
        let v = [pin[0] - c[0], pin[1] - c[1]];
        let angle = (dir[0] * v[1] - dir[1] * v[0])
            .atan2(dir[0] * v[0] + dir[1] * v[1])
            .to_degrees();
        (lo, hi) = (lo.min(angle), hi.max(angle));
    }
    // The file says the pin swings between about -33.4° and 12.6°, inside
    // its ends [-40, 20].
    assert!((lo + 33.4).abs() < 0.05 && (hi - 12.6).abs() < 0.05, "{lo} {hi}");
}

#[test]
fn an_arc_s_end_is_a_limit_the_search_lands_on() {
    let short = text("arc_yoke").replace("ends = [-25.0, 25.0]", "ends = [-15.0, 15.0]");
    let m = load_str("short.toml", &short, Format::Toml).unwrap();
    let (r, phi0, big_r) = yoke_dims(&m);
    // The pin's angle about C from its dir (−1, 0) is −asin(r sin φ / R):
    // it reaches the end −15° where r sin φ = R sin 15°.
    let landing = ((big_r * 15f64.to_radians().sin() / r).asin() - phi0).to_degrees();
    let search = Options {
        breaking: BreakPolicy::Search,
        ..Options::default()
    };
    let mut d = Driver::new(Interpreter::new(plan(&m)), search);
    let FrameStatus::Searched { brk, .. } = d.frame(&[40.0]) else {
        panic!("expected the search to stop at the arc's end");
    };
    assert_eq!(brk.kind, BreakKind::PastSlotEnd);
    let angle = |theta: f64| (r * (phi0 + theta.to_radians()).sin() / big_r).asin();
    let gap = big_r * (angle(40.0) - 15f64.to_radians());
    assert!((brk.gap - gap).abs() < 1e-12, "gap {} vs {gap}", brk.gap);
    let got = d.inputs()[0];
    assert!(
        (got - landing).abs() < 1e-8,
        "searched to {got}, the end at {landing}"
    );
    assert!(max_relative_residual(&m, d.poses(), d.inputs()) < 1e-12);
    // Limited, it holds the last pose within the arc; stretched, the pin
    // runs on round the circle past the end.
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    assert!(d.frame(&[10.0]).is_solved());
    assert!(matches!(d.frame(&[40.0]), FrameStatus::Limited { .. }));
    assert_eq!(d.inputs(), &[10.0]);
    let stretch = Options {
        breaking: BreakPolicy::Stretch,
        ..Options::default()
    };
    let mut d = Driver::new(Interpreter::new(plan(&m)), stretch);
    assert!(matches!(d.frame(&[40.0]), FrameStatus::Stretched { .. }));
    assert!(max_relative_residual(&m, d.poses(), d.inputs()) < 1e-12);
}

#[test]
fn the_arc_pushes_along_its_radius_and_the_crank_holds_the_yoke() {
    // A force F = −50 along x on the yoke: the crank holds it with
    // T = −F·dx/dθ (per radian), x the yoke's centre; the arc's force on
    // the pin is along the radius through it and passes F on (the rail
    // only pushes square to x).
    let loaded = format!(
        "{}\n[loads.push]\nkind = \"force\"\nmarker = \"yoke.Y\"\nforce = [-50.0, 0.0]\n",
        text("arc_yoke")
    );
    let m = load_str("loaded.toml", &loaded, Format::Toml).unwrap();
    let (r, phi0, big_r) = yoke_dims(&m);
    let fp = force_plan(&m).unwrap();
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    for k in 0..36 {
        let theta = 10.0 * k as f64 + 5.0;
        assert!(d.frame(&[theta]).is_solved());
        let rx = reactions(&m, &fp, d.poses(), None).unwrap();
        let q = input_forces(&m, d.solver(), d.state(), d.inputs(), None).unwrap()[0];
        let torque = 50.0 * yoke_centre(r, big_r, phi0 + theta.to_radians()).1;
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
        let pin = marker_at(&m, d.poses(), m.find_marker("crank.P").unwrap());
        let centre = marker_at(&m, d.poses(), m.find_marker("yoke.C").unwrap());
        let radius = [pin[0] - centre[0], pin[1] - centre[1]];
        let across = (slot[0] * radius[1] - slot[1] * radius[0]) / big_r;
        assert!(across.abs() < 1e-9, "along the radius: {slot:?} at {theta}");
        assert!(
            (slot[0] + 50.0).abs() < 1e-9,
            "the arc passes the push on: {slot:?}"
        );
        assert!(rx.residual < 1e-9);
    }
}

#[test]
fn pure_newton_solves_the_on_circle_equation_to_the_plan_s_poses() {
    for name in ["arc_yoke", "curved_lever"] {
        let m = load(name);
        let requested = sweep_inputs(&m, Some(721));
        let newton = run(PureNewton::new(&m), Options::default(), &requested);
        let planned = run(Interpreter::new(plan(&m)), Options::default(), &requested);
        for (i, (n, p)) in newton.iter().zip(&planned).enumerate() {
            assert!(n.status.is_solved() && p.status.is_solved(), "{name} frame {i}");
            assert!(max_relative_residual(&m, &n.poses, &n.inputs) <= 1e-9);
            for (a, b) in n.poses.iter().zip(&p.poses) {
                let d = (a.at[0] - b.at[0]).abs().max((a.at[1] - b.at[1]).abs());
                let d = d.max((a.rot.c - b.rot.c).abs()).max((a.rot.s - b.rot.s).abs());
                assert!(d <= 1e-9 * m.size(), "{name} frame {i}: {d:e}");
            }
        }
    }
}

#[test]
fn an_arc_slot_s_bad_radius_centre_or_ends_are_errors() {
    let base = text("curved_lever");
    let err = |from: &str, to: &str| {
        let t = base.replace(from, to);
        assert_ne!(t, base, "{from}");
        load_str("bad.toml", &t, Format::Toml).unwrap_err().to_string()
    };
    let e = err("radius = 3.5", "radius = 3.4");
    assert!(
        e.contains("joint `S`")
            && e.contains("crank.P")
            && e.contains("lever.C")
            && e.contains("not its radius 3.4"),
        "{e}"
    );
    assert!(e.contains("bad.toml:"), "a location: {e}");
    let e = err("radius = 3.5", "radius = -3.5");
    assert!(e.contains("must be positive"), "{e}");
    let e = err("ends = [-40.0, 20.0]", "ends = [-200.0, 170.0]");
    assert!(e.contains("at most a turn"), "{e}");
    let e = err("ends = [-40.0, 20.0]", "ends = [5.0, 20.0]");
    assert!(
        e.contains("outside its ends") && e.contains("about the slot's centre"),
        "{e}"
    );
    let e = err(
        "C = { at = [3.3307433592589737, 2.9243966127774184], dir = [-0.8087838169311353, -0.5881060597122799] }",
        "C = [3.3307433592589737, 2.9243966127774184]",
    );
    assert!(
        e.contains("arc slot is its centre") && e.contains("lever.C"),
        "{e}"
    );
}

#[test]
fn a_running_arc_yoke_press_s_input_power_is_its_energy_s_rate() {
    // mechanisms/loads/arc_yoke_press.toml at a constant 2 rad/s: the
    // input power Q·ω, Q from the reactions (each body's equilibrium, the
    // arc's radial force among them), equals dE/dt, E the kinetic,
    // gravity's, the press's and the spring's energy (no damper), dE/dθ
    // by a fourth-order central difference of E along the crank angle.
    use dofplan::forces::planar::Moving;
    let m = dofplan_tests::load("loads/arc_yoke_press");
    let interp = Interpreter::new(plan(&m));
    let fp = force_plan(&m).unwrap();
    let w = 2.0f64;
    let rates = [w.to_degrees()];
    let mut d = Driver::new(interp.clone(), Options::default());
    let mut e_at = |theta: f64| {
        assert!(d.frame(&[theta]).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), &rates, &[0.0]).unwrap();
        crate::forces::energy(&m, &jets).0
    };
    let mut d2 = Driver::new(interp.clone(), Options::default());
    let h = 0.01f64;
    let (mut largest, mut worst) = (0.0f64, 0.0f64);
    for k in 0..36 {
        let theta = 10.0 * k as f64 + 3.0;
        let mut e = |dt: f64| e_at(theta + dt);
        let de_dtheta = (-e(2.0 * h) + 8.0 * e(h) - 8.0 * e(-h) + e(-2.0 * h)) / (12.0 * h.to_radians());
        assert!(d2.frame(&[theta]).is_solved());
        let jets = interp.rates(d2.state(), d2.inputs(), &rates, &[0.0]).unwrap();
        let rx = reactions(&m, &fp, d2.poses(), Some(&jets)).unwrap();
        let moving = Moving {
            rates: &rates,
            accelerations: &[0.0],
        };
        let q = input_forces(&m, d2.solver(), d2.state(), d2.inputs(), Some(moving)).unwrap()[0];
        assert!(
            (rx.inputs[0] - q).abs() < 1e-9 * q.abs().max(1.0),
            "{} vs {q}",
            rx.inputs[0]
        );
        let (input, balance) = (rx.inputs[0] * w, de_dtheta * w);
        largest = largest.max(input.abs());
        worst = worst.max((input - balance).abs());
    }
    assert!(largest > 10.0, "the loads do work: {largest}");
    assert!(worst < 1e-8 * largest, "worst {worst:e} of {largest}");
}
