//! Breaking policies against closed-form break points.
//!
//! `rocker_rocker` is a non-Grashof four-bar whose input link cannot turn
//! fully: it assembles for θ ∈ [θ_lo, θ_hi], the ends being the poses where
//! coupler and output rocker are stretched out (|BD| = b + c). The break
//! angles and the gaps beyond them are computed here from the mechanism's
//! own marker coordinates (law of cosines in triangle ABD) and compared with
//! what the limit, search and stretch policies report, for the plan
//! interpreter and for the compiled plan (typed and by name).

use dofplan::interp::Interpreter;
use dofplan::model::Mechanism;
use dofplan::plan::{Plan, StepKind};
use dofplan::simulate::{marker_at, max_relative_residual, residuals, run, run_animate, sweep_inputs};
use dofplan_generated::rocker_rocker;
use dofplan_runtime::{
    Animate, BranchPolicy, BreakKind, BreakPolicy, Ctx, Driver, FrameStatus, Options, Pose, StepId,
};
use dofplan_tests::{load, plan};

use dofplan_tests::vec2::{add, dist, rotate, sub, P};

/// Tolerance on break angles (degrees) and gaps (length units).
const TOL: f64 = 1e-9;

/// `v` turned by `degrees` counter-clockwise.
fn rotate_deg(v: P, degrees: f64) -> P {
    rotate(v, degrees.to_radians())
}

/// Drawn (= local) position of the marker "body.marker".
fn drawn(m: &Mechanism, name: &str) -> P {
    m.marker(m.find_marker(name).unwrap_or_else(|| panic!("no marker {name}")))
        .at
}

/// World position of the marker "body.marker" in `poses`.
fn at(m: &Mechanism, poses: &[Pose], name: &str) -> P {
    marker_at(m, poses, m.find_marker(name).unwrap())
}

/// The rocker-rocker's geometry and break points, from its markers.
struct Closed {
    /// Ground pivot of the input link, and its drawn pin.
    a_pivot: P,
    b0: P,
    /// Ground pivot of the output rocker.
    d_pivot: P,
    /// Coupler |BC| and output rocker |CD|.
    b: f64,
    c: f64,
    /// Break angles of the input θ (degrees, relative to the drawn pose).
    lo: f64,
    hi: f64,
}

impl Closed {
    fn new(m: &Mechanism) -> Closed {
        let a_pivot = drawn(m, "ground.A");
        let d_pivot = drawn(m, "ground.D");
        let b0 = drawn(m, "input.B");
        let c0 = drawn(m, "coupler.C");
        assert_eq!(a_pivot, drawn(m, "input.A"));
        assert_eq!(b0, drawn(m, "coupler.B"));
        assert_eq!(c0, drawn(m, "output.C"));
        let a = dist(b0, a_pivot);
        let b = dist(c0, b0);
        let c = dist(d_pivot, c0);
        let d = dist(d_pivot, a_pivot);
        // Drawn input angle, measured from the ground line A → D.
        let ad = sub(d_pivot, a_pivot);
        let ab = sub(b0, a_pivot);
        let phi0 = (ab[1].atan2(ab[0]) - ad[1].atan2(ad[0])).to_degrees();
        // Stretched (|BD| = b + c) in triangle ABD.
        let cos_star = (a * a + d * d - (b + c).powi(2)) / (2.0 * a * d);
        let phi_star = cos_star.acos().to_degrees();
        // The folded break |BD| = |b − c| is out of reach (|BD| ≥ d − a).
        assert!((b - c).abs() < d - a, "rocker_rocker: folded break reachable");
        Closed {
            a_pivot,
            b0,
            d_pivot,
            b,
            c,
            lo: -phi_star - phi0,
            hi: phi_star - phi0,
        }
    }

    /// The input link's pin at input θ (degrees).
    fn pin(&self, theta: f64) -> P {
        add(self.a_pivot, rotate_deg(sub(self.b0, self.a_pivot), theta))
    }

    /// How far circle(B, b) and circle(D, c) are apart at input θ.
    fn gap(&self, theta: f64) -> f64 {
        dist(self.pin(theta), self.d_pivot) - (self.b + self.c)
    }

    fn assembles(&self, theta: f64) -> bool {
        (self.lo..=self.hi).contains(&theta)
    }

