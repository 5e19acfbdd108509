//! Velocities and accelerations by forward-mode differentiation through the
//! plan ([`Interpreter::rates`]), against independent computations: the
//! four-bar's loop-closure equations differentiated by hand and solved
//! here, and central differences of positions on every bundled sweep.

use dofplan::interp::{Interpreter, RateError};
use dofplan::simulate::sweep_requests;
use dofplan_runtime::planar::Pose;
use dofplan_runtime::real::Jet2;
use dofplan_runtime::{Driver, FrameStatus, Options, Solver};
use dofplan_tests::{bundled, load, plan};

/// A body's angular velocity and acceleration from its rotation's jets:
/// for a unit (c, s), ω = c·ṡ − s·ċ and α = c·s̈ − s·c̈.
fn omega_alpha(p: &Pose<Jet2>) -> (f64, f64) {
    let (c, s) = (p.rot.c, p.rot.s);
    (c.v * s.d - s.v * c.d, c.v * s.dd - s.v * c.dd)
}

/// The four-bar at several crank angles: the coupler's and rocker's
/// angular velocity and acceleration from the loop closure
/// a·e^{iθ2} + b·e^{iθ3} − c·e^{iθ4} = d, differentiated once and twice
/// and solved here as 2×2 linear systems (Cramer), with the angles read
/// from the solved frame's markers.
#[test]
fn a_fourbar_moves_as_its_loop_closure_says() {
    let m = load("fourbar");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let body = |name: &str| m.bodies.iter().position(|b| b.name == name).unwrap();
    let (crank, coupler, rocker) = (body("crank"), body("coupler"), body("rocker"));
    let marker = |b: usize, name: &str| m.bodies[b].markers.iter().find(|k| k.name == name).unwrap().at;
    // Crank at 30°/s and 5°/s² (rates in degrees, as inputs are).
    let (rate, accel) = (30.0, 5.0);
    let k = std::f64::consts::PI / 180.0;
    let (w2, a2) = (rate * k, accel * k);
    for theta in [0.0, 37.0, 90.0, 151.0, 200.0, 299.0] {
        assert_eq!(d.frame(&[theta]), FrameStatus::Solved);
        let poses = d.poses();
        let at = |b: usize, name: &str| poses[b].world(marker(b, name));
        let (a_, b_, c_, d_) = (at(crank, "A"), at(crank, "B"), at(coupler, "C"), at(rocker, "D"));
        let ang = |p: [f64; 2], q: [f64; 2]| (q[1] - p[1]).atan2(q[0] - p[0]);
        let len = |p: [f64; 2], q: [f64; 2]| (q[0] - p[0]).hypot(q[1] - p[1]);
        let (t2, t3, t4) = (ang(a_, b_), ang(b_, c_), ang(d_, c_));
        let (a, b, c) = (len(a_, b_), len(b_, c_), len(d_, c_));
        // i·a·ω2·e^{iθ2} + i·b·ω3·e^{iθ3} − i·c·ω4·e^{iθ4} = 0, as
        // [−b sin θ3, c sin θ4; b cos θ3, −c cos θ4]·(ω3, ω4) = (a ω2 sin θ2, −a ω2 cos θ2).
        let solve = |m: [[f64; 2]; 2], r: [f64; 2]| {
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            [
                (r[0] * m[1][1] - m[0][1] * r[1]) / det,
                (m[0][0] * r[1] - r[0] * m[1][0]) / det,
            ]
        };
        let lhs = [[-b * t3.sin(), c * t4.sin()], [b * t3.cos(), -c * t4.cos()]];
        let [w3, w4] = solve(lhs, [a * w2 * t2.sin(), -a * w2 * t2.cos()]);
        // Differentiated again: the same matrix on (α3, α4), and the
        // centripetal terms on the right.
        let rx = a * a2 * t2.sin() + a * w2 * w2 * t2.cos() + b * w3 * w3 * t3.cos() - c * w4 * w4 * t4.cos();
        let ry =
            -a * a2 * t2.cos() + a * w2 * w2 * t2.sin() + b * w3 * w3 * t3.sin() - c * w4 * w4 * t4.sin();
        let [a3, a4] = solve(lhs, [rx, ry]);
        let jets = interp.rates(d.state(), &[theta], &[rate], &[accel]).unwrap();
        let (pw2, pa2) = omega_alpha(&jets[crank]);
        let (pw3, pa3) = omega_alpha(&jets[coupler]);
        let (pw4, pa4) = omega_alpha(&jets[rocker]);
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + y.abs());
        assert!(close(pw2, w2) && close(pa2, a2), "{theta}°: crank {pw2} {pa2}");
        assert!(
            close(pw3, w3) && close(pw4, w4),
            "{theta}°: ω3 {pw3} vs {w3}, ω4 {pw4} vs {w4}"
        );
        assert!(
            close(pa3, a3) && close(pa4, a4),
            "{theta}°: α3 {pa3} vs {a3}, α4 {pa4} vs {a4}"
        );
    }
}

