//! A mechanism never jumps to a circuit it cannot reach.
//!
//! Driven past an assembly limit, a mechanism is held; a later frame may
//! resume only when its input comes back into the interval it left. Two
//! mechanisms whose inputs assemble again further along, on another
//! circuit, are swept past their limits under every breaking policy, in
//! both back ends and in batches:
//! - `rocker_rocker`, a Grashof-less double rocker whose input assembles for
//!   θ ∈ [θ_lo, θ_hi] and so again for θ ∈ [θ_lo + 360°, θ_hi + 360°];
//! - `tests/fixtures/slider_driven.toml`, a slider-crank driven by its
//!   slider, whose input interval has two disjoint pieces (the rod on
//!   either side of the crank);
//! - `tests/fixtures/narrow_gap.toml`, a four-bar a hair past its change
//!   point, whose crank stops at two dead points closer together than a
//!   sweep's step: frames on both sides of the gap assemble.
//!
//! Where a frame assembles and where it should be is computed here from the
//! files' marker coordinates, not from dofplan's output.

use dofplan::interp::Interpreter;
use dofplan::load_file;
use dofplan::model::Mechanism;
use dofplan::simulate::{marker_at, max_relative_residual};
use dofplan_runtime::{
    Animate, Batch, BreakKind, BreakPolicy, Ctx, Driver, FrameStatus, Options, Pose, Solver, StartPolicy,
};
use dofplan_tests::vec2::{add, dist, rotate, sub, P};
use dofplan_tests::{load, plan};