    /// Where a search toward `theta` lands: the break point on its side.
    fn landing(&self, theta: f64) -> f64 {
        if theta > self.hi {
            self.hi
        } else {
            assert!(theta < self.lo);
            self.lo
        }
    }
}

/// The plan's circle–circle step (the only one that can break) and the
/// joint it serves.
fn breaking_step(p: &Plan) -> (StepId, String) {
    let ids: Vec<usize> = (0..p.steps.len())
        .filter(|&i| matches!(p.steps[i].kind, StepKind::CircleCircle { .. }))
        .collect();
    assert_eq!(ids.len(), 1, "rocker_rocker has one intersection step");
    let step = &p.steps[ids[0]];
    assert_eq!(step.serves.len(), 1);
    (ids[0] as StepId, step.serves[0].clone())
}

fn options(breaking: BreakPolicy) -> Options {
    Options {
        breaking,
        ..Options::default()
    }
}

/// Every back end at the drawn pose: the interpreter, the typed compiled
/// plan, and the compiled plan picked by name.
fn drivers(m: &Mechanism, opts: Options) -> Vec<(&'static str, Box<dyn Animate>)> {
    vec![
        (
            "interpreted",
            Box::new(Driver::new(Interpreter::new(plan(m)), opts)),
        ),
        ("compiled", Box::new(Driver::new(rocker_rocker::Plan, opts))),
        (
            "compiled by name",
            dofplan_generated::driver("rocker_rocker", opts).expect("rocker_rocker is compiled"),
        ),
    ]
}

/// Bit-for-bit equality of two sets of poses.
fn same_bits(a: &[Pose], b: &[Pose]) -> bool {
    let bits = |p: &Pose| [p.at[0], p.at[1], p.rot.c, p.rot.s].map(f64::to_bits);
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| bits(x) == bits(y))
}

#[test]
fn break_angles_match_the_law_of_cosines() {
    let m = load("rocker_rocker");
    let cf = Closed::new(&m);
    // The header's rounded values, as a check on the derivation above.
    assert!((cf.hi - 45.5224878141).abs() < 1e-9, "theta_hi = {}", cf.hi);
    assert!((cf.lo + 105.5224878141).abs() < 1e-9, "theta_lo = {}", cf.lo);
    // At the break points the circles are exactly tangent.
    assert!(cf.gap(cf.hi).abs() < 1e-12 && cf.gap(cf.lo).abs() < 1e-12);
    assert!(cf.gap(cf.hi + 1e-3) > 0.0 && cf.gap(cf.hi - 1e-3) < 0.0);
    assert!(cf.gap(cf.lo - 1e-3) > 0.0 && cf.gap(cf.lo + 1e-3) < 0.0);
}

#[test]
fn search_lands_on_the_closed_form_break_angles() {
    let m = load("rocker_rocker");
    let cf = Closed::new(&m);
    let (step, _) = breaking_step(&plan(&m));
    for (backend, mut driver) in drivers(&m, options(BreakPolicy::Search)) {
        for request in [60.0, 100.0, -120.0, -170.0] {
            let last = driver.inputs()[0];
            let status = driver.frame(&[request]);
            let what = format!("rocker_rocker ({backend}) {last} -> {request}");
            let FrameStatus::Searched { brk, reached } = status else {
                panic!("{what}: {status:?}, expected searched");
            };
            assert_eq!(brk.step, step, "{what}: breaking step");
            assert_eq!(brk.kind, BreakKind::CirclesApart, "{what}");
            assert!(
                (brk.gap - cf.gap(request)).abs() <= TOL,
                "{what}: gap {} vs {}",
                brk.gap,
                cf.gap(request)
            );
            let got = driver.inputs()[0];
            let expected = cf.landing(request);
            eprintln!(
                "{what}: searched to {got:.12} (reached {reached:.9}), closed form {expected:.12}, \
                 diff {:e}",
                got - expected
            );
            assert!(
                (got - expected).abs() <= TOL,
                "{what}: reached {got}, break at {expected}"
            );
            // `reached` is the fraction of the way from the last input.
            let along = last + reached * (request - last);
            assert!(
                (got - along).abs() <= 1e-12 * request.abs().max(1.0),
                "{what}: reached {reached}"
            );
            // The pose at the break point holds every joint, stretched out.
            let r = max_relative_residual(&m, driver.poses(), driver.inputs());
            assert!(r <= 1e-9, "{what}: relative residual {r:e}");
            let b = at(&m, driver.poses(), "input.B");
            assert!(dist(b, cf.pin(got)) <= TOL, "{what}: input pin");
            let span = dist(b, cf.d_pivot) - (cf.b + cf.c);
            assert!(span.abs() <= TOL, "{what}: |BD| − (b + c) = {span:e}");
        }
    }
}

