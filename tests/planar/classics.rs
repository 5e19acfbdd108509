//! The classic mechanisms against their textbook closed forms.
//!
//! Every property is recomputed here from the mechanism's own drawn marker
//! coordinates (link lengths, offsets, pivots, drawn angles are all derived
//! from the loaded `Mechanism`, never copied from solver output) and
//! compared with the solver on every frame of the bundled sweep, for both
//! back ends: the plan interpreter and the plan compiled into
//! `dofplan-generated`.

use dofplan::interp::Interpreter;
use dofplan::model::Mechanism;
use dofplan::plan::StepKind;
use dofplan::simulate::{marker_at, max_relative_residual, run, run_animate, sweep_inputs, Frame};
use dofplan_runtime::{BranchPolicy, FrameStatus, Options};
use dofplan_tests::{bundled, load, plan};

use dofplan_tests::vec2::{add, cross, dist, dot, norm, perp, rotate, scale, sub, unit, P};

/// Tolerance of every closed-form comparison (absolute, in the mechanisms'
/// length units or radians; the bundled mechanisms are a few units across).
const TOL: f64 = 1e-9;

/// Wraps an angle (radians) into [−π, π).
fn wrap(angle: f64) -> f64 {
    (angle + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// Drawn (= local) position of the marker "body.marker".
fn drawn(m: &Mechanism, name: &str) -> P {
    let id = m
        .find_marker(name)
        .unwrap_or_else(|| panic!("{}: no marker {name}", m.name));
    m.marker(id).at
}

/// Unit direction of the marker "body.marker" as drawn.
fn drawn_dir(m: &Mechanism, name: &str) -> P {
    let id = m
        .find_marker(name)
        .unwrap_or_else(|| panic!("{}: no marker {name}", m.name));
    m.marker(id)
        .unit_dir()
        .unwrap_or_else(|| panic!("{}: {name} has no dir", m.name))
}

/// World position of the marker "body.marker" in a solved frame.
fn at(m: &Mechanism, f: &Frame, name: &str) -> P {
    marker_at(m, &f.poses, m.find_marker(name).unwrap())
}

/// Rotation (radians, relative to the drawn pose) of a body in a frame.
fn rotation(m: &Mechanism, f: &Frame, body: &str) -> f64 {
    let b = m.bodies.iter().position(|b| b.name == body).unwrap();
    let r = f.poses[b].rot;
    r.s.atan2(r.c)
}

/// +1 if `x` lies left of the directed line `c1 → c2`, −1 if right.
fn side(c1: P, c2: P, x: P) -> f64 {
    let s = cross(sub(c2, c1), sub(x, c1));
    assert!(s != 0.0, "drawn pose on the centre line");
    s.signum()
}

/// The intersection of circle(`c1`, `r1`) and circle(`c2`, `r2`) on the
/// side `sign` of `c1 → c2`: law of cosines for the foot of the chord along
/// the centre line, Pythagoras for the half-chord.
fn circles(c1: P, r1: f64, c2: P, r2: f64, sign: f64) -> P {
    let d = dist(c1, c2);
    let along = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h2 = r1 * r1 - along * along;
    assert!(h2 > 0.0, "circles do not meet (h² = {h2})");
    let e = unit(sub(c2, c1));
    add(add(c1, scale(e, along)), scale(perp(e), sign * h2.sqrt()))
}

/// The rigid motion taking drawn points `p0`, `q0` to `p`, `q` (which must
/// be as far apart), applied to the drawn point `x0`.
fn carry(p0: P, q0: P, p: P, q: P, x0: P) -> P {
    let (l, w) = (sub(q0, p0), sub(q, p));
    let angle = cross(l, w).atan2(dot(l, w));
    add(p, rotate(sub(x0, p0), angle))
}

/// Both back ends over `requested`: (label, frames).
fn both_on(m: &Mechanism, opts: Options, requested: &[Vec<f64>]) -> Vec<(&'static str, Vec<Frame>)> {
    let interpreted = run(Interpreter::new(plan(m)), opts, requested);
    let mut driver = dofplan_generated::driver(&m.name, opts)
        .unwrap_or_else(|| panic!("{} is not compiled into dofplan-generated", m.name));
    let compiled = run_animate(driver.as_mut(), requested);
    vec![("interpreted", interpreted), ("compiled", compiled)]
}

/// Loads `name` and runs its bundled sweep on both back ends (default
/// options), checking that every frame solved and holds its joints.
fn solved_sweep(name: &str) -> (Mechanism, Vec<(&'static str, Vec<Frame>)>) {
    let m = load(name);
    let requested = sweep_inputs(&m, None);
    assert!(requested.len() > 1, "{name} has a sweep");
    let runs = both_on(&m, Options::default(), &requested);
    for (backend, frames) in &runs {
        assert_eq!(frames.len(), requested.len());
        for (i, f) in frames.iter().enumerate() {
            assert_eq!(f.status, FrameStatus::Solved, "{name} ({backend}) frame {i}");
            assert_eq!(f.inputs, f.requested, "{name} ({backend}) frame {i}");
            let r = max_relative_residual(&m, &f.poses, &f.inputs);
            assert!(r <= 1e-9, "{name} ({backend}) frame {i}: relative residual {r:e}");
        }
    }
    (m, runs)
}

/// Asserts `err ≤ TOL` and returns it (for the running maximum).
fn check(err: f64, what: impl FnOnce() -> String) -> f64 {
    assert!(err <= TOL, "{}: off by {err:e}", what());
    err
}

#[test]
fn fourbar_coupler_follows_the_circle_intersection() {
    let (m, runs) = solved_sweep("fourbar");
    let a = drawn(&m, "ground.A");
    let d = drawn(&m, "ground.D");
    let (b0, c0, p0) = (
        drawn(&m, "crank.B"),
        drawn(&m, "coupler.C"),
        drawn(&m, "coupler.P"),
    );
    assert_eq!(c0, drawn(&m, "rocker.C"));
    let coupler = dist(b0, c0);
    let rocker = dist(c0, d);
    // The drawn assembly: C on this side of the moving centre line B → D.
    let branch = side(b0, d, c0);
    for (backend, frames) in &runs {
        let mut worst = 0.0_f64;
        for f in frames {
            let theta = f.inputs[0].to_radians();
            let b = add(a, rotate(sub(b0, a), theta));
            let c = circles(b, coupler, d, rocker, branch);
            let p = carry(b0, c0, b, c, p0);
            let what = |n: &str| format!("fourbar ({backend}) theta = {}: {n}", f.inputs[0]);
            worst = worst.max(check(dist(at(&m, f, "crank.B"), b), || what("crank.B")));
            worst = worst.max(check(dist(at(&m, f, "coupler.C"), c), || what("coupler.C")));
            worst = worst.max(check(dist(at(&m, f, "rocker.C"), c), || what("rocker.C")));
            worst = worst.max(check(dist(at(&m, f, "coupler.P"), p), || what("coupler.P")));
        }
        eprintln!("fourbar ({backend}): worst deviation from the circle intersection {worst:e}");
    }
}

#[test]
fn slider_crank_slider_follows_the_offset_formula() {
    let (m, runs) = solved_sweep("slider_crank");
    let o = drawn(&m, "ground.O");
    let track = drawn(&m, "ground.S");
    let ex = drawn_dir(&m, "ground.S");
    let (b0, c0) = (drawn(&m, "crank.B"), drawn(&m, "slider.C"));
    // Track coordinates relative to the crank pivot: along the track, and
    // across it (to the left).
    let along = |x: P| dot(sub(x, o), ex);
    let across = |x: P| cross(ex, sub(x, o));
    let r = dist(b0, o);
    let l = dist(c0, b0);
    let e = across(track);
    let phi0 = across(b0).atan2(along(b0));
    // The header's formula takes the slider ahead of the crank pin.
    assert!(
        along(c0) > along(b0),
        "slider_crank drawn with the slider behind the crank"
    );
    let x_c = |phi: f64| r * phi.cos() + (l * l - (r * phi.sin() - e).powi(2)).sqrt();
    assert!(
        (x_c(phi0) - along(c0)).abs() <= TOL,
        "the formula reproduces the drawn pose"
    );
    for (backend, frames) in &runs {
        let mut worst = 0.0_f64;
        for f in frames {
            let phi = phi0 + f.inputs[0].to_radians();
            let what = |n: &str| format!("slider_crank ({backend}) theta = {}: {n}", f.inputs[0]);
            for name in ["slider.C", "rod.C"] {
                let c = at(&m, f, name);
                worst = worst.max(check((along(c) - x_c(phi)).abs(), || what(name)));
                worst = worst.max(check((across(c) - e).abs(), || what(name)));
            }
            let b = at(&m, f, "crank.B");
            let pin = [r * phi.cos(), r * phi.sin()];
            worst = worst.max(check(dist([along(b), across(b)], pin), || what("crank.B")));
        }
        eprintln!("slider_crank ({backend}): worst deviation from x_C(theta) {worst:e}");
    }
}

#[test]
fn inverted_slider_crank_rocker_follows_atan2() {
    let (m, runs) = solved_sweep("inverted_slider_crank");
    let o2 = drawn(&m, "ground.O2");
    let o4 = drawn(&m, "ground.O4");
    let b0 = drawn(&m, "crank.B");
    // Frame of the ground line O2 → O4.
    let ex = unit(sub(o4, o2));
    let local = |x: P| [dot(sub(x, o2), ex), cross(ex, sub(x, o2))];
    let r = dist(b0, o2);
    let d = dist(o4, o2);
    let phi0 = local(b0)[1].atan2(local(b0)[0]);
    let psi = |phi: f64| (r * phi.sin()).atan2(r * phi.cos() - d);
    let slot = |phi: f64| (r * r + d * d - 2.0 * r * d * phi.cos()).sqrt();
    for (backend, frames) in &runs {
        let (mut worst_psi, mut worst_s) = (0.0_f64, 0.0_f64);
        for f in frames {
            let phi = phi0 + f.inputs[0].to_radians();
            let what = |n: &str| format!("inverted_slider_crank ({backend}) theta = {}: {n}", f.inputs[0]);
            let turn = wrap(rotation(&m, f, "rocker") - (psi(phi) - psi(phi0))).abs();
            worst_psi = worst_psi.max(check(turn, || what("rocker rotation")));
            let s = dist(at(&m, f, "block.S"), at(&m, f, "rocker.O4"));
            worst_s = worst_s.max(check((s - slot(phi)).abs(), || what("|O4 B|")));
        }
        eprintln!(
            "inverted_slider_crank ({backend}): worst rocker angle error {worst_psi:e} rad, \
             slot position error {worst_s:e}"
        );
    }
}

#[test]
fn peaucellier_traces_a_straight_line_by_inversion() {
    let (m, runs) = solved_sweep("peaucellier");
    let o = drawn(&m, "ground.O");
    let o2 = drawn(&m, "ground.O2");
    let (q0, a0) = (drawn(&m, "crank.Q"), drawn(&m, "armA.A"));
    let r = dist(q0, o2);
    assert!(
        (dist(o2, o) - r).abs() <= 1e-12,
        "the crank circle passes through O"
    );
    let l = dist(a0, o);
    let s = dist(q0, a0);
    let power = l * l - s * s;
    let x_line = power / (2.0 * r);
    let axis = unit(sub(o2, o));
    for (backend, frames) in &runs {
        let (mut worst_line, mut worst_inv) = (0.0_f64, 0.0_f64);
        for f in frames {
            let what = |n: &str| format!("peaucellier ({backend}) theta = {}: {n}", f.inputs[0]);
            let q = at(&m, f, "crank.Q");
            for name in ["linkPA.P", "linkPB.P"] {
                let p = at(&m, f, name);
                let op = sub(p, o);
                worst_line = worst_line.max(check((dot(op, axis) - x_line).abs(), || what(name)));
                // Inversion in the circle of power l² − s² about O:
                // O, Q, P collinear and |OQ|·|OP| = l² − s².
                let off = cross(sub(q, o), op).abs() / norm(op);
                worst_inv = worst_inv.max(check(off, || what("O, Q, P collinear")));
                let prod = norm(sub(q, o)) * norm(op);
                worst_inv = worst_inv.max(check((prod - power).abs(), || what("|OQ| |OP|")));
            }
        }
        eprintln!(
            "peaucellier ({backend}): x = {x_line} line, worst {worst_line:e}; \
             |OQ||OP| = {power}, worst {worst_inv:e}"
        );
    }
}

#[test]
fn trammel_points_trace_ellipses() {
    let (m, runs) = solved_sweep("trammel");
    let (tx, ex) = (drawn(&m, "ground.TX"), drawn_dir(&m, "ground.TX"));
    let (ty, ey) = (drawn(&m, "ground.TY"), drawn_dir(&m, "ground.TY"));
    assert!(dot(ex, ey).abs() <= 1e-15, "the tracks are perpendicular");
    // Centre: where the two tracks cross.
    let centre = add(tx, scale(ex, cross(sub(ty, tx), ey) / cross(ex, ey)));
    let uv = |x: P| [dot(sub(x, centre), ex), dot(sub(x, centre), ey)];
    let (x0, y0) = (drawn(&m, "bar.X"), drawn(&m, "bar.Y"));
    let len = dist(x0, y0);
    let (ux0, vy0) = (uv(x0)[0], uv(y0)[1]);
    assert!(
        uv(x0)[1].abs() <= 1e-15 && uv(y0)[0].abs() <= 1e-15,
        "pins on their tracks"
    );
    for (backend, frames) in &runs {
        let mut worst = 0.0_f64;
        for point in ["bar.M", "bar.N"] {
            let p0 = drawn(&m, point);
            let lambda = dot(sub(p0, x0), sub(y0, x0)) / (len * len);
            assert!(
                cross(sub(p0, x0), sub(y0, x0)).abs() <= 1e-12,
                "{point} on the bar"
            );
            let (a, b) = ((1.0 - lambda).abs() * len, lambda.abs() * len);
            for f in frames {
                let what = || format!("trammel ({backend}) s = {}: {point}", f.inputs[0]);
                let p = uv(at(&m, f, point));
                let ellipse = p[0] * p[0] / (a * a) + p[1] * p[1] / (b * b) - 1.0;
                worst = worst.max(check(ellipse.abs(), what));
                // And where on the ellipse: the pins at x_X = x0 + s and
                // y_Y = ±sqrt(L² − x_X²) on the drawn side.
                let x_x = ux0 + f.inputs[0];
                let y_y = vy0.signum() * (len * len - x_x * x_x).sqrt();
                let expected = [(1.0 - lambda) * x_x, lambda * y_y];
                worst = worst.max(check(dist(p, expected), what));
            }
            eprintln!("trammel: {point} on x²/{a}² + y²/{b}² = 1");
        }
        eprintln!("trammel ({backend}): worst deviation {worst:e}");
    }
}

#[test]
fn pantograph_pen_is_a_scaled_copy_of_the_tracer() {
    let (m, runs) = solved_sweep("pantograph");
    let o = drawn(&m, "ground.O");
    let c0 = drawn(&m, "ground.C0");
    let (t0, p0) = (drawn(&m, "crank.T"), drawn(&m, "barEP.P"));
    let k = dist(p0, o) / dist(t0, o);
    assert!(
        cross(sub(t0, o), sub(p0, o)).abs() <= 1e-12,
        "O, T, P collinear as drawn"
    );
    for (backend, frames) in &runs {
        let mut worst = 0.0_f64;
        for f in frames {
            let what = |n: &str| format!("pantograph ({backend}) theta = {}: {n}", f.inputs[0]);
            let tracer = at(&m, f, "crank.T");
            let pen = at(&m, f, "barEP.P");
            let expected = add(o, scale(sub(tracer, o), k));
            worst = worst.max(check(dist(pen, expected), || what("pen vs tracer")));
            // The tracer itself is on the crank circle about C0.
            let t = add(c0, rotate(sub(t0, c0), f.inputs[0].to_radians()));
            worst = worst.max(check(dist(tracer, t), || what("tracer")));
            let expected = add(o, scale(sub(t, o), k));
            worst = worst.max(check(dist(pen, expected), || what("pen")));
        }
        eprintln!("pantograph ({backend}): k = {k}, worst deviation {worst:e}");
    }
}

#[test]
fn sixbar_a_follows_its_two_circle_intersections() {
    let (m, runs) = solved_sweep("sixbar_a");
    let (a, d, fp) = (
        drawn(&m, "ground.A"),
        drawn(&m, "ground.D"),
        drawn(&m, "ground.F"),
    );
    let (b0, c0, e0) = (
        drawn(&m, "coupler.B"),
        drawn(&m, "coupler.C"),
        drawn(&m, "coupler.E"),
    );
    let (g0, p0) = (drawn(&m, "link4.G"), drawn(&m, "link4.P"));
    let (bc, cd) = (dist(b0, c0), dist(c0, d));
    let (eg, gf) = (dist(e0, g0), dist(g0, fp));
    let branch_c = side(b0, d, c0);
    let branch_g = side(e0, fp, g0);
    for (backend, frames) in &runs {
        let mut worst = 0.0_f64;
        for f in frames {
            let what = |n: &str| format!("sixbar_a ({backend}) theta = {}: {n}", f.inputs[0]);
            // First loop: the crank-rocker A-B-C-D.
            let b = add(a, rotate(sub(b0, a), f.inputs[0].to_radians()));
            let c = circles(b, bc, d, cd, branch_c);
            // The coupler carries E; the dyad E-G-F closes on the ground.
            let e = carry(b0, c0, b, c, e0);
            let g = circles(e, eg, fp, gf, branch_g);
            let p = carry(e0, g0, e, g, p0);
            for (name, x) in [
                ("coupler.C", c),
                ("rocker.C", c),
                ("coupler.E", e),
                ("link4.G", g),
                ("link5.G", g),
                ("link4.P", p),
            ] {
                worst = worst.max(check(dist(at(&m, f, name), x), || what(name)));
            }
        }
        eprintln!("sixbar_a ({backend}): worst deviation {worst:e}");
    }
}

/// The parallelogram four-bar through its two change points, where all four
/// links are collinear and the circle–circle step is tangent (a double root):
/// θ = 120 (crank at 180°, |BD| = g + a = 6 = |BC| + |CD|) and θ = 300
/// (crank at 0°, |BD| = g − a = 2 = |BC| − |CD|). Both are hit exactly by the
/// sweep, and every frame of it solves with every joint holding to 1e-9.
///
/// Observed (identical in both back ends, deterministic):
///
/// - Keep (default): θ ∈ [0, 120] the linkage is a parallelogram (coupler
///   translating, rotation 0, C = B + (C₀ − B₀)); θ ∈ (120, 300) it is the
///   crossed antiparallelogram (C = the mirror of A in the perpendicular
///   bisector of BD; at θ = 121 the coupler has turned 0.667°, at θ = 240 by
///   60°); θ ∈ [300, 360] a parallelogram again, back to the drawn pose at
///   360. The kept branch is the side of C relative to the centre line
///   B → D, and for the parallelogram that side is the sign of the crank
///   pin's height y_B, which flips at each change point: keeping the side
///   switches mode at θ = 120 and switches back at θ = 300.
/// - Nearest: exactly the same poses, bit for bit. Leaving a change point,
///   the root nearest the tangent point is the one that moves slower: after
///   θ = 120 the antiparallelogram's C (it moves ~1/3 as fast as the
///   parallelogram's, 0.0116 vs 0.0349 for 1°), after θ = 300 the
///   parallelogram's (~3× slower than the antiparallelogram's). So nearest
///   root makes the same choices as keeping the side: neither policy keeps
///   the linkage a parallelogram over the full turn.
#[test]
fn parallelogram_switches_to_the_antiparallelogram_between_the_change_points() {
    let m = load("parallelogram");
    let requested = sweep_inputs(&m, None);
    let a = drawn(&m, "ground.A");
    let d = drawn(&m, "ground.D");
    let (b0, c0) = (drawn(&m, "crank.B"), drawn(&m, "coupler.C"));
    // Each mode's C, in closed form from the crank pin B.
    let pin = |theta: f64| add(a, rotate(sub(b0, a), theta.to_radians()));
    let parallelogram = |b: P| add(b, sub(c0, b0));
    let antiparallelogram = |b: P| {
        // Triangles ABD and CDB are congruent; crossed, C mirrors A in the
        // perpendicular bisector of BD.
        let u = unit(sub(d, b));
        let mid = scale(add(b, d), 0.5);
        sub(a, scale(u, 2.0 * dot(sub(a, mid), u)))
    };
    // The change points of the sweep: the crank collinear with the ground.
    let change = |theta: f64| cross(sub(d, a), sub(pin(theta), a)).abs() <= 1e-12;
    let changes: Vec<f64> = requested.iter().map(|r| r[0]).filter(|&t| change(t)).collect();
    assert_eq!(changes, [120.0, 300.0], "change points of the sweep");

    let mut keep = None;
    for branch in [BranchPolicy::Keep, BranchPolicy::Nearest] {
        let opts = Options {
            branch,
            ..Options::default()
        };
        for (backend, frames) in both_on(&m, opts, &requested) {
            for f in &frames {
                let theta = f.inputs[0];
                let what = format!("parallelogram ({branch:?}, {backend}) theta = {theta}");
                assert_eq!(f.status, FrameStatus::Solved, "{what}");
                assert_eq!(f.inputs, f.requested, "{what}");
                let r = max_relative_residual(&m, &f.poses, &f.inputs);
                assert!(r <= 1e-9, "{what}: relative residual {r:e}");
                let b = pin(theta);
                let (par, anti) = (parallelogram(b), antiparallelogram(b));
                let turn = wrap(rotation(&m, f, "coupler"));
                for name in ["coupler.C", "rocker.C"] {
                    let c = at(&m, f, name);
                    if change(theta) {
                        // Both modes meet at the tangent pose.
                        assert!(
                            dist(par, anti) <= TOL,
                            "{what}: modes apart by {:e}",
                            dist(par, anti)
                        );
                        assert!(dist(c, par) <= TOL, "{what}: {name} off by {:e}", dist(c, par));
                    } else if (120.0..=300.0).contains(&theta) {
                        // Strictly between the change points.
                        assert!(
                            dist(c, anti) <= TOL,
                            "{what}: {name} not an antiparallelogram ({:e})",
                            dist(c, anti)
                        );
                        assert!(dist(c, par) > 1e-3, "{what}: {name} still a parallelogram");
                        assert!(turn.abs() > 1e-3, "{what}: coupler did not turn ({turn:e})");
                    } else {
                        assert!(
                            dist(c, par) <= TOL,
                            "{what}: {name} not a parallelogram ({:e})",
                            dist(c, par)
                        );
                        assert!(turn.abs() <= TOL, "{what}: coupler turned {turn:e}");
                    }
                }
            }
            // The same poses under both policies, in both back ends.
            match &keep {
                None => keep = Some(frames),
                Some(k) => {
                    for (i, (fk, f)) in k.iter().zip(&frames).enumerate() {
                        assert_eq!(
                            fk.poses, f.poses,
                            "parallelogram frame {i}: {branch:?} ({backend}) differs from Keep"
                        );
                    }
                }
            }
        }
    }
    // Why nearest root agrees: leaving each change point, the mode it takes
    // has the root nearer the tangent pose.
    for (tangent, next, slower) in [
        (120.0, 121.0, "antiparallelogram"),
        (300.0, 301.0, "parallelogram"),
    ] {
        let c = parallelogram(pin(tangent));
        let b = pin(next);
        let (to_par, to_anti) = (dist(parallelogram(b), c), dist(antiparallelogram(b), c));
        eprintln!("parallelogram: leaving theta = {tangent}: parallelogram root {to_par:.5}, antiparallelogram root {to_anti:.5} away");
        assert_eq!(
            if to_anti < to_par {
                "antiparallelogram"
            } else {
                "parallelogram"
            },
            slower
        );
    }
}

/// The stress chains are a crank followed by k = (n − 2)/2 RRR dyads (n
/// bodies including the ground): the plan is one orient + one anchor for the
/// crank, then per dyad one circle–circle intersection and two aligns, so
/// 2 + 3k steps, k branch slots and k computed points (the unknowns left
/// after the crank: one intersection point per dyad).
#[test]
fn stress_chains_plan_two_steps_plus_three_per_dyad() {
    let names: Vec<String> = bundled()
        .into_iter()
        .filter(|n| n.starts_with("stress_"))
        .collect();
    assert_eq!(
        names,
        ["stress_10", "stress_20", "stress_30", "stress_40", "stress_50"]
    );
    for name in names {
        let m = load(&name);
        let p = plan(&m);
        let n = m.bodies.len();
        assert_eq!(name, format!("stress_{n}"), "body count in the name");
        assert_eq!(n % 2, 0);
        let k = (n - 2) / 2;
        eprintln!(
            "{name}: {n} bodies, {} joints, {} steps, {} branches, {} temps (k = {k})",
            m.joints.len(),
            p.steps.len(),
            p.branches.len(),
            p.temps.len()
        );
        assert_eq!(m.joints.len(), 3 * k + 1, "{name}: joints");
        assert_eq!(p.steps.len(), 2 + 3 * k, "{name}: steps");
        assert_eq!(p.branches.len(), k, "{name}: branch slots");
        assert_eq!(p.temps.len(), k, "{name}: computed points");
        assert!(
            matches!(p.steps[0].kind, StepKind::Orient { .. }),
            "{name}: step 0"
        );
        assert!(
            matches!(p.steps[1].kind, StepKind::Anchor { .. }),
            "{name}: step 1"
        );
        for (j, dyad) in p.steps[2..].chunks(3).enumerate() {
            assert!(
                matches!(
                    [&dyad[0].kind, &dyad[1].kind, &dyad[2].kind],
                    [
                        StepKind::CircleCircle { .. },
                        StepKind::Align { .. },
                        StepKind::Align { .. }
                    ]
                ),
                "{name}: dyad {} is not intersect + align + align",
                j + 1
            );
        }
    }
}