fn fixture(name: &str) -> Mechanism {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/{name}.toml"));
    load_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

fn marker(m: &Mechanism, name: &str) -> P {
    m.marker(m.find_marker(name).unwrap_or_else(|| panic!("no marker {name}")))
        .at
}

fn at(m: &Mechanism, poses: &[Pose], name: &str) -> P {
    marker_at(m, poses, m.find_marker(name).unwrap())
}

fn options(breaking: BreakPolicy) -> Options {
    Options {
        breaking,
        ..Options::default()
    }
}

const POLICIES: [BreakPolicy; 3] = [BreakPolicy::Limit, BreakPolicy::Search, BreakPolicy::Stretch];

/// The interpreter and the compiled plan (by name) of `name`.
fn drivers(name: &str, m: &Mechanism, opts: Options) -> Vec<(&'static str, Box<dyn Animate>)> {
    vec![
        (
            "interpreted",
            Box::new(Driver::new(Interpreter::new(plan(m)), opts)),
        ),
        (
            "compiled",
            dofplan_generated::driver(name, opts).expect("compiled"),
        ),
    ]
}

/// The rocker-rocker's input pin and the condition for it to assemble.
struct RockerRocker {
    a: P,
    b0: P,
    d: P,
    /// Coupler and output rocker lengths.
    b: f64,
    c: f64,
}

impl RockerRocker {
    fn new(m: &Mechanism) -> Self {
        let (a, b0, d, c0) = (
            marker(m, "ground.A"),
            marker(m, "input.B"),
            marker(m, "ground.D"),
            marker(m, "coupler.C"),
        );
        RockerRocker {
            a,
            b0,
            d,
            b: dist(c0, b0),
            c: dist(d, c0),
        }
    }
    fn pin(&self, theta: f64) -> P {
        add(self.a, rotate(sub(self.b0, self.a), theta.to_radians()))
    }
    /// circle(B, b) and circle(D, c) meet.
    fn assembles(&self, theta: f64) -> bool {
        let bd = dist(self.pin(theta), self.d);
        bd <= self.b + self.c && bd >= (self.b - self.c).abs()
    }
    /// The interval containing the drawn pose (θ = 0), to 1e-6°.
    fn interval(&self) -> (f64, f64) {
        assert!(self.assembles(0.0));
        let edge = |dir: f64| {
            let (mut lo, mut hi) = (0.0, 180.0);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                if self.assembles(dir * mid) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            dir * lo
        };
        (edge(-1.0), edge(1.0))
    }
}

/// Whether a frame met its input (solved), and whether it moved at all.
fn met(status: &FrameStatus) -> bool {
    status.is_solved()
}

#[test]
fn a_double_rocker_swept_past_its_limit_stays_held_where_it_would_assemble_on_another_circuit() {
    let m = load("rocker_rocker");
    let rr = RockerRocker::new(&m);
    let (lo, hi) = rr.interval();
    // The sweep leaves the interval at θ_hi and meets inputs that assemble
    // again, a turn later: the jump the driver must not make.
    let sweep: Vec<f64> = (0..=720).map(f64::from).collect();
    let again: Vec<usize> = (0..sweep.len())
        .filter(|&k| sweep[k] > hi && rr.assembles(sweep[k]))
        .collect();
    assert!(
        again.len() > 100
            && again
                .iter()
                .all(|&k| (sweep[k] - lo).rem_euclid(360.0) <= hi - lo + 1e-9),
        "the sweep reaches the interval a turn on ({} frames)",
        again.len()
    );
    for policy in POLICIES {
        for (backend, mut d) in drivers("rocker_rocker", &m, options(policy)) {
            let what = format!("{backend} {policy:?}");
            let mut held: Option<Vec<Pose>> = None;
            for (k, &theta) in sweep.iter().enumerate() {
                let status = d.frame(&[theta]);
                if theta <= hi {
                    assert!(met(&status), "{what}: θ {theta} is in the interval: {status:?}");
                    let r = max_relative_residual(&m, d.poses(), d.inputs());
                    assert!(r <= 1e-9, "{what}: θ {theta}: residual {r:e}");
                    assert!(dist(at(&m, d.poses(), "input.B"), rr.pin(theta)) <= 1e-9);
                    continue;
                }
                assert!(
                    !met(&status),
                    "{what}: θ {theta} is past the limit: solved on another circuit"
                );
                if again.contains(&k) {
                    // It would assemble: the report says why it is not taken.
                    match status {
                        FrameStatus::Limited { brk } => {
                            assert_eq!(brk.kind, BreakKind::OtherCircuit, "{what}: θ {theta}")
                        }
                        FrameStatus::Searched { brk, reached } => {
                            assert_eq!(brk.kind, BreakKind::OtherCircuit, "{what}: θ {theta}");
                            assert_eq!(reached, 0.0, "{what}: θ {theta}: stays at the break point");
                        }
                        FrameStatus::Stretched { .. }
                        | FrameStatus::Unreached { .. }
                        | FrameStatus::Solved => {
                            panic!("{what}: θ {theta}: {status:?}, expected held")
                        }
                    }
                }
                if policy != BreakPolicy::Stretch {
                    // Held: every frame past the limit shows one pose, which
                    // lies on the interval's edge side of the drawn circuit.
                    let poses = d.poses().to_vec();
                    let first = held.get_or_insert_with(|| poses.clone());
                    assert_eq!(&poses, first, "{what}: θ {theta}: the held pose moved");
                    let shown = d.inputs()[0];
                    assert!(shown <= hi + 1e-9 && shown >= hi - 1.0, "{what}: held at {shown}");
                }
            }
        }
    }
}

#[test]
fn a_double_rocker_resumes_when_its_input_comes_back_into_the_interval() {
    let m = load("rocker_rocker");
    let rr = RockerRocker::new(&m);
    let (lo, hi) = rr.interval();
    // Out past θ_hi, back in, out past θ_lo, back in: one degree at a time.
    let mut path: Vec<f64> = Vec::new();
    path.extend((0..=100).map(f64::from));
    path.extend((-150..100).rev().map(f64::from));
    path.extend((-150..=0).map(f64::from));
    for policy in POLICIES {
        for (backend, mut d) in drivers("rocker_rocker", &m, options(policy)) {
            for &theta in &path {
                let status = d.frame(&[theta]);
                let inside = theta >= lo && theta <= hi;
                assert_eq!(
                    met(&status),
                    inside,
                    "{backend} {policy:?}: θ {theta}: {status:?}"
                );
                if inside {
                    let r = max_relative_residual(&m, d.poses(), d.inputs());
                    assert!(r <= 1e-9, "θ {theta}: residual {r:e}");
                    assert!(dist(at(&m, d.poses(), "input.B"), rr.pin(theta)) <= 1e-9);
                }
            }
        }
    }
}

/// The slider-crank driven by its slider: the slider's x must keep
/// |OC| within [rod − crank, rod + crank].
struct SliderDriven {
    x0: f64,
    e: f64,
    crank: f64,
    rod: f64,
}

impl SliderDriven {
    fn new(m: &Mechanism) -> Self {
        let (o, b, c) = (marker(m, "ground.O"), marker(m, "crank.B"), marker(m, "slider.C"));
        assert_eq!(o, [0.0, 0.0]);
        SliderDriven {
            x0: c[0],
            e: c[1],
            crank: dist(b, o),
            rod: dist(c, b),
        }
    }
    /// The input's two pieces: the drawn one, and its mirror.
    fn pieces(&self) -> [(f64, f64); 2] {
        let near = ((self.rod - self.crank).powi(2) - self.e * self.e).sqrt();
        let far = ((self.rod + self.crank).powi(2) - self.e * self.e).sqrt();
        [(near - self.x0, far - self.x0), (-far - self.x0, -near - self.x0)]
    }
    fn assembles(&self, s: f64) -> bool {
        let oc = (self.x0 + s).hypot(self.e);
        oc >= self.rod - self.crank && oc <= self.rod + self.crank
    }
}

#[test]
fn a_slider_swept_through_the_gap_between_two_pieces_never_reappears_in_the_second() {
    let m = fixture("slider_driven");
    let sd = SliderDriven::new(&m);
    let [(a1, b1), (a2, b2)] = sd.pieces();
    assert!(a1 < 0.0 && 0.0 < b1 && b2 < a1, "pieces {a1}..{b1}, {a2}..{b2}");
    let sweep: Vec<f64> = (0..=200).map(|k| -0.05 * f64::from(k)).collect();
    let second: Vec<f64> = sweep.iter().copied().filter(|&s| s >= a2 && s <= b2).collect();
    assert!(second.len() > 30);
    // The plan itself assembles there (a frame solved on its own from the
    // drawing): only the driver's hold keeps the mechanism from jumping.
    let interp = Interpreter::new(plan(&m));
    for &s in &second {
        assert!(sd.assembles(s));
        let mut state = interp.initial_state();
        let mut ctx = Ctx::new(Default::default(), false);
        assert!(
            interp.solve(&mut state, &[s], &mut ctx).is_ok(),
            "s {s} assembles"
        );
    }
    for policy in POLICIES {
        for (backend, mut d) in drivers("slider_driven", &m, options(policy)) {
            for &s in &sweep {
                let status = d.frame(&[s]);
                assert_eq!(
                    met(&status),
                    s >= a1,
                    "{backend} {policy:?}: s {s} (pieces {a1}..{b1}, {a2}..{b2}): {status:?}"
                );
                if met(&status) {
                    let r = max_relative_residual(&m, d.poses(), d.inputs());
                    assert!(r <= 1e-9, "s {s}: residual {r:e}");
                    // The drawn circuit: the rod stays to the right of the crank.
                    let (b, c) = (at(&m, d.poses(), "crank.B"), at(&m, d.poses(), "slider.C"));
                    assert!(c[0] > b[0], "s {s}: rod flipped");
                }
            }
        }
    }
}

/// Batches give the driver's frames past a limit too, in lanes and in order,
/// on one core and on all.
#[test]
fn batches_hold_past_a_limit_as_the_driver_does() {
    for name in ["rocker_rocker", "slider_driven", "narrow_gap"] {
        let m = if name == "rocker_rocker" {
            load(name)
        } else {
            fixture(name)
        };
        let inputs: Vec<f64> = if name != "slider_driven" {
            (0..4000).map(|k| f64::from(k % 1000) * 0.72).collect()
        } else {
            (0..4000).map(|k| -0.005 * f64::from(k % 2000)).collect()
        };
        let b = m.bodies.len();
        let mut want = vec![Pose::IDENTITY; inputs.len() * b];
        let mut want_status = vec![FrameStatus::Solved; inputs.len()];
        let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
        for (k, x) in inputs.iter().enumerate() {
            want_status[k] = d.frame(&[*x]);
            want[k * b..(k + 1) * b].copy_from_slice(d.poses());
        }
        assert!(
            want_status
                .iter()
                .any(|s| matches!(s, FrameStatus::Limited { brk } if brk.kind == BreakKind::OtherCircuit)),
            "{name}: the sweep meets another circuit"
        );
        let check = |what: &str, out: &[Pose], status: &[FrameStatus]| {
            assert_eq!(status, &want_status[..], "{name} {what}: statuses");
            let close = out.iter().zip(&want).all(|(a, b)| {
                (a.at[0] - b.at[0]).abs() <= 1e-12
                    && (a.at[1] - b.at[1]).abs() <= 1e-12
                    && (a.rot.c - b.rot.c).abs() <= 1e-12
                    && (a.rot.s - b.rot.s).abs() <= 1e-12
            });
            assert!(close, "{name} {what}: poses differ from the driver's");
        };
        let mut out = vec![Pose::IDENTITY; inputs.len() * b];
        let mut status = vec![FrameStatus::Solved; inputs.len()];
        Interpreter::new(plan(&m)).solve_batch(&inputs, &mut out, &mut status);
        check("interpreted", &out, &status);
        dofplan_runtime::batch::solve_batch_parallel(
            &Interpreter::new(plan(&m)),
            &inputs,
            &mut out,
            &mut status,
        );
        check("interpreted, every core", &out, &status);
        dofplan_generated::with_plan!(name, |p| {
            p.solve_batch(&inputs, &mut out, &mut status);
            check("compiled", &out, &status);
            dofplan_runtime::batch::solve_batch_parallel(&p, &inputs, &mut out, &mut status);
            check("compiled, every core", &out, &status);
        })
        .expect("compiled");
    }
}

/// `tests/fixtures/narrow_gap.toml`'s gap in its input where the coupler
/// and the rocker do not meet, from the law of cosines on the file's
/// coordinates: its ends in (0°, 360°), where |BD| = b − c. (The file
/// names its markers as `rocker_rocker` does.)
fn narrow_gap(ng: &RockerRocker) -> (f64, f64) {
    let (ab, ad) = (sub(ng.b0, ng.a), sub(ng.d, ng.a));
    let (r, g) = (dist(ng.b0, ng.a), dist(ng.d, ng.a));
    let half = ((g * g + r * r - (ng.b - ng.c).powi(2)) / (2.0 * g * r))
        .acos()
        .to_degrees();
    let centre = (ad[1].atan2(ad[0]) - ab[1].atan2(ab[0]))
        .to_degrees()
        .rem_euclid(360.0);
    (centre - half, centre + half)
}

/// A gap narrower than the step between two frames, both of which
/// assemble, is found between them: the mechanism stops at its near side,
/// turning forward or back, under every policy, in both back ends.
#[test]
fn a_gap_narrower_than_the_frame_step_is_not_jumped() {
    let m = fixture("narrow_gap");
    let ng = RockerRocker::new(&m);
    let (g0, g1) = narrow_gap(&ng);
    assert!(g1 - g0 < 0.5 && g0 > 269.0 && g1 < 270.0, "the gap: {g0}..{g1}");
    for step in [1.0, 0.5, 3.0, -1.0, -3.0] {
        // Forward, the mechanism stops at g0; back, at g1 − 360°.
        let sweep: Vec<f64> = (0..=(360.0 / f64::abs(step)) as i32)
            .map(|k| step * f64::from(k))
            .collect();
        let edge = if step > 0.0 { g0 } else { g1 - 360.0 };
        let beyond = |t: f64, e: f64| (t - e) * step > 0.0;
        let jumped = sweep.iter().filter(|&&t| beyond(t, edge)).count();
        assert!(jumped > 10, "the sweep goes past the gap");
        for policy in POLICIES {
            for (backend, mut d) in drivers("narrow_gap", &m, options(policy)) {
                let what = format!("{backend} {policy:?} step {step}");
                let mut held: Option<Vec<Pose>> = None;
                for &theta in &sweep {
                    let status = d.frame(&[theta]);
                    if !beyond(theta, edge) {
                        assert!(met(&status), "{what}: θ {theta} is on the circuit: {status:?}");
                        let r = max_relative_residual(&m, d.poses(), d.inputs());
                        assert!(r <= 1e-9, "{what}: θ {theta}: residual {r:e}");
                        assert!(dist(at(&m, d.poses(), "input.B"), ng.pin(theta)) <= 1e-9);
                        continue;
                    }
                    assert!(
                        !met(&status),
                        "{what}: θ {theta} is past the gap: solved on another circuit"
                    );
                    if policy != BreakPolicy::Stretch {
                        let poses = d.poses().to_vec();
                        let first = held.get_or_insert_with(|| poses.clone());
                        assert_eq!(&poses, first, "{what}: θ {theta}: the held pose moved");
                        let shown = d.inputs()[0];
                        assert!(
                            // (Within 1e-6° past it: a step tangent to
                            // round-off counts as met.)
                            (shown - edge).abs() <= step.abs() + 1e-9
                                && !beyond(shown, edge + step.signum() * 1e-6),
                            "{what}: held at {shown}, the gap starts at {edge}"
                        );
                        if policy == BreakPolicy::Search {
                            assert!(
                                (shown - edge).abs() <= 1e-6,
                                "{what}: stopped at {shown}, not {edge}"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// A sweep that starts out of reach has no pose to hold: its frames are
/// unreached until the input enters the range, and the first frame there is
/// the drawn circuit's pose.
#[test]
fn a_sweep_that_starts_out_of_reach_is_unreached_until_it_enters_the_range() {
    let m = fixture("slider_driven");
    let sd = SliderDriven::new(&m);
    let [(a1, b1), _] = sd.pieces();
    let sweep: Vec<f64> = (0..=30).map(|k| -2.0 + 0.1 * f64::from(k)).collect();
    for policy in POLICIES {
        let opts = Options {
            start: StartPolicy::Sweep,
            ..options(policy)
        };
        for (backend, mut d) in drivers("slider_driven", &m, opts) {
            let mut started = false;
            for &s in &sweep {
                let status = d.frame(&[s]);
                let what = format!("{backend} {policy:?}: s {s}");
                if s < a1 {
                    assert!(!started);
                    match status {
                        FrameStatus::Unreached { brk } => {
                            assert_eq!(brk.kind, BreakKind::CirclesApart, "{what}")
                        }
                        // Stretch relaxes the step: a pose, flagged.
                        FrameStatus::Stretched { .. } if policy == BreakPolicy::Stretch => {}
                        _ => panic!("{what}: {status:?}, expected unreached"),
                    }
                } else if s <= b1 {
                    started = true;
                    assert!(status.is_solved(), "{what}: {status:?}");
                    assert_eq!(d.inputs(), &[s]);
                    let r = max_relative_residual(&m, d.poses(), d.inputs());
                    assert!(r <= 1e-9, "{what}: residual {r:e}");
                } else {
                    assert!(!status.is_solved(), "{what}");
                    if policy == BreakPolicy::Search {
                        // The break point, found once: the same for every frame.
                        assert!((d.inputs()[0] - b1).abs() <= 1e-8, "{what}: at {}", d.inputs()[0]);
                    }
                }
            }
            assert!(started, "{backend} {policy:?}");
        }
    }
}

/// A change point is passed, not a limit: the parallelogram's sweep, which
/// goes through both of them, solves every frame, in both back ends.
#[test]
fn a_change_point_is_not_a_limit() {
    let m = load("parallelogram");
    let sweep: Vec<f64> = (0..=720).map(|k| f64::from(k) * 0.5).collect();
    for policy in POLICIES {
        for (backend, mut d) in drivers("parallelogram", &m, options(policy)) {
            for &theta in &sweep {
                let status = d.frame(&[theta]);
                assert!(status.is_solved(), "{backend} {policy:?}: θ {theta}: {status:?}");
            }
        }
    }
}

/// A two-input arm (`tests/fixtures/fivebar_arm.toml`, a five-bar) with both
/// inputs driven together: past its reach at t = 30° it is held, and the
/// half turn on where it would assemble again (|BD| = 2 + 2 sin t ≤ 3,
/// computed here) is another circuit. The way is a line in the plane of the
/// two inputs.
#[test]
fn a_two_input_arm_driven_past_its_reach_stays_held() {
    let m = fixture("fivebar_arm");
    let requests = dofplan::simulate::sweep_inputs(&m, None);
    let assembles = |t: f64| 2.0 + 2.0 * t.to_radians().sin() <= 3.0;
    let t_of = |r: &[f64]| r[0];
    assert!(requests.iter().all(|r| r[1] == -r[0]), "the inputs move together");
    let again = requests
        .iter()
        .filter(|r| t_of(r) > 30.0 && assembles(t_of(r)))
        .count();
    assert!(again > 200, "{again} frames would assemble on another circuit");
    for policy in POLICIES {
        for (backend, mut d) in drivers("fivebar_arm", &m, options(policy)) {
            for r in &requests {
                let t = t_of(r);
                let status = d.frame(r);
                let what = format!("{backend} {policy:?}: t {t}");
                assert_eq!(met(&status), t <= 30.0, "{what}: {status:?}");
                if met(&status) {
                    let res = max_relative_residual(&m, d.poses(), d.inputs());
                    assert!(res <= 1e-9, "{what}: residual {res:e}");
                } else if policy == BreakPolicy::Limit && assembles(t) {
                    let brk = status.brk().expect("held");
                    // At t = 270° the pins meet and the two arms' circles
                    // coincide: said so, and held all the same.
                    let want = if t == 270.0 {
                        BreakKind::CirclesCoincide
                    } else {
                        BreakKind::OtherCircuit
                    };
                    assert_eq!(brk.kind, want, "{what}");
                    assert_eq!(d.inputs(), &[30.0, -30.0], "{what}: held at the last frame");
                }
            }
        }
    }
}

/// A plan that counts its executions.
struct Counting<S> {
    inner: S,
    runs: std::cell::Cell<usize>,
}

impl<S: Solver> Solver for Counting<S> {
    type Pose = S::Pose;
    type State = S::State;
    type Inputs = S::Inputs;
    fn initial_state(&self) -> S::State {
        self.inner.initial_state()
    }
    fn initial_inputs(&self) -> S::Inputs {
        self.inner.initial_inputs()
    }
    fn poses(state: &S::State) -> &[S::Pose] {
        S::poses(state)
    }
    fn solve(
        &self,
        state: &mut S::State,
        inputs: &[f64],
        ctx: &mut Ctx,
    ) -> Result<(), dofplan_runtime::Break> {
        self.runs.set(self.runs.get() + 1);
        self.inner.solve(state, inputs, ctx)
    }
}

/// The checks a hold makes cost a bounded number of plan runs: the
/// rocker-rocker's sweep (−180° … 180°, out of reach at both ends) driven
/// ten times over, each time back from θ = 180° to −180° in one frame, runs
/// the plan at most twice a frame plus one way of at most 64 runs each
/// time the input comes back into the interval.
#[test]
fn holds_cost_a_bounded_number_of_plan_runs() {
    let m = load("rocker_rocker");
    let sweep: Vec<f64> = (0..=360).map(|k| -180.0 + f64::from(k)).collect();
    for policy in [BreakPolicy::Limit, BreakPolicy::Stretch] {
        let solver = Counting {
            inner: Interpreter::new(plan(&m)),
            runs: std::cell::Cell::new(0),
        };
        let mut d = Driver::new(solver, options(policy));
        let mut frames = 0;
        for _ in 0..10 {
            for &theta in &sweep {
                d.frame(&[theta]);
                frames += 1;
            }
        }
        let runs = d.solver().runs.get();
        assert!(
            runs <= 2 * frames + 10 * 64,
            "{policy:?}: {runs} plan runs for {frames} frames"
        );
    }
}