#[test]
fn limit_keeps_the_last_valid_pose_bit_for_bit() {
    let m = load("rocker_rocker");
    let cf = Closed::new(&m);
    let (step, _) = breaking_step(&plan(&m));
    for (backend, mut driver) in drivers(&m, options(BreakPolicy::Limit)) {
        for (valid, beyond) in [(40.0, 60.0), (45.0, 100.0), (-100.0, -110.0), (-105.0, -180.0)] {
            assert!(cf.assembles(valid) && !cf.assembles(beyond));
            assert_eq!(
                driver.frame(&[valid]),
                FrameStatus::Solved,
                "{backend} at {valid}"
            );
            let poses = driver.poses().to_vec();
            let status = driver.frame(&[beyond]);
            let what = format!("rocker_rocker ({backend}) {valid} -> {beyond}");
            let FrameStatus::Limited { brk } = status else {
                panic!("{what}: {status:?}, expected limited");
            };
            assert_eq!(brk.step, step, "{what}: breaking step");
            assert_eq!(brk.kind, BreakKind::CirclesApart, "{what}");
            assert!(
                (brk.gap - cf.gap(beyond)).abs() <= TOL,
                "{what}: gap {} vs {}",
                brk.gap,
                cf.gap(beyond)
            );
            assert_eq!(driver.inputs(), [valid], "{what}: inputs");
            assert!(same_bits(driver.poses(), &poses), "{what}: the pose moved");
            // Asking again changes nothing either.
            assert_eq!(driver.frame(&[beyond]), status, "{what}: again");
            assert!(same_bits(driver.poses(), &poses), "{what}: the pose moved");
        }
    }
}

#[test]
fn a_break_leaves_the_compiled_state_untouched() {
    let m = load("rocker_rocker");
    let cf = Closed::new(&m);
    let (step, _) = breaking_step(&plan(&m));
    let mut state = rocker_rocker::State::DRAWN;
    let before = state;
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    let brk = rocker_rocker::solve(&mut state, &[60.0], &mut ctx).unwrap_err();
    assert_eq!(state, before);
    assert_eq!(brk.step, step);
    assert!((brk.gap - cf.gap(60.0)).abs() <= TOL);
}

#[test]
fn stretch_applies_the_input_and_reports_the_closed_form_gap() {
    let m = load("rocker_rocker");
    let cf = Closed::new(&m);
    let (step, joint) = breaking_step(&plan(&m));
    let size = m.size();
    for (backend, mut driver) in drivers(&m, options(BreakPolicy::Stretch)) {
        for request in [60.0, 100.0, -150.0, -110.0] {
            let status = driver.frame(&[request]);
            let what = format!("rocker_rocker ({backend}) stretched to {request}");
            let FrameStatus::Stretched { step: s, residual } = status else {
                panic!("{what}: {status:?}, expected stretched");
            };
            let gap = cf.gap(request);
            eprintln!(
                "{what}: residual {residual:.12}, closed-form gap {gap:.12}, diff {:e}",
                residual - gap
            );
            assert_eq!(s, step, "{what}: stretched step");
            assert!(gap > 0.0 && residual > 0.0);
            assert!(
                (residual - gap).abs() <= TOL,
                "{what}: residual {residual} vs gap {gap}"
            );
            // The input is applied: the pin is where the crank puts it.
            assert_eq!(driver.inputs(), [request], "{what}: inputs");
            let b = at(&m, driver.poses(), "input.B");
            assert!(dist(b, cf.pin(request)) <= TOL, "{what}: input pin");
            // Every joint holds but the stretched one, which is open by the gap.
            for r in residuals(&m, driver.poses(), driver.inputs()) {
                if r.name == joint {
                    assert!(
                        (r.value - gap).abs() <= TOL,
                        "{what}: {} open by {} not {gap}",
                        r.name,
                        r.value
                    );
                } else {
                    assert!(r.value <= 1e-9 * size, "{what}: {} off by {:e}", r.name, r.value);
                }
            }
        }
        // Back in range the pose is exactly the one a fresh driver reaches.
        assert_eq!(driver.frame(&[30.0]), FrameStatus::Solved, "{backend} back at 30");
        let mut fresh = Driver::new(Interpreter::new(plan(&m)), Options::default());
        assert_eq!(fresh.frame(&[30.0]), FrameStatus::Solved);
        for (p, q) in driver.poses().iter().zip(fresh.poses()) {
            let d = dist(p.at, q.at)
                .max((p.rot.c - q.rot.c).abs())
                .max((p.rot.s - q.rot.s).abs());
            assert!(d <= 1e-12, "{backend}: after stretching, 30 lands {d:e} off");
        }
    }
}