/// Every bundled planar sweep without numeric clusters (those with one:
/// tests/planar/cluster_rates.rs): at frames spread
/// over the sweep, each marker's first and second derivatives along the
/// sweep's direction equal central differences of positions solved by the
/// plan (h = 1e-3 of the direction), except at dead points, which must be
/// reported singular rather than as numbers.
#[test]
fn rates_agree_with_central_differences_on_every_bundled_sweep() {
    let mut checked = 0;
    for name in bundled() {
        let m = load(&name);
        let Some(sweep) = m.sweep.clone() else { continue };
        let p = plan(&m);
        if p.clusters() > 0 {
            continue;
        }
        let interp = Interpreter::new(p);
        let n = m.inputs.len();
        // The sweep's direction in input space, per unit of its parameter.
        let mut dir = vec![0.0; n];
        for s in &sweep.inputs {
            dir[s.input] = s.to - s.from;
        }
        let scale = dir.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        if scale == 0.0 {
            continue;
        }
        let dir: Vec<f64> = dir.iter().map(|x| x / scale).collect();
        let requests: Vec<Vec<f64>> = sweep_requests(&sweep, n).collect();
        let mut d = Driver::new(interp.clone(), Options::default());
        let size = m.size();
        for (i, u) in requests.iter().enumerate() {
            if d.frame(u) != FrameStatus::Solved || i % (requests.len() / 7).max(1) != 0 {
                continue;
            }
            let jets = match interp.rates(d.state(), u, &dir, &vec![0.0; n]) {
                Ok(j) => j,
                Err(RateError::Singular) => continue,
                Err(e) => panic!("{name} frame {i}: {e}"),
            };
            // Positions at u ± h·dir, each solved from this frame.
            let h = 1e-3;
            let at = |t: f64| -> Option<Vec<Pose>> {
                let v: Vec<f64> = u.iter().zip(&dir).map(|(x, e)| x + t * e).collect();
                let mut state = d.state().clone();
                let mut ctx = dofplan_runtime::Ctx::new(Default::default(), false);
                interp.solve(&mut state, &v, &mut ctx).ok()?;
                Some(Interpreter::poses(&state).to_vec())
            };
            let (Some(plus), Some(minus)) = (at(h), at(-h)) else {
                continue; // at the edge of assembly
            };
            let here = d.poses().to_vec();
            for id in m.all_markers() {
                let local = m.marker(id).at;
                let j = jets[id.body].world(local);
                let (pp, pm, p0) = (
                    plus[id.body].world(local),
                    minus[id.body].world(local),
                    here[id.body].world(local),
                );
                for k in 0..2 {
                    let first = (pp[k] - pm[k]) / (2.0 * h);
                    let second = (pp[k] - 2.0 * p0[k] + pm[k]) / (h * h);
                    assert!(
                        (j[k].d - first).abs() <= 1e-5 * size.max(j[k].d.abs()),
                        "{name} frame {i} {}: d {} vs {first}",
                        m.marker_name(id),
                        j[k].d
                    );
                    assert!(
                        (j[k].dd - second).abs() <= 1e-3 * size.max(j[k].dd.abs()),
                        "{name} frame {i} {}: dd {} vs {second}",
                        m.marker_name(id),
                        j[k].dd
                    );
                }
            }
            checked += 1;
        }
    }
    assert!(checked >= 50, "{checked} frames checked");
}

/// At a dead point the rate is infinite: rocker_rocker at its break point
/// (the coupler and output in line) reports singular, not a huge number.
#[test]
fn a_dead_point_is_reported_singular() {
    let m = load("rocker_rocker");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(
        interp.clone(),
        Options {
            breaking: dofplan_runtime::BreakPolicy::Search,
            ..Options::default()
        },
    );
    // Past the upper break point (45.52°): search stops at it.
    let status = d.frame(&[60.0]);
    assert!(matches!(status, FrameStatus::Searched { .. }), "{status:?}");
    let at = d.inputs().to_vec();
    let r = interp.rates(d.state(), &at, &[1.0], &[0.0]);
    assert_eq!(r.err(), Some(RateError::Singular), "at {at:?}");
}

