//! Velocities and accelerations through numeric clusters, by the implicit
//! function theorem on each cluster's Jacobian, against independent
//! computations: central differences of positions on every sweep whose
//! plan has a cluster, the compiled plans' rates against the interpreter's,
//! and Chain-4's minimum-norm velocity from its loop-closure equations
//! differentiated and solved here.

use dofplan::interp::{Interpreter, RateError};
use dofplan::model::Mechanism;
use dofplan::simulate::sweep_requests;
use dofplan_runtime::planar::Pose;
use dofplan_runtime::real::{Jet2, Rates};
use dofplan_runtime::{Ctx, Driver, FrameStatus, Options, Solver};
use dofplan_tests::{bundled, load, plan};

/// Every bundled mechanism and test fixture whose plan has a numeric
/// cluster, with its compiled module's name.
fn with_clusters() -> Vec<(String, Mechanism)> {
    let mut all: Vec<(String, Mechanism)> = bundled().into_iter().map(|n| (n.clone(), load(&n))).collect();
    let fixture = dofplan_tests::mechanisms_dir().join("../tests/fixtures/sixbar_slotted.toml");
    let m = dofplan::load_file(&fixture).unwrap_or_else(|e| panic!("{e}"));
    all.push((m.name.clone(), m));
    all.retain(|(_, m)| plan(m).clusters() > 0);
    assert!(all.len() >= 10, "{} mechanisms with clusters", all.len());
    all
}

/// The jet of marker `local` on a body.
fn marker(pose: &Pose<Jet2>, local: [f64; 2]) -> [Jet2; 2] {
    pose.world(local)
}