#[test]
fn a_search_sweep_solves_inside_and_lands_on_the_break_points_outside() {
    let m = load("rocker_rocker");
    let cf = Closed::new(&m);
    let (step, _) = breaking_step(&plan(&m));
    let requested = sweep_inputs(&m, None);
    let opts = options(BreakPolicy::Search);
    let interpreted = run(Interpreter::new(plan(&m)), opts, &requested);
    let mut compiled = dofplan_generated::driver("rocker_rocker", opts).unwrap();
    let compiled = run_animate(compiled.as_mut(), &requested);
    let inside = requested.iter().filter(|r| cf.assembles(r[0])).count();
    assert_eq!(inside, 151, "frames -105..45 assemble");
    for (backend, frames) in [("interpreted", interpreted), ("compiled", compiled)] {
        let mut solved = 0;
        for (i, f) in frames.iter().enumerate() {
            let v = f.requested[0];
            let what = format!("rocker_rocker ({backend}) frame {i} (theta = {v})");
            let r = max_relative_residual(&m, &f.poses, &f.inputs);
            assert!(r <= 1e-9, "{what}: relative residual {r:e}");
            if cf.assembles(v) {
                assert_eq!(f.status, FrameStatus::Solved, "{what}");
                assert_eq!(f.inputs, f.requested, "{what}");
                solved += 1;
                continue;
            }
            let FrameStatus::Searched { brk, reached } = f.status else {
                panic!("{what}: {:?}, expected searched", f.status);
            };
            assert_eq!(brk.step, step, "{what}: breaking step");
            let landing = cf.landing(v);
            assert!(
                (f.inputs[0] - landing).abs() <= TOL,
                "{what}: at {} not {landing}",
                f.inputs[0]
            );
            // The first frame out of range (from the drawn pose, or right
            // after the last assembling frame) travels to the break point.
            let first = i == 0 || cf.assembles(frames[i - 1].requested[0]);
            if first {
                assert!(reached > 0.0 && reached < 1.0, "{what}: reached {reached}");
                eprintln!(
                    "{what}: first out of range, searched to {:.12} (closed form {landing:.12}, diff {:e})",
                    f.inputs[0],
                    f.inputs[0] - landing
                );
            }
        }
        assert_eq!(solved, inside, "{backend}: solved frames");
    }
}

#[test]
fn nearest_and_keep_agree_on_a_smooth_fourbar_sweep() {
    let m = load("fourbar");
    for steps in [None, Some(3601)] {
        let requested = sweep_inputs(&m, steps);
        let mut runs = Vec::new();
        for branch in [BranchPolicy::Keep, BranchPolicy::Nearest] {
            let opts = Options {
                branch,
                ..Options::default()
            };
            runs.push((
                branch,
                "interpreted",
                run(Interpreter::new(plan(&m)), opts, &requested),
            ));
            let mut driver = Driver::new(dofplan_generated::fourbar::Plan, opts);
            runs.push((branch, "compiled", run_animate(&mut driver, &requested)));
        }
        let (_, _, reference) = &runs[0];
        for (branch, backend, frames) in &runs {
            assert_eq!(frames.len(), requested.len());
            for (i, (f, r)) in frames.iter().zip(reference).enumerate() {
                assert_eq!(
                    f.status,
                    FrameStatus::Solved,
                    "fourbar ({branch:?}, {backend}) frame {i}"
                );
                assert!(
                    same_bits(&f.poses, &r.poses),
                    "fourbar ({branch:?}, {backend}) frame {i}: differs from Keep (interpreted)"
                );
            }
        }
    }
}