/// The offset slider-crank's piston: x = r cos φ + √(l² − (r sin φ − e)²)
/// with φ = φ0 + θ, differentiated by hand here (with g = r sin φ − e and
/// w = √(l² − g²): ẋ = −r sin φ·φ̇ − g·ġ/w, ġ = r cos φ·φ̇), at a constant
/// crank rate, against the plan's jets of slider.C.
#[test]
fn a_slider_crank_piston_moves_as_its_closed_form_says() {
    let m = load("slider_crank");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let slider = m.bodies.iter().position(|b| b.name == "slider").unwrap();
    let c_local = m.bodies[slider]
        .markers
        .iter()
        .find(|k| k.name == "C")
        .unwrap()
        .at;
    // The file's geometry (its header): r = 1, l = 3.5, e = 0.25, φ0 = 30°.
    let (r, l, e, phi0) = (1.0_f64, 3.5_f64, 0.25_f64, 30.0_f64);
    let rate = 120.0_f64; // degrees per second, constant
    let w = rate.to_radians();
    for theta in [0.0_f64, 45.0, 100.0, 180.0, 250.0, 333.0] {
        assert_eq!(d.frame(&[theta]), FrameStatus::Solved);
        let phi = (phi0 + theta).to_radians();
        let g = r * phi.sin() - e;
        let root = (l * l - g * g).sqrt();
        let x = r * phi.cos() + root;
        let g_dot = r * phi.cos() * w;
        let g_ddot = -r * phi.sin() * w * w;
        let root_dot = -g * g_dot / root;
        let x_dot = -r * phi.sin() * w + root_dot;
        // (g ġ)' = ġ² + g g̈; w' = −(g ġ)'/w + (g ġ)·w'/w² … written as
        // root'' = −(ġ² + g g̈)/root − root'²/root.
        let root_ddot = -(g_dot * g_dot + g * g_ddot) / root - root_dot * root_dot / root;
        let x_ddot = -r * phi.cos() * w * w + root_ddot;
        let jets = interp.rates(d.state(), &[theta], &[rate], &[0.0]).unwrap();
        let p = jets[slider].world(c_local);
        assert!((p[0].v - x).abs() < 1e-12, "{theta}°: x {} vs {x}", p[0].v);
        assert!(
            (p[0].d - x_dot).abs() < 1e-9 * (1.0 + x_dot.abs()),
            "{theta}°: ẋ {} vs {x_dot}",
            p[0].d
        );
        assert!(
            (p[0].dd - x_ddot).abs() < 1e-9 * (1.0 + x_ddot.abs()),
            "{theta}°: ẍ {} vs {x_ddot}",
            p[0].dd
        );
        // The piston stays on its track: no vertical rate.
        assert!(p[1].d.abs() < 1e-12 && p[1].dd.abs() < 1e-12);
    }
}

/// The generated modules' `rates` (the same steps emitted for jets) equal
/// the interpreter's to 1e-12 on every frame of every bundled sweep, numeric
/// clusters included (tests/planar/cluster_rates.rs checks those further).
#[test]
fn compiled_rates_equal_interpreted_rates() {
    use dofplan_runtime::real::Rates;
    let mut compared = 0;
    for name in bundled() {
        let m = load(&name);
        let Some(sweep) = m.sweep.clone() else { continue };
        let p = plan(&m);
        // A cluster is solved again by `rates`, not bit for bit as the one
        // pass solved it (tests/planar/cluster_rates.rs compares those two).
        let clusters = p.clusters() > 0;
        let interp = Interpreter::new(p);
        let n = m.inputs.len();
        let rates: Vec<f64> = (0..n).map(|k| 10.0 + k as f64).collect();
        let accels: Vec<f64> = (0..n).map(|k| 2.0 - k as f64).collect();
        let requests: Vec<Vec<f64>> = sweep_requests(&sweep, n).collect();
        dofplan_generated::with_plan!(name.as_str(), |compiled| {
            let mut dc = Driver::new(compiled, Options::default());
            let mut di = Driver::new(interp.clone(), Options::default());
            let mut out = vec![Pose::<Jet2>::cst(Pose::IDENTITY); m.bodies.len()];
            let mut fused_out = out.clone();
            // The fused pass (solve and rates on jets at once), driven by
            // hand beside the driver: its positions are exactly solve's.
            let mut fused_state = dofplan_runtime::Solver::initial_state(&compiled);
            for u in &requests {
                assert_eq!(dc.frame(u), di.frame(u), "{name}");
                let mut ctx = dofplan_runtime::Ctx::new(Default::default(), false);
                let fused =
                    compiled.solve_rates_into(&mut fused_state, u, &rates, &accels, &mut ctx, &mut fused_out);
                if fused.is_ok() || fused == Err(RateError::Singular) {
                    assert_eq!(
                        fused_state.poses,
                        dc.state().poses,
                        "{name}: the fused pass's positions are solve's"
                    );
                }
                let c = compiled.rates_into(dc.state(), dc.inputs(), &rates, &accels, &mut out);
                let i = interp.rates(di.state(), di.inputs(), &rates, &accels);
                match (c, i) {
                    (Ok(()), Ok(jets)) => {
                        if fused.is_ok() && !clusters {
                            assert_eq!(fused_out, out, "{name}: the fused pass's rates are rates'");
                        }
                        for (a, b) in out.iter().zip(&jets) {
                            for (x, y) in [
                                (a.at[0], b.at[0]),
                                (a.at[1], b.at[1]),
                                (a.rot.c, b.rot.c),
                                (a.rot.s, b.rot.s),
                            ] {
                                for (p, q) in [(x.d, y.d), (x.dd, y.dd)] {
                                    assert!((p - q).abs() <= 1e-12 * (1.0 + q.abs()), "{name}: {p} vs {q}");
                                }
                            }
                        }
                        compared += 1;
                    }
                    (Err(a), Err(b)) if a == b => {}
                    (c, i) => panic!("{name}: compiled {c:?}, interpreted {:?}", i.map(|_| ())),
                }
            }
        })
        .expect("every bundled mechanism is compiled");
    }
    assert!(compared > 1000, "{compared} frames compared");
}