/// On every sweep whose plan has a cluster, at frames spread over it: each
/// marker's first and second derivatives along the sweep's direction equal
/// central differences of positions solved from the frame (h = 1e-3 of the
/// direction). A frame reported singular must be near a dead point: its
/// neighbours' rates are large.
#[test]
fn cluster_rates_agree_with_central_differences() {
    let mut checked = 0;
    for (name, m) in with_clusters() {
        let Some(sweep) = m.sweep.clone() else { continue };
        let interp = Interpreter::new(plan(&m));
        let n = m.inputs.len();
        let mut dir = vec![0.0; n];
        for s in &sweep.inputs {
            dir[s.input] = s.to - s.from;
        }
        let scale = dir.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
        assert!(scale > 0.0, "{name}");
        let dir: Vec<f64> = dir.iter().map(|x| x / scale).collect();
        let requests: Vec<Vec<f64>> = sweep_requests(&sweep, n).collect();
        let mut d = Driver::new(interp.clone(), Options::default());
        let size = m.size();
        let mut here_checked = 0;
        for (i, u) in requests.iter().enumerate() {
            if d.frame(u) != FrameStatus::Solved || i % (requests.len() / 9).max(1) != 0 {
                continue;
            }
            let jets = match interp.rates(d.state(), u, &dir, &vec![0.0; n]) {
                Ok(j) => j,
                Err(RateError::Singular) => continue,
                Err(e) => panic!("{name} frame {i}: {e}"),
            };
            let h = 1e-3;
            let at = |t: f64| -> Option<Vec<Pose>> {
                let v: Vec<f64> = u.iter().zip(&dir).map(|(x, e)| x + t * e).collect();
                let mut state = d.state().clone();
                let mut ctx = Ctx::new(Default::default(), false);
                interp.solve(&mut state, &v, &mut ctx).ok()?;
                Some(Interpreter::poses(&state).to_vec())
            };
            let (Some(plus), Some(minus)) = (at(h), at(-h)) else {
                continue;
            };
            let here = d.poses().to_vec();
            for id in m.all_markers() {
                let local = m.marker(id).at;
                let j = marker(&jets[id.body], local);
                let (pp, pm, p0) = (
                    plus[id.body].world(local),
                    minus[id.body].world(local),
                    here[id.body].world(local),
                );
                for k in 0..2 {
                    // The frame solved again from itself: to round-off.
                    assert!(
                        (j[k].v - p0[k]).abs() <= 1e-12 * size,
                        "{name} frame {i}: the value is the frame's"
                    );
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
            here_checked += 1;
        }
        assert!(here_checked >= 3, "{name}: {here_checked} frames checked");
        checked += here_checked;
    }
    assert!(checked >= 50, "{checked} frames checked");
}

/// The compiled plans with clusters: `rates` equals the interpreter's to
/// 1e-12 on every frame of their sweeps, `solve_rates` gives `solve`'s
/// positions bit for bit and `rates`' jets exactly.
#[test]
fn compiled_cluster_rates_equal_interpreted_ones() {
    let mut compared = 0;
    for (name, m) in with_clusters() {
        let Some(sweep) = m.sweep.clone() else { continue };
        let interp = Interpreter::new(plan(&m));
        let n = m.inputs.len();
        let rates: Vec<f64> = (0..n).map(|k| 10.0 + k as f64).collect();
        let accels: Vec<f64> = (0..n).map(|k| 2.0 - k as f64).collect();
        let requests: Vec<Vec<f64>> = sweep_requests(&sweep, n).collect();
        let module = dofplan::emit::ident_for(&name);
        dofplan_generated::with_plan!(module.as_str(), |compiled| {
            let mut dc = Driver::new(compiled, Options::default());
            let mut di = Driver::new(interp.clone(), Options::default());
            let mut out = vec![Pose::<Jet2>::cst(Pose::IDENTITY); m.bodies.len()];
            let mut fused_out = out.clone();
            let mut fused_state = Solver::initial_state(&compiled);
            for (i, u) in requests.iter().enumerate() {
                assert_eq!(dc.frame(u), di.frame(u), "{name}");
                let mut ctx = Ctx::new(Default::default(), false);
                let fused =
                    compiled.solve_rates_into(&mut fused_state, u, &rates, &accels, &mut ctx, &mut fused_out);
                assert!(
                    matches!(fused, Ok(()) | Err(RateError::Singular)),
                    "{name} frame {i}: {fused:?}"
                );
                assert_eq!(
                    fused_state.poses,
                    dc.state().poses,
                    "{name} frame {i}: solve_rates' positions are solve's"
                );
                let c = compiled.rates_into(dc.state(), dc.inputs(), &rates, &accels, &mut out);
                let i_rates = interp.rates(di.state(), di.inputs(), &rates, &accels);
                match (c, i_rates) {
                    (Ok(()), Ok(jets)) => {
                        // `rates` solves the cluster again from the frame
                        // (the unknowns read back from the poses, within
                        // Newton's tolerance of the one pass's solution but
                        // not bit for bit, and a last iteration when that
                        // tips the residual over the tolerance): the one
                        // pass's jets agree with it to that tolerance, the
                        // compiled and interpreted `rates` to round-off.
                        let pairs = |a: &[Pose<Jet2>], b: &[Pose<Jet2>], tol: f64, what: &str| {
                            for (a, b) in a.iter().zip(b) {
                                for (x, y) in [
                                    (a.at[0], b.at[0]),
                                    (a.at[1], b.at[1]),
                                    (a.rot.c, b.rot.c),
                                    (a.rot.s, b.rot.s),
                                ] {
                                    for (p, q) in [(x.v, y.v), (x.d, y.d), (x.dd, y.dd)] {
                                        assert!(
                                            (p - q).abs() <= tol * (1.0 + q.abs()),
                                            "{name} frame {i}, {what}: {p} vs {q}"
                                        );
                                    }
                                }
                            }
                        };
                        if fused.is_ok() {
                            pairs(&fused_out, &out, 1e-9, "solve_rates against rates");
                        }
                        pairs(&out, &jets, 1e-12, "compiled against interpreted");
                        compared += 1;
                    }
                    (Err(a), Err(b)) if a == b => {}
                    (c, i_rates) => panic!(
                        "{name} frame {i}: compiled {c:?}, interpreted {:?}",
                        i_rates.map(|_| ())
                    ),
                }
            }
        })
        .expect("every mechanism with a cluster is compiled");
    }
    assert!(compared > 300, "{compared} frames compared");
}

/// A body's angular velocity and acceleration from its rotation's jets:
/// for a unit (c, s), ω = c·ṡ − s·ċ and α = c·s̈ − s·c̈.
fn omega_alpha(p: &Pose<Jet2>) -> (f64, f64) {
    let (c, s) = (p.rot.c, p.rot.s);
    (c.v * s.d - s.v * c.d, c.v * s.dd - s.v * c.dd)
}

/// Chain-4 (links 2 to 4 a cluster of three angles and one closing joint,
/// under-constrained): with aₖ link k's vector (joint to joint, the last
/// one to the ground pivot G1) and P1 the driven link's end, the loop
/// closure P1 + a2 + a3 + a4 = G1 differentiated gives
/// [a2⊥ a3⊥ a4⊥]·(ω2, ω3, ω4) = −ω1·P1⊥, and again
/// [a2⊥ a3⊥ a4⊥]·(α2, α3, α4) = −α1·P1⊥ + ω1²·P1 + Σ ωₖ²·aₖ: two equations
/// in three rates, solved here by the minimum-norm formula Aᵀ(AAᵀ)⁻¹b (the
/// least motion the cluster's Newton takes, all unknowns being angles on
/// one scale), against the plan's jets.
#[test]
fn chain_4_moves_by_the_least_motion_its_loop_closure_allows() {
    let m = load("chain_4");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let body = |name: &str| m.bodies.iter().position(|b| b.name == name).unwrap();
    let links = [body("link_1"), body("link_2"), body("link_3"), body("link_4")];
    let marker = |b: usize, name: &str| m.bodies[b].markers.iter().find(|k| k.name == name).unwrap().at;
    let g1 = marker(body("ground"), "G1");
    let (rate, accel) = (30.0, 5.0);
    let k = std::f64::consts::PI / 180.0;
    let (w1, a1) = (rate * k, accel * k);
    let perp = |v: [f64; 2]| [-v[1], v[0]];
    let sub = |a: [f64; 2], b: [f64; 2]| [a[0] - b[0], a[1] - b[1]];
    // The minimum-norm solution of the 2 × 3 system [c0 c1 c2]·x = b.
    let min_norm = |c: [[f64; 2]; 3], b: [f64; 2]| {
        let g = |i: usize, j: usize| c.iter().map(|col| col[i] * col[j]).sum::<f64>();
        let (g00, g01, g11) = (g(0, 0), g(0, 1), g(1, 1));
        let det = g00 * g11 - g01 * g01;
        let y = [(g11 * b[0] - g01 * b[1]) / det, (g00 * b[1] - g01 * b[0]) / det];
        c.map(|col| col[0] * y[0] + col[1] * y[1])
    };
    for theta in [0.0, -5.0, -11.0, -17.0, -24.0, -30.0] {
        assert_eq!(d.frame(&[theta]), FrameStatus::Solved);
        let poses = d.poses();
        let at = |l: usize, name: &str| poses[links[l]].world(marker(links[l], name));
        let (p1, p2, p3) = (at(0, "E"), at(1, "E"), at(2, "E"));
        let a = [sub(p2, p1), sub(p3, p2), sub(g1, p3)];
        let cols = a.map(perp);
        let pp1 = perp(p1); // G0 is the origin
        let w = min_norm(cols, [-w1 * pp1[0], -w1 * pp1[1]]);
        let rhs =
            |i: usize| -a1 * pp1[i] + w1 * w1 * p1[i] + (0..3).map(|k| w[k] * w[k] * a[k][i]).sum::<f64>();
        let al = min_norm(cols, [rhs(0), rhs(1)]);
        let jets = interp.rates(d.state(), &[theta], &[rate], &[accel]).unwrap();
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * (1.0 + y.abs());
        for l in 1..4 {
            let (pw, pa) = omega_alpha(&jets[links[l]]);
            assert!(close(pw, w[l - 1]), "{theta}°: ω{} {pw} vs {}", l + 1, w[l - 1]);
            assert!(close(pa, al[l - 1]), "{theta}°: α{} {pa} vs {}", l + 1, al[l - 1]);
        }
    }
}

/// Turned the other way Chain-4 pulls straight (at about 12.75°): the
/// search policy stops the input there, where the cluster's Jacobian has
/// lost rank, and the rates are reported singular, not as huge numbers.
#[test]
fn a_cluster_pulled_straight_is_reported_singular() {
    let m = load("chain_4");
    let interp = Interpreter::new(plan(&m));
    let options = Options {
        breaking: dofplan_runtime::BreakPolicy::Search,
        ..Options::default()
    };
    let mut d = Driver::new(interp.clone(), options);
    for theta in [5.0, 10.0, 12.0, 20.0] {
        d.frame(&[theta]);
    }
    let at = d.inputs().to_vec();
    assert!(at[0] > 12.0 && at[0] < 13.0, "stopped at {at:?}");
    assert_eq!(
        interp.rates(d.state(), &at, &[1.0], &[0.0]).err(),
        Some(RateError::Singular)
    );
    dofplan_generated::with_plan!("chain_4", |compiled| {
        let mut dc = Driver::new(compiled, options);
        for theta in [5.0, 10.0, 12.0, 20.0] {
            dc.frame(&[theta]);
        }
        let mut out = vec![Pose::<Jet2>::cst(Pose::IDENTITY); m.bodies.len()];
        let r = compiled.rates_into(dc.state(), dc.inputs(), &[1.0], &[0.0], &mut out);
        assert_eq!(r, Err(RateError::Singular));
    })
    .unwrap();
}

/// sixbar_b is sixbar_a driven from another joint (tests/planar/mixed.rs): its
/// square cluster's rates, by the implicit function theorem, are the
/// closed-form plan's rates of sixbar_a driven at the crank angle, rate
/// and acceleration sixbar_b's jets give its crank (the chain rule), for
/// every body, velocities and accelerations.
#[test]
fn sixbar_b_cluster_rates_are_sixbar_a_closed_form_rates() {
    let (a, b) = (load("sixbar_a"), load("sixbar_b"));
    let (pa, pb) = (plan(&a), plan(&b));
    assert!(pb.clusters() > 0 && pa.clusters() == 0);
    let (ia, ib) = (Interpreter::new(pa), Interpreter::new(pb));
    let mut db = Driver::new(ib.clone(), Options::default());
    let mut da = Driver::new(ia.clone(), Options::default());
    let crank = b.bodies.iter().position(|x| x.name == "crank").unwrap();
    let deg = 180.0 / std::f64::consts::PI;
    let (rate, accel) = (30.0, -4.0);
    let mut compared = 0;
    for u in sweep_requests(b.sweep.as_ref().unwrap(), 1) {
        assert_eq!(db.frame(&u), FrameStatus::Solved);
        let jb = ib.rates(db.state(), &u, &[rate], &[accel]).unwrap();
        let r = db.poses()[crank].rot;
        let phi = r.s.atan2(r.c) * deg;
        let (w, al) = omega_alpha(&jb[crank]);
        assert_eq!(da.frame(&[phi]), FrameStatus::Solved);
        let ja = ia.rates(da.state(), &[phi], &[w * deg], &[al * deg]).unwrap();
        for (k, body) in b.bodies.iter().enumerate() {
            let ka = a.bodies.iter().position(|x| x.name == body.name).unwrap();
            let (x, y) = (&jb[k], &ja[ka]);
            for (p, q) in [
                (x.at[0], y.at[0]),
                (x.at[1], y.at[1]),
                (x.rot.c, y.rot.c),
                (x.rot.s, y.rot.s),
            ] {
                for (s, t) in [(p.d, q.d), (p.dd, q.dd)] {
                    assert!(
                        (s - t).abs() <= 1e-9 * (1.0 + t.abs()),
                        "θ = {}: {}: {s} (cluster) vs {t} (closed form)",
                        u[0],
                        body.name
                    );
                }
            }
        }
        compared += 1;
    }
    assert!(compared > 20, "{compared}");
}
